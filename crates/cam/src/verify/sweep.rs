//! The inner loop of the verifying simulation: every dexel lowered to its first entry into the
//! cutter over all poses. Called by [`super::simulate`] on the grid and on the refinement.
//!
//! A binary tree over the pose sequence bounds each run of consecutive poses by one pose of
//! it thickened by how far the run strays from that pose; dexels are taken in spatial tiles,
//! each tile collects the runs whose boxes meet it, and each dexel descends only into runs whose
//! thickened cutter it enters below its current height. The result is the exact minimum over
//! all poses, as a plain loop over them would give, in far fewer entries; tiles run in parallel
//! and each dexel's result depends on nothing but its own ray, so it is deterministic.
//!
//! The bound (why a run's poses cannot cut deeper than its thickened representative): pose `k`
//! is pose `P` moved rigidly — its core's bottom centre `c` by `e₀ ≥ |c_k − c_P|`, its axis
//! turned by `θ` about `c_P`, `e₁ ≥ |a_k − a_P| = 2 sin(θ/2)` — so a core point `y` moves
//! at most `e₀ + e₁|y − c_P|`, and `|y − c_P| ≤ |y − x| + |x − c_P|`. Hence for any point `x`,
//! `dist(x, core_k) ≥ (1 − e₁)·dist(x, core_P) − e₁|x − c_P| − e₀`, and a point of the cutter
//! at pose `k` (distance ≤ r to its core) on a dexel whose ends lie within `M` of `c_P` is
//! within `(r + e₀ + e₁M)/(1 − e₁)` of `P`'s core.
//!
//! A ball's bound is far tighter where the dexel passes below every ball centre of the run
//! (`z_k(x) = (x − c_k)·a_k < 0`, which `z_P(x) < −(e₀ + e₁M)` at both ends of the dexel proves,
//! `|z_k − z_P| ≤ e₀ + e₁M`): there its solid is the ball `|x − c_k| ≤ r` alone, and the balls of
//! a run lie in the capsule of radius `r + d` about the chord of their centres, `d` the centres'
//! largest distance from it — near the continuous sweep itself on a smooth pass.

use rayon::prelude::*;
use tezgah_geom::Vec3;

use super::solid::{capsule_entry, CutterPose, CutterSolid};
use super::Dexel;

/// Poses at the tree's leaves (entered one by one).
const LEAF: usize = 4;
/// Runs whose poses' core bottoms span at most this many tool radii are what a tile collects (and
/// each dexel descends into): the sweep spaces poses by the motion of the cutter's farthest
/// point, so near a turn of the axis they crowd at the tip, and a count would not do.
const RUN_RADII: f64 = 1.0;
/// Runs whose axis turns this much (2 sin(θ/2)) are not bounded by their representative.
const MAX_TURN: f64 = 0.5;
/// Slack on the bounds against rounding: a run is entered when its bound is this close.
const SLACK: f64 = 1e-9;

/// Lowers dexels to where they enter the cutter at each pose.
pub(super) struct Sweeper {
    pub solid: CutterSolid,
    /// Tool radius R.
    pub radius: f64,
    /// Tile edge, mm.
    pub tile: f64,
}

/// A run of consecutive poses `lo..hi` and what bounds it.
struct Node {
    lo: u32,
    hi: u32,
    /// Children (indices into the node list); none at a leaf.
    children: Option<(u32, u32)>,
    /// The representative pose (the middle one).
    rep: u32,
    /// Largest motion of the core's bottom centre from the representative's.
    e0: f64,
    /// Largest |a_k − a_P| (twice the sine of half the turn).
    e1: f64,
    /// Box holding every pose's solid.
    min: Vec3,
    max: Vec3,
    /// Chord from the first to the last ball centre (core bottom: start, unit direction,
    /// length) and the centres' largest distance from it.
    chord: (Vec3, Vec3, f64),
    deviation: f64,
}

struct PoseTree {
    nodes: Vec<Node>,
}

impl PoseTree {
    fn build(poses: &[CutterPose], solid: &CutterSolid, radius: f64) -> Self {
        let bottom = |p: &CutterPose| p.tip + p.axis * solid.corner;
        let top = |p: &CutterPose| p.tip + p.axis * solid.core_top;
        let mut tree = PoseTree {
            nodes: Vec::with_capacity(2 * poses.len() / LEAF + 2),
        };
        tree.grow(poses, 0, poses.len(), &bottom, &top, radius);
        tree
    }

    fn grow(
        &mut self,
        poses: &[CutterPose],
        lo: usize,
        hi: usize,
        bottom: &impl Fn(&CutterPose) -> Vec3,
        top: &impl Fn(&CutterPose) -> Vec3,
        radius: f64,
    ) -> u32 {
        let rep = lo + (hi - lo) / 2;
        let (c_rep, a_rep) = (bottom(&poses[rep]), poses[rep].axis);
        let (mut e0, mut e1) = (0.0_f64, 0.0_f64);
        let mut min = Vec3::repeat(f64::INFINITY);
        let mut max = Vec3::repeat(f64::NEG_INFINITY);
        for p in &poses[lo..hi] {
            let (c, t) = (bottom(p), top(p));
            e0 = e0.max((c - c_rep).norm());
            e1 = e1.max((p.axis - a_rep).norm());
            min = min.inf(&c).inf(&t);
            max = max.sup(&c).sup(&t);
        }
        // Every solid lies within R of its axis segment from the core's bottom to its top.
        let (min, max) = (min.add_scalar(-radius), max.add_scalar(radius));
        let (c0, c1) = (bottom(&poses[lo]), bottom(&poses[hi - 1]));
        let deviation = poses[lo..hi]
            .iter()
            .map(|p| point_segment_distance(&bottom(p), &c0, &c1))
            .fold(0.0, f64::max);
        let len = (c1 - c0).norm();
        let along = if len > 0.0 {
            (c1 - c0) / len
        } else {
            poses[rep].axis
        };
        let chord = (c0, along, len);
        let at = self.nodes.len();
        self.nodes.push(Node {
            lo: lo as u32,
            hi: hi as u32,
            children: None,
            rep: rep as u32,
            e0,
            e1,
            min,
            max,
            chord,
            deviation,
        });
        if hi - lo > LEAF {
            let left = self.grow(poses, lo, rep, bottom, top, radius);
            let right = self.grow(poses, rep, hi, bottom, top, radius);
            self.nodes[at].children = Some((left, right));
        }
        at as u32
    }

    /// The runs whose core bottoms span at most `span` mm whose boxes meet the box `lo`–`hi`.
    fn runs_meeting(&self, lo: &Vec3, hi: &Vec3, span: f64, out: &mut Vec<u32>) {
        let mut stack = vec![0u32];
        while let Some(k) = stack.pop() {
            let node = &self.nodes[k as usize];
            if !boxes_meet(&node.min, &node.max, lo, hi) {
                continue;
            }
            match node.children {
                Some((l, r)) if 2.0 * node.e0 > span => {
                    stack.push(r);
                    stack.push(l);
                }
                _ => out.push(k),
            }
        }
    }
}

fn point_segment_distance(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + d * s)).norm()
}

fn boxes_meet(a0: &Vec3, a1: &Vec3, b0: &Vec3, b1: &Vec3) -> bool {
    (0..3).all(|i| a0[i] <= b1[i] && b0[i] <= a1[i])
}

/// One dexel's ray and its current height, while it descends the tree.
struct Ray {
    foot: Vec3,
    normal: Vec3,
    height: f64,
    /// How deep below its foot it reaches.
    floor: f64,
    /// The pose that last lowered it.
    best: Option<u32>,
    /// Its deepest point, its point at the current height, and the box of the two.
    bottom: Vec3,
    top: Vec3,
    min: Vec3,
    max: Vec3,
}

impl Ray {
    fn new(d: &Dexel) -> Self {
        let bottom = d.foot - d.normal * d.floor;
        let mut ray = Ray {
            foot: d.foot,
            normal: d.normal,
            height: d.height,
            floor: d.floor,
            best: None,
            bottom,
            top: bottom,
            min: bottom,
            max: bottom,
        };
        ray.lower(d.height);
        ray
    }

    fn lower(&mut self, height: f64) {
        self.height = height;
        self.top = self.foot + self.normal * height;
        self.min = self.bottom.inf(&self.top);
        self.max = self.bottom.sup(&self.top);
    }
}

impl Sweeper {
    pub fn run(&self, dexels: &mut [Dexel], poses: &[CutterPose]) {
        if dexels.is_empty() || poses.is_empty() || poses.len() >= u32::MAX as usize {
            if poses.len() >= u32::MAX as usize {
                // Unreachable in practice (the sweep caps its poses long before); fall back
                // to the plain loop rather than truncate.
                for d in dexels.iter_mut() {
                    for pose in poses {
                        self.enter(pose, d);
                    }
                }
            }
            return;
        }
        let tree = PoseTree::build(poses, &self.solid, self.radius);
        // Tiles: dexels grouped by the cube of side `tile` their foot is in.
        let mut lo = Vec3::repeat(f64::INFINITY);
        for d in dexels.iter() {
            lo = lo.inf(&d.foot);
        }
        let cube = |p: &Vec3| -> [u32; 3] {
            [0, 1, 2].map(|i| ((p[i] - lo[i]) / self.tile).floor().clamp(0.0, 1e9) as u32)
        };
        let mut order: Vec<([u32; 3], u32)> = dexels
            .iter()
            .enumerate()
            .map(|(k, d)| (cube(&d.foot), k as u32))
            .collect();
        order.par_sort_unstable();
        let mut tiles = Vec::new();
        let mut start = 0;
        for k in 1..=order.len() {
            if k == order.len() || order[k].0 != order[start].0 {
                tiles.push(start..k);
                start = k;
            }
        }
        let shared: &[Dexel] = dexels;
        let heights: Vec<Vec<f64>> = tiles
            .par_iter()
            .map(|range| self.sweep_tile(shared, &order[range.clone()], &tree, poses))
            .collect();
        for (range, hs) in tiles.iter().zip(heights) {
            for (&(_, k), h) in order[range.clone()].iter().zip(hs) {
                dexels[k as usize].height = h;
            }
        }
    }

    /// The plain update of one dexel by one pose.
    fn enter(&self, pose: &CutterPose, d: &mut Dexel) {
        if let Some(t) = self
            .solid
            .entry(pose, &d.foot, &d.normal, -d.floor, d.height)
        {
            d.height = d.height.min(t);
        }
    }

    /// The new heights of one tile's dexels, in its order.
    fn sweep_tile(
        &self,
        dexels: &[Dexel],
        members: &[([u32; 3], u32)],
        tree: &PoseTree,
        poses: &[CutterPose],
    ) -> Vec<f64> {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for &(_, k) in members {
            let d = &dexels[k as usize];
            let (a, b) = (d.foot - d.normal * d.floor, d.foot + d.normal * d.height);
            lo = lo.inf(&a).inf(&b);
            hi = hi.sup(&a).sup(&b);
        }
        let mut runs = Vec::new();
        tree.runs_meeting(&lo, &hi, RUN_RADII * self.radius, &mut runs);
        // Nearest runs first: the first dexel finds its low point early and prunes the rest.
        let centre = (lo + hi) * 0.5;
        let mut keyed: Vec<(f64, u32)> = runs
            .iter()
            .map(|&k| {
                let p = &poses[tree.nodes[k as usize].rep as usize];
                ((p.tip - centre).norm_squared(), k)
            })
            .collect();
        keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut hint: Option<u32> = None;
        let mut stack = Vec::new();
        members
            .iter()
            .map(|&(_, k)| {
                let d = &dexels[k as usize];
                let mut ray = Ray::new(d);
                // The neighbour's lowest pose is most often this dexel's too.
                if let Some(h) = hint {
                    self.leaf(&mut ray, &poses[h as usize], h);
                }
                for &(_, run) in &keyed {
                    self.descend(&mut ray, run, tree, poses, &mut stack);
                }
                if ray.best.is_some() {
                    hint = ray.best;
                }
                ray.height
            })
            .collect()
    }

    fn leaf(&self, ray: &mut Ray, pose: &CutterPose, k: u32) {
        if let Some(t) = self
            .solid
            .entry(pose, &ray.foot, &ray.normal, -ray.floor, ray.height)
        {
            if t < ray.height {
                ray.lower(t);
                ray.best = Some(k);
            }
        }
    }

    fn descend(
        &self,
        ray: &mut Ray,
        root: u32,
        tree: &PoseTree,
        poses: &[CutterPose],
        stack: &mut Vec<u32>,
    ) {
        stack.clear();
        stack.push(root);
        while let Some(k) = stack.pop() {
            let node = &tree.nodes[k as usize];
            if !self.may_cut(ray, node, poses) {
                continue;
            }
            match node.children {
                Some((l, r)) => {
                    stack.push(r);
                    stack.push(l);
                }
                None => {
                    for i in node.lo..node.hi {
                        self.leaf(ray, &poses[i as usize], i);
                    }
                }
            }
        }
    }

    /// Whether some pose of `node` may enter the dexel below its current height (the bound of
    /// the module's doc).
    fn may_cut(&self, ray: &Ray, node: &Node, poses: &[CutterPose]) -> bool {
        let (a, b) = (ray.bottom, ray.top);
        if !boxes_meet(&node.min, &node.max, &ray.min, &ray.max) {
            return false;
        }
        if node.e1 >= MAX_TURN {
            return true;
        }
        let rep = &poses[node.rep as usize];
        let c = rep.tip + rep.axis * self.solid.corner;
        let m = (a - c).norm().max((b - c).norm());
        if self.solid.core_radius == 0.0 {
            let below = (a - c).dot(&rep.axis).max((b - c).dot(&rep.axis));
            if below < -(node.e0 + node.e1 * m) {
                let (c0, along, len) = node.chord;
                let reach = self.solid.corner + node.deviation;
                return capsule_entry(&c0, &along, len, reach, &ray.foot, &ray.normal, -ray.floor)
                    .is_some_and(|t| t < ray.height + SLACK);
            }
        }
        let reach = (self.solid.corner + node.e0 + node.e1 * m) / (1.0 - node.e1);
        self.solid
            .entry_within(
                rep,
                &ray.foot,
                &ray.normal,
                -ray.floor,
                ray.height + SLACK,
                reach,
            )
            .is_some_and(|t| t < ray.height + SLACK)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::{Cutter, CutterShape};
    use proptest::prelude::*;

    fn dexel(foot: Vec3, normal: Vec3, height: f64, floor: f64) -> Dexel {
        Dexel {
            node: (0, 0),
            foot,
            normal,
            uv: (0.0, 0.0),
            height,
            floor,
        }
    }

    /// A wavy 5-axis-like pass over a bumpy sheet: the tree sweep equals the plain loop.
    fn check(shape: CutterShape, seed: u64, count: usize) {
        let solid = CutterSolid::of(&Cutter::standard(shape));
        let r = shape.radius();
        let sweeper = Sweeper {
            solid,
            radius: r,
            tile: 1.0,
        };
        let mut rng = seed;
        let mut next = || {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((rng >> 11) as f64) / (1u64 << 53) as f64
        };
        let (amp, freq) = (0.5 + next(), 0.2 + 0.3 * next());
        let mut poses = Vec::new();
        for pass in 0..6 {
            let y = pass as f64 * 1.1;
            for k in 0..count {
                let x = k as f64 * 0.13;
                let tilt = 0.3 * (freq * x).sin();
                poses.push(CutterPose {
                    tip: Vec3::new(x, y, amp * (freq * x).cos() - 0.05),
                    axis: Vec3::new(tilt.sin(), 0.1 * tilt, tilt.cos()).normalize(),
                });
            }
        }
        let mut plain: Vec<Dexel> = Vec::new();
        for i in 0..40 {
            for j in 0..25 {
                let (x, y) = (i as f64 * 0.1 * count as f64 / 40.0, j as f64 * 0.23);
                let slope = -amp * freq * (freq * x).sin();
                let n = Vec3::new(-slope, 0.0, 1.0).normalize();
                plain.push(dexel(Vec3::new(x, y, amp * (freq * x).cos()), n, r, r));
            }
        }
        let mut fast: Vec<Dexel> = plain
            .iter()
            .map(|d| dexel(d.foot, d.normal, d.height, d.floor))
            .collect();
        for d in &mut plain {
            for p in &poses {
                sweeper.enter(p, d);
            }
        }
        sweeper.run(&mut fast, &poses);
        for (a, b) in plain.iter().zip(&fast) {
            assert!(
                (a.height - b.height).abs() < 1e-9,
                "{:?}: {} vs {}",
                a.foot,
                a.height,
                b.height
            );
        }
        assert!(plain.iter().any(|d| d.height < r));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(12))]
        #[test]
        fn tree_sweep_equals_the_plain_loop(seed in any::<u64>(), which in 0..3usize) {
            let shape = [
                CutterShape::Ball { radius: 3.0 },
                CutterShape::Flat { radius: 2.0 },
                CutterShape::BullNose { radius: 3.0, corner_radius: 1.0 },
            ][which];
            check(shape, seed, 120);
        }
    }
}

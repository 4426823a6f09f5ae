//! The edge of the machine's reach on the surface (with `Settings::max_axis_tilt_deg`): the
//! curve where the outward normal leans from +Z the tilt limit less the cutter's nominal lean
//! (`Settings::reach_normal_tilt_deg`), so the cutter reaches all of it. Runs after a strategy's
//! passes are placed: a pass that crosses the edge is ended on it (not a forward step short of
//! it), and the edge itself is cut as passes of its own, so the strip between the last
//! reachable pass and the edge — up to a side step wide — is machined like the rest.
//!
//! The edge is a level set `n_z(u, v) = cos θ_max`, traced by marching squares (Lorensen &
//! Cline 1987, in two dimensions) on a grid over the domain, each crossing of a grid edge found
//! by bisection and kept on its reachable side; saddle cells are split by the value at their
//! centre.

use std::collections::{HashMap, HashSet};

use super::{Context, GougeReport, Placed, Refusal};
use crate::forward_step::UvPolyline;

/// Grid cells per parameter for tracing the edge (its topology; the points are exact).
const GRID: usize = 90;
/// Bisections of a grid edge (the crossing to 2⁻⁴⁰ of the cell).
const BISECTIONS: usize = 40;
/// The edge is traced this far inside the limit (in the normal's z), so rounding does not
/// put its points out of reach.
const INSIDE: f64 = 1e-9;
/// Bisections of a forward step that crosses the edge, for the pass's last reachable contact.
const END_BISECTIONS: usize = 24;

/// A grid edge: between nodes (i, j) and (i + 1, j) (`along_u`) or (i, j) and (i, j + 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct GridEdge {
    along_u: bool,
    i: usize,
    j: usize,
}

impl Context<'_> {
    /// How far inside the reach the outward normal at (u, v) lies: its z less the limit's
    /// cosine (less [`INSIDE`]); `None` where there is no normal.
    fn reach_margin(&self, cos_limit: f64, u: f64, v: f64) -> Option<f64> {
        let n = self.derivs(u, v).normal()?.into_inner();
        let n = if self.settings.reverse_normal { -n } else { n };
        Some(n.z - cos_limit - INSIDE)
    }

    /// The reach edges as parameter polylines (empty without a tilt limit or where the whole
    /// domain lies on one side of it).
    pub(super) fn reach_edges(&self) -> Vec<UvPolyline> {
        let Some(limit) = self.settings.reach_normal_tilt_deg(self.shape()) else {
            return Vec::new();
        };
        let cos_limit = limit.to_radians().cos();
        let (du, dv) = (self.surface.domain_u(), self.surface.domain_v());
        let n = GRID;
        let at = |k: usize, r: (f64, f64)| r.0 + (r.1 - r.0) * k as f64 / n as f64;
        let inside_at =
            |u: f64, v: f64| self.reach_margin(cos_limit, u, v).is_some_and(|m| m >= 0.0);
        let inside: Vec<bool> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i, j)))
            .map(|(i, j)| inside_at(at(i, du), at(j, dv)))
            .collect();
        let node = |i: usize, j: usize| inside[i * (n + 1) + j];
        let ends = |e: GridEdge| {
            if e.along_u {
                ((e.i, e.j), (e.i + 1, e.j))
            } else {
                ((e.i, e.j), (e.i, e.j + 1))
            }
        };
        let crossed = |e: GridEdge| {
            let (a, b) = ends(e);
            node(a.0, a.1) != node(b.0, b.1)
        };
        let mut links: HashMap<GridEdge, Vec<GridEdge>> = HashMap::new();
        let mut link = |a: GridEdge, b: GridEdge| {
            links.entry(a).or_default().push(b);
            links.entry(b).or_default().push(a);
        };
        for i in 0..n {
            for j in 0..n {
                // Counter-clockwise: bottom, right, top, left.
                let sides = [
                    GridEdge {
                        along_u: true,
                        i,
                        j,
                    },
                    GridEdge {
                        along_u: false,
                        i: i + 1,
                        j,
                    },
                    GridEdge {
                        along_u: true,
                        i,
                        j: j + 1,
                    },
                    GridEdge {
                        along_u: false,
                        i,
                        j,
                    },
                ];
                let cut: Vec<GridEdge> = sides.iter().copied().filter(|&e| crossed(e)).collect();
                match cut.as_slice() {
                    [a, b] => link(*a, *b),
                    [_, _, _, _] => {
                        // A saddle: if the centre is on the bottom-left corner's side, the
                        // edge cuts off the bottom-right and top-left corners, else the other two.
                        let centre = inside_at(
                            0.5 * (at(i, du) + at(i + 1, du)),
                            0.5 * (at(j, dv) + at(j + 1, dv)),
                        );
                        if centre == node(i, j) {
                            link(sides[0], sides[1]);
                            link(sides[2], sides[3]);
                        } else {
                            link(sides[0], sides[3]);
                            link(sides[1], sides[2]);
                        }
                    }
                    _ => {}
                }
            }
        }
        // The crossing on a grid edge, on its reachable side.
        let point = |e: GridEdge| {
            let (a, b) = ends(e);
            let (mut pin, mut pout) = ((at(a.0, du), at(a.1, dv)), (at(b.0, du), at(b.1, dv)));
            if !node(a.0, a.1) {
                std::mem::swap(&mut pin, &mut pout);
            }
            for _ in 0..BISECTIONS {
                let mid = (0.5 * (pin.0 + pout.0), 0.5 * (pin.1 + pout.1));
                if inside_at(mid.0, mid.1) {
                    pin = mid;
                } else {
                    pout = mid;
                }
            }
            pin
        };
        // Chains: open ones from the edges with one link (on the domain's boundary) first,
        // then the closed loops.
        let mut seen: HashSet<GridEdge> = HashSet::new();
        let mut starts: Vec<GridEdge> = links
            .iter()
            .filter(|(_, l)| l.len() == 1)
            .map(|(e, _)| *e)
            .collect();
        let mut rest: Vec<GridEdge> = links.keys().copied().collect();
        // A fixed order (the map's is random) keeps the plan deterministic.
        let key = |e: &GridEdge| (e.i, e.j, e.along_u);
        starts.sort_by_key(key);
        rest.sort_by_key(key);
        let mut out = Vec::new();
        for start in starts.into_iter().chain(rest) {
            if !seen.insert(start) {
                continue;
            }
            let mut chain = vec![start];
            let mut here = start;
            while let Some(next) = links[&here].iter().copied().find(|e| !seen.contains(e)) {
                seen.insert(next);
                chain.push(next);
                here = next;
            }
            // A loop closes on its start.
            if links[&here].contains(&start) && chain.len() > 2 {
                chain.push(start);
            }
            if chain.len() >= 2 {
                out.push(UvPolyline {
                    points: chain.into_iter().map(point).collect(),
                });
            }
        }
        out
    }

    /// Where a pass crosses out of reach between the contacts at `t_in` (placed) and `t_out`
    /// (refused as out of reach, or as an interference gouge), the last contact that is
    /// placed: bisection on the pass. Toward the reach edge a gouge on the way leaves the pass
    /// as it is; toward a gouge every refusal bounds the bisection, so the end found is a
    /// placed contact short of the first one.
    pub(super) fn reach_end(
        &self,
        t_in: f64,
        (t_out, out): (f64, &Refusal),
        place_at: impl Fn(f64) -> Result<Placed, GougeReport>,
    ) -> Option<(f64, Placed)> {
        let toward_gouge = out.is_interference();
        let (mut lo, mut hi) = (t_in, t_out);
        let mut best = None;
        for _ in 0..END_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            match place_at(mid) {
                Ok(p) => {
                    lo = mid;
                    best = Some((mid, p));
                }
                Err(r) if r.refusal.is_beyond() || toward_gouge => hi = mid,
                // Something else refuses the way to the edge (a gouge): leave the pass as is.
                Err(_) => return None,
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Context, Settings, StrategyKind};
    use crate::cutter::{Cutter, CutterShape};

    #[test]
    fn the_reach_edge_of_a_sphere_patch_is_its_parallel_at_the_limit() {
        // Sphere R 30 between latitudes 10° and 60°: with 50° of tilt the edge is the
        // parallel at latitude 40° (normals 50° from +Z), one polyline across the patch's
        // longitudes, every point on it to rounding and on the reachable side.
        let r = 30.0;
        let surface = crate::testing::sphere(r);
        let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
        let mut settings = Settings::new(StrategyKind::ZigZag, 0.2, 0.01);
        settings.max_axis_tilt_deg = Some(50.0);
        let ctx = Context::new(&surface, &cutter, &settings).unwrap();
        let edges = ctx.reach_edges();
        assert_eq!(edges.len(), 1, "{edges:?}");
        let z = r * 40f64.to_radians().sin();
        let (mut x_min, mut y_min) = (f64::INFINITY, f64::INFINITY);
        for &(u, v) in &edges[0].points {
            let p = surface.point(u, v);
            let n = surface.normal(u, v).unwrap();
            assert!((p.z - z).abs() < 1e-6, "{p:?}");
            assert!(n.z >= 50f64.to_radians().cos(), "{n:?}");
            x_min = x_min.min(p.x);
            y_min = y_min.min(p.y);
        }
        // From one longitude edge (x = 0 or y = 0) of the patch to the other.
        assert!(x_min.abs() < 1e-9 && y_min.abs() < 1e-9, "{x_min} {y_min}");
        // No limit, or a limit every normal keeps: no edge.
        settings.max_axis_tilt_deg = Some(85.0);
        let ctx = Context::new(&surface, &cutter, &settings).unwrap();
        assert!(ctx.reach_edges().is_empty());
        settings.max_axis_tilt_deg = None;
        let ctx = Context::new(&surface, &cutter, &settings).unwrap();
        assert!(ctx.reach_edges().is_empty());
    }
}

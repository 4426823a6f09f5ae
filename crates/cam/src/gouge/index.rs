//! The spatial index of the rear and global gouge checks: points sampled on the surface at a
//! given spacing, bucketed in a uniform 3-D grid stored compressed (cell offsets + points
//! sorted by cell), so a query visits only the cells its box overlaps. A uniform grid fits
//! here better than a tree: the samples are evenly spread by construction and every query is
//! a box of about the same size (the tool), so one cell size serves all.

use crate::arc_grid::{arc_nodes, spread};
use tezgah_geom::{NurbsSurface, Vec3};

/// Cells allowed in a grid; the cell grows when the surface's box would need more.
pub const MAX_CELLS: usize = 1 << 22;
/// Samples allowed per index (≈ 100 MB of points); more is refused rather than coarsened, so
/// the check never silently loses resolution.
pub const MAX_SAMPLES: usize = 4_000_000;

/// One surface sample: its point, unit normal (zero where the surface has none, e.g. a pole)
/// and its node on the sampling lattice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub point: Vec3,
    pub normal: Vec3,
    /// How far the sample's [`SurfaceSamples::cell`] reaches from it.
    pub reach: Reach,
    /// Indices into [`SurfaceSamples::u`] and [`SurfaceSamples::v`].
    pub node: [u32; 2],
}

/// A lattice of surface samples: the parameter lines and a sample at every crossing.
#[derive(Debug, Clone)]
pub struct SurfaceSamples {
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub samples: Vec<Sample>,
}

impl SurfaceSamples {
    /// The parameter rectangle of the surface nearer to sample `node` than to its lattice
    /// neighbours (half-way to each, the domain's edge at the lattice's edge):
    /// `[u_lo, u_hi, v_lo, v_hi]`.
    pub fn cell(&self, node: [u32; 2]) -> [f64; 4] {
        let half = |xs: &[f64], i: usize| {
            let lo = if i > 0 {
                0.5 * (xs[i - 1] + xs[i])
            } else {
                xs[i]
            };
            let hi = if i + 1 < xs.len() {
                0.5 * (xs[i] + xs[i + 1])
            } else {
                xs[i]
            };
            (lo, hi)
        };
        let (u0, u1) = half(&self.u, node[0] as usize);
        let (v0, v1) = half(&self.v, node[1] as usize);
        [u0, u1, v0, v1]
    }
}

/// Points sampled on the surface on a lattice of parameter lines at equal steps of arc
/// length (`arc_grid`, as the verifying simulation's dexels), neighbours at most `spacing` mm
/// apart along either parameter everywhere: a STEP fit whose speed varies 5:1 is not sampled
/// at its fastest place's density all over. `None` when that would exceed [`MAX_SAMPLES`].
pub fn sample_surface(surface: &NurbsSurface, spacing: f64) -> Option<SurfaceSamples> {
    let (du, dv) = (surface.domain_u(), surface.domain_v());
    let (us, lu) = arc_nodes(|u, v| surface.derivs(u, v).su.norm(), du, dv);
    let (vs, lv) = arc_nodes(|v, u| surface.derivs(u, v).sv.norm(), dv, du);
    let count = |len: f64| (len / spacing).ceil().max(1.0) + 1.0;
    let (nu, nv) = (count(lu), count(lv));
    if nu * nv > MAX_SAMPLES as f64 || (nu * nv).is_nan() {
        return None;
    }
    let (u_nodes, v_nodes) = (spread(&us, nu as usize), spread(&vs, nv as usize));
    let mut lattice = SurfaceSamples {
        samples: Vec::with_capacity(u_nodes.len() * v_nodes.len()),
        u: u_nodes,
        v: v_nodes,
    };
    for i in 0..lattice.u.len() {
        for j in 0..lattice.v.len() {
            let node = [i as u32, j as u32];
            let (u, v) = (lattice.u[i], lattice.v[j]);
            let d = surface.derivs(u, v);
            let [u0, u1, v0, v1] = lattice.cell(node);
            lattice.samples.push(Sample {
                point: d.point,
                normal: d.normal().map_or(Vec3::zeros(), |n| n.into_inner()),
                reach: Reach::of(&d, (u - u0).max(u1 - u), (v - v0).max(v1 - v)),
                node,
            });
        }
    }
    Some(lattice)
}

/// How far a parameter cell reaches from a point of it: the surface there lies within
/// `α·du + β·dv` (|α|, |β| ≤ 1) of the point along its tangent plane, to first order
/// (`S_u·Δu`, `S_v·Δv` with [`COVER_MARGIN`] for the derivatives' change across a cell, a
/// fraction of a millimetre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    pub du: Vec3,
    pub dv: Vec3,
}

impl Reach {
    pub fn of(d: &tezgah_geom::SurfaceDerivs, du: f64, dv: f64) -> Reach {
        Reach {
            du: d.su * (du.abs() * COVER_MARGIN),
            dv: d.sv * (dv.abs() * COVER_MARGIN),
        }
    }

    /// Farthest the cell reaches, mm.
    pub fn cover(&self) -> f64 {
        self.du.norm() + self.dv.norm()
    }

    /// The most `g·(x − p)` can be over the cell's tangent extent.
    pub fn along(&self, g: &Vec3) -> f64 {
        g.dot(&self.du).abs() + g.dot(&self.dv).abs()
    }
}

/// Margin of [`Reach`].
pub const COVER_MARGIN: f64 = 1.1;

/// Points bucketed in a uniform grid of cubic cells.
#[derive(Debug, Clone)]
pub struct PointGrid {
    origin: Vec3,
    cell: f64,
    dims: [usize; 3],
    /// `starts[c]..starts[c + 1]` indexes `points` of cell `c`.
    starts: Vec<u32>,
    points: Vec<Sample>,
}

impl PointGrid {
    /// Buckets `points` in cells of about `cell` mm (larger if the box would need more than
    /// [`MAX_CELLS`] cells).
    pub fn new(points: Vec<Sample>, cell: f64) -> PointGrid {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in &points {
            lo = lo.inf(&p.point);
            hi = hi.sup(&p.point);
        }
        if points.is_empty() {
            (lo, hi) = (Vec3::zeros(), Vec3::zeros());
        }
        let extent = hi - lo;
        let mut cell = if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            1.0
        };
        let dims = loop {
            let d = [0, 1, 2].map(|k| (extent[k] / cell).floor() as usize + 1);
            if d[0] * d[1] * d[2] <= MAX_CELLS {
                break d;
            }
            cell *= 2.0;
        };
        let mut grid = PointGrid {
            origin: lo,
            cell,
            dims,
            starts: vec![0; dims[0] * dims[1] * dims[2] + 1],
            points: Vec::new(),
        };
        let ids: Vec<usize> = points.iter().map(|p| grid.cell_of(&p.point)).collect();
        for &c in &ids {
            grid.starts[c + 1] += 1;
        }
        for c in 0..grid.starts.len() - 1 {
            grid.starts[c + 1] += grid.starts[c];
        }
        let mut fill = grid.starts.clone();
        // Every slot is overwritten below; the clone only sizes the buffer.
        let mut sorted = points.clone();
        for (p, c) in points.iter().zip(ids) {
            sorted[fill[c] as usize] = *p;
            fill[c] += 1;
        }
        grid.points = sorted;
        grid
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    fn index(&self, p: &Vec3, k: usize) -> usize {
        let x = ((p[k] - self.origin[k]) / self.cell).floor();
        (x.max(0.0) as usize).min(self.dims[k] - 1)
    }

    fn cell_of(&self, p: &Vec3) -> usize {
        let [i, j, k] = [0, 1, 2].map(|a| self.index(p, a));
        (i * self.dims[1] + j) * self.dims[2] + k
    }

    /// Calls `visit` on every sample of the cells overlapping the box `[lo, hi]` (a superset of
    /// the samples in the box) until it returns `false`.
    pub fn visit_box(&self, lo: &Vec3, hi: &Vec3, mut visit: impl FnMut(&Sample) -> bool) {
        let top = self.origin + Vec3::from([0, 1, 2].map(|k| self.dims[k] as f64 * self.cell));
        if (0..3).any(|k| hi[k] < self.origin[k] || lo[k] > top[k]) {
            return;
        }
        let a = [0, 1, 2].map(|k| self.index(lo, k));
        let b = [0, 1, 2].map(|k| self.index(hi, k));
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                let row = (i * self.dims[1] + j) * self.dims[2];
                let (s, e) = (
                    self.starts[row + a[2]] as usize,
                    self.starts[row + b[2] + 1] as usize,
                );
                for p in &self.points[s..e] {
                    if !visit(p) {
                        return;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_queries_find_exactly_the_points_a_scan_finds() {
        let samples = sample_surface(&crate::testing::freeform(0.3), 1.5).unwrap();
        assert!(sample_surface(&crate::testing::plane(1e5), 0.01).is_none());
        let pts: Vec<Vec3> = samples.samples.iter().map(|s| s.point).collect();
        assert!(pts.len() > 4000);
        let grid = PointGrid::new(samples.samples.clone(), 4.0);
        for (lo, hi) in [
            (Vec3::new(10.0, 10.0, -20.0), Vec3::new(17.0, 23.0, 20.0)),
            (Vec3::new(-5.0, 90.0, 0.0), Vec3::new(3.0, 130.0, 1.0)),
            (Vec3::new(40.0, 40.0, 100.0), Vec3::new(50.0, 50.0, 120.0)),
        ] {
            let inside = |p: &Vec3| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
            let want = pts.iter().filter(|p| inside(p)).count();
            let mut got = 0;
            grid.visit_box(&lo, &hi, |p| {
                got += usize::from(inside(&p.point));
                true
            });
            assert_eq!(got, want);
        }
    }

    #[test]
    fn samples_follow_arc_length_on_a_warped_parametrisation() {
        // Columns at x = 100·g² (warp 1): the speed along u runs from 0 to twice its mean.
        let surface = crate::testing::freeform(1.0);
        let spacing = 1.0;
        let pts: Vec<Vec3> = sample_surface(&surface, spacing)
            .unwrap()
            .samples
            .iter()
            .map(|s| s.point)
            .collect();
        // Every surface point has a sample within half a cell's diagonal (plus the 5 % speed
        // margin's worth), at 300 pseudo-random parameters.
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let p = surface.point(next(), next());
            let d = pts
                .iter()
                .map(|q| (p - q).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.75 * spacing, "{p:?}: nearest sample {d}");
        }
        // A uniform lattice at the fastest speed would need far more.
        let fastest = |f: &dyn Fn(f64, f64) -> f64| {
            (0..=32)
                .flat_map(|i| (0..=32).map(move |j| (i as f64 / 32.0, j as f64 / 32.0)))
                .map(|(u, v)| f(u, v))
                .fold(0.0_f64, f64::max)
        };
        let lu = fastest(&|u, v| surface.derivs(u, v).su.norm());
        let lv = fastest(&|u, v| surface.derivs(u, v).sv.norm());
        let uniform = (lu / spacing).ceil() * (lv / spacing).ceil();
        assert!(
            (pts.len() as f64) < 0.7 * uniform,
            "{} vs {uniform}",
            pts.len()
        );
    }
}

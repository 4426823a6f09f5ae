//! The spatial index of the rear and global gouge checks: points sampled on the surface at a
//! given spacing, bucketed in a uniform 3-D grid stored compressed (cell offsets + points
//! sorted by cell), so a query visits only the cells its box overlaps. A uniform grid fits
//! here better than a tree: the samples are evenly spread by construction and every query is
//! a box of about the same size (the tool), so one cell size serves all.

use tezgah_geom::{NurbsSurface, Vec3};

/// Cells allowed in a grid; the cell grows when the surface's box would need more.
pub const MAX_CELLS: usize = 1 << 22;
/// Samples allowed per index (≈ 100 MB of points); more is refused rather than coarsened, so
/// the check never silently loses resolution.
pub const MAX_SAMPLES: usize = 4_000_000;

/// Points sampled on the surface on a parametric lattice fine enough that neighbours are at
/// most about `spacing` mm apart: the lattice counts come from the longest of a few iso
/// lines' polygon lengths in each direction. `None` when that would exceed [`MAX_SAMPLES`].
pub fn sample_surface(surface: &NurbsSurface, spacing: f64) -> Option<Vec<Vec3>> {
    let (u0, u1) = surface.domain_u();
    let (v0, v1) = surface.domain_v();
    let probe = 48;
    let length = |along_u: bool| {
        (0..=4)
            .map(|k| {
                let fixed = k as f64 / 4.0;
                let mut len = 0.0;
                let mut prev: Option<Vec3> = None;
                for i in 0..=probe {
                    let s = i as f64 / probe as f64;
                    let p = if along_u {
                        surface.point(u0 + (u1 - u0) * s, v0 + (v1 - v0) * fixed)
                    } else {
                        surface.point(u0 + (u1 - u0) * fixed, v0 + (v1 - v0) * s)
                    };
                    if let Some(q) = prev {
                        len += (p - q).norm();
                    }
                    prev = Some(p);
                }
                len
            })
            .fold(0.0, f64::max)
    };
    // The polygon underestimates a wiggly line's length; 1.2 and the speed's variation along
    // the line are covered by sampling each direction a little denser than needed.
    let count = |len: f64| (1.2 * len / spacing).ceil().max(2.0);
    let (nu, nv) = (count(length(true)), count(length(false)));
    let total = (nu + 1.0) * (nv + 1.0);
    if total.is_nan() || total > MAX_SAMPLES as f64 {
        return None;
    }
    let (nu, nv) = (nu as usize, nv as usize);
    let mut points = Vec::with_capacity((nu + 1) * (nv + 1));
    for i in 0..=nu {
        let u = u0 + (u1 - u0) * i as f64 / nu as f64;
        for j in 0..=nv {
            points.push(surface.point(u, v0 + (v1 - v0) * j as f64 / nv as f64));
        }
    }
    Some(points)
}

/// Points bucketed in a uniform grid of cubic cells.
#[derive(Debug, Clone)]
pub struct PointGrid {
    origin: Vec3,
    cell: f64,
    dims: [usize; 3],
    /// `starts[c]..starts[c + 1]` indexes `points` of cell `c`.
    starts: Vec<u32>,
    points: Vec<Vec3>,
}

impl PointGrid {
    /// Buckets `points` in cells of about `cell` mm (larger if the box would need more than
    /// [`MAX_CELLS`] cells).
    pub fn new(points: Vec<Vec3>, cell: f64) -> PointGrid {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in &points {
            lo = lo.inf(p);
            hi = hi.sup(p);
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
        let ids: Vec<usize> = points.iter().map(|p| grid.cell_of(p)).collect();
        for &c in &ids {
            grid.starts[c + 1] += 1;
        }
        for c in 0..grid.starts.len() - 1 {
            grid.starts[c + 1] += grid.starts[c];
        }
        let mut fill = grid.starts.clone();
        let mut sorted = vec![Vec3::zeros(); points.len()];
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

    /// Calls `visit` on every point of the cells overlapping the box `[lo, hi]` (a superset of
    /// the points in the box) until it returns `false`.
    pub fn visit_box(&self, lo: &Vec3, hi: &Vec3, mut visit: impl FnMut(&Vec3) -> bool) {
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
        let pts = sample_surface(&crate::testing::freeform(0.3), 1.5).unwrap();
        assert!(sample_surface(&crate::testing::plane(1e5), 0.01).is_none());
        assert!(pts.len() > 4000);
        let grid = PointGrid::new(pts.clone(), 4.0);
        for (lo, hi) in [
            (Vec3::new(10.0, 10.0, -20.0), Vec3::new(17.0, 23.0, 20.0)),
            (Vec3::new(-5.0, 90.0, 0.0), Vec3::new(3.0, 130.0, 1.0)),
            (Vec3::new(40.0, 40.0, 100.0), Vec3::new(50.0, 50.0, 120.0)),
        ] {
            let inside = |p: &Vec3| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
            let want = pts.iter().filter(|p| inside(p)).count();
            let mut got = 0;
            grid.visit_box(&lo, &hi, |p| {
                got += usize::from(inside(p));
                true
            });
            assert_eq!(got, want);
        }
    }
}

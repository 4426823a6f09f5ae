//! The part of a surface's parameter plane that a trimmed face covers: its boundary loops as
//! closed polygons in (u, v), with a point-in-region test. The STEP reader builds it from a
//! face's loops (`step::Face::uv_region`); the strategies keep their contact points in it and
//! the verification judges only the surface inside it.
//!
//! Inside means the even–odd rule (a point is in the face when a ray from it crosses the loops
//! an odd number of times; Foley et al., *Computer Graphics*, §2.1.3): it needs no loop
//! orientation, so an outer loop and its holes are told apart by nesting alone (writers such as
//! OpenCascade mark no loop as the outer one). The crossings are counted only against the
//! edges of the point's horizontal band of an edge index, so a test costs a few edges, not all.

/// Horizontal bands of the edge index, per loop vertex (at least one band).
const BANDS_PER_VERTEX: f64 = 0.25;

/// A point this fraction of the region's extent from a loop counts as inside: a contact
/// point on the trim curve itself (a boundary pass runs along it) belongs to the face.
pub const BOUNDARY_SLACK: f64 = 1e-9;

/// A face's (u, v) region: the points inside an odd number of its loops.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceRegion {
    loops: Vec<Vec<(f64, f64)>>,
    /// Every loop edge as (loop, index of its first vertex).
    bands: Vec<Vec<(usize, usize)>>,
    v0: f64,
    band_height: f64,
    u_range: (f64, f64),
    v_range: (f64, f64),
    slack: f64,
}

/// Where a parameter rectangle lies against a region ([`FaceRegion::classify`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RectSide {
    Inside,
    Outside,
    /// A loop crosses it: part in, part out.
    Across,
}

/// Why loops do not make a region.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegionError {
    #[error("a loop has {0} points; a closed polygon needs at least 3")]
    TooFewPoints(usize),
    #[error("a loop point is not finite")]
    NotFinite,
    #[error("the loops enclose no area")]
    Empty,
}

impl FaceRegion {
    /// The region of closed polygons in (u, v) (each without its first point repeated).
    pub fn new(loops: Vec<Vec<(f64, f64)>>) -> Result<FaceRegion, RegionError> {
        if loops.is_empty() {
            return Err(RegionError::Empty);
        }
        for l in &loops {
            if l.len() < 3 {
                return Err(RegionError::TooFewPoints(l.len()));
            }
            if !l.iter().all(|p| p.0.is_finite() && p.1.is_finite()) {
                return Err(RegionError::NotFinite);
            }
        }
        let points = || loops.iter().flatten();
        let u_range = points().fold((f64::INFINITY, f64::NEG_INFINITY), |r, p| {
            (r.0.min(p.0), r.1.max(p.0))
        });
        let v_range = points().fold((f64::INFINITY, f64::NEG_INFINITY), |r, p| {
            (r.0.min(p.1), r.1.max(p.1))
        });
        let extent = (u_range.1 - u_range.0).max(v_range.1 - v_range.0);
        if extent.is_nan() || extent <= 0.0 {
            return Err(RegionError::Empty);
        }
        let vertices: usize = loops.iter().map(Vec::len).sum();
        let count = ((vertices as f64 * BANDS_PER_VERTEX).ceil() as usize).max(1);
        let band_height = (v_range.1 - v_range.0).max(f64::MIN_POSITIVE) / count as f64;
        let mut region = FaceRegion {
            loops,
            bands: vec![Vec::new(); count],
            v0: v_range.0,
            band_height,
            u_range,
            v_range,
            slack: BOUNDARY_SLACK * extent,
        };
        for (l, poly) in region.loops.iter().enumerate() {
            for i in 0..poly.len() {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                let (lo, hi) = region.band_span(a.1.min(b.1), a.1.max(b.1));
                for band in &mut region.bands[lo..=hi] {
                    band.push((l, i));
                }
            }
        }
        if region.area() <= 0.0 {
            return Err(RegionError::Empty);
        }
        Ok(region)
    }

    /// The loops, as given.
    pub fn loops(&self) -> &[Vec<(f64, f64)>] {
        &self.loops
    }

    /// The (u, v) box of the loops.
    pub fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        (self.u_range, self.v_range)
    }

    /// The region's (u, v) box within the parameter ranges `u` and `v` (a surface's domain or
    /// a part of it); `None` when they do not meet.
    pub fn clip_box(&self, u: (f64, f64), v: (f64, f64)) -> Option<((f64, f64), (f64, f64))> {
        let (cu, cv) = (
            (u.0.max(self.u_range.0), u.1.min(self.u_range.1)),
            (v.0.max(self.v_range.0), v.1.min(self.v_range.1)),
        );
        (cu.0 < cu.1 && cv.0 < cv.1).then_some((cu, cv))
    }

    /// True when (u, v) lies in the region or within [`BOUNDARY_SLACK`] of its boundary.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let s = self.slack;
        if u < self.u_range.0 - s
            || u > self.u_range.1 + s
            || v < self.v_range.0 - s
            || v > self.v_range.1 + s
        {
            return false;
        }
        let (lo, hi) = self.band_span(v - s, v + s);
        let mut near = false;
        for band in &self.bands[lo..=hi] {
            near |= band
                .iter()
                .any(|&(l, i)| segment_distance(self.edge(l, i), (u, v)) <= s);
        }
        if near {
            return true;
        }
        let (band, _) = self.band_span(v, v);
        let crossings = self.bands[band]
            .iter()
            .filter(|&&(l, i)| crosses_right(self.edge(l, i), (u, v)))
            .count();
        crossings % 2 == 1
    }

    /// Where the parameter rectangle `[u0, u1] × [v0, v1]` lies: wholly in the region, wholly
    /// out of it, or across its boundary (a loop edge meets the rectangle, grown by the
    /// boundary slack). The gouge checks use it to skip the parts of a trimmed face's surface
    /// that are not the face.
    pub fn classify(&self, [u0, u1, v0, v1]: [f64; 4]) -> RectSide {
        let s = self.slack;
        let (lo, hi) = (u0 - s, u1 + s);
        let (blo, bhi) = (v0 - s, v1 + s);
        if hi < self.u_range.0
            || lo > self.u_range.1
            || bhi < self.v_range.0
            || blo > self.v_range.1
        {
            return RectSide::Outside;
        }
        let (first, last) = self.band_span(blo, bhi);
        let crossed = self.bands[first..=last].iter().any(|band| {
            band.iter()
                .any(|&(l, i)| segment_meets_rect(self.edge(l, i), [lo, hi, blo, bhi]))
        });
        if crossed {
            RectSide::Across
        } else if self.contains(0.5 * (u0 + u1), 0.5 * (v0 + v1)) {
            RectSide::Inside
        } else {
            RectSide::Outside
        }
    }

    /// The region's area in the parameter plane: each loop's shoelace area, added for a loop
    /// nested in an even number of others (an outer boundary or an island) and taken away for
    /// an odd number (a hole).
    pub fn area(&self) -> f64 {
        self.loops
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let depth = self
                    .loops
                    .iter()
                    .enumerate()
                    .filter(|&(j, other)| j != k && inside_polygon(other, l[0]))
                    .count();
                let a = shoelace(l).abs();
                if depth % 2 == 0 {
                    a
                } else {
                    -a
                }
            })
            .sum()
    }

    fn edge(&self, l: usize, i: usize) -> ((f64, f64), (f64, f64)) {
        let poly = &self.loops[l];
        (poly[i], poly[(i + 1) % poly.len()])
    }

    /// The bands a v interval touches (clamped to the index).
    fn band_span(&self, lo: f64, hi: f64) -> (usize, usize) {
        let last = self.bands.len() - 1;
        let at = |v: f64| (((v - self.v0) / self.band_height).floor().max(0.0) as usize).min(last);
        (at(lo), at(hi))
    }
}

/// The area of `surface` over `region` (its whole domain for `None`), mm²: the midpoint rule
/// on a `samples` × `samples` grid over the region's box, `|S_u × S_v|` at the cells whose
/// centre is inside. A cell straddling the trim counts whole or not at all, so the error is
/// at most the trim's length times a cell's diagonal on the surface.
pub fn surface_area(
    surface: &tezgah_geom::NurbsSurface,
    region: Option<&FaceRegion>,
    samples: usize,
) -> f64 {
    let n = samples.max(1);
    let ((u0, u1), (v0, v1)) = match region {
        Some(r) => r.bounds(),
        None => (surface.domain_u(), surface.domain_v()),
    };
    let (du, dv) = ((u1 - u0) / n as f64, (v1 - v0) / n as f64);
    let mut area = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = (u0 + du * (i as f64 + 0.5), v0 + dv * (j as f64 + 0.5));
            if region.is_some_and(|r| !r.contains(u, v)) {
                continue;
            }
            let d = surface.derivs(u, v);
            area += d.su.cross(&d.sv).norm() * du * dv;
        }
    }
    area
}

/// True when the edge `a–b` crosses the ray from `p` toward +u (half-open in v, so a ray
/// through a vertex counts it once).
fn crosses_right((a, b): ((f64, f64), (f64, f64)), p: (f64, f64)) -> bool {
    if (a.1 > p.1) == (b.1 > p.1) {
        return false;
    }
    let u_at = a.0 + (p.1 - a.1) * (b.0 - a.0) / (b.1 - a.1);
    u_at > p.0
}

/// Even–odd test against one polygon (all its edges).
fn inside_polygon(poly: &[(f64, f64)], p: (f64, f64)) -> bool {
    (0..poly.len())
        .filter(|&i| crosses_right((poly[i], poly[(i + 1) % poly.len()]), p))
        .count()
        % 2
        == 1
}

/// Signed area of a closed polygon (positive counter-clockwise).
fn shoelace(poly: &[(f64, f64)]) -> f64 {
    0.5 * (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
}

/// True when the segment `a–b` meets the rectangle `[u0, u1] × [v0, v1]`: the segment
/// clipped to the rectangle's slabs in u and then in v (Liang & Barsky 1984) is not empty.
fn segment_meets_rect((a, b): ((f64, f64), (f64, f64)), [u0, u1, v0, v1]: [f64; 4]) -> bool {
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, d, lo, hi) in [(a.0, b.0 - a.0, u0, u1), (a.1, b.1 - a.1, v0, v1)] {
        if d == 0.0 {
            if p < lo || p > hi {
                return false;
            }
            continue;
        }
        let (ta, tb) = ((lo - p) / d, (hi - p) / d);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Distance from `p` to the segment `a–b`.
fn segment_distance((a, b): ((f64, f64), (f64, f64)), p: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.0 - (a.0 + t * dx)).hypot(p.1 - (a.1 + t * dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(c: (f64, f64), r: f64, n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                (c.0 + r * a.cos(), c.1 + r * a.sin())
            })
            .collect()
    }

    #[test]
    fn a_square_with_a_round_hole_has_the_closed_form_area_and_membership() {
        let n = 4000;
        let outer = vec![(0.0, 0.0), (80.0, 0.0), (80.0, 60.0), (0.0, 60.0)];
        let region = FaceRegion::new(vec![outer, circle((25.0, 30.0), 10.0, n)]).unwrap();
        // The inscribed n-gon's area: n/2 r² sin(2π/n).
        let polygon = 0.5 * n as f64 * 100.0 * (std::f64::consts::TAU / n as f64).sin();
        assert!((region.area() - (4800.0 - polygon)).abs() < 1e-9);
        assert!((region.area() - (4800.0 - 100.0 * std::f64::consts::PI)).abs() < 1e-3);
        // Points on a lattice against the closed form (away from the boundary by more than
        // the polygon's sagitta r(1 − cos(π/n)) < 3.1e-6).
        let mut checked = 0;
        for i in 0..=160 {
            for j in 0..=120 {
                let (u, v) = (
                    -0.25 + 0.5 * i as f64 + 0.0137,
                    -0.25 + 0.5 * j as f64 + 0.0071,
                );
                let r = (u - 25.0).hypot(v - 30.0);
                if (r - 10.0).abs() < 1e-4 {
                    continue;
                }
                let want = (0.0..=80.0).contains(&u) && (0.0..=60.0).contains(&v) && r > 10.0;
                assert_eq!(region.contains(u, v), want, "({u}, {v})");
                checked += 1;
            }
        }
        assert!(checked > 19_000);
    }

    #[test]
    fn rectangles_are_classified_as_their_points_are() {
        // Random rectangles against a square with a round hole: `Inside` and `Outside` agree
        // with every point of a lattice over the rectangle, and `Across` has points of both
        // sides unless the boundary only grazes it.
        let region = FaceRegion::new(vec![
            vec![(0.0, 0.0), (80.0, 0.0), (80.0, 60.0), (0.0, 60.0)],
            circle((25.0, 30.0), 10.0, 400),
        ])
        .unwrap();
        let mut seed = 7_u64;
        let mut next = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut counts = [0; 3];
        for _ in 0..2000 {
            let (u, v) = (-10.0 + 100.0 * next(), -10.0 + 80.0 * next());
            let (w, h) = (0.01 + 8.0 * next(), 0.01 + 8.0 * next());
            let rect = [u, u + w, v, v + h];
            let side = region.classify(rect);
            let (mut ins, mut outs) = (0, 0);
            for i in 0..=12 {
                for j in 0..=12 {
                    let p = (u + w * i as f64 / 12.0, v + h * j as f64 / 12.0);
                    if region.contains(p.0, p.1) {
                        ins += 1;
                    } else {
                        outs += 1;
                    }
                }
            }
            match side {
                RectSide::Inside => assert_eq!(outs, 0, "{rect:?}"),
                RectSide::Outside => assert_eq!(ins, 0, "{rect:?}"),
                RectSide::Across => {}
            }
            if ins > 0 && outs > 0 {
                assert_eq!(side, RectSide::Across, "{rect:?}");
            }
            counts[side as usize] += 1;
        }
        assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
    }

    #[test]
    fn points_on_the_boundary_belong_to_the_region() {
        let region =
            FaceRegion::new(vec![vec![(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]]).unwrap();
        for p in [(0.0, 0.5), (2.0, 0.3), (1.0, 0.0), (1.3, 1.0), (2.0, 1.0)] {
            assert!(region.contains(p.0, p.1), "{p:?}");
        }
        assert!(!region.contains(2.0 + 1e-6, 0.5));
        assert!(!region.contains(1.0, -1e-6));
    }

    #[test]
    fn an_island_in_a_hole_counts_again() {
        let region = FaceRegion::new(vec![
            circle((0.0, 0.0), 10.0, 512),
            circle((0.0, 0.0), 5.0, 512),
            circle((0.0, 0.0), 2.0, 512),
        ])
        .unwrap();
        assert!(region.contains(0.0, 0.0));
        assert!(!region.contains(3.5, 0.0));
        assert!(region.contains(7.5, 0.0));
        assert!(!region.contains(11.0, 0.0));
        let pi = std::f64::consts::PI;
        assert!((region.area() - pi * (100.0 - 25.0 + 4.0)).abs() < 0.02);
    }

    #[test]
    fn degenerate_loops_are_refused() {
        assert_eq!(
            FaceRegion::new(vec![vec![(0.0, 0.0), (1.0, 0.0)]]),
            Err(RegionError::TooFewPoints(2))
        );
        assert_eq!(
            FaceRegion::new(vec![vec![(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]]),
            Err(RegionError::Empty)
        );
        assert_eq!(
            FaceRegion::new(vec![vec![(0.0, 0.0), (f64::NAN, 0.0), (2.0, 1.0)]]),
            Err(RegionError::NotFinite)
        );
        assert_eq!(FaceRegion::new(vec![]), Err(RegionError::Empty));
    }
}

//! Point inversion on a NURBS surface (Piegl & Tiller §6.1): the surface point nearest to a
//! given point, by a bounding-box search over the knot-span pieces and a damped, projected
//! Newton iteration inside each — what CC-point projection and gouge checks will call.

use super::{NurbsSurface, SurfaceError};
use crate::curve::Vec3;

/// Seeds per knot span and direction for [`NurbsSurface::closest_point`].
pub const CLOSEST_SEEDS_PER_SPAN: usize = 8;
/// Newton iterations allowed per cell to [`NurbsSurface::closest_point`] (it converges
/// quadratically; the cap only bounds the work on a pathological surface).
const CLOSEST_MAX_ITERATIONS: usize = 50;

/// The foot of the perpendicular from a point to the surface: parameters, point and distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoint {
    pub u: f64,
    pub v: f64,
    pub point: Vec3,
    pub distance: f64,
}

impl NurbsSurface {
    /// The surface point closest to `q` (P&T §6.1, point inversion), searched piece by
    /// piece: every knot-span cell lies in the bounding box of its `(p+1)(q+1)` control points
    /// (convex hull property, weights > 0), so cells are visited nearest box first and the
    /// search ends when the next box is farther than the best point found. In a cell, Newton
    /// on `f = (S − q)·S_u = 0`, `g = (S − q)·S_v = 0` (eq. 6.6) starts from every seed of a
    /// `(`[`CLOSEST_SEEDS_PER_SPAN`]` + 1)²` lattice that is no farther than its neighbours; the
    /// parameters stay in the cell (a crease along a knot line is a cell edge, not a trap),
    /// an edge that the descent direction points out of holds its parameter (projected
    /// Newton), and each step is halved until the distance drops. A cell search stops when a
    /// step moves the point by at most `tolerance` (mm) or cannot lower the distance. The
    /// result is a local minimum, and the global one when the seeds resolve each piece's
    /// valleys (a wild piece folding between seeds can still hide a nearer point).
    pub fn closest_point(&self, q: &Vec3, tolerance: f64) -> Result<ClosestPoint, SurfaceError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(SurfaceError::Tolerance(tolerance));
        }
        if !q.iter().all(|c| c.is_finite()) {
            return Err(SurfaceError::QueryNotFinite);
        }
        let (p, dq) = (self.u.degree, self.v.degree);
        let mut cells = Vec::new();
        for su in (self.u.first..=self.u.last).filter(|&s| self.u.knots[s] < self.u.knots[s + 1]) {
            for sv in
                (self.v.first..=self.v.last).filter(|&s| self.v.knots[s] < self.v.knots[s + 1])
            {
                let (mut lo, mut hi) =
                    (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
                for i in su - p..=su {
                    for j in sv - dq..=sv {
                        let c = self.cw(i, j);
                        let pt = Vec3::new(c.x, c.y, c.z) / c.w;
                        lo = lo.inf(&pt);
                        hi = hi.sup(&pt);
                    }
                }
                let gap = (lo - q).sup(&(q - hi)).sup(&Vec3::zeros());
                cells.push((gap.norm(), su, sv));
            }
        }
        cells.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (u0, v0) = (self.u.domain().0, self.v.domain().0);
        let start = self.point(u0, v0);
        let mut best = ClosestPoint {
            u: u0,
            v: v0,
            point: start,
            distance: (start - q).norm(),
        };
        for (bound, su, sv) in cells {
            if bound >= best.distance {
                break;
            }
            let c = self.closest_in_cell(q, su, sv, tolerance);
            if c.distance < best.distance {
                best = c;
            }
        }
        Ok(best)
    }

    /// [`NurbsSurface::closest_point`] confined to the piece of knot spans `(su, sv)`: Newton
    /// from every seed that is no farther than its lattice neighbours (a discrete local
    /// minimum), so a piece with several valleys toward `q` has each of them searched.
    fn closest_in_cell(&self, q: &Vec3, su: usize, sv: usize, tolerance: f64) -> ClosestPoint {
        let (u0, u1) = (self.u.knots[su], self.u.knots[su + 1]);
        let (v0, v1) = (self.v.knots[sv], self.v.knots[sv + 1]);
        let k = CLOSEST_SEEDS_PER_SPAN;
        let at = |a: usize, b: usize| {
            let tu = u0 + (u1 - u0) * a as f64 / k as f64;
            let tv = v0 + (v1 - v0) * b as f64 / k as f64;
            (tu, tv)
        };
        let mut e = vec![0.0; (k + 1) * (k + 1)];
        for a in 0..=k {
            for b in 0..=k {
                let (tu, tv) = at(a, b);
                e[a * (k + 1) + b] = (self.point_at(su, sv, tu, tv) - q).norm_squared();
            }
        }
        let mut best: Option<ClosestPoint> = None;
        for a in 0..=k {
            for b in 0..=k {
                let here = e[a * (k + 1) + b];
                let valley = (a.saturating_sub(1)..=(a + 1).min(k)).all(|x| {
                    (b.saturating_sub(1)..=(b + 1).min(k)).all(|y| e[x * (k + 1) + y] >= here)
                });
                if !valley {
                    continue;
                }
                let (tu, tv) = at(a, b);
                let c = self.newton_in_cell(q, su, sv, (tu, tv, here), tolerance);
                if best.is_none_or(|b| c.distance < b.distance) {
                    best = Some(c);
                }
            }
        }
        // The lattice's smallest value is always a valley, so `best` is set; the fallback
        // (the cell corner) only keeps this total.
        best.unwrap_or_else(|| {
            let point = self.point_at(su, sv, u0, v0);
            ClosestPoint {
                u: u0,
                v: v0,
                point,
                distance: (point - q).norm(),
            }
        })
    }

    /// Damped Newton on eq. 6.6 inside the cell `(su, sv)` from the seed `(u, v, |S − q|²)`.
    fn newton_in_cell(
        &self,
        q: &Vec3,
        su: usize,
        sv: usize,
        (mut u, mut v, mut d2): (f64, f64, f64),
        tolerance: f64,
    ) -> ClosestPoint {
        let (u0, u1) = (self.u.knots[su], self.u.knots[su + 1]);
        let (v0, v1) = (self.v.knots[sv], self.v.knots[sv + 1]);
        for _ in 0..CLOSEST_MAX_ITERATIONS {
            let d = self.derivs_at(su, sv, u, v);
            let r = d.point - q;
            let (f, g) = (r.dot(&d.su), r.dot(&d.sv));
            let j00 = d.su.norm_squared() + r.dot(&d.suu);
            let j01 = d.su.dot(&d.sv) + r.dot(&d.suv);
            let j11 = d.sv.norm_squared() + r.dot(&d.svv);
            let det = j00 * j11 - j01 * j01;
            let newton = j00 > 0.0 && det > 0.0;
            let (mut du, mut dv) = if newton {
                ((g * j01 - f * j11) / det, (f * j01 - g * j00) / det)
            } else {
                // Not a minimum's neighbourhood: descend along the scaled gradient instead.
                let (a, b) = (d.su.norm_squared(), d.sv.norm_squared());
                (
                    if a > 0.0 { -f / a } else { 0.0 },
                    if b > 0.0 { -g / b } else { 0.0 },
                )
            };
            // On a cell edge where the descent direction −(f, g) points out, the edge holds
            // that parameter and the step becomes the 1-D one along the other (projected
            // Newton); held on both, the corner is a minimum (the KKT conditions hold).
            let (u_held, v_held) = (
                (u == u0 && f > 0.0) || (u == u1 && f < 0.0),
                (v == v0 && g > 0.0) || (v == v1 && g < 0.0),
            );
            let along = |grad: f64, curv: f64, speed2: f64| {
                if curv > 0.0 {
                    -grad / curv
                } else if speed2 > 0.0 {
                    -grad / speed2
                } else {
                    0.0
                }
            };
            match (u_held, v_held) {
                (true, true) => break,
                (true, false) => (du, dv) = (0.0, along(g, j11, d.sv.norm_squared())),
                (false, true) => (du, dv) = (along(f, j00, d.su.norm_squared()), 0.0),
                (false, false) => {}
            }
            if !(du.is_finite() && dv.is_finite()) {
                break;
            }
            // Near a minimum |S − q|² is flat to rounding (more so near a centre of
            // curvature), so a Newton step is also taken when the distance holds within its
            // rounding and the residual (f, g) falls: that keeps quadratic convergence in u, v.
            let residual = f.hypot(g);
            let slack = 8.0 * f64::EPSILON * (d.point.norm() + q.norm()) * d2.sqrt();
            let mut step = None;
            for _ in 0..60 {
                let (nu, nv) = ((u + du).clamp(u0, u1), (v + dv).clamp(v0, v1));
                let n = self.derivs_at(su, sv, nu, nv);
                let r = n.point - q;
                let e = r.norm_squared();
                let falls = || r.dot(&n.su).hypot(r.dot(&n.sv)) < residual;
                if e < d2 || (newton && e <= d2 + slack && falls()) {
                    step = Some((d.su * (nu - u) + d.sv * (nv - v)).norm());
                    (u, v, d2) = (nu, nv, e.min(d2));
                    break;
                }
                du *= 0.5;
                dv *= 0.5;
            }
            match step {
                Some(moved) if moved > tolerance => {}
                _ => break,
            }
        }
        let point = self.point_at(su, sv, u, v);
        ClosestPoint {
            u,
            v,
            point,
            distance: (point - q).norm(),
        }
    }
}

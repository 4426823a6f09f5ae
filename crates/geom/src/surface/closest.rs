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
/// A parameter this fraction of its cell's width from an edge counts as on the edge.
const EDGE_SNAP: f64 = 1e-9;

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
        let mut best_cell = (self.u.first, self.v.first);
        let visits = cells.len();
        for (bound, su, sv) in cells {
            if bound >= best.distance {
                break;
            }
            let c = self.closest_in_cell(q, su, sv, tolerance);
            if c.distance < best.distance {
                best = c;
                best_cell = (su, sv);
            }
        }
        Ok(self.continue_across_knots(q, best, best_cell, tolerance, visits))
    }

    /// A cell's search can end held on one of its edges with the descent pointing out of the
    /// cell; where that edge is an interior knot line and not the domain's boundary, the
    /// surface goes on and so does the descent: Newton is resumed in the neighbouring cell
    /// from that point (a narrow valley the neighbour's seed lattice did not resolve is found
    /// this way). Each resumption lowers the distance, and there are at most `visits` of them.
    fn continue_across_knots(
        &self,
        q: &Vec3,
        mut best: ClosestPoint,
        (mut su, mut sv): (usize, usize),
        tolerance: f64,
        visits: usize,
    ) -> ClosestPoint {
        for _ in 0..visits {
            let d = self.derivs_at(su, sv, best.u, best.v);
            let r = d.point - q;
            let next_u = self.u.span_across(su, best.u, r.dot(&d.su));
            let next_v = self.v.span_across(sv, best.v, r.dot(&d.sv));
            if next_u.is_none() && next_v.is_none() {
                break;
            }
            let (nu, nv) = (next_u.unwrap_or(su), next_v.unwrap_or(sv));
            let seed = (best.u, best.v, best.distance * best.distance);
            let c = self.newton_in_cell(q, nu, nv, seed, tolerance);
            if c.distance >= best.distance {
                break;
            }
            (best, su, sv) = (c, nu, nv);
        }
        best
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
                saddle_free_step(&d.su, &d.sv, [j00, j01, j11], f, g)
            };
            // On a cell edge where the descent direction −(f, g) points out, the edge holds
            // that parameter and the step becomes the 1-D one along the other (projected
            // Newton); held on both, the corner is a minimum (the KKT conditions hold). A
            // parameter within rounding of the edge is on it: a step that lands 1e-14 inside
            // would otherwise be clamped back at once and halved to nothing, ending the search
            // before it has slid along the edge.
            let (eu, ev) = (EDGE_SNAP * (u1 - u0), EDGE_SNAP * (v1 - v0));
            let (u_held, v_held) = (
                (u - u0 <= eu && f > 0.0) || (u1 - u <= eu && f < 0.0),
                (v - v0 <= ev && g > 0.0) || (v1 - v <= ev && g < 0.0),
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

/// The descent step where the Hessian `[j00 j01; j01 j11]` of `|S − q|²/2` is not positive
/// definite (a saddle of the distance: the point is beyond a centre of curvature in one
/// direction): the saddle-free Newton step (Dauphin et al. 2014), each eigen-direction of the
/// Hessian taken with the magnitude of its curvature, so that the negative one is descended
/// rather than climbed. The eigenproblem is the generalised one `H v = λ M v` against the
/// first fundamental form `M = [E F; F G]`: on a surface `H = M + (S − q)·S''`, so the `λ`
/// are `1 − d κᵢ` (`κᵢ` the principal curvatures toward `q`), dimensionless, and floored at
/// [`SADDLE_FLOOR`] where a direction is nearly flat. A Gauss–Newton or per-parameter step
/// zig-zags down the curved valley such a saddle region makes and can spend the iteration
/// budget short of the minimum. A degenerate metric (a pole) falls back to the
/// per-parameter scaling.
fn saddle_free_step(su: &Vec3, sv: &Vec3, [h00, h01, h11]: [f64; 3], f: f64, g: f64) -> (f64, f64) {
    let (e, ff, gg) = (su.norm_squared(), su.dot(sv), sv.norm_squared());
    let det_m = e * gg - ff * ff;
    if det_m <= 1e-12 * e * gg {
        return (
            if e > 0.0 { -f / e } else { 0.0 },
            if gg > 0.0 { -g / gg } else { 0.0 },
        );
    }
    // det(H − λM) = det_m λ² − b λ + det_h = 0.
    let b = h00 * gg + h11 * e - 2.0 * h01 * ff;
    let det_h = h00 * h11 - h01 * h01;
    let root = (b * b - 4.0 * det_m * det_h).max(0.0).sqrt();
    let mut step = (0.0, 0.0);
    for lambda in [(b - root) / (2.0 * det_m), (b + root) / (2.0 * det_m)] {
        // (H − λM) v = 0: v is orthogonal to the larger of the matrix's two rows.
        let r0 = (h00 - lambda * e, h01 - lambda * ff);
        let r1 = (h01 - lambda * ff, h11 - lambda * gg);
        let row = if r0.0.hypot(r0.1) >= r1.0.hypot(r1.1) {
            r0
        } else {
            r1
        };
        let (mut a, mut c) = (-row.1, row.0);
        if a == 0.0 && c == 0.0 {
            // H is a multiple of M: any direction is an eigen-direction; take the
            // M-orthogonal pair u and its complement.
            (a, c) = if step == (0.0, 0.0) {
                (1.0, 0.0)
            } else {
                (-ff, e)
            };
        }
        let m_norm2 = a * a * e + 2.0 * a * c * ff + c * c * gg;
        let slope = f * a + g * c;
        let scale = slope / (m_norm2 * lambda.abs().max(SADDLE_FLOOR));
        step = (step.0 - scale * a, step.1 - scale * c);
    }
    step
}

/// The smallest curvature magnitude, relative to the metric, [`saddle_free_step`] divides by:
/// a nearly flat direction gets at most this many times a Gauss–Newton step.
const SADDLE_FLOOR: f64 = 0.05;

impl super::Direction {
    /// The knot span beyond span `s`'s edge that the parameter `t` sits on (within
    /// [`EDGE_SNAP`] of its width), when the slope `grad` of the distance along this
    /// direction descends across that edge and the edge is not the end of the domain.
    fn span_across(&self, s: usize, t: f64, grad: f64) -> Option<usize> {
        let (t0, t1) = (self.knots[s], self.knots[s + 1]);
        let snap = EDGE_SNAP * (t1 - t0);
        if t1 - t <= snap && grad < 0.0 {
            (s + 1..=self.last).find(|&k| self.knots[k] < self.knots[k + 1])
        } else if t - t0 <= snap && grad > 0.0 {
            (self.first..s)
                .rev()
                .find(|&k| self.knots[k] < self.knots[k + 1])
        } else {
            None
        }
    }
}

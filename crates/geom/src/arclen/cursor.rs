//! The forward arc-length cursor: [`ArcLengthMap::advance`] is the map's `u(s)` for samples
//! that move forward along the curve (the interpolator's). An [`ArcLengthCursor`] remembers the
//! last `(u, s)`; the next `s(u)` is that `s` plus 8-point Gauss–Legendre over `[u_prev, u]`, a
//! sub-interval of an accepted panel (so at least as accurate as `u_at`'s quadrature from the
//! panel start), re-anchored at the table's `(u_k, s_k)` whenever a panel is entered, so
//! quadrature errors never accumulate past one panel. The Newton step solves the cubic Taylor
//! model of `s(u)`; it is accepted when the model's last term is below half the Newton
//! tolerance (the same a-posteriori test as `u_at`'s, one order higher), and the tiny model
//! residual is carried in the cursor's `s`.
//!
//! Fast path: on entering a panel the cursor takes `|C'|` at the panel's eight Gauss–Legendre
//! nodes (the values the map's quadrature sums) and keeps their degree-7 interpolant in the
//! Legendre basis, `v(x) ≈ Σ a_j P_j(x)` on `u = m + h·x`: Gauss's discrete orthogonality gives
//! `a_j = (2j+1)/2 · Σ w_i v_i P_j(x_i)` exactly (Trefethen, *Approximation Theory and
//! Approximation Practice*, ch. 19; Davis & Rabinowitz, *Methods of Numerical Integration*,
//! §2.7). Its integral `S(x) = s_k + h·Σ a_j ∫P_j`, with `∫_{-1}^x P_j = (P_{j+1} − P_{j−1})/(2j+1)`,
//! is a polynomial `s(u)` on the panel that equals the table at both ends (`S(1)` is the
//! panel's Gauss–Legendre value). It is checked once against the map, twice over: the
//! interpolant's leading speed error is ∝ `P_8`, largest at the panel's ends, where the table
//! holds the true speeds — that error times the panel's width must be within half the Newton
//! tolerance; and the leading arc-length error `∝ ∫P_8 = (P_9 − P_7)/17` is largest at the
//! innermost Gauss nodes (it vanishes at the middle), so `s` is taken there by the map's
//! quadrature and `S` must be within the Newton tolerance of it (a hundredth of the map's
//! tolerance: the margin for the terms the checks do not see). A sample on an accepted panel is
//! then a Newton solve of `S(x) = s` on the polynomial (no curve evaluation) and one `C(u)`;
//! other panels (a heavy weight, a fast-changing speed) keep the quadrature and Newton below.
//! Like the map's own bound, the checks are a-posteriori (module `arclen`).
//!
//! Sits between the map and the interpolator (`tezgah-motion`'s `interpolate::Param`).

use super::{gauss_legendre, ArcLengthMap, GL_W, GL_X};
use crate::curve::{clamp_param, Curve, Vec3};

/// Largest final Newton step, as a part of the panel's width, for which [`ArcLengthMap::advance`]
/// takes `C(u)` from the Taylor series at the previous iterate.
const TAYLOR_STEP: f64 = 1e-4;

/// Where the last [`ArcLengthMap::advance`] ended: the panel, the parameter and its arc
/// length, and the speed and its rate there for the next guess. Start with
/// [`ArcLengthMap::cursor`]; any `s` may follow any other (going back re-anchors). A cursor
/// belongs to the map that made it: on another map nothing panics, but the answers mean nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcLengthCursor {
    panel: usize,
    u: f64,
    s: f64,
    /// `|C'(u)|`.
    speed: f64,
    /// `d|C'|/du` at `u` (0 when unknown: a first-order guess); on a panel with an accepted
    /// polynomial, `ds/dx` of the polynomial at the last answer instead.
    speed_rate: f64,
    /// The panel's checked inverse, once the panel has been entered.
    inverse: PanelInverse,
}

/// The cursor's panel's polynomial `s(u)`, as checked on entry.
#[derive(Debug, Clone, Copy, PartialEq)]
enum PanelInverse {
    /// Not checked yet.
    Unchecked,
    /// Failed the check (or not finite): quadrature and Newton.
    Rejected,
    /// `u = mid + half·x`; `s(x) − s_k = Σ c_i·xⁱ` (module documentation).
    Legendre { mid: f64, half: f64, c: [f64; 9] },
}

/// Coefficients of `xⁱ` in the Legendre polynomials `P_0 … P_8` (Bonnet's recurrence).
const fn legendre_monomials() -> [[f64; 9]; 9] {
    let mut p = [[0.0; 9]; 9];
    p[0][0] = 1.0;
    p[1][1] = 1.0;
    let mut n = 1;
    while n < 8 {
        let nf = n as f64;
        let mut i = 0;
        while i < 9 {
            let shifted = if i > 0 { p[n][i - 1] } else { 0.0 };
            p[n + 1][i] = ((2.0 * nf + 1.0) * shifted - nf * p[n - 1][i]) / (nf + 1.0);
            i += 1;
        }
        n += 1;
    }
    p
}

/// `K[i][k]`: the coefficient of `xⁱ` in `∫_{-1}^x v / h` per unit moment `m_k = ½Σ w v xᵏ`
/// of the node speeds: `b_j = Σ_k P_j[k]·m_k` and `∫_{-1}^x Σ a_j P_j = b_0·(x+1) +
/// Σ_{j≥1} b_j·(P_{j+1} − P_{j−1})`, `b_j = a_j/(2j+1)` (module documentation).
const MOMENTS_TO_INTEGRAL: [[f64; 8]; 9] = {
    let p = legendre_monomials();
    let mut k = [[0.0; 8]; 9];
    let mut m = 0;
    while m < 8 {
        k[0][m] += p[0][m];
        k[1][m] += p[0][m];
        let mut j = 1;
        while j < 8 {
            let mut i = 0;
            while i < 9 {
                k[i][m] += p[j][m] * (p[j + 1][i] - p[j - 1][i]);
                i += 1;
            }
            j += 1;
        }
        m += 1;
    }
    k
};

/// `Σ c_i·xⁱ` and its first two derivatives, by Horner.
#[inline]
fn horner(c: &[f64; 9], x: f64) -> [f64; 3] {
    let (mut f, mut d, mut dd) = (c[8], 0.0, 0.0);
    for &ci in c[..8].iter().rev() {
        dd = dd * x + d;
        d = d * x + f;
        f = f * x + ci;
    }
    [f, d, 2.0 * dd]
}

/// A point found by [`ArcLengthMap::advance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcPosition {
    /// Curve parameter.
    pub u: f64,
    /// `C(u)`.
    pub point: Vec3,
}

impl ArcLengthMap {
    /// A cursor at the start of the curve, for [`Self::advance`].
    pub fn cursor(&self) -> ArcLengthCursor {
        self.anchor(0)
    }

    /// A cursor at the start of the panel holding arc length `s` (clamped): for a caller that
    /// starts part-way along the curve (a trimmed piece of it), found by bisection of the
    /// table, where [`Self::advance`] from [`Self::cursor`] would walk every panel before it.
    pub fn cursor_at(&self, s: f64) -> ArcLengthCursor {
        let n = self.panels();
        if n == 0 {
            return self.anchor(0);
        }
        let k = self.s.partition_point(|&x| x <= s).clamp(1, n) - 1;
        self.anchor(k)
    }

    fn anchor(&self, k: usize) -> ArcLengthCursor {
        ArcLengthCursor {
            panel: k,
            u: self.u[k],
            s: self.s[k],
            speed: self.speed[k],
            speed_rate: 0.0,
            inverse: PanelInverse::Unchecked,
        }
    }

    /// The Legendre `s(u)` of panel `k`, if it passes both checks against the map (module
    /// documentation).
    fn panel_inverse<C: Curve + ?Sized>(&self, curve: &C, k: usize) -> PanelInverse {
        let (ua, ub) = (self.u[k], self.u[k + 1]);
        let (mid, half) = (0.5 * (ua + ub), 0.5 * (ub - ua));
        // Moments m_k = ½Σ w v xᵏ over the symmetric node pairs ±x.
        let mut moments = [0.0; 8];
        let speeds = curve.gauss_speeds(ua, ub);
        for ((&x, &w), v) in GL_X.iter().zip(GL_W.iter()).zip(speeds.chunks_exact(2)) {
            let (vm, vp) = (v[0], v[1]);
            let (even, odd) = (0.5 * w * (vp + vm), 0.5 * w * (vp - vm));
            let mut xk = 1.0;
            for pair in moments.chunks_exact_mut(2) {
                pair[0] += even * xk;
                pair[1] += odd * xk * x;
                xk *= x * x;
            }
        }
        let mut c = [0.0; 9];
        for (ci, row) in c.iter_mut().zip(MOMENTS_TO_INTEGRAL.iter()) {
            *ci = half
                * row
                    .iter()
                    .zip(moments.iter())
                    .map(|(k, m)| k * m)
                    .sum::<f64>();
        }
        // The interpolant's speed error is ∝ P_8(x) to leading order, largest at the panel's
        // ends, where the table holds the true speeds: at most that error over the whole
        // panel width bounds the leading term of the arc-length error anywhere.
        let end_error = [(-1.0, self.speed[k]), (1.0, self.speed[k + 1])]
            .map(|(x, v)| (horner(&c, x)[1] / half - v).abs())
            .into_iter()
            .fold(0.0, f64::max);
        // And the whole error, all orders, at the innermost node, where the leading term of
        // the integral, ∝ P_9 − P_7, is largest: against the map's quadrature.
        let xc = -GL_X[0];
        let sc = gauss_legendre(curve, ua, mid + half * xc);
        let ok = 2.0 * (ub - ua) * end_error <= self.newton_tolerance
            && (horner(&c, xc)[0] - sc).abs() <= self.newton_tolerance;
        if ok && c.iter().all(|v| v.is_finite()) {
            PanelInverse::Legendre { mid, half, c }
        } else {
            PanelInverse::Rejected
        }
    }

    /// Solves `S(x) = s` on an accepted panel by Newton from the last answer, never behind
    /// it: `u` and `dS/dx` there; `None` when it does not settle (the caller falls back).
    fn solve_panel(
        &self,
        k: usize,
        (mid, half, c): (f64, f64, &[f64; 9]),
        cursor: &ArcLengthCursor,
        s: f64,
    ) -> Option<(f64, f64)> {
        let target = s - self.s[k];
        let xlo = (cursor.u - mid) / half;
        // From the last answer along the polynomial's slope there (zero right after
        // anchoring: then the linear guess over the panel).
        let mut x = if cursor.speed_rate > 0.0 {
            xlo + (s - cursor.s) / cursor.speed_rate
        } else {
            -1.0 + 2.0 * target / (self.s[k + 1] - self.s[k])
        };
        let tolerance = 0.01 * self.newton_tolerance;
        for _ in 0..8 {
            x = x.clamp(xlo.max(-1.0), 1.0);
            let [f, slope, curl] = horner(c, x);
            let f = f - target;
            if f.abs() <= tolerance {
                return Some(((mid + half * x).clamp(cursor.u, self.u[k + 1]), slope));
            }
            // A non-positive or NaN slope: no Newton step (the caller falls back).
            if slope.is_nan() || slope <= 0.0 {
                return None;
            }
            let step = f / slope;
            x -= step;
            // After the step the residual is S''·δ²/2 to third order (as in `u_at`): when that
            // is far inside the tolerance, the evaluation that would confirm it is skipped.
            if (curl * step * step).abs() <= tolerance && x > xlo.max(-1.0) && x < 1.0 {
                let slope = slope - curl * step;
                return Some(((mid + half * x).clamp(cursor.u, self.u[k + 1]), slope));
            }
        }
        None
    }

    /// The point at arc length `s` (clamped to `[0, length]`), from the cursor's last place:
    /// `u` and `C(u)` for the same `u` as [`Self::u_at`] to within the map's bound (module
    /// documentation): on a panel whose polynomial passed its checks, a Newton solve on it and
    /// one `C(u)`; elsewhere about one quadrature and one derivative evaluation per call when
    /// `s` moves forward by less than a panel. There `C(u)` comes from the same evaluation as the
    /// Newton step: the Taylor series to third order about the last iterate when the step δ is
    /// at most 1e-4 of the panel's width `w` — exact for curves of degree ≤ 3, off by
    /// `|C⁗|·δ⁴/24 ≤ 4e-18·|C⁗|·w⁴` otherwise (a fourth difference over the panel, below
    /// rounding) — else a separate evaluation.
    pub fn advance<C: Curve + ?Sized>(
        &self,
        curve: &C,
        cursor: &mut ArcLengthCursor,
        s: f64,
    ) -> ArcPosition {
        let n = self.panels();
        if n == 0 {
            let u = self.u[0];
            return ArcPosition {
                u,
                point: curve.point(u),
            };
        }
        let s = clamp_param(s, 0.0, self.length());
        // The end is the table's last entry, as `u_at` finds it; searched for, its root would
        // sit on the bracket's end (so would a panel's end: that is the next panel's start).
        if s >= self.length() {
            *cursor = self.anchor(n - 1);
            let u = self.u[n];
            return ArcPosition {
                u,
                point: curve.point(u),
            };
        }
        // Stay on the cursor's panel when `s` is ahead of it and before the panel's end; else
        // re-anchor at the start of the panel holding `s` (forward walk when ahead), where
        // `s` equal to the start is the table's `u` exactly.
        let k = cursor.panel.min(n - 1);
        if !(s >= cursor.s && s < self.s[k + 1] && cursor.panel < n) {
            let k = if s >= cursor.s && cursor.panel < n {
                let mut k = k;
                while k + 1 < n && self.s[k + 1] <= s {
                    k += 1;
                }
                k
            } else {
                self.s.partition_point(|&x| x <= s).clamp(1, n) - 1
            };
            *cursor = self.anchor(k);
        }
        let k = cursor.panel;
        let (ua, sa) = (cursor.u, cursor.s);
        let (mut lo, mut hi) = (ua, self.u[k + 1]);
        if self.s[k + 1] - self.s[k] <= 0.0 || s <= sa {
            return ArcPosition {
                u: ua,
                point: curve.point(ua),
            };
        }
        if cursor.inverse == PanelInverse::Unchecked {
            cursor.inverse = self.panel_inverse(curve, k);
        }
        // By reference: the polynomial is most of the cursor, and this runs per sample.
        let solved = match &cursor.inverse {
            PanelInverse::Legendre { mid, half, c } => {
                Some(self.solve_panel(k, (*mid, *half, c), cursor, s))
            }
            _ => None,
        };
        match solved {
            Some(Some((u, slope))) => {
                cursor.u = u;
                cursor.s = s;
                cursor.speed_rate = slope;
                return ArcPosition {
                    u,
                    point: curve.point(u),
                };
            }
            Some(None) => {
                // Not settled: this panel keeps the quadrature from the table's start.
                *cursor = self.anchor(k);
                cursor.inverse = PanelInverse::Rejected;
                return self.advance(curve, cursor, s);
            }
            None => {}
        }
        // Second-order inverse series u(s) about the cursor: u' = 1/v, u'' = −v'/v³.
        let ds = s - sa;
        let (v0, r0) = (cursor.speed, cursor.speed_rate);
        let mut u = if v0 > 0.0 {
            ua + ds / v0 - r0 * ds * ds / (2.0 * v0 * v0 * v0)
        } else {
            ua + (hi - ua) * ds / (self.s[k + 1] - sa)
        };
        if !(u > lo && u < hi) {
            u = ua + (hi - ua) * ds / (self.s[k + 1] - sa);
        }
        for _ in 0..60 {
            let integral = gauss_legendre(curve, ua, u);
            let f = sa + integral - s;
            let [p, d1, d2, d3] = curve.derivs(u);
            let v = d1.norm();
            // F = s(u) − s: F' = v, F'' = v' = C'·C''/v, F''' = v'' = (|C''|² + C'·C''' − v'²)/v.
            let (v1, v2) = if v > 0.0 {
                let v1 = d1.dot(&d2) / v;
                (v1, (d2.norm_squared() + d1.dot(&d3) - v1 * v1) / v)
            } else {
                (0.0, 0.0)
            };
            if f.abs() <= self.newton_tolerance {
                *cursor = ArcLengthCursor {
                    panel: k,
                    u,
                    s: sa + integral,
                    speed: v,
                    speed_rate: v1,
                    inverse: PanelInverse::Rejected,
                };
                return ArcPosition { u, point: p };
            }
            if f > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            if hi - lo <= f64::EPSILON * (ua.abs() + self.u[k + 1].abs()) || v <= 0.0 {
                break;
            }
            // Root of the cubic model f + v·δ + v'·δ²/2 + v''·δ³/6 by Newton from −f/v.
            let model = |d: f64| f + d * (v + d * (0.5 * v1 + d * v2 / 6.0));
            let mut d = -f / v;
            for _ in 0..3 {
                let slope = v + d * (v1 + 0.5 * d * v2);
                // Past a turning point of the model (or NaN): keep the last root estimate.
                if slope.is_nan() || slope <= 0.0 {
                    break;
                }
                d -= model(d) / slope;
            }
            let next = u + d;
            if !(next > lo && next < hi && d.is_finite()) {
                u = 0.5 * (lo + hi);
                continue;
            }
            // The model's remainder is about its next term; when the last kept term is far
            // inside the tolerance, the quadrature that would confirm the step is skipped.
            if (v2 * d * d * d / 6.0).abs() <= 0.5 * self.newton_tolerance {
                *cursor = ArcLengthCursor {
                    panel: k,
                    u: next,
                    s: s + model(d),
                    speed: v + d * (v1 + 0.5 * d * v2),
                    speed_rate: v1 + d * v2,
                    inverse: PanelInverse::Rejected,
                };
                // C(next) from the derivatives already at hand (exact to third order) when
                // the step is a small part of the panel; else one more evaluation.
                let point = if d.abs() <= TAYLOR_STEP * (self.u[k + 1] - self.u[k]) {
                    p + (d1 + (d2 + d3 * (d / 3.0)) * (d / 2.0)) * d
                } else {
                    curve.point(next)
                };
                return ArcPosition { u: next, point };
            }
            u = next;
        }
        // Bracket collapsed (or no progress): the bracket's point, re-anchored next time.
        *cursor = self.anchor(k);
        cursor.inverse = PanelInverse::Rejected;
        cursor.u = u;
        cursor.s = sa + gauss_legendre(curve, ua, u);
        cursor.speed = curve.speed(u);
        ArcPosition {
            u,
            point: curve.point(u),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Nurbs;

    /// Runs the cursor forward in `steps` equal steps; every answer is checked against an
    /// independent fine map (within the map's tolerance of the true arc length) and `C(u)`.
    /// Returns how many panels the cursor entered and how many of them took the polynomial path.
    fn sweep(c: &Nurbs, tol: f64, steps: usize) -> (usize, usize) {
        let m = ArcLengthMap::new(c, tol).unwrap();
        let fine = ArcLengthMap::new(c, tol * 1e-3).unwrap();
        let mut cur = m.cursor();
        let (mut entered, mut fast, mut panel) = (0, 0, usize::MAX);
        for i in 0..=steps {
            let s = m.length() * i as f64 / steps as f64;
            let at = m.advance(c, &mut cur, s);
            let back = fine.s_at(c, at.u);
            assert!((back - s).abs() <= tol, "s = {s}: true arc length {back}");
            assert!((at.point - c.point(at.u)).norm() <= 1e-12 * (1.0 + at.point.norm()));
            if cur.panel != panel && cur.inverse != PanelInverse::Unchecked {
                panel = cur.panel;
                entered += 1;
                fast += usize::from(matches!(cur.inverse, PanelInverse::Legendre { .. }));
            }
        }
        (entered, fast)
    }

    fn cubic(points: &[[f64; 3]], weights: &[f64]) -> Nurbs {
        let pts: Vec<Vec3> = points.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        let n = pts.len();
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|i| i as f64));
        knots.extend([(n - 3) as f64; 4]);
        Nurbs::new(3, &pts, weights, knots).unwrap()
    }

    /// A cursor started part-way (`cursor_at`, as the interpolator does on a trimmed part of a
    /// curve whose map was built over the whole) lands on the panel holding `s`, and gives the
    /// same answers as one run from the start, within the map's bound of the true arc length.
    #[test]
    fn cursor_at_starts_part_way() {
        let c = cubic(
            &[
                [0.0, 0.0, 0.0],
                [0.3, 0.05, 0.01],
                [0.5, 0.4, 0.0],
                [1.2, 0.5, -0.02],
                [1.3, 1.1, 0.0],
                [2.0, 1.0, 0.03],
            ],
            &[1.0; 6],
        );
        let tol = 1e-9;
        let m = ArcLengthMap::new(&c, tol).unwrap();
        let fine = ArcLengthMap::new(&c, tol * 1e-3).unwrap();
        let len = m.length();
        for start in [0.0, 0.1, 0.37, 0.5, 0.91].map(|f| f * len) {
            let mut cur = m.cursor_at(start);
            assert!(m.s[cur.panel] <= start && start < m.s[cur.panel + 1]);
            let mut from_start = m.cursor();
            for i in 0..=200 {
                let s = start + (len - start) * i as f64 / 200.0;
                let at = m.advance(&c, &mut cur, s);
                let reference = m.advance(&c, &mut from_start, s);
                assert!((fine.s_at(&c, at.u) - s).abs() <= tol, "s = {s}");
                assert!((fine.s_at(&c, reference.u) - fine.s_at(&c, at.u)).abs() <= 2.0 * tol);
            }
        }
        // Past the end: the last panel.
        assert_eq!(m.cursor_at(2.0 * len).panel, m.panels() - 1);
    }

    /// A smooth, uneven-speed cubic like a compressed surfacing pass (mm, map tolerance 1e-9
    /// per mm as the interpolator asks): most panels take the checked Legendre inverse. (Nine
    /// in ten with 8 starting panels per knot span; since the map starts an evenly paced span
    /// with 2 (`Curve::speed_ratio`), its panels are longer and 16 of 24 pass here.)
    #[test]
    fn smooth_spline_takes_the_polynomial_inverse() {
        let c = cubic(
            &[
                [0.0, 0.0, 0.0],
                [0.3, 0.05, 0.01],
                [0.5, 0.4, 0.0],
                [1.2, 0.5, -0.02],
                [1.3, 1.1, 0.0],
                [2.0, 1.0, 0.03],
            ],
            &[1.0; 6],
        );
        let len = ArcLengthMap::new(&c, 1e-9).unwrap().length();
        let (entered, fast) = sweep(&c, 1e-9 * len.max(1.0), 4000);
        assert!(entered >= 8, "{entered} panels");
        assert!(fast * 3 >= entered * 2, "{fast} of {entered} panels fast");
    }

    /// A cusp (`C' = 0` at u = 0.5) and a heavy weight (a speed that changes fast, which the
    /// degree-7 interpolant cannot follow on some panels: those fall back to quadrature and
    /// Newton): the answers stay within the bound everywhere.
    #[test]
    fn cusp_and_heavy_weight_fall_back() {
        let cusp = cubic(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
            ],
            &[1.0; 4],
        );
        // |C'| is |u − ½|-like: smooth on each panel (½ is a panel end), so the panels may
        // well be fast; the answers are checked against the fine map either way.
        sweep(&cusp, 1e-9, 3000);
        let heavy = cubic(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 2.0, 0.0],
                [2.0, -1.0, 1.0],
                [3.0, 0.0, 0.0],
            ],
            &[1.0, 400.0, 0.02, 1.0],
        );
        let (entered, fast) = sweep(&heavy, 1e-9, 3000);
        assert!(fast < entered, "{fast} of {entered} panels fast");
    }

    /// Closed form: `C(u) = (f(u), 0, 0)` with `f` a monotone cubic has speed `f'(u)`, a
    /// polynomial the degree-7 interpolant holds exactly, so `s(u) = f(u) − f(0)` and every
    /// panel is fast; the cursor's `u` gives back `s` to the solve's tolerance.
    #[test]
    fn polynomial_speed_is_inverted_exactly() {
        let c = cubic(
            &[
                [0.0, 0.0, 0.0],
                [0.1, 0.0, 0.0],
                [1.5, 0.0, 0.0],
                [2.0, 0.0, 0.0],
            ],
            &[1.0; 4],
        );
        let m = ArcLengthMap::new(&c, 1e-9).unwrap();
        let mut cur = m.cursor();
        let (mut entered, mut fast, mut panel) = (0, 0, usize::MAX);
        for i in 0..=1000 {
            let s = 2.0 * i as f64 / 1000.0;
            let at = m.advance(&c, &mut cur, s);
            // Within the polynomial solve's own tolerance (a hundredth of the Newton one).
            assert!(
                (at.point.x - s).abs() <= 2e-13,
                "s = {s}: x = {}",
                at.point.x
            );
            if cur.panel != panel {
                panel = cur.panel;
                entered += 1;
                fast += usize::from(matches!(cur.inverse, PanelInverse::Legendre { .. }));
            }
        }
        assert!(entered >= 8);
        // The last panel is answered from the table at s = length (no polynomial built).
        assert!(fast + 1 >= entered, "{fast} of {entered} panels fast");
    }
}

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
//! Sits between the map and the interpolator (`tezgah-motion`'s `interpolate::Param`).

use super::{gauss_legendre, ArcLengthMap};
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
    /// `d|C'|/du` at `u` (0 when unknown: a first-order guess).
    speed_rate: f64,
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

    fn anchor(&self, k: usize) -> ArcLengthCursor {
        ArcLengthCursor {
            panel: k,
            u: self.u[k],
            s: self.s[k],
            speed: self.speed[k],
            speed_rate: 0.0,
        }
    }

    /// The point at arc length `s` (clamped to `[0, length]`), from the cursor's last place:
    /// `u` and `C(u)` for the same `u` as [`Self::u_at`] to within the map's bound (module
    /// documentation), at about one quadrature and one derivative evaluation per call when
    /// `s` moves forward by less than a panel. `C(u)` comes from the same evaluation as the
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
        cursor.u = u;
        cursor.s = sa + gauss_legendre(curve, ua, u);
        cursor.speed = curve.speed(u);
        ArcPosition {
            u,
            point: curve.point(u),
        }
    }
}

//! The quintic corner blend of Kahraman et al. (§3, eqs 4–6): a degree-5 polynomial in local
//! time `τ` in `[0, T]` that matches position, velocity and acceleration at both ends, so a
//! blended junction is C² in time. The path builder places one at every blended corner.

use crate::bezier::Bezier;
use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

/// Boundary state of a blend end: position, velocity, acceleration (mm, mm/s, mm/s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    pub p: Vec3,
    pub v: Vec3,
    pub a: Vec3,
}

/// `P(τ) = a τ⁵ + b τ⁴ + c τ³ + d τ² + e τ + f`, `τ` in `[0, T]`. Derivatives are time
/// derivatives, so `derivs` gives position, velocity, acceleration and jerk directly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quintic {
    /// Coefficients from `τ⁰` (f) to `τ⁵` (a).
    coef: [Vec3; 6],
    duration: f64,
}

impl Quintic {
    /// The unique quintic with the given end states over `duration` seconds (Kahraman et
    /// al., §3; checked against coefficients worked out by hand in `tests/closed_forms.rs`).
    pub fn hermite(start: State, end: State, duration: f64) -> Result<Self, CurveError> {
        let t = duration;
        if !(t.is_finite() && t > 0.0) {
            return Err(CurveError::Duration(t));
        }
        let vals = [start.p, start.v, start.a, end.p, end.v, end.a];
        if !vals.iter().flat_map(|v| v.iter()).all(|c| c.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        let (p0, v0, a0, p1, v1, a1) = (start.p, start.v, start.a, end.p, end.v, end.a);
        let (t2, t3) = (t * t, t * t * t);
        let c = ((p1 - p0) * 20.0 - (v1 * 8.0 + v0 * 12.0) * t - (a0 * 3.0 - a1) * t2) / (2.0 * t3);
        let b = ((p0 - p1) * 30.0 + (v1 * 14.0 + v0 * 16.0) * t + (a0 * 3.0 - a1 * 2.0) * t2)
            / (2.0 * t3 * t);
        let a = ((p1 - p0) * 12.0 - (v1 + v0) * 6.0 * t - (a0 - a1) * t2) / (2.0 * t3 * t2);
        Ok(Quintic {
            coef: [p0, v0, a0 * 0.5, c, b, a],
            duration: t,
        })
    }

    /// Coefficients `[f, e, d, c, b, a]` (from `τ⁰` to `τ⁵`).
    pub fn coefficients(&self) -> [Vec3; 6] {
        self.coef
    }
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The same curve as a degree-5 Bézier on `[0, 1]` (`u = τ / T`).
    pub fn to_bezier(&self) -> Bezier {
        // Power basis in u: coefficient k scales by T^k; then the power-to-Bernstein map
        // b_i = Σ_{k≤i} C(i,k)/C(5,k) m_k.
        let mut m = self.coef;
        let mut f = 1.0;
        for c in m.iter_mut() {
            *c *= f;
            f *= self.duration;
        }
        let binom = |n: usize, k: usize| -> f64 {
            (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
        };
        let pts = (0..6)
            .map(|i| {
                (0..=i).fold(Vec3::zeros(), |acc, k| {
                    acc + m[k] * (binom(i, k) / binom(5, k))
                })
            })
            .collect();
        Bezier::from_finite(pts)
    }
}

impl Curve for Quintic {
    fn domain(&self) -> (f64, f64) {
        (0.0, self.duration)
    }
    fn derivs(&self, tau: f64) -> [Vec3; 4] {
        let t = clamp_param(tau, 0.0, self.duration);
        let c = &self.coef;
        // Horner for the polynomial and its first three derivatives.
        let p = ((((c[5] * t + c[4]) * t + c[3]) * t + c[2]) * t + c[1]) * t + c[0];
        let v = (((c[5] * 5.0 * t + c[4] * 4.0) * t + c[3] * 3.0) * t + c[2] * 2.0) * t + c[1];
        let a = ((c[5] * 20.0 * t + c[4] * 12.0) * t + c[3] * 6.0) * t + c[2] * 2.0;
        let j = (c[5] * 60.0 * t + c[4] * 24.0) * t + c[3] * 6.0;
        [p, v, a, j]
    }
}

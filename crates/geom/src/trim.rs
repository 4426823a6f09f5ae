//! A piece of any curve: `[u0, u1]` of its domain. Corner blending trims the segments either
//! side of a junction back to the blend's end points; this keeps the original curve (and its
//! exact parameterisation) instead of re-fitting it.

use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

/// The sub-curve `u` in `[u0, u1]` of `curve`, with the same parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Trimmed<C> {
    curve: C,
    u0: f64,
    u1: f64,
}

impl<C: Curve> Trimmed<C> {
    /// `u0 <= u1`, both finite; they are clamped into the curve's domain.
    pub fn new(curve: C, u0: f64, u1: f64) -> Result<Self, CurveError> {
        if !(u0.is_finite() && u1.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        if u0 > u1 {
            return Err(CurveError::EmptyDomain);
        }
        let (a, b) = curve.domain();
        Ok(Trimmed {
            u0: u0.clamp(a, b),
            u1: u1.clamp(a, b),
            curve,
        })
    }

    /// The untrimmed curve.
    pub fn inner(&self) -> &C {
        &self.curve
    }
}

impl<C: Curve> Curve for Trimmed<C> {
    fn domain(&self) -> (f64, f64) {
        (self.u0, self.u1)
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        self.curve.derivs(clamp_param(u, self.u0, self.u1))
    }
    fn point(&self, u: f64) -> Vec3 {
        self.curve.point(clamp_param(u, self.u0, self.u1))
    }
    fn d1(&self, u: f64) -> Vec3 {
        self.curve.d1(clamp_param(u, self.u0, self.u1))
    }
    fn speed_integral(&self, a: f64, b: f64) -> f64 {
        // Inside the trimmed domain no node is clamped: the inner curve's own rule applies.
        if a >= self.u0 && b <= self.u1 && a <= b {
            self.curve.speed_integral(a, b)
        } else {
            crate::arclen::gauss_legendre_8(|u| self.speed(u), a, b)
        }
    }
    fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
        if a >= self.u0 && b <= self.u1 && a <= b {
            self.curve.gauss_speeds(a, b)
        } else {
            crate::arclen::gauss_nodes_8(|u| self.speed(u), a, b)
        }
    }
    fn breakpoints(&self) -> Vec<f64> {
        let mut out = vec![self.u0];
        out.extend(
            self.curve
                .breakpoints()
                .into_iter()
                .filter(|&b| b > self.u0 && b < self.u1),
        );
        out.push(self.u1);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arc::Arc;
    use crate::line::Line;

    #[test]
    fn trimmed_lengths_add_up() {
        let a = Arc::new(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), Vec3::z(), 3.0, 1.0).unwrap();
        let (l, r) = (
            Trimmed::new(a, 0.0, 0.4).unwrap(),
            Trimmed::new(a, 0.4, 1.0).unwrap(),
        );
        assert!((l.length() + r.length() - a.length()).abs() < 1e-9);
        assert!((l.length() - 0.4 * a.length()).abs() < 1e-9);
        let line = Line::new(Vec3::zeros(), Vec3::x() * 10.0).unwrap();
        let t = Trimmed::new(line, 2.0, 20.0).unwrap();
        assert_eq!(t.domain(), (2.0, 10.0));
        assert_eq!(t.length(), 8.0);
        assert!(Trimmed::new(line, 3.0, 1.0).is_err());
    }
}

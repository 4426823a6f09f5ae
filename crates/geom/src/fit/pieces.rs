//! A polynomial B-spline of degree ≤ 3 re-expressed per knot span in Taylor (power) form, for
//! the fitter's many deviation samples: Horner on 4 coefficients instead of basis functions
//! (about 10× cheaper). Exact up to rounding, since each span is one cubic polynomial.

use crate::curve::{clamp_param, Curve, Vec3};
use crate::nurbs::Nurbs;

pub(crate) struct Pieces {
    /// Span starts, then the domain end.
    starts: Vec<f64>,
    /// `C(a), C'(a), C''(a)/2, C'''(a)/6` at each span start `a` (right-hand derivatives).
    coef: Vec<[Vec3; 4]>,
}

impl Pieces {
    /// `None` for rational curves or degree above 3 (not a cubic per span).
    pub(crate) fn new(c: &Nurbs) -> Option<Self> {
        if c.degree() > 3 || c.weights().iter().any(|&w| w != 1.0) {
            return None;
        }
        let starts = c.breakpoints();
        let coef = starts[..starts.len() - 1]
            .iter()
            .map(|&a| {
                let [p, d1, d2, d3] = c.derivs(a);
                [p, d1, d2 * 0.5, d3 * (1.0 / 6.0)]
            })
            .collect();
        Some(Pieces { starts, coef })
    }

    fn locate(&self, u: f64) -> (usize, f64) {
        let n = self.coef.len();
        let u = clamp_param(u, self.starts[0], self.starts[n]);
        let k = self.starts.partition_point(|&x| x <= u).clamp(1, n) - 1;
        (k, u - self.starts[k])
    }
}

impl Curve for Pieces {
    fn domain(&self) -> (f64, f64) {
        (self.starts[0], self.starts[self.coef.len()])
    }
    fn point(&self, u: f64) -> Vec3 {
        let (k, h) = self.locate(u);
        let c = &self.coef[k];
        ((c[3] * h + c[2]) * h + c[1]) * h + c[0]
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        let (k, h) = self.locate(u);
        let c = &self.coef[k];
        [
            ((c[3] * h + c[2]) * h + c[1]) * h + c[0],
            (c[3] * (3.0 * h) + c[2] * 2.0) * h + c[1],
            c[3] * (6.0 * h) + c[2] * 2.0,
            c[3] * 6.0,
        ]
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.starts.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_bspline() {
        let pts: Vec<Vec3> = (0..7)
            .map(|i| Vec3::new(i as f64, ((i * 5) % 3) as f64, (i % 2) as f64))
            .collect();
        let knots = vec![0., 0., 0., 0., 0.2, 0.5, 0.7, 1., 1., 1., 1.];
        let c = Nurbs::bspline(3, &pts, knots).unwrap();
        let p = Pieces::new(&c).unwrap();
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let (a, b) = (c.derivs(u), p.derivs(u));
            for k in 0..4 {
                assert!((a[k] - b[k]).norm() < 1e-10, "u={u} k={k}");
            }
        }
    }
}

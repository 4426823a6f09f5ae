//! Global interpolation (Piegl & Tiller A9.1): the B-spline of degree `p` through every data
//! point, with parameters from [`Parameterisation`] and averaged knots (uniform knots for the
//! universal method). The thesis's G05.1 fit; exact at the points, unbounded between them.

use super::params::{averaged_knots, check_points, parameters, uniform_knots, Parameterisation};
use crate::banded::Banded;
use crate::basis::{basis_funs, find_span, W};
use crate::curve::Vec3;
use crate::error::CurveError;
use crate::nurbs::Nurbs;

/// The degree-`p` B-spline through `points` (at least `p + 1`, consecutive ones distinct),
/// passing through point `k` at parameter `t_k`. Returns the curve and the parameters.
pub fn interpolate(
    points: &[Vec3],
    p: usize,
    method: Parameterisation,
) -> Result<(Nurbs, Vec<f64>), CurveError> {
    if p == 0 || p > crate::basis::MAX_DEGREE {
        return Err(CurveError::Degree {
            degree: p,
            max: crate::basis::MAX_DEGREE,
        });
    }
    check_points(points, p, p + 1)?;
    let t = parameters(points, method, p)?;
    let m = points.len() - 1;
    let knots = match method {
        Parameterisation::Universal => uniform_knots(m, p),
        _ => averaged_knots(&t, p)?,
    };
    // Row k of the collocation matrix has its non-zeros in columns span−p..=span; find the
    // band first, then fill.
    let spans: Vec<usize> = t.iter().map(|&u| find_span(&knots, p, m, u)).collect();
    let (mut kl, mut ku) = (0, 0);
    for (k, &s) in spans.iter().enumerate() {
        kl = kl.max(k.saturating_sub(s - p));
        ku = ku.max(s.saturating_sub(k));
    }
    let mut a = Banded::new(m + 1, kl, ku);
    let mut n = [0.0; W];
    for (k, (&u, &s)) in t.iter().zip(&spans).enumerate() {
        basis_funs(&knots, s, u, p, &mut n);
        for (j, v) in n[..=p].iter().enumerate() {
            a.add(k, s - p + j, *v);
        }
    }
    let mut ctrl = points.to_vec();
    a.solve(&mut ctrl)?;
    // The end rows are exactly (1, 0, …) and (…, 0, 1); pin them against rounding.
    ctrl[0] = points[0];
    ctrl[m] = points[m];
    Ok((Nurbs::bspline(p, &ctrl, knots)?, t))
}

//! Bézier curves of any degree as a [`Curve`], on `u` in `[0, 1]`: the general form of the
//! corner micro-splines the path builder inserts (a quintic blend converts to one with
//! [`crate::quintic::Quintic::to_bezier`]). Evaluation by de Casteljau on the hodographs.

use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

/// `C(u) = Σ B_{i,n}(u) P_i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Bezier {
    /// Control points of the curve and of its first three hodographs (derivative curves);
    /// a hodograph of a degree below its order is empty (that derivative is zero).
    hodo: [Vec<Vec3>; 4],
}

/// One derivative of a Bézier's control polygon: `n (P_{i+1} − P_i)`.
fn hodograph(p: &[Vec3]) -> Vec<Vec3> {
    let n = p.len().saturating_sub(1) as f64;
    p.windows(2).map(|w| (w[1] - w[0]) * n).collect()
}

/// de Casteljau's algorithm; the empty polygon is the zero curve.
fn de_casteljau(p: &[Vec3], u: f64, scratch: &mut Vec<Vec3>) -> Vec3 {
    if p.is_empty() {
        return Vec3::zeros();
    }
    scratch.clear();
    scratch.extend_from_slice(p);
    for r in 1..p.len() {
        for i in 0..p.len() - r {
            scratch[i] = scratch[i] * (1.0 - u) + scratch[i + 1] * u;
        }
    }
    scratch[0]
}

impl Bezier {
    /// A Bézier curve through its control polygon (at least two points, all finite).
    pub fn new(points: Vec<Vec3>) -> Result<Self, CurveError> {
        if points.len() < 2 {
            return Err(CurveError::TooFewPoints {
                points: points.len(),
                degree: points.len().saturating_sub(1),
                need: 2,
            });
        }
        if !points.iter().flat_map(|p| p.iter()).all(|c| c.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        Ok(Bezier::from_finite(points))
    }

    /// For callers that already hold at least two finite points.
    pub(crate) fn from_finite(points: Vec<Vec3>) -> Bezier {
        let h1 = hodograph(&points);
        let h2 = hodograph(&h1);
        let h3 = hodograph(&h2);
        Bezier {
            hodo: [points, h1, h2, h3],
        }
    }

    pub fn degree(&self) -> usize {
        self.hodo[0].len() - 1
    }
    pub fn control_points(&self) -> &[Vec3] {
        &self.hodo[0]
    }
}

impl Curve for Bezier {
    fn domain(&self) -> (f64, f64) {
        (0.0, 1.0)
    }
    fn point(&self, u: f64) -> Vec3 {
        let mut s = Vec::with_capacity(self.hodo[0].len());
        de_casteljau(&self.hodo[0], clamp_param(u, 0.0, 1.0), &mut s)
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        let u = clamp_param(u, 0.0, 1.0);
        let mut s = Vec::with_capacity(self.hodo[0].len());
        let mut out = [Vec3::zeros(); 4];
        for (o, h) in out.iter_mut().zip(self.hodo.iter()) {
            *o = de_casteljau(h, u, &mut s);
        }
        out
    }
}

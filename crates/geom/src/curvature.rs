//! Local curvature maxima of a curve: where the feed planner must slow down (Kelekçi,
//! 2021, §3.3.1, eq. 3.33, splits a NURBS at the maxima above a threshold and limits the feed there
//! by `√(A/κ)` and `(J/κ²)^(1/3)`). Dense sampling per knot span plus golden-section refinement.

use crate::curve::Curve;
use crate::deviation::maximise;

/// A local maximum of curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvaturePeak {
    pub u: f64,
    /// 1/mm.
    pub curvature: f64,
}

/// Interior local maxima of `κ(u)`, in order of `u`, found with `samples` samples per knot span
/// (each refined to ~1e-13 of its bracket). A maximum must be separated from its neighbours by
/// a dip that the sampling resolves; plateaus (lines, arcs) report none.
pub fn curvature_peaks<C: Curve + ?Sized>(curve: &C, samples: usize) -> Vec<CurvaturePeak> {
    let n = samples.max(4);
    let bps = curve.breakpoints();
    let mut us = Vec::with_capacity(n * bps.len());
    for w in bps.windows(2) {
        let h = (w[1] - w[0]) / n as f64;
        us.extend((0..n).map(|i| w[0] + h * i as f64));
    }
    us.push(*bps.last().unwrap_or(&curve.domain().1));
    let k: Vec<f64> = us.iter().map(|&u| curve.curvature(u)).collect();
    let mut out: Vec<CurvaturePeak> = Vec::new();
    for i in 1..k.len().saturating_sub(1) {
        // Rises below rounding (a constant-curvature piece) are no peaks.
        let eps = 1e-12 * k[i].abs();
        if k[i] > k[i - 1] + eps && k[i] + eps >= k[i + 1] {
            let d = maximise(|u| curve.curvature(u), us[i - 1], us[i + 1], 2);
            let peak = CurvaturePeak {
                u: d.u,
                curvature: d.distance,
            };
            // Two samples can climb the same peak from either side of a flat top.
            match out.last_mut() {
                Some(last) if (last.u - peak.u).abs() <= 1e-9 * (1.0 + peak.u.abs()) => {
                    if peak.curvature > last.curvature {
                        *last = peak;
                    }
                }
                _ => out.push(peak),
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arc::Arc;
    use crate::curve::Vec3;

    #[test]
    fn an_arc_has_no_peak() {
        let a = Arc::new(Vec3::zeros(), Vec3::x(), Vec3::z(), 2.0, 0.0).unwrap();
        assert!(curvature_peaks(&a, 32).is_empty());
    }
}

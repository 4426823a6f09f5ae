//! Forward step by the true chord error: where to put the next cutter-contact point along a
//! curve on the surface so that the straight move between two contact points stays within
//! the tolerance of the curve everywhere between them. Every strategy steps its passes here.
//!
//! Can (2010, §3.4.3.1) tests one mid-point per chord, which cannot see an inflection: on the
//! boundary curve of the thesis's own STEP surface it lets 0.424 mm through at ε = 0.05 mm. Here
//! the deviation of a chord is measured as the maximum distance from the curve to the segment over
//! [`CHORD_SAMPLES`] interior samples, refined by golden-section search around every local
//! maximum among them (`tezgah_geom::deviation::maximise`), so both humps of an S-shaped span
//! are seen; the step is then grown or shrunk by the
//! `ε ∝ Δt²` law until the error lies in `[ε/2, ε]` (or the span ends or reaches the length
//! cap).

use tezgah_geom::deviation::{maximise, point_segment_distance};
use tezgah_geom::{NurbsSurface, Vec3};

use crate::error::CamError;

/// Interior samples per chord for the deviation measurement.
pub const CHORD_SAMPLES: usize = 16;
/// Trials allowed for one forward step before the search is declared stalled.
const MAX_TRIALS: usize = 60;
/// Contact points allowed on one path.
pub const MAX_POINTS: usize = 1_000_000;

/// A curve on the surface: `t ↦ (u, v)` over `[start, end]`.
pub trait SurfacePath {
    fn range(&self) -> (f64, f64);
    fn uv(&self, t: f64) -> (f64, f64);
}

/// The u- or v-iso-parametric line: `t ↦ (fixed, t)` or `(t, fixed)` over `[start, end]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsoLine {
    pub fixed: f64,
    /// `true`: `u` is fixed and `t` runs along `v`.
    pub along_v: bool,
    pub start: f64,
    pub end: f64,
}

impl SurfacePath for IsoLine {
    fn range(&self) -> (f64, f64) {
        (self.start, self.end)
    }
    fn uv(&self, t: f64) -> (f64, f64) {
        if self.along_v {
            (self.fixed, t)
        } else {
            (t, self.fixed)
        }
    }
}

/// A polyline in the parameter plane, `t ∈ [0, points − 1]`, linear between the points.
#[derive(Debug, Clone, PartialEq)]
pub struct UvPolyline {
    pub points: Vec<(f64, f64)>,
}

impl SurfacePath for UvPolyline {
    fn range(&self) -> (f64, f64) {
        (0.0, self.points.len().saturating_sub(1) as f64)
    }
    fn uv(&self, t: f64) -> (f64, f64) {
        let Some(&first) = self.points.first() else {
            return (0.0, 0.0);
        };
        if t.is_nan() {
            return first;
        }
        let last = self.points.len() - 1;
        let t = t.clamp(0.0, last as f64);
        let i = (t.floor() as usize).min(last.saturating_sub(1));
        let s = t - i as f64;
        let (a, b) = (self.points[i], self.points[(i + 1).min(last)]);
        (a.0 + (b.0 - a.0) * s, a.1 + (b.1 - a.1) * s)
    }
}

fn at(surface: &NurbsSurface, path: &impl SurfacePath, t: f64) -> Vec3 {
    let (u, v) = path.uv(t);
    surface.point(u, v)
}

/// The true chord error of the move from the point at `ta` to the point at `tb`: the largest
/// distance from the curve between them to the straight segment (module comment).
pub fn chord_error(surface: &NurbsSurface, path: &impl SurfacePath, ta: f64, tb: f64) -> f64 {
    let (a, b) = (at(surface, path, ta), at(surface, path, tb));
    let dist = |t: f64| point_segment_distance(&at(surface, path, t), &a, &b);
    // geom's maximiser refines around every local peak among the samples, not only the
    // highest: of an S-shaped span's two humps the lower-sampled one may be the taller.
    maximise(dist, ta, tb, CHORD_SAMPLES + 1).distance
}

/// The chord of a circle of radius `rho` whose sagitta is `eps`: `λ = 2√(2ρε − ε²)` (Can,
/// 2010, Eq. 3.22; Choi 1991) — the forward step on a path of constant curvature.
pub fn chord_for_sagitta(rho: f64, eps: f64) -> f64 {
    2.0 * (2.0 * rho * eps - eps * eps).max(0.0).sqrt()
}

/// Contact-point parameters along `path` from its start to its end such that every chord's
/// [`chord_error`] is at most `tolerance` and every chord is at most `max_step` long (mm).
/// Both ends are included. `first_guess` is the parameter step to try first (e.g. the last
/// pass's typical step); `None` starts from an eighth of the range.
pub fn forward_steps(
    surface: &NurbsSurface,
    path: &impl SurfacePath,
    tolerance: f64,
    max_step: f64,
    first_guess: Option<f64>,
) -> Result<Vec<f64>, CamError> {
    crate::error::positive("tolerance", tolerance)?;
    crate::error::positive("max_step", max_step)?;
    let (t0, t1) = path.range();
    let mut ts = vec![t0];
    if !(t0.is_finite() && t1.is_finite()) || t1 <= t0 {
        return Ok(ts);
    }
    let span = t1 - t0;
    let mut dt = first_guess.filter(|d| *d > 0.0).unwrap_or(span / 8.0);
    let mut t = t0;
    while t < t1 {
        let start = at(surface, path, t);
        let mut trial = dt.min(t1 - t);
        let mut good: Option<f64> = None;
        let mut bad = f64::INFINITY;
        let mut last_error = 0.0;
        for _ in 0..MAX_TRIALS {
            let err = chord_error(surface, path, t, t + trial);
            let len = (at(surface, path, t + trial) - start).norm();
            last_error = err;
            let fits = err <= tolerance && len <= max_step;
            if fits {
                good = Some(good.map_or(trial, |g: f64| g.max(trial)));
                let full = t + trial >= t1 || err >= 0.5 * tolerance || len >= 0.5 * max_step;
                if full || bad <= trial * 1.05 {
                    break;
                }
            } else {
                bad = bad.min(trial);
            }
            // ε ∝ Δt² and length ∝ Δt: aim at 0.8 of whichever limit binds.
            let by_error = if err > 0.0 {
                (0.8 * tolerance / err).sqrt()
            } else {
                4.0
            };
            let by_length = if len > 0.0 { 0.8 * max_step / len } else { 4.0 };
            let mut next = trial * by_error.min(by_length).clamp(0.1, 4.0);
            if let Some(g) = good {
                // Stay inside the bracket (good, bad) once it exists.
                if bad.is_finite() {
                    next = next.clamp(g, bad);
                    if next <= g * 1.02 || next >= bad * 0.98 {
                        next = 0.5 * (g + bad);
                    }
                }
            } else if next >= bad {
                next = 0.5 * bad;
            }
            trial = next.min(t1 - t);
            if trial <= span * 1e-12 {
                break;
            }
        }
        let Some(step) = good else {
            return Err(CamError::StepStalled {
                at: t,
                error: last_error,
            });
        };
        t = if t + step >= t1 { t1 } else { t + step };
        ts.push(t);
        if ts.len() > MAX_POINTS {
            return Err(CamError::TooLarge {
                what: "contact points on one pass",
                limit: MAX_POINTS,
            });
        }
        dt = step;
    }
    Ok(ts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing;

    /// The thesis's midpoint test (Can, 2010, §3.4.3.1), for the regression that shows its defect.
    fn midpoint_error(s: &NurbsSurface, path: &impl SurfacePath, ta: f64, tb: f64) -> f64 {
        let (a, b) = (at(s, path, ta), at(s, path, tb));
        point_segment_distance(&at(s, path, 0.5 * (ta + tb)), &a, &b)
    }

    fn dense_error(s: &NurbsSurface, path: &impl SurfacePath, ts: &[f64]) -> f64 {
        ts.windows(2)
            .map(|w| {
                let (a, b) = (at(s, path, w[0]), at(s, path, w[1]));
                (1..512)
                    .map(|k| {
                        let t = w[0] + (w[1] - w[0]) * k as f64 / 512.0;
                        point_segment_distance(&at(s, path, t), &a, &b)
                    })
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn boundary_curve_of_001_keeps_the_true_chord_error() {
        let s = testing::boundary_curve_001();
        let path = IsoLine {
            fixed: 0.0,
            along_v: true,
            start: 0.0,
            end: 1.0,
        };
        // Golden values of S(0, v), by Cox–de Boor on the thesis's STEP data (Appendix A).
        let golden = [
            (0.1, [12.973_465_610, 160.0, 0.257_625_035]),
            (0.25, [32.400_423_760, 160.0, -0.194_959_050]),
            (0.5, [64.716_606_570, 160.0, -2.609_006_400]),
            (0.75, [97.127_191_700, 160.0, -1.961_494_260]),
            (0.9, [116.543_372_760, 160.0, -0.833_556_840]),
            (1.0, [129.475_449_392, 160.0, 0.0]),
        ];
        for (v, p) in golden {
            let q = s.point(0.0, v);
            assert!((q - Vec3::from(p)).norm() < 2e-8, "v = {v}: {q:?}");
        }
        // The thesis's CC points at ε = 0.05 (Can, 2010, §3.4.3.1) pass its midpoint test within ±5
        // % but deviate by up to 0.424 mm; ours stay within ε.
        let thesis = [0.0, 0.1289, 0.5751, 0.6680, 0.8236, 1.0];
        let worst_mid = thesis
            .windows(2)
            .map(|w| midpoint_error(&s, &path, w[0], w[1]))
            .fold(0.0, f64::max);
        assert!(worst_mid < 0.06, "{worst_mid}");
        let true_dev = dense_error(&s, &path, &thesis);
        assert!((true_dev - 0.424).abs() < 0.005, "{true_dev}");
        for eps in [0.05, 0.02, 0.01] {
            let ts = forward_steps(&s, &path, eps, 1e3, None).unwrap();
            let dev = dense_error(&s, &path, &ts);
            println!(
                "001 boundary curve, ε = {eps}: {} points, true deviation {dev:.5}",
                ts.len()
            );
            assert!(dev <= eps * 1.0001, "ε = {eps}: {dev}");
            // Not wastefully dense either: the steps use at least half the tolerance.
            assert!(ts.len() < 40, "ε = {eps}: {} points", ts.len());
        }
    }

    #[test]
    fn chord_error_on_a_circle_is_the_sagitta() {
        // Can (2010), Eq. 3.22: ρ = 100, ε = 0.05 → λ = 6.3238 mm.
        assert!((chord_for_sagitta(100.0, 0.05) - 6.3238).abs() < 5e-5);
        // On a roller of radius 100 (an exact rational arc across u), two points a chord λ
        // apart deviate from the arc by exactly ε in the middle.
        let s = testing::cylinder(100.0, 10.0, true);
        let path = IsoLine {
            fixed: 0.5,
            along_v: false,
            start: 0.0,
            end: 1.0,
        };
        let a = at(&s, &path, 0.3);
        // Find tb with |P(tb) − P(0.3)| = λ by bisection.
        let lambda = chord_for_sagitta(100.0, 0.05);
        let (mut lo, mut hi) = (0.3, 1.0);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if (at(&s, &path, mid) - a).norm() < lambda {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let err = chord_error(&s, &path, 0.3, lo);
        assert!((err - 0.05).abs() < 1e-9, "{err}");
        assert!(forward_steps(&s, &path, f64::NAN, 1.0, None).is_err());
        assert!(forward_steps(&s, &path, 0.01, -1.0, None).is_err());
        assert_eq!(UvPolyline { points: vec![] }.uv(0.5), (0.0, 0.0));
    }

    #[test]
    fn length_cap_holds() {
        let s = testing::plane(100.0);
        let path = IsoLine {
            fixed: 0.5,
            along_v: true,
            start: 0.0,
            end: 1.0,
        };
        let ts = forward_steps(&s, &path, 0.01, 7.0, None).unwrap();
        for w in ts.windows(2) {
            let d = (at(&s, &path, w[1]) - at(&s, &path, w[0])).norm();
            assert!(d <= 7.0 + 1e-9 && d > 3.0, "{d}");
        }
        assert_eq!(*ts.last().unwrap(), 1.0);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]
        #[test]
        fn chord_error_within_tolerance_on_random_surfaces(
            seed in 0u64..1_000_000, eps in 0.002f64..0.1, fixed in 0.0f64..1.0, along_v: bool
        ) {
            let s = testing::random_bicubic(seed);
            let path = IsoLine { fixed, along_v, start: 0.0, end: 1.0 };
            let ts = forward_steps(&s, &path, eps, 50.0, None).unwrap();
            let dev = dense_error(&s, &path, &ts);
            proptest::prop_assert!(dev <= eps * 1.001, "{} > {}", dev, eps);
        }
    }
}

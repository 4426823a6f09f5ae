//! Deviation measures between a curve and the programmed path: the largest distance by dense
//! sampling plus local golden-section refinement. Used by the fitter to enforce its tolerance,
//! by tests, and later by `tezgah run`'s report (`max_deviation_mm`).

use crate::curve::{Curve, Vec3};

/// Samples per piece when the caller does not say: enough that the refinement starts in the
/// right basin for the curves tezgah builds (a piece turns by far less than a half circle).
pub const DEFAULT_SAMPLES: usize = 16;

/// Golden-section iterations: shrink the bracket (two sample spacings) by 0.618³² ≈ 2e-7;
/// near a smooth maximum the value error is quadratic in that.
const GOLDEN_ITERATIONS: usize = 32;

/// A distance and the curve parameter where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviation {
    pub distance: f64,
    pub u: f64,
}

/// Distance from `p` to the segment `a`–`b` (a point when `a = b`).
#[inline]
pub fn point_segment_distance(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    point_segment_distance_squared(p, a, b).sqrt()
}

/// The square of [`point_segment_distance`] (its root is that distance bit for bit): for
/// comparisons that need the root only when a candidate is near enough.
#[inline]
pub fn point_segment_distance_squared(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm_squared()
}

/// Distance from `p` to the polyline (brute force over its segments).
pub fn point_polyline_distance(p: &Vec3, polyline: &[Vec3]) -> f64 {
    match polyline {
        [] => f64::INFINITY,
        [q] => (p - q).norm(),
        _ => polyline
            .windows(2)
            .map(|w| point_segment_distance(p, &w[0], &w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

/// Maximise `f` on `[u0, u1]`: `samples + 1` equally spaced samples, then golden-section
/// search in the bracket around every local maximum among the samples (a piece that wiggles
/// has several; refining only the best sample can miss a taller peak between samples).
pub fn maximise(f: impl Fn(f64) -> f64, u0: f64, u1: f64, samples: usize) -> Deviation {
    search(&f, u0, u1, samples, GOLDEN_ITERATIONS)
}

/// [`maximise`] with `iterations` golden-section steps per local maximum.
fn search(
    f: &impl Fn(f64) -> f64,
    u0: f64,
    u1: f64,
    samples: usize,
    iterations: usize,
) -> Deviation {
    let n = samples.max(2);
    let h = (u1 - u0) / n as f64;
    let at = |i: usize| if i == n { u1 } else { u0 + h * i as f64 };
    // On the stack for the usual sample counts: this runs per segment and per blend sample.
    let mut stack = [0.0; 65];
    let mut heap = Vec::new();
    let vals: &mut [f64] = if n < stack.len() {
        &mut stack[..=n]
    } else {
        heap.resize(n + 1, 0.0);
        &mut heap
    };
    for (i, v) in vals.iter_mut().enumerate() {
        *v = f(at(i));
    }
    let vals: &[f64] = vals;
    let mut best = Deviation {
        distance: vals[0],
        u: u0,
    };
    for (i, &v) in vals.iter().enumerate() {
        if v > best.distance {
            best = Deviation {
                distance: v,
                u: at(i),
            };
        }
    }
    if h.is_nan() || h <= 0.0 {
        return best;
    }
    for i in 0..=n {
        let left = if i > 0 {
            vals[i - 1]
        } else {
            f64::NEG_INFINITY
        };
        let right = if i < n {
            vals[i + 1]
        } else {
            f64::NEG_INFINITY
        };
        if vals[i] >= left && vals[i] >= right {
            let d = golden(f, at(i.saturating_sub(1)), at((i + 1).min(n)), iterations);
            if d.distance > best.distance {
                best = d;
            }
        }
    }
    best
}

/// Golden-section search for the maximum of `f` on `[a, b]` (assumed unimodal there; Kiefer
/// 1953): `iterations` shrink the bracket by 0.618 each.
pub fn golden(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, iterations: usize) -> Deviation {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..iterations {
        if f1 >= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = f(x2);
        }
    }
    if f1 >= f2 {
        Deviation {
            distance: f1,
            u: x1,
        }
    } else {
        Deviation {
            distance: f2,
            u: x2,
        }
    }
}

/// Largest distance from the curve piece `u` in `[u0, u1]` to the segment `a`–`b`.
pub fn max_distance_to_segment<C: Curve + ?Sized>(
    curve: &C,
    u0: f64,
    u1: f64,
    a: &Vec3,
    b: &Vec3,
    samples: usize,
) -> Deviation {
    maximise(
        |u| point_segment_distance(&curve.point(u), a, b),
        u0,
        u1,
        samples,
    )
}

/// Golden-section iterations before Newton polishes a closest point: they only have to land
/// in the minimum's basin (bracket 0.618¹² ≈ 3e-3 of two sample spacings), where Newton
/// converges quadratically; the 32 of [`maximise`] cost two thirds of the evaluations.
const CLOSEST_GOLDEN_ITERATIONS: usize = 12;
/// Newton steps on `(C(u) − q)·C′(u) = 0` after the golden section (each kept only while the
/// distance shrinks).
const CLOSEST_NEWTON_STEPS: usize = 8;

/// Closest point of the curve piece `u` in `[u0, u1]` to `q`: `samples + 1` samples, a short
/// golden section around every local minimum among them, Newton from the best.
pub fn closest_point<C: Curve + ?Sized>(
    curve: &C,
    q: &Vec3,
    u0: f64,
    u1: f64,
    samples: usize,
) -> Deviation {
    let f = |u: f64| -(curve.point(u) - q).norm();
    let d = search(&f, u0, u1, samples, CLOSEST_GOLDEN_ITERATIONS);
    let mut best = Deviation {
        distance: -d.distance,
        u: d.u,
    };
    // Newton on (C(u) − q)·C'(u) = 0 polishes the golden-section result: at a near-zero
    // distance the distance is V-shaped in u, so golden section alone stops at ~|C'|·bracket.
    let mut u = best.u;
    for _ in 0..CLOSEST_NEWTON_STEPS {
        let [p, d1, d2, _] = curve.derivs(u);
        let r = p - q;
        let f = r.dot(&d1);
        let fp = d1.norm_squared() + r.dot(&d2);
        if fp <= 0.0 || !fp.is_finite() {
            break;
        }
        u = (u - f / fp).clamp(u0, u1);
        let dist = (curve.point(u) - q).norm();
        if dist < best.distance {
            best = Deviation { distance: dist, u };
        } else {
            break;
        }
    }
    best
}

/// Largest distance from the curve to the polyline (curve → polyline, one-sided Hausdorff):
/// `samples` points per breakpoint span, each refined locally. Cost is samples × segments.
pub fn curve_to_polyline<C: Curve + ?Sized>(
    curve: &C,
    polyline: &[Vec3],
    samples: usize,
) -> Deviation {
    let f = |u: f64| point_polyline_distance(&curve.point(u), polyline);
    over_spans(curve, f, samples)
}

/// Largest distance from the polyline to the curve (polyline → curve): every vertex and
/// `samples` points per segment, each projected onto the curve by sampling plus refinement.
pub fn polyline_to_curve<C: Curve + ?Sized>(curve: &C, polyline: &[Vec3], samples: usize) -> f64 {
    let (a, b) = curve.domain();
    let coarse = samples.max(2) * curve.breakpoints().len().max(2) * 4;
    let dist = |q: &Vec3| closest_point(curve, q, a, b, coarse).distance;
    let mut worst = polyline.iter().map(dist).fold(0.0, f64::max);
    for w in polyline.windows(2) {
        let seg = maximise(|t| dist(&(w[0] + (w[1] - w[0]) * t)), 0.0, 1.0, samples);
        worst = worst.max(seg.distance);
    }
    worst
}

/// Largest distance from curve `a` to curve `b` (a → b): samples of `a` projected onto `b`.
pub fn curve_to_curve<A: Curve + ?Sized, B: Curve + ?Sized>(
    a: &A,
    b: &B,
    samples: usize,
) -> Deviation {
    let (b0, b1) = b.domain();
    let coarse = samples.max(2) * b.breakpoints().len().max(2) * 4;
    let f = |u: f64| closest_point(b, &a.point(u), b0, b1, coarse).distance;
    over_spans(a, f, samples)
}

fn over_spans<C: Curve + ?Sized>(curve: &C, f: impl Fn(f64) -> f64, samples: usize) -> Deviation {
    let bps = curve.breakpoints();
    let mut best = Deviation {
        distance: f(curve.domain().0),
        u: curve.domain().0,
    };
    for w in bps.windows(2) {
        let d = maximise(&f, w[0], w[1], samples);
        if d.distance > best.distance {
            best = d;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::Line;

    #[test]
    fn segment_distance_and_parallel_line() {
        let (a, b) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 0.0, 0.0));
        assert_eq!(
            point_segment_distance(&Vec3::new(5.0, 3.0, 4.0), &a, &b),
            5.0
        );
        assert_eq!(
            point_segment_distance(&Vec3::new(-3.0, 4.0, 0.0), &a, &b),
            5.0
        );
        let l = Line::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(10.0, 2.0, 0.0)).unwrap();
        let d = curve_to_polyline(&l, &[a, b], 8);
        assert!((d.distance - 2.0).abs() < 1e-12);
        assert!((d.u - l.length()).abs() < 1e-12);
    }
}

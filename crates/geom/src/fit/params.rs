//! Parameter values for data points (uniform, chord length, centripetal, universal) and the
//! averaged knot vector (Piegl & Tiller eq. 9.8; Kelekçi, 2021, §2.4) that fitting builds on.

use crate::basis::{basis_funs, find_span, W};
use crate::curve::Vec3;
use crate::error::CurveError;

/// How data points are assigned parameters in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Parameterisation {
    /// `t_k = k / m`: ignores spacing; overshoots on uneven data (Kelekçi, 2021, Table 2.6).
    Uniform,
    /// Proportional to the cumulative chord length.
    ChordLength,
    /// Proportional to the cumulative square root of chord lengths (Lee 1989): the thesis's
    /// choice for G05.1, and ours by default.
    #[default]
    Centripetal,
    /// Lim's universal method: uniform knots, `t_k` where `N_{k,p}` peaks. The thesis's printed
    /// formula (2.59) is garbled (exceeds 1); this is the definition it cites.
    Universal,
}

/// Validate points for fitting: finite, at least `need`, no two consecutive equal.
pub(crate) fn check_points(points: &[Vec3], degree: usize, need: usize) -> Result<(), CurveError> {
    if points.len() < need {
        return Err(CurveError::TooFewPoints {
            points: points.len(),
            degree,
            need,
        });
    }
    if !points.iter().flat_map(|p| p.iter()).all(|c| c.is_finite()) {
        return Err(CurveError::NotFinite);
    }
    if let Some(i) = points.windows(2).position(|w| w[0] == w[1]) {
        return Err(CurveError::DuplicatePoints {
            index: i,
            next: i + 1,
        });
    }
    Ok(())
}

/// Cumulative, normalised sums of `f(|Q_k − Q_{k−1}|)`.
fn cumulative(points: &[Vec3], f: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut t = Vec::with_capacity(points.len());
    t.push(0.0);
    let mut acc = 0.0;
    for w in points.windows(2) {
        acc += f((w[1] - w[0]).norm());
        t.push(acc);
    }
    for v in t.iter_mut() {
        *v /= acc;
    }
    if let Some(last) = t.last_mut() {
        *last = 1.0;
    }
    t
}

/// Uniform clamped knots of degree `p` with `n + 1` control points: `[0^{p+1}, 1/(n−p+1), …, 1^{p+1}]`.
pub(crate) fn uniform_knots(n: usize, p: usize) -> Vec<f64> {
    let segs = (n + 1 - p) as f64;
    let mut k = vec![0.0; p + 1];
    k.extend((1..=n - p).map(|j| j as f64 / segs));
    k.extend(std::iter::repeat_n(1.0, p + 1));
    k
}

/// Where `N_{k,p}` of a knot vector peaks (golden-section search over its support; B-spline
/// basis functions are unimodal).
fn basis_peak(knots: &[f64], p: usize, k: usize, n: usize) -> f64 {
    let value = |u: f64| {
        let span = find_span(knots, p, n, u);
        if k + p < span || k > span {
            return 0.0;
        }
        let mut b = [0.0; W];
        basis_funs(knots, span, u, p, &mut b);
        b[k + p - span]
    };
    let (mut a, mut b) = (knots[k].max(0.0), knots[k + p + 1].min(1.0));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..100 {
        let (x1, x2) = (b - g * (b - a), a + g * (b - a));
        if value(x1) >= value(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    0.5 * (a + b)
}

/// Parameters `t_k` in `[0, 1]` for the points under `method`, for degree `p` (used by the
/// universal method only). Errors on fewer than two points, non-finite or repeated points.
pub fn parameters(
    points: &[Vec3],
    method: Parameterisation,
    p: usize,
) -> Result<Vec<f64>, CurveError> {
    check_points(points, p, 2)?;
    let m = points.len() - 1;
    Ok(match method {
        Parameterisation::Uniform => (0..=m).map(|k| k as f64 / m as f64).collect(),
        Parameterisation::ChordLength => cumulative(points, |d| d),
        Parameterisation::Centripetal => cumulative(points, f64::sqrt),
        Parameterisation::Universal => {
            if m < p {
                return Err(CurveError::TooFewPoints {
                    points: points.len(),
                    degree: p,
                    need: p + 1,
                });
            }
            let knots = uniform_knots(m, p);
            let mut t: Vec<f64> = (0..=m).map(|k| basis_peak(&knots, p, k, m)).collect();
            t[0] = 0.0;
            t[m] = 1.0;
            t
        }
    })
}

/// Averaged knots (P&T eq. 9.8): clamped, `u_{j+p} = (1/p) Σ_{i=j}^{j+p−1} t_i` for
/// `j = 1..=m−p`. The reference prints the indices off by one (it counts order, not degree).
/// Needs at least `p + 1` parameters.
pub fn averaged_knots(t: &[f64], p: usize) -> Result<Vec<f64>, CurveError> {
    if p == 0 || t.len() < p + 1 {
        return Err(CurveError::TooFewPoints {
            points: t.len(),
            degree: p,
            need: p + 1,
        });
    }
    let m = t.len() - 1;
    let mut k = vec![t[0]; p + 1];
    for j in 1..=m - p {
        k.push(t[j..j + p].iter().sum::<f64>() / p as f64);
    }
    k.extend(std::iter::repeat_n(t[m], p + 1));
    Ok(k)
}

//! Tolerance-bounded least-squares approximation (Piegl & Tiller A9.7 with end points fixed,
//! plus knot insertion): the fewest-knots spline we find that stays within a tolerance of every
//! input point and every input segment. This is what compression of short G1 runs runs on.
//!
//! Loop: solve the least-squares problem for the current knots; measure, for every segment
//! `Q_k Q_{k+1}`, the largest distance from the curve piece `u` in `[t_k, t_{k+1}]` to the
//! polyline around it (segments `k−1, k, k+1`: the piece may drift a little along the path
//! across a vertex, which is no deviation), and for every point its distance to the curve
//! (sampling plus golden-section refinement, [`crate::deviation`]); bisect each knot span that
//! holds a violation; repeat. The result: every input point is within the
//! tolerance of the curve, and every point of the curve within the tolerance of the polyline
//! (of the segment its piece belongs to or a neighbour) — the two directions of the Hausdorff
//! distance, locally. Knot spans that would hold too little data for a well-posed least-squares
//! problem get extra samples of the polyline itself, so refinement always converges toward the
//! polyline instead of running out of data (the plain A9.7 stalls at interpolation).

use super::params::{check_points, parameters, Parameterisation};
use crate::banded::Banded;
use crate::basis::{basis_funs, ders_basis_funs, find_span, MAX_DEGREE, MAX_DER, W};
use crate::curve::{Curve, Vec3};
use crate::deviation::{closest_point, maximise, Deviation};
use crate::error::CurveError;
use crate::nurbs::Nurbs;

/// Rounds of knot insertion before giving up; each round halves every offending span, so 64
/// rounds reach spans far below any meaningful parameter resolution.
const MAX_ROUNDS: usize = 64;
/// Fairing bandwidth, in data spacings. The least squares minimises
/// `Σ |C(t_k) − Q_k|² + λ ∫ |C″(u)|² du` (a smoothing spline; Reinsch 1967, Piegl & Tiller §9.4
/// name fairing as the companion of approximation); by Silverman's (1984) equivalent kernel the
/// bandwidth is `h = (λ/ρ)^{1/4}` with `ρ ≈ m` points per unit parameter, so
/// `λ = FAIRING⁴ / m³` damps wiggles shorter than `FAIRING` data spacings and leaves the
/// shape (bias ~ κh²) far inside the tolerance. It stops the spline folding into the vertices
/// of uneven data where refinement gives it knot spans far shorter than the data spacing.
const FAIRING: f64 = 0.5;
/// Rounds that keep the fairing term; refinement goes on without it, so it still converges
/// where the band needs sharper bends than the fairing allows.
const FAIR_ROUNDS: usize = 24;

/// `λ` for `m` segments (see [`FAIRING`]).
fn fairing_weight(m: usize) -> f64 {
    let m = m.max(1) as f64;
    FAIRING.powi(4) / (m * m * m)
}

/// Samples per segment for the deviation checks (then refined).
const SAMPLES: usize = 8;

/// The fitted curve and how it was obtained.
#[derive(Debug, Clone)]
pub struct Approximation {
    /// Clamped B-spline; its ends are exactly the first and last input points.
    pub curve: Nurbs,
    /// Parameter of each input point (segment `k` corresponds to `[params[k], params[k+1]]`).
    pub params: Vec<f64>,
    /// Largest measured distance over all points and segments (≤ the tolerance); where the
    /// control polygon proved a piece inside the tolerance, its bound counts instead (≥ the
    /// true distance).
    pub max_deviation: f64,
    /// Least-squares solves it took.
    pub rounds: usize,
}

/// Fit a degree-`p` B-spline to the polyline `points` so that every point is within
/// `tolerance` of the curve and every curve piece is within `tolerance` of its segment or the
/// segments either side of it.
pub fn approximate(
    points: &[Vec3],
    p: usize,
    tolerance: f64,
    method: Parameterisation,
) -> Result<Approximation, CurveError> {
    if p == 0 || p > MAX_DEGREE {
        return Err(CurveError::Degree {
            degree: p,
            max: MAX_DEGREE,
        });
    }
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(CurveError::Tolerance(tolerance));
    }
    check_points(points, p, 2)?;
    let t = parameters(points, method, p)?;
    // Faired first. Where the tolerance band is much narrower than the chords' sag, fairing
    // only makes refinement chase the band with ever more knots; a faired fit that needs more
    // control points than there are points has stopped approximating, and the plain
    // refinement (which converges toward the polyline itself) is used instead.
    match refine(points, p, tolerance, &t, true) {
        Ok(a) => Ok(a),
        Err(_) => refine(points, p, tolerance, &t, false),
    }
}

/// The refinement loop of [`approximate`] on parameters `t`, with or without fairing.
fn refine(
    points: &[Vec3],
    p: usize,
    tolerance: f64,
    t: &[f64],
    fair: bool,
) -> Result<Approximation, CurveError> {
    let mut interior: Vec<f64> = Vec::new();
    let mut data: Vec<(f64, Vec3)> = t.iter().copied().zip(points.iter().copied()).collect();
    let mut best = f64::INFINITY;
    // Each segment once, with its inverse squared length: the distance tests run several
    // times per piece and round, and a division and square root each was their cost.
    let segs: Vec<Segment> = points
        .windows(2)
        .map(|w| Segment::new(&w[0], &w[1]))
        .collect();
    for round in 1..=MAX_ROUNDS {
        densify(&mut data, &interior, p, t, points);
        if fair && interior.len() + p + 1 > points.len() {
            return Err(CurveError::NotConverged {
                tolerance,
                achieved: best,
                iterations: round,
            });
        }
        let lambda = if fair && round <= FAIR_ROUNDS {
            fairing_weight(points.len() - 1)
        } else {
            0.0
        };
        // Over very short knot spans the fairing entries (~λ/h³) can dwarf the data's and trip
        // the banded solver's relative pivot test: then solve without it.
        let curve = match least_squares(&data, &interior, p, lambda) {
            Ok(c) => c,
            Err(_) if lambda > 0.0 => least_squares(&data, &interior, p, 0.0)?,
            Err(e) => return Err(e),
        };
        // (The curve evaluates from its Bézier span cache: cubic, non-rational.)
        // A samples-only pass finds the violations of the early rounds at a fraction of the
        // cost; only when it finds none does the refined check (the one that can accept) run,
        // reusing the hull bounds the first pass proved (same curve, same bounds).
        let mut hulls = vec![f64::NAN; points.len() - 1];
        let mut check = |quick| {
            measure(
                &curve, points, t, &interior, tolerance, quick, &segs, &mut hulls,
            )
        };
        let (mut worst, mut worst_in_span) = check(true);
        if worst <= tolerance {
            (worst, worst_in_span) = check(false);
        }
        if worst <= tolerance {
            return Ok(Approximation {
                curve,
                params: t.to_vec(),
                max_deviation: worst,
                rounds: round,
            });
        }
        best = best.min(worst);
        let mut added = false;
        let bounds = span_bounds(&interior);
        for (s, w) in worst_in_span.iter().enumerate() {
            if w.is_some() {
                let (a, b) = (bounds[s], bounds[s + 1]);
                // Bisect. Splitting at the worst spot instead grades the spans badly over the
                // rounds: on a 1000-point CAM-like run it needed 3× the control points.
                let xi = 0.5 * (a + b);
                if xi > a && xi < b {
                    interior.push(xi);
                    added = true;
                }
            }
        }
        if !added {
            break;
        }
        interior.sort_by(f64::total_cmp);
    }
    Err(CurveError::NotConverged {
        tolerance,
        achieved: best,
        iterations: MAX_ROUNDS,
    })
}

/// `[0, interior knots…, 1]`.
fn span_bounds(interior: &[f64]) -> Vec<f64> {
    std::iter::once(0.0)
        .chain(interior.iter().copied())
        .chain(std::iter::once(1.0))
        .collect()
}

/// Largest deviation over all pieces and points (or its convex-hull bound where that proves
/// a piece inside), and the worst violation `(distance, u)` in each knot span (None where the
/// span is within tolerance). `hulls[k]` holds piece `k`'s squared hull bound once computed
/// (NaN before): the refined pass after a quick one reuses them. `segs` are the polyline's.
#[allow(clippy::too_many_arguments)]
fn measure(
    curve: &Nurbs,
    points: &[Vec3],
    t: &[f64],
    interior: &[f64],
    tolerance: f64,
    quick: bool,
    segs: &[Segment],
    hulls: &mut [f64],
) -> (f64, Vec<Option<(f64, f64)>>) {
    let m = points.len() - 1;
    let bounds = span_bounds(interior);
    let mut marks = Marks {
        worst_in_span: vec![None; bounds.len() - 1],
        bounds,
        worst: 0.0,
        tolerance,
    };
    let tol2 = tolerance * tolerance;
    let mut span = 0;
    for k in 0..m {
        // Only which knot spans hold a violation decides the next knots: a piece wholly
        // inside a span already marked can add nothing, so it is not measured again.
        span = marks.advance(span, t[k]);
        if t[k + 1] <= marks.bounds[span + 1] && marks.worst_in_span[span].is_some() {
            continue;
        }
        // The piece lies in the convex hull of its Bézier control points and the distance to
        // segment k is convex, so the largest vertex distance bounds the piece's distance from
        // above (and the distance to the three segments is at most that to segment k): when it
        // is inside the tolerance no sample can find a violation, and the bound is recorded.
        if hulls[k].is_nan() {
            if let Some(h2) = curve.hull_max(t[k], t[k + 1], |q| segs[k].distance2(q)) {
                hulls[k] = h2;
            }
        }
        if hulls[k] <= tol2 {
            marks.note(hulls[k].sqrt(), t[k]);
            continue;
        }
        // More samples where knots fall inside the piece: each span may bend on its own.
        let inside =
            interior.partition_point(|&x| x < t[k + 1]) - interior.partition_point(|&x| x <= t[k]);
        let samples = SAMPLES + 4 * inside;
        let dist = |u: f64| {
            let c = curve.point(u);
            // The piece belongs to segment k, but a little tangential drift of the
            // parameter across a vertex is no deviation from the path: measure to the
            // segments around it.
            let mut d2 = segs[k].distance2(&c);
            if k > 0 {
                d2 = d2.min(segs[k - 1].distance2(&c));
            }
            if k + 1 < m {
                d2 = d2.min(segs[k + 1].distance2(&c));
            }
            d2.sqrt()
        };
        let d = if quick {
            sampled_max(dist, t[k], t[k + 1], samples)
        } else {
            maximise(dist, t[k], t[k + 1], samples)
        };
        marks.note(d.distance, d.u);
    }
    if quick {
        return (marks.worst, marks.worst_in_span);
    }
    let mut span = 0;
    for k in 1..m {
        span = marks.advance(span, t[k - 1]);
        if t[k + 1] <= marks.bounds[span + 1] && marks.worst_in_span[span].is_some() {
            continue;
        }
        // The point at its own parameter bounds the distance; refine only when needed.
        let direct = (curve.point(t[k]) - points[k]).norm();
        if direct > tolerance {
            let inside = interior.partition_point(|&x| x < t[k + 1])
                - interior.partition_point(|&x| x <= t[k - 1]);
            let samples = 2 * SAMPLES + 4 * inside;
            let d = closest_point(&curve, &points[k], t[k - 1], t[k + 1], samples);
            marks.note(d.distance, d.u);
        }
    }
    (marks.worst, marks.worst_in_span)
}

/// What a measurement found: the largest deviation, and the worst violation per knot span.
struct Marks {
    /// `[0, interior knots…, 1]`.
    bounds: Vec<f64>,
    worst_in_span: Vec<Option<(f64, f64)>>,
    worst: f64,
    tolerance: f64,
}

impl Marks {
    fn note(&mut self, d: f64, u: f64) {
        self.worst = self.worst.max(d);
        if d > self.tolerance {
            let s = self
                .bounds
                .partition_point(|&x| x <= u)
                .clamp(1, self.bounds.len() - 1)
                - 1;
            if self.worst_in_span[s].is_none_or(|(w, _)| d > w) {
                self.worst_in_span[s] = Some((d, u));
            }
        }
    }

    /// The knot span holding `u`, searching forward from span `from` (`u` never decreases).
    fn advance(&self, mut from: usize, u: f64) -> usize {
        while from + 2 < self.bounds.len() && self.bounds[from + 1] <= u {
            from += 1;
        }
        from
    }
}

/// A programmed segment `a + t·ab`, `t` in `[0, 1]`, for repeated distance queries.
struct Segment {
    a: Vec3,
    ab: Vec3,
    /// `1 / |ab|²`, 0 for a zero-length segment (then the distance is to `a`).
    inv_len2: f64,
}

impl Segment {
    fn new(a: &Vec3, b: &Vec3) -> Self {
        let ab = b - a;
        let len2 = ab.norm_squared();
        Segment {
            a: *a,
            ab,
            inv_len2: if len2 > 0.0 { 1.0 / len2 } else { 0.0 },
        }
    }

    /// Squared distance from `p` (as [`crate::deviation::point_segment_distance`], squared).
    #[inline]
    fn distance2(&self, p: &Vec3) -> f64 {
        let ap = p - self.a;
        let t = (ap.dot(&self.ab) * self.inv_len2).clamp(0.0, 1.0);
        (ap - self.ab * t).norm_squared()
    }
}

/// The largest of `samples + 1` equally spaced values: a lower bound of the maximum, enough
/// to prove a violation (not to prove compliance).
fn sampled_max(f: impl Fn(f64) -> f64, u0: f64, u1: f64, samples: usize) -> Deviation {
    let h = (u1 - u0) / samples as f64;
    (0..=samples)
        .map(|i| {
            let u = if i == samples { u1 } else { u0 + h * i as f64 };
            Deviation { distance: f(u), u }
        })
        .fold(
            Deviation {
                distance: f64::NEG_INFINITY,
                u: u0,
            },
            |a, b| {
                if b.distance > a.distance {
                    b
                } else {
                    a
                }
            },
        )
}

/// The point of the polyline at parameter `u` (linear within segment `k`).
fn polyline_at(u: f64, t: &[f64], points: &[Vec3]) -> Vec3 {
    let k = t.partition_point(|&x| x <= u).clamp(1, t.len() - 1) - 1;
    let f = (u - t[k]) / (t[k + 1] - t[k]);
    points[k] + (points[k + 1] - points[k]) * f
}

/// Give every knot span at least `max(1, p − 1)` data parameters strictly inside it (added as
/// samples of the polyline), which keeps the least-squares problem well posed
/// (Schoenberg–Whitney) however finely the knots are refined.
fn densify(data: &mut Vec<(f64, Vec3)>, interior: &[f64], p: usize, t: &[f64], points: &[Vec3]) {
    let need = p.saturating_sub(1).max(1);
    let bounds: Vec<f64> = std::iter::once(0.0)
        .chain(interior.iter().copied())
        .chain(std::iter::once(1.0))
        .collect();
    let mut extra = Vec::new();
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        let lo = data.partition_point(|d| d.0 <= a);
        let hi = data.partition_point(|d| d.0 < b);
        let have = hi.saturating_sub(lo);
        if have < need {
            for i in 1..=need {
                let u = a + (b - a) * i as f64 / (need + 1) as f64;
                extra.push((u, polyline_at(u, t, points)));
            }
        }
    }
    if !extra.is_empty() {
        data.extend(extra);
        data.sort_by(|x, y| x.0.total_cmp(&y.0));
        data.dedup_by(|x, y| x.0 == y.0);
    }
}

/// The data's share of the normal equations: the upper band of `NᵀN` (`upper[i][d]` is entry
/// `(i, i + d)` of the unknown interior control points) and `Nᵀr`, `r` the data less the pinned
/// end control points' share.
struct Sums<'a> {
    upper: &'a mut [[f64; W]],
    rhs: &'a mut [Vec3],
}

impl Sums<'_> {
    /// Add every datum but the two ends (they pin the end control points). The data are
    /// sorted by parameter (densify keeps them so): the span only moves forward, a step
    /// instead of a binary search per point.
    #[inline(always)]
    fn add_data(self, data: &[(f64, Vec3)], knots: &[f64], p: usize, n: usize, q0: Vec3, qm: Vec3) {
        let mut b = [0.0; W];
        let mut s = p;
        for &(u, q) in &data[1..data.len() - 1] {
            while s < n && u >= knots[s + 1] {
                s += 1;
            }
            if u < knots[s] {
                s = find_span(knots, p, n, u);
            }
            basis_funs(knots, s, u, p, &mut b);
            let mut r = q;
            if s == p {
                r -= q0 * b[0];
            }
            if s == n {
                r -= qm * b[p];
            }
            for j in 0..=p {
                let i = s - p + j;
                if i == 0 || i == n {
                    continue;
                }
                let bj = b[j];
                self.rhs[i - 1] += r * bj;
                let row = &mut self.upper[i - 1];
                for l in j..=p {
                    if s - p + l == n {
                        break;
                    }
                    row[l - j] += bj * b[l];
                }
            }
        }
    }
}

/// Least squares with the end control points pinned to the end data (A9.7's formulation):
/// minimise `Σ |C(t_k) − Q_k|²` over the interior control points.
fn least_squares(
    data: &[(f64, Vec3)],
    interior: &[f64],
    p: usize,
    lambda: f64,
) -> Result<Nurbs, CurveError> {
    let mut knots = vec![0.0; p + 1];
    knots.extend_from_slice(interior);
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    let n = knots.len() - p - 2; // index of the last control point
    let (q0, qm) = match (data.first(), data.last()) {
        (Some(a), Some(b)) => (a.1, b.1),
        _ => return Err(CurveError::Singular),
    };
    let unknowns = n.saturating_sub(1);
    let mut ctrl = Vec::with_capacity(n + 1);
    ctrl.push(q0);
    if unknowns > 0 {
        // The normal matrix is symmetric: its upper band is summed here (`upper[i][d]` is
        // entry `(i, i + d)`, each a sum over the data in the same order as a full assembly,
        // so bit for bit the same) and mirrored once at the end.
        let mut upper = vec![[0.0; W]; unknowns];
        let mut rhs = vec![Vec3::zeros(); unknowns];
        let sums = Sums {
            upper: &mut upper,
            rhs: &mut rhs,
        };
        // The cubic (every compressed run) with the degree a constant, so the loops unroll.
        if p == 3 {
            sums.add_data(data, &knots, 3, n, q0, qm);
        } else {
            sums.add_data(data, &knots, p, n, q0, qm);
        }
        let mut a = Banded::new(unknowns, p, p);
        for (i, row) in upper.iter().enumerate() {
            a.add(i, i, row[0]);
            let width = p.min(unknowns - 1 - i);
            for (d, &v) in row.iter().enumerate().take(width + 1).skip(1) {
                a.add(i, i + d, v);
                a.add(i + d, i, v);
            }
        }
        if lambda > 0.0 {
            add_fairing(&mut a, &mut rhs, &knots, p, n, q0, qm, lambda);
        }
        a.solve(&mut rhs)?;
        ctrl.extend(rhs);
    }
    ctrl.push(qm);
    Nurbs::bspline(p, &ctrl, knots)
}

/// Add `λ ∫ N_i″ N_j″ du` to the normal equations (the pinned end control points move to the
/// right-hand side). `N″` of a cubic is linear on each knot span, so 2-point Gauss–Legendre
/// is exact for the products up to degree 3; higher degrees use 4 points (exact to degree 7).
#[allow(clippy::too_many_arguments)]
fn add_fairing(
    a: &mut Banded,
    rhs: &mut [Vec3],
    knots: &[f64],
    p: usize,
    n: usize,
    q0: Vec3,
    qm: Vec3,
    lambda: f64,
) {
    const G2: [(f64, f64); 2] = [
        (-0.577_350_269_189_625_8, 1.0),
        (0.577_350_269_189_625_8, 1.0),
    ];
    const G4: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    if p < 2 {
        return;
    }
    let rule: &[(f64, f64)] = if p <= 3 { &G2 } else { &G4 };
    let mut ders = [[0.0; W]; MAX_DER + 1];
    for s in p..=n {
        let (u0, u1) = (knots[s], knots[s + 1]);
        if u1 <= u0 {
            continue;
        }
        let half = 0.5 * (u1 - u0);
        for &(x, w) in rule {
            let u = u0 + half * (1.0 + x);
            ders_basis_funs(knots, s, u, p, 2, &mut ders);
            let d2 = &ders[2];
            let wl = lambda * w * half;
            for j in 0..=p {
                let i = s - p + j;
                if i == 0 || i == n {
                    continue;
                }
                for l in 0..=p {
                    let c = s - p + l;
                    let v = wl * d2[j] * d2[l];
                    if c == 0 {
                        rhs[i - 1] -= q0 * v;
                    } else if c == n {
                        rhs[i - 1] -= qm * v;
                    } else {
                        a.add(i - 1, c - 1, v);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_reproduces_a_cubic_in_its_space() {
        // A cubic polynomial curve is in every cubic spline space: the fit must be exact.
        let f = |u: f64| Vec3::new(u, 3.0 * u * u - u * u * u, 2.0 * u);
        let data: Vec<(f64, Vec3)> = (0..=200)
            .map(|i| i as f64 / 200.0)
            .map(|u| (u, f(u)))
            .collect();
        let c = least_squares(&data, &[0.25, 0.5, 0.75], 3, 0.0).unwrap();
        let res = data
            .iter()
            .map(|(u, q)| (c.point(*u) - q).norm())
            .fold(0.0, f64::max);
        assert!(res < 1e-12, "{res}");
    }

    /// `∫ |C″|²` by the midpoint rule on 4000 points (enough to compare fits).
    fn bending(c: &Nurbs) -> f64 {
        let n = 4000;
        (0..n)
            .map(|i| {
                let u = (i as f64 + 0.5) / n as f64;
                c.derivs(u)[2].norm_squared() / n as f64
            })
            .sum()
    }

    #[test]
    fn fairing_leaves_a_line_alone() {
        // C″ = 0 for points on a line: the pinned ends' share of the fairing term must cancel
        // exactly, whatever λ, or the line bends.
        let data: Vec<(f64, Vec3)> = (0..=50)
            .map(|i| i as f64 / 50.0)
            .map(|u| (u, Vec3::new(3.0 * u - 1.0, 2.0 * u, -u)))
            .collect();
        for lambda in [1e-6, 1e-2, 10.0] {
            let c = least_squares(&data, &[0.2, 0.3, 0.7], 3, lambda).unwrap();
            let res = data
                .iter()
                .map(|(u, q)| (c.point(*u) - q).norm())
                .fold(0.0, f64::max);
            assert!(res < 1e-10, "λ = {lambda}: {res}");
        }
    }

    #[test]
    fn more_fairing_bends_less() {
        // Penalised least squares: the penalty at the optimum never grows with λ, and the data
        // misfit never shrinks. Noisy samples of a wave on many knots.
        let data: Vec<(f64, Vec3)> = (0..=120)
            .map(|i| {
                let u = i as f64 / 120.0;
                let noise = 0.01 * (((i * 7919) % 13) as f64 / 6.0 - 1.0);
                (u, Vec3::new(10.0 * u, (6.0 * u).sin() + noise, 0.0))
            })
            .collect();
        let knots: Vec<f64> = (1..40).map(|i| i as f64 / 40.0).collect();
        let misfit = |c: &Nurbs| {
            data.iter()
                .map(|(u, q)| (c.point(*u) - q).norm_squared())
                .sum::<f64>()
        };
        let mut last = (f64::INFINITY, 0.0);
        for lambda in [0.0, 1e-8, 1e-6, 1e-4, 1e-2] {
            let c = least_squares(&data, &knots, 3, lambda).unwrap();
            let (b, m) = (bending(&c), misfit(&c));
            assert!(
                b <= last.0 * (1.0 + 1e-9),
                "λ = {lambda}: bending {b} after {}",
                last.0
            );
            assert!(
                m >= last.1 * (1.0 - 1e-9),
                "λ = {lambda}: misfit {m} after {}",
                last.1
            );
            last = (b, m);
        }
        // And it does something: the strongest fairing bends less than half as much.
        let free = bending(&least_squares(&data, &knots, 3, 0.0).unwrap());
        assert!(last.0 < 0.5 * free, "{} vs {free}", last.0);
    }
}

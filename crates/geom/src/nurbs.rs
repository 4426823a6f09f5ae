//! Rational B-spline curves (NURBS) of any degree up to [`MAX_DEGREE`]: the G06.2 block and the
//! output of spline fitting. Evaluation uses span search A2.1, basis functions A2.2/A2.3 and
//! the rational derivative rule A4.2 (Piegl & Tiller) up to the third derivative.

// Index loops mirror the book's pseudo-code, so the code can be checked against it line by line.
#![allow(clippy::needless_range_loop)]

use nalgebra::Vector4;

use crate::basis::{basis_funs, ders_basis_funs, find_span, MAX_DEGREE, MAX_DER, W};
use crate::bezier_spans::{self, BezierSpans};
use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

/// An axis-aligned box, `min ≤ max` componentwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingBox {
    pub min: Vec3,
    pub max: Vec3,
}

impl BoundingBox {
    /// Distance from `q` to the box (0 inside).
    pub fn distance(&self, q: &Vec3) -> f64 {
        let below = self.min - q;
        let above = q - self.max;
        below.sup(&above).sup(&Vec3::zeros()).norm()
    }
}

/// `C(u) = Σ N_{i,p}(u) w_i P_i / Σ N_{i,p}(u) w_i`, `u` in `[knots[p], knots[n+1]]`.
///
/// Control points are stored homogeneous (`w·x, w·y, w·z, w`), as A4.2 works on them. The
/// knot vector need not be clamped: the domain is always `[u_p, u_{n+1}]` (P&T §2.2).
#[derive(Clone, PartialEq)]
pub struct Nurbs {
    degree: usize,
    knots: Vec<f64>,
    cw: Vec<Vector4<f64>>,
    /// First and last non-empty span of the domain (for A2.1 at the domain ends).
    first: usize,
    last: usize,
    /// Non-rational curves of degree ≤ 3: the non-empty spans in Bézier form, a cache for
    /// fast evaluation ([`bezier_spans`]).
    spans: Option<BezierSpans>,
}

/// The curve's data, without the evaluation cache (as before the cache existed: printed
/// moves and error messages stay readable).
impl std::fmt::Debug for Nurbs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Nurbs")
            .field("degree", &self.degree)
            .field("knots", &self.knots)
            .field("cw", &self.cw)
            .field("first", &self.first)
            .field("last", &self.last)
            .finish()
    }
}

impl Nurbs {
    /// A NURBS curve. Validates: degree in `1..=MAX_DEGREE`, at least `degree + 1` control
    /// points, one weight per point, `points + degree + 1` knots, everything finite, knots
    /// non-decreasing, weights > 0, no knot repeated more than `degree` times inside the
    /// domain (the curve would break apart there) or `degree + 1` times anywhere, and a
    /// non-empty domain.
    pub fn new(
        degree: usize,
        points: &[Vec3],
        weights: &[f64],
        knots: Vec<f64>,
    ) -> Result<Self, CurveError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(CurveError::Degree {
                degree,
                max: MAX_DEGREE,
            });
        }
        if points.len() < degree + 1 {
            return Err(CurveError::TooFewPoints {
                points: points.len(),
                degree,
                need: degree + 1,
            });
        }
        if weights.len() != points.len() {
            return Err(CurveError::WeightCount {
                weights: weights.len(),
                points: points.len(),
            });
        }
        let expected = points.len() + degree + 1;
        if knots.len() != expected {
            return Err(CurveError::KnotCount {
                got: knots.len(),
                expected,
            });
        }
        if !points.iter().flat_map(|p| p.iter()).all(|c| c.is_finite())
            || !knots.iter().all(|k| k.is_finite())
        {
            return Err(CurveError::NotFinite);
        }
        for (index, &value) in weights.iter().enumerate() {
            if !(value.is_finite() && value > 0.0) {
                return Err(CurveError::Weight { index, value });
            }
        }
        let (first, last) = domain_spans(degree, &knots)?;
        let cw = points
            .iter()
            .zip(weights)
            .map(|(p, &w)| Vector4::new(p.x * w, p.y * w, p.z * w, w))
            .collect();
        Ok(Nurbs {
            degree,
            knots,
            cw,
            first,
            last,
            spans: None,
        }
        .with_spans())
    }

    /// Fill the Bézier span cache when the curve qualifies (non-rational, degree ≤ 3).
    fn with_spans(mut self) -> Self {
        if self.degree > 3 || self.cw.iter().any(|c| c.w != 1.0) {
            return self;
        }
        let parts = (self.first..=self.last).filter_map(|s| {
            let (a, b) = (self.knots[s], self.knots[s + 1]);
            if b <= a {
                return None;
            }
            let [ca, da, ..] = self.rat_derivs_in(s, a, 1);
            let [cb, db, ..] = self.rat_derivs_in(s, b, 1);
            Some((a, b, bezier_spans::from_hermite((ca, da), (cb, db), b - a)))
        });
        self.spans = Some(BezierSpans::new(parts));
        self
    }

    /// An upper bound of the convex function `f` (a distance to a point, segment or other
    /// convex set) over the piece `u` in `[u0, u1]`, from the convex hull of the piece's Bézier
    /// control points; `None` for curves without the Bézier cache (rational, degree > 3).
    pub fn hull_max(&self, u0: f64, u1: f64, f: impl Fn(&Vec3) -> f64) -> Option<f64> {
        self.spans.as_ref().map(|s| s.hull_max(u0, u1, f))
    }

    /// The axis-aligned box around the Bézier control points of the piece `u` in `[u0, u1]`:
    /// it holds the piece (convex hull property), so its distance to a point bounds the
    /// piece's from below. `None` for curves without the Bézier cache.
    pub fn hull_box(&self, u0: f64, u1: f64) -> Option<BoundingBox> {
        let spans = self.spans.as_ref()?;
        let mut b = BoundingBox {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        };
        spans.hull_points(u0, u1, |q| {
            b.min = b.min.inf(q);
            b.max = b.max.sup(q);
        });
        Some(b)
    }

    /// The cached span holding `u` (clamped), `u`'s place `t` in it and `1 / width`; `None`
    /// when the curve has no cache.
    #[inline]
    fn bezier_at(&self, u: f64) -> Option<(&bezier_spans::Span, f64, f64)> {
        let spans = self.spans.as_ref()?;
        let (a, b) = self.domain();
        Some(spans.locate(clamp_param(u, a, b)))
    }

    /// The image of the curve under the affine map `f` (a change of frame, units or offsets):
    /// the NURBS of the mapped control points with the same weights and knots, which is the
    /// exact image because rational B-splines are invariant under affine maps (P&T §4.2). A
    /// valid curve stays valid, so nothing is checked again, and the Bézier cache is mapped
    /// the same way instead of being derived again; `f` must be affine.
    pub fn mapped(&self, f: impl Fn(Vec3) -> Vec3) -> Nurbs {
        let cw = self
            .cw
            .iter()
            .map(|c| {
                let p = f(Vec3::new(c.x / c.w, c.y / c.w, c.z / c.w));
                Vector4::new(p.x * c.w, p.y * c.w, p.z * c.w, c.w)
            })
            .collect();
        Nurbs {
            degree: self.degree,
            knots: self.knots.clone(),
            cw,
            first: self.first,
            last: self.last,
            spans: self.spans.as_ref().map(|s| s.mapped(&f)),
        }
    }

    /// A non-rational B-spline (all weights 1).
    pub fn bspline(degree: usize, points: &[Vec3], knots: Vec<f64>) -> Result<Self, CurveError> {
        Nurbs::new(degree, points, &vec![1.0; points.len()], knots)
    }

    pub fn degree(&self) -> usize {
        self.degree
    }
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }
    /// Control points in Cartesian form.
    pub fn control_points(&self) -> Vec<Vec3> {
        self.cw
            .iter()
            .map(|c| Vec3::new(c.x / c.w, c.y / c.w, c.z / c.w))
            .collect()
    }
    pub fn weights(&self) -> Vec<f64> {
        self.cw.iter().map(|c| c.w).collect()
    }

    /// A5.1 CurveKnotIns: the same curve with `u` inserted `times` more times (`u` strictly
    /// inside the domain; its multiplicity may not exceed the degree). Knot insertion is how a
    /// spline is cut at a corner or compared control point by control point with another.
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<Nurbs, CurveError> {
        let p = self.degree;
        let (lo, hi) = self.domain();
        if !u.is_finite() {
            return Err(CurveError::NotFinite);
        }
        if !(u > lo && u < hi) {
            return Err(CurveError::EmptyDomain);
        }
        let s = self.knots.iter().filter(|&&k| k == u).count();
        if s + times > p {
            return Err(CurveError::KnotMultiplicity {
                value: u,
                multiplicity: s + times,
                degree: p,
            });
        }
        if times == 0 {
            return Ok(self.clone());
        }
        let (up, pw, r) = (&self.knots, &self.cw, times);
        let np = pw.len() - 1;
        let mp = np + p + 1;
        let k = find_span(up, self.first, self.last, u);
        let mut uq = Vec::with_capacity(up.len() + r);
        uq.extend_from_slice(&up[..=k]);
        uq.extend(std::iter::repeat_n(u, r));
        uq.extend_from_slice(&up[k + 1..=mp]);
        let mut qw = vec![Vector4::zeros(); np + r + 1];
        qw[..=k - p].copy_from_slice(&pw[..=k - p]);
        qw[k - s + r..].copy_from_slice(&pw[k - s..]);
        let mut rw: Vec<Vector4<f64>> = pw[k - p..=k - s].to_vec();
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for i in 0..=p - j - s {
                let alpha = (u - up[l + i]) / (up[i + k + 1] - up[l + i]);
                rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
            }
            qw[l] = rw[0];
            qw[k + r - j - s] = rw[p - j - s];
        }
        if l + 1 < k - s {
            qw[l + 1..k - s].copy_from_slice(&rw[1..k - s - l]);
        }
        Nurbs::from_homogeneous(p, qw, uq)
    }

    /// Cut the curve at `u` (strictly inside the domain) into two curves that meet there:
    /// `u` is inserted up to multiplicity `degree`, and the control polygon splits at the
    /// control point that then lies on the curve.
    pub fn split(&self, u: f64) -> Result<(Nurbs, Nurbs), CurveError> {
        let p = self.degree;
        let s = self.knots.iter().filter(|&&k| k == u).count();
        let full = self.insert_knot(u, p.saturating_sub(s))?;
        let a = full.knots.partition_point(|&k| k < u); // first index of u
        let mut lk = full.knots[..a + p].to_vec();
        lk.push(u);
        let mut rk = vec![u];
        rk.extend_from_slice(&full.knots[a..]);
        let left = Nurbs::from_homogeneous(p, full.cw[..a].to_vec(), lk)?;
        let right = Nurbs::from_homogeneous(p, full.cw[a - 1..].to_vec(), rk)?;
        Ok((left, right))
    }

    /// A curve from homogeneous control points whose degree, knots and weights the caller has
    /// already validated with [`domain_spans`] (a NURBS surface building its iso curves).
    pub(crate) fn from_valid_homogeneous(
        degree: usize,
        cw: Vec<Vector4<f64>>,
        knots: Vec<f64>,
        (first, last): (usize, usize),
    ) -> Nurbs {
        Nurbs {
            degree,
            knots,
            cw,
            first,
            last,
            spans: None,
        }
        .with_spans()
    }

    fn from_homogeneous(
        degree: usize,
        cw: Vec<Vector4<f64>>,
        knots: Vec<f64>,
    ) -> Result<Nurbs, CurveError> {
        let w: Vec<f64> = cw.iter().map(|c| c.w).collect();
        let pts: Vec<Vec3> = cw
            .iter()
            .map(|c| Vec3::new(c.x / c.w, c.y / c.w, c.z / c.w))
            .collect();
        Nurbs::new(degree, &pts, &w, knots)
    }

    /// C and its derivatives up to `nd` (higher ones left zero).
    fn rat_derivs(&self, u: f64, nd: usize) -> [Vec3; 4] {
        let (span, u) = self.span(u);
        self.rat_derivs_in(span, u, nd)
    }

    /// [`Self::rat_derivs`] with the polynomial of span `span` (a one-sided limit at its ends).
    fn rat_derivs_in(&self, span: usize, u: f64, nd: usize) -> [Vec3; 4] {
        let p = self.degree;
        let mut nders = [[0.0; W]; MAX_DER + 1];
        ders_basis_funs(&self.knots, span, u, p, nd, &mut nders);
        // Derivatives of the homogeneous curve Cw (A3.2 on the 4-D points).
        let mut aw = [Vector4::zeros(); MAX_DER + 1];
        for (k, a) in aw.iter_mut().enumerate().take(nd.min(p) + 1) {
            for j in 0..=p {
                *a += self.cw[span - p + j] * nders[k][j];
            }
        }
        // A4.2 RatCurveDerivs: C^(k) = (A^(k) - Σ_{i=1..k} C(k,i) w^(i) C^(k-i)) / w.
        let mut ck = [Vec3::zeros(); MAX_DER + 1];
        let w0 = aw[0].w;
        for k in 0..=nd.min(MAX_DER) {
            let mut v = Vec3::new(aw[k].x, aw[k].y, aw[k].z);
            for i in 1..=k {
                v -= ck[k - i] * (BIN[k][i] * aw[i].w);
            }
            ck[k] = v / w0;
        }
        ck
    }

    fn span(&self, u: f64) -> (usize, f64) {
        let (a, b) = self.domain();
        let u = clamp_param(u, a, b);
        (find_span(&self.knots, self.first, self.last, u), u)
    }
}

/// Knot-vector checks shared by curves and surfaces (`knots.len()` already equals control
/// points + degree + 1, all finite): non-decreasing, a non-empty domain `[u_p, u_{n+1}]`, no
/// knot repeated more than `degree` times inside the domain or `degree + 1` times anywhere.
/// Returns the first and last non-empty span of the domain (for A2.1 at the domain ends).
pub(crate) fn domain_spans(degree: usize, knots: &[f64]) -> Result<(usize, usize), CurveError> {
    for i in 1..knots.len() {
        if knots[i] < knots[i - 1] {
            return Err(CurveError::KnotsDecreasing {
                index: i,
                value: knots[i],
            });
        }
    }
    let n = knots.len() - degree - 2;
    let (lo, hi) = (knots[degree], knots[n + 1]);
    if lo >= hi {
        return Err(CurveError::EmptyDomain);
    }
    let mut i = 0;
    while i < knots.len() {
        let mut j = i;
        while j + 1 < knots.len() && knots[j + 1] == knots[i] {
            j += 1;
        }
        let m = j - i + 1;
        let inside = knots[i] > lo && knots[i] < hi;
        if m > degree + 1 || (inside && m > degree) {
            return Err(CurveError::KnotMultiplicity {
                value: knots[i],
                multiplicity: m,
                degree,
            });
        }
        i = j + 1;
    }
    let first = (degree..=n)
        .find(|&s| knots[s] < knots[s + 1])
        .unwrap_or(degree);
    let last = (degree..=n)
        .rev()
        .find(|&s| knots[s] < knots[s + 1])
        .unwrap_or(n);
    Ok((first, last))
}

/// Binomial coefficients up to 3 for A4.2.
pub(crate) const BIN: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

impl Curve for Nurbs {
    fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.cw.len()])
    }

    fn point(&self, u: f64) -> Vec3 {
        if let Some((b, t, _)) = self.bezier_at(u) {
            return bezier_spans::point(b, t);
        }
        let p = self.degree;
        let (span, u) = self.span(u);
        let mut n = [0.0; W];
        basis_funs(&self.knots, span, u, p, &mut n);
        let mut h = Vector4::zeros();
        for (j, nj) in n[..=p].iter().enumerate() {
            h += self.cw[span - p + j] * *nj;
        }
        Vec3::new(h.x, h.y, h.z) / h.w
    }

    fn derivs(&self, u: f64) -> [Vec3; 4] {
        if let Some((b, t, iw)) = self.bezier_at(u) {
            let mut d = bezier_spans::derivs(b, t, iw);
            // Above the degree the derivatives are zero, not the rounding of the cubic form.
            for v in d.iter_mut().skip(self.degree + 1) {
                *v = Vec3::zeros();
            }
            return d;
        }
        self.rat_derivs(u, MAX_DER)
    }

    fn d1(&self, u: f64) -> Vec3 {
        if let Some((b, t, iw)) = self.bezier_at(u) {
            return bezier_spans::d1(b, t, iw);
        }
        // The arc-length quadrature only needs C'; skip the higher basis derivatives.
        self.rat_derivs(u, 1)[1]
    }

    // The eight nodes of a panel inside one knot span share its span lookup: the same values
    // as eight `speed` calls, bit for bit (the quadrature's cost was mostly the lookups).
    fn speed_integral(&self, a: f64, b: f64) -> f64 {
        if let Some(spans) = &self.spans {
            let (lo, hi) = self.domain();
            if lo <= a && a <= b && b <= hi {
                if let Some(v) = spans.speed_integral(a, b) {
                    return v;
                }
            }
        }
        crate::arclen::gauss_legendre_8(|u| self.speed(u), a, b)
    }

    /// From the Bézier span cache's hodograph (non-rational, degree ≤ 3), else unknown.
    fn speed_ratio(&self, a: f64, b: f64) -> Option<f64> {
        self.spans.as_ref()?.speed_ratio(a, b)
    }

    // As `speed_integral`: one span lookup for the eight nodes, the same values.
    fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
        if let Some(spans) = &self.spans {
            let (lo, hi) = self.domain();
            if lo <= a && a <= b && b <= hi {
                if let Some(v) = spans.gauss_speeds(a, b) {
                    return v;
                }
            }
        }
        crate::arclen::gauss_nodes_8(|u| self.speed(u), a, b)
    }

    fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        let mut out = vec![a];
        for &k in &self.knots {
            if k > *out.last().unwrap_or(&a) && k < b {
                out.push(k);
            }
        }
        out.push(b);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random numbers in [0, 1) (xorshift64*).
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            (x.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn mapped_curve_is_the_image_of_the_curve() {
        // Affine invariance (P&T §4.2): for rational and non-rational curves of degrees 1–5,
        // the mapped curve's points are the mapped points of the curve, to rounding.
        let mut r = rng(0x5eed_0002);
        for case in 0..200 {
            let p = 1 + case % 5;
            let n = p + 1 + (r() * 6.0) as usize;
            let pts: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(20.0 * r() - 10.0, 20.0 * r() - 10.0, r()))
                .collect();
            let weights: Vec<f64> = (0..n)
                .map(|_| if case % 2 == 0 { 1.0 } else { 0.2 + 3.0 * r() })
                .collect();
            let mut knots = vec![0.0; p + 1];
            for k in 1..n - p {
                knots.push(k as f64 + r() * 0.5);
            }
            knots.extend(std::iter::repeat_n((n - p) as f64, p + 1));
            let c = Nurbs::new(p, &pts, &weights, knots.clone()).unwrap();
            let (angle, scale) = (r() * 6.0, 25.4 * r() + 0.1);
            let shift = Vec3::new(r() * 100.0, -r() * 50.0, r());
            let f = |q: Vec3| {
                let (s, co) = angle.sin_cos();
                scale * Vec3::new(co * q.x - s * q.y, s * q.x + co * q.y, q.z) + shift
            };
            let m = c.mapped(f);
            assert_eq!(m.knots(), c.knots());
            assert_eq!(m.weights(), c.weights());
            // The same curve as one built from the mapped points, derivatives (and so the
            // mapped Bézier cache) included.
            let mapped: Vec<Vec3> = pts.iter().map(|&q| f(q)).collect();
            let fresh = Nurbs::new(p, &mapped, &weights, knots).unwrap();
            assert_eq!(m.spans.is_some(), fresh.spans.is_some());
            let (a, b) = c.domain();
            for k in 0..=20 {
                let u = a + (b - a) * k as f64 / 20.0;
                let (want, got) = (f(c.point(u)), m.point(u));
                assert!(
                    (want - got).norm() < 1e-9 * (1.0 + want.norm()),
                    "{case} {u}"
                );
                let (d, e) = (fresh.derivs(u), m.derivs(u));
                for i in 0..3 {
                    let tol = 1e-8 * (1.0 + d[i].norm());
                    assert!((d[i] - e[i]).norm() < tol, "{case} {u} d{i}");
                }
            }
        }
    }

    #[test]
    fn bezier_spans_match_the_basis_recurrences() {
        // Degrees 1–3, uneven knots with interior multiplicities up to the degree (where
        // derivatives jump), clamped and unclamped: the cached Bézier form must give the same
        // point and derivatives as A2.3 + A4.2 on the same span, everywhere including knots.
        let mut r = rng(0x5eed_0001);
        for case in 0..300 {
            let p = 1 + case % 3;
            let n = p + 1 + (r() * 9.0) as usize;
            let pts: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(100.0 * r() - 50.0, 10.0 * r(), r() - 0.5))
                .collect();
            let clamped = case % 4 != 3;
            let mut knots: Vec<f64> = Vec::new();
            let interior = n - p - 1;
            let mut v: f64 = 0.0;
            if clamped {
                knots.extend(std::iter::repeat_n(0.0, p + 1));
            } else {
                for _ in 0..=p {
                    knots.push(v);
                    v += 0.1 + r();
                }
                v = *knots.last().unwrap_or(&0.0);
            }
            let mut k = 0;
            while k < interior {
                v += 0.01 + r();
                let mult = (1 + (r() * p as f64) as usize).min(interior - k);
                knots.extend(std::iter::repeat_n(v, mult));
                k += mult;
            }
            v += 0.01 + r();
            if clamped {
                knots.extend(std::iter::repeat_n(v, p + 1));
            } else {
                for _ in 0..=p {
                    knots.push(v);
                    v += 0.1 + r();
                }
            }
            let c = Nurbs::bspline(p, &pts, knots.clone()).unwrap();
            assert!(c.spans.is_some());
            let (a, b) = c.domain();
            let mut us: Vec<f64> = (0..=200).map(|i| a + (b - a) * i as f64 / 200.0).collect();
            us.extend(knots.iter().copied().filter(|&k| k >= a && k <= b));
            for u in us {
                let fast = c.derivs(u);
                let slow = c.rat_derivs(u, MAX_DER);
                for d in 0..=p {
                    let scale = 1.0 + slow[d].norm();
                    assert!(
                        (fast[d] - slow[d]).norm() <= 1e-9 * scale,
                        "case {case} p {p} u {u} d {d}: {} vs {}",
                        fast[d],
                        slow[d]
                    );
                }
                // Above the degree: exactly zero (the recurrences leave rounding there).
                assert!(fast[p + 1..].iter().all(|v| *v == Vec3::zeros()));
                assert!((c.point(u) - slow[0]).norm() <= 1e-12 * (1.0 + slow[0].norm()));
                assert!((c.d1(u) - slow[1]).norm() <= 1e-9 * (1.0 + slow[1].norm()));
            }
            if clamped {
                // The ends of a clamped curve are its end control points, bit for bit.
                assert_eq!(c.point(a), pts[0]);
                assert_eq!(c.point(b), pts[n - 1]);
            }
        }
    }

    #[test]
    fn hull_box_bounds_the_distance_from_below() {
        let mut r = rng(0x5eed_0002);
        for _ in 0..50 {
            let pts: Vec<Vec3> = (0..9)
                .map(|_| Vec3::new(10.0 * r(), 10.0 * r(), r()))
                .collect();
            let knots = vec![0., 0., 0., 0., 0.1, 0.3, 0.35, 0.6, 0.9, 1., 1., 1., 1.];
            let c = Nurbs::bspline(3, &pts, knots).unwrap();
            let (u0, u1) = (0.5 * r(), 0.5 + 0.5 * r());
            let b = c.hull_box(u0, u1).unwrap();
            let q = Vec3::new(20.0 * r() - 5.0, 20.0 * r() - 5.0, 4.0 * r() - 2.0);
            let lb = b.distance(&q);
            for i in 0..=400 {
                let p = c.point(u0 + (u1 - u0) * i as f64 / 400.0);
                // Inside up to the rounding of the blossom (a few ulp of the coordinates).
                assert!(b.distance(&p) <= 1e-13, "{p} outside {b:?}");
                assert!((p - q).norm() >= lb - 1e-13, "{} < {lb}", (p - q).norm());
            }
        }
    }

    #[test]
    fn rational_and_high_degree_curves_keep_the_recurrences() {
        let pts = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let w = [1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0];
        let quarter = Nurbs::new(2, &pts, &w, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).unwrap();
        assert!(quarter.spans.is_none());
        for i in 0..=20 {
            let r = quarter.point(i as f64 / 20.0).norm();
            assert!((r - 1.0).abs() < 1e-14, "{r}");
        }
        let pts5: Vec<Vec3> = (0..6).map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
        let knots = [vec![0.0; 6], vec![1.0; 6]].concat();
        assert!(Nurbs::bspline(5, &pts5, knots).unwrap().spans.is_none());
    }
}

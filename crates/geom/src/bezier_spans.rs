//! Each knot span of a non-rational B-spline of degree ≤ 3 in cubic Bézier form, kept by
//! [`crate::nurbs::Nurbs`] so that the path builder's and the interpolator's many evaluations
//! (deviation samples, arc-length quadrature, s → u) cost a span search and one Bernstein
//! combination instead of the basis-function recurrences A2.2/A2.3 and the rational rule A4.2.
//!
//! A span's polynomial has degree ≤ 3, so its cubic Hermite data at the span ends determine it
//! exactly (Piegl & Tiller eq. 1.9–1.10, Bézier from Hermite: `B1 = C(a) + w·C′(a)/3`,
//! `B2 = C(b) − w·C′(b)/3`, `w = b − a`); the end values are the de Boor values of that span
//! themselves, so the Bernstein form reproduces them bit for bit at `t = 0` and `t = 1` (the
//! clamped ends of a fit stay exactly its end points).

use crate::curve::Vec3;

/// Control points `B0..B3` of one span.
pub(crate) type Span = [Vec3; 4];

/// The Bézier points of a span on `[a, b]` from the value and first derivative at both ends.
pub(crate) fn from_hermite(a: (Vec3, Vec3), b: (Vec3, Vec3), width: f64) -> Span {
    let h = width / 3.0;
    [a.0, a.0 + a.1 * h, b.0 - b.1 * h, b.0]
}

/// `C(t)`, `t` in `[0, 1]`, Bernstein form (exact at both ends).
#[inline]
pub(crate) fn point(b: &Span, t: f64) -> Vec3 {
    let s = 1.0 - t;
    let (s2, t2) = (s * s, t * t);
    b[0] * (s2 * s) + b[1] * (3.0 * s2 * t) + b[2] * (3.0 * s * t2) + b[3] * (t2 * t)
}

/// `dC/du` at `t`, for a span of width `1 / inv_width` in `u`.
#[inline]
pub(crate) fn d1(b: &Span, t: f64, inv_width: f64) -> Vec3 {
    let s = 1.0 - t;
    let (d0, d1, d2) = (b[1] - b[0], b[2] - b[1], b[3] - b[2]);
    (d0 * (s * s) + d1 * (2.0 * s * t) + d2 * (t * t)) * (3.0 * inv_width)
}

/// `[C, C′, C″, C‴]` (derivatives in `u`) at `t`.
#[inline]
pub(crate) fn derivs(b: &Span, t: f64, inv_width: f64) -> [Vec3; 4] {
    let s = 1.0 - t;
    let (d0, d1, d2) = (b[1] - b[0], b[2] - b[1], b[3] - b[2]);
    let (e0, e1) = (d1 - d0, d2 - d1);
    let iw2 = inv_width * inv_width;
    [
        point(b, t),
        (d0 * (s * s) + d1 * (2.0 * s * t) + d2 * (t * t)) * (3.0 * inv_width),
        (e0 * s + e1 * t) * (6.0 * iw2),
        (e1 - e0) * (6.0 * iw2 * inv_width),
    ]
}

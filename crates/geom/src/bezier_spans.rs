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

/// The non-empty knot spans of a curve in Bézier form.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BezierSpans {
    /// Span starts, then the domain end.
    starts: Vec<f64>,
    /// `1 / width` of each span.
    inv: Vec<f64>,
    spans: Vec<Span>,
    /// Spans per unit parameter, for the interpolation guess in [`Self::index`].
    density: f64,
}

impl BezierSpans {
    /// From `(a, b, span)` triples in order of `u`, each `a < b`, contiguous.
    pub(crate) fn new(parts: impl Iterator<Item = (f64, f64, Span)>) -> Self {
        let mut out = BezierSpans {
            starts: Vec::new(),
            inv: Vec::new(),
            spans: Vec::new(),
            density: 0.0,
        };
        let mut end = 0.0;
        for (a, b, sp) in parts {
            out.starts.push(a);
            out.inv.push(1.0 / (b - a));
            out.spans.push(sp);
            end = b;
        }
        out.starts.push(end);
        let width = end - out.starts[0];
        out.density = if width > 0.0 {
            out.spans.len() as f64 / width
        } else {
            0.0
        };
        out
    }

    /// The spans of the curve's image under the affine map `f`: a Bézier's image under an
    /// affine map is the Bézier of the mapped control points.
    pub(crate) fn mapped(&self, f: impl Fn(Vec3) -> Vec3) -> Self {
        BezierSpans {
            spans: self.spans.iter().map(|s| s.map(&f)).collect(),
            ..self.clone()
        }
    }

    /// The last span whose start is at or before `u` (the first span for `u` before it):
    /// `starts.partition_point(|x| x <= u).clamp(1, n) − 1`. Knots of fits and programs are
    /// spread roughly evenly, so the span in proportion to `u` is a guess a few steps from the
    /// answer (interpolation search); far off, binary search.
    #[inline]
    fn index(&self, u: f64) -> usize {
        const WALK: usize = 4;
        let n = self.spans.len();
        let guess = (u - self.starts[0]) * self.density;
        let mut k = if guess >= 0.0 {
            (guess as usize).min(n - 1)
        } else {
            0
        };
        for _ in 0..WALK {
            if self.starts[k] > u {
                if k == 0 {
                    return 0;
                }
                k -= 1;
            } else if k + 1 < n && self.starts[k + 1] <= u {
                k += 1;
            } else {
                return k;
            }
        }
        self.starts.partition_point(|&x| x <= u).clamp(1, n) - 1
    }

    /// The span holding `u` (already clamped to the domain; a knot belongs to the span it
    /// starts, the domain end to the last), `u`'s place `t` in it and `1 / width`.
    #[inline]
    pub(crate) fn locate(&self, u: f64) -> (&Span, f64, f64) {
        let k = self.index(u);
        let b = self.starts[k + 1];
        let t = if u >= b {
            1.0
        } else {
            (u - self.starts[k]) * self.inv[k]
        };
        (&self.spans[k], t, self.inv[k])
    }

    /// `∫_a^b |C'(u)| du` by 8-point Gauss–Legendre when `[a, b]` (inside the domain) lies in
    /// one span, with that span looked up once; `None` when it crosses a knot. Each node's
    /// `t` and `C'` are computed as [`Self::locate`] and [`d1`] compute them, so the result is
    /// the per-node quadrature's bit for bit.
    pub(crate) fn speed_integral(&self, a: f64, b: f64) -> Option<f64> {
        let span = self.span_speed(a, b)?;
        Some(crate::arclen::gauss_legendre_8(|u| span.at(u), a, b))
    }

    /// `|C'|` at the eight Gauss–Legendre nodes of `[a, b]` (`arclen::gauss_nodes_8`'s
    /// order) with one span lookup, each as [`Self::speed_integral`] computes it; `None`
    /// when `[a, b]` crosses a knot.
    pub(crate) fn gauss_speeds(&self, a: f64, b: f64) -> Option<[f64; 8]> {
        let span = self.span_speed(a, b)?;
        Some(crate::arclen::gauss_nodes_8(|u| span.at(u), a, b))
    }

    /// The speed of the one span holding `[a, b]` (`None` when it crosses a knot).
    #[inline]
    fn span_speed(&self, a: f64, b: f64) -> Option<SpanSpeed> {
        let k = self.index(a);
        let (start, end) = (self.starts[k], self.starts[k + 1]);
        // Every node is strictly inside (a, b); with b at most the span end they all belong
        // to span k (a node at `end` would belong to the next span).
        if !(a >= start && b <= end) {
            return None;
        }
        let (b0, iw) = (&self.spans[k], self.inv[k]);
        // `d1`'s differences, once for the eight nodes; per node the same arithmetic as `d1`.
        Some(SpanSpeed {
            start,
            end,
            iw,
            d: [b0[1] - b0[0], b0[2] - b0[1], b0[3] - b0[2]],
            scale: 3.0 * iw,
        })
    }

    /// An upper bound of `max |C'| / min |C'|` over `[u0, u1]` when it lies in one span: the
    /// derivative of a Bézier span lies in the convex hull of its hodograph's control points
    /// `3(b_{i+1} − b_i)` (Farin, *Curves and Surfaces for CAGD*, §4.5), so its length is at
    /// most the longest of them and at least their smallest component along their mean
    /// direction, when that is positive. `None` across a knot or when the hull nears zero.
    pub(crate) fn speed_ratio(&self, u0: f64, u1: f64) -> Option<f64> {
        let k = self.index(0.5 * (u0 + u1));
        if u0 < self.starts[k] || u1 > self.starts[k + 1] {
            return None;
        }
        let b = &self.spans[k];
        let h = [b[1] - b[0], b[2] - b[1], b[3] - b[2]];
        let mean = h[0] + h[1] + h[2];
        let d = mean / mean.norm();
        let low = h.iter().map(|v| v.dot(&d)).fold(f64::INFINITY, f64::min);
        let high = h.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let ratio = high / low;
        (low > 0.0 && ratio.is_finite()).then_some(ratio)
    }

    /// An upper bound of `f` over the curve piece `u` in `[u0, u1]` when `f` is convex (a
    /// distance to a convex set): the piece is cut at the knots, each part's Bézier control
    /// points are found by blossoming, and the part lies in their convex hull (Piegl & Tiller
    /// §1.4), where a convex function takes its maximum at a vertex.
    pub(crate) fn hull_max(&self, u0: f64, u1: f64, f: impl Fn(&Vec3) -> f64) -> f64 {
        let mut worst = f64::NEG_INFINITY;
        self.hull_points(u0, u1, |q| worst = worst.max(f(q)));
        worst
    }

    /// Calls `f` with the Bézier control points of the piece `u` in `[u0, u1]` cut at the
    /// knots (blossoming): the piece lies in their convex hull (Piegl & Tiller §1.4).
    pub(crate) fn hull_points(&self, u0: f64, u1: f64, mut f: impl FnMut(&Vec3)) {
        let n = self.spans.len();
        let (lo, hi) = (self.starts[0], self.starts[n]);
        let (u0, u1) = (u0.clamp(lo, hi), u1.clamp(lo, hi));
        let mut k = self.index(u0);
        loop {
            let (a, b) = (self.starts[k], self.starts[k + 1]);
            let t0 = ((u0.max(a) - a) * self.inv[k]).clamp(0.0, 1.0);
            let t1 = ((u1.min(b) - a) * self.inv[k]).clamp(0.0, 1.0);
            for q in sub_span(&self.spans[k], t0, t1) {
                f(&q);
            }
            k += 1;
            if k >= n || self.starts[k] >= u1 {
                return;
            }
        }
    }
}

/// Control points of the part `t` in `[t0, t1]` of a cubic Bézier: its blossom values
/// `b(t0,t0,t0), b(t0,t0,t1), b(t0,t1,t1), b(t1,t1,t1)` (de Casteljau with a different
/// parameter per level; Ramshaw 1989).
fn sub_span(b: &Span, t0: f64, t1: f64) -> Span {
    let lerp = |p: &Vec3, q: &Vec3, t: f64| p * (1.0 - t) + q * t;
    let a1 = [
        lerp(&b[0], &b[1], t0),
        lerp(&b[1], &b[2], t0),
        lerp(&b[2], &b[3], t0),
    ];
    let b1 = [
        lerp(&b[0], &b[1], t1),
        lerp(&b[1], &b[2], t1),
        lerp(&b[2], &b[3], t1),
    ];
    let aa = [lerp(&a1[0], &a1[1], t0), lerp(&a1[1], &a1[2], t0)];
    let ab = [lerp(&a1[0], &a1[1], t1), lerp(&a1[1], &a1[2], t1)];
    let bb = [lerp(&b1[0], &b1[1], t1), lerp(&b1[1], &b1[2], t1)];
    [
        lerp(&aa[0], &aa[1], t0),
        lerp(&aa[0], &aa[1], t1),
        lerp(&ab[0], &ab[1], t1),
        lerp(&bb[0], &bb[1], t1),
    ]
}

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

/// `|C'|` on one cubic span, from its control-point differences (`d1`'s arithmetic).
struct SpanSpeed {
    start: f64,
    end: f64,
    iw: f64,
    d: [Vec3; 3],
    scale: f64,
}

impl SpanSpeed {
    #[inline]
    fn at(&self, u: f64) -> f64 {
        let t = if u >= self.end {
            1.0
        } else {
            (u - self.start) * self.iw
        };
        let s = 1.0 - t;
        let [d0, d1, d2] = self.d;
        ((d0 * (s * s) + d1 * (2.0 * s * t) + d2 * (t * t)) * self.scale).norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_is_the_binary_search() {
        // Uneven spans (one long, many short, a cluster): the interpolation guess plus the
        // walk must give what the plain binary search gives, for every u including knots.
        let mut starts = vec![0.0, 10.0];
        let mut x: f64 = 10.0;
        for i in 0..60 {
            x += if i % 7 == 0 {
                1e-6
            } else {
                0.01 + 0.1 * (i % 5) as f64
            };
            starts.push(x);
        }
        let z = [Vec3::zeros(); 4];
        let spans = BezierSpans::new(starts.windows(2).map(|w| (w[0], w[1], z)));
        let n = starts.len() - 1;
        let mut us: Vec<f64> = starts.clone();
        us.extend((0..=5000).map(|i| x * i as f64 / 5000.0));
        us.extend(starts.iter().map(|s| s - 1e-12));
        for u in us {
            let u = u.clamp(0.0, x);
            let want = starts.partition_point(|&s| s <= u).clamp(1, n) - 1;
            assert_eq!(spans.index(u), want, "u = {u}");
        }
    }

    #[test]
    fn sub_span_is_the_same_curve() {
        let b = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 3.0, -1.0),
            Vec3::new(4.0, -2.0, 2.0),
            Vec3::new(5.0, 1.0, 0.5),
        ];
        for (t0, t1) in [(0.0, 1.0), (0.2, 0.7), (0.5, 0.5), (0.9, 1.0)] {
            let q = sub_span(&b, t0, t1);
            for i in 0..=10 {
                let x = i as f64 / 10.0;
                let want = point(&b, t0 + (t1 - t0) * x);
                assert!((point(&q, x) - want).norm() < 1e-13, "{t0} {t1} {x}");
            }
        }
    }

    #[test]
    fn hull_bound_is_above_every_sample() {
        // A wavy two-span curve; the distance to a line is convex, so the hull bound must be
        // at least every sampled value of every piece, and close to it on short pieces.
        let s0 = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(2.0, -2.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
        ];
        let s1 = [
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(4.0, 2.0, 0.0),
            Vec3::new(5.0, 1.0, 1.0),
            Vec3::new(6.0, 0.0, 0.0),
        ];
        let spans = BezierSpans::new([(0.0, 0.5, s0), (0.5, 1.0, s1)].into_iter());
        let f = |p: &Vec3| (p.y * p.y + p.z * p.z).sqrt();
        for (u0, u1) in [
            (0.0, 1.0),
            (0.1, 0.2),
            (0.4, 0.6),
            (0.5, 0.5001),
            (0.45, 0.5),
        ] {
            let bound = spans.hull_max(u0, u1, f);
            let mut sampled = 0.0f64;
            for i in 0..=1000 {
                let u = u0 + (u1 - u0) * i as f64 / 1000.0;
                let (sp, t, _) = spans.locate(u);
                sampled = sampled.max(f(&point(sp, t)));
            }
            assert!(
                bound >= sampled - 1e-15,
                "[{u0}, {u1}]: {bound} < {sampled}"
            );
            if u1 - u0 < 1e-3 {
                assert!(bound - sampled < 1e-5, "[{u0}, {u1}]: {bound} vs {sampled}");
            }
        }
    }

    #[test]
    fn speed_ratio_bounds_the_sampled_speeds() {
        // Random cubic spans: wherever a ratio is claimed, every sampled |C'| lies within it
        // (max/min over 400 samples ≤ the ratio), and straight-ish spans do get one.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let (mut claimed, mut tried) = (0, 0);
        for case in 0..2000 {
            // From nearly straight to wild: control points off a line by `bend`.
            let bend = [0.01, 0.1, 0.5, 2.0][case % 4];
            let mut p = |i: f64| Vec3::new(i, bend * rnd(), bend * rnd());
            let b = [p(0.0), p(1.0), p(2.0), p(3.0)];
            let spans = BezierSpans::new(std::iter::once((0.0, 2.0, b)));
            tried += 1;
            let Some(r) = spans.speed_ratio(0.0, 2.0) else {
                continue;
            };
            claimed += 1;
            let speeds: Vec<f64> = (0..=400)
                .map(|i| d1(&b, i as f64 / 400.0, 0.5).norm())
                .collect();
            let (lo, hi) = speeds
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
            assert!(
                hi / lo <= r * (1.0 + 1e-12),
                "case {case}: {} > {r}",
                hi / lo
            );
            // Inside one span only.
            assert!(spans.speed_ratio(-0.5, 1.0).is_none());
        }
        assert!(claimed * 2 > tried, "{claimed} of {tried}");
    }
}

//! Planning sections: a long curved segment with knots (a compressed spline) is planned as
//! consecutive sections cut at its knots, so that its speed limit follows the curvature along
//! it instead of its worst point. The path is unchanged: each section is the same curve,
//! trimmed, with the same parameter; the interpolator samples it as any other segment.
//!
//! Why: the planner bounds a segment by its largest |q′|, |q″|, |q‴| (see [`super::limits`]),
//! so a 60 mm spline row with one tight wiggle was driven at the wiggle's speed from end to end.

use std::sync::Arc;

use tezgah_geom::{Curve, Trimmed, Vec3};

use crate::path::{Junction, Segment, SegmentFeed};

/// A curve shared by the sections of one segment.
struct Shared(Arc<dyn Curve + Send + Sync>);

impl Curve for Shared {
    fn domain(&self) -> (f64, f64) {
        self.0.domain()
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        self.0.derivs(u)
    }
    fn point(&self, u: f64) -> Vec3 {
        self.0.point(u)
    }
    fn d1(&self, u: f64) -> Vec3 {
        self.0.d1(u)
    }
    fn speed(&self, u: f64) -> f64 {
        self.0.speed(u)
    }
    fn curvature(&self, u: f64) -> f64 {
        self.0.curvature(u)
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.0.breakpoints()
    }
}

/// Whether the curve's unit tangent and curvature vector are continuous at `u` (a knot of a
/// C2 spline; not a corner of a degree-1 or repeated-knot one), compared just either side.
fn smooth_at(curve: &dyn Curve, u: f64) -> bool {
    let (a, b) = curve.domain();
    let h = 1e-7 * (b - a);
    let side = |x: f64| {
        let [_, d1, d2, _] = curve.derivs(x);
        let sp = d1.norm();
        let t = d1 / sp;
        (t, (d2 - t * t.dot(&d2)) / (sp * sp))
    };
    let ((t0, k0), (t1, k1)) = (side(u - h), side(u + h));
    let scale = k0.norm().max(k1.norm()).max(1.0);
    (t1 - t0).norm() <= 1e-5 && (k1 - k0).norm() <= 1e-3 * scale
}

/// Cuts `seg` at knots into sections of at least `min_length` mm (the last may be shorter
/// only when the whole is), or returns it whole when it is straight, rotary-only, has no
/// inner knot or is shorter than two sections. Rotary axes keep moving in proportion to arc
/// length; an inverse-time feed is shared in proportion to length (same speed). Cuts are made
/// only at knots where the tangent and curvature are continuous, so every inner junction is
/// `Smooth`.
pub fn sections(seg: Segment, min_length: f64) -> Vec<Segment> {
    let knots = seg.curve.breakpoints();
    if seg.rotary_only()
        || knots.len() < 3
        || seg.length < 2.0 * min_length
        || min_length.is_nan()
        || min_length <= 0.0
    {
        return vec![seg];
    }
    // Cut points: knots where the length since the last cut reaches min_length, and the
    // rest long enough for another section.
    let span = |a: f64, b: f64| tezgah_geom::arclen::gauss_legendre(&*seg.curve, a, b);
    let mut cuts = vec![(knots[0], 0.0)];
    let mut s = 0.0;
    let mut since = 0.0;
    for w in knots.windows(2) {
        let l = span(w[0], w[1]);
        s += l;
        since += l;
        if since >= min_length && seg.length - s >= min_length && smooth_at(&*seg.curve, w[1]) {
            cuts.push((w[1], s));
            since = 0.0;
        }
    }
    if cuts.len() < 2 {
        return vec![seg];
    }
    let (_, ub) = seg.curve.domain();
    cuts.push((ub, seg.length));
    let Segment {
        curve,
        length,
        rotary: [r0, r1],
        line,
        feed,
        end,
        tolerance,
        control,
    } = seg;
    let shared: Arc<dyn Curve + Send + Sync> = Arc::from(curve);
    let rot = |s: f64| [0, 1, 2].map(|i| r0[i] + (r1[i] - r0[i]) * (s / length));
    let count = cuts.len() - 1;
    let mut out = Vec::with_capacity(count);
    for (k, w) in cuts.windows(2).enumerate() {
        let ((ua, sa), (ub, sb)) = (w[0], w[1]);
        let Ok(piece) = Trimmed::new(Shared(Arc::clone(&shared)), ua, ub) else {
            // Cannot happen for cuts taken from the sorted breakpoints; keep the path whole.
            return vec![Segment {
                curve: Box::new(Shared(shared)),
                length,
                rotary: [r0, r1],
                line,
                feed,
                end,
                tolerance,
                control,
            }];
        };
        // The last section takes the rest, so the lengths add up exactly.
        let l = if k + 1 == count { length - sa } else { sb - sa };
        out.push(Segment {
            curve: Box::new(piece),
            length: l,
            rotary: [rot(sa), if k + 1 == count { r1 } else { rot(sb) }],
            line,
            feed: match feed {
                SegmentFeed::InverseTime(t) if length > 0.0 => {
                    SegmentFeed::InverseTime(t * l / length)
                }
                other => other,
            },
            end: if k + 1 == count {
                end
            } else {
                Junction::Smooth
            },
            tolerance,
            control,
        });
    }
    out
}

//! Following the smoothed path sample by sample: the midpoint of the chord between two samples
//! lies next to the path just past the previous midpoint, so its closest point is found by a
//! few safeguarded Newton steps from there, on the segments passed between the two samples
//! (never a search over a whole segment).

use std::sync::Arc;

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Vec3};

use crate::path::Segment;

/// Newton steps before falling back to a bracketed search.
const NEWTON_STEPS: usize = 8;

/// A Newton step this small (mm along the curve) ends the iteration: its point is taken from
/// the Taylor expansion `C + C′·Δu + C″·Δu²/2` already at hand, off by `|C‴|·Δu³/6`, about
/// 1e-18 mm, and the step leaves a residual of order `κ·step²` to the foot of the normal.
const CONVERGED_MM: f64 = 1e-6;

/// Where the last chord's midpoint fell on the last sample's segment: a lower bound for the
/// next chord's, and the curve's speed there for the next first guess.
struct Last {
    seg: Arc<Segment>,
    u: f64,
    speed: f64,
}

/// The cursor on the smoothed path.
#[derive(Default)]
pub(crate) struct Follow {
    last: Option<Last>,
}

impl Follow {
    /// The distance (mm) of the midpoint of the chord from `previous` to `tip` from the path
    /// between the two samples: `path` is the segments passed since the previous sample,
    /// ending with the sample's own (none while standing still: `None`). The tip itself lies
    /// on its segment by construction (the interpolator's point of the curve). `chord: false`
    /// (across a tool-control switch) only moves the cursor.
    pub(crate) fn push(
        &mut self,
        tip: &Vec3,
        previous: Option<&Vec3>,
        path: &[Arc<Segment>],
        chord: bool,
    ) -> Option<f64> {
        let seg = path.last()?;
        let (a, _) = seg.curve.domain();
        let mut next = match self.last.as_ref() {
            Some(l) if Arc::ptr_eq(&l.seg, seg) => (l.u, l.speed),
            _ => (a, seg.curve.speed(a)),
        };
        let mut d_chord = None;
        if let (true, Some(p), Some(last)) = (chord, previous, self.last.as_ref()) {
            let mid = 0.5 * (p + tip);
            let half = 0.5 * (tip - p).norm();
            let mut best = f64::INFINITY;
            let mut measure = |s: &Arc<Segment>| {
                let (sa, sb) = s.curve.domain();
                if s.rotary_only() {
                    return (s.curve.point(sa) - mid).norm();
                }
                let (lo, start) = if Arc::ptr_eq(s, &last.seg) {
                    // The last midpoint was half a chord behind the previous sample, this
                    // one is half a chord past it: a whole chord on (at a steady speed the
                    // first Newton step then confirms the guess).
                    let step = if last.speed > 0.0 {
                        2.0 * half / last.speed
                    } else {
                        0.0
                    };
                    (last.u, last.u + step)
                } else {
                    (sa, sa)
                };
                let (d, u, speed) = local(&*s.curve, &mid, lo, sb, start);
                if Arc::ptr_eq(s, seg) {
                    next = (u, speed);
                }
                d
            };
            for s in path {
                best = best.min(measure(s));
            }
            // After a dwell the previous sample's segment is no longer in `path`.
            if !path.iter().any(|s| Arc::ptr_eq(s, &last.seg)) {
                best = best.min(measure(&last.seg.clone()));
            }
            d_chord = Some(best);
        }
        match &mut self.last {
            // The same segment: no new reference to count.
            Some(l) if Arc::ptr_eq(&l.seg, seg) => (l.u, l.speed) = next,
            last => {
                *last = Some(Last {
                    seg: seg.clone(),
                    u: next.0,
                    speed: next.1,
                })
            }
        }
        d_chord
    }
}

/// Closest point of `c` on `[lo, hi]` to `q` (distance, parameter, the curve's speed there),
/// from `u`: Newton on `g(u) = (C(u) − q)·C′(u) = 0` (point inversion, Piegl & Tiller, *The
/// NURBS Book*, 2nd ed., §6.1, eq. 6.3), each step clamped to the bracket; where
/// Newton stalls (`g′ ≤ 0`, a point beyond the centre of curvature) or does not converge,
/// geom's sampled golden-section search over the bracket.
pub(crate) fn local(c: &dyn Curve, q: &Vec3, lo: f64, hi: f64, mut u: f64) -> (f64, f64, f64) {
    if hi <= lo {
        return ((c.point(lo) - q).norm(), lo, c.speed(lo));
    }
    u = u.clamp(lo, hi);
    for _ in 0..NEWTON_STEPS {
        let [p, d1, d2, _] = c.derivs(u);
        let r = p - q;
        let g = r.dot(&d1);
        let h = d1.norm_squared() + r.dot(&d2);
        if !(h > 0.0 && h.is_finite()) {
            break;
        }
        let next = (u - g / h).clamp(lo, hi);
        let speed = d1.norm();
        let du = next - u;
        if du.abs() * speed <= CONVERGED_MM {
            let at = r + d1 * du + d2 * (0.5 * du * du);
            return (at.norm(), next, speed);
        }
        u = next;
    }
    let d = closest_point(c, q, lo, hi, 4);
    (d.distance, d.u, c.speed(d.u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::Arc as Circle;

    /// On a 6 rad arc of radius 10 the closest point of a point off the axis, at an angle the
    /// arc holds, is radial: Newton from a guess a little off finds it, and a bracket that
    /// excludes it gives the nearer end.
    #[test]
    fn newton_on_a_circle() {
        let c = Circle::new(
            Vec3::zeros(),
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::z(),
            6.0,
            0.0,
        )
        .unwrap();
        let sweep = c.sweep();
        for k in 1..20 {
            let t = k as f64 * 0.3;
            let q = Vec3::new(12.0 * t.cos(), 12.0 * t.sin(), 1.0);
            let (d, u, _) = local(&c, &q, 0.0, 1.0, t / sweep + 0.02);
            assert!((d - 5f64.sqrt()).abs() < 1e-12, "{d}");
            assert!((u * sweep - t).abs() < 1e-9, "{u}");
        }
        let q = Vec3::new(0.0, 12.0, 0.0);
        let (d, u, _) = local(&c, &q, 0.0, 0.1, 0.05);
        let end = c.point(0.1);
        assert!((d - (end - q).norm()).abs() < 1e-12 && u == 0.1);
    }
}

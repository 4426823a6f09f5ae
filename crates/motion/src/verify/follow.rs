//! Following the smoothed path sample by sample: a sample lies on its own segment just past
//! the previous one, so its parameter is found by a few safeguarded Newton steps from there
//! (never a search over the whole segment), and the chord between two samples is measured
//! against the part of the path between their two parameters.

use std::sync::Arc;

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Vec3};

use crate::path::Segment;

/// Newton steps before falling back to a bracketed search.
const NEWTON_STEPS: usize = 8;

/// A step this small (mm along the curve) ends Newton's iteration.
const CONVERGED_MM: f64 = 1e-13;

/// The cursor: the last sample's segment and parameter on it.
#[derive(Default)]
pub(crate) struct Follow {
    last: Option<(Arc<Segment>, f64)>,
}

/// Distances (mm) of one sample from the smoothed path.
pub(crate) struct Measured {
    /// The sample's tip from its own segment.
    pub tip: f64,
    /// The midpoint of the chord from the previous sample from the path between the two.
    pub chord: Option<f64>,
}

impl Follow {
    /// Measures the sample at `tip` on `path` (the segments passed since the previous
    /// sample, ending with its own: not empty); `chord` asks for the chord from `previous`.
    pub(crate) fn push(
        &mut self,
        tip: &Vec3,
        previous: Option<&Vec3>,
        path: &[Arc<Segment>],
        chord: bool,
    ) -> Measured {
        let Some(seg) = path.last() else {
            return Measured {
                tip: 0.0,
                chord: None,
            };
        };
        let (a, b) = seg.curve.domain();
        let same = self.last.as_ref().filter(|(s, _)| Arc::ptr_eq(s, seg));
        let (lo, guess) = match (same, previous) {
            (Some((_, u)), Some(p)) => (*u, advance(&*seg.curve, *u, (tip - p).norm(), b)),
            (Some((_, u)), None) => (*u, *u),
            (None, _) => {
                let d = (tip - seg.curve.point(a)).norm();
                (a, advance(&*seg.curve, a, d, b))
            }
        };
        let (d_tip, u) = if seg.rotary_only() {
            ((seg.curve.point(a) - tip).norm(), a)
        } else {
            local(&*seg.curve, tip, lo, b, guess)
        };
        let mut d_chord = None;
        if let (true, Some(p), Some((pseg, pu))) = (chord, previous, self.last.as_ref()) {
            let mid = 0.5 * (p + tip);
            let n = path.len();
            let mut best = f64::INFINITY;
            for (k, s) in path.iter().enumerate() {
                let (sa, sb) = s.curve.domain();
                let lo = if Arc::ptr_eq(s, pseg) { *pu } else { sa };
                let hi = if k + 1 == n { u } else { sb };
                best = best.min(part(s, &mid, lo, hi));
            }
            // After a dwell the previous sample's segment is no longer in `path`.
            if !path.iter().any(|s| Arc::ptr_eq(s, pseg)) {
                best = best.min(part(pseg, &mid, *pu, pseg.curve.domain().1));
            }
            d_chord = Some(best);
        }
        self.last = Some((seg.clone(), u));
        Measured {
            tip: d_tip,
            chord: d_chord,
        }
    }
}

/// The parameter `distance` mm on from `u` at the curve's speed there (a first guess).
fn advance(c: &dyn Curve, u: f64, distance: f64, hi: f64) -> f64 {
    let v = c.speed(u);
    if v > 0.0 {
        (u + distance / v).min(hi)
    } else {
        u
    }
}

/// Distance from `q` to the part `[lo, hi]` of a segment (its start point if rotary-only).
fn part(s: &Segment, q: &Vec3, lo: f64, hi: f64) -> f64 {
    if s.rotary_only() {
        return (s.curve.point(s.curve.domain().0) - q).norm();
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    local(&*s.curve, q, lo, hi, 0.5 * (lo + hi)).0
}

/// Closest point of `c` on `[lo, hi]` to `q` (distance, parameter), from `u`: Newton on
/// `g(u) = (C(u) − q)·C′(u) = 0`, each step clamped to the bracket, and the bracket's ends;
/// where Newton stalls (`g′ ≤ 0`, a point beyond the centre of curvature) or does not
/// converge, geom's sampled golden-section search over the bracket.
pub(crate) fn local(c: &dyn Curve, q: &Vec3, lo: f64, hi: f64, mut u: f64) -> (f64, f64) {
    if hi <= lo {
        return ((c.point(lo) - q).norm(), lo);
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
        let step = (next - u).abs() * d1.norm();
        u = next;
        if step <= CONVERGED_MM {
            let mut best = ((c.point(u) - q).norm(), u);
            for e in [lo, hi] {
                let d = (c.point(e) - q).norm();
                if d < best.0 {
                    best = (d, e);
                }
            }
            return best;
        }
    }
    let d = closest_point(c, q, lo, hi, 4);
    (d.distance, d.u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::Arc as Circle;

    /// On a 6 rad arc of radius 10 the closest point of any point off the axis over it is radial: Newton
    /// from a guess a little off finds it, and a bracket that excludes it gives the nearer end.
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
            let (d, u) = local(&c, &q, 0.0, 1.0, t / sweep + 0.02);
            assert!((d - 5f64.sqrt()).abs() < 1e-12, "{d}");
            assert!((u * sweep - t).abs() < 1e-9, "{u}");
        }
        let q = Vec3::new(0.0, 12.0, 0.0);
        let (d, u) = local(&c, &q, 0.0, 0.1, 0.05);
        let end = c.point(0.1);
        assert!((d - (end - q).norm()).abs() < 1e-12 && u == 0.1);
    }
}

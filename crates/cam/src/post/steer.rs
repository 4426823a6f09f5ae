//! Ball end mills: the tool axis re-chosen with the machine in the loop, before the post
//! picks its angles. A ball cuts with its sphere, whose centre `tip + R·axis` does not depend
//! on the axis, so any axis within a cone about the planned one cuts the same surface. Near
//! the pole (the axis along the table's C axis) the planned axis makes C spin — the azimuth
//! of an axis `d` from the pole turns by `ds/d` per step; here C is chosen instead, pass by
//! pass, so it moves as little and as slowly as the cone allows.
//!
//! For each location the cone of half-angle α about the planned axis `k` (polar angle θ,
//! azimuth `c` on the machine's C) admits the C values whose meridian plane passes within α
//! of `k`: `|sin(C − c)| ≤ sin α / sin θ` (the angular distance from a point to a great circle
//! through the pole), every C where θ ≤ α. Where the table may also tilt the other way
//! (θ + α within the negative tilt limit) that set repeats every 180° (the tilt changes
//! sign), else every 360°. Along a pass C must stay in these intervals with
//! `|ΔC| ≤ L·Δs` (Δs the tip's travel): the smallest feasible L is found by bisection,
//! feasibility by a backward sweep of the reachable intervals, then C is taken forward, each
//! as near the one before as the intervals allow (held wherever it may be; a pass starts as
//! near the previous pass's last C as it can). The tilt is the one nearest the planned axis in
//! C's meridian plane, and the tip moves so the ball's centre stays put.

use std::f64::consts::PI;

use rayon::prelude::*;

use tezgah_geom::Vec3;

use super::orient::Orienter;
use crate::toolpath::ToolPath;

/// Most C may turn per millimetre of tip travel that the bisection tries, rad/mm.
const MOST_RATE: f64 = 1e3;
/// Bisection steps on the rate (the log of the rate bracket halves each step).
const BISECTIONS: usize = 48;
/// Tip travel below which two locations count as one place, mm.
const SAME_PLACE: f64 = 1e-6;

/// The C values a location admits: an interval `centre ± half` repeating every `period`
/// (π or 2π), or any C.
#[derive(Debug, Clone, Copy)]
struct Admits {
    centre: f64,
    half: f64,
    period: f64,
}

impl Admits {
    fn any(&self) -> bool {
        self.half >= 0.5 * self.period
    }

    /// The copy of the interval nearest `c` (rad, unwrapped): `[lo, hi]`.
    fn near(&self, c: f64) -> (f64, f64) {
        if self.any() {
            return (f64::NEG_INFINITY, f64::INFINITY);
        }
        let k = ((c - self.centre) / self.period).round();
        let m = self.centre + k * self.period;
        (m - self.half, m + self.half)
    }
}

/// The C values within `cone` (rad) of axis `k` on the machine of `o`.
fn admits(o: &Orienter, k: &Vec3, cone: f64, both_ways: bool) -> Admits {
    let [b0, _] = o.solutions(k);
    let theta = b0.tilt.abs();
    // The meridian's point nearest the axis is nearer the pole than the axis: a tilt of at
    // most θ either way.
    let both = both_ways && -o.tilt_limit.min >= theta;
    let period = if both { PI } else { 2.0 * PI };
    let ratio = cone.sin() / theta.sin().max(1e-300);
    let half = if theta <= cone || ratio >= 1.0 {
        PI
    } else {
        ratio.asin()
    };
    Admits {
        centre: b0.c,
        half,
        period,
    }
}

/// Whether C can go from the end back to the start of a pass within the intervals at rate
/// `rate` (rad/mm); the backward-reachable interval at each location, nearest the copies the
/// forward walk from `start` uses, in `reach`.
fn feasible(
    adm: &[Admits],
    steps: &[Step],
    rate: f64,
    start: f64,
    reach: &mut Vec<(f64, f64)>,
) -> bool {
    // The copies of every interval along a continuous C are fixed by walking the centres
    // forward from the start (the nearest copy each time), as C itself will go.
    let n = adm.len();
    let mut copies = Vec::with_capacity(n);
    let mut at = start;
    for a in adm {
        let (lo, hi) = a.near(at);
        if lo.is_finite() {
            at = 0.5 * (lo + hi);
        }
        copies.push((lo, hi));
    }
    reach.clear();
    reach.resize(n, (f64::NEG_INFINITY, f64::INFINITY));
    reach[n - 1] = copies[n - 1];
    for i in (0..n - 1).rev() {
        let slack = steps[i].slack(rate);
        let (nlo, nhi) = reach[i + 1];
        let lo = copies[i].0.max(nlo - slack);
        let hi = copies[i].1.min(nhi + slack);
        if lo > hi {
            return false;
        }
        reach[i] = (lo, hi);
    }
    true
}

/// One step along a pass, from a location to the next.
#[derive(Debug, Clone, Copy)]
struct Step {
    /// The tip's travel, mm.
    length: f64,
    /// The most C may turn in it, rad: the axis may turn at most [`Steer::max_step`] by C.
    cap: f64,
}

impl Step {
    fn slack(&self, rate: f64) -> f64 {
        (rate * self.length).min(self.cap)
    }
}

/// C along one pass of admitted sets `adm` with steps `steps` (`steps[i]` from i to i + 1),
/// starting as near `start` as it may: the smallest rate that fits, C held wherever it can be.
/// `None` when no rate fits (the sets jump where the cap allows no turn to follow).
fn pass_c(adm: &[Admits], steps: &[Step], start: f64) -> Option<Vec<f64>> {
    let mut reach = Vec::new();
    let (mut lo, mut hi) = (1e-6_f64, MOST_RATE);
    if !feasible(adm, steps, hi, start, &mut reach) {
        return None;
    }
    if feasible(adm, steps, lo, start, &mut reach) {
        hi = lo;
    } else {
        for _ in 0..BISECTIONS {
            let mid = (lo * hi).sqrt();
            if feasible(adm, steps, mid, start, &mut reach) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
    }
    let rate = hi;
    feasible(adm, steps, rate, start, &mut reach);
    let mut out = Vec::with_capacity(adm.len());
    let mut c = start;
    for (i, r) in reach.iter().enumerate() {
        let slack = if i == 0 {
            f64::INFINITY
        } else {
            steps[i - 1].slack(rate)
        };
        // The backward sweep guarantees the next set is reachable from here.
        c = c.clamp(
            r.0.max(c - slack),
            r.1.min(c + slack).max(r.0.max(c - slack)),
        );
        out.push(c);
    }
    Some(out)
}

/// The most the steered axis may turn between neighbouring locations, rad, for a ball of
/// radius `radius` (mm) and a linearisation tolerance `tolerance` (mm). Between two locations
/// the machine moves the tip straight and turns the axis, so the ball's centre
/// `tip + R·axis` bows off the straight line between the two centres by `R(1 − cos(δ/2)) ≈
/// R·δ²/8` for an axis turn δ; kept within half the tolerance, `δ = √(4·tolerance/R)`.
pub fn max_step(radius: f64, tolerance: f64) -> f64 {
    (4.0 * tolerance / radius).sqrt()
}

/// Figures of the steering.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Steered {
    /// Largest angle between a steered axis and the planned one, rad.
    pub max_change: f64,
    /// Largest angle between the steered axes of neighbouring locations, rad.
    pub max_step: f64,
    /// Passes that keep their planned axes: no rate of C fitted within the cone and the step
    /// cap, or the steered tool would touch the part.
    pub kept_passes: usize,
}

/// Re-chooses every axis of the ball end mill's `path` within `cone` (rad) of the planned one
/// so that C moves little and slowly (module doc); tips move to keep the ball's centre.
/// `path` must be of a ball cutter of radius `radius` (mm). C turns the axis by at most about
/// `max_step` (rad) between neighbouring locations ([`max_step`]).
pub fn steer(
    path: &mut ToolPath,
    o: &Orienter,
    cone: f64,
    radius: f64,
    max_step: f64,
    clear: &(dyn Fn(&Vec3, &Vec3) -> bool + Sync),
) -> Steered {
    let mut out = Steered::default();
    let mut c_end = 0.0;
    for pass in &mut path.passes {
        if pass.points.is_empty() {
            continue;
        }
        let admitted = |both_ways: bool| -> Vec<Admits> {
            pass.points
                .iter()
                .map(|p| admits(o, &p.axis, cone, both_ways))
                .collect()
        };
        let steps: Vec<Step> = pass
            .points
            .windows(2)
            .map(|w| {
                // C turning by ΔC turns an axis θ from the pole by about ΔC·sin θ.
                let sin = |k: &Vec3| k.x.hypot(k.y) / k.norm();
                let sin = sin(&w[0].axis).max(sin(&w[1].axis)).max(1e-9);
                Step {
                    length: (w[1].tip - w[0].tip).norm().max(SAME_PLACE),
                    cap: max_step / sin,
                }
            })
            .collect();
        // Both tilt directions where the machine has them; where the sets then jump (the
        // axis leaves the reach of the negative tilt on the other copy), the positive tilt
        // only; where even that does not fit, the pass keeps its planned axes.
        let Some(cs) = pass_c(&admitted(true), &steps, c_end)
            .or_else(|| pass_c(&admitted(false), &steps, c_end))
        else {
            out.kept_passes += 1;
            continue;
        };
        let steered: Vec<(Vec3, Vec3)> = pass
            .points
            .iter()
            .zip(&cs)
            .map(|(p, c)| {
                let mut angles = o.keeping_c(&p.axis, *c);
                // A machine that cannot tilt both ways stands at the pole instead (within
                // the cone: the admitted C then are any only where the pole is within it).
                angles.tilt = angles.tilt.clamp(o.tilt_limit.min, o.tilt_limit.max);
                let axis = o.axis(angles);
                (p.tip + p.axis * radius - axis * radius, axis)
            })
            .collect();
        // The ball is the same, but its flutes and shank lean otherwise: a pass where the
        // steered tool would touch the part keeps its planned axes.
        if !steered.par_iter().all(|(tip, axis)| clear(tip, axis)) {
            out.kept_passes += 1;
            continue;
        }
        let mut last: Option<Vec3> = None;
        for (p, (tip, axis)) in pass.points.iter_mut().zip(steered) {
            out.max_change = out.max_change.max(axis.angle(&p.axis));
            p.tip = tip;
            p.axis = axis;
            if let Some(l) = last {
                out.max_step = out.max_step.max(l.angle(&axis));
            }
            last = Some(axis);
        }
        c_end = *cs.last().unwrap_or(&c_end);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::{Cutter, CutterShape};
    use crate::toolpath::{CutterLocation, Pass};
    use tezgah_kinematics::trunnion::TiltAxis;
    use tezgah_kinematics::{JointKind, JointLimit};

    fn table_ac() -> Orienter {
        Orienter {
            tilt_axis: TiltAxis::X,
            tilt_limit: JointLimit::new("a", JointKind::Rotary, -30f64.to_radians(), 2.0944),
            c_limit: JointLimit::endless("c"),
            pole_sin: 1e-6,
        }
    }

    /// A pass of ball locations 0.2 mm apart whose axis sweeps along X past the pole at
    /// `miss_deg` on the Y side, ±`sweep_deg`.
    fn pass_by_pole(miss_deg: f64, sweep_deg: f64) -> ToolPath {
        let miss = miss_deg.to_radians();
        let n = 121;
        let points = (0..n)
            .map(|i| {
                let t = (-1.0 + 2.0 * i as f64 / (n - 1) as f64) * sweep_deg.to_radians();
                let axis = Vec3::new(t.sin(), miss.sin(), t.cos() * miss.cos()).normalize();
                let centre = Vec3::new(0.2 * i as f64, 0.0, 3.0);
                CutterLocation {
                    tip: centre - axis * 3.0,
                    axis,
                    contact: centre - Vec3::z() * 3.0,
                    normal: Vec3::z(),
                    uv: (0.0, 0.0),
                }
            })
            .collect();
        ToolPath {
            cutter: Cutter::standard(CutterShape::Ball { radius: 3.0 }),
            passes: vec![Pass { points }],
        }
    }

    fn c_of(o: &Orienter, path: &ToolPath) -> Vec<f64> {
        let mut last = 0.0;
        path.passes[0]
            .points
            .iter()
            .map(|p| {
                let a = o.solutions(&p.axis);
                // The solution nearest the last C, mod 2π.
                let pick = a
                    .iter()
                    .map(|s| last + tezgah_kinematics::angle::wrap_pi(s.c - last))
                    .min_by(|x, y| (x - last).abs().total_cmp(&(y - last).abs()))
                    .unwrap();
                last = pick;
                pick
            })
            .collect()
    }

    fn travel(c: &[f64]) -> f64 {
        c.windows(2).map(|w| (w[1] - w[0]).abs()).sum()
    }

    #[test]
    fn within_the_cone_c_is_held_and_the_centres_stay() {
        let o = table_ac();
        let planned = pass_by_pole(2.0, 12.0);
        let mut path = planned.clone();
        let cone = 10f64.to_radians();
        let got = steer(&mut path, &o, cone, 3.0, 1.0, &|_, _| true);
        assert!(got.max_change <= cone + 1e-12, "{got:?}");
        // Planned: C swings about half a turn at the pole.
        assert!(travel(&c_of(&o, &planned)).to_degrees() > 150.0);
        for (p, q) in path.passes[0].points.iter().zip(&planned.passes[0].points) {
            assert!(p.axis.angle(&q.axis) <= cone + 1e-12);
            let (a, b) = (p.tip + p.axis * 3.0, q.tip + q.axis * 3.0);
            assert!((a - b).norm() < 1e-12, "the ball's centre moved");
        }
        // Every steered axis lies in one meridian plane (A changes sign on the way): C held,
        // to the bisection's lowest rate (1e-6 rad/mm over the pass's 24 mm: 0.0014°).
        let held = travel(&c_of(&o, &path)).to_degrees();
        assert!(held < 0.0015, "C turns {held}°");
    }

    /// The C values (degrees, a 0.01° grid over ±180°) whose best axis lies within `cone` of
    /// `k`, found by trying each: the oracle for the intervals.
    fn admitted_by_search(o: &Orienter, k: &Vec3, cone: f64) -> Vec<f64> {
        (-18000..=18000)
            .map(|i| i as f64 * 0.01)
            .filter(|c| {
                let a = o.keeping_c(k, c.to_radians());
                o.tilt_limit.contains(a.tilt) && o.axis(a).angle(k) <= cone
            })
            .collect()
    }

    #[test]
    fn past_the_cone_c_turns_only_what_it_must() {
        let o = table_ac();
        let cone = 10f64.to_radians();
        let planned = pass_by_pole(15.0, 12.0);
        let mut path = planned.clone();
        let got = steer(&mut path, &o, cone, 3.0, 1.0, &|_, _| true);
        assert!(got.max_change <= cone + 1e-9, "{got:?}");
        // The axis passes 15° from the pole: C must go from the first location's admitted
        // C (all below the middle's azimuth, 0°) to the last's (all above): at least the gap
        // between them, which the steered C turns and no more.
        let pts = &planned.passes[0].points;
        let first = admitted_by_search(&o, &pts[0].axis, cone);
        let last = admitted_by_search(&o, &pts[pts.len() - 1].axis, cone);
        let (hi_first, lo_last) = (
            first
                .iter()
                .copied()
                .filter(|c| c.abs() < 90.0)
                .fold(f64::MIN, f64::max),
            last.iter()
                .copied()
                .filter(|c| c.abs() < 90.0)
                .fold(f64::MAX, f64::min),
        );
        let need = lo_last - hi_first;
        assert!(need > 10.0, "{need}");
        let steered = travel(&c_of(&o, &path)).to_degrees();
        assert!((steered - need).abs() < 0.05, "{steered} vs {need}");
        // The planned axes turn C by the whole swing of their azimuth, ±38.6°.
        let planned_travel = travel(&c_of(&o, &planned)).to_degrees();
        assert!((planned_travel - 77.2).abs() < 0.5, "{planned_travel}");
    }
}

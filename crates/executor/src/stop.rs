//! The joints' jerk-limited stop: every joint brought from its commanded position, velocity
//! and acceleration to rest on its own time-optimal profile (the one solver's velocity
//! interface, [`reach_velocity`] to speed 0, as Ruckig's; a start acceleration past the limit
//! is braked back to it first), all starting together. One piece for the real-time side's underrun stop and the manual modes'
//! abort, hold and failed homing. Fixed size and closed form, no allocation: it runs inside
//! the real-time period.
//!
//! Each joint stops on its own time, so a tool on a path leaves it by the difference: after an
//! underrun that is a fault, the stop only makes it harmless (no jump, no limit exceeded).

use tezgah_kinematics::Joints;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::profile::{reach_velocity, stopping_displacement, Limits, State};
use tezgah_motion::Profile;

use crate::setpoint::SetPoint;

const MAX: usize = tezgah_kinematics::pose::MAX_JOINTS;

/// The joint limits a stop obeys (internal units, machine-file order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopLimits {
    /// Only to build the solver's [`Limits`]: a stop never speeds up.
    pub max_velocity: Joints,
    pub max_acceleration: Joints,
    pub max_jerk: Joints,
}

impl StopLimits {
    /// The machine's joint limits as the planner holds them (internal units).
    pub fn of(machine: &PlanMachine) -> StopLimits {
        let j = |v: &[f64]| Joints::from_slice(v).unwrap_or_else(|_| Joints::zeros(0));
        StopLimits {
            max_velocity: j(&machine.max_velocity),
            max_acceleration: j(&machine.max_acceleration),
            max_jerk: j(&machine.max_jerk),
        }
    }
}

/// Distance a jerk-limited stop from speed `v` and acceleration `a` travels under `limits`
/// (the same solver, along a path or a joint; signed, the way the speed points).
pub fn stopping_distance(v: f64, a: f64, limits: &Limits) -> f64 {
    let st = State {
        s: 0.0,
        v,
        a,
        j: 0.0,
    };
    stopping_displacement(st, limits).unwrap_or(0.0)
}

/// The time-optimal change from `from` to speed `target` at zero acceleration (the solver's
/// velocity interface): the stops here, JOG and the homing searches. A state that is not
/// finite (which the executor's own profiles never produce) holds still where it can.
pub fn velocity_profile(from: State, target: f64, limits: &Limits) -> Profile {
    reach_velocity(from, target, limits)
        .unwrap_or_else(|_| Profile::at_rest(if from.s.is_finite() { from.s } else { 0.0 }))
}

/// Relative slack on a path state's acceleration past the limit (the plan's own rounding).
const PATH_STOP_SLACK: f64 = 1e-9;

/// The stop from path state `x` (from s = 0) under `l`; `None` when the acceleration is past
/// the limit beyond rounding, or the stop would need the speed to go negative (braking harder
/// than the jerk can release: v + a|a|/(2J) < 0) — the path cannot be driven backward.
pub fn path_stop(x: &State, l: &Limits) -> Option<Profile> {
    let a_max = l.max_acceleration();
    if x.v.is_nan() || x.v < 0.0 || x.a.abs() > a_max * (1.0 + PATH_STOP_SLACK) {
        return None;
    }
    let a = x.a.clamp(-a_max, a_max);
    if x.v + a * a.abs() / (2.0 * l.max_jerk()) < 0.0 {
        return None;
    }
    let start = State {
        s: 0.0,
        v: x.v,
        a,
        j: 0.0,
    };
    reach_velocity(start, 0.0, l).ok()
}

/// A joint state on the stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointState {
    pub position: Joints,
    pub velocity: Joints,
    pub acceleration: Joints,
}

/// Every joint's stop, evaluated together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointStop {
    ramps: [Option<Profile>; MAX],
    len: usize,
}

impl JointStop {
    /// The stop from the state a set-point commands (its velocity and acceleration exact:
    /// see [`crate::setpoint::History`]) under `limits`.
    pub fn new(from: &SetPoint, limits: &StopLimits) -> JointStop {
        let len = from.position.len();
        let mut ramps = [None; MAX];
        for (i, ramp) in ramps.iter_mut().enumerate().take(len) {
            let g = |q: &Joints| q.as_slice().get(i).copied().unwrap_or(0.0);
            let start = State {
                s: from.position[i],
                v: from.velocity[i],
                a: from.acceleration[i],
                j: 0.0,
            };
            let l = Limits::new(
                g(&limits.max_velocity),
                g(&limits.max_acceleration),
                g(&limits.max_jerk),
            );
            // A joint with no limits to stop with keeps its position (nothing to ramp).
            if let Ok(l) = l {
                *ramp = Some(velocity_profile(start, 0.0, &l));
            }
        }
        JointStop { ramps, len }
    }

    /// Time until the last joint is at rest, s.
    pub fn duration(&self) -> f64 {
        self.ramps[..self.len]
            .iter()
            .flatten()
            .map(Profile::duration)
            .fold(0.0, f64::max)
    }

    /// The joints t seconds into the stop (exactly at rest once a joint's ramp is over:
    /// rounding in its sums must not leave a creep).
    pub fn at(&self, t: f64) -> JointState {
        let z = Joints::zeros(self.len);
        let (mut position, mut velocity, mut acceleration) = (z, z, z);
        for (i, ramp) in self.ramps[..self.len].iter().enumerate() {
            let Some(r) = ramp else {
                position[i] = f64::NAN;
                continue;
            };
            let st = if t >= r.duration() {
                r.end()
            } else {
                r.state_at(t)
            };
            position[i] = st.s;
            velocity[i] = st.v;
            acceleration[i] = st.a;
        }
        JointState {
            position,
            velocity,
            acceleration,
        }
    }
}

/// A stop played one period at a time: the states at Ts, 2Ts, … up to and including the first
/// at or past its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlayedStop {
    stop: JointStop,
    /// Held position of joints without a ramp.
    from: Joints,
    period: f64,
    played: u64,
    over: bool,
}

impl PlayedStop {
    /// The stop from `from` under `limits`, played at `period`.
    pub fn new(from: &SetPoint, limits: &StopLimits, period: f64) -> PlayedStop {
        PlayedStop {
            stop: JointStop::new(from, limits),
            from: from.position,
            period,
            played: 0,
            over: false,
        }
    }

    /// True once the state at rest has been played.
    pub fn is_over(&self) -> bool {
        self.over
    }
}

impl Iterator for PlayedStop {
    type Item = JointState;

    /// The next period's state, `None` once the stop is over.
    fn next(&mut self) -> Option<JointState> {
        if self.over {
            return None;
        }
        self.played += 1;
        let t = self.played as f64 * self.period;
        self.over = t >= self.stop.duration();
        let mut s = self.stop.at(t);
        for (p, held) in s
            .position
            .as_mut_slice()
            .iter_mut()
            .zip(self.from.as_slice())
        {
            if p.is_nan() {
                *p = *held;
            }
        }
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn one(p: f64, v: f64, a: f64, a_max: f64, j_max: f64) -> JointStop {
        let j = |x: f64| Joints::from_slice(&[x]).unwrap();
        let sp = SetPoint {
            index: 0,
            line: 0,
            position: j(p),
            velocity: j(v),
            acceleration: j(a),
        };
        let limits = StopLimits {
            max_velocity: j(1000.0),
            max_acceleration: j(a_max),
            max_jerk: j(j_max),
        };
        JointStop::new(&sp, &limits)
    }

    fn at(s: &JointStop, t: f64) -> (f64, f64, f64) {
        let st = s.at(t);
        (st.position[0], st.velocity[0], st.acceleration[0])
    }

    /// The textbook case: from v with a = 0 and A reached, the stop takes v/A + A/J and
    /// travels v²/(2A) + vA/(2J) (the jerk-limited braking distance).
    #[test]
    fn from_cruise_matches_the_closed_form() {
        let (v, a_max, j_max) = (100.0, 1000.0, 20_000.0);
        let s = one(0.0, v, 0.0, a_max, j_max);
        let t = s.duration();
        assert!((t - (v / a_max + a_max / j_max)).abs() < 1e-12);
        let (p, ve, ae) = at(&s, t);
        assert!((p - (v * v / (2.0 * a_max) + v * a_max / (2.0 * j_max))).abs() < 1e-9);
        assert_eq!((ve, ae), (0.0, 0.0));
        let l = Limits::new(v, a_max, j_max).unwrap();
        assert!((stopping_distance(v, 0.0, &l) - p).abs() < 1e-12);
    }

    /// Played at the period: one state per period, the last at rest, then nothing.
    #[test]
    fn played_ends_at_rest() {
        let j = |x: f64| Joints::from_slice(&[x, 3.0]).unwrap();
        let sp = SetPoint {
            index: 0,
            line: 0,
            position: j(1.0),
            velocity: Joints::from_slice(&[50.0, 0.0]).unwrap(),
            acceleration: Joints::zeros(2),
        };
        let limits = StopLimits {
            max_velocity: j(1000.0),
            max_acceleration: j(1000.0),
            max_jerk: j(20_000.0),
        };
        let mut played = PlayedStop::new(&sp, &limits, 1e-3);
        let d = JointStop::new(&sp, &limits).duration();
        let n = played.by_ref().count();
        assert_eq!(n, (d / 1e-3).ceil() as usize);
        assert!(played.is_over());
    }

    proptest! {
        /// Any start state within the limits: at rest at the end, velocity never changes
        /// sign beyond rounding (no backing up), acceleration within A, jerk within J.
        #[test]
        fn stops_within_limits(v in -300.0..300.0f64, af in -1.0..=1.0f64,
                               a_max in 10.0..5000.0f64, j_max in 100.0..1e6f64) {
            let a0 = af * a_max;
            let s = one(1.0, v, a0, a_max, j_max);
            let t_end = s.duration();
            prop_assert!(t_end.is_finite());
            let coast = v + a0 * a0.abs() / (2.0 * j_max);
            let n = 400;
            let mut prev = at(&s, 0.0);
            let mut crossings = 0;
            for k in 1..=n {
                let t = t_end * k as f64 / n as f64;
                let (p, vv, aa) = at(&s, t);
                prop_assert!(aa.abs() <= a_max * (1.0 + 1e-9), "a {aa}");
                // The velocity crosses zero at most once (only when the start acceleration
                // already carries it past zero: then the stop settles on coast's side).
                if vv * prev.1 < 0.0 && vv.abs().min(prev.1.abs()) > 1e-9 * (1.0 + v.abs()) {
                    crossings += 1;
                }
                let dt = t_end / n as f64;
                prop_assert!((aa - prev.2).abs() <= j_max * dt * (1.0 + 1e-9) + 1e-9);
                prev = (p, vv, aa);
            }
            prop_assert!(crossings <= 1);
            if crossings == 1 {
                prop_assert!(v * coast < 0.0, "v {v} coast {coast}");
            }
            let (_, ve, ae) = at(&s, t_end);
            prop_assert_eq!((ve, ae), (0.0, 0.0));
            // Just before the end the state is continuous with rest (no jump into it).
            let dt = 1e-9 * t_end;
            let (_, ve, ae) = at(&s, t_end - dt);
            prop_assert!(ae.abs() <= j_max * dt * (1.0 + 1e-6) + 1e-9 * a_max, "a {ae}");
            prop_assert!(ve.abs() <= j_max * dt * dt + 1e-9 * (1.0 + v.abs()), "v {ve}");
        }

        /// A start a little beyond the acceleration limit (a state estimate a hair past it)
        /// is not clamped — that would be a jump in acceleration — but brought back at the
        /// jerk limit first, as Ruckig's brake does; beyond the start's own magnitude it
        /// never goes, and within A once back.
        #[test]
        fn a_start_past_the_limit_is_braked_back(v in -300.0..300.0f64, af in 1.0..1.05f64,
                                                 sign in prop::bool::ANY) {
            let (a_max, j_max) = (2000.0, 50_000.0);
            let a0 = if sign { af * a_max } else { -af * a_max };
            let s = one(0.0, v, a0, a_max, j_max);
            let t_end = s.duration();
            let back = (a0.abs() - a_max) / j_max;
            let n = 400;
            let mut prev = at(&s, 0.0).2;
            prop_assert_eq!(prev, a0);
            for k in 1..=n {
                let t = t_end * k as f64 / n as f64;
                let aa = at(&s, t).2;
                prop_assert!(aa.abs() <= a0.abs() * (1.0 + 1e-9), "a {aa}");
                if t >= back * (1.0 + 1e-9) {
                    prop_assert!(aa.abs() <= a_max * (1.0 + 1e-9), "a {aa} at {t}");
                }
                prop_assert!((aa - prev).abs() <= j_max * t_end / n as f64 * (1.0 + 1e-9) + 1e-9);
                prev = aa;
            }
            prop_assert_eq!(at(&s, t_end).1, 0.0);
        }
    }
}

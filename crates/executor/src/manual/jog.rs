//! JOG: one joint moves continuously at a set speed until told to stop — velocity mode
//! (Kelekçi, 2021, §4.1). Starts, speed changes (override steps, 0–200 %) and stops are
//! jerk-limited velocity profiles (the one solver's velocity interface,
//! [`crate::stop::velocity_profile`]) taking effect at the next period; a stop takes exactly the
//! jerk-limited minimum distance from the state it is asked in. Toward a soft limit the jog
//! brakes on its own at the instant (found between periods) from which the time-optimal stop
//! ends exactly on the limit, so no set-point ever lies past it.

use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::profile::{Limits, State};
use tezgah_motion::Profile;

use super::{check_start, JointAxis, ManualError};
use crate::setpoint::SetPoint;
use crate::speed_override::Override;
use crate::stop::{stopping_distance, velocity_profile};

/// Which way a manual move goes along its joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    Plus,
    Minus,
}

impl Direction {
    pub fn sign(self) -> f64 {
        match self {
            Direction::Plus => 1.0,
            Direction::Minus => -1.0,
        }
    }
}

/// A continuous jog of one joint; poll [`Iterator::next`] once per period.
#[derive(Debug, Clone)]
pub struct Jog {
    axis: JointAxis,
    limits: Limits,
    joint: usize,
    /// Every joint's position (the jogged one is overwritten each period).
    held: Joints,
    dir: f64,
    period: f64,
    start_index: u64,
    /// Periods emitted so far; the last set-point was at t = emitted·Ts.
    emitted: u64,
    /// Start time of the current ramp and the ramp (State.s is the joint's position).
    t0: f64,
    ramp: Profile,
    /// Set speed (internal units/s) and override factor.
    speed: f64,
    factor: f64,
    /// The soft limit ahead (±∞ for an endless joint).
    limit: f64,
    stopping: bool,
    braked_at_limit: bool,
    done: bool,
}

impl Jog {
    /// Jogs `joint` of `machine` from `start` (at rest; the set-point at `index` is the start)
    /// in `direction` at `speed` (file units per second, capped at the joint's max_velocity).
    pub fn new(
        machine: &Machine,
        joint: usize,
        start: &Joints,
        direction: Direction,
        speed: f64,
        index: u64,
    ) -> Result<Jog, ManualError> {
        let axis = JointAxis::from_machine(machine, joint)?;
        let limits = axis.limits()?;
        check_start(machine, start)?;
        let speed = axis.speed(speed)?;
        let dir = direction.sign();
        let limit = if dir > 0.0 { axis.max } else { axis.min };
        let x0 = start[joint];
        if dir * (limit - x0) <= 0.0 {
            return Err(axis.beyond(x0, limit));
        }
        let rest = State {
            s: x0,
            ..State::default()
        };
        let mut jog = Jog {
            ramp: velocity_profile(rest, 0.0, &limits),
            axis,
            limits,
            joint,
            held: *start,
            dir,
            period: machine.motion.period_s,
            start_index: index,
            emitted: 0,
            t0: 0.0,
            speed,
            factor: 1.0,
            limit,
            stopping: false,
            braked_at_limit: false,
            done: false,
        };
        jog.retarget();
        Ok(jog)
    }

    /// Sets the speed override; the speed changes smoothly from the next period.
    pub fn set_override(&mut self, speed_override: Override) {
        self.factor = speed_override.factor();
        self.retarget();
    }

    /// Asks for a stop: the joint comes to rest in the jerk-limited minimum distance.
    pub fn stop(&mut self) {
        if !self.stopping {
            self.begin(self.now(), 0.0);
            self.stopping = true;
        }
    }

    /// The target speed in force (signed, internal units).
    pub fn target_speed(&self) -> f64 {
        if self.stopping {
            0.0
        } else {
            self.dir * (self.speed * self.factor).min(self.axis.max_velocity)
        }
    }

    /// True once the jog braked by itself for the soft limit.
    pub fn braked_at_limit(&self) -> bool {
        self.braked_at_limit
    }

    /// True while (or after) stopping.
    pub fn is_stopping(&self) -> bool {
        self.stopping
    }

    /// The state of the jogged joint at the last set-point.
    pub fn state(&self) -> State {
        self.ramp.state_at(self.now() - self.t0)
    }

    /// Where the joint would come to rest if a stop were asked now.
    pub fn stop_position(&self) -> f64 {
        let st = self.state();
        st.s + stopping_distance(st.v, st.a, &self.limits)
    }

    fn now(&self) -> f64 {
        self.emitted as f64 * self.period
    }

    fn retarget(&mut self) {
        if !self.stopping {
            self.begin(self.now(), self.target_speed());
        }
    }

    fn begin(&mut self, t: f64, target: f64) {
        let st = self.ramp.state_at(t - self.t0);
        self.ramp = velocity_profile(st, target, &self.limits);
        self.t0 = t;
    }

    /// How far past the limit a stop begun at `t` would end (≤ 0: it stops in time).
    fn overrun(&self, t: f64) -> f64 {
        let st = self.ramp.state_at(t - self.t0);
        let stop = stopping_distance(st.v, st.a, &self.limits);
        self.dir * (st.s + stop - self.limit)
    }

    /// Brakes for the soft limit if the period ending at `t` would carry the joint past the
    /// last instant from which a stop still ends on it.
    fn guard_limit(&mut self, t: f64) {
        if self.stopping || !self.limit.is_finite() || self.overrun(t) <= 0.0 {
            return;
        }
        // overrun ≤ 0 at the last set-point (by induction), > 0 at t: bisect the crossing.
        let (mut lo, mut hi) = (self.now().max(self.t0), t);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.overrun(mid) > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        self.begin(lo, 0.0);
        self.stopping = true;
        self.braked_at_limit = true;
    }
}

impl Iterator for Jog {
    type Item = SetPoint;

    fn next(&mut self) -> Option<SetPoint> {
        if self.done {
            return None;
        }
        let t = (self.emitted + 1) as f64 * self.period;
        self.guard_limit(t);
        let mut st = self.ramp.state_at(t - self.t0);
        self.emitted += 1;
        if self.stopping && t - self.t0 >= self.ramp.duration() {
            self.done = true;
            st = State {
                s: self.ramp.end().s,
                ..State::default()
            };
        }
        // Rounding must not put a set-point past the limit.
        if self.limit.is_finite() && self.dir * (st.s - self.limit) > 0.0 {
            st.s = self.limit;
        }
        let mut sp = SetPoint::at_rest(self.start_index + self.emitted, 0, self.held);
        sp.position[self.joint] = st.s;
        sp.velocity[self.joint] = st.v;
        sp.acceleration[self.joint] = st.a;
        self.held[self.joint] = st.s;
        Some(sp)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{check_limits, positions};
    use super::*;
    use proptest::prelude::*;
    use tezgah_motion::profile::{min_stopping_distance, Limits};

    fn mill() -> Machine {
        Machine::builtin("mill3").unwrap()
    }

    #[test]
    fn cruises_at_the_set_speed_and_stops_in_the_minimum_distance() {
        let m = mill();
        let start = Joints::new([-150.0, 0.0, 0.0]);
        let mut jog = Jog::new(&m, 0, &start, Direction::Plus, 50.0, 10).unwrap();
        let mut sps: Vec<SetPoint> = jog.by_ref().take(500).collect();
        assert_eq!(sps[0].index, 11);
        let cruise = sps.last().unwrap();
        assert!((cruise.velocity[0] - 50.0).abs() < 1e-9);
        assert_eq!(cruise.acceleration[0], 0.0);
        let at_request = cruise.position[0];
        jog.stop();
        sps.extend(jog.by_ref());
        let last = sps.last().unwrap();
        assert_eq!((last.velocity[0], last.acceleration[0]), (0.0, 0.0));
        let l = Limits::new(200.0, 2000.0, 50000.0).unwrap();
        let d = min_stopping_distance(50.0, &l).unwrap();
        assert!(
            (last.position[0] - at_request - d).abs() < 1e-9,
            "{} vs {d}",
            last.position[0] - at_request
        );
        // the other joints never moved
        assert!(sps
            .iter()
            .all(|s| s.position[1] == 0.0 && s.position[2] == 0.0));
        check_limits(&positions(&start, &sps, 0), 1e-3, 200.0, 2000.0, 50000.0).unwrap();
        // the set-point's velocity is the derivative of its position (exact evaluation)
        for w in sps.windows(2) {
            let fd = (w[1].position[0] - w[0].position[0]) / 1e-3;
            let mean = 0.5 * (w[0].velocity[0] + w[1].velocity[0]);
            assert!((fd - mean).abs() < 0.05, "{fd} {mean}");
        }
    }

    #[test]
    fn override_steps_change_the_speed_smoothly() {
        let m = mill();
        let start = Joints::new([-190.0, 0.0, 0.0]);
        let mut jog = Jog::new(&m, 0, &start, Direction::Plus, 80.0, 0).unwrap();
        let mut sps = Vec::new();
        for pct in [25.0, 100.0, 50.0, 200.0, 0.0] {
            jog.set_override(Override::new(pct).unwrap());
            sps.extend(jog.by_ref().take(300));
            let v = sps.last().unwrap().velocity[0];
            let want = (80.0 * pct / 100.0).min(200.0);
            assert!((v - want).abs() < 1e-9, "{pct}%: {v}");
        }
        // at 0 % the jog is alive but still
        assert!(!jog.is_stopping());
        jog.stop();
        sps.extend(jog.by_ref());
        check_limits(&positions(&start, &sps, 0), 1e-3, 200.0, 2000.0, 50000.0).unwrap();
    }

    #[test]
    fn brakes_onto_the_soft_limit_never_past_it() {
        let m = mill();
        // x max is 200: from far (full speed) and from near (still speeding up), both ways
        for (x0, dir, speed) in [
            (-150.0, Direction::Plus, 200.0),
            (199.0, Direction::Plus, 200.0),
            (199.999, Direction::Plus, 50.0),
            (150.0, Direction::Minus, 120.0),
            (-199.5, Direction::Minus, 50.0),
        ] {
            let start = Joints::new([x0, 0.0, 0.0]);
            let jog = Jog::new(&m, 0, &start, dir, speed, 0).unwrap();
            let sps: Vec<SetPoint> = jog.take(100_000).collect();
            let limit = if dir == Direction::Plus {
                200.0
            } else {
                -200.0
            };
            let s = dir.sign();
            assert!(sps.iter().all(|p| s * (p.position[0] - limit) <= 0.0));
            let last = sps.last().unwrap();
            assert!(
                (last.position[0] - limit).abs() < 1e-9,
                "{x0}: {}",
                last.position[0]
            );
            assert_eq!(last.velocity[0], 0.0);
            check_limits(&positions(&start, &sps, 0), 1e-3, 200.0, 2000.0, 50000.0)
                .unwrap_or_else(|e| panic!("{x0}: {e}"));
        }
    }

    #[test]
    fn refuses_bad_requests() {
        let m = mill();
        let at_max = Joints::new([200.0, 0.0, 0.0]);
        assert!(matches!(
            Jog::new(&m, 0, &at_max, Direction::Plus, 50.0, 0),
            Err(ManualError::BeyondLimit { .. })
        ));
        assert!(Jog::new(&m, 0, &at_max, Direction::Minus, 50.0, 0).is_ok());
        let z = Joints::zeros(3);
        assert!(matches!(
            Jog::new(&m, 3, &z, Direction::Plus, 50.0, 0),
            Err(ManualError::NoSuchJoint { .. })
        ));
        assert!(matches!(
            Jog::new(&m, 0, &z, Direction::Plus, -5.0, 0),
            Err(ManualError::Speed { .. })
        ));
        assert!(matches!(
            Jog::new(&m, 0, &Joints::zeros(2), Direction::Plus, 5.0, 0),
            Err(ManualError::JointCount { .. })
        ));
        assert!(matches!(
            Jog::new(
                &m,
                0,
                &Joints::new([0.0, f64::NAN, 0.0]),
                Direction::Plus,
                5.0,
                0
            ),
            Err(ManualError::NotFinite { joint: 1, .. })
        ));
    }

    #[test]
    fn endless_rotary_jogs_in_degrees() {
        let m = Machine::builtin("yzca").unwrap();
        let start = Joints::zeros(4);
        // C: 20 °/s default of Kelekçi (2021, §4.1)
        let mut jog = Jog::new(
            &m,
            2,
            &start,
            Direction::Minus,
            super::super::default_jog_speed(tezgah_kinematics::JointKind::Rotary),
            0,
        )
        .unwrap();
        let v = jog.by_ref().take(2000).last().unwrap().velocity[2];
        assert!((v + 20f64.to_radians()).abs() < 1e-12);
        jog.stop();
        assert!(jog.last().unwrap().velocity[2] == 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn random_sessions_hold_the_limits(
            x0 in -199.0..199.0f64,
            plus in any::<bool>(),
            speed in 1.0..300.0f64,
            steps in proptest::collection::vec((0.0..200.0f64, 1usize..120), 1..5),
        ) {
            let m = mill();
            let start = Joints::new([x0, 0.0, 0.0]);
            let dir = if plus { Direction::Plus } else { Direction::Minus };
            let mut jog = Jog::new(&m, 0, &start, dir, speed, 0).unwrap();
            let mut sps = Vec::new();
            for (pct, n) in steps {
                jog.set_override(Override::new(pct).unwrap());
                sps.extend(jog.by_ref().take(n));
            }
            let request = jog.stop_position();
            jog.stop();
            sps.extend(jog.by_ref().take(100_000));
            let last = sps.last().unwrap();
            prop_assert_eq!(last.velocity[0], 0.0);
            prop_assert!(sps.iter().all(|p| (-200.0..=200.0).contains(&p.position[0])));
            // a stop asked by the operator ends where the stop position said
            prop_assert!((last.position[0] - request).abs() < 1e-9 || jog.braked_at_limit());
            let r = check_limits(&positions(&start, &sps, 0), 1e-3, 200.0, 2000.0, 50000.0);
            prop_assert!(r.is_ok(), "{:?}", r);
        }
    }
}

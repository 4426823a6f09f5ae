//! INC: one press moves one joint by a fixed small step, rest to rest — position mode
//! (Kelekçi, 2021, §4.1: X1 = 0.0001, X10 = 0.001, X100 = 0.01, X1000 = 0.1 mm; the same numbers
//! in degrees on a rotary joint). The move is the motion crate's time-optimal 7-phase profile
//! (`tezgah_motion::profile::solve`) evaluated exactly at each period; the last set-point is the
//! exact target, so steps add up without drift.

use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::profile::{solve, Limits, Profile};

use super::jog::Direction;
use super::{check_start, JointAxis, ManualError};
use crate::setpoint::SetPoint;

/// Smallest INC step, file units (mm or degrees).
pub const MIN_STEP: f64 = 0.0001;
/// Largest INC step, file units.
pub const MAX_STEP: f64 = 0.1;

/// A validated INC step in file units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IncStep(f64);

impl IncStep {
    pub const X1: IncStep = IncStep(0.0001);
    pub const X10: IncStep = IncStep(0.001);
    pub const X100: IncStep = IncStep(0.01);
    pub const X1000: IncStep = IncStep(0.1);

    /// Any step from [`MIN_STEP`] to [`MAX_STEP`] (file units).
    pub fn new(value: f64) -> Result<IncStep, ManualError> {
        // a step typed as 0.1 must pass even if it was computed as 0.1 + 1 ulp
        let slack = 1e-12;
        if value.is_finite()
            && value >= MIN_STEP * (1.0 - slack)
            && value <= MAX_STEP * (1.0 + slack)
        {
            Ok(IncStep(value))
        } else {
            Err(ManualError::Step { value })
        }
    }

    pub fn value(self) -> f64 {
        self.0
    }
}

/// One INC move; poll [`Iterator::next`] once per period.
#[derive(Debug, Clone)]
pub struct Inc {
    joint: usize,
    held: Joints,
    start: f64,
    dir: f64,
    target: f64,
    profile: Profile,
    period: f64,
    start_index: u64,
    emitted: u64,
    done: bool,
}

impl Inc {
    /// Moves `joint` of `machine` from `start` (at rest; the set-point at `index`) by `step` in
    /// `direction`, at most at `speed` (file units per second). A step that would end past a
    /// soft limit is refused.
    pub fn new(
        machine: &Machine,
        joint: usize,
        start: &Joints,
        direction: Direction,
        step: IncStep,
        speed: f64,
        index: u64,
    ) -> Result<Inc, ManualError> {
        let axis = JointAxis::from_machine(machine, joint)?;
        check_start(machine, start)?;
        let v = axis.speed(speed)?;
        let dir = direction.sign();
        let distance = step.value() / axis.to_file;
        let x0 = start[joint];
        let target = x0 + dir * distance;
        if target > axis.max {
            return Err(axis.beyond(target, axis.max));
        }
        if target < axis.min {
            return Err(axis.beyond(target, axis.min));
        }
        let motion = |reason: String| ManualError::Motion {
            name: axis.name.clone(),
            reason,
        };
        let limits = Limits::new(v, axis.max_acceleration, axis.max_jerk)
            .map_err(|e| motion(format!("{e:?}")))?;
        let profile = solve(distance, 0.0, 0.0, &limits).map_err(|e| motion(e.to_string()))?;
        Ok(Inc {
            joint,
            held: *start,
            start: x0,
            dir,
            target,
            profile,
            period: machine.motion.period_s,
            start_index: index,
            emitted: 0,
            done: false,
        })
    }

    /// The move's duration, s (the last set-point is at the next period at or after it).
    pub fn duration(&self) -> f64 {
        self.profile.duration()
    }
}

impl Iterator for Inc {
    type Item = SetPoint;

    fn next(&mut self) -> Option<SetPoint> {
        if self.done {
            return None;
        }
        self.emitted += 1;
        let t = self.emitted as f64 * self.period;
        let mut sp = SetPoint::at_rest(self.start_index + self.emitted, 0, self.held);
        if t >= self.profile.duration() {
            self.done = true;
            sp.position[self.joint] = self.target;
        } else {
            let st = self.profile.state_at(t);
            sp.position[self.joint] = self.start + self.dir * st.s;
            sp.velocity[self.joint] = self.dir * st.v;
            sp.acceleration[self.joint] = self.dir * st.a;
        }
        Some(sp)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{check_limits, positions};
    use super::*;

    #[test]
    fn steps_are_exact_and_jerk_limited() {
        let m = Machine::builtin("mill3").unwrap();
        let mut at = Joints::new([0.0, 0.0, 0.0]);
        let mut all = Vec::new();
        let mut index = 0;
        // ten presses of each size, both ways
        for step in [IncStep::X1, IncStep::X10, IncStep::X100, IncStep::X1000] {
            for dir in [Direction::Plus, Direction::Minus] {
                for _ in 0..10 {
                    let inc = Inc::new(&m, 2, &at, dir, step, 50.0, index).unwrap();
                    let want = at[2] + dir.sign() * step.value();
                    let sps: Vec<SetPoint> = inc.collect();
                    let last = sps.last().unwrap();
                    assert_eq!(last.position[2], want);
                    assert_eq!((last.velocity[2], last.acceleration[2]), (0.0, 0.0));
                    // monotone: never past the target on the way
                    let s = dir.sign();
                    assert!(sps.iter().all(|p| s * (p.position[2] - want) <= 0.0));
                    assert_eq!(last.index, index + sps.len() as u64);
                    index = last.index;
                    at = last.position;
                    all.extend(sps);
                }
            }
            // back where we started after equal presses both ways (to rounding of the sums)
            assert!(at[2].abs() < 1e-12, "{}", at[2]);
        }
        // z: 100 mm/s, 1000 mm/s², 25000 mm/s³
        check_limits(
            &positions(&Joints::zeros(3), &all, 2),
            1e-3,
            50.0,
            1000.0,
            25000.0,
        )
        .unwrap();
    }

    #[test]
    fn a_0_1_mm_step_takes_the_time_optimal_duration() {
        // A short rest-to-rest move that reaches neither A nor V is four jerk phases of equal
        // length τ with d = 2Jτ³: τ = (d/(2J))^(1/3).
        let m = Machine::builtin("mill3").unwrap();
        let inc = Inc::new(
            &m,
            0,
            &Joints::zeros(3),
            Direction::Plus,
            IncStep::X1000,
            50.0,
            0,
        )
        .unwrap();
        let tau = (0.1f64 / (2.0 * 50000.0)).cbrt();
        assert!(
            (inc.duration() - 4.0 * tau).abs() < 1e-12,
            "{}",
            inc.duration()
        );
        assert_eq!(inc.count(), (4.0 * tau / 1e-3).ceil() as usize);
    }

    #[test]
    fn rotary_steps_are_degrees() {
        let m = Machine::builtin("yzca").unwrap();
        let start = Joints::new([0.0, 0.0, 0.0, 0.3]);
        let inc = Inc::new(&m, 3, &start, Direction::Minus, IncStep::X1000, 20.0, 0).unwrap();
        let last = inc.last().unwrap();
        assert!((last.position[3] - (0.3 - 0.1f64.to_radians())).abs() < 1e-15);
        assert_eq!(&last.position.as_slice()[..3], &[0.0; 3]);
    }

    #[test]
    fn refuses_bad_steps_and_limits() {
        let m = Machine::builtin("mill3").unwrap();
        for v in [0.0, 0.00009, 0.11, f64::NAN, -0.01] {
            assert!(
                matches!(IncStep::new(v), Err(ManualError::Step { .. })),
                "{v}"
            );
        }
        assert_eq!(IncStep::new(0.05).unwrap().value(), 0.05);
        let near = Joints::new([199.95, 0.0, 0.0]);
        let e = Inc::new(&m, 0, &near, Direction::Plus, IncStep::X1000, 50.0, 0).unwrap_err();
        assert!(e.to_string().contains("soft limit 200"), "{e}");
        assert!(Inc::new(&m, 0, &near, Direction::Plus, IncStep::X10, 50.0, 0).is_ok());
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        #[test]
        fn random_steps_end_exactly_within_limits(
            x0 in -99.0..99.0f64,
            step in MIN_STEP..MAX_STEP,
            plus in proptest::bool::ANY,
            speed in 0.01..300.0f64,
        ) {
            let m = Machine::builtin("mill3").unwrap();
            let start = Joints::new([0.0, 0.0, x0]);
            let dir = if plus { Direction::Plus } else { Direction::Minus };
            let inc = Inc::new(&m, 2, &start, dir, IncStep::new(step).unwrap(), speed, 7).unwrap();
            let sps: Vec<SetPoint> = inc.collect();
            let last = sps.last().unwrap();
            proptest::prop_assert_eq!(last.position[2], x0 + dir.sign() * step);
            // z: V = min(speed, 100), A 1000, J 25000
            let r = check_limits(
                &positions(&start, &sps, 2),
                1e-3,
                speed.min(100.0),
                1000.0,
                25000.0,
            );
            proptest::prop_assert!(r.is_ok(), "{:?}", r);
        }
    }
}

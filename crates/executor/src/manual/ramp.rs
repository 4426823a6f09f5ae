//! The velocity-mode jerk-limited ramp that JOG and the homing searches run on: from any state
//! (x, v, a) to a target speed at zero acceleration, time-optimally under |a| ≤ A and |j| ≤ J
//! (bang-bang jerk, Ruckig's velocity interface in one dimension). Closed forms only; the ramp
//! is evaluated exactly at any time, so set-points lie on it and a change (override, stop, the
//! soft-limit brake) can start between periods.
//!
//! With σ = ±1 the side the target lies on from the speed reached by bringing a to 0 at once,
//! v_r = v₀ + a₀|a₀|/(2J), the acceleration goes from a₀ to a peak σ·a_p, holds, and returns
//! to 0. A jerk phase taking the acceleration from α to β at jerk ±J changes the speed by
//! (β² − α²)/(±2J), so (in the frame where σ = +1) without a plateau
//!   σ(v_t − v₀) = (2a_p² − a₀²)/(2J)  ⇒  a_p = √((2Jσ(v_t − v₀) + a₀²)/2),
//! and with a_p capped at A a plateau of (σ(v_t − v₀) − (2A² − a₀²)/(2J))/A. Phase times:
//! t₁ = (a_p − σa₀)/J, t₂ = the plateau, t₃ = a_p/J.

use tezgah_motion::profile::knots::{self, Knot};
use tezgah_motion::profile::State;

/// A ramp of three constant-jerk phases, then cruise at the target speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityRamp {
    /// Phase start times (index 3: the end) and states there.
    knots: [Knot; 4],
}

impl VelocityRamp {
    /// From `start` (its jerk is ignored) to speed `target` with zero final acceleration, for
    /// `max_jerk` > 0. A start acceleration beyond `max_acceleration` (a state estimate a hair
    /// past it) is not clamped, which would be a jump: toward the target it is held, then
    /// released; away from it the first phase brings it back at the jerk limit.
    pub fn new(start: State, target: f64, max_acceleration: f64, max_jerk: f64) -> VelocityRamp {
        let j = max_jerk;
        let (v0, a0) = (start.v, start.a);
        let v_rest = v0 + a0 * a0.abs() / (2.0 * j);
        let sigma = if target >= v_rest { 1.0 } else { -1.0 };
        // Past the limit toward the target: the peak is the start itself (no plateau is
        // negative: the target lies beyond v_rest, which includes that acceleration's run-out).
        let a_lim = max_acceleration.max(sigma * a0);
        let dv = sigma * (target - v0);
        let free = ((2.0 * j * dv + a0 * a0) / 2.0).max(0.0).sqrt();
        let (a_p, plateau) = if free > a_lim {
            (
                a_lim,
                ((dv - (2.0 * a_lim * a_lim - a0 * a0) / (2.0 * j)) / a_lim).max(0.0),
            )
        } else {
            (free, 0.0)
        };
        let durations = [((a_p - sigma * a0) / j).max(0.0), plateau, a_p / j];
        let jerks = [sigma * j, 0.0, -sigma * j];
        let mut knots = [(0.0, State::default()); 4];
        knots::integrate(start, &durations, &jerks, &mut knots);
        // The end is the target speed at rest in acceleration (rounding left aside).
        knots[3].1.v = target;
        knots[3].1.a = 0.0;
        VelocityRamp { knots }
    }

    pub fn duration(&self) -> f64 {
        self.knots[3].0
    }

    pub fn start(&self) -> State {
        self.knots[0].1
    }

    /// The state at the end of the ramp.
    pub fn end(&self) -> State {
        self.knots[3].1
    }

    /// Displacement from start to end.
    pub fn distance(&self) -> f64 {
        self.knots[3].1.s - self.knots[0].1.s
    }

    /// The state at `t` after the start: exact on each phase; after the end it cruises at the
    /// target speed; before the start (or NaN) it is the start state.
    pub fn state_at(&self, t: f64) -> State {
        knots::state_at(&self.knots, t, || self.knots[0].1)
    }
}

/// Displacement of the time-optimal stop from `state` (the braking distance, signed).
pub fn stopping_displacement(state: State, max_acceleration: f64, max_jerk: f64) -> f64 {
    VelocityRamp::new(state, 0.0, max_acceleration, max_jerk).distance()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use tezgah_motion::profile::knots::advance;
    use tezgah_motion::profile::{min_stopping_distance, speed_change_time, Limits};

    fn at(v: f64, a: f64) -> State {
        State {
            s: 0.0,
            v,
            a,
            j: 0.0,
        }
    }

    #[test]
    fn from_rest_matches_the_profile_solver() {
        // At zero start acceleration the ramp is the motion crate's speed change (eqs. R1–R3).
        let l = Limits::new(200.0, 2000.0, 50000.0).unwrap();
        for (v0, v1) in [
            (0.0, 50.0),
            (0.0, 200.0),
            (120.0, 0.0),
            (30.0, 31.0),
            (80.0, 20.0),
        ] {
            let r = VelocityRamp::new(at(v0, 0.0), v1, 2000.0, 50000.0);
            let t = speed_change_time(v0, v1, &l).unwrap();
            assert!((r.duration() - t).abs() < 1e-12, "{v0}→{v1}");
            if v1 == 0.0 {
                let d = min_stopping_distance(v0, &l).unwrap();
                assert!((r.distance() - d).abs() < 1e-12 * d.max(1.0));
            }
            assert!((r.end().v - v1).abs() < 1e-9);
        }
    }

    proptest! {
        #[test]
        fn reaches_the_target_within_limits(
            v0 in -100.0..100.0f64, a0 in -1.0..1.0f64, target in -100.0..100.0f64,
        ) {
            let (a_lim, j) = (1000.0, 20000.0);
            let a0 = a0 * a_lim;
            let r = VelocityRamp::new(at(v0, a0), target, a_lim, j);
            // the last phase integrates to the target speed at zero acceleration
            let (te, x) = r.knots[2];
            let end = advance(x, x.j, r.duration() - te);
            prop_assert!((end.v - target).abs() < 1e-9 * (1.0 + target.abs() + v0.abs()));
            prop_assert!(end.a.abs() < 1e-9 * a_lim);
            for (_, k) in r.knots {
                prop_assert!(k.a.abs() <= a_lim * (1.0 + 1e-12));
                prop_assert!(k.j.abs() <= j);
            }
        }

        #[test]
        fn state_is_continuous(v0 in 0.0..100.0f64, a0 in -1.0..1.0f64, target in 0.0..100.0f64) {
            let r = VelocityRamp::new(at(v0, 1000.0 * a0), target, 1000.0, 20000.0);
            for &(t, k) in &r.knots[1..] {
                let left = r.state_at(t - 1e-9);
                prop_assert!((left.v - k.v).abs() < 1e-4 && (left.a - k.a).abs() < 1e-4);
            }
        }
    }
}

//! The velocity interface: from any state (v0, a0) to a target speed at zero acceleration,
//! time-optimally under |a| ≤ A and |j| ≤ J — Ruckig's velocity control for one axis
//! (Berscheid & Kröger, RSS 2021: the velocity interface), used by JOG, homing, every stop.
//! [`Change`] is also the half-profile the position interface joins two of ([`super::target`]).
//!
//! With σ = ±1 the side the target lies on from the speed reached by bringing a to 0 at once,
//! v_r = v0 + a0|a0|/(2J), the acceleration goes from a0 to a peak σ·a_p, holds, and returns
//! to 0 (bang-bang jerk). A jerk phase taking the acceleration from α to β at jerk ±J changes
//! the speed by (β² − α²)/(±2J), so (in the frame where σ = +1, a' = σ·a0) without a plateau
//!   σ(v_t − v0) = (2a_p² − a'²)/(2J)  ⇒  a_p = √((2Jσ(v_t − v0) + a'²)/2),        (eq. V1)
//! and with a_p capped at A a plateau of (σ(v_t − v0) − (2A² − a'²)/(2J))/A.          (eq. V2)
//! Phase times: t₁ = (a_p − a')/J, t₂ = the plateau, t₃ = a_p/J. At a0 = 0 these are the
//! speed ramps of eqs. R1–R2. A start with |a0| > A is first braked to ±A ([`super::brake`]).

use super::brake;
use super::error::ProfileError;
use super::{Limits, Profile, State};

/// One time-optimal change of speed to a target at zero acceleration (eqs. V1, V2), from a
/// start acceleration within ±A.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Change {
    /// Jerk phase, plateau, jerk phase (s).
    pub durations: [f64; 3],
    /// σ·J: the first phase's jerk; the last phase has the opposite.
    pub jerk: f64,
}

impl Change {
    /// From speed `v0` and acceleration `a0` (|a0| ≤ A, up to rounding) to speed `target`.
    pub fn new(v0: f64, a0: f64, target: f64, limits: &Limits) -> Change {
        let (a_max, j) = (limits.max_acceleration(), limits.max_jerk());
        let a0 = a0.clamp(-a_max, a_max);
        let v_rest = v0 + a0 * a0.abs() / (2.0 * j);
        let sigma = if target >= v_rest { 1.0 } else { -1.0 };
        let (a1, dv) = (sigma * a0, sigma * (target - v0));
        let free = ((2.0 * j * dv + a1 * a1) / 2.0).max(0.0).sqrt();
        let (peak, plateau) = if free > a_max {
            let rest = dv - (2.0 * a_max * a_max - a1 * a1) / (2.0 * j);
            (a_max, (rest / a_max).max(0.0))
        } else {
            (free, 0.0)
        };
        Change {
            durations: [((peak - a1) / j).max(0.0), plateau, peak / j],
            jerk: sigma * j,
        }
    }

    pub fn duration(&self) -> f64 {
        self.durations.iter().sum()
    }

    /// The three (duration, jerk) phases.
    pub fn phases(&self) -> [(f64, f64); 3] {
        [
            (self.durations[0], self.jerk),
            (self.durations[1], 0.0),
            (self.durations[2], -self.jerk),
        ]
    }
}

/// The time-optimal motion from `start` (position, speed, acceleration; its jerk is ignored)
/// to speed `target` at zero acceleration, under the acceleration and jerk of `limits` (see
/// the module comment). As in Ruckig's velocity interface the speed limit is not applied: the
/// caller chooses the target (a JOG speed, 0 for a stop), and the speed runs monotonically
/// to it once the start acceleration is released. Afterwards the motion cruises at `target`.
///
/// # Errors
/// [`ProfileError::Start`] for a start state that is not finite, [`ProfileError::Target`] for
/// a target speed that is not.
pub fn reach_velocity(start: State, target: f64, limits: &Limits) -> Result<Profile, ProfileError> {
    check_start(&start)?;
    if !target.is_finite() {
        return Err(ProfileError::Target(target));
    }
    let brake = brake::velocity(start.a, limits);
    let braked = brake::apply(start, &brake);
    let change = Change::new(braked.v, braked.a, target, limits);
    let mut durations = [0.0; 7];
    let mut jerks = [0.0; 7];
    for (k, (d, j)) in change.phases().into_iter().enumerate() {
        durations[k] = d;
        jerks[k] = j;
    }
    Ok(Profile::braked(start, brake, durations, jerks, None).ending_at(target, 0.0))
}

/// Displacement of the time-optimal stop from `start` under `limits` (signed: the way the
/// speed points), the velocity interface to speed 0.
pub fn stopping_displacement(start: State, limits: &Limits) -> Result<f64, ProfileError> {
    reach_velocity(start, 0.0, limits).map(|p| p.distance())
}

pub(crate) fn check_start(start: &State) -> Result<(), ProfileError> {
    if [start.s, start.v, start.a].iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ProfileError::Start {
            v: start.v,
            a: start.a,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::profile::knots::advance;
    use crate::profile::{min_stopping_distance, speed_change_time};
    use proptest::prelude::*;

    /// A state at s = 0 with speed `v` and acceleration `a` (the tests' start states).
    pub(crate) fn at(v: f64, a: f64) -> State {
        State {
            s: 0.0,
            v,
            a,
            j: 0.0,
        }
    }

    #[test]
    fn from_zero_acceleration_it_is_the_speed_ramp() {
        let l = Limits::new(200.0, 2000.0, 50000.0).unwrap();
        for (v0, v1) in [
            (0.0, 50.0),
            (0.0, 200.0),
            (120.0, 0.0),
            (30.0, 31.0),
            (80.0, 20.0),
        ] {
            let p = reach_velocity(at(v0, 0.0), v1, &l).unwrap();
            let t = speed_change_time(v0, v1, &l).unwrap();
            assert!((p.duration() - t).abs() < 1e-12, "{v0}→{v1}");
            if v1 == 0.0 {
                let d = min_stopping_distance(v0, &l).unwrap();
                assert!((p.distance() - d).abs() < 1e-12 * d.max(1.0));
            }
            assert_eq!((p.end().v, p.end().a), (v1, 0.0));
        }
    }

    #[test]
    fn a_stop_from_a_start_acceleration_has_the_closed_form() {
        // v0 = 10, a0 = 1000 toward the stop's opposite side, A = 2000, J = 50 000: a_p =
        // −√(a0²/2 + J·v0) = −√(500 000 + 500 000) = −1000 (eq. V1 with σ = −1), so the phases
        // last (a0 + 1000)/J = 0.04 s and 1000/J = 0.02 s.
        let l = Limits::new(100.0, 2000.0, 50000.0).unwrap();
        let p = reach_velocity(at(10.0, 1000.0), 0.0, &l).unwrap();
        assert!((p.duration() - 0.06).abs() < 1e-15, "{}", p.duration());
        assert!(p.brake()[0].0 == 0.0);
        // Beyond A: braked to A at −J first (0.01 s from 2500), then as from (v, A).
        let p = reach_velocity(at(0.0, 2500.0), 0.0, &l).unwrap();
        assert!((p.brake()[0].0 - 0.01).abs() < 1e-15 && p.brake()[0].1 == -50000.0);
        assert!(p.knots()[2].1.a <= 2000.0 + 1e-9);
        assert!(reach_velocity(at(f64::NAN, 0.0), 0.0, &l).is_err());
        assert!(reach_velocity(at(0.0, 0.0), f64::INFINITY, &l).is_err());
    }

    proptest! {
        /// From any state, brake included: the target is met exactly at zero acceleration,
        /// |j| ≤ J throughout, |a| ≤ A after the brake, which only ever brings |a| down.
        #[test]
        fn reaches_the_target_within_limits(
            v0 in -100.0..100.0f64, a0 in -1.5..1.5f64, target in -100.0..100.0f64,
        ) {
            let l = Limits::new(100.0, 1000.0, 20000.0).unwrap();
            let p = reach_velocity(at(v0, a0 * 1000.0), target, &l).unwrap();
            let last = p.knots()[p.knots().len() - 2];
            let end = advance(last.1, last.1.j, p.duration() - last.0);
            prop_assert!((end.v - target).abs() < 1e-9 * (1.0 + target.abs() + v0.abs()));
            prop_assert!(end.a.abs() < 1e-9 * 1000.0);
            let (tb, _) = p.knots()[p.knots().len() - 8];
            let a_start = (a0 * 1000.0).abs();
            for &(t, k) in p.knots() {
                prop_assert!(k.j.abs() <= 20000.0);
                let cap = if t < tb { a_start } else { 1000.0 };
                prop_assert!(k.a.abs() <= cap * (1.0 + 1e-12) + 1e-9, "{k:?}");
            }
        }
    }
}

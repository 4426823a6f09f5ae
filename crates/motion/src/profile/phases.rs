//! [`Profile`]: the single truth for one timed motion along the path — a start state and seven
//! constant-jerk phases (Ruckig's `Profile`). Everything else (state at any time, duration,
//! distance) is evaluated from it analytically, so any plan can be replayed and checked.
//!
//! Phase layout: jerk +σ₁J, 0, −σ₁J (speed change v0 → vm, σ₁ = ±1), cruise at vm (jerk 0),
//! jerk +σ₂J, 0, −σ₂J (vm → v1). σ₁ = +1, σ₂ = −1 is the usual speed-up-then-slow-down; the
//! other signs give slow-down-then-speed-up and monotone shapes. The phases are integrated and
//! walked as a knot table ([`super::knots`], exact cubics). A start state outside the limits
//! is first brought back within them by a brake of up to two phases, as Ruckig does
//! ([`super::brake`]); the seven phases follow it.

use super::knots;
use super::ramp::Ramp;

/// Position, velocity, acceleration and jerk at one instant (mm, mm/s, mm/s², mm/s³).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    pub s: f64,
    pub v: f64,
    pub a: f64,
    pub j: f64,
}

/// A timed 1-D motion: an optional brake of up to two phases, then seven constant-jerk phases
/// (see the module comment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile {
    /// The brake (two phases) and the seven main phases.
    durations: [f64; PHASES],
    jerks: [f64; PHASES],
    /// Time and (s, v, a) at the start of each phase and at the end (index 9), integrated once
    /// from the start state; the jerk field holds the phase's jerk (0 at the end).
    knots: [(f64, State); PHASES + 1],
    /// Index of the first knot [`Profile::knots`] shows: 0 with a brake, 2 without (the two
    /// brake phases then last 0 s, and the table reads as the seven main phases alone).
    first: usize,
}

/// Two brake phases and seven main phases.
const PHASES: usize = 9;

/// Index of the cruise phase (the main phases' fourth).
const CRUISE: usize = 5;

impl Profile {
    /// Integrates the phases from `start` (its jerk field is ignored). Durations must be ≥ 0;
    /// the solver guarantees it, so this is not public.
    pub(crate) fn from_phases(start: State, durations: [f64; 7], jerks: [f64; 7]) -> Profile {
        Profile::braked(start, [(0.0, 0.0); 2], durations, jerks, None)
    }

    /// A profile whose seven phases follow a brake of two (duration, jerk) phases (Ruckig's
    /// brake pre-trajectory, [`super::brake`]); a brake of zero duration is no brake. A cruise
    /// runs at zero acceleration and, if given, exactly at `cruise_speed`.
    pub(crate) fn braked(
        start: State,
        brake: [(f64, f64); 2],
        durations: [f64; 7],
        jerks: [f64; 7],
        cruise_speed: Option<f64>,
    ) -> Profile {
        let mut all_d = [0.0; PHASES];
        let mut all_j = [0.0; PHASES];
        for (k, (d, j)) in brake.iter().enumerate() {
            all_d[k] = *d;
            all_j[k] = *j;
        }
        all_d[2..].copy_from_slice(&durations);
        all_j[2..].copy_from_slice(&jerks);
        let mut knots = [(0.0, State::default()); PHASES + 1];
        // Up to the cruise, then on from it at exactly zero acceleration (and at the cruise
        // speed): a rounding residue there would be integrated over the whole cruise.
        knots::integrate(
            start,
            &all_d[..CRUISE],
            &all_j[..CRUISE],
            &mut knots[..=CRUISE],
        );
        let (t, mut at_cruise) = knots[CRUISE];
        if all_d[CRUISE] > 0.0 {
            at_cruise.a = 0.0;
            at_cruise.v = cruise_speed.unwrap_or(at_cruise.v);
        }
        knots::integrate(
            at_cruise,
            &all_d[CRUISE..],
            &all_j[CRUISE..],
            &mut knots[CRUISE..],
        );
        for k in &mut knots[CRUISE..] {
            k.0 += t;
        }
        let first = if brake.iter().all(|b| b.0 == 0.0) {
            2
        } else {
            0
        };
        Profile {
            durations: all_d,
            jerks: all_j,
            knots,
            first,
        }
    }

    /// No motion: at rest at position `s` (duration 0).
    pub fn at_rest(s: f64) -> Profile {
        Profile::from_phases(
            State {
                s,
                ..State::default()
            },
            [0.0; 7],
            [0.0; 7],
        )
    }

    /// The same profile with its end speed and acceleration set to the target exactly, which
    /// the integration meets up to rounding (the motion after the end then runs at exactly
    /// the target speed).
    pub(crate) fn ending_at(mut self, v: f64, a: f64) -> Profile {
        let end = &mut self.knots[PHASES].1;
        end.v = v;
        end.a = a;
        self
    }

    /// Two ramps around a cruise: `first` takes the speed from v0 in direction `sign1` (±1),
    /// `cruise` seconds at the reached speed, then `second` in direction `sign2`.
    pub(crate) fn from_ramps(
        v0: f64,
        first: Ramp,
        sign1: f64,
        cruise: f64,
        second: Ramp,
        sign2: f64,
        jerk: f64,
    ) -> Profile {
        let (j1, j2) = (sign1 * jerk, sign2 * jerk);
        Profile::from_phases(
            State {
                s: 0.0,
                v: v0,
                a: 0.0,
                j: 0.0,
            },
            [
                first.jerk_time,
                first.accel_time,
                first.jerk_time,
                cruise,
                second.jerk_time,
                second.accel_time,
                second.jerk_time,
            ],
            [j1, 0.0, -j1, 0.0, j2, 0.0, -j2],
        )
    }

    /// The seven main phase durations (s), after the brake.
    pub fn durations(&self) -> [f64; 7] {
        let mut d = [0.0; 7];
        d.copy_from_slice(&self.durations[2..]);
        d
    }

    /// The seven main phase jerks (mm/s³).
    pub fn jerks(&self) -> [f64; 7] {
        let mut j = [0.0; 7];
        j.copy_from_slice(&self.jerks[2..]);
        j
    }

    /// The brake's two phases as (duration s, jerk mm/s³); zero durations when the start
    /// state is within the limits.
    pub fn brake(&self) -> [(f64, f64); 2] {
        [
            (self.durations[0], self.jerks[0]),
            (self.durations[1], self.jerks[1]),
        ]
    }

    /// The state at t = 0.
    pub fn start(&self) -> State {
        self.knots[0].1
    }

    /// The state at t = duration (jerk 0).
    pub fn end(&self) -> State {
        self.knots[PHASES].1
    }

    /// Time and state at the start of each phase, and at the end (the last): the seven main
    /// phases, preceded by the brake's two when there is a brake.
    pub fn knots(&self) -> &[(f64, State)] {
        &self.knots[self.first..]
    }

    pub fn duration(&self) -> f64 {
        self.knots[PHASES].0
    }

    /// Distance travelled from start to end.
    pub fn distance(&self) -> f64 {
        self.knots[PHASES].1.s - self.knots[0].1.s
    }

    /// The state at time `t`, exactly (one cubic per phase). Before 0 this is the start state;
    /// after the end the motion continues at the end speed (zero acceleration and jerk), as
    /// Ruckig's trajectories do. NaN gives the start state.
    pub fn state_at(&self, t: f64) -> State {
        knots::state_at(&self.knots, t, || {
            // The jerk of the first phase that lasts (a zero-length one is never entered).
            let first_j = self
                .durations
                .iter()
                .zip(self.jerks)
                .find(|(d, _)| **d > 0.0)
                .map_or(0.0, |(_, j)| j);
            State {
                j: first_j,
                ..self.knots[0].1
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn state_at_is_continuous_and_matches_knots() {
        let p = Profile::from_phases(
            State {
                s: 0.0,
                v: 1.0,
                a: 0.0,
                j: 0.0,
            },
            [0.1, 0.2, 0.1, 0.5, 0.1, 0.2, 0.1],
            [10.0, 0.0, -10.0, 0.0, -10.0, 0.0, 10.0],
        );
        assert!((p.duration() - 1.3).abs() < 1e-15);
        for &(t, x) in p.knots() {
            let left = p.state_at(t - 1e-12);
            let right = p.state_at(t);
            assert!((left.s - x.s).abs() < 1e-10 && (right.s - x.s).abs() < 1e-12);
            assert!((left.v - x.v).abs() < 1e-10 && (right.v - x.v).abs() < 1e-12);
            assert!((left.a - x.a).abs() < 1e-9 && (right.a - x.a).abs() < 1e-12);
        }
        let e = p.end();
        assert!(e.a.abs() < 1e-14 && (e.v - 1.0).abs() < 1e-14);
        let after = p.state_at(p.duration() + 2.0);
        assert!((after.s - (e.s + 2.0)).abs() < 1e-12 && after.j == 0.0);
        assert_eq!(p.state_at(f64::NAN).s, 0.0);
        assert_eq!(p.state_at(-1.0).j, 10.0);
    }
}

//! The brake that brings a start state outside the limits back within them before the
//! time-optimal profile starts: Ruckig's brake pre-trajectory (Berscheid & Kröger, "Jerk-limited
//! Real-time Trajectory Generation with Arbitrary Target States", RSS 2021, and Ruckig's
//! `brake.cpp`, re-derived here), at most two phases — a jerk phase, then a constant one.
//!
//! * Velocity interface: only |a0| > A matters (speed is the target itself): jerk ∓J until
//!   |a| = A.
//! * Position interface: |a0| > A, or a speed that is above V or will pass it once the
//!   acceleration is brought to zero (v0 + a0|a0|/(2J) > V). The brake runs jerk −J (for the
//!   upper side; the lower mirrors) until the speed is back at V or the acceleration reaches
//!   −A, holding −A then until the speed is at V; neither may drive the speed below −V once
//!   the acceleration is released, which caps both phases. A start acceleration above A whose
//!   release would still end above V is braked as a speed; otherwise the acceleration is
//!   brought to A (and held there while the speed is below −V).
//!
//! Each phase is as short as the limits allow, so the motion re-enters the limits as soon as a
//! jerk-limited motion can, and the seven-phase solver takes over from a state within them.

use super::knots::advance;
use super::{Limits, State};

/// Up to two (duration s, jerk) phases; zero durations when no brake is needed.
pub(crate) type Brake = [(f64, f64); 2];

const NONE: Brake = [(0.0, 0.0); 2];

/// The brake of the velocity interface: the acceleration back to ±A at full jerk.
pub(crate) fn velocity(a0: f64, limits: &Limits) -> Brake {
    let (a, j) = (limits.max_acceleration(), limits.max_jerk());
    if a0 > a {
        [((a0 - a) / j, -j), (0.0, 0.0)]
    } else if a0 < -a {
        [((-a - a0) / j, j), (0.0, 0.0)]
    } else {
        NONE
    }
}

/// The brake of the position interface from speed `v0` and acceleration `a0`.
pub(crate) fn position(v0: f64, a0: f64, limits: &Limits) -> Brake {
    let (v, a, j) = (
        limits.max_velocity(),
        limits.max_acceleration(),
        limits.max_jerk(),
    );
    // Speed once the acceleration is brought to zero at full jerk.
    let released = v0 + a0 * a0.abs() / (2.0 * j);
    if a0 > a {
        acceleration_brake(v0, a0, limits, 1.0)
    } else if a0 < -a {
        acceleration_brake(-v0, -a0, limits, -1.0)
    } else if (v0 > v && v0 - a0 * a0 / (2.0 * j) > -v) || (a0 > 0.0 && released > v) {
        speed_brake(v0, a0, limits, 1.0)
    } else if (v0 < -v && v0 + a0 * a0 / (2.0 * j) < v) || (a0 < 0.0 && released < -v) {
        speed_brake(-v0, -a0, limits, -1.0)
    } else {
        NONE
    }
}

/// In the frame where the excess is upward (`sign` = +1; −1 mirrors speeds, accelerations and
/// jerks): the acceleration a0 > A brought down to A, or braked as a speed if releasing it
/// would still pass V.
fn acceleration_brake(v0: f64, a0: f64, limits: &Limits, sign: f64) -> Brake {
    let (v, a, j) = (
        limits.max_velocity(),
        limits.max_acceleration(),
        limits.max_jerk(),
    );
    let to_limit = (a0 - a) / j;
    if v0 + a0 * a0 / (2.0 * j) > v {
        return speed_brake(v0, a0, limits, sign);
    }
    let at_limit = speed_after(v0, a0, -j, to_limit);
    let hold = if at_limit < -v {
        // Still below −V at A: hold A until the speed is back at −V, but not so long that
        // releasing A would pass V.
        let to_min = (-v - at_limit) / a;
        let to_max = -a / (2.0 * j) + (v - at_limit) / a;
        to_min.min(to_max).max(0.0)
    } else {
        0.0
    };
    [(to_limit, -sign * j), (hold, 0.0)]
}

/// In the frame where the speed is too high (`sign` = +1): jerk −J until the speed is back at
/// V (or until releasing the acceleration would land at −V, if sooner), holding −A between if
/// the acceleration reaches it first.
fn speed_brake(v0: f64, a0: f64, limits: &Limits, sign: f64) -> Brake {
    let (v, a, j) = (
        limits.max_velocity(),
        limits.max_acceleration(),
        limits.max_jerk(),
    );
    // v0 + a0·t − J·t²/2 = V, the later root; and the t after which releasing at +J lands at
    // −V: v0 + a0·t − J·t²/2 + (a0 − J·t)²/(2J) = −V.
    let to_max = (a0 + (a0 * a0 + 2.0 * j * (v0 - v)).max(0.0).sqrt()) / j;
    let to_min = (a0 + (0.5 * a0 * a0 + j * (v0 + v)).max(0.0).sqrt()) / j;
    let jerk_time = to_max.min(to_min);
    let to_a_min = (a0 + a) / j;
    if to_a_min < jerk_time {
        let at = speed_after(v0, a0, -j, to_a_min);
        let hold_to_max = (at - v) / a;
        let hold_to_min = -a / (2.0 * j) + (at + v) / a;
        [
            (to_a_min.max(0.0), -sign * j),
            (hold_to_max.min(hold_to_min).max(0.0), 0.0),
        ]
    } else {
        [(jerk_time.max(0.0), -sign * j), (0.0, 0.0)]
    }
}

/// The speed after `t` s at jerk `jerk` from speed `v0` and acceleration `a0`.
fn speed_after(v0: f64, a0: f64, jerk: f64, t: f64) -> f64 {
    v0 + t * (a0 + 0.5 * t * jerk)
}

/// The state after `brake` from `start`.
pub(crate) fn apply(start: State, brake: &Brake) -> State {
    brake.iter().fold(start, |x, &(dt, jk)| advance(x, jk, dt))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::velocity::tests::at;

    #[test]
    fn brings_the_state_within_the_limits() {
        let l = Limits::new(100.0, 1000.0, 20000.0).unwrap();
        // Above A, speed fine: jerk −J for (a0 − A)/J.
        let b = position(0.0, 1500.0, &l);
        assert!((b[0].0 - 0.025).abs() < 1e-15 && b[0].1 == -20000.0 && b[1].0 == 0.0);
        // Above V at rest: jerk −J until v = V: t = √(2(v0 − V)/J).
        let b = position(110.0, 0.0, &l);
        assert!((b[0].0 - (2.0 * 10.0 / 20000.0f64).sqrt()).abs() < 1e-15);
        let x = apply(at(110.0, 0.0), &b);
        assert!((x.v - 100.0).abs() < 1e-12);
        // Far above V: −A reached, then held until v = V.
        let b = position(300.0, 0.0, &l);
        let x = apply(at(300.0, 0.0), &b);
        assert!(
            (x.v - 100.0).abs() < 1e-9 && (x.a + 1000.0).abs() < 1e-9,
            "{x:?}"
        );
        // Within the limits, and mirrored.
        assert_eq!(position(50.0, 100.0, &l), NONE);
        let b = position(-300.0, 0.0, &l);
        let x = apply(at(-300.0, 0.0), &b);
        assert!(
            (x.v + 100.0).abs() < 1e-9 && (x.a - 1000.0).abs() < 1e-9,
            "{x:?}"
        );
        assert_eq!(velocity(-1200.0, &l), [(0.01, 20000.0), (0.0, 0.0)]);
    }
}

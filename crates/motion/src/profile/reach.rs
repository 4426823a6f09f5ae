//! What a look-ahead planner asks of one segment before it asks for a profile: the distance and
//! time of a speed change, the stopping distance, and the end speeds reachable in a distance.
//!
//! Reachability follows [`solve`](super::solve)'s two cases: from v0, an end speed v1 can be met
//! in L iff L ≥ d(v0→v1) (one ramp, then speed up-and-down to use up the rest) or
//! L ≥ d(v0→0) + d(0→v1) (slow down as far as a stop, then speed up). The second can be the
//! shorter one: a jerk-limited ramp's time grows like √δ, so from a low v0 it may pay to stop.

use super::error::{ProfileError, SpeedKind};
use super::ramp::{change_distance, change_time, speed_gain_over, Ramp};
use super::roots::brent;
use super::solve::{check_distance, check_speed};
use super::{Limits, Profile};

/// Distance of the time-optimal speed change v0 → v1 with zero end accelerations (eq. R3).
pub fn speed_change_distance(v0: f64, v1: f64, limits: &Limits) -> Result<f64, ProfileError> {
    check_speed(SpeedKind::Start, v0, limits)?;
    check_speed(SpeedKind::End, v1, limits)?;
    Ok(change_distance(v0, v1, limits))
}

/// Duration of the time-optimal speed change v0 → v1 with zero end accelerations (eqs. R1, R2).
pub fn speed_change_time(v0: f64, v1: f64, limits: &Limits) -> Result<f64, ProfileError> {
    check_speed(SpeedKind::Start, v0, limits)?;
    check_speed(SpeedKind::End, v1, limits)?;
    Ok(change_time(v0, v1, limits))
}

/// The shortest distance in which speed `v` (at zero acceleration) can be brought to a stop.
pub fn min_stopping_distance(v: f64, limits: &Limits) -> Result<f64, ProfileError> {
    speed_change_distance(v, 0.0, limits)
}

/// The highest end speed (≤ V, at zero acceleration) reachable from `v0` within `distance`
/// moving forward; every end speed from `v0` up to it is reachable too.
pub fn max_reachable_speed(v0: f64, distance: f64, limits: &Limits) -> Result<f64, ProfileError> {
    check_speed(SpeedKind::Start, v0, limits)?;
    check_distance(distance)?;
    Ok(reach_up(v0, distance, limits)
        .speed
        .min(limits.max_velocity()))
}

/// The lowest end speed v1 ≤ `v0` such that every end speed in [v1, v0] is reachable from
/// `v0` within `distance` (braking, at zero end acceleration).
pub fn min_reachable_speed(v0: f64, distance: f64, limits: &Limits) -> Result<f64, ProfileError> {
    check_speed(SpeedKind::Start, v0, limits)?;
    check_distance(distance)?;
    Ok(reach_down(v0, distance, limits).map_or(0.0, |b| b.speed))
}

/// An extreme reachable end speed and the two ramps that reach it using exactly the distance,
/// so that [`solve`](super::solve) can return it for an end speed a rounding error beyond.
pub(crate) struct Bound {
    pub speed: f64,
    first: (Ramp, f64),
    second: (Ramp, f64),
}

impl Bound {
    pub fn profile(&self, v0: f64, limits: &Limits) -> Profile {
        let (r0, s0) = self.first;
        let (r1, s1) = self.second;
        Profile::from_ramps(v0, r0, s0, 0.0, r1, s1, limits.max_jerk())
    }
}

/// The highest end speed from `v0` in `distance`, not capped at V: one ramp up over the whole
/// distance, or a stop first and a ramp up from rest over what is left, whichever is higher.
pub(crate) fn reach_up(v0: f64, distance: f64, limits: &Limits) -> Bound {
    let gain = speed_gain_over(v0, distance, limits);
    let mut best = Bound {
        speed: v0 + gain,
        first: (Ramp::new(gain, limits), 1.0),
        second: (Ramp::new(0.0, limits), -1.0),
    };
    let stop = change_distance(v0, 0.0, limits);
    if stop < distance {
        let gain = speed_gain_over(0.0, distance - stop, limits);
        if gain > best.speed {
            best = Bound {
                speed: gain,
                first: (Ramp::new(v0, limits), -1.0),
                second: (Ramp::new(gain, limits), 1.0),
            };
        }
    }
    best
}

/// The braking bound of [`min_reachable_speed`]; `None` when every speed down to 0 is reachable.
///
/// d(v0 → v0−δ) is concave in δ (module comment of [`solve`](super::solve)), so the braking
/// distance rises to a maximum and may fall again; the bound is the first δ where it reaches
/// `distance`, if it does before the maximum.
pub(crate) fn reach_down(v0: f64, distance: f64, limits: &Limits) -> Option<Bound> {
    let (a, j) = (limits.max_acceleration(), limits.max_jerk());
    // Maximiser of the braking distance: δ = 2v0/3 without plateau, v0 − A²/(2J) with one.
    let delta_b = limits.full_ramp_speed_change();
    let delta_m = if 2.0 * v0 / 3.0 <= delta_b {
        2.0 * v0 / 3.0
    } else {
        v0 - 0.5 * a * a / j
    };
    let braking = |delta: f64| Ramp::new(delta, limits).distance(v0, (v0 - delta).max(0.0));
    if braking(delta_m) <= distance {
        return None;
    }
    let g = |u: f64| braking(u * u) - distance;
    let u_hi = delta_m.sqrt();
    let u = brent(g, 0.0, u_hi, g(0.0), g(u_hi));
    let delta = u * u;
    Some(Bound {
        speed: (v0 - delta).max(0.0),
        first: (Ramp::new(delta, limits), -1.0),
        second: (Ramp::new(0.0, limits), 1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reachable_speeds_round_trip_through_solve() {
        let l = Limits::new(50.0, 1000.0, 20000.0).unwrap();
        for v0 in [0.0, 0.1, 5.0, 30.0, 50.0] {
            for d in [0.0, 1e-6, 0.01, 0.3, 1.0, 5.0] {
                let up = max_reachable_speed(v0, d, &l).unwrap();
                let p = crate::profile::solve(d, v0, up, &l).unwrap();
                assert!((p.end().v - up).abs() <= 1e-9 * 50.0, "{v0} {d} {up}");
                let down = min_reachable_speed(v0, d, &l).unwrap();
                assert!(down <= v0);
                let p = crate::profile::solve(d, v0, down, &l).unwrap();
                assert!(
                    (p.distance() - d).abs() <= 1e-9 * d.max(1e-9),
                    "{v0} {d} {down}"
                );
            }
        }
    }
}

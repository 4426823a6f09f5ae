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
use super::solve::{check_distance, check_speed, solve};
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

/// The highest start speed (≤ V) from which the motion can end at *some* speed ≤ `end_cap`
/// within `distance` — the speed a backward pass may allow at the start of a segment whose
/// end must not exceed `end_cap`.
///
/// From v0 above e = `end_cap`, an end speed v1 ∈ [0, e] is met directly iff d(v0 → v1) ≤ L;
/// d(v0 → v0 − δ) is concave in δ (see [`reach_down`]), so over v1 ∈ [0, e] it is smallest at
/// an end, v1 = e or v1 = 0. Both d(v0 → e) and d(v0 → 0) grow with v0, and by time reversal
/// the highest v0 with d(v0 → x) ≤ L is the highest speed reachable from x speeding up over L.
/// (Braking through rest to v1 needs d(v0 → 0) ≤ L as well, so it adds nothing.) Hence the
/// answer is the larger of the reach from e and the reach from rest.
///
/// The reach from e alone would not do: a jerk-limited ramp gains less speed over a distance
/// the faster it starts (it has less time), so e + gain(e) falls below gain(0) while e is small
/// against the gain. A backward pass using it would *lower* the start speed of a segment when
/// a later junction allows more, after the forward pass may already have arrived at the old,
/// higher speed (the end speed then proves unreachable). This bound only grows with `end_cap`.
pub fn max_start_speed(end_cap: f64, distance: f64, limits: &Limits) -> Result<f64, ProfileError> {
    check_speed(SpeedKind::End, end_cap, limits)?;
    check_distance(distance)?;
    let from_cap = reach_up(end_cap, distance, limits).speed;
    let from_rest = speed_gain_over(0.0, distance, limits);
    Ok(from_cap.max(from_rest).min(limits.max_velocity()))
}

/// The time-optimal profile over `distance` from `v0` to the highest end speed ≤ `end_cap`
/// that is reachable — the forward pass's step. `v0` must be at most
/// [`max_start_speed`]`(end_cap, distance)`, which guarantees that such an end speed exists.
///
/// Speeding up, every end speed from v0 to [`max_reachable_speed`] is reachable, so the end
/// speed is the smaller of that and the cap. Braking, the cap itself may lie in a gap: d(v0 →
/// v0 − δ) rises and falls again in δ, so a cap that is too close to v0 for the distance can
/// be unreachable while lower speeds are not (see [`max_start_speed`]). The end speed is then
/// the faster of the gap's far side (one braking ramp whose distance has come back down to
/// the segment's) and a stop followed by a speed-up over what is left, below the cap.
///
/// # Errors
/// As [`solve`](super::solve); [`ProfileError::EndSpeedUnreachable`] only when `v0` is above
/// [`max_start_speed`].
pub fn solve_at_most(
    distance: f64,
    v0: f64,
    end_cap: f64,
    limits: &Limits,
) -> Result<Profile, ProfileError> {
    check_distance(distance)?;
    check_speed(SpeedKind::Start, v0, limits)?;
    let cap = end_cap.clamp(0.0, limits.max_velocity());
    let v1 = if cap >= v0 {
        cap.min(max_reachable_speed(v0, distance, limits)?)
    } else {
        cap
    };
    match solve(distance, v0, v1, limits) {
        Ok(p) => Ok(p),
        // Speeding up: the reachable bound differs from v1 by rounding only. Lower the end
        // speed to it, never raise it.
        Err(ProfileError::EndSpeedUnreachable { reachable, .. })
            if v1 >= v0 && reachable <= v1 * (1.0 + 1e-9) + 1e-12 =>
        {
            solve(distance, v0, reachable, limits)
        }
        Err(e @ ProfileError::EndSpeedUnreachable { .. }) if v1 < v0 => {
            // v1 lies in the gap: end at the faster of the far side of the gap and the
            // speed-up from rest, both below v1.
            let far = reach_past_gap(v0, distance, limits).filter(|b| b.speed <= v1);
            let rest = reach_through_rest(v0, distance, limits).filter(|b| b.speed <= v1);
            match (far, rest) {
                (Some(f), Some(r)) if r.speed > f.speed => Ok(r.profile(v0, limits)),
                (Some(b), _) | (None, Some(b)) => Ok(b.profile(v0, limits)),
                // Rest is reachable whenever v1 is not (v0 ≤ max_start_speed), if only at
                // the bound, up to rounding, where `solve` takes the reversed speed-up.
                (None, None) => solve(distance, v0, 0.0, limits).map_err(|_| e),
            }
        }
        Err(e) => Err(e),
    }
}

/// The far side of the braking gap: one braking ramp from `v0` whose distance, falling again
/// past its maximum (see [`reach_down`]), comes back to `distance`; `None` when even a full
/// stop takes longer (then there is no far side).
fn reach_past_gap(v0: f64, distance: f64, limits: &Limits) -> Option<Bound> {
    let braking = |delta: f64| Ramp::new(delta, limits).distance(v0, (v0 - delta).max(0.0));
    if braking(v0) > distance {
        return None;
    }
    // Maximiser of the braking distance, as in `reach_down`.
    let (a, j) = (limits.max_acceleration(), limits.max_jerk());
    let delta_m = if 2.0 * v0 / 3.0 <= limits.full_ramp_speed_change() {
        2.0 * v0 / 3.0
    } else {
        v0 - 0.5 * a * a / j
    };
    let g = |delta: f64| braking(delta) - distance;
    let (gm, g0) = (g(delta_m), g(v0));
    if gm <= 0.0 {
        return None;
    }
    let delta = brent(g, delta_m, v0, gm, g0);
    Some(Bound {
        speed: (v0 - delta).max(0.0),
        first: (Ramp::new(delta, limits), -1.0),
        second: (Ramp::new(0.0, limits), 1.0),
    })
}

/// Braking from `v0` to rest, then speeding up over the rest of `distance`: the highest end
/// speed that way and its two ramps; `None` when `v0` cannot stop within `distance`.
fn reach_through_rest(v0: f64, distance: f64, limits: &Limits) -> Option<Bound> {
    let stop = change_distance(v0, 0.0, limits);
    if stop > distance {
        return None;
    }
    let gain = speed_gain_over(0.0, distance - stop, limits);
    Some(Bound {
        speed: gain,
        first: (Ramp::new(v0, limits), -1.0),
        second: (Ramp::new(gain, limits), 1.0),
    })
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

    /// The same motion run backward, from `v0` (the bound's speed up to rounding) to the
    /// speed it started from: the ramps in reverse order with their signs flipped.
    pub fn reversed(&self, v0: f64, limits: &Limits) -> Profile {
        let (r0, s0) = self.first;
        let (r1, s1) = self.second;
        Profile::from_ramps(v0, r1, -s1, 0.0, r0, -s0, limits.max_jerk())
    }
}

/// The highest end speed from `v0` in `distance`, not capped at V: one ramp up over the whole
/// distance, or a stop first and a ramp up from rest over what is left, whichever is higher.
pub(crate) fn reach_up(v0: f64, distance: f64, limits: &Limits) -> Bound {
    let gain = speed_gain_over(v0, distance, limits);
    let best = Bound {
        speed: v0 + gain,
        first: (Ramp::new(gain, limits), 1.0),
        second: (Ramp::new(0.0, limits), -1.0),
    };
    match reach_through_rest(v0, distance, limits) {
        Some(b) if b.speed > best.speed => b,
        _ => best,
    }
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
    fn start_bound_grows_with_the_end_cap_and_every_start_below_it_is_planned() {
        let l = Limits::new(50.0, 2000.0, 50000.0).unwrap();
        for d in [0.01, 0.05, 0.3, 2.0] {
            let mut last = 0.0;
            for k in 0..=50 {
                let cap = k as f64;
                let bound = max_start_speed(cap, d, &l).unwrap();
                assert!(bound >= last, "{d} {cap}: {bound} < {last}");
                last = bound;
                for f in [0.0, 0.3, 0.7, 0.99, 1.0] {
                    let v0 = f * bound;
                    let p = solve_at_most(d, v0, cap, &l).unwrap();
                    assert!(p.end().v <= cap + 1e-9, "{d} {cap} {v0}: {}", p.end().v);
                    assert!((p.distance() - d).abs() <= 1e-9 * d, "{d} {cap} {v0}");
                }
            }
        }
        // The single ramp from the cap alone falls as the cap rises from rest (0.05 mm at
        // J = 50000: 5 mm/s from rest, 4.77 from 1 mm/s); the bound keeps the 5.
        let single = max_reachable_speed(1.0, 0.05, &l).unwrap();
        assert!((single - 4.77).abs() < 0.01, "{single}");
        assert!((max_start_speed(1.0, 0.05, &l).unwrap() - 5.0).abs() < 1e-12);
    }

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

//! The time-optimal forward profile over a path length L from speed v0 to speed v1 with zero
//! acceleration at both ends, under limits V, A, J: [`solve`].
//!
//! Every candidate is two time-optimal ramps ([`Ramp`]) through a middle speed vm plus a cruise
//! at vm; its distance is F(vm) = ½(v0+vm)·T(|vm−v0|) + ½(vm+v1)·T(|v1−vm|) (eq. R3) + vm·t_c.
//! Let d = F(v0 → v1 directly), the distance of the single ramp between the two speeds.
//! * L ≥ d: speed up then slow down (the most distance in a given time). F is increasing in
//!   vm ≥ max(v0, v1), so vm is the root of F(vm) = L, or vm = V with the rest as cruise when
//!   F(V) ≤ L (eq. S1).
//! * L < d: the single ramp already goes too far, and the least distance in a given time is
//!   covered by slowing down below min(v0, v1) first, then speeding up. F is concave in
//!   vm ≤ min(v0, v1) (each ramp's distance is concave in its speed change: √δ pieces and a
//!   downward parabola, joined C¹), and F(min) = d > L, so {F ≤ L} is a ray and vm is its
//!   largest point (eq. S2). F first rises as vm drops, so the duration jumps as L falls below
//!   d. If even vm = 0 gives F > L, the optimum would drive backward (Ruckig returns exactly
//!   that); for a path that is [`ProfileError::EndSpeedUnreachable`].
//!
//! These are the extremal ("bang-bang jerk") profiles that Ruckig enumerates for one axis with
//! zero end accelerations (Berscheid & Kröger 2021); tests/ruckig_oracle.rs checks the match.
//! vm is solved for as an offset x ≥ 0 from max(v0, v1) or min(v0, v1), so that small speed
//! changes keep full relative precision; in x = u², F is smooth in u. Closed forms: cruise
//! (S1 at V), both ramps at the acceleration limit (F quadratic in x), and equal end speeds
//! without plateaus (a depressed cubic in u); the other pieces are polynomials of higher
//! degree in u, solved with Brent's method on the piece's bracket.

use super::error::{ProfileError, SpeedKind};
use super::ramp::{change_distance, Ramp};
use super::roots::{brent, depressed_cubic};
use super::{reach, Limits, Profile};

/// Distances within this relative amount of a feasibility boundary count as on it, so that an
/// end speed returned by [`reach::max_reachable_speed`] is accepted back by [`solve`]. The
/// resulting end-position error is far below the 1e-9 the tests demand.
pub(crate) const DISTANCE_TOL: f64 = 1e-12;

/// An end speed within this amount (relative to V) of the reachable bound is taken as the bound:
/// near a bound, one ulp of speed can be worth far more than one ulp of distance (d ∝ √δ).
pub(crate) const SPEED_TOL: f64 = 1e-12;

/// The time-optimal profile covering `distance` from speed `v0` to speed `v1`, with zero
/// acceleration at both ends and v ≥ 0 throughout (see the module comment).
///
/// # Errors
/// [`ProfileError::Distance`] or [`ProfileError::Speed`] for invalid input (NaN, negative,
/// speed above the limit); [`ProfileError::EndSpeedUnreachable`] when v1 cannot be met within
/// `distance` while moving forward, carrying the reachable end speed nearest to it.
pub fn solve(distance: f64, v0: f64, v1: f64, limits: &Limits) -> Result<Profile, ProfileError> {
    check_distance(distance)?;
    check_speed(SpeedKind::Start, v0, limits)?;
    check_speed(SpeedKind::End, v1, limits)?;
    let direct = change_distance(v0, v1, limits);
    if distance >= direct * (1.0 - DISTANCE_TOL) {
        let fam = Family::new(v0, v1, Side::Up, limits);
        let x_max = (limits.max_velocity() - fam.base).max(0.0);
        let f_max = fam.distance(x_max);
        if f_max <= distance {
            // S1 at the speed limit: the remainder is cruise at V.
            let cruise = (distance - f_max) / limits.max_velocity();
            return Ok(fam.profile(x_max, cruise));
        }
        let x = if distance <= direct {
            0.0
        } else {
            fam.solve(distance, x_max)
        };
        return Ok(fam.profile(x, 0.0));
    }
    let fam = Family::new(v0, v1, Side::Down, limits);
    let x_max = fam.base;
    let f_zero = fam.distance(x_max);
    if f_zero > distance * (1.0 + DISTANCE_TOL) {
        let bound = if v1 > v0 {
            Some(reach::reach_up(v0, distance, limits))
        } else {
            reach::reach_down(v0, distance, limits)
        };
        let reachable = bound.as_ref().map_or(0.0, |b| b.speed);
        if let Some(b) = bound.filter(|b| (b.speed - v1).abs() <= SPEED_TOL * limits.max_velocity())
        {
            // v1 is the reachable bound up to rounding: the bound's profile uses exactly the
            // distance and ends within SPEED_TOL of v1.
            return Ok(b.profile(v0, limits));
        }
        if v1 < v0 {
            // Braking, v0 may be the highest start from which v1 is reachable, up to rounding
            // (a backward pass finds it by speeding up from v1): that speed-up, run backward,
            // uses exactly the distance.
            let back = reach::reach_up(v1, distance, limits);
            if (back.speed - v0).abs() <= SPEED_TOL * limits.max_velocity() {
                return Ok(back.reversed(v0, limits));
            }
        }
        return Err(ProfileError::EndSpeedUnreachable {
            start: v0,
            requested: v1,
            distance,
            reachable,
        });
    }
    let x = if f_zero >= distance {
        x_max
    } else {
        fam.solve(distance, x_max)
    };
    Ok(fam.profile(x, 0.0))
}

pub(crate) fn check_distance(distance: f64) -> Result<(), ProfileError> {
    if distance.is_finite() && distance >= 0.0 {
        Ok(())
    } else {
        Err(ProfileError::Distance(distance))
    }
}

pub(crate) fn check_speed(which: SpeedKind, v: f64, limits: &Limits) -> Result<(), ProfileError> {
    if v >= 0.0 && v <= limits.max_velocity() {
        Ok(())
    } else {
        Err(ProfileError::Speed {
            which,
            value: v,
            max_velocity: limits.max_velocity(),
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Side {
    /// vm = max(v0, v1) + x.
    Up,
    /// vm = min(v0, v1) − x.
    Down,
}

/// The two-ramp profiles through vm, parametrised by the offset x ≥ 0 of vm from `base`.
struct Family<'a> {
    v0: f64,
    v1: f64,
    side: Side,
    /// max(v0, v1) for `Up`, min(v0, v1) for `Down`.
    base: f64,
    /// |base − v0| and |base − v1| (one of them is 0).
    gap0: f64,
    gap1: f64,
    limits: &'a Limits,
}

impl<'a> Family<'a> {
    fn new(v0: f64, v1: f64, side: Side, limits: &'a Limits) -> Self {
        let base = match side {
            Side::Up => v0.max(v1),
            Side::Down => v0.min(v1),
        };
        Family {
            v0,
            v1,
            side,
            base,
            gap0: (base - v0).abs(),
            gap1: (base - v1).abs(),
            limits,
        }
    }

    fn middle_speed(&self, x: f64) -> f64 {
        match self.side {
            Side::Up => self.base + x,
            Side::Down => (self.base - x).max(0.0),
        }
    }

    /// The two ramps' speed changes, each computed without cancellation.
    fn ramps(&self, x: f64) -> (Ramp, Ramp) {
        (
            Ramp::new(self.gap0 + x, self.limits),
            Ramp::new(self.gap1 + x, self.limits),
        )
    }

    /// F(vm(x)), the distance without cruise.
    fn distance(&self, x: f64) -> f64 {
        let vm = self.middle_speed(x);
        let (r0, r1) = self.ramps(x);
        r0.distance(self.v0, vm) + r1.distance(vm, self.v1)
    }

    fn profile(&self, x: f64, cruise: f64) -> Profile {
        let (r0, r1) = self.ramps(x);
        let (s0, s1) = match self.side {
            Side::Up => (1.0, -1.0),
            Side::Down => (-1.0, 1.0),
        };
        Profile::from_ramps(self.v0, r0, s0, cruise, r1, s1, self.limits.max_jerk())
    }

    /// The offset x ∈ [0, x_max] with F = `distance` (S1's root for `Up`, S2's for `Down`),
    /// given F(0) − distance and F(x_max) − distance of opposite signs.
    fn solve(&self, distance: f64, x_max: f64) -> f64 {
        let (a, j) = (self.limits.max_acceleration(), self.limits.max_jerk());
        // Both ramps reach A once x ≥ A²/J (one gap is 0). There F is quadratic in x:
        // F(x_b + y) = F_b + F'_b·y ± y²/A with F'_b = 2·vm_b/A ± A/J (+ for Up, − for Down).
        let x_b = self.limits.full_ramp_speed_change();
        if x_b < x_max {
            let f_b = self.distance(x_b);
            let vm_b = self.middle_speed(x_b);
            let y = match self.side {
                Side::Up if f_b <= distance => {
                    let slope = 2.0 * vm_b / a + a / j;
                    let rest = distance - f_b;
                    Some(2.0 * rest / (slope + (slope * slope + 4.0 * rest / a).sqrt()))
                }
                Side::Down if f_b >= distance => {
                    // Concave: the one positive root of F_b − L + F'_b·y − y²/A = 0.
                    let slope = 2.0 * vm_b / a - a / j;
                    let excess = f_b - distance;
                    let root = (slope * slope + 4.0 * excess / a).sqrt();
                    Some(if slope >= 0.0 {
                        0.5 * a * (slope + root)
                    } else {
                        2.0 * excess / (root - slope)
                    })
                }
                _ => None,
            };
            if let Some(y) = y {
                return (x_b + y).min(x_max);
            }
        }
        let x_hi = x_b.min(x_max);
        if self.side == Side::Up && self.gap0 == 0.0 && self.gap1 == 0.0 {
            // Equal end speeds, no plateau: F = 2(2v + u²)·u/√J, i.e. u³ + 2v·u − L√J/2 = 0.
            let u = depressed_cubic(2.0 * self.base, 0.5 * distance * j.sqrt());
            return (u * u).min(x_hi);
        }
        let g = |u: f64| self.distance(u * u) - distance;
        let u_hi = x_hi.sqrt();
        let u = brent(g, 0.0, u_hi, g(0.0), g(u_hi));
        (u * u).min(x_hi)
    }
}

//! One time-optimal speed change by δ ≥ 0 that starts and ends at zero acceleration: jerk ±J,
//! an optional constant-acceleration plateau at ±A, jerk ∓J (the three phases on either side of
//! a [`Profile`](super::Profile)'s cruise). Closed forms only.
//!
//! With jerk time `tj` and plateau time `ta` the change is δ = J·tj·(tj + ta) (acceleration
//! rises to J·tj, holds, falls). Minimum time takes J·tj = A as soon as δ ≥ A²/J:
//!   δ ≤ A²/J: tj = √(δ/J),  ta = 0            (eq. R1)
//!   δ > A²/J: tj = A/J,      ta = δ/A − A/J    (eq. R2)
//! The speed curve is point-symmetric about the ramp's midpoint, so the distance covered is the
//! mean speed times the duration: d = ½(v_start + v_end)·(2·tj + ta)  (eq. R3).

use super::Limits;

/// Phase durations of one speed change (see the module comment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ramp {
    /// Duration of each of the two jerk phases.
    pub jerk_time: f64,
    /// Duration of the constant-acceleration plateau.
    pub accel_time: f64,
}

impl Ramp {
    /// The time-optimal ramp for a speed change of `delta` ≥ 0 (eqs. R1, R2).
    pub fn new(delta: f64, limits: &Limits) -> Ramp {
        let (a, j) = (limits.max_acceleration(), limits.max_jerk());
        let delta = delta.max(0.0);
        if delta <= limits.full_ramp_speed_change() {
            Ramp {
                jerk_time: (delta / j).sqrt(),
                accel_time: 0.0,
            }
        } else {
            Ramp {
                jerk_time: a / j,
                accel_time: delta / a - a / j,
            }
        }
    }

    pub fn duration(&self) -> f64 {
        2.0 * self.jerk_time + self.accel_time
    }

    /// Distance covered while the speed goes from `v_start` to `v_end` (eq. R3).
    pub fn distance(&self, v_start: f64, v_end: f64) -> f64 {
        0.5 * (v_start + v_end) * self.duration()
    }
}

/// Duration of the time-optimal speed change v0 → v1 (zero acceleration at both ends).
pub(crate) fn change_time(v0: f64, v1: f64, limits: &Limits) -> f64 {
    Ramp::new((v1 - v0).abs(), limits).duration()
}

/// Distance of the time-optimal speed change v0 → v1 (zero acceleration at both ends).
pub(crate) fn change_distance(v0: f64, v1: f64, limits: &Limits) -> f64 {
    Ramp::new((v1 - v0).abs(), limits).distance(v0, v1)
}

/// Solves, in closed form, for the speed gain δ ≥ 0 of a speed-up from `v_start` that covers
/// exactly `distance` ≥ 0 (the inverse of eq. R3 for v_end = v_start + δ).
///
/// Below the plateau (eq. R1) d = (2·v_start + δ)·√(δ/J): with u = √δ this is the depressed cubic
/// u³ + 2·v_start·u − d·√J = 0, which has one real root ([`super::roots::depressed_cubic`]).
/// With a plateau (eq. R2) d is quadratic in δ; it is expanded about the break δ_b = A²/J so that
/// no large terms cancel.
pub(crate) fn speed_gain_over(v_start: f64, distance: f64, limits: &Limits) -> f64 {
    let (a, j) = (limits.max_acceleration(), limits.max_jerk());
    let delta_b = limits.full_ramp_speed_change();
    let d_b = Ramp::new(delta_b, limits).distance(v_start, v_start + delta_b);
    if distance <= d_b {
        let u = super::roots::depressed_cubic(2.0 * v_start, distance * j.sqrt());
        return u * u;
    }
    // d(δ_b + y) = d_b + d'_b·y + y²/(2A), d'_b = v_start/A + 3A/(2J)  (derivative of R3 with R2).
    let slope = v_start / a + 1.5 * a / j;
    let rest = distance - d_b;
    let y = 2.0 * rest / (slope + (slope * slope + 2.0 * rest / a).sqrt());
    delta_b + y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_reaches_the_speed_change() {
        let l = Limits::new(100.0, 1000.0, 20000.0).unwrap();
        for delta in [0.0, 1e-9, 1.0, 50.0, 50.0 + 1e-9, 80.0] {
            let r = Ramp::new(delta, &l);
            let got = 20000.0 * r.jerk_time * (r.jerk_time + r.accel_time);
            assert!(
                (got - delta).abs() <= 1e-12 * delta.max(1.0),
                "{delta} {got}"
            );
            assert!(20000.0 * r.jerk_time <= 1000.0 * (1.0 + 1e-15));
        }
    }

    #[test]
    fn speed_gain_inverts_distance() {
        let l = Limits::new(100.0, 1000.0, 20000.0).unwrap();
        for vs in [0.0, 3.0, 40.0] {
            for d in [1e-9, 0.01, 0.5, 1.0, 3.0, 30.0] {
                let delta = speed_gain_over(vs, d, &l);
                let back = Ramp::new(delta, &l).distance(vs, vs + delta);
                assert!((back - d).abs() <= 1e-12 * d, "{vs} {d} {delta} {back}");
            }
        }
    }
}

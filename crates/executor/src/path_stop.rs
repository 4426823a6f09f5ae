//! The feed hold's stop along the path: the time-optimal jerk-limited stop of the path speed
//! from the state the hold meets (ṡ, s̈), under the path limits of the piece in hand. The
//! executor plays it instead of driving the time scale to 0 when it fits inside the piece
//! (see `executor/hold.rs`); resume then re-times the plan from rest where it stopped.
//!
//! Three constant-jerk phases, Kröger & Wahl's velocity-to-zero case (as Ruckig's velocity
//! interface solves it, and as `stop.rs` stops each joint on an underrun): jerk −J until the
//! acceleration reaches its peak a_p, hold a_p, jerk +J back to zero acceleration exactly as
//! the speed reaches zero. The speed change over the two ramps is (a₀² − 2a_p²)/(2J) = −v₀, so
//! a_p = −√(a₀²/2 + J·v₀), capped at −A with a constant-acceleration phase between. Among
//! jerk-limited stops from (v₀, a₀) it ends soonest and travels least.

/// A stop along the path from speed `v0` (≥ 0) and acceleration `a0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathStop {
    v0: f64,
    a0: f64,
    /// Phase durations (s) and jerks.
    phases: [(f64, f64); 3],
}

/// Distance, speed and acceleration along a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopState {
    pub s: f64,
    pub v: f64,
    pub a: f64,
}

impl PathStop {
    /// The stop under `max_acceleration`, `max_jerk`; `None` if the state cannot stop
    /// without the speed going negative (braking harder than the jerk can release: a₀ < 0 and
    /// v₀ < a₀²/2J) or already exceeds the acceleration limit.
    pub fn new(v0: f64, a0: f64, max_acceleration: f64, max_jerk: f64) -> Option<PathStop> {
        let (a_lim, j) = (max_acceleration, max_jerk);
        if !(v0 >= 0.0 && j > 0.0 && a_lim > 0.0 && a0.abs() <= a_lim) {
            return None;
        }
        // Speed reached if the acceleration were brought to zero at once with full jerk.
        let coast = v0 + a0 * a0.abs() / (2.0 * j);
        if coast < 0.0 {
            return None;
        }
        let peak = -(a0 * a0 / 2.0 + j * v0).sqrt();
        let phases = if peak < -a_lim {
            [
                ((a0 + a_lim) / j, -j),
                (
                    ((v0 + (a0 * a0 - 2.0 * a_lim * a_lim) / (2.0 * j)) / a_lim).max(0.0),
                    0.0,
                ),
                (a_lim / j, j),
            ]
        } else {
            [((a0 - peak) / j, -j), (0.0, 0.0), (-peak / j, j)]
        };
        Some(PathStop {
            v0,
            a0,
            phases: phases.map(|(d, jk)| (d.max(0.0), jk)),
        })
    }

    pub fn duration(&self) -> f64 {
        self.phases.iter().map(|p| p.0).sum()
    }

    /// The state `t` seconds into the stop (at rest after its end).
    pub fn at(&self, t: f64) -> StopState {
        let (mut s, mut v, mut a) = (0.0, self.v0, self.a0);
        let mut left = t.max(0.0);
        for &(d, j) in &self.phases {
            let dt = left.min(d);
            s += dt * (v + dt * (a / 2.0 + dt * j / 6.0));
            v += dt * (a + dt * j / 2.0);
            a += j * dt;
            left -= dt;
            if left <= 0.0 {
                break;
            }
        }
        if t >= self.duration() {
            // Exactly at rest: rounding in the sums must not leave a creep.
            StopState { s, v: 0.0, a: 0.0 }
        } else {
            StopState { s, v, a }
        }
    }

    /// Distance to rest.
    pub fn distance(&self) -> f64 {
        self.at(self.duration()).s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// From cruise, v₀ < A²/J: the stop never reaches A; t = 2√(v/J), distance v·√(v/J)
    /// (two jerk ramps, the closed form of a symmetric S-curve).
    #[test]
    fn cruise_stop_closed_form() {
        let (v, a, j) = (10.0, 2000.0, 50_000.0);
        let stop = PathStop::new(v, 0.0, a, j).unwrap();
        assert!((stop.duration() - 2.0 * (v / j).sqrt()).abs() < 1e-15);
        assert!((stop.distance() - v * (v / j).sqrt()).abs() < 1e-12);
        // v₀ > A²/J: ramps A/J each and a constant phase v/A − A/J; distance
        // v²/(2A) + vA/(2J).
        let v = 200.0;
        let stop = PathStop::new(v, 0.0, a, j).unwrap();
        assert!((stop.duration() - (v / a + a / j)).abs() < 1e-12);
        let want = v * v / (2.0 * a) + v * a / (2.0 * j);
        assert!((stop.distance() - want).abs() < 1e-9, "{}", stop.distance());
    }

    proptest! {
        /// From any state that can stop: the speed never goes negative, the acceleration and
        /// jerk stay within the limits (by differences over a fine grid), and it ends at rest.
        #[test]
        fn stops_within_the_limits(v0 in 0.0..300.0f64, a_share in -1.0..=1.0f64,
                                   a in 100.0..5000.0f64, j in 1e3..1e6f64) {
            let a0 = a_share * a;
            let Some(stop) = PathStop::new(v0, a0, a, j) else {
                prop_assert!(v0 + a0 * a0.abs() / (2.0 * j) < 0.0);
                return Ok(());
            };
            let n = 2000;
            let d = stop.duration();
            let h = d / n as f64;
            let mut prev = stop.at(0.0);
            for k in 1..=n {
                let x = stop.at(k as f64 * h);
                prop_assert!(x.v >= -1e-9 * v0.max(1.0), "v {}", x.v);
                prop_assert!(x.a.abs() <= a * (1.0 + 1e-9));
                prop_assert!(((x.a - prev.a) / h).abs() <= j * (1.0 + 1e-6));
                prop_assert!(x.s >= prev.s - 1e-12);
                prev = x;
            }
            let end = stop.at(d);
            prop_assert!(end.v == 0.0 && end.a == 0.0);
            prop_assert!((stop.at(d + 1.0).s - end.s).abs() < 1e-12);
        }
    }
}

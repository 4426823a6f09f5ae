//! The jerk-limited stop of each joint from its last commanded velocity and acceleration: what
//! the real-time thread plays when the ring runs dry (an underrun). Closed form, fixed size,
//! no allocation: it runs inside the period.
//!
//! Per joint, the time-optimal velocity-to-zero profile (Kröger & Wahl's velocity-control
//! case, as Ruckig's "velocity interface" solves it): jerk −J until the acceleration reaches a
//! peak `a_p`, hold `a_p`, jerk +J back to zero acceleration exactly as the velocity reaches
//! zero. With the joint's state mirrored so that it must slow down (v + a|a|/(2J) > 0), the
//! velocity change over the two ramps is (a₀² − 2a_p²)/(2J) = −v₀, so
//! a_p = −√(a₀²/2 + J·v₀), capped at −A with a constant-acceleration phase between. Each joint
//! stops on its own time, so the tool leaves the path by the difference: an underrun is a
//! fault, the stop only makes it harmless (no jump, no limit exceeded).

use tezgah_kinematics::Joints;

const MAX: usize = tezgah_kinematics::pose::MAX_JOINTS;

/// One joint's stop: three constant-jerk phases from (p₀, v₀, a₀).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct AxisStop {
    p0: f64,
    v0: f64,
    a0: f64,
    /// Phase durations (s) and jerks.
    phases: [(f64, f64); 3],
}

impl AxisStop {
    fn new(p0: f64, v0: f64, a0: f64, max_acc: f64, max_jerk: f64) -> AxisStop {
        let (a_lim, j) = (max_acc, max_jerk);
        let mut phases = [(0.0, 0.0); 3];
        // Velocity reached if the acceleration were brought to zero at once with full jerk.
        let coast = v0 + a0 * a0.abs() / (2.0 * j);
        if coast == 0.0 || !(j > 0.0 && a_lim > 0.0) {
            // Only the acceleration to remove (or no limits to stop with).
            if j > 0.0 {
                phases[0] = (a0.abs() / j, -a0.signum() * j);
            }
            return AxisStop { p0, v0, a0, phases };
        }
        // Mirror so that the joint must slow a positive velocity.
        let sigma = coast.signum();
        let (v, a) = (sigma * v0, sigma * a0);
        let (t1, t2, t3);
        if a < -a_lim {
            // Already beyond the limit (a corrupt set-point): hold it, then release.
            t1 = 0.0;
            t2 = ((v - a * a / (2.0 * j)) / -a).max(0.0);
            t3 = -a / j;
        } else {
            let peak = -(a * a / 2.0 + j * v).max(0.0).sqrt();
            if peak < -a_lim {
                t1 = (a + a_lim) / j;
                t2 = ((v + (a * a - 2.0 * a_lim * a_lim) / (2.0 * j)) / a_lim).max(0.0);
                t3 = a_lim / j;
            } else {
                t1 = (a - peak) / j;
                t2 = 0.0;
                t3 = -peak / j;
            }
        }
        phases[0] = (t1.max(0.0), -sigma * j);
        phases[1] = (t2, 0.0);
        phases[2] = (t3.max(0.0), sigma * j);
        AxisStop { p0, v0, a0, phases }
    }

    fn duration(&self) -> f64 {
        self.phases.iter().map(|p| p.0).sum()
    }

    /// Position, velocity, acceleration at time t after the start (at rest after the end).
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let (mut p, mut v, mut a) = (self.p0, self.v0, self.a0);
        let mut left = t.max(0.0);
        for &(d, j) in &self.phases {
            let dt = left.min(d);
            p += v * dt + a * dt * dt / 2.0 + j * dt * dt * dt / 6.0;
            v += a * dt + j * dt * dt / 2.0;
            a += j * dt;
            left -= dt;
            if left <= 0.0 {
                break;
            }
        }
        if t >= self.duration() {
            // Exactly at rest: rounding in the sums must not leave a creep.
            (p, 0.0, 0.0)
        } else {
            (p, v, a)
        }
    }
}

/// Distance a jerk-limited stop from speed `v` and acceleration `a` travels under
/// `max_acceleration`, `max_jerk` (the same closed form, along a path or a joint).
pub fn stopping_distance(v: f64, a: f64, max_acceleration: f64, max_jerk: f64) -> f64 {
    let s = AxisStop::new(0.0, v, a, max_acceleration, max_jerk);
    s.at(s.duration()).0
}

/// Every joint's stop, evaluated together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointStop {
    axes: [AxisStop; MAX],
    len: usize,
}

/// A joint state on the stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointState {
    pub position: Joints,
    pub velocity: Joints,
    pub acceleration: Joints,
}

impl JointStop {
    /// The stop from `position`, `velocity`, `acceleration` under per-joint limits
    /// `max_acceleration`, `max_jerk` (same units, same order).
    pub fn new(
        position: &Joints,
        velocity: &Joints,
        acceleration: &Joints,
        max_acceleration: &Joints,
        max_jerk: &Joints,
    ) -> JointStop {
        let len = position.len();
        let mut axes = [AxisStop::default(); MAX];
        for (i, axis) in axes.iter_mut().enumerate().take(len) {
            let g = |q: &Joints| q.as_slice().get(i).copied().unwrap_or(0.0);
            *axis = AxisStop::new(
                g(position),
                g(velocity),
                g(acceleration),
                g(max_acceleration),
                g(max_jerk),
            );
        }
        JointStop { axes, len }
    }

    /// Time until the last joint is at rest, s.
    pub fn duration(&self) -> f64 {
        self.axes[..self.len]
            .iter()
            .map(AxisStop::duration)
            .fold(0.0, f64::max)
    }

    /// The joints t seconds into the stop.
    pub fn at(&self, t: f64) -> JointState {
        let mut position = Joints::zeros(self.len);
        let mut velocity = Joints::zeros(self.len);
        let mut acceleration = Joints::zeros(self.len);
        for i in 0..self.len {
            let (p, v, a) = self.axes[i].at(t);
            position.as_mut_slice()[i] = p;
            velocity.as_mut_slice()[i] = v;
            acceleration.as_mut_slice()[i] = a;
        }
        JointState {
            position,
            velocity,
            acceleration,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The textbook case: from v with a = 0 and A reached, the stop takes v/A + A/J and
    /// travels v²/(2A) + vA/(2J) (the jerk-limited braking distance).
    #[test]
    fn from_cruise_matches_the_closed_form() {
        let (v, a_max, j_max) = (100.0, 1000.0, 20_000.0);
        let s = AxisStop::new(0.0, v, 0.0, a_max, j_max);
        let t = s.duration();
        assert!((t - (v / a_max + a_max / j_max)).abs() < 1e-12);
        let (p, ve, ae) = s.at(t);
        assert!((p - (v * v / (2.0 * a_max) + v * a_max / (2.0 * j_max))).abs() < 1e-9);
        assert_eq!((ve, ae), (0.0, 0.0));
    }

    proptest! {
        /// Any start state within the limits: at rest at the end, velocity never changes
        /// sign beyond rounding (no backing up), acceleration within A, jerk within J.
        #[test]
        fn stops_within_limits(v in -300.0..300.0f64, af in -1.0..=1.0f64,
                               a_max in 10.0..5000.0f64, j_max in 100.0..1e6f64) {
            let a0 = af * a_max;
            let s = AxisStop::new(1.0, v, a0, a_max, j_max);
            let t_end = s.duration();
            prop_assert!(t_end.is_finite());
            let coast = v + a0 * a0.abs() / (2.0 * j_max);
            let n = 400;
            let mut prev = s.at(0.0);
            let mut crossings = 0;
            for k in 1..=n {
                let t = t_end * k as f64 / n as f64;
                let (p, vv, aa) = s.at(t);
                prop_assert!(aa.abs() <= a_max * (1.0 + 1e-9), "a {aa}");
                // The velocity crosses zero at most once (only when the start acceleration
                // already carries it past zero: then the stop settles on coast's side).
                if vv * prev.1 < 0.0 && vv.abs().min(prev.1.abs()) > 1e-9 * (1.0 + v.abs()) {
                    crossings += 1;
                }
                let dt = t_end / n as f64;
                prop_assert!((aa - prev.2).abs() <= j_max * dt * (1.0 + 1e-9) + 1e-9);
                prev = (p, vv, aa);
            }
            prop_assert!(crossings <= 1);
            if crossings == 1 {
                prop_assert!(v * coast < 0.0, "v {v} coast {coast}");
            }
            let (_, ve, ae) = s.at(t_end);
            prop_assert_eq!((ve, ae), (0.0, 0.0));
            // Just before the end the state is continuous with rest (no jump into it).
            let dt = 1e-9 * t_end;
            let (_, ve, ae) = s.at(t_end - dt);
            prop_assert!(ae.abs() <= j_max * dt * (1.0 + 1e-6) + 1e-9 * a_max, "a {ae}");
            prop_assert!(ve.abs() <= j_max * dt * dt + 1e-9 * (1.0 + v.abs()), "v {ve}");
        }
    }
}

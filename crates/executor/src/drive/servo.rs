//! The simulated servo drive: per joint a discrete-time position loop with velocity and
//! acceleration (torque) feed-forward around a velocity loop, driving a rigid inertia with
//! viscous friction through a saturating actuator. It sits at the end of the executor's flow
//! (set-point → [`Drive::apply`]) and produces the following error that the tracking metrics
//! (Kelekçi, 2021, eq. 5.1) report.
//!
//! Per joint, in internal units (mm or rad), with e = x_c − x the following error:
//!   u = k_aff·(a_c + β·v_c) + K_v·(k_vff·v_c + K_p·e − v),   ẍ = sat(u) − β·ẋ,
//! where u is the actuator force divided by the inertia m and β = b/m the friction rate. With
//! K_v = 4·K_p the loop without feed-forward is K_vK_p/(s² + K_v s + K_vK_p) = 4K_p²/(s + 2K_p)²,
//! a critically damped pair whose −3 dB frequency is 2K_p·√(√2 − 1) = 1.287·K_p; the machine
//! file's `bandwidth_hz` is that frequency, so K_p = 2π·f/1.287. Closed forms the tests check:
//! on a ramp of speed v without feed-forward, e = v·(1 + β/K_v)/K_p (v/K_p without friction);
//! with full feed-forward the error dynamics are ë + (K_v + β)ė + K_vK_p·e = 0, so e → 0.
//!
//! The drive runs its loop `n` times per set-point period (the machine's `loop_period_s`), as
//! real drives run their velocity loop at 8–16 kHz under a 1 kHz set-point stream (CSP mode).
//! Between two set-points it follows the cubic Hermite curve through their positions and
//! velocities (exact for the constant-jerk pieces the planners produce) and reports the
//! following error at the set-point's own instant. Each control step holds u (zero-order hold)
//! and integrates the plant exactly; the feed-forward takes the command at the step's middle,
//! which is its mean over the step for a cubic, so the held force delivers the commanded
//! velocity change.

use std::f64::consts::PI;

use tezgah_kinematics::machine::{ServoSettings, SERVO_BANDWIDTH_PER_KP};
use tezgah_kinematics::pose::MAX_JOINTS;
use tezgah_kinematics::{JointKind, Joints, Machine};
use thiserror::Error;

use super::{Drive, DriveFault, DriveStatus};
use crate::setpoint::SetPoint;

/// Why a servo drive could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ServoError {
    /// A parameter is out of range (the machine reader checks the same for files).
    #[error("servo joint {joint}: {reason}")]
    Invalid { joint: usize, reason: String },
    /// The set-point period is not a positive number of seconds.
    #[error("servo drive: period {0} s must be > 0")]
    Period(f64),
    /// The start position has another joint count than the parameters.
    #[error("servo drive: {given} start joints for {expected} axes")]
    JointCount { given: usize, expected: usize },
}

/// One axis's loop in internal units (mm or rad; forces per unit inertia).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoParams {
    /// Position loop gain K_p, 1/s.
    pub kp: f64,
    /// Velocity loop gain K_v, 1/s (4·K_p).
    pub kv: f64,
    /// Friction rate β = b/m, 1/s.
    pub friction_rate: f64,
    /// Saturation of u = force/m, mm/s² or rad/s².
    pub max_accel: f64,
    /// Velocity feed-forward gain.
    pub kvff: f64,
    /// Torque feed-forward gain.
    pub kaff: f64,
    /// Control period of the drive, s.
    pub loop_period_s: f64,
    /// Fault threshold on |e|, mm or rad (∞: never).
    pub following_error_limit: f64,
}

/// Velocity-loop gain over position-loop gain: 4 makes the pair critically damped.
pub const VELOCITY_LOOP_RATIO: f64 = 4.0;

impl ServoParams {
    /// From a `[joint.servo]` table (file units) for a joint of `kind`.
    pub fn from_settings(s: &ServoSettings, kind: JointKind) -> ServoParams {
        // SI per internal unit: 1 mm = 1e-3 m; a rotary joint is already in rad.
        let (si, to_internal) = match kind {
            JointKind::Linear => (1e-3, 1.0),
            JointKind::Rotary => (1.0, PI / 180.0),
        };
        let kp = 2.0 * PI * s.bandwidth_hz / SERVO_BANDWIDTH_PER_KP;
        ServoParams {
            kp,
            kv: VELOCITY_LOOP_RATIO * kp,
            friction_rate: s.friction / s.inertia,
            max_accel: s.max_force / (s.inertia * si),
            kvff: s.velocity_feed_forward,
            kaff: s.acceleration_feed_forward,
            loop_period_s: s.loop_period_s,
            following_error_limit: s
                .following_error_limit
                .map_or(f64::INFINITY, |l| l * to_internal),
        }
    }

    /// The closed-loop −3 dB bandwidth without feed-forward, Hz.
    pub fn bandwidth_hz(&self) -> f64 {
        self.kp * SERVO_BANDWIDTH_PER_KP / (2.0 * PI)
    }

    fn check(&self, joint: usize) -> Result<(), ServoError> {
        let bad = |reason: &str| {
            Err(ServoError::Invalid {
                joint,
                reason: reason.to_owned(),
            })
        };
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !(pos(self.kp) && pos(self.kv) && pos(self.max_accel) && pos(self.loop_period_s)) {
            return bad("gains, saturation and loop period must be finite and > 0");
        }
        if !(self.friction_rate.is_finite() && self.friction_rate >= 0.0) {
            return bad("friction must be finite and >= 0");
        }
        if !(self.kvff.is_finite() && self.kaff.is_finite()) {
            return bad("feed-forward gains must be finite");
        }
        if self.following_error_limit.is_nan() || self.following_error_limit <= 0.0 {
            return bad("following error limit must be > 0");
        }
        Ok(())
    }
}

/// The command seen by one control step: position, velocity and acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisCommand {
    /// Position and velocity at the step's start (compared with the measured ones).
    pub position: f64,
    pub velocity: f64,
    /// Velocity and acceleration at the step's middle (feed-forward).
    pub ff_velocity: f64,
    pub ff_acceleration: f64,
}

/// One simulated axis: the plant state and its loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoAxis {
    params: ServoParams,
    /// Measured position and velocity.
    x: f64,
    v: f64,
}

impl ServoAxis {
    /// At rest at `position`.
    pub fn new(params: ServoParams, position: f64) -> ServoAxis {
        ServoAxis {
            params,
            x: position,
            v: 0.0,
        }
    }

    pub fn position(&self) -> f64 {
        self.x
    }

    pub fn velocity(&self) -> f64 {
        self.v
    }

    pub fn params(&self) -> &ServoParams {
        &self.params
    }

    /// The force per unit inertia the loop asks for, after saturation.
    pub fn control(&self, c: &AxisCommand) -> f64 {
        let p = &self.params;
        let u = p.kaff * (c.ff_acceleration + p.friction_rate * c.ff_velocity)
            + p.kv * (p.kvff * c.velocity + p.kp * (c.position - self.x) - self.v);
        u.clamp(-p.max_accel, p.max_accel)
    }

    /// One control step of `h` seconds: hold u, integrate ẍ = u − β·ẋ exactly.
    pub fn step(&mut self, c: &AxisCommand, h: f64) {
        let u = self.control(c);
        let beta = self.params.friction_rate;
        let bh = beta * h;
        if bh < 1e-6 {
            // Series of the exact solution in βh (the closed form below cancels badly).
            let dv = (u - beta * self.v) * h * (1.0 - 0.5 * bh);
            self.x += h * (self.v + 0.5 * (u - beta * self.v) * h * (1.0 - bh / 3.0));
            self.v += dv;
        } else {
            // v(t) = v∞ + (v₀ − v∞)e^{−βt} with v∞ = u/β; x integrates it.
            let vinf = u / beta;
            let decay = -(-bh).exp_m1(); // 1 − e^{−βh}
            self.x += vinf * h + (self.v - vinf) * decay / beta;
            self.v = vinf + (self.v - vinf) * (1.0 - decay);
        }
    }
}

/// A cubic Hermite piece through (x₀, v₀) at 0 and (x₁, v₁) at T: the command between two
/// set-points.
#[derive(Debug, Clone, Copy)]
struct Hermite {
    c: [f64; 4],
}

impl Hermite {
    fn new(x0: f64, v0: f64, x1: f64, v1: f64, t: f64) -> Hermite {
        let d = x1 - x0;
        Hermite {
            c: [
                x0,
                v0,
                (3.0 * d - (2.0 * v0 + v1) * t) / (t * t),
                (-2.0 * d + (v0 + v1) * t) / (t * t * t),
            ],
        }
    }

    /// Position, velocity, acceleration at τ.
    fn at(&self, tau: f64) -> (f64, f64, f64) {
        let [a, b, c, d] = self.c;
        (
            a + tau * (b + tau * (c + tau * d)),
            b + tau * (2.0 * c + 3.0 * tau * d),
            2.0 * c + 6.0 * tau * d,
        )
    }
}

/// The simulated drive of a whole machine: one [`ServoAxis`] per joint.
#[derive(Debug, Clone)]
pub struct ServoDrive {
    axes: [ServoAxis; MAX_JOINTS],
    joints: usize,
    period_s: f64,
    /// Control steps per set-point period.
    substeps: usize,
    /// The last set-point applied (position, velocity), the start of the next Hermite piece.
    last: SetPoint,
    fault: Option<DriveFault>,
}

impl ServoDrive {
    /// One axis per parameter set, at rest at `start`, fed every `period_s`.
    pub fn new(params: &[ServoParams], period_s: f64, start: &Joints) -> Result<Self, ServoError> {
        if start.len() != params.len() || params.len() > MAX_JOINTS {
            return Err(ServoError::JointCount {
                given: start.len(),
                expected: params.len(),
            });
        }
        let mut axes = [ServoAxis::new(
            ServoParams {
                kp: 1.0,
                kv: 4.0,
                friction_rate: 0.0,
                max_accel: 1.0,
                kvff: 0.0,
                kaff: 0.0,
                loop_period_s: period_s,
                following_error_limit: f64::INFINITY,
            },
            0.0,
        ); MAX_JOINTS];
        for (i, p) in params.iter().enumerate() {
            p.check(i)?;
            axes[i] = ServoAxis::new(*p, start[i]);
        }
        if !(period_s.is_finite() && period_s > 0.0) {
            return Err(ServoError::Period(period_s));
        }
        // The finest loop period among the axes sets the common step count.
        let finest = params
            .iter()
            .map(|p| p.loop_period_s)
            .fold(period_s, f64::min);
        let substeps = ((period_s / finest).round() as usize).max(1);
        Ok(ServoDrive {
            axes,
            joints: params.len(),
            period_s,
            substeps,
            last: SetPoint::at_rest(0, 0, *start),
            fault: None,
        })
    }

    /// The machine's `[joint.servo]` tables at its `motion.period_s`.
    pub fn from_machine(machine: &Machine, start: &Joints) -> Result<Self, ServoError> {
        let params: Vec<ServoParams> = machine
            .joints
            .iter()
            .map(|j| ServoParams::from_settings(&j.servo, j.kind))
            .collect();
        Self::new(&params, machine.motion.period_s, start)
    }

    /// Measured joint positions.
    pub fn position(&self) -> Joints {
        let mut q = Joints::zeros(self.joints);
        for (v, a) in q.as_mut_slice().iter_mut().zip(&self.axes) {
            *v = a.position();
        }
        q
    }

    /// The axes (their state and parameters).
    pub fn axes(&self) -> &[ServoAxis] {
        &self.axes[..self.joints]
    }

    /// Control steps per set-point period.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    fn status(&self, commanded: &Joints) -> DriveStatus {
        let position = self.position();
        let mut following_error = Joints::zeros(self.joints);
        for (i, e) in following_error.as_mut_slice().iter_mut().enumerate() {
            *e = commanded[i] - position[i];
        }
        DriveStatus {
            position,
            following_error,
            fault: self.fault,
        }
    }
}

impl Drive for ServoDrive {
    fn apply(&mut self, setpoint: &SetPoint) -> DriveStatus {
        if self.fault.is_some() || setpoint.position.len() != self.joints {
            // Faulted (or fed the wrong machine): the axes are held where they are.
            self.fault.get_or_insert(DriveFault::Offline);
            return self.status(&setpoint.position);
        }
        let (t, n) = (self.period_s, self.substeps);
        let h = t / n as f64;
        for (i, axis) in self.axes[..self.joints].iter_mut().enumerate() {
            let curve = Hermite::new(
                self.last.position[i],
                self.last.velocity[i],
                setpoint.position[i],
                setpoint.velocity[i],
                t,
            );
            for k in 0..n {
                let tau = k as f64 * h;
                let (x, v, _) = curve.at(tau);
                let (_, vm, am) = curve.at(tau + 0.5 * h);
                axis.step(
                    &AxisCommand {
                        position: x,
                        velocity: v,
                        ff_velocity: vm,
                        ff_acceleration: am,
                    },
                    h,
                );
            }
        }
        self.last = *setpoint;
        let status = self.status(&setpoint.position);
        if let Some(joint) = (0..self.joints).find(|&i| {
            status.following_error[i].abs() > self.axes[i].params.following_error_limit
                || !status.position[i].is_finite()
        }) {
            self.fault = Some(DriveFault::FollowingError { joint });
            return DriveStatus {
                fault: self.fault,
                ..status
            };
        }
        status
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(bandwidth_hz: f64, kvff: f64, kaff: f64, friction_rate: f64) -> ServoParams {
        let kp = 2.0 * PI * bandwidth_hz / SERVO_BANDWIDTH_PER_KP;
        ServoParams {
            kp,
            kv: 4.0 * kp,
            friction_rate,
            max_accel: 1e9,
            kvff,
            kaff,
            loop_period_s: 125e-6,
            following_error_limit: f64::INFINITY,
        }
    }

    /// A ramp at speed v from rest (the start jump in speed is what a P loop sees).
    fn run_ramp(p: ServoParams, v: f64, seconds: f64) -> (ServoDrive, f64) {
        let start = Joints::new([0.0]);
        let mut d = ServoDrive::new(&[p], 1e-3, &start).unwrap();
        let mut e = 0.0;
        let n = (seconds / 1e-3) as u64;
        for k in 1..=n {
            let t = k as f64 * 1e-3;
            let s = SetPoint {
                index: k,
                line: 0,
                position: Joints::new([v * t]),
                velocity: Joints::new([v]),
                acceleration: Joints::new([0.0]),
            };
            e = d.apply(&s).following_error[0];
        }
        (d, e)
    }

    #[test]
    fn p_loop_lags_a_ramp_by_v_over_kp() {
        let p = params(20.0, 0.0, 0.0, 0.0);
        let (_, e) = run_ramp(p, 50.0, 0.5);
        let expected = 50.0 / p.kp;
        assert!((e - expected).abs() < 1e-9 * expected, "{e} vs {expected}");
        // with friction: v·(1 + β/K_v)/K_p
        let p = params(20.0, 0.0, 0.0, 30.0);
        let (_, e) = run_ramp(p, 50.0, 0.5);
        let expected = 50.0 * (1.0 + 30.0 / p.kv) / p.kp;
        assert!((e - expected).abs() < 1e-9 * expected, "{e} vs {expected}");
    }

    #[test]
    fn step_response_is_the_critically_damped_pair() {
        // x(t) = 1 − (1 + 2K_p t)e^{−2K_p t} for a held unit step from rest.
        let mut p = params(20.0, 0.0, 0.0, 0.0);
        p.loop_period_s = 1e-6;
        let mut a = ServoAxis::new(p, 0.0);
        let h = 1e-6;
        let c = AxisCommand {
            position: 1.0,
            ..AxisCommand::default()
        };
        let mut worst: f64 = 0.0;
        for k in 1..=40_000 {
            a.step(&c, h);
            let t = k as f64 * h;
            let w = 2.0 * p.kp * t;
            worst = worst.max((a.position() - (1.0 - (1.0 + w) * (-w).exp())).abs());
        }
        // Zero-order hold at 1 µs against K_v = 390/s: a delay of h/2 ≈ 2e-4 of the rise time.
        assert!(worst < 1e-3, "{worst}");
    }

    #[test]
    fn bandwidth_is_the_minus_3db_frequency() {
        for f in [10.0, 20.0, 50.0] {
            let p = params(f, 0.0, 0.0, 0.0);
            let start = Joints::new([0.0]);
            let mut d = ServoDrive::new(&[p], 1e-3, &start).unwrap();
            let w = 2.0 * PI * f;
            let amp = 1.0;
            let periods = 40.0;
            let n = (periods / f / 1e-3) as u64;
            let mut peak: f64 = 0.0;
            for k in 1..=n {
                let t = k as f64 * 1e-3;
                let s = SetPoint {
                    index: k,
                    line: 0,
                    position: Joints::new([amp * (w * t).sin()]),
                    velocity: Joints::new([amp * w * (w * t).cos()]),
                    acceleration: Joints::new([-amp * w * w * (w * t).sin()]),
                };
                d.apply(&s);
                if t > 0.5 * periods / f {
                    peak = peak.max(d.position()[0].abs());
                }
            }
            // Sampled at 1 ms, the peak is seen to within 1 − cos(πf·1ms).
            let gain = peak / amp;
            assert!(
                (gain - std::f64::consts::FRAC_1_SQRT_2).abs() < 0.01,
                "{f} Hz: gain {gain}"
            );
        }
    }

    #[test]
    fn full_feed_forward_tracks_a_smooth_path() {
        // A jerk-limited S-curve: without feed-forward the error is v/K_p-sized, with it ~0.
        let lim = tezgah_motion::profile::Limits::new(100.0, 1000.0, 20000.0).unwrap();
        let prof = tezgah_motion::profile::solve(40.0, 0.0, 0.0, &lim).unwrap();
        let run = |p: ServoParams| {
            let start = Joints::new([0.0]);
            let mut d = ServoDrive::new(&[p], 1e-3, &start).unwrap();
            let mut worst: f64 = 0.0;
            let n = (prof.duration() / 1e-3).ceil() as u64 + 200;
            for k in 1..=n {
                let st = prof.state_at(k as f64 * 1e-3);
                let s = SetPoint {
                    index: k,
                    line: 0,
                    position: Joints::new([st.s]),
                    velocity: Joints::new([st.v]),
                    acceleration: Joints::new([st.a]),
                };
                worst = worst.max(d.apply(&s).following_error[0].abs());
            }
            worst
        };
        let p_only = run(params(20.0, 0.0, 0.0, 50.0));
        let full = run(params(20.0, 1.0, 1.0, 50.0));
        let v_only = run(params(20.0, 1.0, 0.0, 0.0));
        assert!(p_only > 0.9 * 100.0 / params(20.0, 0.0, 0.0, 0.0).kp);
        // velocity feed-forward alone leaves a/(K_v K_p) under acceleration
        let p = params(20.0, 0.0, 0.0, 0.0);
        let accel_lag = 1000.0 / (p.kv * p.kp);
        assert!(
            v_only < 1.05 * accel_lag && v_only > 0.7 * accel_lag,
            "{v_only} vs {accel_lag}"
        );
        eprintln!("S-curve 40 mm, V 100: max |e| P-only {p_only:.4} mm, velocity FF {v_only:.3e} mm, full FF {full:.3e} mm");
        assert!(full < 1e-4 * p_only, "full {full} vs p-only {p_only}");
    }

    #[test]
    fn saturation_bounds_the_acceleration() {
        let mut p = params(20.0, 1.0, 1.0, 0.0);
        p.max_accel = 500.0;
        let start = Joints::new([0.0]);
        let mut d = ServoDrive::new(&[p], 1e-3, &start).unwrap();
        let mut v_prev = 0.0;
        for k in 1..200 {
            // a 10 mm step: far beyond what 500 mm/s² can follow
            let s = SetPoint::at_rest(k, 0, Joints::new([10.0]));
            d.apply(&s);
            let v = d.axes()[0].velocity();
            assert!((v - v_prev).abs() <= 500.0 * 1e-3 * (1.0 + 1e-12));
            v_prev = v;
        }
    }

    #[test]
    fn following_error_limit_faults_and_holds() {
        let mut p = params(20.0, 0.0, 0.0, 0.0);
        p.following_error_limit = 0.5;
        let start = Joints::new([0.0, 0.0]);
        let mut d = ServoDrive::new(&[p, p], 1e-3, &start).unwrap();
        let mut faulted = None;
        for k in 1..100u64 {
            let t = k as f64 * 1e-3;
            // joint 1 ramps at 100 mm/s: e → 100/K_p ≈ 1.02 mm > 0.5
            let s = SetPoint {
                index: k,
                line: 0,
                position: Joints::new([0.0, 100.0 * t]),
                velocity: Joints::new([0.0, 100.0]),
                acceleration: Joints::new([0.0, 0.0]),
            };
            let st = d.apply(&s);
            if st.fault.is_some() {
                faulted = Some((k, st));
                break;
            }
        }
        let (_, st) = faulted.expect("faults");
        assert_eq!(st.fault, Some(DriveFault::FollowingError { joint: 1 }));
        assert!(st.following_error[1].abs() > 0.5);
        let held = d.position();
        let again = d.apply(&SetPoint::at_rest(999, 0, Joints::new([5.0, 5.0])));
        assert_eq!(again.position, held);
        assert!(again.fault.is_some());
    }

    #[test]
    fn rejects_bad_parameters() {
        let ok = params(20.0, 1.0, 1.0, 0.0);
        let q = Joints::new([0.0]);
        assert_eq!(
            ServoDrive::new(&[ok], 0.0, &q).unwrap_err(),
            ServoError::Period(0.0)
        );
        for bad in [
            ServoParams { kp: f64::NAN, ..ok },
            ServoParams {
                friction_rate: -1.0,
                ..ok
            },
            ServoParams {
                max_accel: 0.0,
                ..ok
            },
            ServoParams {
                following_error_limit: 0.0,
                ..ok
            },
        ] {
            assert!(matches!(
                ServoDrive::new(&[ok, bad], 1e-3, &Joints::new([0.0, 0.0])),
                Err(ServoError::Invalid { joint: 1, .. })
            ));
        }
        assert!(matches!(
            ServoDrive::new(&[ok], 1e-3, &Joints::new([0.0, 0.0])),
            Err(ServoError::JointCount { .. })
        ));
    }

    #[test]
    fn from_machine_reads_the_servo_tables() {
        let m = Machine::builtin("mill3").unwrap();
        let d = ServoDrive::from_machine(&m, &m.home()).unwrap();
        assert_eq!(d.substeps(), 8);
        let x = d.axes()[0].params();
        assert!((x.bandwidth_hz() - 20.0).abs() < 1e-12);
        assert!((x.friction_rate - 400.0 / 120.0).abs() < 1e-12);
        assert!((x.following_error_limit - 1.0).abs() < 1e-15);
        assert!(ServoDrive::from_machine(&m, &Joints::zeros(2)).is_err());
    }
}

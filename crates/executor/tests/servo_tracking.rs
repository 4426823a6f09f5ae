//! The simulated servo drive under manual motion and under a circle, against closed forms:
//! a single-joint jog lags along its own line (following error, no contour error); a circle
//! through two identical loops shrinks by the loop's gain at ω = v/R (contour error) and each
//! joint's error is the sinusoid R·|1 − H(jω)| (RMSE = that / √2, Kelekçi, 2021, eq. 5.1).

use std::f64::consts::PI;

use nalgebra::Vector3;
use tezgah_executor::drive::{ContourError, Drive, JointTracking, ServoDrive, ServoParams};
use tezgah_executor::manual::jog::Direction;
use tezgah_executor::manual::Jog;
use tezgah_executor::SetPoint;
use tezgah_kinematics::{Joints, Machine};

fn tip(q: &Joints) -> Vector3<f64> {
    Vector3::new(q[0], q[1], q[2])
}

#[test]
fn a_jog_lags_along_its_line() {
    // mill3 with feed-forward off on x: at 50 mm/s the lag is v·(1 + β/K_v)/K_p.
    let text = Machine::builtin_text("mill3")
        .unwrap()
        .replace("velocity_feed_forward = 1.0", "velocity_feed_forward = 0.0")
        .replace(
            "acceleration_feed_forward = 1.0",
            "acceleration_feed_forward = 0.0",
        );
    let m = Machine::from_toml_str(&text).unwrap();
    let start = Joints::new([-150.0, 10.0, 5.0]);
    let mut drive = ServoDrive::from_machine(&m, &start).unwrap();
    let p = *drive.axes()[0].params();
    let mut jog = Jog::new(&m, 0, &start, Direction::Plus, 50.0, 0).unwrap();
    let mut track = JointTracking::new(3);
    let mut contour = ContourError::default();
    let mut cruise_error = 0.0;
    for k in 0..3000 {
        if k == 1500 {
            jog.stop();
        }
        let Some(sp) = jog.next() else { break };
        let st = drive.apply(&sp);
        assert!(st.fault.is_none());
        if k == 1499 {
            cruise_error = st.following_error[0];
        }
        track.record(&st);
        contour.push(tip(&sp.position), tip(&st.position));
    }
    let expected = 50.0 * (1.0 + p.friction_rate / p.kv) / p.kp;
    assert!(
        (cruise_error - expected).abs() < 1e-9 * expected,
        "{cruise_error} vs {expected}"
    );
    // the lag is the largest error (critically damped: no overshoot beyond it)
    assert!(track.max(0) <= expected * (1.0 + 1e-9) && track.max(0) > 0.99 * expected);
    assert_eq!(track.max(1), 0.0);
    let c = contour.finish();
    eprintln!(
        "jog 50 mm/s, FF off: cruise lag {cruise_error:.6} mm, RMSE x {:.6} mm, contour max {:.3e} mm",
        track.rmse(0),
        c.max
    );
    // a lag along the line is no contour error; only overshoot past the end point would be
    assert!(c.max < 1e-3 * expected, "{}", c.max);
}

#[test]
fn a_circle_shrinks_by_the_loop_gain() {
    let bw = 20.0;
    let kp = 2.0 * PI * bw / tezgah_kinematics::machine::SERVO_BANDWIDTH_PER_KP;
    let beta = 3.0;
    let p = ServoParams {
        kp,
        kv: 4.0 * kp,
        friction_rate: beta,
        max_accel: 1e6,
        kvff: 0.0,
        kaff: 0.0,
        loop_period_s: 125e-6,
        following_error_limit: f64::INFINITY,
    };
    let (r, v) = (10.0, 50.0);
    let w = v / r;
    let ts = 1e-3;
    let start = Joints::new([r, 0.0, 0.0]);
    let mut drive = ServoDrive::new(&[p, p, p], ts, &start).unwrap();
    let mut track = JointTracking::new(3);
    let mut contour = ContourError::new(50);
    let n = 8000;
    for k in 1..=n {
        let t = k as f64 * ts;
        let (s, c) = (w * t).sin_cos();
        let sp = SetPoint {
            index: k,
            line: 0,
            position: Joints::new([r * c, r * s, 0.0]),
            velocity: Joints::new([-r * w * s, r * w * c, 0.0]),
            acceleration: Joints::new([-r * w * w * c, -r * w * w * s, 0.0]),
        };
        let st = drive.apply(&sp);
        contour.push(tip(&sp.position), tip(&st.position));
        // after 3 s the start transient (time constant 1/(2K_p) ≈ 5 ms) is gone
        if k == 3000 {
            contour.restart_stats();
        }
        if k > 3000 {
            track.record(&st);
        }
    }
    // H(jω) = K_vK_p / (K_vK_p − ω² + jω(K_v + β))
    let (kv, kk) = (p.kv, p.kv * p.kp);
    let (re, im) = (kk - w * w, w * (kv + beta));
    let den = re * re + im * im;
    let (hr, hi) = (kk * re / den, -kk * im / den);
    let gain = (hr * hr + hi * hi).sqrt();
    let radial = r * (1.0 - gain);
    let err_amp = r * ((1.0 - hr).powi(2) + hi * hi).sqrt();
    let c = contour.finish();
    eprintln!(
        "circle R {r} mm at {v} mm/s, FF off, 20 Hz: contour {:.6} mm (closed form {radial:.6}), RMSE x {:.6} (closed form {:.6})",
        c.max,
        track.rmse(0),
        err_amp / 2f64.sqrt()
    );
    // the commanded polyline's chords sag R(1 − cos(ωTs/2)) inside the circle
    let sag = r * (1.0 - (0.5 * w * ts).cos());
    assert!(
        (c.max - radial).abs() < 0.01 * radial + sag,
        "{} vs {radial}",
        c.max
    );
    assert!((c.rmse - radial).abs() < 0.01 * radial + sag);
    let rmse = err_amp / 2f64.sqrt();
    assert!(
        (track.rmse(0) - rmse).abs() < 0.01 * rmse,
        "{}",
        track.rmse(0)
    );
    assert!((track.rmse(1) - rmse).abs() < 0.01 * rmse);
    assert!((track.max(0) - err_amp).abs() < 0.01 * err_amp);
}

#[test]
fn full_feed_forward_makes_the_jog_lag_vanish() {
    // mill3 as shipped: x with full velocity and torque feed-forward, friction compensated.
    let m = Machine::builtin("mill3").unwrap();
    let start = Joints::new([-150.0, 10.0, 5.0]);
    let mut drive = ServoDrive::from_machine(&m, &start).unwrap();
    let p = *drive.axes()[0].params();
    let mut jog = Jog::new(&m, 0, &start, Direction::Plus, 200.0, 0).unwrap();
    let mut track = JointTracking::new(3);
    for k in 0..3000 {
        if k == 1000 {
            jog.stop();
        }
        let Some(sp) = jog.next() else { break };
        track.record(&drive.apply(&sp));
    }
    let lag = 200.0 * (1.0 + p.friction_rate / p.kv) / p.kp;
    eprintln!(
        "jog 200 mm/s (A 2000, J 50000), full FF: max |e| {:.3e} mm, RMSE {:.3e} mm (lag without FF {lag:.4} mm)",
        track.max(0),
        track.rmse(0)
    );
    assert!(track.max(0) < 1e-4 * lag, "{}", track.max(0));
}

//! One `[[joint]]` of the machine file: its limits in file units, and the simulated servo
//! drive (`[joint.servo]`, read by the executor's `drive::servo`) and homing (`[joint.home]`,
//! read by the executor's homing) with their defaults filled in. The kinematic model sees the
//! joints only through [`Joint::limit`].

use std::f64::consts::PI;

use serde::Deserialize;

use super::check::{finite, invalid, positive, MachineError};
use crate::pose::{JointKind, JointLimit};

/// `[[joint]]` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawJoint {
    name: String,
    kind: String,
    min: Option<f64>,
    max: Option<f64>,
    #[serde(default)]
    endless: bool,
    max_velocity: f64,
    max_acceleration: f64,
    max_jerk: f64,
    servo: Option<RawServo>,
    home: Option<RawHome>,
}

/// `[joint.servo]`: the simulated servo drive of the joint (issue 8); every field optional.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawServo {
    bandwidth_hz: Option<f64>,
    inertia: Option<f64>,
    friction: Option<f64>,
    max_force: Option<f64>,
    velocity_feed_forward: Option<f64>,
    acceleration_feed_forward: Option<f64>,
    loop_period_s: Option<f64>,
    following_error_limit: Option<f64>,
}

/// `[joint.home]`: the joint's homing switch and sequence (issue 8); every field optional.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawHome {
    switch: Option<f64>,
    search_velocity: Option<f64>,
    latch_velocity: Option<f64>,
    position: Option<f64>,
    sequence: Option<u32>,
}

/// One `[[joint]]`, in machine-file units (mm or degrees).
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name (column header of the samples CSV).
    pub name: String,
    /// Linear or rotary.
    pub kind: JointKind,
    /// Lower limit, mm or deg (−∞ for an endless rotary).
    pub min: f64,
    /// Upper limit, mm or deg (+∞ for an endless rotary).
    pub max: f64,
    /// A rotary that turns forever (no position limits).
    pub endless: bool,
    /// mm/s or deg/s.
    pub max_velocity: f64,
    /// mm/s² or deg/s².
    pub max_acceleration: f64,
    /// mm/s³ or deg/s³.
    pub max_jerk: f64,
    /// `[joint.servo]` with defaults filled in.
    pub servo: ServoSettings,
    /// `[joint.home]` with defaults filled in.
    pub home: HomeSettings,
}

/// A joint's simulated servo drive (`[joint.servo]`), in file units (mm or degrees) and SI for
/// the plant. The executor's `drive::servo` turns it into its discrete-time model.
#[derive(Clone, Debug, PartialEq)]
pub struct ServoSettings {
    /// Closed-loop −3 dB bandwidth of the position loop without feed-forward, Hz.
    pub bandwidth_hz: f64,
    /// Moving mass (kg, linear) or inertia (kg·m², rotary) seen by the motor.
    pub inertia: f64,
    /// Viscous friction, N·s/m (linear) or N·m·s/rad (rotary), ≥ 0.
    pub friction: f64,
    /// Actuator saturation, N or N·m.
    pub max_force: f64,
    /// Velocity feed-forward gain, 0 (off) to 1 (full); up to 2 accepted.
    pub velocity_feed_forward: f64,
    /// Torque feed-forward gain on the rigid model (inertia·a + friction·v), 0 to 1; up to 2.
    pub acceleration_feed_forward: f64,
    /// The drive's own control period (it runs several per set-point period), s.
    pub loop_period_s: f64,
    /// Following error (mm or deg) beyond which the drive faults; `None` never faults.
    pub following_error_limit: Option<f64>,
}

/// Default servo bandwidth, Hz: a mid-range industrial position loop (Kv factor ≈ 5 m/min/mm).
pub const DEFAULT_SERVO_BANDWIDTH_HZ: f64 = 20.0;
/// Default moving mass of a linear joint, kg, and inertia of a rotary joint, kg·m².
pub const DEFAULT_INERTIA: (f64, f64) = (100.0, 0.5);
/// Default servo loop period, s (a drive's velocity loop, 8 kHz).
pub const DEFAULT_SERVO_LOOP_PERIOD_S: f64 = 125e-6;
/// Default saturation: this many times the force the joint's own limits need
/// (inertia·max_acceleration + friction·max_velocity).
pub const DEFAULT_FORCE_MARGIN: f64 = 3.0;

/// A joint's homing (`[joint.home]`), in file units (mm or degrees).
#[derive(Clone, Debug, PartialEq)]
pub struct HomeSettings {
    /// Machine position of the home switch's edge.
    pub switch: f64,
    /// Signed speed of the search toward the switch (the sign is the direction), per s.
    pub search_velocity: f64,
    /// Speed (> 0) of backing off the switch and of the slow approach that latches it.
    pub latch_velocity: f64,
    /// Where the joint goes once homed.
    pub position: f64,
    /// Homing order: lower first, equal together.
    pub sequence: u32,
}

impl Joint {
    /// Factor from file units to internal units: 1 for mm, π/180 for degrees.
    pub fn to_internal(&self) -> f64 {
        match self.kind {
            JointKind::Linear => 1.0,
            JointKind::Rotary => PI / 180.0,
        }
    }

    /// Position limits in internal units.
    pub fn limit(&self) -> JointLimit {
        let s = self.to_internal();
        JointLimit::new(&self.name, self.kind, self.min * s, self.max * s)
    }
}

/// Every `[[joint]]` validated, in file order, with the `sequence` each gave (the homing
/// order is filled in by [`home_order`] once the model has said which joint is Z). A servo
/// loop slower than the interpolation period (`period_s`) is refused, as are two joints of
/// one name (the samples CSV's columns).
pub(crate) fn build_joints(
    raw: Vec<RawJoint>,
    period_s: f64,
) -> Result<(Vec<Joint>, Vec<Option<u32>>), MachineError> {
    let sequences: Vec<Option<u32>> = raw
        .iter()
        .map(|j| j.home.as_ref().and_then(|h| h.sequence))
        .collect();
    let joints = raw
        .into_iter()
        .enumerate()
        .map(|(i, j)| build_joint(i, j))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, j) in joints.iter().enumerate() {
        if j.servo.loop_period_s > period_s {
            return Err(invalid(
                format!("joint[{i}].servo.loop_period_s"),
                format!("must be at most motion.period_s ({period_s})"),
            ));
        }
    }
    for (i, j) in joints.iter().enumerate() {
        if let Some(k) = joints[..i].iter().position(|o| o.name == j.name) {
            return Err(invalid(
                format!("joint[{i}].name"),
                format!("`{}` is already the name of joint[{k}]", j.name),
            ));
        }
    }
    Ok((joints, sequences))
}

fn build_joint(i: usize, j: RawJoint) -> Result<Joint, MachineError> {
    let f = |name: &str| format!("joint[{i}].{name}");
    if j.name.trim().is_empty() {
        return Err(invalid(f("name"), "must not be empty"));
    }
    let kind = match j.kind.as_str() {
        "linear" => JointKind::Linear,
        "rotary" => JointKind::Rotary,
        other => {
            return Err(invalid(
                f("kind"),
                format!("`{other}` is not `linear` or `rotary`"),
            ))
        }
    };
    let (min, max) = if j.endless {
        if kind != JointKind::Rotary {
            return Err(invalid(f("endless"), "only a rotary joint can be endless"));
        }
        if j.min.is_some() {
            return Err(invalid(f("min"), "an endless joint has no limits"));
        }
        if j.max.is_some() {
            return Err(invalid(f("max"), "an endless joint has no limits"));
        }
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        let min = finite(
            &f("min"),
            j.min.ok_or_else(|| invalid(f("min"), "missing"))?,
        )?;
        let max = finite(
            &f("max"),
            j.max.ok_or_else(|| invalid(f("max"), "missing"))?,
        )?;
        if max <= min {
            return Err(invalid(
                f("max"),
                format!("must be greater than min ({min})"),
            ));
        }
        (min, max)
    };
    let max_velocity = positive(&f("max_velocity"), j.max_velocity)?;
    let max_acceleration = positive(&f("max_acceleration"), j.max_acceleration)?;
    let max_jerk = positive(&f("max_jerk"), j.max_jerk)?;
    let servo = build_servo(&f, kind, max_velocity, max_acceleration, j.servo)?;
    let home = build_home(&f, min, max, max_velocity, j.home)?;
    Ok(Joint {
        name: j.name,
        kind,
        min,
        max,
        endless: j.endless,
        max_velocity,
        max_acceleration,
        max_jerk,
        servo,
        home,
    })
}

/// `[joint.servo]` validated, defaults filled in. SI conversions: a linear joint's speeds are
/// mm/s (×10⁻³ to m/s), a rotary joint's deg/s (×π/180 to rad/s).
fn build_servo(
    f: &dyn Fn(&str) -> String,
    kind: JointKind,
    max_velocity: f64,
    max_acceleration: f64,
    raw: Option<RawServo>,
) -> Result<ServoSettings, MachineError> {
    let r = raw.unwrap_or_default();
    let opt_pos = |name: &str, v: Option<f64>, default: f64| match v {
        Some(v) => positive(&f(&format!("servo.{name}")), v),
        None => Ok(default),
    };
    let gain = |name: &str, v: Option<f64>| -> Result<f64, MachineError> {
        match v {
            Some(v) if v.is_finite() && (0.0..=2.0).contains(&v) => Ok(v),
            Some(_) => Err(invalid(f(&format!("servo.{name}")), "must be in [0, 2]")),
            None => Ok(1.0),
        }
    };
    let si = match kind {
        JointKind::Linear => 1e-3,
        JointKind::Rotary => PI / 180.0,
    };
    let bandwidth_hz = opt_pos("bandwidth_hz", r.bandwidth_hz, DEFAULT_SERVO_BANDWIDTH_HZ)?;
    let inertia = opt_pos(
        "inertia",
        r.inertia,
        match kind {
            JointKind::Linear => DEFAULT_INERTIA.0,
            JointKind::Rotary => DEFAULT_INERTIA.1,
        },
    )?;
    let friction = match r.friction {
        Some(v) if v.is_finite() && v >= 0.0 => v,
        Some(_) => return Err(invalid(f("servo.friction"), "must be >= 0")),
        None => 0.0,
    };
    let needed = inertia * max_acceleration * si + friction * max_velocity * si;
    let max_force = opt_pos("max_force", r.max_force, DEFAULT_FORCE_MARGIN * needed)?;
    if max_force < needed {
        return Err(invalid(
            f("servo.max_force"),
            format!(
                "{max_force} cannot give the joint's own max_acceleration and max_velocity \
                 (inertia·a + friction·v = {needed})"
            ),
        ));
    }
    let loop_period_s = opt_pos(
        "loop_period_s",
        r.loop_period_s,
        DEFAULT_SERVO_LOOP_PERIOD_S,
    )?;
    // The velocity loop gain is 4·Kp with Kp = 2π·f/1.287 (see the executor's drive::servo);
    // its forward-Euler step is well damped only while Kv·h stays small.
    let kv = 4.0 * 2.0 * PI * bandwidth_hz / SERVO_BANDWIDTH_PER_KP;
    if kv * loop_period_s > MAX_SERVO_STEP {
        return Err(invalid(
            f("servo.bandwidth_hz"),
            format!(
                "{bandwidth_hz} Hz is too high for loop_period_s = {loop_period_s} \
                 (at most {:.1} Hz)",
                MAX_SERVO_STEP * SERVO_BANDWIDTH_PER_KP / (8.0 * PI * loop_period_s)
            ),
        ));
    }
    let following_error_limit = r
        .following_error_limit
        .map(|v| positive(&f("servo.following_error_limit"), v))
        .transpose()?;
    Ok(ServoSettings {
        bandwidth_hz,
        inertia,
        friction,
        max_force,
        velocity_feed_forward: gain("velocity_feed_forward", r.velocity_feed_forward)?,
        acceleration_feed_forward: gain("acceleration_feed_forward", r.acceleration_feed_forward)?,
        loop_period_s,
        following_error_limit,
    })
}

/// The −3 dB bandwidth of the servo's position loop in units of its gain Kp (rad/s per 1/s):
/// with the velocity loop at 4·Kp the closed loop is 4Kp²/(s + 2Kp)², whose magnitude is 1/√2
/// at ω = 2Kp·√(√2 − 1).
pub const SERVO_BANDWIDTH_PER_KP: f64 = 1.287_188_505_811_165_4;

/// Largest Kv·h (velocity-loop gain × servo loop period) accepted.
const MAX_SERVO_STEP: f64 = 0.5;

/// `[joint.home]` validated, defaults filled in: the switch at the top of the travel (an
/// endless rotary at 0), searched for at a tenth of the joint's speed, latched at a tenth of
/// that; home position 0 (or the nearest limit); sequence filled in later by [`home_order`].
fn build_home(
    f: &dyn Fn(&str) -> String,
    min: f64,
    max: f64,
    max_velocity: f64,
    raw: Option<RawHome>,
) -> Result<HomeSettings, MachineError> {
    let r = raw.unwrap_or_default();
    let inside = |name: &str, v: f64| -> Result<f64, MachineError> {
        let v = finite(&f(&format!("home.{name}")), v)?;
        if v < min || v > max {
            return Err(invalid(
                f(&format!("home.{name}")),
                format!("{v} is outside the joint's limits [{min}, {max}]"),
            ));
        }
        Ok(v)
    };
    let switch = inside(
        "switch",
        r.switch.unwrap_or(if max.is_finite() { max } else { 0.0 }),
    )?;
    let search_velocity = match r.search_velocity {
        Some(v) if v.is_finite() && v != 0.0 && v.abs() <= max_velocity => v,
        Some(_) => {
            return Err(invalid(
                f("home.search_velocity"),
                format!("must be non-zero and at most max_velocity ({max_velocity}) in size"),
            ))
        }
        None => 0.1 * max_velocity,
    };
    let latch_velocity = match r.latch_velocity {
        Some(v) if v.is_finite() && v > 0.0 && v <= search_velocity.abs() => v,
        Some(_) => {
            return Err(invalid(
                f("home.latch_velocity"),
                format!(
                    "must be > 0 and at most |search_velocity| ({})",
                    search_velocity.abs()
                ),
            ))
        }
        None => 0.1 * search_velocity.abs(),
    };
    let position = inside("position", r.position.unwrap_or(0.0_f64.clamp(min, max)))?;
    Ok(HomeSettings {
        switch,
        search_velocity,
        latch_velocity,
        position,
        // filled in by `home_order`, which sees every joint
        sequence: r.sequence.unwrap_or(0),
    })
}

/// Fills in the homing order. By default the joint that carries Z (`z`, from the model's
/// joint-to-axis map) goes first (as Kelekçi, 2021, §4.1: away from the work before anything
/// moves sideways), then the others one after another in file order; joints without a
/// `sequence` when others have one follow them one after another in file order.
pub(crate) fn home_order(
    joints: &mut [Joint],
    given: &[Option<u32>],
    z: Option<usize>,
) -> Result<(), MachineError> {
    // With no sequence given, Z is first; joints without one follow the given ones (or Z).
    let mut next = match given.iter().flatten().max() {
        Some(m) => m.checked_add(1).ok_or_else(|| {
            invalid(
                format!(
                    "joint[{}].home.sequence",
                    given.iter().position(|g| *g == Some(*m)).unwrap_or(0)
                ),
                "too large",
            )
        })?,
        None => u32::from(z.is_some()),
    };
    let none_given = given.iter().all(Option::is_none);
    for (i, (j, g)) in joints.iter_mut().zip(given).enumerate() {
        j.home.sequence = match g {
            Some(s) => *s,
            None if none_given && Some(i) == z => 0,
            None => {
                next = next.saturating_add(1);
                next - 1
            }
        };
    }
    Ok(())
}

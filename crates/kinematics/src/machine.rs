//! Machine definitions: the TOML machine file (docs/machine-files.md) read,
//! validated field by field, and turned into a kinematic [`Model`]. The CLI's `--machine`
//! and `tezgah machines` and the planner's joint limits all start here.
//!
//! Every error names its field (`joint[2].max_jerk: must be > 0`); unknown fields are
//! refused. New issues add fields to the raw structs below with `#[serde(default)]` and to
//! [`Motion`] / [`Joint`]; nothing else has to change.

use std::f64::consts::PI;
use std::path::Path;

use nalgebra::Vector3;
use serde::Deserialize;
use tezgah_geom::Axis;
use thiserror::Error;

use crate::cartesian::Cartesian;
use crate::error::KinematicsError;
use crate::kinematics::{Jacobian, Kinematics, Tolerances};
use crate::linear_delta::{DeltaGeometry, LinearDelta};
use crate::pose::{JointKind, JointLimit, Joints, Tool, ToolPose};
use crate::trunnion::{TiltAxis, Trunnion};
use crate::yzca::Yzca;

/// Why a machine definition was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MachineError {
    /// Not TOML, a wrong type, a missing or an unknown field (the message has line and column).
    #[error("machine file: {message}")]
    Toml {
        /// The TOML reader's message.
        message: String,
    },
    /// A field has a value the machine cannot use.
    #[error("{field}: {reason}")]
    Invalid {
        /// Dotted path of the field, e.g. `joint[2].max_jerk`.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The file could not be read.
    #[error("cannot read machine file {path}: {message}")]
    Io {
        /// The path given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// `Machine::builtin` was given a name that is not built in.
    #[error("no built-in machine `{name}` (built in: {known})")]
    UnknownBuiltin {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
}

fn invalid(field: impl Into<String>, reason: impl Into<String>) -> MachineError {
    MachineError::Invalid {
        field: field.into(),
        reason: reason.into(),
    }
}

/// The built-in machine files, embedded at compile time; the first is the default. They are the
/// workspace's `machines/` folder, the one copy users read and edit (a symlink into the crate was
/// tried and did not survive every checkout).
const BUILTIN: &[(&str, &str)] = &[
    ("mill3", include_str!("../../../machines/mill3.toml")),
    ("yzca", include_str!("../../../machines/yzca.toml")),
    ("table-ac", include_str!("../../../machines/table-ac.toml")),
    ("table-bc", include_str!("../../../machines/table-bc.toml")),
    (
        "linear-delta",
        include_str!("../../../machines/linear-delta.toml"),
    ),
];

/// Names accepted by [`Machine::builtin`], default first (for `tezgah machines`).
pub fn builtin_names() -> impl Iterator<Item = &'static str> {
    BUILTIN.iter().map(|(n, _)| *n)
}

// ---------------------------------------------------------------------------------------
// Raw file shape (serde). Everything optional that some type lacks is checked by hand so the
// error can say which field does not belong.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    name: String,
    kinematics: RawKinematics,
    motion: RawMotion,
    #[serde(default)]
    path: RawPath,
    #[serde(default)]
    joint: Vec<RawJoint>,
    #[serde(default)]
    probe: Option<crate::probe::RawProbe>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawKinematics {
    #[serde(rename = "type")]
    kind: String,
    tcp: Option<String>,
    axis_tolerance_deg: Option<f64>,
    pole_cone_deg: Option<f64>,
    centre_tolerance_mm: Option<f64>,
    // table-ac / table-bc
    pivot: Option<[f64; 3]>,
    c_offset: Option<[f64; 3]>,
    // yzca
    pivot_to_gauge: Option<f64>,
    // linear-delta
    radius: Option<f64>,
    rod_length: Option<f64>,
    tower_angles: Option<[f64; 3]>,
    carriage_offsets: Option<[f64; 3]>,
    min_rod_angle_deg: Option<f64>,
    max_joint_angle_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotion {
    period_s: f64,
    tolerance_mm: f64,
    home_required: Option<bool>,
}

/// `[path]`: the smoothing builder's options (issue 4); every field optional.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawPath {
    compress_corner_angle_deg: Option<f64>,
    short_segment_mm: Option<f64>,
    blend_max_angle_deg: Option<f64>,
    axis_tolerance_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJoint {
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
#[derive(Deserialize)]
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
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHome {
    switch: Option<f64>,
    search_velocity: Option<f64>,
    latch_velocity: Option<f64>,
    position: Option<f64>,
    sequence: Option<u32>,
}

// ---------------------------------------------------------------------------------------
// Validated machine.

/// The `[motion]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Interpolation period, s.
    pub period_s: f64,
    /// Path deviation allowed for smoothing, chord error and segmentation, mm.
    pub tolerance_mm: f64,
    /// `home_required` (default false): the executor refuses AUTO and MDI until the machine
    /// is homed.
    pub home_required: bool,
}

/// The optional `[path]` table: smoothing options for this machine. `None` leaves the path
/// builder's default (`tezgah_motion::path::smooth::SmoothOptions`); the kinematics crate only
/// validates the values (positive, angles at most 180°).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct PathSettings {
    /// Largest turn between consecutive moves inside a compressed run, degrees.
    pub compress_corner_angle_deg: Option<f64>,
    /// Longest G1 move counted as short for compression, mm.
    pub short_segment_mm: Option<f64>,
    /// Largest turn that is blended, degrees (sharper corners are passed at rest).
    pub blend_max_angle_deg: Option<f64>,
    /// Angular tolerance, degrees: under tool-centre-point control the largest angle between
    /// the tool axis and the programmed one (corner blends of the axis keep within it).
    pub axis_tolerance_deg: Option<f64>,
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

/// When tool-centre-point control is on (`[kinematics] tcp`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TcpSwitch {
    /// `"program"` (the default): as the program says, on from `G43.4 H<n>` until `G49` (or
    /// another tool-length code); off, program axes are joints.
    #[default]
    Program,
    /// `"always"`: program coordinates are always the tool tip and orientation; G43 H gives
    /// the tool length along the tool axis, G49 zeroes it.
    Always,
}

/// A validated machine: name, kinematic model, motion settings, joints.
#[derive(Clone, Debug)]
pub struct Machine {
    /// `name`.
    pub name: String,
    /// The model built from `[kinematics]` and the joints.
    pub kinematics: Model,
    /// `[motion]`.
    pub motion: Motion,
    /// `[path]` (optional).
    pub path: PathSettings,
    /// `[[joint]]`, in file order (the order of joint values everywhere).
    pub joints: Vec<Joint>,
    /// `[kinematics] tcp`: when tool-centre-point control is on.
    pub tcp: TcpSwitch,
    /// `[probe]` (optional): the simulated probe G38 moves touch.
    pub probe: Option<crate::probe::ProbeModel>,
}

impl Machine {
    /// Parses and validates a machine file's text.
    pub fn from_toml_str(text: &str) -> Result<Self, MachineError> {
        let raw: RawMachine = toml::from_str(text).map_err(|e| MachineError::Toml {
            message: e.to_string().trim_end().to_owned(),
        })?;
        build(raw)
    }

    /// Reads, parses and validates a machine file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, MachineError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| MachineError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Self::from_toml_str(&text)
    }

    /// A built-in machine by name (see [`builtin_names`]).
    pub fn builtin(name: &str) -> Result<Self, MachineError> {
        match BUILTIN.iter().find(|(n, _)| *n == name) {
            Some((_, text)) => Self::from_toml_str(text),
            None => Err(MachineError::UnknownBuiltin {
                name: name.to_owned(),
                known: builtin_names().collect::<Vec<_>>().join(", "),
            }),
        }
    }

    /// The default machine (`mill3`, a 3-axis Cartesian mill).
    pub fn default_machine() -> Self {
        // The embedded file is checked by the crate's tests; a failure here is a build bug.
        Self::builtin(BUILTIN[0].0).expect("embedded default machine is valid")
    }

    /// The text of a built-in machine file (to show or copy it).
    pub fn builtin_text(name: &str) -> Option<&'static str> {
        BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }

    /// Joint values from machine-file units (mm, degrees) to internal units (mm, rad).
    pub fn from_file_units(&self, values: &[f64]) -> Result<Joints, KinematicsError> {
        if values.len() != self.joints.len() {
            return Err(KinematicsError::BadInput {
                reason: format!(
                    "{} joints given, machine has {}",
                    values.len(),
                    self.joints.len()
                ),
            });
        }
        let mut q = Joints::from_slice(values)?;
        for (v, j) in q.as_mut_slice().iter_mut().zip(&self.joints) {
            *v *= j.to_internal();
        }
        Ok(q)
    }

    /// Joint values from internal units to machine-file units (what the samples CSV prints;
    /// rotary joints stay continuous, never wrapped).
    pub fn to_file_units(&self, q: &Joints) -> Vec<f64> {
        q.as_slice()
            .iter()
            .zip(&self.joints)
            .map(|(v, j)| v / j.to_internal())
            .collect()
    }

    /// The program axes (A, B, C) that carry the TCP angles of [`Kinematics::tcp_angles`], in
    /// that order: (A, C) on table-ac, (B, C) on table-bc, (C, A) on yzca, none on a delta,
    /// and on a Cartesian machine the extra joints by name (`a`, `b` or `c`).
    pub fn tcp_axes(&self) -> Result<Vec<Axis>, MachineError> {
        Ok(match &self.kinematics {
            Model::TableAc(_) => vec![Axis::A, Axis::C],
            Model::TableBc(_) => vec![Axis::B, Axis::C],
            Model::Yzca(_) => vec![Axis::C, Axis::A],
            Model::LinearDelta(_) => vec![],
            Model::Cartesian(_) => self.joints[3..]
                .iter()
                .enumerate()
                .map(|(i, j)| match j.name.to_ascii_lowercase().as_str() {
                    "a" => Ok(Axis::A),
                    "b" => Ok(Axis::B),
                    "c" => Ok(Axis::C),
                    _ => Err(invalid(
                        format!("joint[{}].name", i + 3),
                        "an extra joint of a cartesian machine must be named a, b or c to take a program axis",
                    )),
                })
                .collect::<Result<_, _>>()?,
        })
    }

    /// The program axes the machine has (LinuxCNC's axis mask): X Y Z, the tool tip, on every
    /// machine, and the rotary axes that carry [`Machine::tcp_axes`]. A program word of any
    /// other axis is refused (`Bad character 'a' used`), never silently dropped. A cartesian
    /// machine whose extra joints are not named a, b or c takes none of them.
    pub fn program_axes(&self) -> Vec<Axis> {
        let mut axes = vec![Axis::X, Axis::Y, Axis::Z];
        axes.extend(self.tcp_axes().unwrap_or_default());
        axes
    }

    /// Joints at zero (or the nearest limit when zero is outside): a start for continuity.
    pub fn home(&self) -> Joints {
        let mut q = Joints::zeros(self.joints.len());
        for (v, l) in q
            .as_mut_slice()
            .iter_mut()
            .zip(self.kinematics.joint_limits())
        {
            *v = 0.0_f64.clamp(l.min, l.max);
        }
        q
    }
}

fn positive(field: &str, v: f64) -> Result<f64, MachineError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(field, "must be > 0"))
    }
}

fn finite(field: &str, v: f64) -> Result<f64, MachineError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, "must be finite"))
    }
}

fn finite3(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, MachineError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

fn build(raw: RawMachine) -> Result<Machine, MachineError> {
    if raw.name.trim().is_empty() {
        return Err(invalid("name", "must not be empty"));
    }
    let motion = Motion {
        period_s: positive("motion.period_s", raw.motion.period_s)?,
        tolerance_mm: positive("motion.tolerance_mm", raw.motion.tolerance_mm)?,
        home_required: raw.motion.home_required.unwrap_or(false),
    };
    let angle = |field: &str, v: Option<f64>| -> Result<Option<f64>, MachineError> {
        match v {
            Some(a) if a > 180.0 => Err(invalid(field, format!("{a} is more than 180 degrees"))),
            Some(a) => positive(field, a).map(Some),
            None => Ok(None),
        }
    };
    let path = PathSettings {
        compress_corner_angle_deg: angle(
            "path.compress_corner_angle_deg",
            raw.path.compress_corner_angle_deg,
        )?,
        short_segment_mm: raw
            .path
            .short_segment_mm
            .map(|v| positive("path.short_segment_mm", v))
            .transpose()?,
        blend_max_angle_deg: angle("path.blend_max_angle_deg", raw.path.blend_max_angle_deg)?,
        axis_tolerance_deg: angle("path.axis_tolerance_deg", raw.path.axis_tolerance_deg)?,
    };
    let sequences: Vec<Option<u32>> = raw
        .joint
        .iter()
        .map(|j| j.home.as_ref().and_then(|h| h.sequence))
        .collect();
    let mut joints = raw
        .joint
        .into_iter()
        .enumerate()
        .map(|(i, j)| build_joint(i, j))
        .collect::<Result<Vec<_>, _>>()?;
    home_order(&mut joints, &sequences)?;
    for (i, j) in joints.iter().enumerate() {
        if j.servo.loop_period_s > motion.period_s {
            return Err(invalid(
                format!("joint[{i}].servo.loop_period_s"),
                format!("must be at most motion.period_s ({})", motion.period_s),
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
    let kinematics = build_model(&raw.kinematics, &joints)?;
    let tcp = match raw.kinematics.tcp.as_deref() {
        None | Some("program") => TcpSwitch::Program,
        Some("always") => TcpSwitch::Always,
        Some(other) => {
            return Err(invalid(
                "kinematics.tcp",
                format!("`{other}` is not `program` or `always`"),
            ))
        }
    };
    Ok(Machine {
        name: raw.name,
        kinematics,
        motion,
        path,
        joints,
        tcp,
        probe: raw.probe.map(|p| p.build("probe.")).transpose()?,
    })
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
    let r = raw.unwrap_or(RawServo {
        bandwidth_hz: None,
        inertia: None,
        friction: None,
        max_force: None,
        velocity_feed_forward: None,
        acceleration_feed_forward: None,
        loop_period_s: None,
        following_error_limit: None,
    });
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
    let r = raw.unwrap_or(RawHome {
        switch: None,
        search_velocity: None,
        latch_velocity: None,
        position: None,
        sequence: None,
    });
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

/// Fills in the homing order. By default Z goes first (as Kelekçi, 2021, §4.1: away from the work
/// before anything moves sideways), then the others one after another in file order; joints
/// without a `sequence` when others have one follow them one after another in file order.
fn home_order(joints: &mut [Joint], given: &[Option<u32>]) -> Result<(), MachineError> {
    let z = joints.iter().position(|j| j.name.eq_ignore_ascii_case("z"));
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

/// Which kinematics parameters each type accepts.
fn allowed(kind: &str) -> &'static [&'static str] {
    match kind {
        "cartesian" => &["axis_tolerance_deg"],
        "yzca" => &[
            "axis_tolerance_deg",
            "pole_cone_deg",
            "centre_tolerance_mm",
            "pivot_to_gauge",
        ],
        "table-ac" | "table-bc" => &["axis_tolerance_deg", "pole_cone_deg", "pivot", "c_offset"],
        "linear-delta" => &[
            "axis_tolerance_deg",
            "radius",
            "rod_length",
            "tower_angles",
            "carriage_offsets",
            "min_rod_angle_deg",
            "max_joint_angle_deg",
        ],
        _ => &[],
    }
}

fn check_joint_kinds(
    kind: &str,
    joints: &[Joint],
    expected: &[JointKind],
) -> Result<(), MachineError> {
    if joints.len() != expected.len() {
        return Err(invalid(
            "joint",
            format!(
                "{kind} needs {} joints, the file has {}",
                expected.len(),
                joints.len()
            ),
        ));
    }
    for (i, (j, e)) in joints.iter().zip(expected).enumerate() {
        if j.kind != *e {
            return Err(invalid(
                format!("joint[{i}].kind"),
                format!(
                    "{kind} needs a {} joint here",
                    if *e == JointKind::Linear {
                        "linear"
                    } else {
                        "rotary"
                    }
                ),
            ));
        }
    }
    Ok(())
}

fn build_model(k: &RawKinematics, joints: &[Joint]) -> Result<Model, MachineError> {
    use JointKind::{Linear as L, Rotary as R};
    let kind = k.kind.as_str();
    let present: [(&str, bool); 12] = [
        ("axis_tolerance_deg", k.axis_tolerance_deg.is_some()),
        ("pole_cone_deg", k.pole_cone_deg.is_some()),
        ("centre_tolerance_mm", k.centre_tolerance_mm.is_some()),
        ("pivot", k.pivot.is_some()),
        ("c_offset", k.c_offset.is_some()),
        ("pivot_to_gauge", k.pivot_to_gauge.is_some()),
        ("radius", k.radius.is_some()),
        ("rod_length", k.rod_length.is_some()),
        ("tower_angles", k.tower_angles.is_some()),
        ("carriage_offsets", k.carriage_offsets.is_some()),
        ("min_rod_angle_deg", k.min_rod_angle_deg.is_some()),
        ("max_joint_angle_deg", k.max_joint_angle_deg.is_some()),
    ];
    let ok = allowed(kind);
    if ok.is_empty() {
        return Err(invalid(
            "kinematics.type",
            format!("`{kind}` is not one of cartesian, yzca, table-ac, table-bc, linear-delta"),
        ));
    }
    if let Some((name, _)) = present.iter().find(|(n, p)| *p && !ok.contains(n)) {
        return Err(invalid(
            format!("kinematics.{name}"),
            format!("not a parameter of {kind}"),
        ));
    }
    let d = Tolerances::default();
    let tol = Tolerances {
        axis_rad: match k.axis_tolerance_deg {
            Some(v) => positive("kinematics.axis_tolerance_deg", v)?.to_radians(),
            None => d.axis_rad,
        },
        pole_cone_rad: match k.pole_cone_deg {
            Some(v) => positive("kinematics.pole_cone_deg", v)?.to_radians(),
            None => d.pole_cone_rad,
        },
        centre_mm: match k.centre_tolerance_mm {
            Some(v) => positive("kinematics.centre_tolerance_mm", v)?,
            None => d.centre_mm,
        },
    };
    let limits: Vec<JointLimit> = joints.iter().map(Joint::limit).collect();
    let wrap = |e: KinematicsError| invalid("kinematics", e.to_string());
    let require = |name: &str, v: Option<f64>| -> Result<f64, MachineError> {
        v.ok_or_else(|| {
            invalid(
                format!("kinematics.{name}"),
                format!("missing (required by {kind})"),
            )
        })
    };
    Ok(match kind {
        "cartesian" => {
            if joints.len() < 3 || joints.len() > crate::pose::MAX_JOINTS {
                return Err(invalid(
                    "joint",
                    format!(
                        "cartesian needs 3 to {} joints, the file has {}",
                        crate::pose::MAX_JOINTS,
                        joints.len()
                    ),
                ));
            }
            check_joint_kinds(kind, &joints[..3], &[L, L, L])?;
            Model::Cartesian(Cartesian::new(limits, tol).map_err(wrap)?)
        }
        "yzca" => {
            check_joint_kinds(kind, joints, &[L, L, R, R])?;
            let l = finite(
                "kinematics.pivot_to_gauge",
                require("pivot_to_gauge", k.pivot_to_gauge)?,
            )?;
            Model::Yzca(Yzca::new(l, limits, tol).map_err(wrap)?)
        }
        "table-ac" | "table-bc" => {
            check_joint_kinds(kind, joints, &[L, L, L, R, R])?;
            let pivot = finite3(
                "kinematics.pivot",
                k.pivot.ok_or_else(|| {
                    invalid("kinematics.pivot", format!("missing (required by {kind})"))
                })?,
            )?;
            let c_offset = finite3("kinematics.c_offset", k.c_offset.unwrap_or([0.0; 3]))?;
            let (tilt, wrapf): (TiltAxis, fn(Trunnion) -> Model) = if kind == "table-ac" {
                (TiltAxis::X, Model::TableAc)
            } else {
                (TiltAxis::Y, Model::TableBc)
            };
            wrapf(Trunnion::new(tilt, pivot, c_offset, limits, tol).map_err(wrap)?)
        }
        _ => {
            check_joint_kinds(kind, joints, &[L, L, L])?;
            let radius = positive("kinematics.radius", require("radius", k.radius)?)?;
            let rod = positive(
                "kinematics.rod_length",
                require("rod_length", k.rod_length)?,
            )?;
            if rod <= radius {
                return Err(invalid(
                    "kinematics.rod_length",
                    format!("must be greater than radius ({radius}) or the centre is unreachable"),
                ));
            }
            let angles = finite3(
                "kinematics.tower_angles",
                k.tower_angles.unwrap_or([90.0, 210.0, 330.0]),
            )?;
            let offsets = finite3(
                "kinematics.carriage_offsets",
                k.carriage_offsets.unwrap_or([0.0; 3]),
            )?;
            let min_angle = finite(
                "kinematics.min_rod_angle_deg",
                k.min_rod_angle_deg.unwrap_or(0.0),
            )?;
            if !(0.0..90.0).contains(&min_angle) {
                return Err(invalid(
                    "kinematics.min_rod_angle_deg",
                    "must be in [0, 90)",
                ));
            }
            let max_joint = match k.max_joint_angle_deg {
                Some(v) if v.is_finite() && v > 0.0 && v < 180.0 => Some(v.to_radians()),
                Some(_) => {
                    return Err(invalid(
                        "kinematics.max_joint_angle_deg",
                        "must be in (0, 180)",
                    ))
                }
                None => None,
            };
            let geometry = DeltaGeometry {
                max_joint_angle: max_joint,
                radius,
                rod_length: rod,
                tower_angles: [
                    angles.x.to_radians(),
                    angles.y.to_radians(),
                    angles.z.to_radians(),
                ],
                carriage_offsets: [offsets.x, offsets.y, offsets.z],
                min_rod_angle: min_angle.to_radians(),
            };
            Model::LinearDelta(
                LinearDelta::new(geometry, limits, tol)
                    .map_err(|e| invalid("kinematics.tower_angles", e.to_string()))?,
            )
        }
    })
}

/// The kinematic models, one variant per `kinematics.type` (static dispatch for the 1 ms loop).
#[derive(Clone, Debug)]
pub enum Model {
    /// `cartesian`
    Cartesian(Cartesian),
    /// `yzca`
    Yzca(Yzca),
    /// `table-ac`
    TableAc(Trunnion),
    /// `table-bc`
    TableBc(Trunnion),
    /// `linear-delta`
    LinearDelta(LinearDelta),
}

impl Model {
    /// The `kinematics.type` string.
    pub fn type_name(&self) -> &'static str {
        match self {
            Model::Cartesian(_) => "cartesian",
            Model::Yzca(_) => "yzca",
            Model::TableAc(_) => "table-ac",
            Model::TableBc(_) => "table-bc",
            Model::LinearDelta(_) => "linear-delta",
        }
    }
}

macro_rules! dispatch {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            Model::Cartesian($m) => $e,
            Model::Yzca($m) => $e,
            Model::TableAc($m) => $e,
            Model::TableBc($m) => $e,
            Model::LinearDelta($m) => $e,
        }
    };
}

impl Kinematics for Model {
    fn joint_limits(&self) -> &[JointLimit] {
        dispatch!(self, m => m.joint_limits())
    }
    #[inline]
    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
        dispatch!(self, m => m.forward(q, tool))
    }
    #[inline]
    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        dispatch!(self, m => m.inverse(pose, tool, previous))
    }
    fn tcp_angles(&self, q: &Joints) -> Joints {
        dispatch!(self, m => m.tcp_angles(q))
    }
    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        dispatch!(self, m => m.tcp_inverse(tip, angles, tool, previous))
    }
    fn jacobian(&self, q: &Joints, tool: &Tool) -> Result<Jacobian, KinematicsError> {
        dispatch!(self, m => m.jacobian(q, tool))
    }
}

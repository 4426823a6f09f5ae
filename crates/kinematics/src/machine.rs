//! Machine definitions: the TOML machine file (docs/machine-files.md) read, validated field by
//! field, and turned into a kinematic [`Model`]. The CLI's `--machine` and `tezgah machines`
//! and the planner's joint limits all start here.
//!
//! This module reads the part every machine shares: `name`, `[motion]`, `[path]`,
//! `[[joint]]` (`machine/joint.rs`) and the `type` and `tcp` keys of `[kinematics]`. The rest
//! of `[kinematics]` belongs to the model that `type` names, which reads it itself (its section
//! struct and `FromSection`, `machine/section.rs`, in the model's own file) and declares which
//! program axis each joint carries ([`Kinematics::joint_axes`]). A new machine family is one
//! model file plus a line in the list of models at the end of this file.
//!
//! Every error names its field (`joint[2].max_jerk: must be > 0`); unknown fields are refused.

pub(crate) mod check;
mod joint;
mod section;

use std::path::Path;

use nalgebra::Vector3;
use serde::Deserialize;
use tezgah_geom::Axis;

pub use check::MachineError;
pub(crate) use check::{finite, finite3, invalid, positive, require};
pub use joint::{
    HomeSettings, Joint, ServoSettings, DEFAULT_FORCE_MARGIN, DEFAULT_INERTIA,
    DEFAULT_SERVO_BANDWIDTH_HZ, DEFAULT_SERVO_LOOP_PERIOD_S, SERVO_BANDWIDTH_PER_KP,
};
pub(crate) use section::{check_joint_kinds, limits, refused, tolerances, FromSection};

use crate::cartesian::Cartesian;
use crate::error::KinematicsError;
use crate::kinematics::{Jacobian, Kinematics};
use crate::linear_delta::LinearDelta;
use crate::pose::{JointLimit, Joints, Tool, ToolPose};
use crate::trunnion::Trunnion;
use crate::yzca::Yzca;
use joint::{build_joints, home_order, RawJoint};

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
// Raw file shape (serde): the shared part. `[kinematics]` keeps only what the machine reads;
// the model's own fields are checked (unknown ones refused) by the model's section.

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
    #[serde(default)]
    spindle: Option<crate::spindle::RawSpindle>,
    /// `[drive]`: the drive bus's own table (the `tezgah-ethercat` crate reads and checks it
    /// from the same text); the machine only lets it through.
    #[serde(default)]
    #[allow(dead_code)]
    drive: Option<serde::de::IgnoredAny>,
}

/// `[kinematics]` as the machine reads it: the model's `type` and the `tcp` switch.
#[derive(Deserialize)]
struct RawKinematics {
    #[serde(rename = "type")]
    kind: String,
    tcp: Option<String>,
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
    /// `[spindle]` (optional, defaults otherwise): how the spindle's speed responds, for G33.
    pub spindle: crate::spindle::SpindleModel,
}

impl Machine {
    /// Parses and validates a machine file's text.
    pub fn from_toml_str(text: &str) -> Result<Self, MachineError> {
        let raw: RawMachine = toml::from_str(text).map_err(MachineError::toml)?;
        build(raw, text)
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
    /// that order: the axes the model maps its [`Kinematics::tcp_joints`] to ((A, C) on
    /// table-ac, (B, C) on table-bc, (C, A) on yzca, none on a delta, a Cartesian machine's
    /// extra joints by their names). Refused when such a joint carries no program axis.
    pub fn tcp_axes(&self) -> Result<Vec<Axis>, MachineError> {
        let axes = self.kinematics.joint_axes();
        self.kinematics
            .tcp_joints()
            .into_iter()
            .map(|i| {
                axes.get(i).copied().flatten().ok_or_else(|| {
                    invalid(
                        format!("joint[{i}].name"),
                        "names no program axis (a, b or c), so tool-centre-point control cannot \
                         drive it",
                    )
                })
            })
            .collect()
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

fn build(raw: RawMachine, text: &str) -> Result<Machine, MachineError> {
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
    let (mut joints, sequences) = build_joints(raw.joint, motion.period_s)?;
    let kinematics = Model::from_file(&raw.kinematics.kind, text, &joints)?;
    let z = kinematics
        .joint_axes()
        .iter()
        .position(|a| *a == Some(Axis::Z));
    home_order(&mut joints, &sequences, z)?;
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
        spindle: raw
            .spindle
            .map(|s| s.build())
            .transpose()?
            .unwrap_or_default(),
    })
}

/// Declares [`Model`], one variant per `kinematics.type`, and its dispatch: reading the model's
/// section and every [`Kinematics`] method (a `match`, static dispatch for the 1 ms loop).
macro_rules! models {
    ($($(#[$doc:meta])* $variant:ident($model:ty) = $kind:literal,)+) => {
        /// The kinematic models, one variant per `kinematics.type` (static dispatch for the 1 ms
        /// loop).
        #[derive(Clone, Debug)]
        pub enum Model {
            $($(#[$doc])* $variant($model),)+
        }

        impl Model {
            /// The `kinematics.type` string.
            pub fn type_name(&self) -> &'static str {
                match self {
                    $(Model::$variant(_) => $kind,)+
                }
            }

            /// The model `kind` names, from its section of the machine file `text`.
            fn from_file(kind: &str, text: &str, joints: &[Joint]) -> Result<Self, MachineError> {
                match kind {
                    $($kind => section::build::<$model>($kind, text, joints).map(Model::$variant),)+
                    other => Err(invalid(
                        "kinematics.type",
                        format!("`{other}` is not one of {}", [$($kind),+].join(", ")),
                    )),
                }
            }
        }

        impl Kinematics for Model {
            fn joint_limits(&self) -> &[JointLimit] {
                match self {
                    $(Model::$variant(m) => m.joint_limits(),)+
                }
            }
            #[inline]
            fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
                match self {
                    $(Model::$variant(m) => m.forward(q, tool),)+
                }
            }
            #[inline]
            fn inverse(
                &self,
                pose: &ToolPose,
                tool: &Tool,
                previous: &Joints,
            ) -> Result<Joints, KinematicsError> {
                match self {
                    $(Model::$variant(m) => m.inverse(pose, tool, previous),)+
                }
            }
            fn tcp_angles(&self, q: &Joints) -> Joints {
                match self {
                    $(Model::$variant(m) => m.tcp_angles(q),)+
                }
            }
            fn tcp_inverse(
                &self,
                tip: &Vector3<f64>,
                angles: &Joints,
                tool: &Tool,
                previous: &Joints,
            ) -> Result<Joints, KinematicsError> {
                match self {
                    $(Model::$variant(m) => m.tcp_inverse(tip, angles, tool, previous),)+
                }
            }
            fn jacobian(&self, q: &Joints, tool: &Tool) -> Result<Jacobian, KinematicsError> {
                match self {
                    $(Model::$variant(m) => m.jacobian(q, tool),)+
                }
            }
            fn joint_axes(&self) -> Vec<Option<Axis>> {
                match self {
                    $(Model::$variant(m) => m.joint_axes(),)+
                }
            }
            fn tcp_joints(&self) -> Vec<usize> {
                match self {
                    $(Model::$variant(m) => m.tcp_joints(),)+
                }
            }
        }
    };
}

// The machine families: a new one is its model file (with `Kinematics` and `FromSection`) and
// a line here.
models! {
    /// `cartesian`
    Cartesian(Cartesian) = "cartesian",
    /// `yzca`
    Yzca(Yzca) = "yzca",
    /// `table-ac`
    TableAc(Trunnion) = "table-ac",
    /// `table-bc`
    TableBc(Trunnion) = "table-bc",
    /// `linear-delta`
    LinearDelta(LinearDelta) = "linear-delta",
}

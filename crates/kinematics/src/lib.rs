//! tezgah-kinematics: machine models that map tool poses (tip + tool axis in the workpiece
//! frame) to joint positions and back, and the machine definitions they are built from.
//!
//! Sits between the planner's interpolator and the joint set-points (ARCHITECTURE.md,
//! "Data flow": `poses ──kinematics: inverse──► joint set-points`). Layout, one idea per module:
//!
//! * [`pose`], [`error`], [`angle`]: typed values, errors, angle unwrapping;
//! * [`kinematics`]: the [`Kinematics`] trait;
//! * models: [`cartesian`], [`yzca`], [`trunnion`] with [`table_ac`] / [`table_bc`],
//!   [`linear_delta`];
//! * [`machine`]: the TOML machine file's shared part, validation, built-in machines (each
//!   model reads its own `[kinematics]` section, in its own file);
//! * [`tcp`]: tool-centre-point control (program = tip + rotary angles);
//! * [`segment`]: splitting moves by deviation for machines that interpolate in joints;
//! * [`iso9283`]: pose accuracy AP and repeatability RP.
//!
//! Units: mm and **radians** inside; degrees only in machine files and printed joints
//! ([`machine::Machine::to_file_units`]).

#![warn(missing_docs)]

pub mod angle;
pub mod cartesian;
pub mod error;
pub mod iso9283;
pub mod kinematics;
pub mod linear_delta;
pub mod machine;
pub mod pose;
pub mod probe;
pub mod segment;
pub mod spindle;
pub mod table_ac;
pub mod table_bc;
pub mod tcp;
pub mod trunnion;
pub mod yzca;

pub use error::{AtLine, KinematicsError};
pub use kinematics::{Jacobian, Kinematics, Tolerances};
pub use machine::{
    builtin_names, HomeSettings, Machine, MachineError, Model, ServoSettings, TcpSwitch,
};
pub use pose::{JointKind, JointLimit, Joints, Tool, ToolPose};

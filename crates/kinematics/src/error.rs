//! Typed errors of the kinematics crate: unreachable poses, joint limits, bad machine files.
//! Every stage that maps poses to joints (pre-flight `check`, the interpolator's inverse)
//! returns these so the caller can attach the program line before any motion.

use thiserror::Error;

/// Why a pose or joint set cannot be used on a machine.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum KinematicsError {
    /// The tool tip cannot be reached at all (e.g. a delta rod would have to be longer).
    #[error("pose unreachable: {reason}")]
    Unreachable {
        /// Human-readable cause, with the numbers that decided it.
        reason: String,
    },
    /// The requested tool axis cannot be produced by this machine's rotary axes.
    #[error("tool axis unreachable: {reason}")]
    AxisUnreachable {
        /// Human-readable cause, with the angle error.
        reason: String,
    },
    /// Every solution puts a joint outside its limits; the nearest violation is reported.
    #[error("joint {joint} (`{name}`) at {value} {unit} is outside its limits [{min}, {max}]")]
    JointLimit {
        /// Index of the joint in machine-file order.
        joint: usize,
        /// Joint name from the machine file.
        name: String,
        /// Offending value in machine-file units (mm or degrees).
        value: f64,
        /// Lower limit in machine-file units.
        min: f64,
        /// Upper limit in machine-file units.
        max: f64,
        /// `mm` or `deg`.
        unit: &'static str,
    },
    /// A joint set or pose of the wrong size, or a non-finite number, was passed in.
    #[error("bad input: {reason}")]
    BadInput {
        /// What was wrong.
        reason: String,
    },
    /// The Jacobian is singular here, so joint rates are unbounded.
    #[error("singular configuration: {reason}")]
    Singular {
        /// Which configuration.
        reason: String,
    },
}

/// A kinematic error attached to the program line that caused it, for pre-flight `check`:
/// every unreachable pose or joint-limit violation is reported with its line before motion.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("line {line}: {error}")]
pub struct AtLine {
    /// 1-based source line of the block.
    pub line: usize,
    /// What went wrong there.
    #[source]
    pub error: KinematicsError,
}

impl KinematicsError {
    /// This error at a program line.
    pub fn at_line(self, line: usize) -> AtLine {
        AtLine { line, error: self }
    }
}

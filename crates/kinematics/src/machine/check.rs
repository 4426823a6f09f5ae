//! Why a machine file is refused ([`MachineError`]) and the field checks every part of the
//! file shares (positive, finite, present). Each error names its field as a dotted path
//! (`joint[2].max_jerk`, `kinematics.pivot`) so the message points into the file.

use nalgebra::Vector3;
use thiserror::Error;

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

impl MachineError {
    /// The TOML reader's error (line, column and the offending key are in its message).
    pub(crate) fn toml(e: toml::de::Error) -> Self {
        MachineError::Toml {
            message: e.to_string().trim_end().to_owned(),
        }
    }
}

pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> MachineError {
    MachineError::Invalid {
        field: field.into(),
        reason: reason.into(),
    }
}

pub(crate) fn positive(field: &str, v: f64) -> Result<f64, MachineError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(invalid(field, "must be > 0"))
    }
}

pub(crate) fn finite(field: &str, v: f64) -> Result<f64, MachineError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, "must be finite"))
    }
}

pub(crate) fn finite3(field: &str, v: [f64; 3]) -> Result<Vector3<f64>, MachineError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(Vector3::from(v))
}

/// A field the model `kind` needs. Optional in its serde struct so that the error can name
/// the field with its section and say which model wants it.
pub(crate) fn require<T>(field: &str, kind: &str, v: Option<T>) -> Result<T, MachineError> {
    v.ok_or_else(|| invalid(field, format!("missing (required by {kind})")))
}

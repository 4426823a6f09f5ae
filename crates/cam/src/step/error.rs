//! Why a STEP file could not be read: every error names the line, and past the syntax the
//! entity instance (`#id`) and its type, so that a user can find the culprit in the file.

use std::fmt;

use thiserror::Error;

/// Where in the file an entity instance is: its name `#id`, its type (for a complex instance,
/// the partial types joined by `+`) and the line its definition starts on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct At {
    pub id: u64,
    pub entity: String,
    pub line: usize,
}

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{} {} (line {})", self.id, self.entity, self.line)
    }
}

/// A STEP input error. [`super::read_file`] wraps the others in [`StepError::File`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    #[error("{path}: {source}")]
    File {
        path: String,
        source: Box<StepError>,
    },
    #[error("{path}: {message}")]
    Io { path: String, message: String },
    /// The exchange structure itself is malformed (ISO 10303-21 syntax).
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    #[error("line {line}: #{id} is defined again (first on line {first})")]
    Duplicate { id: u64, line: usize, first: usize },
    /// A reference to an instance the file does not define.
    #[error("{at}: refers to #{target}, which the file does not define")]
    Dangling { at: At, target: u64 },
    /// An entity type tezgah does not map, met where geometry is needed.
    #[error("{at}: unsupported entity, met as {role}")]
    Unsupported { at: At, role: String },
    /// An instance whose attributes are wrong for its type.
    #[error("{at}: {message}")]
    Invalid { at: At, message: String },
    /// An instance asked for by `#id` that the file does not define.
    #[error("the file does not define #{id}")]
    Missing { id: u64 },
    /// Nothing to machine: no shell-based surface model, solid or shell in the file.
    #[error("no SHELL_BASED_SURFACE_MODEL, MANIFOLD_SOLID_BREP, BREP_WITH_VOIDS, OPEN_SHELL or CLOSED_SHELL in the file")]
    NoShape,
    #[error("the file has several length units: {first} and {second}")]
    MixedUnits { first: String, second: String },
}

//! The executor's typed errors: refused commands and failures of the motion stack below.

use tezgah_gcode::sources::Located;

/// Why a command was refused or a job failed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ExecError {
    #[error("{command} is not possible while {state}")]
    Busy {
        command: &'static str,
        state: &'static str,
    },
    #[error("no program loaded")]
    NoProgram,
    #[error("{0}")]
    Override(#[from] crate::speed_override::OverrideError),
    #[error("line {0} is not a line of the program with motion after it")]
    NoSuchLine(u32),
    #[error("program: {0}")]
    Gcode(String),
    /// An error of the interpreter or the path builder at a place in the program or in a
    /// subroutine file it called.
    #[error("{at}: {message}")]
    At { at: Located, message: String },
    #[error("path: {0}")]
    Path(tezgah_motion::path::smooth::PathError),
    #[error("plan: {0}")]
    Plan(tezgah_motion::plan::PlanError),
    #[error("line {line}: kinematics: {message}")]
    Kinematics { line: u32, message: String },
    #[error("machine: {0}")]
    Machine(String),
    #[error("the executor's threads have stopped")]
    Stopped,
    #[error("{0}")]
    Manual(#[from] crate::manual::ManualError),
    #[error(
        "{command} needs the machine homed first (the machine file sets motion.home_required)"
    )]
    NotHomed { command: &'static str },
    #[error("no jog in progress")]
    NotJogging,
    /// The pre-flight found a pose out of reach or past a joint limit, at `at` (the program's
    /// line, or a subroutine file's).
    #[error("{at}: out of reach before anything moves: {message}")]
    Preflight { at: Located, message: String },
}

impl From<tezgah_motion::interpolate::InterpolateError> for ExecError {
    fn from(e: tezgah_motion::interpolate::InterpolateError) -> Self {
        match e {
            tezgah_motion::interpolate::InterpolateError::Kinematics { line, source } => {
                ExecError::Kinematics {
                    line,
                    message: source.to_string(),
                }
            }
        }
    }
}

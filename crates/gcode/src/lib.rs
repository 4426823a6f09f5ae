//! tezgah-gcode: RS274/NGC as LinuxCNC speaks it, turned into canonical calls and moves.
//!
//! The flow inside this crate is: [`lexer`] (one line, normalised, spans kept) → [`block`]
//! (words, evaluated with [`reader`]'s expressions and [`params`]) → [`interp`] (modal state,
//! offsets, units, arcs) → [`canon`] calls, which [`moves`] turns into `tezgah_geom::Move`s for
//! the planner; [`sources`] is the one pass that callers (`check`, `run`, the executor's load)
//! make of it, and where their errors are. Nothing here knows about files or terminals.

pub mod block;
pub mod canon;
pub mod codes;
pub mod error;
#[doc(hidden)]
pub mod fuzzing;
pub mod ini;
pub mod interp;
pub mod lexer;
pub mod moves;
pub mod params;
pub mod reader;
pub mod sources;
pub mod span;
pub mod tooltable;

pub use block::AxisMask;
pub use canon::{Canon, CanonSink, Origin, Units};
pub use error::{ErrorKind, GcodeError};
pub use ini::{IniError, IniFile};
pub use interp::{check, check_into, Config, Interpreter, MissingEnd, ProbeModel, ProbeOutcome};
pub use moves::{program_moves, MoveBuilder};
pub use span::Span;
pub use tooltable::{Tool, ToolTable, ToolTableError};

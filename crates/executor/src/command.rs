//! The executor's vocabulary toward a front end (the `serve` WebSocket, a pendant, tests):
//! commands in, status out, plain serde data.

use serde::{Deserialize, Serialize};

/// What an operator can ask.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "command", rename_all = "snake_case")]
pub enum Command {
    /// Load a G-code program for AUTO (checked whole first; nothing moves).
    Load { program: String },
    /// AUTO: start the loaded program, or go on after M0/M1, a single-block stop or a hold.
    CycleStart,
    /// Stop along the path within the jerk-limited distance; resume continues there.
    FeedHold,
    /// Go on after a feed hold (same as cycle start then).
    Resume,
    /// Stop along the path and forget the rest of the job; also clears a fault.
    Abort,
    /// Feed override, percent of the programmed feed (0–200); the limits still cap speed.
    FeedOverride { percent: f64 },
    /// Stop at the end of every block (applies to jobs started from now on).
    SingleBlock { on: bool },
    /// Honour M1.
    OptionalStop { on: bool },
    /// MDI: execute one block now (only while idle).
    Mdi { block: String },
    /// AUTO: run the loaded program from this source line (its modal state before it kept;
    /// the tool goes to the line's start point first).
    RestartFrom { line: u32 },
}

/// The operating mode of the job in hand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    Auto,
    Mdi,
}

/// Why the machine is paused in a program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PauseReason {
    /// M0 (or M60).
    ProgramStop,
    /// M1 with optional stop on.
    OptionalStop,
    /// End of a block in single-block mode.
    SingleBlock,
}

/// What the executor is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum RunState {
    /// No job.
    Idle,
    Running,
    /// Feed hold: slowing to a stop on the path.
    Holding,
    /// Feed hold complete; resume continues.
    Held,
    /// Stopped in a program; cycle start continues.
    Paused {
        reason: PauseReason,
    },
    /// Abort: slowing to a stop on the path, then idle.
    Aborting,
    /// The real-time side stopped on an underrun or drive fault; abort clears it.
    Fault,
}

/// What a front end shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Status {
    pub mode: Mode,
    pub state: RunState,
    /// Source line of the last set-point produced (0 outside a program); the planner runs a
    /// ring ahead of the machine.
    pub line: u32,
    /// Source line of the set-point the real-time thread applied last (what the machine is
    /// executing); 0 when no real-time side reports (the executor alone).
    pub executing_line: u32,
    /// Underruns the real-time side counted.
    pub underruns: u64,
    /// Set-point counter.
    pub index: u64,
    pub feed_override_percent: f64,
    pub single_block: bool,
    pub optional_stop: bool,
    pub program_loaded: bool,
    /// Commanded joints, machine-file order, internal units.
    pub joints: Vec<f64>,
    /// Tool tip, workpiece frame, mm.
    pub tip: [f64; 3],
    /// Current time scale r (1 = as planned, 0 = stopped).
    pub time_scale: f64,
    /// The last error, if any.
    pub error: Option<String>,
}

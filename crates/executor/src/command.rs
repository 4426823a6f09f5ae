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
    /// JOG (only while idle): move joint `joint` (0-based, machine-file order) continuously
    /// until `jog_stop`, at `speed` (file units per second; default 50 mm/s or 20 °/s, capped
    /// by the joint's limit) times the jog override; stops by itself at a soft limit.
    Jog {
        joint: usize,
        direction: Direction,
        #[serde(default)]
        speed: Option<f64>,
    },
    /// End a jog: the joint comes to rest in the jerk-limited minimum distance.
    JogStop,
    /// Jog speed override, percent (0–200); acts on a jog in progress and the next ones.
    JogOverride { percent: f64 },
    /// INC (only while idle): move joint `joint` by `step` (0.0001–0.1 mm, or degrees) rest
    /// to rest.
    Increment {
        joint: usize,
        direction: Direction,
        step: f64,
    },
    /// HOME (only while idle): the machine file's homing sequence, Z first; the homing
    /// offsets take effect at its end.
    Home,
}

pub use crate::manual::jog::Direction;

/// The operating mode of the job in hand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    Auto,
    Mdi,
    /// Continuous jog of one joint.
    Jog,
    /// One increment of one joint.
    Inc,
    /// The homing sequence.
    Home,
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
    /// The real-time thread's worst wake-up lateness so far, s (0 when no real-time side
    /// reports).
    pub late_worst_s: f64,
    /// Periods it woke more than half a period late.
    pub late_over_half: u64,
    /// Set-point counter.
    pub index: u64,
    pub feed_override_percent: f64,
    pub single_block: bool,
    pub optional_stop: bool,
    pub program_loaded: bool,
    /// Every joint homed (the homing offsets are in force).
    pub homed: bool,
    /// Jog speed override, percent.
    pub jog_override_percent: f64,
    /// Commanded joints, machine-file order, internal units.
    pub joints: Vec<f64>,
    /// Measured joints as the drive last reported them (the drives' actual positions),
    /// internal units; empty when no real-time side reports.
    #[serde(default)]
    pub measured: Vec<f64>,
    /// Tool tip, workpiece frame, mm.
    pub tip: [f64; 3],
    /// Current time scale r (1 = as planned, 0 = stopped).
    pub time_scale: f64,
    /// The last error, if any.
    pub error: Option<String>,
    /// The MDI interpreter's modal state and offsets, and the tool tip in its work frame.
    pub work: WorkState,
    /// What the loaded program's interpretation warned of: a text that ended without M2, M30
    /// or `%` (`program:line:col: …; run as if it ended with M2`).
    #[serde(default)]
    pub warning: Option<String>,
    /// The simulated probe (machine file `[probe]`): its input now and the last probe move.
    #[serde(default)]
    pub probe: ProbeStatus,
}

/// The probe as a front end shows it (all false / none on a machine without a probe).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ProbeStatus {
    /// The machine has a (simulated) probe.
    pub fitted: bool,
    /// The probe input at the tool where it stands: in contact.
    pub input: bool,
    /// A probe move (G38.2–G38.5) is in hand.
    pub probing: bool,
    /// The last probe move's answer.
    pub last: Option<ProbeReport>,
}

/// How one probe move ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProbeReport {
    /// `G38.2` … `G38.5`.
    pub code: String,
    /// Its source line.
    pub line: u32,
    /// Whether the input changed on the way.
    pub tripped: bool,
    /// Where it changed: the tool tip, workpiece frame, mm.
    pub trip_mm: Option<[f64; 3]>,
    /// Where the machine came to rest (the moves' coordinates: X Y Z mm, A B C degrees).
    pub stopped: [f64; 6],
}

/// The modal state and offsets the DRO shows (those of the MDI interpreter: zero-set by
/// `G10 L20` in MDI moves them), lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WorkState {
    /// The active coordinate system, 1 (G54) … 9 (G59.3).
    pub coordinate_system: usize,
    /// Its X Y Z offsets and XY rotation (degrees).
    pub g5x: [f64; 3],
    pub rotation_deg: f64,
    /// G92/G52 offsets in force.
    pub g92: [f64; 3],
    /// Tool length offsets in force.
    pub tool: [f64; 3],
    /// G20 (inch) in force, else G21.
    pub inches: bool,
    /// G91 in force, else G90.
    pub incremental: bool,
    /// 17, 18 or 19 (0 for a U V W plane).
    pub plane: u8,
    /// The motion mode, G code × 10 (10 for G1, 20 for G2, …), if any.
    pub motion: Option<u32>,
    /// The feed rate in force, program units per minute.
    pub feed_rate: f64,
    /// The tool tip in the active work frame: `R⁻¹(tip − g5x) − g92`, mm.
    pub position: [f64; 3],
}

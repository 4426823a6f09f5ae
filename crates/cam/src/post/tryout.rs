//! The written program tried on the machine as tezgah's own runner takes it: interpreted by
//! the G-code crate, made ready by the motion crate ([`tezgah_motion::prepare`]: path,
//! pre-flight of every joint limit) and planned and interpolated (the planner's rule that a
//! joint may not jump, a path through a singular pose). Last step of the post-processor: a
//! program `tezgah run` or `tezgah check --machine` would refuse is never handed out, and the
//! machine's cycle time comes with the one that passes.

use tezgah_gcode::sources::{interpret, Pass, Sources};
use tezgah_gcode::{AxisMask, Config, ToolTable};
use tezgah_kinematics::{Machine, TcpSwitch};
use tezgah_motion::interpolate::{InterpolateError, RunError};
use tezgah_motion::plan::PlanError;
use tezgah_motion::prepare::{cycle_time, prepare, PrepareError};

/// What the runner made of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tryout {
    /// The machine's time for the whole program (planned and interpolated), s.
    pub cycle_time_s: f64,
}

/// Why the runner refused the program: its line (of the program text) and the runner's
/// words.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {message}")]
pub struct Refused {
    /// 1-based line of the program, 0 where the runner names none.
    pub line: u32,
    pub message: String,
}

/// Runs `program` on `machine` with tool `tool_number` of length `tool_length_mm` in its
/// table, as `tezgah run --machine` does (its tolerance and period from the machine file).
pub fn tryout(
    program: &str,
    machine: &Machine,
    tool_number: u32,
    tool_length_mm: f64,
) -> Result<Tryout, Refused> {
    let refused = |line: u32, message: String| Refused { line, message };
    let table = ToolTable::parse(&format!(
        "T{tool_number} P{tool_number} Z{tool_length_mm}\n"
    ))
    .map_err(|e| refused(0, format!("the tool table: {e}")))?;
    let config = Config {
        tool_table: table,
        tool_centre_point_always: machine.tcp == TcpSwitch::Always,
        axes: AxisMask::of(machine.program_axes()),
        ..Config::default()
    };
    let done = interpret(
        Sources::new("program", program),
        config,
        Pass::Run,
        |_| None,
        &mut tezgah_gcode::canon::Discard,
    );
    if let Some(e) = done.errors.first() {
        return Err(refused(e.span.line, e.to_string()));
    }
    // One text without subroutine files: its keys are its lines.
    let keys = done.keys;
    let line_of = |key: u32| keys.source(key).line;
    let tolerance = machine.motion.tolerance_mm;
    let prepared = prepare(done.moves, machine, tolerance).map_err(|e| match &e {
        PrepareError::Path(p) => refused(p.line().map_or(0, line_of), p.detail()),
        PrepareError::Preflight(p) => refused(line_of(p.line), p.source.to_string()),
        other => refused(0, other.to_string()),
    })?;
    let cycle = cycle_time(prepared, machine.motion.period_s)
        .map_err(|e| refused(run_line(&e).map_or(0, line_of), e.to_string()))?;
    Ok(Tryout {
        cycle_time_s: cycle,
    })
}

/// The line a planner's or interpolator's error names, if any.
fn run_line(e: &RunError) -> Option<u32> {
    match e {
        RunError::Interpolate(InterpolateError::Kinematics { line, .. }) => Some(*line),
        RunError::Plan(p) => match p {
            PlanError::NoLimit { line, .. }
            | PlanError::Profile { line, .. }
            | PlanError::JointJump { line, .. }
            | PlanError::NoJoint { line, .. }
            | PlanError::BadDwell { line, .. } => Some(*line),
            PlanError::UnsupportedKinematics { .. } | PlanError::Option { .. } => None,
        },
    }
}

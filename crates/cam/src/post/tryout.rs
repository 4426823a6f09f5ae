//! The written program tried on the machine as tezgah's own runner takes it: interpreted by
//! the G-code crate, made ready by the motion crate ([`tezgah_motion::prepare`]: path,
//! pre-flight of every joint limit every 0.5 mm) and planned as `tezgah run` plans it (the
//! planner's rule that a joint may not jump, a path through a singular pose; the cycle time
//! is the planned profiles' — the interpolator samples exactly these, within 0.1 % on issue
//! 23's wavy patch, at 40 % less cost). Last step of the post-processor: a
//! program `tezgah run` or `tezgah check --machine` would refuse is never handed out, and the
//! machine's cycle time comes with the one that passes.

use tezgah_gcode::sources::{interpret, Pass, Sources};
use tezgah_gcode::{AxisMask, Config, ToolTable};
use tezgah_geom::Pose;
use tezgah_kinematics::{Machine, TcpSwitch};
use tezgah_motion::plan::PlanError;
use tezgah_motion::prepare::{planned_time, prepare, PrepareError};

/// What the runner made of the program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tryout {
    /// The machine's time for the whole program as tezgah plans it, s.
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
    let prepared = prepare(done.moves, machine, tolerance, Pose::ZERO).map_err(|e| match &e {
        PrepareError::Path(p) => refused(p.line().map_or(0, line_of), p.detail()),
        PrepareError::Preflight(p) => refused(line_of(p.line), p.source.to_string()),
        other => refused(0, other.to_string()),
    })?;
    let cycle = planned_time(prepared, machine.motion.period_s)
        .map_err(|e| refused(plan_line(&e).map_or(0, line_of), e.to_string()))?;
    Ok(Tryout {
        cycle_time_s: cycle,
    })
}

/// The line a planner's error names, if any.
fn plan_line(e: &PlanError) -> Option<u32> {
    match e {
        PlanError::NoLimit { line, .. }
        | PlanError::Profile { line, .. }
        | PlanError::JointJump { line, .. }
        | PlanError::NoJoint { line, .. }
        | PlanError::BadDwell { line, .. } => Some(*line),
        PlanError::UnsupportedKinematics { .. } | PlanError::Option { .. } => None,
    }
}

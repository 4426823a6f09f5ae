//! `tezgah run` and `tezgah machines`: wires gcode → motion (direct path, plan, interpolate,
//! verify) → the samples CSV, the report JSON, plots and the terminal summary.

use std::io::Write;
use std::path::PathBuf;

use miette::{miette, IntoDiagnostic, Result, WrapErr};
use tezgah_gcode::sources::{LineKeys, Sources};
use tezgah_gcode::{Config, ToolTable};
use tezgah_geom::{Pose, Vec3};
use tezgah_kinematics::{builtin_names, Machine, TcpSwitch};
use tezgah_motion::interpolate::Sample;
use tezgah_motion::path::smooth;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::prepare::{plan_options, prepare, PrepareError};
use tezgah_motion::tool_pose::SampleTool;
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::slack::{BINS, NEAR_LIMIT};
use tezgah_motion::verify::{Report, Verifier};

use crate::diagnostics::report_line;
use crate::plot::Trace;
use crate::replay::Replay;
use crate::tracking::{DriveKind, Tracker, Tracking};

/// The path a machine will follow, checked whole before anything moves.
pub struct BuiltPath {
    pub items: Vec<tezgah_motion::PathItem>,
    pub pm: PlanMachine,
    /// How far the blended tool axis strays from the programmed one.
    pub axis: AxisFigures,
}

/// The program's moves made ready for `machine` ([`tezgah_motion::prepare`]: smoothed, then
/// the pre-flight), every error a report naming the file, line and column. `moves` carry
/// `keys` numbers ([`tezgah_gcode::sources`]); the path returned carries plain line numbers.
pub fn build_path(
    sources: &Sources,
    keys: &LineKeys,
    moves: Vec<tezgah_geom::Move>,
    machine: &Machine,
    tolerance: f64,
    start: Pose,
) -> Result<BuiltPath> {
    let prepared = prepare(moves, machine, tolerance, start).map_err(|e| match e {
        PrepareError::Path(e) => path_error(sources, keys, &e),
        PrepareError::Preflight(e) => {
            report_line(sources, keys.source(e.line), &e.source.to_string())
        }
        other => miette!("{other}"),
    })?;
    let mut items = prepared.items;
    if !keys.is_plain() {
        for item in &mut items {
            let line = item.line_mut();
            *line = keys.plain(*line);
        }
    }
    Ok(BuiltPath {
        items,
        pm: prepared.pm,
        axis: AxisFigures {
            deviation_deg: prepared.max_axis_deviation_deg,
            tolerance_deg: prepared.angular_tolerance_deg,
        },
    })
}

/// A path builder's error at the file, line and column of its move (the message without its
/// own `line N:`, which would give the key).
fn path_error(sources: &Sources, keys: &LineKeys, e: &smooth::PathError) -> miette::Report {
    match e.line() {
        Some(line) => report_line(sources, keys.source(line), &e.detail()),
        None => miette!("{e}"),
    }
}

pub const DEMO: &str = include_str!("../../../examples/demo.ngc");
/// The demo's tool table.
pub const DEMO_TOOLS: &str = include_str!("../../../examples/tools.tbl");

/// Samples after which a progress bar is shown (about a minute of machining at 1 ms).
const PROGRESS_SAMPLES: u64 = 60_000;

/// Why the samples CSV could not be written: the file, or a sample's forward kinematics
/// (joints the interpolator produced are always finite and in limits, so not expected).
enum SinkError {
    Write(std::io::Error),
    Forward(u32, tezgah_kinematics::KinematicsError),
}

/// The command line of `tezgah run` (README.md describes it).
#[derive(clap::Args)]
pub struct RunArgs {
    /// The G-code program (default: the built-in demo).
    pub program: Option<PathBuf>,
    /// A built-in machine name (see `tezgah machines`) or a machine file.
    #[arg(long)]
    pub machine: Option<String>,
    /// Write every sample to this CSV file.
    #[arg(long)]
    pub samples: Option<PathBuf>,
    /// Write the verification report to this JSON file.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write plots (SVG and PNG) of feed and joint v/a/j into this directory.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Interpolation period, s (default: the machine file's `period_s`).
    #[arg(long)]
    pub period: Option<f64>,
    /// Path tolerance, mm (default: the machine file's `tolerance_mm`; G64 P overrides).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// The drive the samples go to: `ideal` (measured = commanded) or `servo` (the machine
    /// file's servo model; the report adds tracking RMSE, following and contour errors).
    #[arg(long, value_enum, default_value = "ideal")]
    pub drive: crate::tracking::DriveKind,
    /// A probe file (the fields of a machine file's `[probe]` section) for G38 moves to
    /// touch; default: the machine file's `[probe]`.
    #[arg(long)]
    pub probe: Option<PathBuf>,
    #[command(flatten)]
    pub inputs: crate::library::Inputs,
}

/// A machine by built-in name or file path.
pub fn load_machine(spec: Option<&str>) -> Result<Machine> {
    match spec {
        None => Ok(Machine::default_machine()),
        Some(s) if builtin_names().any(|n| n == s) => Machine::builtin(s).into_diagnostic(),
        Some(s) => Machine::from_file(s)
            .into_diagnostic()
            .wrap_err_with(|| format!("machine {s}")),
    }
}

/// The text of the machine file `spec` names (the built-in's own text for a built-in name):
/// for the tables another crate reads itself (`[drive]`).
pub fn machine_text(spec: Option<&str>) -> Result<String> {
    match spec {
        None => Ok(
            Machine::builtin_text(builtin_names().next().unwrap_or("mill3"))
                .unwrap_or_default()
                .to_owned(),
        ),
        Some(s) if builtin_names().any(|n| n == s) => {
            Ok(Machine::builtin_text(s).unwrap_or_default().to_owned())
        }
        Some(s) => std::fs::read_to_string(s)
            .into_diagnostic()
            .wrap_err_with(|| format!("machine {s}")),
    }
}

/// The interpreter's settings for a program run on `machine`: its units (mm) for the tool
/// table and stored offsets, its program axes, its tool-centre-point switch.
pub fn machine_config(
    machine: &Machine,
    tool_table: ToolTable,
    extra: &crate::library::ProgramInputs,
) -> Config {
    Config {
        tool_table,
        subroutines: extra.subroutines.clone(),
        ini: extra.ini.clone(),
        parameters: extra.parameters.clone(),
        tool_centre_point_always: machine.tcp == TcpSwitch::Always,
        axes: tezgah_gcode::AxisMask::of(machine.program_axes()),
        ..Config::default()
    }
}

/// `tezgah machines`.
pub fn machines() -> Result<()> {
    for name in builtin_names() {
        let m = Machine::builtin(name).into_diagnostic()?;
        let joints: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
        let default = if name == "mill3" { " (default)" } else { "" };
        println!(
            "{name:<14} {:<13} joints {}{default}",
            m.kinematics.type_name(),
            joints.join(" ")
        );
    }
    Ok(())
}

fn unit(machine: &Machine, i: usize) -> (&'static str, f64) {
    let j = &machine.joints[i];
    if j.to_internal() == 1.0 {
        ("mm", 1.0)
    } else {
        ("deg", 1.0 / j.to_internal())
    }
}

pub fn run(args: RunArgs) -> Result<std::process::ExitCode> {
    let machine = load_machine(args.machine.as_deref())?;
    let (name, text) = match &args.program {
        Some(p) => (p.display().to_string(), crate::library::read_text(p)?),
        None => ("built-in demo".to_owned(), DEMO.to_owned()),
    };
    let table = match &args.inputs.tool_table {
        None if args.program.is_none() => ToolTable::parse(DEMO_TOOLS).into_diagnostic()?,
        table => crate::library::load_tool_table(table.as_deref())?,
    };
    let extra = args.inputs.program_inputs(args.program.as_deref())?;
    let config = machine_config(&machine, table, &extra);
    let path_name = args.program.clone().unwrap_or_else(|| "demo.ngc".into());
    let period = args.period.unwrap_or(machine.motion.period_s);
    if !(period > 0.0 && period.is_finite()) {
        return Err(miette!("--period must be > 0, got {period}"));
    }
    let tolerance = args.tolerance.unwrap_or(machine.motion.tolerance_mm);
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(miette!("--tolerance must be > 0, got {tolerance}"));
    }
    let options = plan_options(period);
    let probe = match &args.probe {
        Some(p) => Some(
            tezgah_kinematics::probe::ProbeModel::from_toml_str(&crate::library::read_text(p)?)
                .map_err(|e| miette!("probe file {}: {e}", p.display()))?,
        ),
        None => machine.probe.clone(),
    };
    let probed = crate::run_probe::interpret_probing(
        || Sources::new(path_name.display().to_string(), text.clone()),
        config,
        |name| extra.locate(name),
        probe.as_ref(),
        &machine,
        tolerance,
        &options,
    )?;
    let probed = match probed {
        Ok(p) => p,
        Err(done) => {
            let e = &done.errors[0];
            eprintln!("{:?}", crate::diagnostics::report(&done.sources, e));
            return Ok(std::process::ExitCode::FAILURE);
        }
    };
    for w in &probed.done.warnings {
        eprintln!("warning: {w}");
    }
    // The program as the interpreter emitted it (probe moves ending where the machine
    // stopped, synchronised moves as they ran), which `verify` measures the samples against.
    let pm = PlanMachine::from_machine(&machine).map_err(|e| miette!("{e}"))?;
    let synced = crate::run_synced::run_synced_moves(&probed, &machine, tolerance, &options)?;
    let reference = crate::run_synced::reference_moves(&probed.moves, &synced);
    let make_verifier = || {
        let program = ProgramPath::new(Pose::ZERO, pm.initial, &reference);
        Verifier::new(&pm, period).against(&pm, program)
    };
    // The replay on a second thread, from here (its program path is built while this thread
    // builds the path to plan) to the report.
    std::thread::scope(|scope| {
        let replay = Replay::start(scope, &make_verifier);
        play_and_report(
            &args, &machine, &probed, &synced, &pm, replay, period, tolerance, &name,
        )
    })
}

/// The rest of [`run`]: the path built and played, every sample to `replay` and the sinks the
/// options ask for, then the report, plots and summary.
#[allow(clippy::too_many_arguments)]
fn play_and_report(
    args: &RunArgs,
    machine: &Machine,
    probed: &crate::run_probe::Probed,
    synced: &[crate::run_synced::SyncStep],
    pm: &PlanMachine,
    mut replay: Replay,
    period: f64,
    tolerance: f64,
    name: &str,
) -> Result<std::process::ExitCode> {
    let options = plan_options(period);
    let start = Pose::ZERO;
    let first = crate::run_probe::first_part(probed, synced, machine, tolerance)?;

    // The tool axis columns, for machines with rotary joints.
    let with_axis = machine
        .joints
        .iter()
        .any(|j| j.kind == tezgah_kinematics::JointKind::Rotary);
    let mut tool = SampleTool::new(pm);
    let mut csv = match &args.samples {
        Some(p) => {
            let f = std::fs::File::create(p)
                .into_diagnostic()
                .wrap_err_with(|| format!("cannot write {}", p.display()))?;
            let mut w = std::io::BufWriter::new(f);
            let names: Vec<&str> = machine.joints.iter().map(|j| j.name.as_str()).collect();
            let axis = if with_axis {
                ",tool_i,tool_j,tool_k"
            } else {
                ""
            };
            writeln!(w, "t,line,{},tip_x,tip_y,tip_z{axis}", names.join(",")).into_diagnostic()?;
            Some(w)
        }
        None => None,
    };
    let scales: Vec<f64> = (0..machine.joints.len())
        .map(|i| unit(machine, i).1)
        .collect();
    let mut tracker = match args.drive {
        DriveKind::Ideal => None,
        DriveKind::Servo => {
            let start_joints = pm
                .joints(
                    pm.initial,
                    &Vec3::from(start.xyz()),
                    &[start.0[3], start.0[4], start.0[5]],
                    &tezgah_kinematics::Joints::zeros(pm.joint_count()),
                )
                .map_err(|e| miette!("{e}"))?;
            Some(
                Tracker::new(machine, pm.model.clone(), period, start_joints)
                    .map_err(|e| miette!("--drive servo: {e}"))?,
            )
        }
    };
    let mut trace = args.plot.as_ref().map(|_| Trace::new(machine.joints.len()));
    let bar = indicatif::ProgressBar::hidden();
    let mut write_error: Option<SinkError> = None;
    let mut count: u64 = 0;
    let mut line_buf = String::with_capacity(256);
    let sink = |s: &Sample, seg: &[std::sync::Arc<tezgah_motion::Segment>]| {
        replay.push(s, seg);
        if let Some(t) = tracker.as_mut() {
            t.push(s);
        }
        if let Some(t) = trace.as_mut() {
            t.push(s, &scales);
        }
        if let Some(w) = csv.as_mut() {
            use std::fmt::Write as _;
            line_buf.clear();
            let _ = write!(line_buf, "{},{}", s.t, s.line);
            for (i, q) in s.joints.as_slice().iter().enumerate() {
                let _ = write!(line_buf, ",{:.12}", q * scales[i]);
            }
            // The tool as the joints hold it (the verifier reads the program point `s.tip`).
            match tool.pose(s, seg) {
                Ok(pose) => {
                    let p = pose.tip;
                    let _ = write!(line_buf, ",{:.12},{:.12},{:.12}", p.x, p.y, p.z);
                    if with_axis {
                        let k = pose.axis;
                        let _ = write!(line_buf, ",{:.12},{:.12},{:.12}", k.x, k.y, k.z);
                    }
                    if let Err(e) = writeln!(w, "{line_buf}") {
                        write_error.get_or_insert(SinkError::Write(e));
                    }
                }
                Err(e) => {
                    write_error.get_or_insert(SinkError::Forward(s.line, e));
                }
            }
        }
        count += 1;
        if count == PROGRESS_SAMPLES {
            bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            );
        }
        if count % 10_000 == 0 && count >= PROGRESS_SAMPLES {
            bar.set_message(format!("{:.1} s of machining planned", s.t));
            bar.tick();
        }
    };
    let mut sink = sink;
    let (duration, segments, axis) = crate::run_probe::play(
        probed, synced, first, machine, tolerance, &options, &mut sink,
    )?;
    let axis = axis.unwrap_or(AxisFigures {
        deviation_deg: 0.0,
        tolerance_deg: 0.0,
    });
    bar.finish_and_clear();
    match write_error {
        Some(SinkError::Write(e)) => {
            return Err(e).into_diagnostic().wrap_err("writing the samples")
        }
        Some(SinkError::Forward(line, e)) => {
            return Err(miette!("line {line}: the samples' tool pose: {e}"))
        }
        None => {}
    }
    if let Some(mut w) = csv {
        w.flush().into_diagnostic()?;
    }
    let report = replay.finish()?;
    let tracking = tracker.map(Tracker::finish);
    if let Some(p) = &args.report {
        let mut json = report_json(machine, &report, duration, name, period, tolerance, &axis);
        json["drive"] = serde_json::json!(match args.drive {
            DriveKind::Ideal => "ideal",
            DriveKind::Servo => "servo",
        });
        if let Some(t) = &tracking {
            json["tracking"] = tracking_json(machine, t);
        }
        if !probed.steps.is_empty() {
            json["probes"] = crate::run_probe::probes_json(probed);
        }
        if !synced.is_empty() {
            json["synced"] = crate::run_synced::synced_json(synced);
        }
        crate::library::write_json(p, &json)?;
    }
    if let (Some(dir), Some(t)) = (&args.plot, &trace) {
        std::fs::create_dir_all(dir).into_diagnostic()?;
        let joints: Vec<crate::plot::JointInfo> = machine
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| crate::plot::JointInfo {
                name: j.name.clone(),
                unit: unit(machine, i).0,
                limits: [j.max_velocity, j.max_acceleration, j.max_jerk],
            })
            .collect();
        let files =
            crate::plot::write_all(dir, t, &joints, period, name).map_err(|e| miette!("{e}"))?;
        println!("plots: {} files in {}", files, dir.display());
    }
    summary(
        machine, &report, duration, name, segments, period, tolerance, &axis,
    );
    if let Some(t) = &tracking {
        tracking_summary(machine, t);
    }
    crate::run_probe::probe_summary(probed);
    crate::run_synced::synced_summary(synced);
    let over = report.joints.iter().any(|j| j.worst_ratio() > 1.005)
        || report.deviation_ratio > 1.0
        || tracking.as_ref().is_some_and(|t| t.fault.is_some());
    Ok(if over {
        std::process::ExitCode::FAILURE
    } else {
        std::process::ExitCode::SUCCESS
    })
}

/// The report's `tracking` section: file units per joint (mm or deg), contour in mm.
fn tracking_json(machine: &Machine, t: &Tracking) -> serde_json::Value {
    let joints: Vec<serde_json::Value> = (0..t.rmse.len())
        .map(|i| {
            let (u, k) = unit(machine, i);
            serde_json::json!({
                "name": machine.joints[i].name,
                "unit": u,
                "rmse": t.rmse[i] * k,
                "max_following_error": t.max[i] * k,
            })
        })
        .collect();
    serde_json::json!({
        "joints": joints,
        "contour_rmse_mm": t.contour.rmse,
        "contour_max_mm": t.contour.max,
        "contour_samples": t.contour.samples,
        "fault": t.fault.map(|f| serde_json::json!({
            "t": f.t,
            "line": f.line,
            "fault": format!("{:?}", f.fault),
        })),
    })
}

fn tracking_summary(machine: &Machine, t: &Tracking) {
    println!("servo drive: joint   RMSE   max following error");
    for i in 0..t.rmse.len() {
        let (u, k) = unit(machine, i);
        println!(
            "{:<6} {:>12.3e} {u}  {:>12.3e} {u}",
            machine.joints[i].name,
            t.rmse[i] * k,
            t.max[i] * k
        );
    }
    println!(
        "contour error RMSE {:.3e} mm, max {:.3e} mm",
        t.contour.rmse, t.contour.max
    );
    if let Some(f) = t.fault {
        println!(
            "drive fault {:?} at t = {:.3} s (line {}): the figures after it are not tracking",
            f.fault, f.t, f.line
        );
    }
}

/// The machine file's `kinematics.tcp`, as written there.
fn tcp_name(machine: &Machine) -> &'static str {
    match machine.tcp {
        TcpSwitch::Program => "program",
        TcpSwitch::Always => "always",
    }
}

/// The tool axis's figures (5-axis under TCP): the largest angle between a corner blend's axis
/// and the programmed axis, and the angular tolerance in force, degrees.
#[derive(Debug, Clone, Copy)]
pub struct AxisFigures {
    pub deviation_deg: f64,
    pub tolerance_deg: f64,
}

fn report_json(
    machine: &Machine,
    r: &Report,
    duration: f64,
    program: &str,
    period: f64,
    tolerance: f64,
    axis: &AxisFigures,
) -> serde_json::Value {
    let joints: Vec<serde_json::Value> = r
        .joints
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (u, k) = unit(machine, i);
            serde_json::json!({
                "name": machine.joints[i].name,
                "unit": u,
                "peak_velocity": p.velocity * k,
                "max_velocity": p.max_velocity * k,
                "peak_velocity_line": p.velocity_line,
                "peak_acceleration": p.acceleration * k,
                "max_acceleration": p.max_acceleration * k,
                "peak_acceleration_line": p.acceleration_line,
                "peak_jerk": p.jerk * k,
                "max_jerk": p.max_jerk * k,
                "peak_jerk_line": p.jerk_line,
            })
        })
        .collect();
    serde_json::json!({
        "program": program,
        "machine": machine.name,
        "tcp": tcp_name(machine),
        "period_s": period,
        "tolerance_mm": tolerance,
        "cycle_time_s": r.cycle_time,
        "duration_s": duration,
        "samples": r.samples,
        "max_deviation_mm": r.max_deviation,
        "max_deviation_line": r.max_deviation_line,
        "max_deviation_over_tolerance": r.deviation_ratio,
        "max_deviation_over_tolerance_line": r.deviation_ratio_line,
        "max_deviation_smoothed_mm": r.max_deviation_smoothed,
        "max_deviation_smoothed_line": r.max_deviation_smoothed_line,
        "unmeasured_samples": r.unmeasured,
        "slack": slack_json(r),
        "axis_tolerance_deg": axis.tolerance_deg,
        "max_axis_deviation_deg": axis.deviation_deg,
        "joints": joints,
        "worst_lines": r.worst_lines.iter().map(|(l, x)| serde_json::json!({"line": l, "peak_over_limit": x})).collect::<Vec<_>>(),
    })
}

/// The report's `slack` section: seconds, and the histogram by tenths of the nominal speed.
fn slack_json(r: &Report) -> serde_json::Value {
    let s = &r.slack;
    let bins: Vec<serde_json::Value> = s
        .histogram
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let to = if i + 1 == BINS {
                serde_json::Value::Null
            } else {
                serde_json::json!((i + 1) as f64 / 10.0)
            };
            serde_json::json!({ "from": i as f64 / 10.0, "to": to, "time_s": t })
        })
        .collect();
    serde_json::json!({
        "near_limit": NEAR_LIMIT,
        "slack_s": s.slack,
        "slack_share": s.share(r.cycle_time),
        "moving_s": s.moving,
        "dwell_s": s.dwell,
        "feed_fraction": bins,
    })
}

#[allow(clippy::too_many_arguments)]
fn summary(
    machine: &Machine,
    r: &Report,
    duration: f64,
    program: &str,
    segments: usize,
    period: f64,
    tolerance: f64,
    axis: &AxisFigures,
) {
    println!(
        "{program} on {} ({}, TCP {}), period {} ms, tolerance {} mm",
        machine.name,
        machine.kinematics.type_name(),
        tcp_name(machine),
        period * 1e3,
        tolerance
    );
    println!(
        "cycle time {:.3} s ({} samples, duration {:.6} s), {} segments",
        r.cycle_time, r.samples, duration, segments
    );
    println!("joint   peak v (% of limit)   peak a (%)   peak j (%)");
    for (i, p) in r.joints.iter().enumerate() {
        println!(
            "{:<6} {:>8.1}%  {:>10.1}%  {:>10.1}%",
            machine.joints[i].name,
            100.0 * p.velocity / p.max_velocity,
            100.0 * p.acceleration / p.max_acceleration,
            100.0 * p.jerk / p.max_jerk
        );
    }
    println!(
        "max deviation from the program {:.2e} mm (line {}), from the smoothed path {:.2e} mm, \
         within tolerance: {}",
        r.max_deviation,
        r.max_deviation_line,
        r.max_deviation_smoothed,
        r.deviation_ratio <= 1.0
    );
    let s = &r.slack;
    let share = |t: f64| {
        if s.moving > 0.0 {
            100.0 * t / s.moving
        } else {
            0.0
        }
    };
    println!(
        "slack {:.1} % of the cycle (below the feed, no joint within {:.0} % of a limit); \
         time at the feed {:.1} %",
        100.0 * s.share(r.cycle_time),
        100.0 * NEAR_LIMIT,
        share(s.histogram[BINS - 1]),
    );
    if axis.deviation_deg > 0.0 {
        println!(
            "max tool-axis deviation {:.2e}° (corner blends), within angular tolerance: {}",
            axis.deviation_deg,
            axis.deviation_deg <= axis.tolerance_deg
        );
    }
}

//! Live probing in the executor (AUTO and MDI) on the simulated probe: the probe move stops at
//! the trip within the joints' limits, the trip answers the interpreter and the program goes on
//! from where the machine came to rest, with moves that depend on `#5061`–`#5070`.

mod support;

use support::*;
use tezgah_executor::command::{Command, ProbeReport, RunState};
use tezgah_executor::executor::{ExecOptions, Executor};
use tezgah_geom::{Pose, Vec3};
use tezgah_kinematics::probe::{ProbeModel, Solid};
use tezgah_kinematics::Machine;

/// mill3 with `model` as its probe.
fn probing_executor(model: ProbeModel) -> (Executor, Machine) {
    let mut m = Machine::default_machine();
    m.probe = Some(model);
    let exec = Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap();
    (exec, m)
}

/// The plane z = `h` touched by a ball of radius `r`.
fn plane(h: f64, r: f64) -> ProbeModel {
    ProbeModel {
        tool_radius: r,
        solids: vec![Solid::HalfSpace {
            point: Vec3::new(0.0, 0.0, h),
            normal: Vec3::z(),
        }],
    }
}

/// Runs `program` to its end (or its error), every set-point verified; the trace and the
/// last probe report.
fn run(
    exec: &mut Executor,
    program: &str,
) -> (Vec<tezgah_executor::executor::Produced>, ProbeReport) {
    let mut trace = Trace::new(exec);
    start(exec, program);
    drive(exec, &mut trace, 2_000_000, |_, _| {});
    assert_eq!(exec.state(), RunState::Idle);
    let (out, report) = trace.report();
    assert_within_limits(&report);
    assert_continuous(&out);
    let last = exec.status().probe.last.expect("a probe move ran");
    (out, last)
}

/// Down onto a plane at three feeds: the trip within one period's travel past the contact
/// (z = h + r), the stop's length the jerk-limited stop from cruise, v·√(v/J) (a = 0 there,
/// J the Z joint's), and the moves after it placed by `#5063`: up 2 mm from the rest point
/// (G91), then a feed to X20 at the probed height (G61: the corner between them not blended).
#[test]
fn a_plane_probed_in_auto_places_the_moves_after_it() {
    let (h, r) = (-3.0, 1.0);
    for feed in [120.0, 300.0, 600.0] {
        let (mut exec, machine) = probing_executor(plane(h, r));
        let period = machine.motion.period_s;
        let jerk = machine.joints[2].max_jerk;
        let program = format!(
            "G21 G90 G61\nG0 X10 Y10 Z5\nG38.2 Z-20 F{feed}\nG91 G0 Z2\nG90 G1 X20 Z#5063 F600\nM2\n"
        );
        let (out, last) = run(&mut exec, &program);
        assert_eq!(
            (last.code.as_str(), last.line, last.tripped),
            ("G38.2", 3, true)
        );
        let trip = last.trip_mm.unwrap();
        let v = feed / 60.0;
        let contact = h + r;
        assert!(
            trip[2] <= contact && trip[2] > contact - v * period - 1e-12,
            "F{feed}: trip at z {} for contact {contact}",
            trip[2]
        );
        let stop = trip[2] - last.stopped[2];
        let closed = v * (v / jerk).sqrt();
        assert!(
            (stop - closed).abs() < 1e-9,
            "F{feed}: stop {stop} vs {closed}"
        );
        // The rest point is where the G91 move starts: the highest point after the probe
        // is 2 mm above it.
        let probe_end = out.iter().position(|p| p.setpoint.line == 4).unwrap();
        let top = out[probe_end..]
            .iter()
            .map(|p| p.tip.z)
            .fold(f64::MIN, f64::max);
        assert!(
            (top - (last.stopped[2] + 2.0)).abs() < 1e-6,
            "top {top} rest {:?} trip {trip:?}",
            last.stopped
        );
        let end = out.last().unwrap().tip;
        assert!(
            (end - Vec3::new(20.0, 10.0, trip[2])).norm() < 1e-9,
            "{end:?}"
        );
        assert!(!exec.status().probe.probing);
    }
}

/// A box's walls: G38.2 toward the −X face, G38.4 back off it (trips as the ball leaves), then
/// G38.3 along Y that never touches (no error, `#5070` = 0, the move runs to its end), and
/// moves built from `#5061` and `#5070`.
#[test]
fn a_box_probed_toward_away_and_past() {
    let model = ProbeModel {
        tool_radius: 3.0,
        solids: vec![Solid::Box {
            min: Vec3::new(20.0, -10.0, -30.0),
            max: Vec3::new(40.0, 10.0, 0.0),
        }],
    };
    let (mut exec, machine) = probing_executor(model);
    let period = machine.motion.period_s;
    let program = "G21 G90\nG0 X0 Y0 Z-5\nG38.2 X30 F240\n#1=#5061\nG38.4 X0 F60\n#2=#5061\n\
                   G0 X0\nG38.3 Y-20 F600\nG0 X[#1 - 5] Z[#5070 + 1]\nM2\n";
    let (out, last) = run(&mut exec, program);
    assert_eq!((last.code.as_str(), last.tripped), ("G38.3", false));
    assert_eq!(last.stopped[1], -20.0);
    let end = out.last().unwrap().tip;
    // #1 is the G38.2 trip: within one period's travel past x = 17.
    let x1 = end.x + 5.0;
    assert!(x1 >= 17.0 && x1 < 17.0 + 4.0 * period + 1e-12, "#5061 {x1}");
    assert!(
        (end - Vec3::new(x1 - 5.0, -20.0, 1.0)).norm() < 1e-9,
        "{end:?}"
    );
    // The G38.4 left the contact inside the box's reach, moving −X at 1 mm/s.
    let released = out
        .iter()
        .filter(|p| p.setpoint.line == 5)
        .map(|p| p.tip.x)
        .fold(f64::MAX, f64::min);
    assert!(released < 17.0, "G38.4 rest x {released}");
}

/// G38.2 that never touches fails at its line as LinuxCNC's does, the machine at rest at its
/// end; one that starts in contact is refused before it moves.
#[test]
fn probe_errors_end_the_program_at_their_line() {
    let (mut exec, _) = probing_executor(plane(-50.0, 0.0));
    let (out, last) = run(&mut exec, "G21 G90\nG0 Z5\nG38.2 Z-10 F600\nG0 Z20\nM2\n");
    assert!(!last.tripped);
    assert_eq!(
        exec.status().error.as_deref(),
        Some("program:3:1: G38.2 move finished without making contact.")
    );
    assert!((out.last().unwrap().tip.z + 10.0).abs() < 1e-12);
    let (mut exec, _) = probing_executor(plane(0.0, 2.0));
    run(&mut exec, "G21 G90\nG0 Z1\nG38.3 Z-10 F600\nG0 Z20\nM2\n");
    assert_eq!(
        exec.status().error.as_deref(),
        Some("program:3:1: Probe is already tripped when starting G38.2 or G38.3 move")
    );
    assert!((exec.status().tip[2] - 1.0).abs() < 1e-12);
}

/// A feed hold while the probe move runs: the probe still trips during the hold's stop or
/// after resume, and the program completes at the probed height.
#[test]
fn a_hold_during_the_probe_move() {
    let (mut exec, _) = probing_executor(plane(-3.0, 0.0));
    let mut trace = Trace::new(&exec);
    start(
        &mut exec,
        "G21 G90\nG0 Z5\nG38.2 Z-20 F300\nG1 X5 Z[#5063 + 1] F600\nM2\n",
    );
    let mut held = false;
    for _ in 0..200_000 {
        if !held && exec.status().probe.probing && exec.status().tip[2] < 0.0 {
            exec.command(Command::FeedHold).unwrap();
            held = true;
        }
        match exec.step().unwrap() {
            Some(p) => trace.push(&exec, &p),
            None if exec.state() == RunState::Held => exec.command(Command::Resume).unwrap(),
            None => break,
        }
    }
    assert!(held);
    assert_eq!(exec.state(), RunState::Idle, "{:?}", exec.status().error);
    let (out, report) = trace.report();
    assert_within_limits(&report);
    assert_continuous(&out);
    let trip = exec.status().probe.last.unwrap().trip_mm.unwrap();
    assert!(trip[2] <= -3.0 && trip[2] > -3.0 - 0.005 - 1e-12);
    assert!((out.last().unwrap().tip - Vec3::new(5.0, 0.0, trip[2] + 1.0)).norm() < 1e-9);
}

/// MDI: the probe block stops at the trip, the next block sees `#5063`; a probe that misses is
/// LinuxCNC's error placed at the block; the status shows the input in contact at rest.
#[test]
fn mdi_probes_and_the_next_block_sees_the_result() {
    let (mut exec, machine) = probing_executor(plane(-3.0, 0.0));
    let period = machine.motion.period_s;
    let mut trace = Trace::new(&exec);
    assert!(exec.status().probe.fitted && !exec.status().probe.input);
    run_mdi(&mut exec, &mut trace, "G21 G90 G0 X5 Z5");
    run_mdi(&mut exec, &mut trace, "G38.2 Z-10 F300");
    let status = exec.status();
    let last = status.probe.last.unwrap();
    let trip = last.trip_mm.unwrap();
    assert!(last.tripped && trip[2] <= -3.0 && trip[2] > -3.0 - 5.0 * period - 1e-12);
    assert!(status.probe.input && status.tip[2] < trip[2]);
    run_mdi(&mut exec, &mut trace, "G0 Z[#5063 + 1]");
    assert!((exec.status().tip[2] - (trip[2] + 1.0)).abs() < 1e-9);
    assert!(!exec.status().probe.input);
    exec.command(Command::Mdi {
        block: "G38.2 X20 F600".into(),
    })
    .unwrap();
    drive(&mut exec, &mut trace, 1_000_000, |_, _| {});
    assert_eq!(
        exec.status().error.as_deref(),
        Some("MDI:1:1: G38.2 move finished without making contact.")
    );
    run_mdi(&mut exec, &mut trace, "G0 X0");
    let (out, report) = trace.report();
    assert_within_limits(&report);
    assert_continuous(&out);
}

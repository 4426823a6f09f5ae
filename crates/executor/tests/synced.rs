//! Spindle-synchronised moves against the simulated spindle on mill3: a thread holds the
//! programmed lead within the synchronisation error it reports, a rigid tap overshoots its depth
//! by what the spindle turns while it reverses (pitch · ω² / 2α for a spindle at its
//! acceleration limit) and comes back to its start, every joint within its limits throughout.

use std::sync::Arc;

use tezgah_executor::synced::{run_synced, Spindle, SyncRun};
use tezgah_geom::{Move, MoveKind, Pose, SyncedMove, Vec3};
use tezgah_kinematics::spindle::SpindleModel;
use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::interpolate::Sample;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::Verifier;
use tezgah_motion::PathItem;

const PERIOD: f64 = 0.001;

/// Runs the synchronised move from `start` to `end` on mill3 at `rpm`, spindle at angle 0.3.
fn run(
    start: Pose,
    end: Pose,
    pitch: f64,
    tap: Option<f64>,
    rpm: f64,
    model: SpindleModel,
) -> (SyncRun, Machine) {
    let machine = Machine::default_machine();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let opts = SmoothOptions::for_machine(&machine.path, &pm, 0.01, start);
    // The path of the line as a feed (its geometry and limits; the spindle sets the speed).
    let moves = [
        Move {
            line: 1,
            kind: MoveKind::FeedRate { value: 1.0e7 },
        },
        Move {
            line: 2,
            kind: MoveKind::PathMode(tezgah_geom::PathMode::ExactStop),
        },
        Move {
            line: 2,
            kind: MoveKind::Feed { end },
        },
        Move {
            line: 2,
            kind: MoveKind::Feed { end: start },
        },
    ];
    let items = smooth::build(moves, &opts).unwrap();
    let segments: Vec<_> = items
        .into_iter()
        .filter_map(|i| match i {
            PathItem::Segment(s) => Some(Arc::new(s)),
            _ => None,
        })
        .collect();
    let options = PlanOptions {
        period: PERIOD,
        ..PlanOptions::default()
    };
    let tip = Vec3::from(start.xyz());
    let joints = pm
        .joints(
            pm.initial,
            &tip,
            &[0.0; 3],
            &Joints::zeros(pm.joint_count()),
        )
        .unwrap();
    let mv = SyncedMove { end, pitch, tap };
    let run = run_synced(
        (&segments[0], &segments[1]),
        &mv,
        start,
        rpm,
        0.3,
        model,
        &pm,
        &options,
        joints,
    )
    .unwrap();
    (run, machine)
}

/// Every joint's speed, acceleration and jerk by finite differences at the period (the run's
/// verifier, `tezgah_motion::verify::Verifier`) within 0.5 % of its limits; the samples start
/// from rest at `start`.
fn assert_within_limits(run: &SyncRun, machine: &Machine, start: &[f64]) {
    let pm = PlanMachine::from_machine(machine).unwrap();
    let mut verifier = Verifier::new(&pm, PERIOD);
    if let Some((first, _)) = run.samples.first() {
        let rest = Sample {
            joints: Joints::from_slice(start).unwrap(),
            feed: 0.0,
            ..*first
        };
        verifier.push(&rest, &[]);
    }
    for (s, _) in &run.samples {
        verifier.push(s, &[]);
    }
    for (joint, peaks) in machine.joints.iter().zip(verifier.finish().joints) {
        assert!(peaks.worst_ratio() <= 1.005, "{} {peaks:?}", joint.name);
    }
}

fn pose(x: f64, y: f64, z: f64) -> Pose {
    Pose([x, y, z, 0.0, 0.0, 0.0])
}

/// A thread down Z (K 1.5 at 600 rev/min: 15 mm/s) and one along a diagonal: the move waits for
/// the index (the spindle starts at 0.3 rev: 0.07 s at 10 rev/s), locks, holds the lead within
/// the error it reports, and ends at rest exactly at its end.
#[test]
fn a_thread_holds_its_lead_within_the_reported_error() {
    for (start, end) in [
        (pose(0.0, 0.0, 0.0), pose(0.0, 0.0, -30.0)),
        (pose(0.0, 0.0, 0.0), pose(20.0, 10.0, -5.0)),
    ] {
        let (run, machine) = run(start, end, 1.5, None, 600.0, SpindleModel::default());
        let f = run.figures;
        assert!((f.index_wait - 0.07).abs() <= PERIOD + 1e-9, "{f:?}");
        let length = (Vec3::from(end.xyz()) - Vec3::from(start.xyz())).norm();
        // Over the locked stretch the lead is K to within twice the error over the turns.
        let turns = length / 1.5;
        assert!(
            (f.lead - 1.5).abs() * turns * 0.5 <= 2.0 * f.max_error + 1e-9,
            "{f:?}"
        );
        assert!(f.max_error < 1e-3, "{f:?}");
        let last = run.samples.last().unwrap().0;
        assert!((last.tip - Vec3::from(end.xyz())).norm() < 1e-9 && last.feed == 0.0);
        assert_within_limits(&run, &machine, &[0.0; 3]);
    }
}

/// Rigid tap 10 mm deep at K 1 and 300 rev/min: the spindle, at its 50 rev/s² limit, turns
/// ω²/2α = 0.25 rev while it reverses, so the tool goes 0.25 mm past the depth (to within the
/// sync error); it follows the spindle back, and comes to rest at the start. With I2 the way
/// back runs at twice the speed.
#[test]
fn a_rigid_tap_overshoots_by_the_spindles_reversal_and_returns() {
    let model = SpindleModel::default();
    let (start, end) = (pose(5.0, 5.0, 0.0), pose(5.0, 5.0, -10.0));
    let (tap, machine) = run(start, end, 1.0, Some(1.0), 300.0, model);
    let f = tap.figures;
    let omega = 300.0 / 60.0;
    let closed = 1.0 * omega * omega / (2.0 * model.max_acceleration);
    let overshoot = f.overshoot.unwrap();
    assert!(
        (overshoot - closed).abs() <= f.max_error + 5e-3,
        "{overshoot} vs {closed}: {f:?}"
    );
    let last = tap.samples.last().unwrap().0;
    assert!((last.tip - Vec3::from(start.xyz())).norm() < 1e-9 && last.feed == 0.0);
    assert!(
        (f.lead - 1.0).abs() * 10.0 <= 2.0 * f.max_error + 1e-9,
        "{f:?}"
    );
    let deepest = tap
        .samples
        .iter()
        .map(|s| s.0.tip.z)
        .fold(f64::MAX, f64::min);
    assert!((deepest - (-10.0 - overshoot)).abs() < 1e-9);
    assert_within_limits(&tap, &machine, &[5.0, 5.0, 0.0]);
    let (fast, _) = run(start, end, 1.0, Some(2.0), 300.0, model);
    assert!(
        fast.figures.duration < f.duration,
        "{:?} vs {f:?}",
        fast.figures
    );
}

/// A spindle the axis cannot follow (K 50 mm/rev reversing at 50 rev/s² asks 2 500 mm/s² of
/// a 2 000 mm/s² axis) leaves a real synchronisation error, reported — and the joints still
/// within their limits.
#[test]
fn a_spindle_too_quick_for_the_axis_shows_as_sync_error() {
    let (start, end) = (pose(0.0, 0.0, 0.0), pose(0.0, 0.0, -40.0));
    let (run, machine) = run(start, end, 50.0, Some(1.0), 60.0, SpindleModel::default());
    assert!(run.figures.max_error > 0.05, "{:?}", run.figures);
    assert_within_limits(&run, &machine, &[0.0; 3]);
}

/// The spindle model: from 10 rev/s told −10 it decelerates at its limit, passing zero after
/// ω/α, having turned ω²/2α.
#[test]
fn the_spindle_reverses_at_its_acceleration_limit() {
    let model = SpindleModel::default();
    let mut s = Spindle::steady(model, 10.0, 0.0);
    s.command = -10.0;
    let mut t = 0.0;
    while s.speed > 0.0 {
        s.step(PERIOD);
        t += PERIOD;
    }
    assert!(
        (t - 10.0 / model.max_acceleration).abs() <= PERIOD + 1e-9,
        "{t}"
    );
    assert!((s.angle - 100.0 / (2.0 * model.max_acceleration)).abs() < 0.01 + 1e-9);
}

/// The executor does not synchronise to a spindle: a program with G33 is refused at load,
/// at its line, before anything moves.
#[test]
fn the_executor_refuses_g33_at_its_line() {
    use tezgah_executor::command::Command;
    use tezgah_executor::executor::{ExecOptions, Executor};
    let m = Machine::default_machine();
    let mut exec = Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap();
    let e = exec
        .command(Command::Load {
            program: "G21 G90\nM3 S600\nG0 Z1\nG33.1 Z-5 K1\nM2\n".into(),
        })
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("program:4:1: path: G33/G33.1 follow the spindle"),
        "{e}"
    );
}

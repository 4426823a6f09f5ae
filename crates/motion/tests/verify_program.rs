//! `verify` against the program: G-code → moves → smoothing path → plan → samples, replayed
//! against the programmed moves. A smoothing that leaves the program shows and fails (the
//! smoothed-path figure alone cannot see it), an honest one passes, a skipped feature shows
//! at its vertex, a program shifted by a known distance reads that distance — under 5-axis
//! TCP too, where the tip is the forward kinematics of the joints.

use std::sync::Arc;

use tezgah_gcode::{program_moves, Config, ToolTable};
use tezgah_geom::{Move, MoveKind, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions, Smoother};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::{PathItem, Segment};

/// Square corners (90°) 20 mm apart at 50 mm/s under `G64 P0.5`.
const CORNERS: &str =
    "G21 G90 G17\nG64 P0.5\nG1 F3000 X20 Y0\nX20 Y20\nX0 Y20\nX0 Y40\nX20 Y40\nM2\n";

struct Out {
    report: Report,
    max_blend_deviation: f64,
}

/// Smooths `moves` for `machine`, stamps every segment's tolerance with `claimed` if given
/// (a smoothing that says it kept a tolerance it did not), plans, samples and verifies
/// against `program` (the moves themselves unless another program is given).
fn replay(machine: &Machine, moves: Vec<Move>, claimed: Option<f64>, program: &[Move]) -> Out {
    let pm = PlanMachine::from_machine(machine).unwrap();
    let opts =
        SmoothOptions::for_machine(&machine.path, &pm, machine.motion.tolerance_mm, Pose::ZERO);
    let mut smoother = Smoother::new(moves.into_iter(), opts).unwrap();
    let mut items: Vec<PathItem> = smoother.by_ref().collect::<Result<_, _>>().unwrap();
    if let Some(t) = claimed {
        for item in &mut items {
            if let PathItem::Segment(s) = item {
                s.tolerance = t;
            }
        }
    }
    let program = ProgramPath::new(Pose::ZERO, pm.initial, program);
    let mut verifier = Verifier::new(&pm, machine.motion.period_s).against(&pm, program);
    run(
        items,
        pm,
        PlanOptions {
            period: machine.motion.period_s,
            chord_share: smooth::CHORD_SHARE,
            ..PlanOptions::default()
        },
        (Vec3::zeros(), [0.0; 3]),
        |s, seg: &[Arc<Segment>]| verifier.push(s, seg),
    )
    .unwrap();
    Out {
        report: verifier.finish(),
        max_blend_deviation: smoother.stats().max_blend_deviation,
    }
}

fn moves(text: &str) -> Vec<Move> {
    program_moves(text, Config::default()).unwrap()
}

/// Every X Y Z of the moves shifted by `d`.
fn shifted(moves: &[Move], d: Vec3) -> Vec<Move> {
    let shift = |p: &mut Pose| {
        for (i, x) in d.iter().enumerate() {
            p.0[i] += x;
        }
    };
    moves
        .iter()
        .cloned()
        .map(|mut m| {
            match &mut m.kind {
                MoveKind::Rapid { end } | MoveKind::Feed { end } => shift(end),
                MoveKind::ToolControl { at, .. } => shift(at),
                MoveKind::Arc(a) => panic!("no arcs here: {a:?}"),
                _ => {}
            }
            m
        })
        .collect()
}

/// `G64 P0.5` blends corners by up to 0.4 × 0.5 mm; stamped 0.01 mm, the path claims a
/// tolerance it does not keep. Measured against the program the corner is the blend's
/// deviation from the sampled path (the smoother's closed form, `path::smooth::blend`; the
/// chords, on the blend's inner side, add at most the 0.2 × 0.01 mm chord error): 20 × the
/// tolerance, which fails; measured against the smoothed path, as before, the samples are
/// within the chord error and the failure cannot show.
#[test]
fn a_smoothing_that_leaves_the_program_fails() {
    let m = moves(CORNERS);
    let out = replay(&Machine::default_machine(), m.clone(), Some(0.01), &m);
    let r = &out.report;
    let expected = out.max_blend_deviation;
    assert!(expected > 0.15, "{expected}");
    assert!(
        r.max_deviation >= expected - 1e-9 && r.max_deviation <= expected + 0.002 + 1e-9,
        "{} against the blend's {expected}",
        r.max_deviation
    );
    assert!(r.deviation_ratio > 10.0, "{}", r.deviation_ratio);
    assert!(
        r.max_deviation_smoothed <= 0.01,
        "{}",
        r.max_deviation_smoothed
    );
    assert!(r.max_deviation > 50.0 * r.max_deviation_smoothed);
}

/// The same path under its own tolerance (0.5 mm) is within it, and the figure is the blend's
/// deviation at the corner, not the chord error alone (the chords add at most 0.2 × 0.5 mm).
#[test]
fn an_honest_smoothing_passes_with_its_true_deviation() {
    let m = moves(CORNERS);
    let out = replay(&Machine::default_machine(), m.clone(), None, &m);
    let r = &out.report;
    let expected = out.max_blend_deviation;
    assert!(r.deviation_ratio <= 1.0, "{}", r.deviation_ratio);
    assert!(
        r.max_deviation >= expected - 1e-9 && r.max_deviation <= expected + 0.1,
        "{} against the blend's {expected}",
        r.max_deviation
    );
}

/// A path that skips a feature of the program — a spike 0.2 mm high and 0.1 mm wide, run as
/// the straight line under it at 10 mm/s: every sample is within 0.05 mm of the program (the
/// spike's feet), but the spike's tip is 0.2 mm from the samples, exactly (the chords lie on
/// the line), and the report says so.
#[test]
fn a_skipped_feature_shows_at_its_vertex() {
    let text = "G21 G90 G17\nG61\nG1 F600 X10 Y0\nX10.05 Y0.2\nX10.1 Y0\nX20 Y0\nM2\n";
    let straight = "G21 G90 G17\nG61\nG1 F600 X10 Y0\nX10.1 Y0\nX20 Y0\nM2\n";
    let out = replay(
        &Machine::default_machine(),
        moves(straight),
        None,
        &moves(text),
    );
    let r = &out.report;
    assert!((r.max_deviation - 0.2).abs() < 1e-12, "{}", r.max_deviation);
    assert!(
        r.max_deviation_smoothed < 1e-9,
        "{}",
        r.max_deviation_smoothed
    );
}

/// A program shifted by 0.05 mm across straight moves (G61: no blends): every sample on a
/// line is 0.05 mm from it, exactly, and the report says so; the smoothed path is the
/// program itself (chords on its lines, the corner passed at rest).
#[test]
fn a_shifted_program_reads_the_shift() {
    let text = "G21 G90 G17\nG61\nG1 F3000 X30 Y0\nX30 Y10\nM2\n";
    let m = moves(text);
    let d = Vec3::new(0.0, 0.0, 0.05);
    let out = replay(
        &Machine::default_machine(),
        m.clone(),
        None,
        &shifted(&m, d),
    );
    let r = &out.report;
    assert!((r.max_deviation - 0.05).abs() < 1e-9, "{}", r.max_deviation);
    assert!(
        r.max_deviation_smoothed < 1e-6,
        "{}",
        r.max_deviation_smoothed
    );
}

/// Five axes under TCP on the table-ac trunnion (G43.4 switched on and off again, take-ups
/// at both switches): the forward kinematics of the joints put the tip on the program, within
/// the tolerance; a program under TCP shifted by 0.05 mm in Z reads 0.05 mm (± the
/// tolerance, which the smoothing may take) from it.
#[test]
fn five_axis_under_tcp_measures_the_tool_tip() {
    let machine = Machine::builtin("table-ac").unwrap();
    let text = "G21 G90 G17\nG0 X10 Y5 Z20\nG43.4 H1\nG1 F1200 X20 Y5 Z20 A10 C30\n\
                X30 Y10 Z18 A20 C60\nX30 Y25 Z15 A25 C90\nG49\nG0 Z40\nM2\n";
    let cfg = Config {
        tool_table: ToolTable::parse("T1 P1 Z35.0 D6\n").unwrap(),
        ..Config::default()
    };
    let m = program_moves(text, cfg.clone()).unwrap();
    let out = replay(&machine, m.clone(), None, &m);
    let r = &out.report;
    assert!(r.deviation_ratio <= 1.0, "{r:?}");
    assert!(r.unmeasured > 0, "the take-ups are not the program's");
    let d = Vec3::new(0.0, 0.0, 0.05);
    // Under TCP throughout (a take-up at the start, off the shifted program, is skipped).
    let tcp = "G21 G90 G17\nG0 X10 Y5 Z20\nG43.4 H1\nG1 F1200 X20 Y5 Z20 A10 C30\n\
               X30 Y10 Z18 A20 C60\nX30 Y25 Z15 A25 C90\nM2\n";
    let m = program_moves(tcp, cfg).unwrap();
    let out = replay(&machine, m.clone(), None, &shifted(&m, d));
    let r = &out.report;
    assert!(
        (r.max_deviation - 0.05).abs() <= machine.motion.tolerance_mm,
        "{}",
        r.max_deviation
    );
}

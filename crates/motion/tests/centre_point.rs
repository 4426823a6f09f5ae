//! Tool-centre-point control switched by the program (G43.4 H<n> / G49) on the table-ac
//! trunnion, end to end: G-code → moves → smoothing path → plan → samples. With TCP on the
//! joints put the tool tip on the program point with the tool length along the tool axis
//! (closed form of the table-ac convention, docs/machine-files.md); with TCP off the program axes
//! are the joints and a move is straight in joint space; every joint stays inside its limits.

use std::sync::Arc;

use tezgah_gcode::{program_moves, Config, ToolTable};
use tezgah_geom::{ToolControl, Vec3};
use tezgah_kinematics::{Joints, Kinematics, Machine, Tool};
use tezgah_motion::interpolate::{run, Sample};
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::Segment;

const TOOLS: &str = "T1 P1 Z35.0 D6\nT2 P2 Z28.5 D3\n";

struct Out {
    samples: Vec<(Sample, Option<ToolControl>, Option<Vec3>)>,
    report: Report,
}

fn run_program(program: &str) -> Out {
    let machine = Machine::builtin("table-ac").unwrap();
    let cfg = Config {
        tool_table: ToolTable::parse(TOOLS).unwrap(),
        ..Config::default()
    };
    let moves = program_moves(program, cfg).unwrap();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    // As `tezgah run`: the machine gives the tool axis of the program angles.
    let opts = SmoothOptions {
        orientation: Some(smooth::Orientation(Arc::new(pm.clone()))),
        ..SmoothOptions::default()
    };
    // Measured against the program (take-ups at the switches are not the program's).
    let program = ProgramPath::new(tezgah_geom::Pose::ZERO, pm.initial, &moves);
    let items = smooth::build(moves, &opts).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s).against(&pm, program);
    let mut samples = vec![];
    run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |s: &Sample, seg: &[Arc<Segment>]| {
            verifier.push(s, seg);
            let end = seg.last().map(|g| g.curve.point(g.curve.domain().1));
            samples.push((*s, seg.last().map(|g| g.control), end));
        },
    )
    .unwrap();
    Out {
        samples,
        report: verifier.finish(),
    }
}

fn assert_within_limits(r: &Report) {
    for (i, j) in r.joints.iter().enumerate() {
        assert!(j.worst_ratio() <= 1.005, "joint {i}: {j:?}");
    }
    assert!(r.max_deviation <= 0.01, "deviation {}", r.max_deviation);
}

/// Table-ac (docs/machine-files.md): part point p is at `pivot + Rx(A)·(c_offset + Rz(C)·p)`; the
/// spindle's gauge point is `length` above the tip along machine +Z, the tool axis.
fn closed_form(p: [f64; 3], a_deg: f64, c_deg: f64, length: f64) -> [f64; 5] {
    let (pivot, c_offset) = ([0.0, 0.0, -150.0], [0.0, 2.0, 50.0]);
    let (sa, ca) = a_deg.to_radians().sin_cos();
    let (sc, cc) = c_deg.to_radians().sin_cos();
    // c_offset + Rz(C)·p, then Rx(A).
    let u = [
        c_offset[0] + cc * p[0] - sc * p[1],
        c_offset[1] + sc * p[0] + cc * p[1],
        c_offset[2] + p[2],
    ];
    let m = [u[0], ca * u[1] - sa * u[2], sa * u[1] + ca * u[2]];
    [
        pivot[0] + m[0],
        pivot[1] + m[1],
        pivot[2] + m[2] + length,
        a_deg.to_radians(),
        c_deg.to_radians(),
    ]
}

fn assert_joints(q: &Joints, want: [f64; 5]) {
    for (i, (g, w)) in q.as_slice().iter().zip(want).enumerate() {
        assert!((g - w).abs() < 1e-9, "joint {i}: {g} vs {w} ({q:?})");
    }
}

const TCP_PROGRAM: &str = "G21 G90 G94 G64
G43.4 H{H}
G0 X10 Y5 Z20 A0 C0
G1 Z-3 F600
G1 A30 C40 F3600
G1 X20 F600
M2
";

#[test]
fn tcp_puts_the_tip_on_the_program_point_with_the_length_along_the_tool_axis() {
    for (h, length) in [(1, 35.0), (2, 28.5)] {
        let out = run_program(&TCP_PROGRAM.replace("{H}", &h.to_string()));
        assert_within_limits(&out.report);
        // The final row holds the end of line 6 exactly: the closed form.
        let (last, _, _) = out.samples.last().unwrap();
        assert_joints(
            &last.joints,
            closed_form([20.0, 5.0, -3.0], 30.0, 40.0, length),
        );
        // Every TCP sample: the forward kinematics with this tool puts the tip on the
        // sampled program point and the tool axis at the programmed A and C (seen from
        // the part, (sin A sin C, sin A cos C, cos A)).
        let machine = Machine::builtin("table-ac").unwrap();
        let mut checked = 0;
        for (s, control, _) in &out.samples {
            if *control
                != Some(ToolControl::CentrePoint {
                    tool_length: length,
                })
            {
                continue;
            }
            let pose = machine
                .kinematics
                .forward(&s.joints, &Tool::with_length(length))
                .unwrap();
            assert!(
                (pose.tip - s.tip).norm() < 1e-9,
                "line {}: {:?}",
                s.line,
                pose
            );
            let (a, c) = (s.rotary[0].to_radians(), s.rotary[2].to_radians());
            let axis = Vec3::new(a.sin() * c.sin(), a.sin() * c.cos(), a.cos());
            assert!(
                (pose.axis.into_inner() - axis).norm() < 1e-12,
                "line {}",
                s.line
            );
            checked += 1;
        }
        assert!(checked > 1000, "{checked} TCP samples");
    }
}

#[test]
fn g49_returns_to_joint_mode_where_moves_are_straight_in_joint_space() {
    let program = TCP_PROGRAM
        .replace("{H}", "1")
        .replace("M2\n", "G49\nG0 X50 Y-20 Z10 A10 C-30\nM2\n");
    let out = run_program(&program);
    assert_within_limits(&out.report);
    // TCP off: the program axes are the joints.
    let (last, _, _) = out.samples.last().unwrap();
    assert_joints(
        &last.joints,
        [50.0, -20.0, 10.0, 10f64.to_radians(), -30f64.to_radians()],
    );
    // The G0 (the joint-mode segment that ends at the programmed point; the take-up before
    // it ends where it starts): every sample on the straight joint line between its ends.
    let end = Vec3::new(50.0, -20.0, 10.0);
    let on_g0: Vec<&Sample> = out
        .samples
        .iter()
        .filter(|(_, c, e)| *c == Some(ToolControl::OFF) && *e == Some(end))
        .map(|(s, _, _)| s)
        .collect();
    assert!(on_g0.len() > 100, "{} samples", on_g0.len());
    let goal = [50.0, -20.0, 10.0, 10f64.to_radians(), -30f64.to_radians()];
    let first = on_g0[0].joints;
    for s in &on_g0 {
        // q = goal + λ (first − goal) with one λ for every joint.
        let d0: Vec<f64> = (0..5).map(|j| first[j] - goal[j]).collect();
        let k = (0..5)
            .max_by(|&i, &j| d0[i].abs().total_cmp(&d0[j].abs()))
            .unwrap();
        let lambda = (s.joints[k] - goal[k]) / d0[k];
        for j in 0..5 {
            let want = goal[j] + lambda * d0[j];
            assert!((s.joints[j] - want).abs() < 1e-9, "joint {j} at t {}", s.t);
        }
    }
    // Before the G0, the take-up: the TCP joints of the G49 point become the joint-mode
    // reading of it, at rest at both ends; it belongs to the G0's line.
    let takeup = out
        .samples
        .iter()
        .filter(|(s, c, e)| s.line == 8 && *c == Some(ToolControl::OFF) && *e != Some(end))
        .count();
    assert!(takeup > 10, "{takeup} take-up samples");
}

#[test]
fn a_switch_at_a_point_whose_joints_agree_needs_no_take_up() {
    // On a Cartesian mill G43 H1 then G43.4 H1 reads the same gauge point two ways: the
    // joints agree and nothing is inserted; G1 Z-5 puts the tip at -5, the gauge at 30.
    let machine = Machine::builtin("mill3").unwrap();
    let cfg = Config {
        tool_table: ToolTable::parse(TOOLS).unwrap(),
        ..Config::default()
    };
    let moves = program_moves(
        "G21 G90\nG43 H1\nG0 X1 Z10\nG43.4 H1\nG1 Z-5 F600\nM2\n",
        cfg,
    )
    .unwrap();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    // As `tezgah run`: the machine gives the tool axis of the program angles.
    let opts = SmoothOptions {
        orientation: Some(smooth::Orientation(Arc::new(pm.clone()))),
        ..SmoothOptions::default()
    };
    let items = smooth::build(moves, &opts).unwrap();
    let segments = items
        .iter()
        .filter(|i| matches!(i, tezgah_motion::PathItem::Segment(_)))
        .count();
    let mut lines = vec![];
    let mut last = None;
    run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |s: &Sample, seg: &[Arc<Segment>]| {
            if let Some(g) = seg.last() {
                if lines.last() != Some(&(g.line, g.control)) {
                    lines.push((g.line, g.control));
                }
            }
            last = Some(s.joints);
        },
    )
    .unwrap();
    assert_eq!(segments, 2);
    let tcp = ToolControl::CentrePoint { tool_length: 35.0 };
    let g43 = ToolControl::Joints { tool_length: 35.0 };
    assert_eq!(lines, [(3, g43), (5, tcp)]);
    let q = last.unwrap();
    assert_eq!(q.as_slice(), &[1.0, 0.0, 30.0]);
}

#[test]
fn with_tcp_off_an_axis_without_a_joint_is_refused_not_ignored() {
    let machine = Machine::builtin("table-ac").unwrap();
    let moves = program_moves("G21\nG1 X5 B10 F100\nM2\n", Config::default()).unwrap();
    let items = smooth::build(moves, &SmoothOptions::default()).unwrap();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let err = run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |_, _| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.starts_with("line 2: B has no joint on this machine"),
        "{err}"
    );
}

/// Under TCP a block that only turns the tool takes F in degrees per minute of the
/// tool axis's rotation. At A30, a C turn of 90° moves the axis (sin A sin C, sin A cos C,
/// cos A) on the great circle between its ends (Kahraman et al., eqs 1–3), through
/// 2·asin(sin 30°·sin 45°) = 41.41°: at F600 (10°/s) that is 4.14 s plus the speed's rise and
/// fall, not the 9 s the C axis's own travel would take (nor the 4.5 s of the cone that linear
/// angles would sweep). The A turn of 30°
/// from A0 turns the axis by 30°: 3 s.
#[test]
fn a_block_that_only_turns_the_tool_takes_f_as_the_tool_axis_rotation() {
    let program = "G21 G90 G94 G64\nG43.4 H1\nG0 X0 Y0 Z20 A0 C0\nG1 A30 F600\nG1 C90\nM2\n";
    let out = run_program(program);
    assert_within_limits(&out.report);
    let span = |line: u32| {
        let ts: Vec<f64> = out
            .samples
            .iter()
            .filter(|(s, _, _)| s.line == line)
            .map(|(s, _, _)| s.t)
            .collect();
        ts.last().unwrap() - ts.first().unwrap()
    };
    let (a_turn, c_turn) = (span(4), span(5));
    assert!((3.0..3.1).contains(&a_turn), "A30: {a_turn} s");
    let turn = 2.0 * (0.5 * 45f64.to_radians().sin()).asin().to_degrees();
    assert!(
        (turn / 10.0..turn / 10.0 + 0.1).contains(&c_turn),
        "C90 at A30: {c_turn} s"
    );
}

/// Kahraman et al.'s five-axis path end to end: a 5-axis polygon whose orientation changes along
/// every side and at every corner, under TCP. At every sample the tool axis of the joints (forward
/// kinematics) is within the machine's angular tolerance (0.1°) of the programmed axis at the
/// nearest programmed point — the great circle between the closed-form axes of the move's
/// ends, at that point's fraction of the move — the tip within the path tolerance, every joint
/// within its limits, and the last sample is the programmed end pose exactly.
#[test]
fn the_tool_axis_of_every_sample_stays_within_the_angular_tolerance() {
    let program = "G21 G90 G94 G64
G43.4 H1
G0 X10 Y0 Z5 A10 C0
G1 Z0 F600
G1 X20 Y5 A20 C20
G1 X25 Y15 A25 C50
G1 X15 Y25 A15 C80
G1 X5 Y15 A20 C60
G1 X10 Y0 A10 C0
M2
";
    let points: [([f64; 3], f64, f64); 7] = [
        ([10.0, 0.0, 5.0], 10.0, 0.0),
        ([10.0, 0.0, 0.0], 10.0, 0.0),
        ([20.0, 5.0, 0.0], 20.0, 20.0),
        ([25.0, 15.0, 0.0], 25.0, 50.0),
        ([15.0, 25.0, 0.0], 15.0, 80.0),
        ([5.0, 15.0, 0.0], 20.0, 60.0),
        ([10.0, 0.0, 0.0], 10.0, 0.0),
    ];
    let axis = |a: f64, c: f64| {
        let (a, c) = (a.to_radians(), c.to_radians());
        Vec3::new(a.sin() * c.sin(), a.sin() * c.cos(), a.cos())
    };
    let out = run_program(program);
    assert_within_limits(&out.report);
    let machine = Machine::builtin("table-ac").unwrap();
    let tool = Tool::with_length(35.0);
    let (mut worst, mut checked) = (0.0f64, 0);
    for (s, control, _) in &out.samples {
        if *control != Some(ToolControl::CentrePoint { tool_length: 35.0 }) || s.line < 4 {
            continue;
        }
        let pose = machine.kinematics.forward(&s.joints, &tool).unwrap();
        let mut best = (f64::INFINITY, Vec3::z());
        for w in points.windows(2) {
            let (p0, p1) = (Vec3::from(w[0].0), Vec3::from(w[1].0));
            let d = p1 - p0;
            let t = ((s.tip - p0).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            let dist = (p0 + d * t - s.tip).norm();
            if dist < best.0 {
                let g = tezgah_motion::path::orient::GreatCircle::new(
                    axis(w[0].1, w[0].2),
                    axis(w[1].1, w[1].2),
                )
                .unwrap();
                best = (dist, g.at(t));
            }
        }
        assert!(best.0 <= 0.01, "line {}: tip {} mm off", s.line, best.0);
        let dev = tezgah_motion::path::orient::angle_between(&pose.axis.into_inner(), &best.1);
        worst = worst.max(dev.to_degrees());
        checked += 1;
    }
    assert!(checked > 3000, "{checked} samples");
    assert!(worst <= 0.1, "axis {worst}° off");
    // The corners are blended in the axis too: it leaves the programmed axis there.
    assert!(
        worst > 1e-4,
        "axis at most {worst}° off: no corner blended?"
    );
    let (last, _, _) = out.samples.last().unwrap();
    assert_joints(&last.joints, closed_form([10.0, 0.0, 0.0], 10.0, 0.0, 35.0));
}

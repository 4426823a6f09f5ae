//! Each sample's tool (`tool_pose::SampleTool`, what the samples CSV prints) against closed
//! forms of the kinematic conventions (docs/machine-files.md), end to end (G-code → path → plan →
//! samples): with TCP off on table-ac, table-bc and yzca the tip is where the table or head puts
//! the tool of the G43 length, not the program's X Y Z; with TCP on it is the program tip. And the
//! take-up at a switch starts from the joints the interpolator reached (yzca's endless C).

use std::sync::Arc;

use tezgah_gcode::{program_moves, Config, ToolTable};
use tezgah_geom::{ToolControl, Vec3};
use tezgah_kinematics::{Joints, Machine, ToolPose};
use tezgah_motion::interpolate::{run, Sample};
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::tool_pose::SampleTool;
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::Segment;

const TOOLS: &str = "T1 P1 Z35.0 D6\nT2 P2 Z28.5 D3\n";

struct Row {
    sample: Sample,
    control: Option<ToolControl>,
    pose: ToolPose,
}

fn run_program(machine: &Machine, program: &str) -> (Vec<Row>, Report) {
    let cfg = Config {
        tool_table: ToolTable::parse(TOOLS).unwrap(),
        tool_centre_point_always: machine.tcp == tezgah_kinematics::TcpSwitch::Always,
        ..Config::default()
    };
    let moves = program_moves(program, cfg).unwrap();
    let pm = PlanMachine::from_machine(machine).unwrap();
    let opts = SmoothOptions {
        orientation: Some(smooth::Orientation(Arc::new(pm.clone()))),
        ..SmoothOptions::default()
    };
    // Measured against the program (take-ups at the switches are not the program's).
    let program = ProgramPath::new(tezgah_geom::Pose::ZERO, pm.initial, &moves);
    let items = smooth::build(moves, &opts).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s).against(&pm, program);
    let mut tool = SampleTool::new(&pm);
    let mut rows = vec![];
    run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |s: &Sample, seg: &[Arc<Segment>]| {
            verifier.push(s, seg);
            rows.push(Row {
                sample: *s,
                control: seg.last().map(|g| g.control),
                pose: tool.pose(s, seg).unwrap(),
            });
        },
    )
    .unwrap();
    (rows, verifier.finish())
}

fn assert_within_limits(r: &Report) {
    for (i, j) in r.joints.iter().enumerate() {
        assert!(j.worst_ratio() <= 1.005, "joint {i}: {j:?}");
    }
    assert!(r.max_deviation <= 0.01, "deviation {}", r.max_deviation);
}

fn near(a: &Vec3, b: &Vec3, tol: f64, what: &str) {
    assert!((a - b).norm() < tol, "{what}: {a:?} vs {b:?}");
}

/// Which machine axis a trunnion tilts about.
#[derive(Clone, Copy)]
enum Tilt {
    X,
    Y,
}

/// The conventions: a part point p is at `pivot + R_tilt(θ)·(c_offset + Rz(C)·p)`, the gauge point
/// `length` above the tip along machine +Z; so p = Rz(−C)·(R_tilt(−θ)·(q − length·ẑ − pivot)
/// − c_offset). The axis seen from the part: table-ac (sin A sin C, sin A cos C, cos A),
/// table-bc (−sin B cos C, sin B sin C, cos B).
fn trunnion_tool(tilt: Tilt, pivot: Vec3, c_offset: Vec3, q: &Joints, length: f64) -> (Vec3, Vec3) {
    let (t, c) = (q[3], q[4]);
    let w = Vec3::new(q[0], q[1], q[2] - length) - pivot;
    let (st, ct) = t.sin_cos();
    let u = match tilt {
        Tilt::X => Vec3::new(w.x, ct * w.y + st * w.z, -st * w.y + ct * w.z),
        Tilt::Y => Vec3::new(ct * w.x - st * w.z, w.y, st * w.x + ct * w.z),
    } - c_offset;
    let (sc, cc) = c.sin_cos();
    let p = Vec3::new(cc * u.x + sc * u.y, -sc * u.x + cc * u.y, u.z);
    let axis = match tilt {
        Tilt::X => Vec3::new(st * sc, st * cc, ct),
        Tilt::Y => Vec3::new(-st * cc, st * sc, ct),
    };
    (p, axis)
}

/// README "Kinematic conventions", yzca (joints y z c a): r = y + l·sin A, x = r·cos C,
/// y = −r·sin C, z = z_joint − l·cos A, axis (−sin A cos C, sin A sin C, cos A); l is the tool
/// length (the built-in's pivot_to_gauge is 0).
fn yzca_tool(q: &Joints, length: f64) -> (Vec3, Vec3) {
    let (yj, zj, c, a) = (q[0], q[1], q[2], q[3]);
    let (sa, ca) = a.sin_cos();
    let (sc, cc) = c.sin_cos();
    let r = yj + length * sa;
    (
        Vec3::new(r * cc, -r * sc, zj - length * ca),
        Vec3::new(-sa * cc, sa * sc, ca),
    )
}

/// TCP off, G43 H2 (28.5 mm), A and C moving: forward(joints) of every sample.
const TCP_OFF: &str = "G21 G90 G94 G64
G43 H2
G0 X10 Y20 Z30 A0 C0
G1 X40 Y-10 Z20 A25 C70 F2000
G1 A10 C200 F3000
G1 X-5 Y15 F1500
M2
";

#[test]
fn tcp_off_trunnion_tip_is_the_forward_kinematics_of_the_joints() {
    // The built-ins' pivot and c_offset (machines/table-ac.toml, machines/table-bc.toml).
    let pivot = Vec3::new(0.0, 0.0, -150.0);
    for (name, tilt, letter, c_offset) in [
        ("table-ac", Tilt::X, 'A', Vec3::new(0.0, 2.0, 50.0)),
        ("table-bc", Tilt::Y, 'B', Vec3::new(2.0, 0.0, 50.0)),
    ] {
        let machine = Machine::builtin(name).unwrap();
        let (rows, report) = run_program(&machine, &TCP_OFF.replace('A', &letter.to_string()));
        assert_within_limits(&report);
        let mut moving = 0;
        for r in &rows {
            let (tip, axis) = trunnion_tool(tilt, pivot, c_offset, &r.sample.joints, 28.5);
            near(&r.pose.tip, &tip, 1e-9, name);
            near(&r.pose.axis.into_inner(), &axis, 1e-12, name);
            if r.sample.joints[3].abs() > 0.1 {
                // Tilted: the tool tip is far from the program's X Y Z (the joints).
                assert!((r.pose.tip - r.sample.tip).norm() > 1.0);
                moving += 1;
            }
        }
        assert!(moving > 500, "{name}: {moving} tilted samples");
        // The final row: the forward map of the last block's joints, X-5 Y15 Z20 (+28.5) A10
        // C200 (closed form evaluated at the programmed values).
        let end = Joints::new([-5.0, 15.0, 48.5, 10f64.to_radians(), 200f64.to_radians()]);
        let (tip, _) = trunnion_tool(tilt, pivot, c_offset, &end, 28.5);
        near(&rows.last().unwrap().pose.tip, &tip, 1e-9, name);
    }
}

#[test]
fn tcp_off_at_a_and_c_zero_the_tip_is_the_program_point_less_the_table_offsets() {
    // The built-in table-ac: at A = C = 0 a part point p is at pivot + c_offset + p, so the
    // tip is the program's X Y Z less (0, 2, −100); on a table whose axes meet at the machine
    // origin it is the program's X Y Z itself.
    let program = "G21 G90 G94\nG43 H1\nG0 X10 Y20 Z30\nG1 X40 Y-10 Z5 F3000\nG2 X60 Y10 R20\nM2\n";
    let builtin = Machine::builtin("table-ac").unwrap();
    let text = Machine::builtin_text("table-ac")
        .unwrap()
        .replace("pivot = [0.0, 0.0, -150.0]", "pivot = [0.0, 0.0, 0.0]")
        .replace("c_offset = [0.0, 2.0, 50.0]", "c_offset = [0.0, 0.0, 0.0]");
    let centred = Machine::from_toml_str(&text).unwrap();
    for (machine, shift) in [
        (&builtin, Vec3::new(0.0, 2.0, -100.0)),
        (&centred, Vec3::zeros()),
    ] {
        let (rows, report) = run_program(machine, program);
        assert_within_limits(&report);
        for r in &rows {
            // The sample's program point carries G43's 35 mm in Z (the gauge point).
            let program_point = r.sample.tip - Vec3::new(0.0, 0.0, 35.0);
            near(&r.pose.tip, &(program_point - shift), 1e-9, "tip");
            near(&r.pose.axis.into_inner(), &Vec3::z(), 1e-15, "axis");
        }
        near(
            &rows.last().unwrap().pose.tip,
            &(Vec3::new(60.0, 10.0, 5.0) - shift),
            1e-9,
            "end",
        );
    }
}

#[test]
fn tcp_off_yzca_tip_is_the_forward_kinematics_of_the_joints() {
    let machine = Machine::builtin("yzca").unwrap();
    let program =
        "G21 G90 G94\nG43 H2\nG0 Y50 Z20 A0 C0\nG4 P0.01\nG1 Y80 Z10 A20 C120 F2000\nG1 A-15 C-40\nM2\n";
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    for r in &rows {
        let (tip, axis) = yzca_tool(&r.sample.joints, 28.5);
        near(&r.pose.tip, &tip, 1e-9, "tip");
        near(&r.pose.axis.into_inner(), &axis, 1e-12, "axis");
    }
    // At A = C = 0 (line 3's end, held exactly by the dwell) the Y slide is the part's +X:
    // the tip is (Y, 0, Z), not the program's X Y Z.
    let at_g0 = rows
        .iter()
        .find(|r| r.sample.line == 4)
        .expect("samples of the dwell");
    near(&at_g0.pose.tip, &Vec3::new(50.0, 0.0, 20.0), 1e-9, "G0 end");
}

#[test]
fn tcp_on_the_tip_is_the_program_tip() {
    let program = "G21 G90 G94 G64
G43.4 H1
G0 X10 Y5 Z20 A0 C0
G1 Z-3 F600
G1 A30 C40 F3600
G1 X20 Y-10 F900
G49
G0 X0 Y0 Z50 A0 C0
M2
";
    let machine = Machine::builtin("table-ac").unwrap();
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    let mut on = 0;
    for r in &rows {
        if let Some(ToolControl::CentrePoint { tool_length }) = r.control {
            assert_eq!(tool_length, 35.0);
            near(&r.pose.tip, &r.sample.tip, 1e-9, "tip");
            let (a, c) = (
                r.sample.rotary[0].to_radians(),
                r.sample.rotary[2].to_radians(),
            );
            let axis = Vec3::new(a.sin() * c.sin(), a.sin() * c.cos(), a.cos());
            near(&r.pose.axis.into_inner(), &axis, 1e-12, "axis");
            on += 1;
        }
    }
    assert!(on > 1000, "{on} samples under TCP");
    // After G49 with no G43: no tool length, the tip is the gauge point (program X Y Z at the
    // end, A = C = 0: less the table offsets).
    near(
        &rows.last().unwrap().pose.tip,
        &Vec3::new(0.0, -2.0, 150.0),
        1e-9,
        "after G49",
    );
}

#[test]
fn tcp_always_uses_the_g43_length_along_the_tool_axis() {
    let text = Machine::builtin_text("table-ac")
        .unwrap()
        .replace("tcp = \"program\"", "tcp = \"always\"");
    let machine = Machine::from_toml_str(&text).unwrap();
    let program = "G21 G90 G94\nG43 H2\nG0 X10 Y5 Z20 A0 C0\nG1 A30 C40 F3600\nG1 X-10 F900\nM2\n";
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    for r in rows.iter().filter(|r| r.sample.line >= 4) {
        near(&r.pose.tip, &r.sample.tip, 1e-9, "tip");
    }
    near(
        &rows.last().unwrap().pose.tip,
        &Vec3::new(-10.0, 5.0, 20.0),
        1e-9,
        "end",
    );
}

#[test]
fn mill3_tip_is_the_program_point_without_the_g43_length() {
    let machine = Machine::builtin("mill3").unwrap();
    let program = "G21 G90 G94\nG43 H1\nG0 X10 Y20 Z5\nG1 Z-2 F600\nG49\nG0 Z60\nM2\n";
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    for r in &rows {
        let length = match r.control {
            Some(ToolControl::Joints { tool_length }) => tool_length,
            _ => 0.0,
        };
        let want = r.sample.tip - Vec3::new(0.0, 0.0, length);
        near(&r.pose.tip, &want, 1e-12, "tip");
    }
    // Down to the program's Z-2 with the tool: the tip at -2, the spindle at 33 (the last
    // sample of the block, within a period of its end at rest: a jerk-limited stop covers at
    // most J·Ts³/6 in its last period, Z's J = 25 000 mm/s³ → 4.2 µm).
    let last_period = 25_000.0 * 1e-9 / 6.0;
    let bottom = rows.iter().rfind(|r| r.sample.line == 4).unwrap();
    near(
        &bottom.pose.tip,
        &Vec3::new(10.0, 20.0, -2.0),
        last_period,
        "bottom",
    );
    assert!((bottom.sample.joints[2] - 33.0).abs() < last_period);
    // After G49 the program point is the gauge point again, and so is the tip.
    near(
        &rows.last().unwrap().pose.tip,
        &Vec3::new(10.0, 20.0, 60.0),
        1e-9,
        "end",
    );
}

/// yzca under TCP: the tip circles the C axis through 270° in one block (C programmed along,
/// since it picks the turn), then G49. The take-up starts where the interpolator left the
/// joints: C moves continuously throughout, and TCP off reads the same C (the program's), so
/// the take-up turns C by nothing — not by a turn.
#[test]
fn yzca_take_up_after_a_long_turn_of_c_starts_from_the_joints_reached() {
    let machine = Machine::builtin("yzca").unwrap();
    let program = "G21 G90 G94 G61
G43.4 H2
G0 X50 Y0 Z10 A0 C0
G3 X0 Y-50 I-50 J0 C-270 F3000
G4 P0.01
G49
G0 Y60
M2
";
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    // C = −(polar angle of the tip): from 0 to −270° along the arc.
    let c_min = rows
        .iter()
        .map(|r| r.sample.joints[2].to_degrees())
        .fold(f64::INFINITY, f64::min);
    assert!((c_min + 270.0).abs() < 1e-9, "C reaches {c_min}");
    // No jump anywhere: C moves at most its top speed (360°/s) times the period.
    for w in rows.windows(2) {
        let dc = (w[1].sample.joints[2] - w[0].sample.joints[2]).to_degrees();
        assert!(
            dc.abs() <= 0.36 + 1e-9,
            "C jumps {dc}° at t {}",
            w[1].sample.t
        );
    }
    // The take-up and the G0 (line 7) leave C where the arc left it (the dwell holds the
    // arc's exact end).
    let travel: f64 = rows
        .windows(2)
        .filter(|w| w[1].sample.line == 7)
        .map(|w| (w[1].sample.joints[2] - w[0].sample.joints[2]).abs())
        .sum();
    assert!(
        travel.to_degrees() < 1e-9,
        "take-up turns C {}°",
        travel.to_degrees()
    );
    // TCP off at the end: the joints are the program axes, Y60 Z10+28.5 C-270 A0.
    let last = rows.last().unwrap();
    let want = [60.0, 38.5, (-270f64).to_radians(), 0.0];
    for (g, w) in last.sample.joints.as_slice().iter().zip(want) {
        assert!((g - w).abs() < 1e-9, "{:?}", last.sample.joints);
    }
    // And the tip: forward kinematics of those joints with the 28.5 mm of G43.4, now G49's 0.
    near(
        &last.pose.tip,
        &yzca_tool(&last.sample.joints, 0.0).0,
        1e-12,
        "tip",
    );
}

/// The delta: the forward map of the carriage heights (Ayyıldız, 2017), less
/// G43's 35 mm, is the program point; no tool axis but +Z.
#[test]
fn linear_delta_tip_is_the_program_point_under_g43() {
    let machine = Machine::builtin("linear-delta").unwrap();
    let program = "G21 G90 G94\nG43 H1\nG0 X10 Y5 Z-20\nG1 X-15 Y12 Z-30 F3000\nM2\n";
    let (rows, report) = run_program(&machine, program);
    assert_within_limits(&report);
    for r in rows.iter().filter(|r| r.sample.line >= 3) {
        near(
            &r.pose.tip,
            &(r.sample.tip - Vec3::new(0.0, 0.0, 35.0)),
            1e-9,
            "tip",
        );
        near(&r.pose.axis.into_inner(), &Vec3::z(), 1e-15, "axis");
    }
    near(
        &rows.last().unwrap().pose.tip,
        &Vec3::new(-15.0, 12.0, -30.0),
        1e-9,
        "end",
    );
}

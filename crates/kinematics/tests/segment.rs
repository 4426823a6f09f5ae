//! Segmentation by deviation: the split moves keep the joint-interpolated tip within the
//! tolerance (checked here far more densely than the splitter checks), and the split is not
//! wasteful on machines that need none.

use nalgebra::Vector3;
use tezgah_kinematics::segment::{
    joint_line_deviation, segment_pose_line, segment_tcp_line, SegmentOptions, Segmented,
};
use tezgah_kinematics::tcp::ProgramPose;
use tezgah_kinematics::{Joints, Kinematics, Machine, Tool, ToolPose};

fn worst_dense(m: &Machine, tool: &Tool, s: &Segmented, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    s.points
        .windows(2)
        .map(|w| {
            joint_line_deviation(&m.kinematics, tool, &w[0].1, &w[1].1, a, b, 64)
                .unwrap()
                .0
        })
        .fold(0.0, f64::max)
}

#[test]
fn delta_diagonal_within_tolerance() {
    let m = Machine::builtin("linear-delta").unwrap();
    let tool = Tool::default();
    let a = Vector3::new(-31.654, -28.911, -0.2);
    let b = Vector3::new(39.057, 41.8, -0.2);
    for tol in [0.1, 0.01, 0.001] {
        let s = segment_pose_line(
            &m.kinematics,
            &tool,
            &ToolPose::vertical(a),
            &ToolPose::vertical(b),
            &m.home(),
            &SegmentOptions::tip(tol),
        )
        .unwrap();
        let worst = worst_dense(&m, &tool, &s, &a, &b);
        // three checks per piece see the bow near its top; allow 5 % for the sampled peak
        assert!(worst <= 1.05 * tol, "tol {tol}: dense worst {worst}");
        assert!(s.max_deviation_mm <= tol);
        // sag ∝ length², 4.646 mm unsplit: about √(4.646/tol) pieces are needed, ≤ 2× that used
        let need = (4.646 / tol).sqrt();
        let pieces = (s.points.len() - 1) as f64;
        assert!(
            pieces >= 0.7 * need && pieces <= 2.5 * need,
            "tol {tol}: {pieces} pieces, ~{need} needed"
        );
        // ends are the exact inverse of the programmed ends
        let qa = m
            .kinematics
            .inverse(&ToolPose::vertical(a), &tool, &m.home())
            .unwrap();
        let qb = m
            .kinematics
            .inverse(&ToolPose::vertical(b), &tool, &m.home())
            .unwrap();
        assert_eq!(s.points[0].1, qa);
        assert!((s.points.last().unwrap().1.as_slice()[0] - qb[0]).abs() < 1e-12);
        assert!(s.points.windows(2).all(|w| w[0].0 < w[1].0));
    }
}

#[test]
fn cartesian_needs_one_piece() {
    let m = Machine::builtin("mill3").unwrap();
    let tool = Tool::with_length(20.0);
    let a = ToolPose::vertical(Vector3::new(-50.0, 10.0, 5.0));
    let b = ToolPose::vertical(Vector3::new(80.0, -40.0, -20.0));
    let s = segment_pose_line(
        &m.kinematics,
        &tool,
        &a,
        &b,
        &m.home(),
        &SegmentOptions::tip(1e-6),
    )
    .unwrap();
    assert_eq!(s.points.len(), 2);
}

#[test]
fn table_ac_tcp_move_within_tolerance() {
    let m = Machine::builtin("table-ac").unwrap();
    let tool = Tool::with_length(60.0);
    let a = ProgramPose {
        tip: Vector3::new(20.0, -10.0, 5.0),
        angles: Joints::new([0.0, 0.0]),
    };
    let b = ProgramPose {
        tip: Vector3::new(40.0, 30.0, 0.0),
        angles: Joints::new([60f64.to_radians(), 200f64.to_radians()]),
    };
    let tol = 0.005;
    let s = segment_tcp_line(
        &m.kinematics,
        &tool,
        &a,
        &b,
        &m.home(),
        &SegmentOptions::tip(tol),
    )
    .unwrap();
    assert!(s.points.len() > 10, "{} points", s.points.len());
    let worst = worst_dense(&m, &tool, &s, &a.tip, &b.tip);
    assert!(worst <= 1.05 * tol, "{worst}");
    // Under TCP the joints of each waypoint carry the programmed angles themselves, and C
    // turns the long way (200°) as programmed rather than being unwrapped to −160°.
    let last = s.points.last().unwrap().1;
    assert!(
        (last[3] - 60f64.to_radians()).abs() < 1e-12
            && (last[4] - 200f64.to_radians()).abs() < 1e-12
    );
    // Without splitting, the tip would leave the line by far more.
    let unsplit = joint_line_deviation(
        &m.kinematics,
        &tool,
        &s.points[0].1,
        &last,
        &a.tip,
        &b.tip,
        200,
    )
    .unwrap()
    .0;
    assert!(unsplit > 10.0 * tol, "{unsplit}");
}

#[test]
fn five_axis_pose_move_with_axis_tolerance() {
    let m = Machine::builtin("table-bc").unwrap();
    let tool = Tool::with_length(40.0);
    let a = ToolPose::new(Vector3::new(10.0, 0.0, 10.0), Vector3::new(0.0, 0.3, 1.0));
    let b = ToolPose::new(Vector3::new(-10.0, 25.0, 0.0), Vector3::new(-0.5, 0.2, 1.0));
    let mut opt = SegmentOptions::tip(0.002);
    opt.axis_tolerance_rad = Some(1e-4);
    let s = segment_pose_line(&m.kinematics, &tool, &a, &b, &m.home(), &opt).unwrap();
    assert!(worst_dense(&m, &tool, &s, &a.tip, &b.tip) <= 1.05 * 0.002);
    // the axis at every waypoint is the great-circle axis of the program
    for (sp, q) in &s.points {
        let want = tezgah_kinematics::segment::slerp_axis(&a.axis, &b.axis, *sp).unwrap();
        let got = m.kinematics.forward(q, &tool).unwrap().axis;
        assert!((got.into_inner() - want.into_inner()).norm() < 1e-9);
    }
}

#[test]
fn impossible_tolerance_is_an_error() {
    let m = Machine::builtin("linear-delta").unwrap();
    let tool = Tool::default();
    let a = ToolPose::vertical(Vector3::new(-30.0, 0.0, 0.0));
    let b = ToolPose::vertical(Vector3::new(30.0, 0.0, 0.0));
    let mut opt = SegmentOptions::tip(1e-300);
    opt.max_depth = 12;
    let e = segment_pose_line(&m.kinematics, &tool, &a, &b, &m.home(), &opt).unwrap_err();
    assert!(e.to_string().contains("cannot keep the tip within"), "{e}");
    // and a move that leaves the workspace is refused with the kinematic error
    let far = ToolPose::vertical(Vector3::new(400.0, 0.0, 0.0));
    assert!(segment_pose_line(
        &m.kinematics,
        &tool,
        &a,
        &far,
        &m.home(),
        &SegmentOptions::tip(0.01)
    )
    .is_err());
}

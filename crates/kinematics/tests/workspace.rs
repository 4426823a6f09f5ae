//! Solution choice and workspace checks: branches by continuity and limits, the pole passed
//! without jumps, shortest C unwrap, and typed errors naming the joint (with the program line
//! attached by the caller).

use nalgebra::Vector3;
use tezgah_kinematics::{Kinematics, KinematicsError, Machine, Tool, ToolPose};

fn deg(m: &Machine, q: &tezgah_kinematics::Joints) -> Vec<f64> {
    m.to_file_units(q)
}

fn ac_axis(a: f64, c: f64) -> Vector3<f64> {
    tezgah_kinematics::table_ac::axis(a.to_radians(), c.to_radians())
}

#[test]
fn trunnion_branch_by_continuity_and_limits() {
    let m = Machine::builtin("table-ac").unwrap();
    let tool = Tool::with_length(30.0);
    let pose = ToolPose::new(Vector3::new(10.0, 5.0, 0.0), ac_axis(20.0, 30.0));
    // previous tilt −15°: the (−20°, 210°) branch is nearer
    let prev = m.from_file_units(&[0.0, 0.0, 0.0, -15.0, 200.0]).unwrap();
    let q = deg(&m, &m.kinematics.inverse(&pose, &tool, &prev).unwrap());
    assert!(
        (q[3] + 20.0).abs() < 1e-9 && (q[4] - 210.0).abs() < 1e-9,
        "{q:?}"
    );
    // previous tilt +15°: the (20°, 30°) branch
    let prev = m.from_file_units(&[0.0, 0.0, 0.0, 15.0, 20.0]).unwrap();
    let q = deg(&m, &m.kinematics.inverse(&pose, &tool, &prev).unwrap());
    assert!(
        (q[3] - 20.0).abs() < 1e-9 && (q[4] - 30.0).abs() < 1e-9,
        "{q:?}"
    );
    // tilt 40°: the −40° branch is outside A ∈ [−30°, 120°], so +40° even from A = −25°
    let pose = ToolPose::new(Vector3::new(10.0, 5.0, 0.0), ac_axis(40.0, 30.0));
    let prev = m.from_file_units(&[0.0, 0.0, 0.0, -25.0, 200.0]).unwrap();
    let q = deg(&m, &m.kinematics.inverse(&pose, &tool, &prev).unwrap());
    assert!(
        (q[3] - 40.0).abs() < 1e-9 && (q[4] - 30.0).abs() < 1e-9,
        "{q:?}"
    );
}

#[test]
fn trunnion_shortest_c_unwrap() {
    let m = Machine::builtin("table-ac").unwrap();
    let tool = Tool::default();
    let prev = m.from_file_units(&[0.0, 0.0, 0.0, 30.0, 350.0]).unwrap();
    let pose = ToolPose::new(Vector3::new(1.0, 2.0, 3.0), ac_axis(30.0, 10.0));
    let q = deg(&m, &m.kinematics.inverse(&pose, &tool, &prev).unwrap());
    assert!((q[4] - 370.0).abs() < 1e-9, "{q:?}");
    let prev = m.from_file_units(&[0.0, 0.0, 0.0, 30.0, -710.0]).unwrap();
    let q = deg(&m, &m.kinematics.inverse(&pose, &tool, &prev).unwrap());
    assert!((q[4] + 710.0).abs() < 1e-9, "{q:?}");
}

/// A straight sweep of the axis through the pole: the tilt passes through zero and C holds,
/// with no 180° swing, because the continuity rule takes the other branch on the far side.
#[test]
fn trunnion_pole_sweep_without_jumps() {
    for name in ["table-ac", "table-bc"] {
        let m = Machine::builtin(name).unwrap();
        let tool = Tool::with_length(50.0);
        let mut q = m.from_file_units(&[0.0, 0.0, 0.0, 5.0, 90.0]).unwrap();
        let axis_at = |t: f64| {
            if name == "table-ac" {
                ac_axis(t, 90.0)
            } else {
                tezgah_kinematics::table_bc::axis(t.to_radians(), 90f64.to_radians())
            }
        };
        let c0 = q[4];
        let mut last_t = 5.0;
        for k in 0..=1000 {
            let t = 5.0 - 0.01 * k as f64; // 5° … −5°, through exactly 0
            let pose = ToolPose::new(Vector3::new(20.0, -10.0, 5.0), axis_at(t));
            q = m.kinematics.inverse(&pose, &tool, &q).unwrap();
            let f = deg(&m, &q);
            assert!(
                (q[4] - c0).abs() < 1e-9,
                "{name}: C moved to {} at t = {t}",
                f[4]
            );
            assert!(
                (f[3] - t).abs() < 1e-9 && (f[3] - last_t).abs() < 0.011,
                "{name}: {f:?} at {t}"
            );
            last_t = f[3];
            let back = m.kinematics.forward(&q, &tool).unwrap();
            assert!((back.tip - pose.tip).norm() < 1e-9);
        }
    }
}

#[test]
fn workspace_errors_are_typed_and_named() {
    // A tilt the table cannot make (|A| = 130° on either branch; limits [−30°, 120°]).
    let m = Machine::builtin("table-ac").unwrap();
    let pose = ToolPose::new(Vector3::zeros(), ac_axis(130.0, 0.0));
    let e = m
        .kinematics
        .inverse(&pose, &Tool::default(), &m.home())
        .unwrap_err();
    match &e {
        KinematicsError::JointLimit { name, unit, .. } => {
            assert_eq!((name.as_str(), *unit), ("a", "deg"))
        }
        other => panic!("{other:?}"),
    }
    // with the line attached for pre-flight
    let msg = e.clone().at_line(42).to_string();
    assert!(msg.starts_with("line 42: joint 3 (`a`)"), "{msg}");
    // A linear axis out of travel.
    let pose = ToolPose::new(Vector3::new(900.0, 0.0, 0.0), ac_axis(10.0, 0.0));
    match m
        .kinematics
        .inverse(&pose, &Tool::default(), &m.home())
        .unwrap_err()
    {
        KinematicsError::JointLimit {
            name, unit, value, ..
        } => {
            assert_eq!((name.as_str(), unit), ("x", "mm"));
            assert!(value > 400.0);
        }
        other => panic!("{other:?}"),
    }
    // A tilted axis on a 3-axis mill.
    let mill = Machine::builtin("mill3").unwrap();
    let pose = ToolPose::new(Vector3::zeros(), Vector3::new(0.1, 0.0, 1.0));
    assert!(matches!(
        mill.kinematics
            .inverse(&pose, &Tool::default(), &mill.home()),
        Err(KinematicsError::AxisUnreachable { .. })
    ));
    // A tilt out of the radial plane on Y-Z-C-A.
    let yzca = Machine::builtin("yzca").unwrap();
    let pose = ToolPose::new(Vector3::new(50.0, 0.0, 0.0), Vector3::new(0.0, 0.3, 1.0));
    assert!(matches!(
        yzca.kinematics
            .inverse(&pose, &Tool::default(), &yzca.home()),
        Err(KinematicsError::AxisUnreachable { .. })
    ));
    // Outside the delta's rod-angle boundary (5°) and beyond the rods.
    let delta = Machine::builtin("linear-delta").unwrap();
    for x in [-340.0, 600.0] {
        let e = delta
            .kinematics
            .inverse(
                &ToolPose::vertical(Vector3::new(x, 0.0, 0.0)),
                &Tool::default(),
                &delta.home(),
            )
            .unwrap_err();
        assert!(matches!(e, KinematicsError::Unreachable { .. }), "{e}");
        assert!(e.to_string().contains("tower 1"), "{e}");
    }
    // Carriage stroke (joint limit ±250 mm relative to home).
    let e = delta
        .kinematics
        .inverse(
            &ToolPose::vertical(Vector3::new(0.0, 0.0, 300.0)),
            &Tool::default(),
            &delta.home(),
        )
        .unwrap_err();
    assert!(
        matches!(e, KinematicsError::JointLimit { ref name, .. } if name == "q1"),
        "{e}"
    );
    // Bad input never panics.
    let short = tezgah_kinematics::Joints::zeros(2);
    assert!(matches!(
        m.kinematics.forward(&short, &Tool::default()),
        Err(KinematicsError::BadInput { .. })
    ));
    let nan = ToolPose {
        tip: Vector3::new(f64::NAN, 0.0, 0.0),
        axis: Vector3::z_axis(),
    };
    for name in tezgah_kinematics::builtin_names() {
        let mm = Machine::builtin(name).unwrap();
        assert!(
            matches!(
                mm.kinematics.inverse(&nan, &Tool::default(), &mm.home()),
                Err(KinematicsError::BadInput { .. })
            ),
            "{name}"
        );
        assert!(mm
            .kinematics
            .inverse(
                &ToolPose::vertical(Vector3::zeros()),
                &Tool::default(),
                &short
            )
            .is_err());
    }
}

/// Joint rates from the Jacobian: a delta moving along X at 10 mm/s.
#[test]
fn joint_velocity_through_the_jacobian() {
    let m = Machine::builtin("linear-delta").unwrap();
    let tool = Tool::default();
    let p = Vector3::new(20.0, -10.0, 5.0);
    let q = m
        .kinematics
        .inverse(&ToolPose::vertical(p), &tool, &m.home())
        .unwrap();
    let v = Vector3::new(10.0, 0.0, 0.0);
    let qd = m
        .kinematics
        .joint_velocity(&q, &tool, &v, &Vector3::zeros(), 1e-12)
        .unwrap();
    // finite difference of the inverse
    let h = 1e-5;
    let qa = m
        .kinematics
        .inverse(&ToolPose::vertical(p + v * h), &tool, &q)
        .unwrap();
    let qb = m
        .kinematics
        .inverse(&ToolPose::vertical(p - v * h), &tool, &q)
        .unwrap();
    for i in 0..3 {
        assert!((qd[i] - (qa[i] - qb[i]) / (2.0 * h)).abs() < 1e-6, "{qd:?}");
    }
    // a 5-axis machine: a pure tool-axis rotation about the tip
    let m = Machine::builtin("table-ac").unwrap();
    let q = m.from_file_units(&[10.0, 20.0, 30.0, 40.0, 50.0]).unwrap();
    let pose = m.kinematics.forward(&q, &tool).unwrap();
    let j = m.kinematics.jacobian(&q, &tool).unwrap();
    let qd_want = nalgebra::DVector::from_vec(vec![0.0, 0.0, 0.0, 0.1, -0.2]);
    let pd = &j * &qd_want;
    let got = m
        .kinematics
        .joint_velocity(
            &q,
            &tool,
            &Vector3::new(pd[0], pd[1], pd[2]),
            &Vector3::new(pd[3], pd[4], pd[5]),
            1e-12,
        )
        .unwrap();
    for i in 0..5 {
        assert!((got[i] - qd_want[i]).abs() < 1e-9, "{got:?}");
    }
    assert!(pose.axis.z < 1.0);
}

/// The interpreter's program pose (degrees) maps to TCP joints and back through each
/// machine's program axes.
#[test]
fn tcp_from_interpreter_pose() {
    use tezgah_geom::{Axis, Pose};
    use tezgah_kinematics::tcp::{ProgramPose, Tcp};
    let m = Machine::builtin("table-ac").unwrap();
    let axes = m.tcp_axes().unwrap();
    assert_eq!(axes, [Axis::A, Axis::C]);
    let prog = Pose::new(12.0, -7.0, 3.0, 35.0, 0.0, 400.0);
    let pp = ProgramPose::from_program(&prog, &axes).unwrap();
    let tcp = Tcp::new(&m.kinematics, Tool::with_length(80.0));
    let q = tcp.joints(&pp, &m.home()).unwrap();
    let f = m.to_file_units(&q);
    assert!(
        (f[3] - 35.0).abs() < 1e-12 && (f[4] - 400.0).abs() < 1e-9,
        "{f:?}"
    );
    let back = tcp.program(&q).unwrap().to_program(&axes);
    for i in 0..6 {
        assert!((back.0[i] - prog.0[i]).abs() < 1e-9, "{back:?}");
    }
    // the tool axis of docs/machine-files.md's conventions for (A, C)
    let axis = tcp.tool_pose(&pp, &m.home()).unwrap().axis;
    assert!((axis.into_inner() - ac_axis(35.0, 400.0)).norm() < 1e-12);
    assert_eq!(
        Machine::builtin("yzca").unwrap().tcp_axes().unwrap(),
        [Axis::C, Axis::A]
    );
    assert!(Machine::builtin("linear-delta")
        .unwrap()
        .tcp_axes()
        .unwrap()
        .is_empty());
    assert!(ProgramPose::from_program(&prog, &[Axis::X]).is_err());
    let nan = ProgramPose {
        tip: Vector3::new(f64::NAN, 0.0, 0.0),
        angles: pp.angles,
    };
    assert!(matches!(
        tcp.joints(&nan, &m.home()),
        Err(KinematicsError::BadInput { .. })
    ));
}

/// Which program axes each built-in machine has (the interpreter's axis mask).
#[test]
fn program_axes_of_the_builtin_machines() {
    use tezgah_geom::Axis::*;
    let axes = |name: &str| Machine::builtin(name).unwrap().program_axes();
    assert_eq!(axes("mill3"), [X, Y, Z]);
    assert_eq!(axes("table-ac"), [X, Y, Z, A, C]);
    assert_eq!(axes("table-bc"), [X, Y, Z, B, C]);
    assert_eq!(axes("yzca"), [X, Y, Z, C, A]);
    assert_eq!(axes("linear-delta"), [X, Y, Z]);
}

//! Property tests on every model: forward(inverse(p)) = p, inverse(forward(q)) = q up to
//! branch and turns (outside a 1e-6 rad cone around the pole), the analytic Jacobian against
//! central finite differences, and a warm-started damped-least-squares inverse (the iterative
//! inverse of Kahraman et al., §4) converging to the closed form.

use nalgebra::{DMatrix, DVector, Vector3};
use proptest::prelude::*;
use tezgah_kinematics::{Joints, Kinematics, Machine, Tool, ToolPose};

const POLE_CONE: f64 = 1e-6;

fn machine(name: &str) -> Machine {
    Machine::builtin(name).unwrap()
}

fn cartesian5() -> Machine {
    let text = Machine::builtin_text("mill3").unwrap().to_owned()
        + "
[[joint]]
name = \"a\"
kind = \"rotary\"
min = -90.0
max = 90.0
max_velocity = 90.0
max_acceleration = 900.0
max_jerk = 9000.0

[[joint]]
name = \"c\"
kind = \"rotary\"
endless = true
max_velocity = 90.0
max_acceleration = 900.0
max_jerk = 9000.0
";
    Machine::from_toml_str(&text).unwrap()
}

fn file_q(m: &Machine, v: &[f64]) -> Joints {
    m.from_file_units(v).unwrap()
}

fn assert_pose_eq(a: &ToolPose, b: &ToolPose, tol: f64) -> Result<(), TestCaseError> {
    prop_assert!(
        (a.tip - b.tip).norm() < tol,
        "tip {:?} vs {:?}",
        a.tip,
        b.tip
    );
    prop_assert!(
        (a.axis.into_inner() - b.axis.into_inner()).norm() < tol,
        "axis {:?} vs {:?}",
        a.axis,
        b.axis
    );
    Ok(())
}

fn assert_joints_eq(a: &Joints, b: &Joints, tol: f64) -> Result<(), TestCaseError> {
    for (x, y) in a.as_slice().iter().zip(b.as_slice()) {
        prop_assert!((x - y).abs() < tol, "{:?} vs {:?}", a, b);
    }
    Ok(())
}

/// Forward, inverse from a nearby previous (same branch and turn expected), inverse from an
/// arbitrary previous (any branch, same pose expected).
fn round_trips(
    m: &Machine,
    q: &Joints,
    near: &Joints,
    far: &Joints,
    tool: &Tool,
) -> Result<(), TestCaseError> {
    let k = &m.kinematics;
    let p = k.forward(q, tool).unwrap();
    let q1 = k
        .inverse(&p, tool, near)
        .map_err(|e| TestCaseError::fail(format!("{e} at {q:?}")))?;
    assert_joints_eq(&q1, q, 1e-9)?;
    let q2 = k
        .inverse(&p, tool, far)
        .map_err(|e| TestCaseError::fail(format!("{e} at {q:?}")))?;
    assert_pose_eq(&k.forward(&q2, tool).unwrap(), &p, 1e-9)?;
    k.check_joints(&q2).unwrap();
    Ok(())
}

/// Analytic Jacobian columns against central differences of the forward map.
fn jacobian_matches(m: &Machine, q: &Joints, tool: &Tool) -> Result<(), TestCaseError> {
    let k = &m.kinematics;
    let j = k.jacobian(q, tool).unwrap();
    let h = 1e-6;
    for c in 0..q.len() {
        let (mut qp, mut qm) = (*q, *q);
        qp[c] += h;
        qm[c] -= h;
        let (pp, pm) = (k.forward(&qp, tool).unwrap(), k.forward(&qm, tool).unwrap());
        let dt = (pp.tip - pm.tip) / (2.0 * h);
        let da = (pp.axis.into_inner() - pm.axis.into_inner()) / (2.0 * h);
        for r in 0..3 {
            prop_assert!(
                (j[(r, c)] - dt[r]).abs() < 1e-5 * (1.0 + dt[r].abs()),
                "tip row {r} col {c}: {} vs {}",
                j[(r, c)],
                dt[r]
            );
            prop_assert!(
                (j[(r + 3, c)] - da[r]).abs() < 1e-6,
                "axis row {r} col {c}: {} vs {}",
                j[(r + 3, c)],
                da[r]
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn cartesian_round_trip(x in -200.0..200.0f64, y in -150.0..150.0f64, z in -90.0..90.0f64,
                            a in -90.0..90.0f64, c in -3600.0..3600.0f64, len in 0.0..10.0f64) {
        let m = cartesian5();
        let tool = Tool::with_length(len);
        let q = file_q(&m, &[x, y, z, a, c]);
        round_trips(&m, &q, &q, &m.home(), &tool)?;
        jacobian_matches(&m, &q, &tool)?;
        let m3 = machine("mill3");
        let q3 = file_q(&m3, &[x, y, z]);
        round_trips(&m3, &q3, &m3.home(), &m3.home(), &tool)?;
    }

    #[test]
    fn yzca_round_trip(y in -200.0..200.0f64, z in -150.0..150.0f64, c in -1000.0..1000.0f64,
                       a in -120.0..120.0f64, dc in -60.0..60.0f64, da in -10.0..10.0f64,
                       far_c in -1000.0..1000.0f64, far_a in -120.0..120.0f64, len in 0.0..100.0f64) {
        let m = machine("yzca");
        let tool = Tool::with_length(len);
        let q = file_q(&m, &[y, z, c, a]);
        // the degenerate set: tip on the C axis (r = y + l·sin A = 0) makes C free
        let r = y + len * a.to_radians().sin();
        prop_assume!(r.abs() > 1e-3);
        let near = file_q(&m, &[0.0, 0.0, c + dc, (a + da).clamp(-120.0, 120.0)]);
        let far = file_q(&m, &[0.0, 0.0, far_c, far_a]);
        round_trips(&m, &q, &near, &far, &tool)?;
        jacobian_matches(&m, &q, &tool)?;
    }

    #[test]
    fn table_ac_round_trip(x in -100.0..100.0f64, y in -100.0..100.0f64, z in -100.0..100.0f64,
                           a in -30.0..120.0f64, c in -1000.0..1000.0f64,
                           dc in -60.0..60.0f64, da in -10.0..10.0f64,
                           far_c in -1000.0..1000.0f64, far_a in -30.0..120.0f64, len in 0.0..100.0f64) {
        let m = machine("table-ac");
        prop_assume!(a.to_radians().sin().abs() > POLE_CONE);
        let tool = Tool::with_length(len);
        let q = file_q(&m, &[x, y, z, a, c]);
        let near = file_q(&m, &[0.0, 0.0, 0.0, (a + da).clamp(-30.0, 120.0), c + dc]);
        let far = file_q(&m, &[0.0, 0.0, 0.0, far_a, far_c]);
        round_trips(&m, &q, &near, &far, &tool)?;
        jacobian_matches(&m, &q, &tool)?;
    }

    #[test]
    fn table_bc_round_trip(x in -100.0..100.0f64, y in -100.0..100.0f64, z in -100.0..100.0f64,
                           b in -120.0..120.0f64, c in -1000.0..1000.0f64,
                           dc in -60.0..60.0f64, db in -10.0..10.0f64,
                           far_c in -1000.0..1000.0f64, far_b in -120.0..120.0f64, len in 0.0..100.0f64) {
        let m = machine("table-bc");
        prop_assume!(b.to_radians().sin().abs() > POLE_CONE);
        let tool = Tool::with_length(len);
        let q = file_q(&m, &[x, y, z, b, c]);
        let near = file_q(&m, &[0.0, 0.0, 0.0, (b + db).clamp(-120.0, 120.0), c + dc]);
        let far = file_q(&m, &[0.0, 0.0, 0.0, far_b, far_c]);
        round_trips(&m, &q, &near, &far, &tool)?;
        jacobian_matches(&m, &q, &tool)?;
    }

    /// Near the pole (inside the 1e-6 rad cone but outside the model's own 1e-9 rad cone
    /// too) the pose still round-trips; exactly at the pole C keeps its previous value.
    #[test]
    fn trunnion_pole_keeps_c(x in -100.0..100.0f64, z in -100.0..100.0f64, prev_c in -720.0..720.0f64,
                             tiny in -1e-10..1e-10f64) {
        for name in ["table-ac", "table-bc"] {
            let m = machine(name);
            let tool = Tool::default();
            let q = file_q(&m, &[x, 0.0, z, 0.0, 123.0]);
            let mut p = m.kinematics.forward(&q, &tool).unwrap();
            p.axis = nalgebra::Unit::new_normalize(Vector3::new(tiny, 0.0, 1.0));
            let prev = file_q(&m, &[0.0, 0.0, 0.0, 0.0, prev_c]);
            let got = m.kinematics.inverse(&p, &tool, &prev).unwrap();
            prop_assert!((got[4] - prev[4]).abs() < 1e-15, "C jumped: {:?}", got);
            let back = m.kinematics.forward(&got, &tool).unwrap();
            prop_assert!((back.tip - p.tip).norm() < 1e-9);
            prop_assert!((back.axis.into_inner() - p.axis.into_inner()).norm() < 1e-9);
        }
    }

    #[test]
    fn delta_round_trip(x in -150.0..150.0f64, y in -150.0..150.0f64, z in -100.0..100.0f64, len in 0.0..50.0f64) {
        let m = machine("linear-delta");
        let tool = Tool::with_length(len);
        let p = ToolPose::vertical(Vector3::new(x, y, z));
        match m.kinematics.inverse(&p, &tool, &m.home()) {
            Ok(q) => {
                let back = m.kinematics.forward(&q, &tool).unwrap();
                prop_assert!((back.tip - p.tip).norm() < 1e-9, "{:?} → {:?}", p.tip, back.tip);
                round_trips(&m, &q, &q, &m.home(), &tool)?;
                jacobian_matches(&m, &q, &tool)?;
            }
            // Out of the workspace: only a typed error, and only at the boundary.
            Err(e) => prop_assert!(
                matches!(e, tezgah_kinematics::KinematicsError::Unreachable { .. } | tezgah_kinematics::KinematicsError::JointLimit { .. }),
                "{e}"),
        }
    }

    /// After Kahraman et al. (§4), who invert by Jacobian iteration: a damped-least-squares inverse
    /// warm-started from the previous sample converges to the closed-form joints (checks Jacobian
    /// and closed form against each other).
    #[test]
    fn dls_warm_start_converges_004(x in -100.0..100.0f64, y in -100.0..100.0f64, z in -100.0..100.0f64,
                                    a in 10.0..110.0f64, c in -180.0..180.0f64,
                                    e in proptest::collection::vec(-0.02..0.02f64, 5)) {
        for name in ["table-ac", "table-bc"] {
            let m = machine(name);
            let k = &m.kinematics;
            let tool = Tool::with_length(50.0);
            let target_q = file_q(&m, &[x, y, z, a, c]);
            let target = k.forward(&target_q, &tool).unwrap();
            let mut q = target_q;
            for (i, d) in e.iter().enumerate() {
                q[i] += if i < 3 { d * 100.0 } else { *d };
            }
            for _ in 0..20 {
                let p = k.forward(&q, &tool).unwrap();
                let r = (target.tip - p.tip).iter().chain((target.axis.into_inner() - p.axis.into_inner()).iter())
                    .copied().collect::<Vec<_>>();
                let j = k.jacobian(&q, &tool).unwrap();
                let jd = DMatrix::from_column_slice(6, 5, j.as_slice());
                let lhs = jd.transpose() * &jd + DMatrix::identity(5, 5) * 1e-18;
                let dq = lhs.lu().solve(&(jd.transpose() * DVector::from_vec(r))).unwrap();
                for i in 0..5 { q[i] += dq[i]; }
            }
            assert_joints_eq(&q, &target_q, 1e-9)?;
        }
    }

    /// TCP: program (tip, angles) → joints → program is the identity, and the tool length
    /// enters the tip.
    #[test]
    fn tcp_round_trip(x in -80.0..80.0f64, y in -80.0..80.0f64, z in -80.0..80.0f64,
                      t1 in -30.0..120.0f64, t2 in -720.0..720.0f64, len in 0.0..100.0f64) {
        use tezgah_kinematics::tcp::{ProgramPose, Tcp};
        for name in ["table-ac", "table-bc", "yzca"] {
            let m = machine(name);
            let tcp = Tcp::new(&m.kinematics, Tool::with_length(len));
            let angles = if name == "yzca" {
                Joints::new([t2.to_radians(), t1.clamp(-120.0, 120.0).to_radians()])
            } else {
                Joints::new([t1.to_radians(), t2.to_radians()])
            };
            let prog = ProgramPose { tip: Vector3::new(x, y, z), angles };
            if name == "yzca" {
                // a 4-axis machine reaches only tips in the radial plane: use the one the
                // joints land on, then round-trip from there
                prop_assume!(x.hypot(y) > 1e-3);
            }
            let q = tcp.joints(&prog, &m.home()).unwrap();
            let back = tcp.program(&q).unwrap();
            prop_assert!((back.tip - prog.tip).norm() < 1e-9, "{name}: {:?} vs {:?}", back.tip, prog.tip);
            if name != "yzca" {
                assert_joints_eq(&back.angles, &prog.angles, 1e-12)?;
            } else {
                prop_assert!((back.angles[1] - prog.angles[1]).abs() < 1e-12);
            }
            // A longer tool moves the gauge point back along the axis by the difference.
            let longer = Tcp::new(&m.kinematics, Tool::with_length(len + 10.0));
            let q2 = longer.joints(&prog, &m.home()).unwrap();
            let axis = m.kinematics.forward(&q, &Tool::with_length(len)).unwrap().axis;
            let g1 = m.kinematics.forward(&q, &Tool::default()).unwrap().tip;
            let g2 = m.kinematics.forward(&q2, &Tool::default()).unwrap().tip;
            prop_assert!(((g2 - g1) - axis.into_inner() * 10.0).norm() < 1e-9);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]

    /// The trunnion inverse returns the solution nearest the previous joints (|Δtilt| + |ΔC|)
    /// among the two branches (tilt, C) and (−tilt, C + π), whichever path it takes inside
    /// (the quick one when branch 1 is plainly nearer, the full comparison otherwise).
    #[test]
    fn trunnion_inverse_takes_the_nearest_branch(
        bc in any::<bool>(),
        prev_tilt in -30.0f64..120.0, prev_c in -720.0f64..720.0,
        tilt in -29.0f64..119.0, c in -720.0f64..720.0,
        x in -50.0f64..50.0, y in -50.0f64..50.0, z in -20.0f64..20.0,
    ) {
        let name = if bc { "table-bc" } else { "table-ac" };
        let m = machine(name);
        let tool = Tool::with_length(25.0);
        let target = file_q(&m, &[x, y, z, tilt, c]);
        let pose = m.kinematics.forward(&target, &tool).unwrap();
        prop_assume!(pose.axis.z < 1.0 - 1e-9); // off the pole
        let previous = file_q(&m, &[0.0, 0.0, 0.0, prev_tilt, prev_c]);
        let Ok(q) = m.kinematics.inverse(&pose, &tool, &previous) else {
            return Ok(());
        };
        assert_pose_eq(&m.kinematics.forward(&q, &tool).unwrap(), &pose, 1e-9)?;
        let cost = |t: f64, c: f64| (t - previous[3]).abs() + (c - previous[4]).abs();
        // The other branch, at C's nearest turn (C is endless), if its tilt is in limits.
        let (t2, c2) = (-q[3], q[4] + std::f64::consts::PI);
        let c2 = previous[4] + (c2 - previous[4] + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let lt = &m.kinematics.joint_limits()[3];
        if t2 >= lt.min && t2 <= lt.max {
            let other = file_q(&m, &[0.0, 0.0, 0.0, t2.to_degrees(), c2.to_degrees()]);
            let alt = Joints::from_slice(&[0.0, 0.0, 0.0, other[3], other[4]]).unwrap();
            // Only a candidate if its linear joints are in limits too.
            let in_limits = m.kinematics.inverse(&pose, &tool, &alt).is_ok_and(|a| {
                (a[3] - t2).abs() < 1e-12 && (a[4] - c2).abs() < 1e-9
            });
            if in_limits {
                prop_assert!(
                    cost(q[3], q[4]) <= cost(t2, c2) + 1e-12,
                    "{name}: chose ({}, {}), cost {} > ({t2}, {c2}) cost {}",
                    q[3], q[4], cost(q[3], q[4]), cost(t2, c2)
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, .. ProptestConfig::default() })]

    /// The same for Y-Z-C-A: (C, A) nearest the previous ones among (C, A) and (C + π, −A).
    #[test]
    fn yzca_inverse_takes_the_nearest_branch(
        prev_a in -110.0f64..110.0, prev_c in -720.0f64..720.0,
        y in 5.0f64..150.0, z in -100.0f64..100.0, c in -720.0f64..720.0, a in -110.0f64..110.0,
    ) {
        let m = machine("yzca");
        let tool = Tool::with_length(25.0);
        let pose = m.kinematics.forward(&file_q(&m, &[y, z, c, a]), &tool).unwrap();
        let previous = file_q(&m, &[0.0, 0.0, prev_c, prev_a]);
        let Ok(q) = m.kinematics.inverse(&pose, &tool, &previous) else {
            return Ok(());
        };
        assert_pose_eq(&m.kinematics.forward(&q, &tool).unwrap(), &pose, 1e-9)?;
        let cost = |c: f64, a: f64| (c - previous[2]).abs() + (a - previous[3]).abs();
        let (c2, a2) = (q[2] + std::f64::consts::PI, -q[3]);
        let c2 = previous[2] + (c2 - previous[2] + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let alt = Joints::from_slice(&[-q[0], q[1], c2, a2]).unwrap();
        if m.kinematics.check_joints(&alt).is_ok() {
            prop_assert!(
                cost(q[2], q[3]) <= cost(c2, a2) + 1e-12,
                "chose ({}, {}) cost {} > ({c2}, {a2}) cost {}",
                q[2], q[3], cost(q[2], q[3]), cost(c2, a2)
            );
        }
    }
}

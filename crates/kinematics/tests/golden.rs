//! Golden values from the literature: Kelekçi (2021, §5.3.1, eqs 5.2–5.7: Y-Z-C-A round trip and
//! C unwrap), Ayyıldız (2017: delta inverse kinematics eq. 3.5, the conversions printed in
//! Figs 5.3–5.15, arc chords eqs 4.1–4.3, joint-space sag, ISO 9283 eqs 3.16–3.19), Kahraman
//! et al. (eqs 1–3: Rodrigues). Values not printed in a work are computed from its equations.

use nalgebra::{Unit, Vector3};
use tezgah_kinematics::segment::{joint_line_deviation, slerp_axis};
use tezgah_kinematics::{Kinematics, Machine, Tool, ToolPose};

fn delta() -> Machine {
    Machine::builtin("linear-delta").unwrap()
}

fn ik(m: &Machine, x: f64, y: f64, z: f64) -> Vec<f64> {
    let q = m
        .kinematics
        .inverse(
            &ToolPose::vertical(Vector3::new(x, y, z)),
            &Tool::default(),
            &m.home(),
        )
        .unwrap();
    m.to_file_units(&q)
}

// ---- Kelekçi (2021), eqs 5.2/5.7: Y-Z-C-A round trip, and the C sign -------------------

#[test]
fn yzca_round_trip_eq_5_2() {
    let m = Machine::builtin("yzca").unwrap();
    let tool = Tool::with_length(100.0);
    // joints y z c a in file units (mm, deg)
    let q = m.from_file_units(&[50.0, 10.0, 45.0, 30.0]).unwrap();
    let p = m.kinematics.forward(&q, &tool).unwrap();
    assert!((p.tip.x - 70.7107).abs() < 5e-5, "{}", p.tip.x);
    assert!((p.tip.y + 70.7107).abs() < 5e-5, "{}", p.tip.y);
    assert!((p.tip.z + 76.6025).abs() < 5e-5, "{}", p.tip.z);
    let back = m.kinematics.inverse(&p, &tool, &m.home()).unwrap();
    let f = m.to_file_units(&back);
    assert!(
        (f[0] - 50.0).abs() < 1e-9 && (f[1] - 10.0).abs() < 1e-9,
        "{f:?}"
    );
    // C = −atan2(y_w, x_w) = +45°, not the printed eq. 5.4's 315° ≙ −45°.
    assert!(
        (f[2] - 45.0).abs() < 1e-9 && (f[3] - 30.0).abs() < 1e-9,
        "{f:?}"
    );
}

/// C sign convention: C = +90° carries the part point under a tool at radius r from the
/// part's +X axis to its −Y axis (the table turns counter-clockwise seen from +Z).
#[test]
fn yzca_c_sign_convention() {
    let m = Machine::builtin("yzca").unwrap();
    let q = m.from_file_units(&[100.0, 0.0, 90.0, 0.0]).unwrap();
    let p = m.kinematics.forward(&q, &Tool::default()).unwrap();
    assert!(
        p.tip.x.abs() < 1e-12 && (p.tip.y + 100.0).abs() < 1e-12,
        "{:?}",
        p.tip
    );
    // The part point on +Y needs C = −90° (or 270° by continuity).
    let q = m
        .kinematics
        .inverse(
            &ToolPose::vertical(Vector3::new(0.0, 100.0, 0.0)),
            &Tool::default(),
            &m.home(),
        )
        .unwrap();
    let f = m.to_file_units(&q);
    assert!(
        (f[2] + 90.0).abs() < 1e-9 && (f[0] - 100.0).abs() < 1e-9,
        "{f:?}"
    );
}

/// Kelekçi (2021, §5.3.1): C runs 0 … 355° and the next target at 5° is commanded 365°.
#[test]
fn yzca_endless_c_unwrap_eq_5_5() {
    let m = Machine::builtin("yzca").unwrap();
    let tool = Tool::default();
    let mut q = m.home();
    let mut last = 0.0;
    for k in 0..=73 {
        let c = (5.0 * k as f64) % 360.0; // 0, 5, …, 355, 0, 5
        let (s, co) = c.to_radians().sin_cos();
        // the part point under the tool at C is at polar angle −C
        let p = ToolPose::vertical(Vector3::new(80.0 * co, -80.0 * s, -5.0));
        q = m.kinematics.inverse(&p, &tool, &q).unwrap();
        last = m.to_file_units(&q)[2];
        assert!((last - 5.0 * k as f64).abs() < 1e-9, "step {k}: C = {last}");
    }
    assert!((last - 365.0).abs() < 1e-9);
}

#[test]
fn yzca_tilt_chosen_by_programmed_a() {
    use tezgah_kinematics::yzca::{choose_tilt, normal_tilts};
    // Path going +Z only: the tool must lie along ±Y, i.e. A = ±90°.
    let c = normal_tilts(0.0, 1.0).unwrap();
    let a = choose_tilt(&c, 80f64.to_radians());
    assert!((a.to_degrees() - 90.0).abs() < 1e-12);
    let a = choose_tilt(&c, (-60f64).to_radians());
    assert!((a.to_degrees() + 90.0).abs() < 1e-12);
    // A diagonal path (1, 1): normals at 45° and −135°; the programmed A picks one.
    let c = normal_tilts(1.0, 1.0).unwrap();
    assert!((choose_tilt(&c, 0.0).to_degrees() - 45.0).abs() < 1e-12);
    assert!((choose_tilt(&c, (-170f64).to_radians()).to_degrees() + 135.0).abs() < 1e-12);
    // The chosen tilt really is normal to the path: axis (−sin A, cos A)·(dy, dz) = 0.
    for (dy, dz) in [(1.0, 2.0), (-1.0, 1.0), (-1.0, -3.0), (2.0, -1.0)] {
        for a in normal_tilts(dy, dz).unwrap() {
            assert!((-a.sin() * dy + a.cos() * dz).abs() < 1e-12);
        }
    }
    assert!(normal_tilts(0.0, 0.0).is_none());
}

// ---- Ayyıldız (2017), eq. 3.5: inverse kinematics, absolute and relative ---------------

#[test]
fn delta_inverse_eq_3_5() {
    let m = delta();
    let rows: [([f64; 3], [f64; 3]); 9] = [
        ([0.0, 0.0, 0.0], [311.28765, 311.28765, 311.28765]),
        ([10.0, 0.0, 0.0], [316.22777, 308.54497, 308.54497]),
        ([0.0, 10.0, 0.0], [311.12698, 315.54917, 306.64103]),
        ([10.0, 20.0, -5.0], [310.59468, 311.76894, 293.75983]),
        ([50.0, -30.0, 20.0], [350.90784, 297.82397, 326.29046]),
        ([-100.0, 0.0, 0.0], [234.30749, 320.78030, 320.78030]),
        ([-100.0, 100.0, 100.0], [311.89620, 447.29355, 355.31782]),
        ([0.0, 100.0, 100.0], [394.78806, 438.54514, 343.28417]),
        ([-50.0, 50.0, 50.0], [325.49955, 387.27794, 343.33188]),
    ];
    for (p, q_abs) in rows {
        let q = ik(&m, p[0], p[1], p[2]);
        for i in 0..3 {
            // joints are relative to the thesis's home constant 311.28765
            assert!(
                (q[i] + 311.28765 - q_abs[i]).abs() < 6e-6,
                "{p:?}: {q:?} vs {q_abs:?}"
            );
        }
        // the corrected forward kinematics returns the point to 1e-9 mm
        let back = m
            .kinematics
            .forward(&m.from_file_units(&q).unwrap(), &Tool::default())
            .unwrap();
        assert!(
            (back.tip - Vector3::from(p)).norm() < 1e-9,
            "{p:?} → {:?}",
            back.tip
        );
    }
}

// ---- Ayyıldız (2017), Figs 5.3–5.15: the thesis's printed conversions ------------------

#[test]
fn delta_printed_conversions() {
    let m = delta();
    let printed: [([f64; 3], [f64; 3]); 16] = [
        ([-27.426, -27.714, 0.0], [-17.0, -7.83, 16.51]),
        ([-27.426, -27.714, 10.0], [-7.0, 2.17, 26.51]),
        ([-27.426, -27.714, -0.5], [-17.5, -8.33, 16.01]),
        ([-17.426, -27.714, -0.5], [-11.37, -10.23, 14.24]),
        ([-17.426, -27.714, 10.0], [-0.87, 0.27, 24.74]),
        ([-27.426, -27.714, -2.0], [-19.0, -9.83, 14.51]),
        ([-29.149, -35.382, 10.0], [-8.93, -1.86, 29.27]),
        ([-29.149, -25.382, -0.5], [-18.4, -6.77, 15.48]),
        ([-29.149, -35.382, -2.0], [-20.93, -13.86, 17.27]),
        ([-31.654, -28.911, 0.0], [-19.86, -7.78, 17.56]),
        ([-31.654, -28.911, -0.2], [-20.06, -7.98, 17.36]),
        ([39.057, 41.8, -0.2], [14.28, 3.09, -36.18]),
        ([39.057, 41.8, 10.0], [24.48, 13.29, -25.98]),
        ([19.515, 4.704, 0.0], [9.25, -3.59, -7.86]),
        ([19.515, 4.704, 10.0], [19.25, 6.41, 2.14]),
        ([19.515, 4.704, -0.2], [9.05, -3.79, -8.06]),
    ];
    for (p, want) in printed {
        let q = ik(&m, p[0], p[1], p[2]);
        for i in 0..3 {
            // printed to 2 decimals (half-even): the exact value is within half a unit
            assert!(
                (q[i] - want[i]).abs() <= 0.005 + 1e-9,
                "{p:?}: {q:?} vs {want:?}"
            );
        }
    }
    // Unrounded values, computed from eq. 3.5 to 4 decimals.
    let unrounded: [([f64; 3], [f64; 3]); 7] = [
        ([-27.426, -27.714, 0.0], [-17.0030, -7.8283, 16.5053]),
        ([-17.426, -27.714, -0.5], [-11.3680, -10.2315, 14.2442]),
        ([-29.149, -35.382, 10.0], [-8.9338, -1.8600, 29.2689]),
        ([-29.149, -25.382, -0.5], [-18.3964, -6.7698, 15.4798]),
        ([-31.654, -28.911, 0.0], [-19.8552, -7.7835, 17.5571]),
        ([39.057, 41.8, -0.2], [14.2815, 3.0948, -36.1801]),
        ([19.515, 4.704, 0.0], [9.2460, -3.5893, -7.8556]),
    ];
    for (p, want) in unrounded {
        let q = ik(&m, p[0], p[1], p[2]);
        for i in 0..3 {
            assert!(
                (q[i] - want[i]).abs() <= 5e-5 + 1e-6,
                "{p:?}: {q:?} vs {want:?}"
            );
        }
    }
}

/// Ayyıldız (2017), Fig. 5.15: the 16 chord points of `G3 X7.015 Y17.204 I-12.5 J0.` at Z −0.2.
#[test]
fn delta_arc_chords_fig_5_15() {
    let m = delta();
    let printed: [[f64; 3]; 17] = [
        [9.0, -3.27, -8.59],
        [8.91, -2.73, -9.08],
        [8.77, -2.17, -9.54],
        [8.58, -1.59, -9.95],
        [8.34, -1.01, -10.32],
        [8.05, -0.42, -10.64],
        [7.73, 0.18, -10.9],
        [7.36, 0.76, -11.11],
        [6.96, 1.34, -11.26],
        [6.52, 1.9, -11.36],
        [6.05, 2.44, -11.39],
        [5.56, 2.96, -11.37],
        [5.04, 3.45, -11.29],
        [4.5, 3.91, -11.14],
        [3.96, 4.33, -10.94],
        [3.4, 4.72, -10.69],
        [2.84, 5.06, -10.38], // the end point the thesis does not emit
    ];
    for (k, want) in printed.iter().enumerate() {
        let t = ((k + 1) as f64 * 90.0 / 17.0).to_radians();
        let q = ik(&m, 7.015 + 12.5 * t.cos(), 4.704 + 12.5 * t.sin(), -0.2);
        for i in 0..3 {
            assert!(
                (q[i] - want[i]).abs() <= 0.005 + 1e-9,
                "k={k}: {q:?} vs {want:?}"
            );
        }
    }
}

/// Ayyıldız (2017) converts end points only: interpolating the joints between the converted end
/// points of the 100 mm XY diagonal sags 4.646 mm (Z −4.577, in plane 0.799), against the −4.599 mm
/// measured in its Table 5.2.
#[test]
fn delta_joint_space_sag_table_5_2() {
    let m = delta();
    let tool = Tool::default();
    let a = Vector3::new(-31.654, -28.911, -0.2);
    let b = Vector3::new(39.057, 41.8, -0.2);
    let qa = m
        .kinematics
        .inverse(&ToolPose::vertical(a), &tool, &m.home())
        .unwrap();
    let qb = m
        .kinematics
        .inverse(&ToolPose::vertical(b), &tool, &m.home())
        .unwrap();
    let dq = m
        .to_file_units(&qb)
        .iter()
        .zip(m.to_file_units(&qa))
        .map(|(x, y)| x - y)
        .collect::<Vec<_>>();
    for (d, want) in dq.iter().zip([34.3367, 11.0783, -53.5372]) {
        assert!((d - want).abs() < 1e-4, "{dq:?}");
    }
    let (dev, t, off) = joint_line_deviation(&m.kinematics, &tool, &qa, &qb, &a, &b, 999).unwrap();
    assert!((dev - 4.646).abs() < 5e-4, "deviation {dev}");
    assert!((t - 0.49).abs() < 0.01, "at t = {t}");
    assert!((off.z + 4.577).abs() < 5e-4, "z {}", off.z);
    assert!(
        (off.xy().norm() - 0.799).abs() < 5e-4,
        "in-plane {}",
        off.xy().norm()
    );

    // Subdividing in Cartesian space: 10 mm → 0.0463, 5 mm → 0.0116, 1 mm → 0.00046 mm.
    for (pieces, want, tol) in [
        (10usize, 0.0463, 1e-4),
        (20, 0.0116, 1e-4),
        (100, 0.00046, 1e-5),
    ] {
        let mut worst: f64 = 0.0;
        let mut q0 = qa;
        for k in 1..=pieces {
            let s1 = k as f64 / pieces as f64;
            let s0 = (k - 1) as f64 / pieces as f64;
            let p1 = a + (b - a) * s1;
            let q1 = m
                .kinematics
                .inverse(&ToolPose::vertical(p1), &tool, &q0)
                .unwrap();
            let (d, _, _) =
                joint_line_deviation(&m.kinematics, &tool, &q0, &q1, &(a + (b - a) * s0), &p1, 99)
                    .unwrap();
            worst = worst.max(d);
            q0 = q1;
        }
        assert!((worst - want).abs() < tol, "{pieces} pieces: {worst}");
    }
}

// ---- Kahraman et al., eqs 1–3: Rodrigues tool-axis interpolation -----------------------

#[test]
fn rodrigues_eqs_1_to_3() {
    let v = Vector3::z_axis();
    let u = Unit::new_normalize(Vector3::new(0.5, 0.0, 3f64.sqrt() / 2.0));
    let mid = slerp_axis(&v, &u, 0.5).unwrap();
    assert!((mid.into_inner() - Vector3::new(0.258819, 0.0, 0.965926)).norm() < 1e-6);
    let end = slerp_axis(&v, &u, 1.0).unwrap();
    assert!((end.into_inner() - u.into_inner()).norm() < 1e-15);
    // The unnormalised k of the printed eq. 1 would land on (0.25, 0, 0.866025): not U.
    let k = v.cross(&u);
    let th = 30f64.to_radians();
    let wrong =
        v.into_inner() * th.cos() + k.cross(&v) * th.sin() + k * k.dot(&v) * (1.0 - th.cos());
    assert!((wrong - Vector3::new(0.25, 0.0, 0.866025)).norm() < 1e-6);
    // Opposite axes have no rotation plane.
    assert!(slerp_axis(&v, &-v, 0.5).is_err());
}

// ---- ISO 9283 (Ayyıldız, 2017, eqs 3.16–3.19), synthetic measurements -----------------

#[test]
fn iso9283_eqs_3_16_to_3_19() {
    use tezgah_kinematics::iso9283::{evaluate, parse_csv};
    let csv = "\
pose,cycle,cmd_x,cmd_y,cmd_z,x,y,z
A,1,0,0,0,1,0,0
A,2,0,0,0,-1,0,0
A,3,0,0,0,0,1,0
A,4,0,0,0,0,-1,0
B,1,0,0,0,1,0,0
B,2,0,0,0,3,0,0
C,1,10,20,30,10,20,30
C,2,10,20,30,10,20,30
C,3,10,20,30,13,20,30
D,1,-50,50,50,-49,50.5,50
D,2,-50,50,50,-49.2,50.1,49.6
D,3,-50,50,50,-48.8,50.3,50.2
D,4,-50,50,50,-49.0,49.9,50.1
";
    let r = evaluate(&parse_csv(csv).unwrap()).unwrap();
    let want = [
        (0.0, 1.0, 0.0, 1.0),
        (2.0, 1.0, 0.0, 1.0),
        (1.0, 1.333333, 0.577350, 3.065384),
        (1.020110, 0.344965, 0.061904, 0.530676),
    ];
    for (p, (ap, l, s, rp)) in r.poses.iter().zip(want) {
        assert!((p.ap - ap).abs() < 1e-6, "{}: AP {}", p.pose, p.ap);
        assert!((p.l_mean - l).abs() < 1e-6, "{}: l {}", p.pose, p.l_mean);
        assert!((p.s_l - s).abs() < 1e-6, "{}: S {}", p.pose, p.s_l);
        assert!((p.rp - rp).abs() < 1e-6, "{}: RP {}", p.pose, p.rp);
    }
    assert!((r.poses[3].mean - Vector3::new(-49.0, 50.2, 49.975)).norm() < 1e-12);
    assert!((r.mean_ap - (0.0 + 2.0 + 1.0 + 1.020110) / 4.0).abs() < 1e-6);
}

#[test]
fn iso9283_errors() {
    use tezgah_kinematics::iso9283::{evaluate, parse_csv, Iso9283Error};
    assert_eq!(
        parse_csv("pose,cmd_x,cmd_y,x,y,z\n"),
        Err(Iso9283Error::MissingColumn("cmd_z"))
    );
    assert!(matches!(
        parse_csv("pose,cmd_x,cmd_y,cmd_z,x,y,z\nP1,0,0,0,1,zz,0\n"),
        Err(Iso9283Error::BadRow { line: 2, .. })
    ));
    let one = parse_csv("pose,cmd_x,cmd_y,cmd_z,x,y,z\nP1,0,0,0,1,0,0\n").unwrap();
    assert_eq!(evaluate(&one), Err(Iso9283Error::TooFew("P1".into())));
    let differ =
        parse_csv("pose,cmd_x,cmd_y,cmd_z,x,y,z\nP1,0,0,0,1,0,0\nP1,0,0,1,1,0,0\n").unwrap();
    assert_eq!(
        evaluate(&differ),
        Err(Iso9283Error::CommandedDiffers("P1".into()))
    );
    assert_eq!(evaluate(&[]), Err(Iso9283Error::Empty));
}

/// Workspace of Ayyıldız's delta (2017, §3), counted on a grid: a 500 mm stroke with the 5°
/// rod-angle rule gives ≈ 46 900 cm³; adding a 22° spherical-joint cone about the central rod
/// direction ≈ 16 600 cm³. (The thesis's own 18 786 cm³ has no stated method.) Such a cone excludes
/// the thesis's ISO pose P3, which is why the built-in file leaves it off.
#[test]
fn delta_workspace_volume() {
    let m = delta();
    let tezgah_kinematics::Model::LinearDelta(d) = &m.kinematics else {
        unreachable!()
    };
    let v = d.workspace_volume(7.0, 50_000_000).unwrap() / 1000.0;
    assert!((v - 46_900.0).abs() < 0.01 * 46_900.0, "{v} cm³");
    let text = Machine::builtin_text("linear-delta")
        .unwrap()
        .replace("# max_joint_angle_deg = 22.0", "max_joint_angle_deg = 22.0");
    let coned = Machine::from_toml_str(&text).unwrap();
    let tezgah_kinematics::Model::LinearDelta(dc) = &coned.kinematics else {
        unreachable!()
    };
    let v = dc.workspace_volume(7.0, 50_000_000).unwrap() / 1000.0;
    assert!((v - 16_600.0).abs() < 0.01 * 16_600.0, "{v} cm³");
    let p3 = ToolPose::vertical(Vector3::new(-100.0, 100.0, 100.0));
    let e = coned
        .kinematics
        .inverse(&p3, &Tool::default(), &coned.home())
        .unwrap_err();
    assert!(e.to_string().contains("28.59"), "{e}");
    assert!(m
        .kinematics
        .inverse(&p3, &Tool::default(), &m.home())
        .is_ok());
    assert!(d.workspace_volume(0.001, 1_000_000).is_err());
}

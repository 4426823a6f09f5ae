//! The verifying dexel simulation against closed forms: the scallop of a ball cutter on a
//! plane and on a convex cylinder, and a deliberate gouge found with its depth.

mod common;

use tezgah_cam::verify::{path_poses, simulate, step_over, VerifyOptions};

/// Simulates the path with a cell of a twentieth of its step-over and a sweep spacing of
/// 0.1 mm.
fn run(
    surface: &tezgah_geom::NurbsSurface,
    path: &tezgah_cam::ToolPath,
) -> tezgah_cam::verify::Verification {
    let s = step_over(path).unwrap();
    let options = VerifyOptions {
        cell_mm: s / 20.0,
        sweep_spacing_mm: 0.1,
        region: tezgah_cam::verify::MachinedRegion::ContactBox,
    };
    let poses = path_poses(path, options.sweep_spacing_mm);
    let v = simulate(surface, path, &poses, &options).unwrap();
    assert!(
        v.cell_mm <= s / 20.0 + 1e-12,
        "cell {} for step-over {s}",
        v.cell_mm
    );
    v
}

/// The measured value lies where the error bounds say the true one can put it.
fn within_bounds(measured: f64, truth: f64, v: &tezgah_cam::verify::Verification) {
    eprintln!(
        "measured {measured:.6} closed form {truth:.6} (bounds −{:.6} +{:.6}; {} dexels, {} poses)",
        v.grid_bound_mm, v.sweep_bound_mm, v.dexels, v.poses
    );
    assert!(
        measured <= truth + v.sweep_bound_mm + 1e-9 && measured >= truth - v.grid_bound_mm - 1e-9,
        "measured {measured}, closed form {truth}, bounds −{} +{}",
        v.grid_bound_mm,
        v.sweep_bound_mm
    );
}

#[test]
fn ball_on_a_plane_leaves_the_closed_form_scallop() {
    // 11 passes 1 mm apart on a 10 × 8 mm plane, ball R = 3: h = R − √(R² − (s/2)²).
    let surface = common::plane(10.0, 8.0);
    let path = common::zigzag(&surface, 3.0, 11, 16, 0.0);
    let v = run(&surface, &path);
    let (r, s) = (3.0_f64, 1.0_f64);
    let h = r - (r * r - (s / 2.0).powi(2)).sqrt();
    assert!((step_over(&path).unwrap() - s).abs() < 1e-12);
    within_bounds(v.max_scallop_mm, h, &v);
    assert_eq!(v.uncut, 0);
    assert!(v.gouge_depth_mm < 1e-9, "no gouge: {}", v.gouge_depth_mm);
    // The bounds are small against the scallop itself.
    assert!(
        v.grid_bound_mm < 0.2 * h && v.sweep_bound_mm < 0.02 * h,
        "{v:?}"
    );
}

#[test]
fn ball_with_a_lead_angle_scallops_the_same() {
    // A ball's surface does not care about its axis: 15° of lead changes nothing.
    let surface = common::plane(10.0, 8.0);
    let path = common::zigzag(&surface, 3.0, 6, 16, 15f64.to_radians());
    let v = run(&surface, &path);
    let s = 2.0;
    let h = 3.0 - (9.0_f64 - (s / 2.0_f64).powi(2)).sqrt();
    within_bounds(v.max_scallop_mm, h, &v);
    assert!(v.gouge_depth_mm < 1e-9);
}

#[test]
fn ball_on_a_convex_cylinder() {
    // ρ = 20 about Y, ±15°, passes along the axis 6 evenly spaced in u. The rational arc's u is
    // not proportional to the angle, so the angular spacing is measured from the contacts.
    let (rho, r) = (20.0_f64, 2.0_f64);
    let surface = common::cylinder(rho, 15f64.to_radians(), 6.0);
    let path = common::zigzag(&surface, r, 7, 12, 0.0);
    let v = run(&surface, &path);
    // The largest angular gap between neighbouring passes gives the largest scallop:
    // ball centres at ρ + R, ±Δθ/2 from the ridge: (ρ+h)² + (ρ+R)² − 2(ρ+h)(ρ+R)cos(Δθ/2) = R²,
    // the smaller root.
    let angle = |p: &tezgah_cam::Pass| p.points[0].contact.x.atan2(p.points[0].contact.z);
    let gap = path
        .passes
        .windows(2)
        .map(|w| (angle(&w[1]) - angle(&w[0])).abs())
        .fold(0.0, f64::max);
    let (c, s) = ((gap / 2.0).cos(), (gap / 2.0).sin());
    let h = (rho + r) * c - (r * r - (rho + r).powi(2) * s * s).sqrt() - rho;
    assert!(h > 0.01, "{h}");
    within_bounds(v.max_scallop_mm, h, &v);
    assert!(v.gouge_depth_mm < 1e-9);
}

#[test]
fn a_deliberate_gouge_is_found_with_its_depth() {
    let surface = common::plane(10.0, 8.0);
    let mut path = common::zigzag(&surface, 3.0, 11, 16, 0.0);
    let depth = 0.05;
    path.passes[5].points[8].tip.z -= depth;
    let v = run(&surface, &path);
    within_bounds(v.gouge_depth_mm, depth, &v);
    let (uv, at) = v.gouge_at.unwrap();
    assert!(
        (uv.0 - 0.5).abs() < 0.02 && (uv.1 - 0.5).abs() < 0.02,
        "{uv:?} {at}"
    );
    // The rest of the surface still shows the ordinary scallop.
    let h = 3.0 - (9.0_f64 - 0.25).sqrt();
    within_bounds(v.max_scallop_mm, h, &v);
}

#[test]
fn bad_options_are_errors() {
    let surface = common::plane(10.0, 8.0);
    let path = common::zigzag(&surface, 3.0, 3, 4, 0.0);
    for (cell, spacing) in [(0.0, 0.1), (f64::NAN, 0.1), (0.1, -1.0), (1e-6, 0.1)] {
        let options = VerifyOptions {
            cell_mm: cell,
            sweep_spacing_mm: spacing,
            region: tezgah_cam::verify::MachinedRegion::ContactBox,
        };
        assert!(
            simulate(&surface, &path, &[], &options).is_err(),
            "{cell} {spacing}"
        );
    }
}

mod no_panic {
    use proptest::prelude::*;
    use tezgah_cam::verify::{simulate, CutterPose, VerifyOptions};

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Any poses (NaN and wild ones included) and cell: a measurement or an error.
        #[test]
        fn any_poses_simulate_or_fail_cleanly(
            poses in proptest::collection::vec(
                (proptest::array::uniform3(prop_oneof![Just(f64::NAN), -20.0f64..20.0]),
                 proptest::array::uniform3(-1.0f64..1.0)),
                0..40),
            cell in prop_oneof![Just(0.0), 0.05f64..2.0],
        ) {
            let surface = super::common::plane(10.0, 8.0);
            let path = super::common::zigzag(&surface, 3.0, 3, 4, 0.0);
            let poses: Vec<CutterPose> = poses
                .into_iter()
                .map(|(t, a)| CutterPose { tip: t.into(), axis: nalgebra::Vector3::from(a).normalize() })
                .collect();
            let options = VerifyOptions { cell_mm: cell, sweep_spacing_mm: 0.1 ,    region: tezgah_cam::verify::MachinedRegion::ContactBox,};
            if let Ok(v) = simulate(&surface, &path, &poses, &options) {
                prop_assert!(v.max_scallop_mm >= 0.0 && v.gouge_depth_mm >= 0.0);
            }
        }
    }
}

//! Trimmed faces: the STEP plate with a circular and an elliptic hole (OpenCascade fixture)
//! mapped into its parameter plane, and finished within its bounds — passes end on the trim,
//! the trim curves are cut, no contact point falls in a hole, and the dexel simulation over
//! the face (holes left out) finds no scallop above h and no gouge.

use std::f64::consts::PI;
use std::path::PathBuf;

use tezgah_cam::step::{self, Face};
use tezgah_cam::verify::{path_poses, simulate_on, MachinedRegion, VerifyOptions};
use tezgah_cam::{plan, Cutter, CutterShape, Settings, StrategyKind};

fn plate() -> Face {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/plate_with_holes.stp");
    step::read_file(path).unwrap().faces.remove(0)
}

/// The plate is the plane z = 5 over 80 × 60 mm, its (u, v) the x, y of the points.
const CIRCLE: ((f64, f64), f64) = ((25.0, 30.0), 10.0);
/// The ellipse's centre, semi-axes and the angle of its major axis.
const ELLIPSE: ((f64, f64), (f64, f64), f64) = ((58.0, 30.0), (12.0, 6.0), 0.5);

/// The ellipse's implicit value at (x, y): < 1 inside.
fn in_ellipse(x: f64, y: f64) -> f64 {
    let ((cx, cy), (a, b), t) = ELLIPSE;
    let (dx, dy) = (x - cx, y - cy);
    let (p, q) = (dx * t.cos() + dy * t.sin(), -dx * t.sin() + dy * t.cos());
    (p / a).powi(2) + (q / b).powi(2)
}

#[test]
fn the_plates_region_has_the_closed_form_area_and_membership() {
    let face = plate();
    let tolerance = 1e-3;
    let region = face
        .uv_region(tolerance)
        .unwrap()
        .expect("the plate is trimmed");
    // The holes are polygons inscribed within `tolerance` of their curves: the area lies
    // between the exact one and the exact one plus perimeter × tolerance.
    let exact = 80.0 * 60.0 - PI * 100.0 - PI * 72.0;
    let perimeter = 2.0 * PI * 10.0 + 58.1;
    let excess = region.area() - exact;
    assert!(
        excess >= -1e-9 && excess <= perimeter * tolerance,
        "{excess}"
    );
    let mut checked = 0;
    for i in 0..200 {
        for j in 0..150 {
            let (x, y) = (
                -1.0 + 82.0 * (i as f64 + 0.5) / 200.0,
                -1.0 + 62.0 * (j as f64 + 0.5) / 150.0,
            );
            let r = (x - CIRCLE.0 .0).hypot(y - CIRCLE.0 .1);
            let e = in_ellipse(x, y);
            // Away from the curves by more than the polygon's sagitta.
            if (r - CIRCLE.1).abs() < 0.01 || (e - 1.0).abs() < 0.01 || x.abs() < 0.01 {
                continue;
            }
            let want =
                (0.0..=80.0).contains(&x) && (0.0..=60.0).contains(&y) && r > 10.0 && e > 1.0;
            assert_eq!(region.contains(x, y), want, "({x}, {y})");
            checked += 1;
        }
    }
    assert!(checked > 28_000, "{checked}");
}

#[test]
fn an_untrimmed_face_has_no_region() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/freeform_patch.stp");
    let face = step::read_file(path).unwrap().faces.remove(0);
    assert!(face.uv_region(1e-3).unwrap().is_none());
}

#[test]
fn the_plate_is_finished_within_its_bounds_and_verified() {
    let face = plate();
    let h = 0.2;
    let mut settings = Settings::new(StrategyKind::ZigZag, h, 0.01);
    settings.region = face.uv_region(0.002).unwrap();
    settings.reverse_normal = !face.same_sense;
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let planned = plan(&face.surface, &cutter, &settings).unwrap();
    let region = settings.region.as_ref().unwrap();
    let mut on_circle = 0;
    let mut on_ellipse = 0;
    for cl in planned.path.passes.iter().flat_map(|p| &p.points) {
        let (x, y) = (cl.contact.x, cl.contact.y);
        assert!(region.contains(cl.uv.0, cl.uv.1), "{cl:?}");
        let r = (x - CIRCLE.0 .0).hypot(y - CIRCLE.0 .1);
        assert!(r >= CIRCLE.1 - 0.002, "contact in the round hole: {cl:?}");
        assert!(
            in_ellipse(x, y) >= 1.0 - 1e-3,
            "contact in the elliptic hole: {cl:?}"
        );
        on_circle += usize::from(r < CIRCLE.1 + 1e-3);
        on_ellipse += usize::from(in_ellipse(x, y) < 1.0 + 1e-3);
    }
    // The trim curves are cut along (their own passes) and passes end on them.
    assert!(
        on_circle > 40 && on_ellipse > 40,
        "{on_circle} {on_ellipse}"
    );
    assert!(planned.refused.iter().all(|r| !r.refusal.is_gouge()));
    let spacing = 0.2;
    let poses = path_poses(&planned.path, spacing);
    let options = VerifyOptions {
        cell_mm: 0.4,
        sweep_spacing_mm: spacing,
        region: MachinedRegion::ContactBox,
    };
    let v = simulate_on(&face.surface, &planned.path, &poses, &options, Some(region)).unwrap();
    assert_eq!(v.uncut, 0, "{v:?}");
    assert!(v.max_scallop_mm <= h, "{v:?}");
    assert!(v.gouge_depth_mm <= 1e-3, "{v:?}");
    // Judged over the whole plane instead, the holes' insides (where no pass runs) stand
    // uncut: the face's region is what keeps them out.
    let whole = simulate_on(&face.surface, &planned.path, &poses, &options, None).unwrap();
    assert!(whole.uncut > 1000, "{whole:?}");
}

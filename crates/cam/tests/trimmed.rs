//! Trimmed faces: the STEP plate with a circular and an elliptic hole (OpenCascade fixture)
//! mapped into its parameter plane, and finished within its bounds — passes end on the trim,
//! the trim curves are cut, no contact point falls in a hole, and the dexel simulation over
//! the face (holes left out) finds no scallop above h and no gouge.

use std::f64::consts::PI;
use std::path::PathBuf;

use tezgah_cam::step::{self, Face};
use tezgah_cam::verify::{path_poses, simulate_on, MachinedRegion, Verification, VerifyOptions};
use tezgah_cam::{plan, Cutter, CutterShape, Settings, StrategyKind, ToleranceShares};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn plate() -> Face {
    step::read_file(fixture("plate_with_holes.stp"))
        .unwrap()
        .faces
        .remove(0)
}

/// OpenCascade's free-form patch trimmed in (u, v) by an ellipse about (0.5, 0.5) with
/// semi-axes 0.42 (u) and 0.34 (v), less the disc of radius 0.1 about (0.62, 0.45) (exact
/// conics as pcurves), with OpenCascade's samples and area of the trimmed face.
fn trimmed_freeform() -> (Face, serde_json::Value) {
    let face = step::read_file(fixture("trimmed_freeform.stp"))
        .unwrap()
        .faces
        .remove(0);
    let json = std::fs::read_to_string(fixture("trimmed_freeform.json")).unwrap();
    (face, serde_json::from_str(&json).unwrap())
}

/// Where (u, v) lies against the trimmed free-form's loops: the ellipse's implicit value
/// (< 1 inside) and the distance from the hole's centre (> 0.1 outside the hole).
fn freeform_loops(u: f64, v: f64) -> (f64, f64) {
    (
        ((u - 0.5) / 0.42).powi(2) + ((v - 0.5) / 0.34).powi(2),
        (u - 0.62).hypot(v - 0.45),
    )
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
    let face = step::read_file(fixture("freeform_patch.stp"))
        .unwrap()
        .faces
        .remove(0);
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
    assert_verified(&face, &planned, 0.4, Some(region), h);
    // Judged over the whole plane instead, the holes' insides (where no pass runs) stand
    // uncut: the face's region is what keeps them out.
    let whole = measure(&face, &planned, 0.4, None);
    assert!(whole.uncut > 1000, "{whole:?}");
}

#[test]
fn the_trimmed_free_form_matches_opencascade_and_its_conics() {
    let (face, occ) = trimmed_freeform();
    let reference = &occ["faces"][0];
    for s in reference["samples"].as_array().unwrap() {
        let s: Vec<f64> = s
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let p = face.surface.point(s[0], s[1]);
        assert!((0..3).all(|i| (p[i] - s[2 + i]).abs() < 1e-9), "{s:?}");
    }
    let region = face.uv_region(1e-3).unwrap().expect("trimmed");
    assert_eq!(region.loops().len(), 2);
    for i in 0..120 {
        for j in 0..120 {
            let (u, v) = ((i as f64 + 0.5) / 120.0, (j as f64 + 0.37) / 120.0);
            let (e, r) = freeform_loops(u, v);
            if (e - 1.0).abs() < 0.01 || (r - 0.1).abs() < 0.002 {
                continue;
            }
            assert_eq!(region.contains(u, v), e < 1.0 && r > 0.1, "({u}, {v})");
        }
    }
    // The face's area on the surface against OpenCascade's integration over the trimmed face:
    // the midpoint rule's error is the trim's length (≈ 330 mm) times a cell's diagonal
    // (≈ 0.35 mm at 400 cells over the loops' box), at most 4 %, in practice far less.
    let occ_area = reference["area"].as_f64().unwrap();
    let area = tezgah_cam::region::surface_area(&face.surface, Some(&region), 400);
    assert!(
        (area - occ_area).abs() < 1e-3 * occ_area,
        "{area} vs {occ_area}"
    );
}

#[test]
fn the_trimmed_free_form_is_finished_iso_scallop_within_its_loops() {
    let (face, _) = trimmed_freeform();
    let h = 0.2;
    // As `tezgah cam` plans: the one-sided band of a 0.01 mm tolerance (chords outside the
    // surface, side steps for h − T).
    let shares = ToleranceShares::of(0.01);
    let mut settings = Settings::new(StrategyKind::IsoScallop, h, shares.chord);
    settings.band = Some(shares.band());
    settings.gouge.depth_tolerance = 0.5e-3;
    settings.region = face.uv_region(0.002).unwrap();
    settings.reverse_normal = !face.same_sense;
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let planned = plan(&face.surface, &cutter, &settings).unwrap();
    let mut on_trim = 0;
    for cl in planned.path.passes.iter().flat_map(|p| &p.points) {
        let (e, r) = freeform_loops(cl.uv.0, cl.uv.1);
        assert!(
            e <= 1.0 + 1e-4 && r >= 0.1 - 1e-4,
            "{cl:?} outside the face"
        );
        on_trim += usize::from(e > 1.0 - 1e-3 || r < 0.1 + 1e-3);
    }
    assert!(on_trim > 100, "{on_trim}");
    assert!(planned.refused.iter().all(|r| !r.refusal.is_gouge()));
    assert_verified(&face, &planned, 0.5, settings.region.as_ref(), h);
}

/// Simulates the plan's cut over `face` (judged inside `region`, or over the whole contact
/// box) at `cell` mm and 0.2 mm poses, and asserts issue 7's check: nothing uncut, the scallop
/// within `h`, no gouge deeper than 1 µm. Returns the measurement.
fn assert_verified(
    face: &Face,
    planned: &tezgah_cam::Plan,
    cell: f64,
    region: Option<&tezgah_cam::region::FaceRegion>,
    h: f64,
) -> Verification {
    let v = measure(face, planned, cell, region);
    assert_eq!(v.uncut, 0, "{v:?}");
    assert!(v.max_scallop_mm <= h, "{v:?}");
    assert!(v.gouge_depth_mm <= 1e-3, "{v:?}");
    v
}

fn measure(
    face: &Face,
    planned: &tezgah_cam::Plan,
    cell: f64,
    region: Option<&tezgah_cam::region::FaceRegion>,
) -> Verification {
    let spacing = 0.2;
    let poses = path_poses(&planned.path, spacing);
    let options = VerifyOptions {
        cell_mm: cell,
        sweep_spacing_mm: spacing,
        region: MachinedRegion::ContactBox,
    };
    simulate_on(&face.surface, &planned.path, &poses, &options, region).unwrap()
}

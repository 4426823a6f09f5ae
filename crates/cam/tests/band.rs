//! Issue 7's check on each test surface, measured by the dexel simulation: with the one-sided
//! tolerance band the tool path leaves a scallop no higher than the target `h` and gouges no
//! deeper than 1 µm, for ball, flat and bull-nose cutters. Surfaces: the strategy tests'
//! convex roller, concave trough, sphere patch, saddle and free-form patch, and the STEP
//! free-form fixture. Scallops and cells are coarse to keep each test to seconds; the grid
//! bound each measurement carries is printed with it. Flat and bull-nose cutters stand at
//! 5° lead (their heels touched by up to 4 µm there until the rear check became exact to its
//! tolerance and raised the lead where they would), and at 0° in one test (they lean 0.5°).
//! Flat end mills are swept at closer poses: the rim is a corner along the motion, so the
//! simulation's sweep bound grows by `δ·tan(lean)`.
//! The bull-nose on the saddle measured 0.125 mm at h = 0.1 before side steps were checked
//! against the cutter's true silhouette (`silhouette`): its 3.7 mm step put the cusp where the
//! torus has risen 0.151 mm against its osculating circle's 0.130.

use tezgah_cam::verify::{
    path_poses, simulate, step_over, MachinedRegion, Verification, VerifyOptions,
};
use tezgah_cam::{
    plan, testing, Band, Cutter, CutterShape, FeedDirection, Plan, Settings, StrategyKind,
    ToleranceShares, ToolAxis,
};
use tezgah_geom::NurbsSurface;

/// Issue 7: "no gouge deeper than 1 µm".
const GOUGE_LIMIT: f64 = 0.001;
/// The tolerance the band is planned for (tezgah cam's default shares of it).
const TOLERANCE: f64 = 0.01;
/// Sweep error allowed in the simulation, mm: far below the gouge limit.
const SWEEP_BOUND: f64 = 1e-4;
/// A flat end's rim adds `δ·tan(lean)` to the sweep bound: its poses are spaced so that share
/// is this fraction of h at 10° of lean (the tests' 5° and less leave a smaller share; larger
/// where curvature matching leans further, and the bound reported covers it).
const FLAT_RIM_SHARE: f64 = 0.05;

fn ball(d: f64) -> Cutter {
    Cutter::standard(CutterShape::Ball { radius: 0.5 * d })
}

fn flat(d: f64) -> Cutter {
    Cutter::standard(CutterShape::Flat { radius: 0.5 * d })
}

fn bull(d: f64, r: f64) -> Cutter {
    Cutter::standard(CutterShape::BullNose {
        radius: 0.5 * d,
        corner_radius: r,
    })
}

/// Settings as `tezgah cam` makes them for tolerance [`TOLERANCE`]; flat and bull-nose
/// cutters stand at `lead_deg` (Can, 2010: 5–20°).
fn banded(kind: StrategyKind, h: f64, lead_deg: f64) -> Settings {
    let shares = ToleranceShares::of(TOLERANCE);
    let mut s = Settings::new(kind, h, shares.chord);
    s.band = Some(shares.band());
    // The rear check accepts penetrations up to its depth tolerance: half the gouge limit.
    s.gouge.depth_tolerance = 0.5 * GOUGE_LIMIT;
    if let ToolAxis::Surface { lead_deg: l, .. } = &mut s.axis {
        *l = lead_deg;
    }
    s
}

/// Plans, simulates along the path with cell `cell` and asserts scallop ≤ h (measured heights
/// may exceed the true ones by the sweep bound) and gouge ≤ 1 µm. Returns the measurement.
fn assert_within(
    name: &str,
    surface: &NurbsSurface,
    cutter: &Cutter,
    settings: &Settings,
    cell: f64,
) -> Verification {
    let p = plan(surface, cutter, settings).unwrap();
    assert_plan_within(name, surface, cutter, settings, &p, cell)
}

/// [`assert_within`] for a plan already made with `settings`.
fn assert_plan_within(
    name: &str,
    surface: &NurbsSurface,
    cutter: &Cutter,
    settings: &Settings,
    p: &Plan,
    cell: f64,
) -> Verification {
    let gouges = p.refused.iter().filter(|r| r.refusal.is_gouge()).count();
    assert_eq!(gouges, 0, "{name}: refused {:?}", p.refused.first());
    let rho = match cutter.shape.corner_radius() {
        r if r > 0.0 => r,
        _ => cutter.shape.radius(),
    };
    // δ²/(8ρ) = SWEEP_BOUND; a flat end's rim adds δ·tan(lean) (verify's sweep bound), so
    // its poses are closer.
    let circle = (8.0 * rho * SWEEP_BOUND).sqrt();
    let spacing = match cutter.shape {
        CutterShape::Flat { .. } => {
            circle.min(FLAT_RIM_SHARE * settings.scallop / 10f64.to_radians().tan())
        }
        _ => circle,
    };
    let options = VerifyOptions {
        cell_mm: cell,
        sweep_spacing_mm: spacing,
        // With a tilt limit, all the face the cutter reaches is judged (out to its reach
        // edge), not only what the contacts span.
        region: match settings.reach_normal_tilt_deg(&cutter.shape) {
            Some(max_tilt_deg) => MachinedRegion::Reachable { max_tilt_deg },
            None => MachinedRegion::ContactBox,
        },
    };
    let poses = path_poses(&p.path, spacing);
    let v = simulate(surface, &p.path, &poses, &options).unwrap();
    let h = settings.scallop;
    eprintln!(
        "{name}: {} passes, {} CC, {:.1} mm, step-over {:.3}; scallop {:.5} (h {h}), gouge {:.6}, \
         bounds −{:.4}/+{:.5}, {} dexels, cell {:.3}, scallop at {:?}, gouge at {:?}, {} corrected",
        p.path.passes.len(),
        p.path.contact_count(),
        p.path.cutting_length(),
        step_over(&p.path).unwrap_or(f64::NAN),
        v.max_scallop_mm,
        v.gouge_depth_mm,
        v.grid_bound_mm,
        v.sweep_bound_mm,
        v.dexels,
        v.cell_mm,
        v.max_scallop_at,
        v.gouge_at,
        p.corrected
    );
    assert_eq!(v.uncut, 0, "{name}: {v:?}");
    assert!(v.max_scallop_mm - v.sweep_bound_mm <= h, "{name}: {v:?}");
    assert!(v.gouge_depth_mm <= GOUGE_LIMIT, "{name}: {v:?}");
    v
}

#[test]
fn convex_roller_ball_flat_and_bull_nose() {
    // Fed around the arc, so the chords sag into the convex section.
    let s = testing::cylinder(20.0, 8.0, true);
    let z = StrategyKind::ZigZag;
    let around = |mut s: Settings| {
        s.direction = FeedDirection::AlongU;
        s
    };
    let (b, f) = (around(banded(z, 0.05, 0.0)), around(banded(z, 0.05, 5.0)));
    assert_within("roller ball D6", &s, &ball(6.0), &b, 0.12);
    assert_within("roller flat D8", &s, &flat(8.0), &f, 0.12);
    assert_within("roller bull D8 r2", &s, &bull(8.0, 2.0), &f, 0.12);
}

#[test]
fn concave_trough_ball_flat_and_bull_nose() {
    let s = testing::trough(40.0, 8.0);
    let z = StrategyKind::IsoScallop;
    assert_within(
        "trough ball D6",
        &s,
        &ball(6.0),
        &banded(z, 0.05, 0.0),
        0.15,
    );
    assert_within(
        "trough flat D8",
        &s,
        &flat(8.0),
        &banded(z, 0.05, 5.0),
        0.15,
    );
    assert_within(
        "trough bull D8 r2",
        &s,
        &bull(8.0, 2.0),
        &banded(z, 0.05, 5.0),
        0.15,
    );
}

#[test]
fn sphere_patch_ball_flat_and_bull_nose() {
    let s = testing::sphere(15.0);
    let z = StrategyKind::ZigZag;
    assert_within("sphere ball D6", &s, &ball(6.0), &banded(z, 0.1, 0.0), 0.2);
    assert_within("sphere flat D8", &s, &flat(8.0), &banded(z, 0.1, 5.0), 0.2);
    assert_within(
        "sphere bull D8 r2",
        &s,
        &bull(8.0, 2.0),
        &banded(z, 0.1, 5.0),
        0.2,
    );
}

#[test]
fn sphere_patch_cut_to_the_reach_edge_at_a_lead() {
    // A table that tilts 50°: the patch's lower latitudes lie beyond it. Leaning 5° the
    // cutter reaches the face out to where the normal leans 45° whichever way it feeds; the
    // reach edge is cut there and the face judged out to it. Traced where the normal leans
    // 50°, the edge pass was refused wherever its axis leaned past the limit.
    let s = testing::sphere(15.0);
    let mut settings = banded(StrategyKind::ZigZag, 0.1, 5.0);
    settings.max_axis_tilt_deg = Some(50.0);
    // Along the parallels: the edge is one, and the passes below it are out of reach whole.
    settings.direction = FeedDirection::AlongU;
    let cutter = bull(8.0, 2.0);
    let edge = settings.reach_normal_tilt_deg(&cutter.shape).unwrap();
    assert_eq!(edge, 45.0);
    // The edge pass is cut whole: contacts where the normal leans the edge's angle span the
    // patch's 90° of longitude (the normal of the sphere about the origin is `p/|p|`).
    let p = plan(&s, &cutter, &settings).unwrap();
    let longitudes: Vec<f64> = p
        .path
        .passes
        .iter()
        .flat_map(|pass| &pass.points)
        .filter(|l| ((l.contact.z / l.contact.norm()).acos().to_degrees() - edge).abs() < 0.01)
        .map(|l| l.contact.y.atan2(l.contact.x).to_degrees())
        .collect();
    let (lo, hi) = longitudes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    assert!(lo < 0.01 && hi > 89.99, "edge contacts span {lo}..{hi}°");
    assert_plan_within(
        "sphere bull D8 r2 within 50°",
        &s,
        &cutter,
        &settings,
        &p,
        0.2,
    );
}

#[test]
fn saddle_ball_flat_and_bull_nose() {
    let s = testing::saddle(10.0, 40.0);
    let z = StrategyKind::IsoScallop;
    assert_within("saddle ball D6", &s, &ball(6.0), &banded(z, 0.1, 0.0), 0.15);
    assert_within("saddle flat D8", &s, &flat(8.0), &banded(z, 0.1, 5.0), 0.15);
    assert_within(
        "saddle bull D8 r2",
        &s,
        &bull(8.0, 2.0),
        &banded(z, 0.1, 5.0),
        0.15,
    );
}

#[test]
fn free_form_patch_ball_flat_and_bull_nose() {
    let s = testing::freeform(0.0);
    let z = StrategyKind::IsoScallop;
    assert_within(
        "free-form ball D6",
        &s,
        &ball(6.0),
        &banded(z, 0.4, 0.0),
        0.8,
    );
    assert_within(
        "free-form flat D8",
        &s,
        &flat(8.0),
        &banded(z, 0.4, 5.0),
        0.8,
    );
    assert_within(
        "free-form bull D8 r2",
        &s,
        &bull(8.0, 2.0),
        &banded(z, 0.4, 5.0),
        0.8,
    );
}

#[test]
fn flat_and_bull_nose_asked_for_zero_lead_keep_their_rim_contact() {
    // Standing exactly along the normal, a flat bottom's contact may be anywhere on the rim,
    // and the chord checks (axes interpolated, normals a hair different) saw it jump across:
    // the bull-nose D10 r1 left 4.06 mm (tips lifted by R − r) at h 0.4 before the planner
    // leaned such ends by at least half a degree (0.063 mm since).
    let s = testing::freeform(0.0);
    let z = StrategyKind::IsoScallop;
    assert_within(
        "free-form bull D10 r1, lead 0",
        &s,
        &bull(10.0, 1.0),
        &banded(z, 0.4, 0.0),
        0.8,
    );
    assert_within(
        "free-form flat D6, lead 0",
        &s,
        &flat(6.0),
        &banded(z, 0.4, 0.0),
        0.8,
    );
}

#[test]
fn step_free_form_fixture_ball_flat_and_bull_nose() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/freeform_patch.stp"
    );
    let model = tezgah_cam::step::read_file(path).unwrap();
    let face = &model.faces[0];
    let z = StrategyKind::IsoScallop;
    let with = |mut s: Settings| {
        s.reverse_normal = !face.same_sense;
        s
    };
    let s = &face.surface;
    assert_within(
        "STEP ball D6",
        s,
        &ball(6.0),
        &with(banded(z, 0.4, 0.0)),
        0.8,
    );
    assert_within(
        "STEP flat D8",
        s,
        &flat(8.0),
        &with(banded(z, 0.4, 5.0)),
        0.8,
    );
    assert_within(
        "STEP bull D8 r2",
        s,
        &bull(8.0, 2.0),
        &with(banded(z, 0.4, 5.0)),
        0.8,
    );
}

#[test]
fn without_the_band_chords_cut_into_a_convex_surface() {
    // The same roller job with the band off: contact-point chords sag into the part (the
    // gouge the band removes), and the band's path is longer by its side-step share.
    let s = testing::cylinder(20.0, 8.0, true);
    let shares = ToleranceShares::of(TOLERANCE);
    let mut off = Settings::new(StrategyKind::ZigZag, 0.05, shares.chord);
    off.direction = FeedDirection::AlongU;
    let mut on = off.clone();
    on.band = Some(Band { motion: 0.0 });
    let cutter = ball(6.0);
    let spacing = (8.0 * 3.0 * SWEEP_BOUND).sqrt();
    let options = VerifyOptions {
        cell_mm: 0.12,
        sweep_spacing_mm: spacing,
        region: tezgah_cam::verify::MachinedRegion::ContactBox,
    };
    let measure = |settings: &Settings| {
        let p = plan(&s, &cutter, settings).unwrap();
        let poses = path_poses(&p.path, spacing);
        (
            simulate(&s, &p.path, &poses, &options).unwrap(),
            p.path.cutting_length(),
        )
    };
    let (v_off, len_off) = measure(&off);
    let (v_on, len_on) = measure(&on);
    eprintln!(
        "roller band off: scallop {:.5} gouge {:.5} length {len_off:.1}; on: scallop {:.5} \
         gouge {:.6} length {len_on:.1}",
        v_off.max_scallop_mm, v_off.gouge_depth_mm, v_on.max_scallop_mm, v_on.gouge_depth_mm
    );
    // Off: a ball's centre chord on a convex section of radius ρ sags (1 + R/ρ) times the
    // contacts' chord, which the forward step keeps in [ε/2, ε]: the gouge is of that order.
    assert!(v_off.gouge_depth_mm > 0.4 * shares.chord, "{v_off:?}");
    assert!(v_on.gouge_depth_mm <= GOUGE_LIMIT, "{v_on:?}");
    assert!(
        v_on.max_scallop_mm - v_on.sweep_bound_mm <= 0.05,
        "{v_on:?}"
    );
    assert!(len_on > len_off, "{len_on} {len_off}");
}

#[test]
fn a_band_wider_than_the_scallop_is_refused() {
    let s = testing::plane(10.0);
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.01, 0.005);
    settings.band = Some(Band { motion: 0.0025 });
    assert!(plan(&s, &ball(6.0), &settings).is_err());
    settings.band = Some(Band { motion: f64::NAN });
    assert!(plan(&s, &ball(6.0), &settings).is_err());
    settings.band = Some(Band { motion: 0.001 });
    assert!(plan(&s, &ball(6.0), &settings).is_ok());
}

/// The largest ball on the STEP free-form fixture at h = 0.2 (the 32 mm one `--tool auto`
/// proposes from the standard set): the step-over (≈ 4 mm) is a sizeable part of the concave
/// radii (≥ 26 mm) and the curvature varies across it, where the osculating-circle model is
/// least sure; every side step is also checked on the true surface (`true_cusp`). Only the
/// largest ball runs here (the 12 and 20 mm ones measured 0.196 mm: the session-5 note).
/// The rear check is off: a ball standing on the normal cannot reach the surface behind its
/// contact where every concave radius (≥ 26 mm) exceeds its own (16 mm), and the simulation
/// still measures the gouge. With it on, its proof of that over a 32 mm ball was nine tenths
/// of the tests' time (a minute each).
fn step_free_form_large_ball(kind: StrategyKind, name: &str) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/freeform_patch.stp"
    );
    let model = tezgah_cam::step::read_file(path).unwrap();
    let face = &model.faces[0];
    let mut settings = banded(kind, 0.2, 0.0);
    settings.reverse_normal = !face.same_sense;
    settings.gouge.rear = false;
    assert_within(name, &face.surface, &ball(32.0), &settings, 0.8);
}

/// Zig-zag's constant step, at its worst place. Iso-scallop with the same ball, h and
/// tolerance is `tezgah cam --tool auto`'s job on this fixture, verified end to end (at a
/// finer cell) by the CLI's `cam_tool::auto_from_the_standard_set_on_the_free_form_is_verified`.
#[test]
fn step_free_form_large_ball_zigzag_holds_the_scallop_on_the_true_surface() {
    step_free_form_large_ball(StrategyKind::ZigZag, "STEP ball D32 zigzag h 0.2");
}

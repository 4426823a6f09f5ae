//! End-to-end checks of `strategy::plan`: scallop spacing against the closed form on a sphere
//! and a cylinder, iso-scallop against iso-parametric path length, and the gouge checks
//! (local, rear, global) finding, correcting or reporting what they must.

use tezgah_cam::gouge::rear::penetration;
use tezgah_cam::gouge::{Gouge, ToolPart};
use tezgah_cam::scallop::stepover_exact;
use tezgah_cam::strategy::{iso_parametric_side_step, Refusal};
use tezgah_cam::{
    plan, testing, Cutter, CutterShape, Cylinder, FeedDirection, Pass, Settings, StrategyKind,
    ToolAxis,
};
use tezgah_geom::{NurbsSurface, Vec3};

fn ball(d: f64) -> Cutter {
    Cutter::standard(CutterShape::Ball { radius: d / 2.0 })
}

fn distance_to_polyline(p: &Vec3, pass: &Pass) -> f64 {
    pass.points
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].contact, w[1].contact);
            let ab = b - a;
            let s = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (p - (a + ab * s)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Mean and extremes of the distance from each contact of pass k to pass k + 1, for contacts
/// with `u ≤ 0.8` and `0.05 ≤ v ≤ 0.95`: near the far edge (`u = 1`) passes hug the edge,
/// closer than a full step, and the parts of a pass that would repeat the edge are not cut;
/// at the feed ends a front point that would leave the domain is offset along the edge, which
/// spaces slanted passes closer there (never farther).
fn spacing(passes: &[Pass]) -> (f64, f64, f64) {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, 0.0f64, 0.0, 0);
    let inner =
        |cl: &&tezgah_cam::CutterLocation| cl.uv.0 <= 0.8 && (0.05..=0.95).contains(&cl.uv.1);
    for k in 0..passes.len().saturating_sub(1) {
        for cl in passes[k].points.iter().filter(inner) {
            let d = distance_to_polyline(&cl.contact, &passes[k + 1]);
            lo = lo.min(d);
            hi = hi.max(d);
            sum += d;
            n += 1;
        }
    }
    (lo, hi, sum / n as f64)
}

#[test]
fn iso_scallop_spacing_on_a_sphere_is_the_closed_form() {
    // Convex sphere R 30, ball D 6, h = 0.02: every cross-section is a circle of radius 30, so
    // the step between passes is the exact circle–circle chord everywhere.
    let s = testing::sphere(30.0);
    let h = 0.02;
    let settings = Settings::new(StrategyKind::IsoScallop, h, 0.005);
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", &p.refused[..1]);
    let want = stepover_exact(3.0, -1.0 / 30.0, h).unwrap();
    let (lo, hi, mean) = spacing(&p.path.passes);
    println!("sphere: ω = {want:.5}, measured {lo:.5} … {hi:.5} (mean {mean:.5})");
    // The distance to the next pass's polyline of contacts is the perpendicular one; the
    // contacts lie on the surface, the polyline cuts the chord by ≤ the tolerance.
    assert!(
        hi <= want * 1.01 && lo >= want * 0.97,
        "{lo} {hi} vs {want}"
    );
}

#[test]
fn iso_parametric_step_on_a_cylinder_is_the_closed_form() {
    // Roller R 20 (rational arc, non-uniform speed in u), passes along its axis: the
    // cross-feed section is the circle everywhere, so the constant Δu is set where the arc is
    // fastest in u, and adjacent passes are never farther apart than the closed-form chord.
    let s = testing::cylinder(20.0, 60.0, true);
    let h = 0.01;
    let settings = Settings::new(StrategyKind::ZigZag, h, 0.005);
    let want = stepover_exact(3.0, -1.0 / 20.0, h).unwrap();
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.is_empty());
    let (_, hi, _) = spacing(&p.path.passes);
    assert!(hi <= want * 1.001 && hi >= want * 0.99, "{hi} vs {want}");
    // Iso-scallop spaces them at the chord everywhere: fewer passes.
    let q = plan(
        &s,
        &ball(6.0),
        &Settings::new(StrategyKind::IsoScallop, h, 0.005),
    )
    .unwrap();
    let (lo, hi, _) = spacing(&q.path.passes);
    assert!(
        lo >= want * 0.98 && hi <= want * 1.01,
        "{lo} {hi} vs {want}"
    );
    assert!(q.path.passes.len() < p.path.passes.len());
    // The same quarter cylinder parametrised with its normal toward the axis, machined from
    // outside (`reverse_normal`): the same convex section, the same spacing.
    let inner = testing::cylinder(20.0, 60.0, false);
    let mut settings = Settings::new(StrategyKind::IsoScallop, h, 0.005);
    settings.reverse_normal = true;
    let r = plan(&inner, &ball(6.0), &settings).unwrap();
    assert!(r.refused.is_empty());
    let (lo, hi, _) = spacing(&r.path.passes);
    assert!(
        lo >= want * 0.98 && hi <= want * 1.01,
        "{lo} {hi} vs {want}"
    );
    assert_eq!(r.path.passes.len(), q.path.passes.len());
}

/// The largest ratio, over inner contacts, of the distance to the next pass and the side step
/// the exact scallop model allows there for a ball of radius `r` (5-axis, so `r_e = r`).
fn worst_spacing_ratio(s: &NurbsSurface, passes: &[Pass], r: f64, h: f64) -> f64 {
    use tezgah_cam::gouge::local::surface_curvature;
    use tezgah_cam::orientation::ContactFrame;
    let mut worst = 0.0f64;
    for k in 0..passes.len().saturating_sub(1) {
        let pts = &passes[k].points;
        for i in 1..pts.len().saturating_sub(1) {
            let cl = &pts[i];
            if !(cl.uv.0 <= 0.8 && (0.05..=0.95).contains(&cl.uv.1)) {
                continue;
            }
            let d = s.derivs(cl.uv.0, cl.uv.1);
            let n = s.normal(cl.uv.0, cl.uv.1).unwrap();
            // The pass's course through the contact (central: a one-sided chord at a point
            // where the pass bends would tilt the cross-feed direction).
            let frame = ContactFrame::new(n, pts[i + 1].contact - pts[i - 1].contact).unwrap();
            let k_tt = surface_curvature(&d, &frame).unwrap().tt;
            let allowed = stepover_exact(r, k_tt, h).unwrap().min(r);
            let ratio = distance_to_polyline(&cl.contact, &passes[k + 1]) / allowed;
            worst = worst.max(ratio);
        }
    }
    worst
}

fn compare(name: &str, s: &NurbsSurface, cutter: &Cutter, h: f64) -> f64 {
    let mut lengths = Vec::new();
    for kind in [StrategyKind::ZigZag, StrategyKind::IsoScallop] {
        let settings = Settings::new(kind, h, 0.01);
        let p = plan(s, cutter, &settings).unwrap();
        assert!(
            p.refused.is_empty(),
            "{name} {kind}: {:?}",
            p.refused.first()
        );
        let worst = worst_spacing_ratio(s, &p.path.passes, cutter.shape.radius(), h);
        println!("{name} {kind}: largest spacing / local allowed step = {worst:.4}");
        // ≤ 3 % over the allowed step (≈ 6 % over h, scallop ∝ ω²): the front is linear in
        // (u, v) between its points, and on the saddle it bends slightly on the centre line,
        // where the cross-feed curvature changes sign with the direction.
        assert!(worst <= 1.03, "{name} {kind}: {worst}");
        lengths.push((p.path.cutting_length(), p.path.passes.len()));
    }
    let reduction = 1.0 - lengths[1].0 / lengths[0].0;
    println!(
        "{name}: zigzag {:.0} mm ({} passes), iso-scallop {:.0} mm ({} passes): −{:.1} %",
        lengths[0].0,
        lengths[0].1,
        lengths[1].0,
        lengths[1].1,
        100.0 * reduction
    );
    reduction
}

#[test]
fn iso_scallop_is_shorter_where_curvature_varies() {
    let cutter = ball(6.0);
    // Free-form patch with a hill and a valley, uniform and warped parametrisation; the
    // saddle; all at h = 0.05 mm.
    let r1 = compare("freeform", &testing::freeform(0.0), &cutter, 0.05);
    let r2 = compare("freeform, warped", &testing::freeform(0.6), &cutter, 0.05);
    let r3 = compare("saddle", &testing::saddle(50.0, 40.0), &cutter, 0.05);
    assert!(r1 > 0.05 && r2 > r1 && r3 > 0.0, "{r1} {r2} {r3}");
    // The reductions the README and the notes report (−9.1 %, −35.7 %, −24.3 %), to ±1 %.
    // (The saddle's was −26.2 % while the fronts' ends left the v = 1 edge and were put back
    // on it 1.1–1.46 steps from the old ends; they slide along it now.)
    for (r, want) in [(r1, 0.091), (r2, 0.357), (r3, 0.243)] {
        assert!((r - want).abs() < 0.01, "{r1} {r2} {r3}");
    }
}

#[test]
fn local_gouge_in_a_trough_tighter_than_the_ball_is_reported() {
    // A trough of radius 2.5 under a ball of radius 3 (3-axis): every contact gouges locally.
    let s = testing::trough(2.5, 20.0);
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.05, 0.01);
    settings.axis = ToolAxis::Fixed(Vec3::z());
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.path.passes.is_empty());
    assert!(!p.refused.is_empty());
    assert!(p.refused.iter().all(|r| matches!(
        r.refusal,
        Refusal::Gouge(Gouge::Local { .. }) | Refusal::AxisBelowSurface
    )));
    // A ball of radius 2 fits (3-axis, the walls are 45° at most).
    let p = plan(&s, &ball(4.0), &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", p.refused.first());
}

/// The largest change of the tool's inclination to the normal between neighbouring locations
/// of a pass (degrees).
fn largest_lead_jump(p: &tezgah_cam::Plan) -> f64 {
    let lean = |c: &tezgah_cam::CutterLocation| c.axis.dot(&c.normal).clamp(-1.0, 1.0).acos();
    p.path
        .passes
        .iter()
        .flat_map(|pass| {
            pass.points
                .windows(2)
                .map(|w| (lean(&w[1]) - lean(&w[0])).abs().to_degrees())
        })
        .fold(0.0f64, f64::max)
}

/// Deepest penetration of any emitted cutting end into the surface, against samples 0.05 mm
/// apart independent of the planner's index.
fn worst_penetration(s: &NurbsSurface, p: &tezgah_cam::Plan) -> f64 {
    let n = 400;
    let pts: Vec<Vec3> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i as f64 / n as f64, j as f64 / n as f64)))
        .map(|(u, v)| s.point(u, v))
        .collect();
    let shape = p.path.cutter.shape;
    p.path
        .passes
        .iter()
        .flat_map(|pass| &pass.points)
        .map(|cl| {
            let axis = nalgebra::Unit::new_normalize(cl.axis);
            pts.iter()
                .map(|q| penetration(&shape, &cl.tip, &axis, q))
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn flat_end_in_a_trough_is_curvature_matched_and_rear_gouges_are_corrected() {
    // Flat D 10 in a trough of radius 20 (5-axis). Along the trough: the cross-feed section
    // is concave, so curvature matching leans the tool; no refusals. (h 0.05: what is checked
    // is each location's lean and heel, which the spacing of the passes does not change; at
    // 0.02 the four plans took a minute and a half.)
    let s = testing::trough(20.0, 30.0);
    let flat = Cutter::standard(CutterShape::Flat { radius: 5.0 });
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.05, 0.01);
    settings.direction = FeedDirection::AlongV;
    let p = plan(&s, &flat, &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", p.refused.first());
    let lean = p.path.passes[0].points[0]
        .axis
        .dot(&p.path.passes[0].points[0].normal);
    let want = (5.0f64 / (0.95 * 20.0)).asin().cos();
    assert!((lean - want).abs() < 1e-9, "{lean} vs {want}");
    assert!(worst_penetration(&s, &p) < 0.002 + 1e-3);
    // Across the trough the concavity lies along the feed: locally fine, but the heel digs
    // in behind the contact. Without room to lean, the rear check refuses the points…
    settings.direction = FeedDirection::AlongU;
    settings.axis = ToolAxis::Surface {
        lead_deg: 3.0,
        tilt_deg: 0.0,
        max_lead_deg: 3.0,
        match_curvature: true,
    };
    let p = plan(&s, &flat, &settings).unwrap();
    assert!(!p.refused.is_empty());
    assert!(p.refused.iter().all(|r| matches!(
        r.refusal,
        Refusal::Gouge(Gouge::Interference {
            part: ToolPart::CuttingEnd,
            ..
        })
    )));
    // …and with room, leans the tool until the heel clears.
    settings.axis = ToolAxis::Surface {
        lead_deg: 3.0,
        tilt_deg: 0.0,
        max_lead_deg: 45.0,
        match_curvature: true,
    };
    let p = plan(&s, &flat, &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", p.refused.first());
    assert!(p.corrected > 0);
    let worst = worst_penetration(&s, &p);
    println!(
        "trough across, corrected {} points, worst penetration {worst:.4} mm",
        p.corrected
    );
    assert!(worst < 0.002 + 1e-3, "{worst}");
    // Limiting the lead change between neighbours to 1.5° (the corrections step by 1° on
    // neighbours that differ a little, so 2° jumps occur): still gouge-free, within the limit.
    let before = largest_lead_jump(&p);
    settings.max_lead_change_deg = Some(1.5);
    let q = plan(&s, &flat, &settings).unwrap();
    assert!(q.refused.is_empty());
    let after = largest_lead_jump(&q);
    println!("largest lead change between neighbours: {before:.2}° → {after:.2}° (limit 1.5°)");
    assert!(
        before > 1.5 + 1e-6 && after <= 1.5 + 1e-6,
        "{before} {after}"
    );
    assert!(worst_penetration(&s, &q) < 0.002 + 1e-3);
}

#[test]
fn holder_against_the_trough_walls_is_reported() {
    let s = testing::trough(20.0, 30.0);
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.05, 0.01);
    settings.axis = ToolAxis::Fixed(Vec3::z());
    // Stock proportions: the holder starts 30 mm up, well clear of the 5.9 mm deep trough.
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", p.refused.first());
    // A holder of radius 12 from 4 mm above the tip meets the walls (z = −16 at x = ±12).
    let mut stubby = ball(6.0);
    stubby.flute_length = 4.0;
    stubby.shank = Cylinder {
        radius: 3.0,
        from: 4.0,
        length: 0.0,
    };
    stubby.holder = Cylinder {
        radius: 12.0,
        from: 4.0,
        length: 30.0,
    };
    let p = plan(&s, &stubby, &settings).unwrap();
    assert!(p.refused.iter().any(|r| matches!(
        r.refusal,
        Refusal::Gouge(Gouge::Interference {
            part: ToolPart::Holder,
            ..
        })
    )));
}

#[test]
fn bad_settings_are_errors() {
    let s = testing::plane(10.0);
    for (h, tol) in [(0.0, 0.01), (0.01, -1.0), (f64::NAN, 0.01)] {
        assert!(plan(&s, &ball(6.0), &Settings::new(StrategyKind::ZigZag, h, tol)).is_err());
    }
    let mut settings = Settings::new(StrategyKind::IsoScallop, 0.01, 0.01);
    settings.axis = ToolAxis::Fixed(Vec3::zeros());
    assert!(plan(&s, &ball(6.0), &settings).is_err());
    let step = iso_parametric_side_step(
        &s,
        &ball(6.0),
        &Settings::new(StrategyKind::ZigZag, 0.01, 0.01),
    )
    .unwrap();
    // Plane 10 mm across in u ∈ [0, 1]: Δu = 2√(2rh − h²) / 10.
    assert!((step - 2.0 * (0.06f64 - 1e-4).sqrt() / 10.0).abs() < 1e-12);
}

/// Wavy patches with steep and tight spots: every plan succeeds, every emitted location is
/// finite with a unit axis on the normal's side, and whatever gouges is listed. A coarse
/// scallop and chord tolerance: what is checked is each location, not their spacing (0.05 mm
/// rather than 0.02 makes a pass's locations √2.5 times sparser). One test per patch, so that
/// they run side by side.
fn random_surface_plans_without_failing(seed: u64) {
    let s = testing::random_bicubic(seed);
    for (spec, kind, lead, tilt) in [
        ("ball:6", StrategyKind::IsoScallop, 0.0, 0.0),
        ("flat:10", StrategyKind::ZigZag, 0.0, 0.0),
        ("bull:10:2", StrategyKind::ZigZagOneWay, 0.0, 0.0),
        ("flat:8", StrategyKind::IsoScallop, 8.0, 4.0),
    ] {
        let cutter = Cutter::standard(spec.parse().unwrap());
        let mut settings = Settings::new(kind, 0.6, 0.05);
        settings.axis = ToolAxis::Surface {
            lead_deg: lead,
            tilt_deg: tilt,
            max_lead_deg: 30.0,
            match_curvature: true,
        };
        let p = plan(&s, &cutter, &settings).unwrap();
        assert!(p.path.contact_count() > 0, "{seed} {spec}");
        for cl in p.path.passes.iter().flat_map(|p| &p.points) {
            assert!(cl.tip.iter().all(|x| x.is_finite()));
            assert!((cl.axis.norm() - 1.0).abs() < 1e-12);
            assert!(cl.axis.dot(&cl.normal) > 0.0);
        }
        println!(
            "seed {seed} {spec} {kind}: {} points, {} refused, {} corrected",
            p.path.contact_count(),
            p.refused.len(),
            p.corrected
        );
    }
}

#[test]
fn random_surface_0_and_cutters_plan_without_failing() {
    random_surface_plans_without_failing(0);
}

#[test]
fn random_surface_1_and_cutters_plan_without_failing() {
    random_surface_plans_without_failing(1);
}

#[test]
fn random_surface_2_and_cutters_plan_without_failing() {
    random_surface_plans_without_failing(2);
}

/// The material a ball path leaves above the surface, measured independently of the planner:
/// at a surface point `q`, the cut surface lies `min_k dist(q, centre path) − R` above it (the
/// ball centres move on straight segments between locations; 5-axis along the normal, so the
/// centre is `tip + R·axis`). Returns the largest such height over a lattice of the patch.
fn largest_residual(s: &NurbsSurface, p: &tezgah_cam::Plan, r: f64, lattice: usize) -> f64 {
    let segments: Vec<(Vec3, Vec3)> = p
        .path
        .passes
        .iter()
        .flat_map(|pass| {
            pass.points
                .windows(2)
                .map(|w| (w[0].tip + w[0].axis * r, w[1].tip + w[1].axis * r))
        })
        .collect();
    let mut worst = 0.0f64;
    for i in 0..=lattice {
        for j in 0..=lattice {
            // The whole patch, edges included (the first and last passes run on them).
            let (u, v) = (i as f64 / lattice as f64, j as f64 / lattice as f64);
            let q = s.point(u, v);
            let d = segments
                .iter()
                .map(|(a, b)| {
                    let ab = b - a;
                    let t = ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    (q - (a + ab * t)).norm()
                })
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d - r);
        }
    }
    worst
}

#[test]
fn material_left_by_a_ball_path_is_the_target_scallop() {
    // Free-form, ball D6, h = 0.1, tight chord tolerance (h/25) so chords add little: the
    // highest residual is the scallop itself — h for iso-scallop (everywhere), and at most h
    // for zig-zag (at its binding point; less elsewhere).
    let s = testing::freeform(0.0);
    let (h, tol) = (0.1, 0.004);
    let within = |worst: f64| worst <= 1.06 * h + tol && worst >= 0.8 * h;
    for kind in [StrategyKind::IsoScallop, StrategyKind::ZigZag] {
        let p = plan(&s, &ball(6.0), &Settings::new(kind, h, tol)).unwrap();
        let worst = largest_residual(&s, &p, 3.0, 90);
        println!("{kind}: largest residual {worst:.4} mm for h = {h}");
        assert!(within(worst), "{kind}: {worst}");
    }
    // Feeding along u on the warped patch (passes across the distorted parametrisation).
    let s = testing::freeform(0.6);
    let mut settings = Settings::new(StrategyKind::IsoScallop, h, tol);
    settings.direction = FeedDirection::AlongU;
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    let worst = largest_residual(&s, &p, 3.0, 90);
    println!("warped free-form along u, iso-scallop: largest residual {worst:.4} mm for h = {h}");
    assert!(within(worst), "{worst}");
    // The saddle, where the iso-scallop front bends slightly on the centre line.
    let s = testing::saddle(50.0, 40.0);
    let p = plan(
        &s,
        &ball(6.0),
        &Settings::new(StrategyKind::IsoScallop, h, tol),
    )
    .unwrap();
    let worst = largest_residual(&s, &p, 3.0, 90);
    println!("saddle iso-scallop: largest residual {worst:.4} mm for h = {h}");
    assert!(within(worst), "{worst}");
}

#[test]
fn one_way_and_two_way_zigzag_differ_only_in_direction() {
    let s = testing::plane(40.0);
    let run = |kind| plan(&s, &ball(6.0), &Settings::new(kind, 0.05, 0.01)).unwrap();
    let (two, one) = (run(StrategyKind::ZigZag), run(StrategyKind::ZigZagOneWay));
    assert_eq!(two.path.passes.len(), one.path.passes.len());
    // Plane 40 mm wide, ball R 3, h 0.05: ω = 2√(2·3·0.05 − 0.05²) = 1.0909 → ⌈40/ω⌉ + 1 passes.
    let w = 2.0 * (0.3f64 - 0.0025).sqrt();
    assert_eq!(one.path.passes.len(), (40.0 / w).ceil() as usize + 1);
    for (k, (a, b)) in two.path.passes.iter().zip(&one.path.passes).enumerate() {
        assert_eq!(b.points[0].uv.1, 0.0, "one-way pass {k} starts at v = 0");
        let start = if k % 2 == 0 { 0.0 } else { 1.0 };
        assert_eq!(a.points[0].uv.1, start, "two-way pass {k}");
        assert!((a.length() - 40.0).abs() < 1e-9 && (b.length() - 40.0).abs() < 1e-9);
    }
}

#[test]
fn curvature_matched_flat_end_beats_the_ball_of_the_same_diameter() {
    // Can (2010, Tables 4.1–4.5): a flat end mill with curvature-matched lead cuts 30–40 % less
    // path than a ball of the same diameter. Free-form patch, D6, iso-scallop, h = 0.04, lead 5°
    // (raised where the cross-feed section is concave, and where the heel would gouge). A tight
    // chord tolerance (a tenth of h), so the material left below is the scallop, not the chords.
    // (It ran at h = 0.01, then 0.04 (−65.5 %), now 0.08 (−53.1 %, a fifth of the time): the
    // ball's step grows as √h while h is small against the radii, the flat end's is near its
    // cap (its radius) already, so the saving shrinks with h and stays above Can's.)
    let s = testing::freeform(0.0);
    let (h, tolerance) = (0.08, 0.008);
    let mut settings = Settings::new(StrategyKind::IsoScallop, h, tolerance);
    let ball_plan = plan(&s, &ball(6.0), &settings).unwrap();
    settings.axis = ToolAxis::Surface {
        lead_deg: 5.0,
        tilt_deg: 0.0,
        max_lead_deg: 30.0,
        match_curvature: true,
    };
    let flat = Cutter::standard(CutterShape::Flat { radius: 3.0 });
    let flat_plan = plan(&s, &flat, &settings).unwrap();
    assert!(
        flat_plan.refused.is_empty(),
        "{:?}",
        flat_plan.refused.first()
    );
    let (lb, lf) = (
        ball_plan.path.cutting_length(),
        flat_plan.path.cutting_length(),
    );
    println!(
        "free-form h = {h}: ball D6 {lb:.0} mm ({} passes), flat D6 at 5° lead {lf:.0} mm ({} passes, {} corrected): −{:.1} %",
        ball_plan.path.passes.len(),
        flat_plan.path.passes.len(),
        flat_plan.corrected,
        100.0 * (1.0 - lf / lb)
    );
    assert!(lf < 0.7 * lb);
    // The flat end's scallop, measured independently: the distance from inner surface points
    // to the tool's bottom disc swept along every move (tip and axis interpolated linearly),
    // minimised over the move by golden-section search.
    let disc = |q: &Vec3, c: &Vec3, a: &Vec3| {
        let d = q - c;
        let z = d.dot(a);
        let rho = (d - a * z).norm();
        if rho <= 3.0 {
            z.abs()
        } else {
            (rho - 3.0).hypot(z)
        }
    };
    let moves: Vec<_> = flat_plan
        .path
        .passes
        .iter()
        .flat_map(|pass| pass.points.windows(2).map(|w| (w[0], w[1])))
        .collect();
    let n = 60;
    let mut worst = 0.0f64;
    for i in 0..=n {
        for j in 0..=n {
            let q = s.point(
                0.1 + 0.8 * i as f64 / n as f64,
                0.1 + 0.8 * j as f64 / n as f64,
            );
            let mut best = f64::INFINITY;
            for (a, b) in &moves {
                let ab = b.tip - a.tip;
                let t = ((q - a.tip).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                if (q - (a.tip + ab * t)).norm() > 4.0 {
                    continue;
                }
                let at = |x: f64| {
                    let tip = a.tip * (1.0 - x) + b.tip * x;
                    let axis = (a.axis * (1.0 - x) + b.axis * x).normalize();
                    disc(&q, &tip, &axis)
                };
                let g = 0.5 * (5f64.sqrt() - 1.0);
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..40 {
                    let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                    if at(x1) < at(x2) {
                        hi = x2;
                    } else {
                        lo = x1;
                    }
                }
                best = best.min(at(0.5 * (lo + hi))).min(at(0.0)).min(at(1.0));
            }
            worst = worst.max(best);
        }
    }
    println!("flat D6: largest residual {worst:.4} mm for h = {h}");
    assert!(worst <= 1.1 * h + tolerance, "{worst}");
}

/// The rational sphere OpenCascade wrote (R 40; u the longitude with its seam at 0 = 2π,
/// v the latitude with the poles at ±π/2).
fn step_sphere() -> NurbsSurface {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/rational_sphere.stp"
    );
    let model = tezgah_cam::step::read_file(path).unwrap();
    model.faces[0].surface.clone()
}

#[test]
fn iso_scallop_along_parallels_covers_a_sphere_from_pole_to_pole() {
    // Fronts start at the south pole (a point: it is cut as one, its normal the limit from
    // inside), march up the sphere as parallels spaced by the exact circle–circle step, and the
    // last pass is the north pole: nothing refused, no pass collapses at a pole.
    let (radius, h) = (40.0, 0.2);
    let s = step_sphere();
    let mut settings = Settings::new(StrategyKind::IsoScallop, h, 0.005);
    settings.direction = FeedDirection::AlongU;
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", &p.refused[..1]);
    let passes = &p.path.passes;
    let pole = |pass: &Pass, z: f64| {
        pass.points
            .iter()
            .all(|c| (c.contact - Vec3::new(0.0, 0.0, z)).norm() < 1e-9 && c.normal.z * z > 0.0)
    };
    assert!(pole(&passes[0], -radius) && pole(&passes[passes.len() - 1], radius));
    // Between the poles every pass is a whole parallel, and neighbouring parallels are the
    // exact step apart (measured between contact polylines; the first and last gaps, to the
    // poles, at most that).
    let want = stepover_exact(3.0, -1.0 / radius, h).unwrap();
    let z = |pass: &Pass| pass.points[0].contact.z;
    for w in passes.windows(2) {
        let from = w[0].points[0].contact;
        let d = if pole(&w[1], radius) {
            (from - w[1].points[0].contact).norm()
        } else {
            distance_to_polyline(&from, &w[1])
        };
        assert!(d <= want * 1.01, "gap {d} vs {want} at z {}", z(&w[0]));
        if !pole(&w[0], -radius) && !pole(&w[1], radius) {
            assert!(d >= want * 0.97, "gap {d} vs {want} at z {}", z(&w[0]));
            let r = w[1].points[0].contact.xy().norm();
            for c in &w[1].points {
                assert!(
                    (c.contact.xy().norm() - r).abs() < 1e-6
                        && (c.contact.z - z(&w[1])).abs() < 1e-6
                );
            }
        }
    }
    // Half the meridian (π·R) over the step, give or take the last gap.
    let expected = (std::f64::consts::PI * radius / want).ceil() as usize + 1;
    assert!(
        (expected - 1..=expected + 1).contains(&passes.len()),
        "{} passes, expected {expected}",
        passes.len()
    );
}

#[test]
fn zigzag_along_u_reaches_the_sphere_poles() {
    // Iso-lines along u at the poles have no length: each is cut as the pole point, with the
    // normal from inside (this was `Degenerate { u: 0, v: −π/2 }`).
    let s = step_sphere();
    let mut settings = Settings::new(StrategyKind::ZigZag, 0.3, 0.005);
    settings.direction = FeedDirection::AlongU;
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.is_empty(), "{:?}", &p.refused[..1]);
    let zs: Vec<f64> = p
        .path
        .passes
        .iter()
        .map(|q| q.points[0].contact.z)
        .collect();
    assert!(
        (zs[0] + 40.0).abs() < 1e-9 && (zs[zs.len() - 1] - 40.0).abs() < 1e-9,
        "{zs:?}"
    );
    for c in p.path.passes.iter().flat_map(|q| &q.points) {
        assert!((c.normal - c.contact / 40.0).norm() < 1e-6, "{c:?}");
    }
}

/// Issue 7's settings for the STEP sphere's cap within 45° of +Z: a ball D6, target scallop
/// `h`, tolerance 0.01 shared as the CLI shares it (the one-sided band), passes along `dir`.
fn sphere_cap_settings(kind: StrategyKind, h: f64, dir: FeedDirection) -> Settings {
    let shares = tezgah_cam::ToleranceShares::of(0.01);
    let mut settings = Settings::new(kind, h, shares.chord);
    settings.band = Some(shares.band());
    settings.gouge.depth_tolerance = 0.0005;
    settings.direction = dir;
    settings.max_axis_tilt_deg = Some(45.0);
    settings
}

/// The dexel simulation of `path` along its own passes over `region` (cell 0.5 mm, poses
/// 0.15 mm apart).
fn simulate_cap(
    s: &NurbsSurface,
    path: &tezgah_cam::ToolPath,
    region: tezgah_cam::verify::MachinedRegion,
) -> tezgah_cam::verify::Verification {
    use tezgah_cam::verify::{path_poses, simulate, VerifyOptions};
    let options = VerifyOptions {
        cell_mm: 0.5,
        sweep_spacing_mm: 0.15,
        region,
    };
    simulate(s, path, &path_poses(path, 0.15), &options).unwrap()
}

const CAP: tezgah_cam::verify::MachinedRegion =
    tezgah_cam::verify::MachinedRegion::Reachable { max_tilt_deg: 45.0 };

#[test]
fn iso_scallop_along_meridians_machines_the_whole_sphere_cap() {
    // Fronts from the seam meridian fold and fan out toward the poles; ends sliding along
    // the feed-end boundaries, fill passes where the gap to the previous front exceeds the
    // step, and the reach edge cut as a pass keep every part of the cap within the target
    // (it left 0.80 mm at the rim of the cap).
    let (radius, h) = (40.0, 0.2);
    let s = step_sphere();
    let settings = sphere_cap_settings(StrategyKind::IsoScallop, h, FeedDirection::AlongV);
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.iter().all(|r| r.refusal == Refusal::OutOfReach));
    let v = simulate_cap(&s, &p.path, CAP);
    eprintln!("{v:?}");
    assert_eq!(v.uncut, 0, "{v:?}");
    assert!(v.max_scallop_mm - v.sweep_bound_mm <= h, "{v:?}");
    assert!(v.max_scallop_mm > 0.75 * h, "{v:?}");
    assert!(v.gouge_depth_mm <= 0.001, "{v:?}");
    // The region judged is the whole cap: from the rim (latitude 45°) to the pole.
    assert!(
        v.region_v.0 <= std::f64::consts::FRAC_PI_4
            && v.region_v.1 >= std::f64::consts::FRAC_PI_2 - 1e-9,
        "{v:?}"
    );
    let rim = radius * std::f64::consts::FRAC_1_SQRT_2;
    let lowest = p
        .path
        .passes
        .iter()
        .flat_map(|q| &q.points)
        .map(|c| c.contact.z)
        .fold(f64::INFINITY, f64::min);
    assert!(
        (lowest - rim).abs() < 1e-6,
        "lowest contact {lowest}, rim {rim}"
    );
}

#[test]
fn a_strip_left_uncut_at_the_rim_of_the_sphere_cap_fails_verification() {
    // The parallels' plan of the cap verifies; without its outermost passes (the reach edge
    // and the lowest parallel) the strip between the next parallel and the rim is left, and
    // the verification over the reachable cap reports it — the contact box, which ends at the
    // lowest remaining pass, does not see it.
    let h = 0.2;
    let s = step_sphere();
    let settings = sphere_cap_settings(StrategyKind::IsoScallop, h, FeedDirection::AlongU);
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    let whole = simulate_cap(&s, &p.path, CAP);
    assert!(
        whole.uncut == 0 && whole.max_scallop_mm - whole.sweep_bound_mm <= h,
        "{whole:?}"
    );
    let lowest = |q: &Pass| {
        q.points
            .iter()
            .map(|c| c.contact.z)
            .fold(f64::INFINITY, f64::min)
    };
    let mut path = p.path.clone();
    for _ in 0..2 {
        let k = (0..path.passes.len())
            .min_by(|&a, &b| lowest(&path.passes[a]).total_cmp(&lowest(&path.passes[b])))
            .unwrap();
        path.passes.remove(k);
    }
    let cut = simulate_cap(&s, &path, CAP);
    assert!(cut.max_scallop_mm - cut.sweep_bound_mm > 2.0 * h, "{cut:?}");
    // Below every remaining pass: in the strip.
    let (_, at) = cut.max_scallop_at.unwrap();
    let remaining = path.passes.iter().map(lowest).fold(f64::INFINITY, f64::min);
    assert!(at.z < remaining, "{cut:?}");
    eprintln!("whole {whole:?}\nwithout {cut:?}");
    let boxed = simulate_cap(&s, &path, tezgah_cam::verify::MachinedRegion::ContactBox);
    assert!(
        boxed.max_scallop_mm - boxed.sweep_bound_mm <= h,
        "{boxed:?}"
    );
}

#[test]
fn a_bull_nose_turns_about_the_sphere_pole_under_a_lead() {
    // Along u the pass at the pole has no length. A bull nose leaning 5° one way covers only
    // the side it leans toward, so the pole cut as one location left 0.42 mm against 0.3 mm
    // 1.4 mm from the pole; turned about the pole, its lean following each parameter's feed
    // direction, it leaves what the passes beside it model (0.15 mm).
    let (h, lead, limit) = (0.3, 5.0, 20.0);
    let s = step_sphere();
    let mut settings = sphere_cap_settings(StrategyKind::ZigZag, h, FeedDirection::AlongU);
    settings.max_axis_tilt_deg = Some(limit);
    if let ToolAxis::Surface { lead_deg, .. } = &mut settings.axis {
        *lead_deg = lead;
    }
    let bull = Cutter::standard(CutterShape::BullNose {
        radius: 5.0,
        corner_radius: 2.0,
    });
    let p = plan(&s, &bull, &settings).unwrap();
    let pole = Vec3::new(0.0, 0.0, 40.0);
    let at_pole: Vec<_> = p
        .path
        .passes
        .iter()
        .filter(|q| q.points.iter().all(|c| (c.contact - pole).norm() < 1e-6))
        .collect();
    assert_eq!(at_pole.len(), 1, "one pass at the pole");
    let turn = &at_pole[0].points;
    let azimuths: Vec<f64> = turn.iter().map(|c| c.axis.y.atan2(c.axis.x)).collect();
    for c in turn {
        let leaned = c.axis.dot(&c.normal).acos().to_degrees();
        assert!((leaned - lead).abs() < 1e-6, "lean {leaned}");
    }
    // The lean turns all the way round, the tip following its circle about the pole in
    // chords whose sagitta is within the tolerance.
    let mut turned = 0.0;
    for w in azimuths.windows(2) {
        turned += (w[1] - w[0] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
    }
    for w in turn.windows(2) {
        let (a, b) = (w[0].tip - pole, w[1].tip - pole);
        let sagitta = a.norm() * (1.0 - (a.angle(&b) / 2.0).cos());
        assert!(sagitta <= settings.tolerance + 1e-9, "{sagitta}");
    }
    assert!(
        (turned.abs() - std::f64::consts::TAU).abs() < 1e-6,
        "{turned}"
    );
    let v = simulate_cap(
        &s,
        &p.path,
        tezgah_cam::verify::MachinedRegion::Reachable {
            max_tilt_deg: limit - lead,
        },
    );
    eprintln!("{v:?}");
    assert_eq!(v.uncut, 0, "{v:?}");
    assert!(v.max_scallop_mm - v.sweep_bound_mm <= h, "{v:?}");
    assert!(v.gouge_depth_mm <= 0.001, "{v:?}");
}

#[test]
fn a_trimmed_face_is_stepped_for_itself_not_for_its_surface() {
    // The saddle z = (x² − y²)/80 fed along x, stepped along v (y = −50 + 100 v): the
    // constant parametric step is narrowest at y = ±50, where the surface is steepest across
    // the feed and a step of v spans 1.6 times the millimetres it does in the middle. Trimmed
    // to y ∈ [−10, 10] (v ∈ [0.4, 0.6]) the face holds no such place, so its step is wider
    // (≈ 1.5×), and the cut still holds the target on the face (simulated within it).
    use tezgah_cam::region::FaceRegion;
    use tezgah_cam::verify::{path_poses, simulate_on, MachinedRegion, VerifyOptions};
    let s = testing::saddle(50.0, 40.0);
    let h = 0.05;
    let shares = tezgah_cam::ToleranceShares::of(0.01);
    let mut settings = Settings::new(StrategyKind::ZigZag, h, shares.chord);
    settings.band = Some(shares.band());
    settings.gouge.depth_tolerance = 0.0005;
    settings.direction = FeedDirection::AlongU;
    let whole = iso_parametric_side_step(&s, &ball(6.0), &settings).unwrap();
    let strip =
        FaceRegion::new(vec![vec![(0.0, 0.4), (1.0, 0.4), (1.0, 0.6), (0.0, 0.6)]]).unwrap();
    settings.region = Some(strip.clone());
    let trimmed = iso_parametric_side_step(&s, &ball(6.0), &settings).unwrap();
    eprintln!("parametric step: surface {whole}, face {trimmed}");
    assert!(trimmed > 1.2 * whole, "{trimmed} vs {whole}");
    let p = plan(&s, &ball(6.0), &settings).unwrap();
    assert!(p.refused.iter().all(|r| r.refusal == Refusal::OutsideFace));
    // Every pass on the face: none spent outside it.
    for q in &p.path.passes {
        assert!(
            q.points
                .iter()
                .all(|c| (0.4 - 1e-9..=0.6 + 1e-9).contains(&c.uv.1)),
            "{:?}",
            q.points[0]
        );
    }
    let options = VerifyOptions {
        cell_mm: 0.1,
        sweep_spacing_mm: 0.1,
        region: MachinedRegion::ContactBox,
    };
    let v = simulate_on(
        &s,
        &p.path,
        &path_poses(&p.path, 0.1),
        &options,
        Some(&strip),
    )
    .unwrap();
    assert_eq!(v.uncut, 0, "{v:?}");
    assert!(v.max_scallop_mm - v.sweep_bound_mm <= h, "{v:?}");
    assert!(v.max_scallop_mm > 0.6 * h, "{v:?}");
    assert!(v.gouge_depth_mm <= 0.001, "{v:?}");
}

#[test]
fn a_ball_keeps_its_lean_on_the_way_back_and_a_flat_end_leads_both_ways() {
    // Zig-zag over a plane with a 10° lead (issue 23): a ball's axis is the same on every
    // pass (it trails on the way back, and cuts the same), so the table does not turn over
    // at the links; a flat end leads on every pass, its axis mirrored on the way back.
    let s = testing::plane(10.0);
    let lead = |shape: CutterShape, deg: f64| {
        let mut settings = Settings::new(StrategyKind::ZigZag, 0.5, 0.05);
        settings.axis = ToolAxis::Surface {
            lead_deg: deg,
            tilt_deg: 0.0,
            max_lead_deg: 30.0,
            match_curvature: true,
        };
        let p = plan(&s, &Cutter::standard(shape), &settings).unwrap();
        assert!(p.path.passes.len() >= 3 && p.refused.is_empty());
        p
    };
    let p = lead(CutterShape::Ball { radius: 3.0 }, 10.0);
    let first = p.path.passes[0].points[0].axis;
    assert!(
        (first.z - 10f64.to_radians().cos()).abs() < 1e-12,
        "{first:?}"
    );
    for cl in p.path.passes.iter().flat_map(|q| &q.points) {
        assert!(
            (cl.axis - first).norm() < 1e-12,
            "{:?} vs {first:?}",
            cl.axis
        );
    }
    let p = lead(CutterShape::Flat { radius: 3.0 }, 5.0);
    let (out, back) = (p.path.passes[0].points[0], p.path.passes[1].points[0]);
    // Leaning toward the feed: the axis' horizontal part along the pass's own direction.
    let along = |q: &Pass| q.points[q.points.len() - 1].contact - q.points[0].contact;
    assert!(out.axis.dot(&along(&p.path.passes[0])) > 0.0);
    assert!(back.axis.dot(&along(&p.path.passes[1])) > 0.0);
}

//! The post-processor on table-ac and table-bc: every output point reproduces its cutter
//! location through the forward kinematics, the machine's motion between points stays within
//! the tolerance (measured densely, independently of the post's own check), limits hold, the
//! table never spins at the pole, and feeds add up.

mod common;

use tezgah_cam::post::{post, FeedOutput, OutputForm, PostError, PostOptions, Posted};
use tezgah_cam::ToolPath;
use tezgah_kinematics::segment::{distance_to_segment, slerp_axis};
use tezgah_kinematics::{Kinematics, Machine, Model, Tool};

use nalgebra::Unit;

const TOOL_LENGTH: f64 = 28.5;

fn options(form: OutputForm, feed_output: FeedOutput) -> PostOptions {
    PostOptions {
        form,
        feed_output,
        tool_number: 2,
        tool_length_mm: TOOL_LENGTH,
        ..PostOptions::new(1200.0, 0.01)
    }
}

/// A ball R = 1.5 on the convex cylinder ρ = 20, ±25°: passes along the circumference when
/// `around`, so the tilt changes inside every pass; along the axis otherwise.
fn cylinder_path(around: bool) -> ToolPath {
    let surface = common::cylinder(20.0, 25f64.to_radians(), 12.0);
    common::zigzag_along(&surface, 1.5, 5, 16, 0.0, around)
}

/// The machine's pose a fraction `t` between two posted points, as the controller moves it.
fn machine_pose(
    machine: &Machine,
    form: OutputForm,
    a: &tezgah_cam::post::PostedPoint,
    b: &tezgah_cam::post::PostedPoint,
    t: f64,
) -> (nalgebra::Vector3<f64>, nalgebra::Vector3<f64>) {
    let tool = Tool::with_length(TOOL_LENGTH);
    match form {
        OutputForm::Joints => {
            let p = machine
                .kinematics
                .forward(&a.joints.lerp(&b.joints, t), &tool)
                .unwrap();
            (p.tip, p.axis.into_inner())
        }
        OutputForm::CentrePoint => {
            // Tip straight; table angles linear, turned into joints and forward again.
            let q = a.joints.lerp(&b.joints, t);
            let tip = a.tip + (b.tip - a.tip) * t;
            let p = machine.kinematics.forward(&q, &tool).unwrap();
            (tip, p.axis.into_inner())
        }
    }
}

/// Every check that does not depend on the form; returns the densest deviation found.
fn check_posted(machine: &Machine, path: &ToolPath, posted: &Posted, form: OutputForm) -> f64 {
    let tool = Tool::with_length(TOOL_LENGTH);
    let reach = 1.5_f64.hypot(1.5);
    let tolerance = 0.01;
    for p in &posted.points {
        machine.kinematics.check_joints(&p.joints).unwrap();
        let pose = machine.kinematics.forward(&p.joints, &tool).unwrap();
        assert!((pose.tip - p.tip).norm() < 1e-9, "{:?}", p.source);
        // Off the pole the axis is exact; at the pole within the held-C cone.
        assert!(reach * pose.axis.angle(&p.axis) <= 0.5 * tolerance + 1e-12);
    }
    // Every cutter location of the path is an output point, in order.
    let mut it = posted
        .points
        .iter()
        .filter(|p| !p.inserted && p.source.is_some());
    for (i, pass) in path.passes.iter().enumerate() {
        for (j, cl) in pass.points.iter().enumerate() {
            let p = it.next().unwrap();
            assert_eq!(p.source, Some((i, j)));
            assert!((p.tip - cl.tip).norm() < 1e-12);
        }
    }
    // Dense, independent measure of the machine's motion against the path. Rapid links stand
    // for no path: the whole tool stays outside the ball holding the part wherever the
    // tool turns on them.
    let mut worst: f64 = 0.0;
    let sphere = posted.stats.clearance.unwrap();
    for w in posted.points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if b.motion == tezgah_cam::post::links::Motion::Rapid {
            if a.axis.angle(&b.axis) > 1e-6 {
                for k in 0..=64 {
                    let (tip, axis) = machine_pose(machine, form, a, b, k as f64 / 64.0);
                    assert!(sphere.is_clear(&tip, &axis), "{a:?} {b:?} at {k}/64");
                }
            }
            continue;
        }
        let (ua, ub) = (Unit::new_normalize(a.axis), Unit::new_normalize(b.axis));
        for k in 1..64 {
            let t = k as f64 / 64.0;
            let (tip, axis) = machine_pose(machine, form, a, b, t);
            let (d, off) = distance_to_segment(&tip, &a.tip, &b.tip);
            let chord = b.tip - a.tip;
            let s = if chord.norm() > 0.0 {
                ((tip - off - a.tip).dot(&chord) / chord.norm_squared()).clamp(0.0, 1.0)
            } else {
                t
            };
            let ideal = slerp_axis(&ua, &ub, s).unwrap();
            worst = worst.max(d + reach * axis.angle(&ideal));
        }
    }
    eprintln!(
        "{form:?}: {} points, {} inserted, post's worst {:.5} mm, dense worst {worst:.5} mm",
        posted.points.len(),
        posted.stats.inserted,
        posted.stats.max_linearisation_mm
    );
    assert!(worst <= tolerance * 1.02, "dense deviation {worst}");
    worst
}

#[test]
fn tcp_output_on_table_ac_reproduces_the_path() {
    let machine = Machine::builtin("table-ac").unwrap();
    for around in [false, true] {
        let path = cylinder_path(around);
        let o = options(OutputForm::CentrePoint, FeedOutput::PerMinute);
        let posted = post(&path, &machine, &o).unwrap();
        check_posted(&machine, &path, &posted, OutputForm::CentrePoint);
        assert!(posted.program.contains("G43.4 H2"));
        assert!(posted.program.contains(" F1200"));
        // The cylinder's axes lie in the X-Z plane: the tilt changes sign across the pole
        // while C stays put (it turns once, from home to ±90°, and never again).
        let c_travel: f64 = posted
            .points
            .windows(2)
            .map(|w| (w[1].angles.c - w[0].angles.c).abs())
            .sum();
        assert!(
            c_travel <= std::f64::consts::FRAC_PI_2 + 1e-9,
            "C travels {c_travel}"
        );
        assert!(posted.points.iter().any(|p| p.angles.tilt < -0.1));
        assert!(posted.points.iter().any(|p| p.angles.tilt > 0.1));
        // Lengths: the cutting length is the path's.
        assert!((posted.stats.cutting_length_mm - path.cutting_length()).abs() < 1e-6);
        let t = 60.0 * (posted.stats.cutting_length_mm + posted.stats.plunge_length_mm) / 1200.0;
        assert!((posted.stats.feed_time_s - t).abs() < 1e-9);
    }
}

#[test]
fn joint_output_inserts_points_and_maps_back_through_the_gcode() {
    let machine = Machine::builtin("table-ac").unwrap();
    let path = cylinder_path(true);
    let o = options(OutputForm::Joints, FeedOutput::InverseTime);
    let posted = post(&path, &machine, &o).unwrap();
    // The part lies 120 mm from the A axis: 2° steps of A sag 0.02 mm between points.
    assert!(posted.stats.inserted > 0, "{:?}", posted.stats);
    check_posted(&machine, &path, &posted, OutputForm::Joints);
    assert!(posted.program.contains("G43 H2") && posted.program.contains("G93"));
    // Read the blocks back: X Y Z are the tip in machine coordinates (Z + tool length = the
    // gauge point), A C the table; forward kinematics gives the posted tip to the printed
    // precision. The inverse-time F words add up to the feed time.
    let tool = Tool::with_length(TOOL_LENGTH);
    let blocks: Vec<&str> = posted
        .program
        .lines()
        .filter(|l| l.starts_with("G0 X") || l.starts_with("G1 X"))
        .collect();
    assert_eq!(blocks.len(), posted.points.len());
    let mut minutes = 0.0;
    for (line, p) in blocks.iter().zip(&posted.points) {
        let word = |c: char| -> f64 {
            line.split(' ')
                .find_map(|w| w.strip_prefix(c))
                .map(|v| v.parse().unwrap())
                .unwrap()
        };
        let q = machine
            .from_file_units(&[
                word('X'),
                word('Y'),
                word('Z') + TOOL_LENGTH,
                word('A'),
                word('C'),
            ])
            .unwrap();
        let tip = machine.kinematics.forward(&q, &tool).unwrap().tip;
        assert!((tip - p.tip).norm() < 2e-4, "{line}: {tip} vs {}", p.tip);
        if line.starts_with("G1") {
            minutes += 1.0 / word('F');
        }
    }
    assert!((minutes * 60.0 - posted.stats.feed_time_s).abs() < 1e-3 * posted.stats.feed_time_s);
}

#[test]
fn table_bc_posts_too() {
    let machine = Machine::builtin("table-bc").unwrap();
    let path = cylinder_path(true);
    for form in [OutputForm::CentrePoint, OutputForm::Joints] {
        let posted = post(&path, &machine, &options(form, FeedOutput::PerMinute)).unwrap();
        check_posted(&machine, &path, &posted, form);
        assert_eq!(posted.rotary_letters, ['B', 'C']);
        assert!(posted.program.contains(" B"));
    }
}

#[test]
fn unreachable_and_unsupported_are_errors() {
    // A table-ac that tilts only ±10° cannot reach the cylinder's 25° flanks.
    let text = Machine::builtin_text("table-ac")
        .unwrap()
        .replace("min = -30.0\nmax = 120.0", "min = -10.0\nmax = 10.0");
    let narrow = Machine::from_toml_str(&text).unwrap();
    let path = cylinder_path(false);
    let o = options(OutputForm::CentrePoint, FeedOutput::PerMinute);
    match post(&path, &narrow, &o) {
        Err(PostError::Kinematics {
            at: Some((0, 0)),
            error,
        }) => {
            assert!(error.to_string().contains('a'), "{error}")
        }
        other => panic!("{other:?}"),
    }
    let mill = Machine::builtin("mill3").unwrap();
    assert!(matches!(mill.kinematics, Model::Cartesian(_)));
    assert!(matches!(
        post(&path, &mill, &o),
        Err(PostError::Machine("cartesian"))
    ));
    let mut bad = path.clone();
    bad.passes[1].points[3].axis = nalgebra::Vector3::zeros();
    assert!(matches!(
        post(&bad, &Machine::builtin("table-ac").unwrap(), &o),
        Err(PostError::BadLocation { pass: 1, point: 3 })
    ));
    for (feed, tol) in [(0.0, 0.01), (1000.0, f64::NAN)] {
        let o = PostOptions::new(feed, tol);
        assert!(matches!(
            post(&path, &Machine::builtin("table-ac").unwrap(), &o),
            Err(PostError::Option { .. })
        ));
    }
}

#[test]
fn tcp_output_inserts_points_where_c_turns() {
    // A ring under a tool tilted 30° that turns with it (C steps of 30°): under TCP the table
    // angles move linearly, so the axis runs on a small circle instead of the great circle
    // between the two axes — 0.02 mm at the reach of a D = 3 ball, over the tolerance.
    let machine = Machine::builtin("table-ac").unwrap();
    let tilt = 30f64.to_radians();
    let points = (0..=12)
        .map(|k| {
            let c = (k as f64 * 30.0).to_radians();
            let axis = tezgah_kinematics::table_ac::axis(tilt, c);
            let tip = nalgebra::Vector3::new(10.0 * c.cos(), 10.0 * c.sin(), 0.0);
            tezgah_cam::CutterLocation {
                tip,
                axis,
                contact: tip,
                normal: axis,
                uv: (0.0, c),
            }
        })
        .collect();
    let path = ToolPath {
        cutter: tezgah_cam::Cutter::standard(tezgah_cam::CutterShape::Ball { radius: 1.5 }),
        passes: vec![tezgah_cam::Pass { points }],
    };
    let posted = post(
        &path,
        &machine,
        &options(OutputForm::CentrePoint, FeedOutput::PerMinute),
    )
    .unwrap();
    assert!(posted.stats.inserted >= 12, "{:?}", posted.stats);
    check_posted(&machine, &path, &posted, OutputForm::CentrePoint);
    // C runs continuously through a whole turn.
    let last = posted
        .points
        .iter()
        .rev()
        .find(|p| p.source.is_some())
        .unwrap();
    assert!(
        (last.angles.c.to_degrees() - 360.0).abs() < 1e-9,
        "{}",
        last.angles.c.to_degrees()
    );
}

#[test]
fn the_posted_joint_program_cuts_without_gouging() {
    // The program as the machine moves it — links, plunges, inserted points and all — swept
    // through the dexel simulation: no gouge beyond the path's own chord sag plus the
    // linearisation tolerance (the two add), and the scallop between passes 1.5 mm apart is
    // the closed form's for a D = 3 ball on ρ = 20.
    let machine = Machine::builtin("table-ac").unwrap();
    let surface = common::cylinder(20.0, 25f64.to_radians(), 12.0);
    let path = common::zigzag_along(&surface, 1.5, 9, 16, 0.0, true);
    let o = options(OutputForm::Joints, FeedOutput::InverseTime);
    let posted = post(&path, &machine, &o).unwrap();
    let poses = posted.sweep(&machine, 0.1).unwrap();
    let s = tezgah_cam::verify::step_over(&path).unwrap();
    let v = tezgah_cam::verify::simulate(
        &surface,
        &path,
        &poses,
        &tezgah_cam::verify::VerifyOptions {
            cell_mm: s / 10.0,
            sweep_spacing_mm: 0.1,
            region: tezgah_cam::verify::MachinedRegion::ContactBox,
        },
    )
    .unwrap();
    // The ball centres run on chords of the radius-21.5 circle: sag (ρ + R)(1 − cos(Δθ/2)).
    let step = path.passes[0]
        .points
        .windows(2)
        .map(|w| w[0].normal.angle(&w[1].normal))
        .fold(0.0, f64::max);
    let sag = 21.5 * (1.0 - (step / 2.0).cos());
    assert!(v.gouge_depth_mm > 0.5 * sag, "the chords do cut in: {v:?}");
    assert!(v.gouge_depth_mm <= sag + o.tolerance_mm, "sag {sag}: {v:?}");
    // Passes along the circumference: the ridge runs around the cylinder between ball
    // centres 1.5 mm apart along Y at radius ρ + R, so its height above the surface is the
    // plane's R − √(R² − (s/2)²) measured along the normal.
    let h = 1.5 - (2.25_f64 - 0.75_f64.powi(2)).sqrt();
    assert!((s - 1.5).abs() < 1e-9, "{s}");
    assert!(
        v.max_scallop_mm <= h + v.sweep_bound_mm + 1e-9 && v.max_scallop_mm >= h - v.grid_bound_mm,
        "{} vs {h}: {v:?}",
        v.max_scallop_mm
    );
}

mod no_panic {
    use super::*;
    use proptest::prelude::*;
    use tezgah_cam::{Cutter, CutterLocation, CutterShape, Pass};

    fn location() -> impl Strategy<Value = CutterLocation> {
        (
            proptest::array::uniform3(-60.0f64..60.0),
            proptest::array::uniform3(-1.0f64..1.0),
        )
            .prop_map(|(t, a)| {
                let tip = nalgebra::Vector3::from(t);
                let axis = nalgebra::Vector3::from(a);
                CutterLocation {
                    tip,
                    axis,
                    contact: tip,
                    normal: axis,
                    uv: (0.0, 0.0),
                }
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any path, feed and tolerance: a program whose every joint is within limits, or an
        /// error — never a panic.
        #[test]
        fn any_path_posts_or_fails_cleanly(
            passes in proptest::collection::vec(proptest::collection::vec(location(), 0..6), 0..4),
            feed in prop_oneof![Just(0.0), Just(f64::NAN), 1.0f64..5000.0],
            tolerance in prop_oneof![Just(-1.0), 1e-4f64..0.1],
            joints in any::<bool>(),
            bc in any::<bool>(),
        ) {
            let machine = Machine::builtin(if bc { "table-bc" } else { "table-ac" }).unwrap();
            let path = ToolPath {
                cutter: Cutter::standard(CutterShape::Ball { radius: 2.0 }),
                passes: passes.into_iter().map(|points| Pass { points }).collect(),
            };
            let o = PostOptions {
                form: if joints { OutputForm::Joints } else { OutputForm::CentrePoint },
                ..PostOptions::new(feed, tolerance)
            };
            if let Ok(posted) = post(&path, &machine, &o) {
                prop_assert!(posted.program.ends_with("M2\n"));
                for p in &posted.points {
                    prop_assert!(machine.kinematics.check_joints(&p.joints).is_ok());
                }
            }
        }
    }
}

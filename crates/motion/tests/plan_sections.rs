//! Planning sections (long splines cut at their knots): the sections are the same path — they
//! join end to end exactly, their lengths add up to the segment's, the rotary axes and an
//! inverse-time feed are shared in proportion to length — and planning by sections keeps every
//! joint within its limits while the speed follows the curvature along the spline.

use tezgah_geom::{Curve, Move, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::sections::sections;
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::Verifier;
use tezgah_motion::{PathItem, SegmentFeed};

/// A saw-tooth of 0.7 mm moves turning `deg` at every vertex: short moves with small turns,
/// which the smoother compresses into one wavy spline per run.
fn saw(deg: f64) -> Vec<Move> {
    let h = deg.to_radians() / 2.0;
    let mut s = String::from("G21 G90 G94 G64\nF3000\nG0 X-150 Y0 Z1\nG1 Z0\n");
    let (mut x, mut y) = (-150.0, 0.0);
    for k in 0..60 {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        x += 0.7 * h.cos();
        y += sign * 0.7 * h.sin();
        s.push_str(&format!("G1 X{x:.4} Y{y:.4}\n"));
    }
    s.push_str("M2\n");
    tezgah_gcode::program_moves(&s, tezgah_gcode::Config::default()).unwrap()
}

fn items(moves: &[Move]) -> Vec<PathItem> {
    smooth::build(
        moves.iter().cloned(),
        &SmoothOptions {
            tolerance: 0.01,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap()
}

#[test]
fn sections_are_the_same_path() {
    let mut cut = 0;
    for deg in [10.0, 20.0, 25.0] {
        for item in items(&saw(deg)) {
            let PathItem::Segment(mut seg) = item else {
                continue;
            };
            // Give the spline a rotary move and an inverse-time feed to share.
            seg.rotary = [[0.0, 10.0, -5.0], [30.0, 10.0, 40.0]];
            seg.feed = SegmentFeed::InverseTime(2.0);
            let (a, b) = seg.curve.domain();
            let (start, end, length) = (seg.curve.point(a), seg.curve.point(b), seg.length);
            let end_junction = seg.end;
            let parts = sections(seg, 1.0);
            if parts.len() > 1 {
                cut += 1;
            }
            let total: f64 = parts.iter().map(|p| p.length).sum();
            assert!((total - length).abs() <= 1e-12 * length.max(1.0));
            let first = &parts[0];
            assert_eq!(first.curve.point(first.curve.domain().0), start);
            let last = parts.last().unwrap();
            assert_eq!(last.curve.point(last.curve.domain().1), end);
            assert_eq!(last.end, end_junction);
            assert_eq!(last.rotary[1], [30.0, 10.0, 40.0]);
            let mut s = 0.0;
            let mut time = 0.0;
            for (k, p) in parts.iter().enumerate() {
                // Each section's length is its arc length.
                let l = p.curve.length();
                assert!(
                    (l - p.length).abs() <= 1e-8 * l.max(1.0),
                    "{l} vs {}",
                    p.length
                );
                if parts.len() > 1 {
                    assert!(p.length >= 1.0 || k + 1 == parts.len());
                }
                // Rotary axes linear in arc length over the whole segment.
                for i in 0..3 {
                    let r0 = [0.0, 10.0, -5.0][i];
                    let r1 = [30.0, 10.0, 40.0][i];
                    let want = r0 + (r1 - r0) * s / length;
                    assert!((p.rotary[0][i] - want).abs() <= 1e-9);
                }
                if let SegmentFeed::InverseTime(t) = p.feed {
                    time += t;
                }
                if k + 1 < parts.len() {
                    let q = &parts[k + 1];
                    assert_eq!(
                        p.curve.point(p.curve.domain().1),
                        q.curve.point(q.curve.domain().0)
                    );
                    assert_eq!(p.rotary[1], q.rotary[0]);
                }
                s += p.length;
            }
            assert!((time - 2.0).abs() <= 1e-12);
        }
    }
    assert!(cut > 0, "no spline was cut");
}

/// Duration and worst peak/limit of the saw on `mill3`, planned with `section_length`.
fn plan_saw(deg: f64, section_length: f64) -> (f64, f64) {
    let machine = Machine::default_machine();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s);
    let d = run(
        items(&saw(deg)),
        pm,
        PlanOptions {
            chord_share: smooth::CHORD_SHARE,
            section_length,
            ..PlanOptions::default()
        },
        (Vec3::zeros(), [0.0; 3]),
        |s, seg| verifier.push(s, seg),
    )
    .unwrap();
    let report = verifier.finish();
    let worst = report
        .joints
        .iter()
        .map(|j| j.worst_ratio())
        .fold(0.0, f64::max);
    assert!(report.max_deviation <= 0.01);
    (d, worst)
}

#[test]
fn sections_hold_the_limits_and_let_the_speed_follow_the_curvature() {
    for deg in [10.0, 20.0] {
        let (whole, worst_whole) = plan_saw(deg, 0.0);
        let (cut, worst_cut) = plan_saw(deg, 1.0);
        assert!(
            worst_whole <= 1.005 && worst_cut <= 1.005,
            "{worst_whole} {worst_cut}"
        );
        // A whole spline runs at its tightest wiggle's speed: cut, the rest runs faster.
        assert!(cut < whole, "{deg}°: {cut} s in sections, {whole} s whole");
    }
}

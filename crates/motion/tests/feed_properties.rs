//! The feed planner on random contours as `tezgah run` builds them (smoothing, blends at
//! corners and at tangent line–arc junctions, speed steps on long arcs and helices): every
//! sample within every joint's velocity, acceleration and jerk by finite differences at the
//! period (0.5 % over at most), the smoothed path within the tolerance of the program, and
//! the samples within the chord error of the smoothed path.

#[path = "../benches/common/mod.rs"]
mod common;

use proptest::prelude::*;
use tezgah_geom::{ArcMove, Move, MoveKind, PathMode, Plane, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::deviation;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::verify::Verifier;

/// One random contour: lines, arcs tangent to the line before them (a line into a fillet),
/// arcs at an angle, helices, and feeds, under G64 with the machine's tolerance.
fn contour(seed: u64, n: usize) -> Vec<Move> {
    let mut rng = common::Rng(seed | 1);
    let mut r = || rng.unit();
    let mv = |line: u32, kind| Move { line, kind };
    let mut m = vec![
        mv(
            1,
            MoveKind::FeedRate {
                value: 1200.0 + 10_800.0 * r(),
            },
        ),
        mv(
            2,
            MoveKind::PathMode(PathMode::Continuous { tolerance: None }),
        ),
    ];
    let (mut p, mut dir) = (Vec3::zeros(), Vec3::new(1.0, 0.0, 0.0));
    for i in 0..n {
        let line = 3 + i as u32;
        let k = r();
        if k < 0.1 {
            m.push(mv(
                line,
                MoveKind::FeedRate {
                    value: 1200.0 + 10_800.0 * r(),
                },
            ));
        } else if k < 0.5 && p.xy().norm() < 40.0 {
            // A tangent arc (or helix) of radius 1–30 mm turning 20°–340°.
            let radius = 1.0 + 29.0 * r() * r();
            let turn = if r() < 0.5 { 1 } else { -1 };
            let normal = Vec3::new(-dir.y, dir.x, 0.0) * f64::from(turn);
            let centre = p + normal * radius;
            let sweep = (20.0 + 320.0 * r()).to_radians() * f64::from(turn);
            let start = (p - centre).y.atan2((p - centre).x);
            let a = start + sweep;
            let rise = if r() < 0.3 { 5.0 * (r() - 0.5) } else { 0.0 };
            let end = Vec3::new(
                centre.x + radius * a.cos(),
                centre.y + radius * a.sin(),
                p.z + rise,
            );
            m.push(mv(
                line,
                MoveKind::Arc(ArcMove {
                    plane: Plane::XY,
                    end: Pose::new(end.x, end.y, end.z, 0.0, 0.0, 0.0),
                    center: [centre.x, centre.y],
                    turn,
                }),
            ));
            let radial = (end - centre).normalize();
            dir = Vec3::new(-radial.y, radial.x, 0.0) * f64::from(turn);
            p = end;
        } else {
            // A line along the tangent (a fillet's exit), or turned by up to ±120°.
            let turn = if r() < 0.5 {
                0.0
            } else {
                (240.0 * (r() - 0.5)).to_radians()
            };
            let (s, c) = turn.sin_cos();
            dir = Vec3::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y, 0.0);
            // Far out, back toward the middle of the table (a corner).
            if p.xy().norm() >= 40.0 {
                dir = Vec3::new(-p.x, -p.y, 0.0).normalize();
            }
            let length = 0.5 + 40.0 * r() * r();
            let q = p + dir * length + Vec3::new(0.0, 0.0, 2.0 * (r() - 0.5));
            m.push(mv(
                line,
                MoveKind::Feed {
                    end: Pose::new(q.x, q.y, q.z, 0.0, 0.0, 0.0),
                },
            ));
            dir = Vec3::new((q - p).x, (q - p).y, 0.0).normalize();
            p = q;
        }
    }
    m
}

fn check(moves: &[Move], machine: &Machine) {
    let tolerance = machine.motion.tolerance_mm;
    let items = common::smooth_items(moves, machine);
    let off = deviation(Pose::ZERO, moves, &items);
    assert!(off <= tolerance, "smoothed path {off} mm off the program");
    let pm = PlanMachine::from_machine(machine).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s);
    run(
        items,
        pm,
        common::plan_options(machine),
        (Vec3::zeros(), [0.0; 3]),
        |s, segs| verifier.push(s, segs),
    )
    .unwrap();
    let report = verifier.finish();
    common::assert_joints_within(&report);
    assert!(
        report.max_deviation + off <= tolerance * (1.0 + 1e-9),
        "samples {} mm off the smoothed path, which is {off} mm off the program",
        report.max_deviation
    );
}

/// The issue's mill and the built-in one.
fn machines() -> [Machine; 2] {
    [common::issue_mill(), Machine::default_machine()]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_contours_hold_every_limit(seed in any::<u64>(), which in 0usize..2) {
        let machine = &machines()[which];
        check(&contour(seed, 30), machine);
    }
}

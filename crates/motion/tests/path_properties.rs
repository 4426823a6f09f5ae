//! Properties of the smoothing builder on thousands of random programs (polylines with every
//! kind of turn, dense short runs that compress, chains of lines, arcs and helices): the path
//! stays within the compression + blend shares of the tolerance of the program (both ways),
//! position, tangent and curvature continue at every Smooth joint (measured, 1e-9 relative),
//! corners and the end point are programmed points exactly, nothing is NaN, nothing panics.

mod path_support;

use std::f64::consts::PI;

use path_support::*;
use proptest::prelude::*;
use tezgah_geom::{Move, PathMode, Pose, Vec3};
use tezgah_motion::path::smooth::{build, SmoothOptions};
use tezgah_motion::path::{deviation, Junction};

/// One step of a random program.
#[derive(Debug, Clone)]
enum Step {
    /// Turn the heading by `turn` (rad, in XY), go `len` mm, climbing `dz`, turning A by `da`°.
    Line {
        turn: f64,
        len: f64,
        dz: f64,
        da: f64,
    },
    /// An arc of radius `r` and signed sweep, starting at `offset` rad off the tangent
    /// direction (0 = tangent to the previous move), rising `dz` (a helix).
    Arc {
        offset: f64,
        r: f64,
        sweep: f64,
        dz: f64,
    },
}

fn rot(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, 0.0)
}

/// The moves and their end points (start first).
fn program(steps: &[Step], tol: f64) -> (Vec<Move>, Vec<Vec3>) {
    let mut moves = vec![
        feed(1, 1200.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(tol),
            },
        ),
    ];
    let mut pos = Vec3::zeros();
    let mut heading = Vec3::x();
    let mut verts = vec![pos];
    let mut a = 0.0;
    for (i, s) in steps.iter().enumerate() {
        let line = i as u32 + 3;
        match *s {
            Step::Line { turn, len, dz, da } => {
                heading = rot(heading, turn);
                let end = pos + heading * len + Vec3::new(0.0, 0.0, dz);
                a += da;
                moves.push(g1a(line, end, a));
                pos = end;
            }
            Step::Arc {
                offset,
                r,
                sweep,
                dz,
            } => {
                let side = if sweep > 0.0 { PI / 2.0 } else { -PI / 2.0 };
                let c = pos + rot(heading, side + offset) * r;
                let mut end = c + rot(pos - c, sweep);
                end.z = pos.z + dz;
                let turn = if sweep > 0.0 { 1 } else { -1 };
                let mut mv = arc_xy(line, end, [c.x, c.y], turn);
                if let tezgah_geom::MoveKind::Arc(ref mut am) = mv.kind {
                    am.end.0[3] = a;
                }
                moves.push(mv);
                let radial = end - c;
                let tangent = rot(Vec3::new(radial.x, radial.y, 0.0), side);
                heading = tangent.normalize();
                pos = end;
            }
        }
        verts.push(pos);
    }
    (moves, verts)
}

fn turn() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -PI..PI,
        1 => -0.3..0.3f64,
        1 => Just(0.0),
        1 => Just(PI),
        1 => Just(PI / 2.0),
        1 => -1e-6..1e-6f64,
    ]
}

fn length() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => (-1.5..1.0f64).prop_map(|e| 10f64.powf(e)),
        1 => Just(0.0),
        1 => 0.05..0.3f64,
    ]
}

fn line_step() -> impl Strategy<Value = Step> {
    (
        turn(),
        length(),
        prop_oneof![3 => Just(0.0), 1 => -1.0..1.0f64],
        prop_oneof![3 => Just(0.0), 1 => -20.0..20.0f64],
    )
        .prop_map(|(turn, len, dz, da)| Step::Line { turn, len, dz, da })
}

fn arc_step() -> impl Strategy<Value = Step> {
    (
        prop_oneof![Just(0.0), -1.0..1.0f64],
        (-1.0..1.5f64).prop_map(|e| 10f64.powf(e)),
        prop_oneof![0.05..5.0f64, -5.0..-0.05f64],
        prop_oneof![5 => Just(0.0), 1 => -2.0..2.0f64],
    )
        .prop_map(|(offset, r, sweep, dz)| Step::Arc {
            offset,
            r,
            sweep,
            dz,
        })
}

fn tolerance() -> impl Strategy<Value = f64> {
    (-3.0..-1.0f64).prop_map(|e| 10f64.powf(e))
}

fn check(steps: &[Step], tol: f64, window: usize) -> Result<(), TestCaseError> {
    let (moves, verts) = program(steps, tol);
    let opts = SmoothOptions {
        window,
        ..SmoothOptions::default()
    };
    let items = match build(moves.clone(), &opts) {
        Ok(i) => i,
        // Only arcs this generator cannot make (a zero radius) may fail.
        Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
    };
    check_path(&items, &verts).map_err(TestCaseError::fail)?;
    let d = deviation(Pose::ZERO, &moves, &items);
    let scale = verts.iter().map(|v| v.norm()).fold(1.0, f64::max);
    let bound = (opts.compression_share + opts.blend_share) * tol + 1e-9 * scale;
    prop_assert!(d <= bound, "deviation {} > {}", d, bound);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn random_polylines(steps in prop::collection::vec(line_step(), 1..30), tol in tolerance(),
                        window in prop_oneof![Just(512usize), 1..8usize]) {
        check(&steps, tol, window)?;
    }

}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn random_arc_chains(steps in prop::collection::vec(prop_oneof![line_step(), arc_step()], 1..20),
                         tol in tolerance()) {
        check(&steps, tol, 512)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Dense short moves with gentle turns and an occasional sharp one: compression territory.
    #[test]
    fn dense_runs_compress_within_tolerance(
        steps in prop::collection::vec(
            prop_oneof![
                8 => (-0.2..0.2f64, 0.05..0.3f64, -0.02..0.02f64)
                    .prop_map(|(turn, len, dz)| Step::Line { turn, len, dz, da: 0.0 }),
                1 => line_step(),
            ],
            4..120),
        tol in tolerance(),
    ) {
        check(&steps, tol, 512)?;
    }
}

/// Any move at all, including nonsense: non-finite coordinates, zero and huge values, arcs with
/// the start on the centre, every mode, feed and stop.
fn any_move() -> impl Strategy<Value = Move> {
    use tezgah_geom::{ArcMove, FeedMode, MoveKind, Plane, StopKind};
    let coord = prop_oneof![
        6 => -10.0..10.0f64,
        1 => Just(0.0),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(1e300),
        1 => -1e-12..1e-12f64,
    ];
    let pose = prop::array::uniform6(coord.clone()).prop_map(Pose);
    let kind = prop_oneof![
        3 => pose.clone().prop_map(|end| MoveKind::Feed { end }),
        1 => pose.clone().prop_map(|end| MoveKind::Rapid { end }),
        2 => (pose, coord.clone(), coord.clone(), -3..3i32, 0..3usize).prop_map(|(end, i, j, turn, p)| {
            MoveKind::Arc(ArcMove {
                plane: [Plane::XY, Plane::ZX, Plane::YZ][p],
                end,
                center: [i, j],
                turn,
            })
        }),
        1 => coord.clone().prop_map(|value| MoveKind::FeedRate { value }),
        1 => (0..3usize).prop_map(|k| MoveKind::FeedMode(
            [FeedMode::InverseTime, FeedMode::UnitsPerMinute, FeedMode::UnitsPerRevolution][k])),
        1 => prop_oneof![
            Just(PathMode::ExactStop),
            Just(PathMode::ExactPath),
            prop::option::of(coord.clone()).prop_map(|tolerance| PathMode::Continuous { tolerance }),
        ].prop_map(MoveKind::PathMode),
        1 => coord.prop_map(|seconds| MoveKind::Dwell { seconds }),
        1 => Just(MoveKind::Stop(StopKind::End)),
    ];
    (1..1000u32, kind).prop_map(|(line, kind)| Move { line, kind })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// No input panics; a path that is built has no NaN in it.
    #[test]
    fn no_input_panics(body in prop::collection::vec(any_move(), 0..25), window in 1..6usize) {
        let mut moves = vec![feed(1, 600.0)];
        moves.extend(body);
        let opts = SmoothOptions { window, ..SmoothOptions::default() };
        if let Ok(items) = build(moves, &opts) {
            for s in segments(&items) {
                let (a, b) = s.curve.domain();
                prop_assert!(s.length.is_finite() && a.is_finite() && b.is_finite());
                for k in 0..=4 {
                    let p = s.curve.point(a + (b - a) * k as f64 / 4.0);
                    prop_assert!(p.iter().all(|c| c.is_finite()), "{:?}", s);
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Issue 4's C² requirement where the program allows it: a G64 program of short moves that
    /// turn gently (compressed runs, the spline cuts for the planner, blends between runs and
    /// the lines a hooked fit leaves) has only `Smooth` joints up to its final stop — no
    /// `Tangent` (curvature jump) and no `Corner` — and `check_path` measures each one:
    /// position, unit tangent and curvature vector continue within 1e-9.
    #[test]
    fn gentle_dense_runs_are_g2_everywhere(
        steps in prop::collection::vec(
            (-0.2..0.2f64, 0.05..0.3f64, -0.02..0.02f64)
                .prop_map(|(turn, len, dz)| Step::Line { turn, len, dz, da: 0.0 }),
            4..120),
        tol in tolerance(),
        window in prop_oneof![Just(512usize), 5..40usize],
    ) {
        check(&steps, tol, window)?;
        let (moves, _) = program(&steps, tol);
        let opts = SmoothOptions { window, ..SmoothOptions::default() };
        let items = build(moves, &opts).map_err(|e| TestCaseError::fail(format!("{e}")))?;
        let segs = segments(&items);
        for (i, s) in segs.iter().enumerate() {
            let want = if i + 1 == segs.len() { Junction::Stop } else { Junction::Smooth };
            prop_assert_eq!(s.end, want, "segment {} of {}", i, segs.len());
        }
    }
}

//! A programmed NURBS move (G06.2, G5, G5.1, G5.2) through both path builders: one segment of
//! the curve's own length (Kelekçi, 2021, data (2.39)), a corner or tangent junction at its ends
//! chosen as for an arc, blended within the tolerance under G64, never compressed.

mod path_support;

use std::sync::Arc;

use path_support::*;
use tezgah_geom::{Move, MoveKind, Nurbs, NurbsMove, PathMode, Pose, Vec3};
use tezgah_motion::path::direct::{self, DirectOptions};
use tezgah_motion::path::smooth::{build, SmoothOptions};
use tezgah_motion::path::{deviation, Junction};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Kelekçi (2021), data (2.39): the clamped cubic from (0, 0) to (18, 1), 19.0203 mm long.
fn thesis_curve() -> Nurbs {
    let x = [0.0, 2.5, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0];
    let y = [0.0, 2.3, 1.5, 2.4, 1.0, 2.0, 1.0, 2.0, 0.0, 1.0];
    let pts: Vec<Vec3> = x.iter().zip(y).map(|(&x, y)| v(x, y, 0.0)).collect();
    let knots = vec![
        0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 7.0, 7.0, 7.0,
    ];
    Nurbs::new(3, &pts, &[1.0; 10], knots).unwrap()
}

fn nurbs(line: u32) -> Move {
    Move {
        line,
        kind: MoveKind::Nurbs(NurbsMove {
            curve: Arc::new(thesis_curve()),
            end: Pose::new(18.0, 1.0, 0.0, 0.0, 0.0, 0.0),
        }),
    }
}

const GOLDEN_LENGTH: f64 = 19.0203;

#[test]
fn direct_builder_makes_one_segment_with_corner_or_tangent_ends() {
    // The curve ends heading along (2, 1): a turn to +Y is a corner, going on along (2, 1)
    // is tangent.
    for (next, junction) in [
        (v(18.0, 10.0, 0.0), Junction::Corner),
        (v(22.0, 3.0, 0.0), Junction::Tangent),
    ] {
        let moves = [
            feed(1, 1200.0),
            mode(2, PathMode::ExactPath),
            nurbs(3),
            g1(4, next),
        ];
        let items = direct::build(&moves, Pose::ZERO, DirectOptions::default()).unwrap();
        let segs = segments(&items);
        assert_eq!(segs.len(), 2);
        assert_eq!(segs[0].line, 3);
        assert!(
            (segs[0].length - GOLDEN_LENGTH).abs() < 5e-5,
            "{}",
            segs[0].length
        );
        assert_eq!(segs[0].end, junction);
        assert!((end_point(segs[0]) - v(18.0, 1.0, 0.0)).norm() < 1e-12);
    }
}

#[test]
fn smoothing_builder_blends_at_the_ends_and_never_compresses_the_curve() {
    // Compression on, short lines before and after: the lines may be refitted, the NURBS stays
    // the programmed curve, trimmed only by the blends at its ends.
    let mut moves = vec![
        feed(1, 1200.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(0.01),
            },
        ),
        Move {
            line: 3,
            kind: MoveKind::Smoothing(true),
        },
    ];
    moves.push(g1(4, v(-10.0, 0.0, 0.0)));
    for k in 1..=20 {
        let x = -10.0 + 0.5 * k as f64;
        let y = if k == 20 {
            0.0
        } else {
            0.2 * (k as f64 * 0.3).sin()
        };
        moves.push(g1(4 + k, v(x, y, 0.0)));
    }
    moves.push(nurbs(25));
    moves.push(g1(26, v(18.0, 8.0, 0.0)));
    let items = build(moves.iter().cloned(), &SmoothOptions::default()).unwrap();
    let segs = segments(&items);
    let on_curve: Vec<_> = segs.iter().filter(|s| s.line == 25).collect();
    // The curve's own piece (line 25) is one segment, a little shorter than the whole curve
    // (trimmed by the blends), followed by a blend.
    let piece = on_curve
        .iter()
        .max_by(|a, b| a.length.total_cmp(&b.length))
        .unwrap();
    assert!(piece.length < GOLDEN_LENGTH && piece.length > GOLDEN_LENGTH - 0.5);
    assert_eq!(piece.end, Junction::Smooth);
    // Every sample of the built path within the tolerance of the programmed one.
    let d = deviation(Pose::ZERO, &moves, &items);
    assert!(d <= 0.01 + 1e-9, "deviation {d}");
}

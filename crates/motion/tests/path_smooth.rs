//! The smoothing builder on hand-made programs: Kahraman et al.'s corner blend (§3) at the
//! tolerance-exact leg, G61 and G61.1, tangent and collinear junctions, reversals, zero-length
//! and rotary-only moves, errors, streaming windows, and the compression ratio on a dense
//! surfacing program.

mod path_support;

use path_support::*;
use tezgah_geom::{Curve, FeedMode, Move, MoveKind, PathMode, Pose, StopKind, Vec3};
use tezgah_motion::path::smooth::{build, PathError, SmoothOptions, Smoother};
use tezgah_motion::path::{deviation, Junction, PathItem, SegmentFeed};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn square(tol: Option<f64>) -> Vec<Move> {
    let mut m = vec![feed(1, 600.0)];
    if let Some(t) = tol {
        m.push(mode(2, PathMode::Continuous { tolerance: Some(t) }));
    }
    m.extend([
        g1(3, v(10.0, 0.0, 0.0)),
        g1(4, v(10.0, 10.0, 0.0)),
        g1(5, v(0.0, 10.0, 0.0)),
        g1(6, v(0.0, 0.0, 0.0)),
    ]);
    m
}

#[test]
fn corner_at_tolerance_exact_leg() {
    // Tolerance-driven case: ε = 0.05 mm for the blend at 90° gives ℓ = 0.188562 mm and
    // a corner deviation of exactly 0.05 mm. With the 40 % blend share, the program's tolerance
    // is 0.125 mm.
    let items = build(square(Some(0.125)), &SmoothOptions::default()).unwrap();
    let segs = segments(&items);
    // 4 lines + 3 blends (the last vertex is the program end).
    assert_eq!(segs.len(), 7);
    let leg = 10.0 - segs[0].length;
    assert!((leg - 0.188562).abs() < 5e-7, "leg {leg}");
    let blend = segs[1];
    assert_eq!(blend.end, Junction::Smooth);
    assert_eq!(
        blend.line, 3,
        "a blend reports the line of the corner's incoming move"
    );
    assert_eq!(blend.feed, SegmentFeed::Feed(10.0));
    let (a, b) = blend.curve.domain();
    let mid = blend.curve.point(0.5 * (a + b));
    let dev = (mid - v(10.0, 0.0, 0.0)).norm();
    assert!((dev - 0.05).abs() < 1e-12, "deviation {dev}");
    let d = deviation(Pose::ZERO, &square(Some(0.125)), &items);
    assert!((d - 0.05).abs() < 1e-6, "measured {d}");
    let verts = [
        v(0., 0., 0.),
        v(10., 0., 0.),
        v(10., 10., 0.),
        v(0., 10., 0.),
        v(0., 0., 0.),
    ];
    check_path(&items, &verts).unwrap();
}

#[test]
fn blend_45_degree_corner() {
    // Another case: 45° turn with ℓ = 0.5 gives δ = 0.071753. ℓ = 8ε/(3 sin 22.5°) = 0.5
    // for ε = 0.0717530…; tolerance = ε / 0.4.
    let eps = 0.5 * 3.0 * (22.5f64.to_radians()).sin() / 8.0;
    let m = vec![
        feed(1, 600.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(eps / 0.4),
            },
        ),
        g1(3, v(10.0, 0.0, 0.0)),
        g1(4, v(20.0, 10.0, 0.0)),
    ];
    let items = build(m, &SmoothOptions::default()).unwrap();
    let segs = segments(&items);
    assert_eq!(segs.len(), 3);
    assert!((10.0 - segs[0].length - 0.5).abs() < 1e-12);
    let mid = segs[1].curve.point(0.5);
    assert!(((mid - v(10.0, 0.0, 0.0)).norm() - 0.071753).abs() < 5e-7);
}

#[test]
fn g61_keeps_corners_and_g61_1_stops() {
    let mut m = square(None);
    m.insert(1, mode(2, PathMode::ExactPath));
    let items = build(m, &SmoothOptions::default()).unwrap();
    let ends: Vec<Junction> = segments(&items).iter().map(|s| s.end).collect();
    assert_eq!(
        ends,
        [
            Junction::Corner,
            Junction::Corner,
            Junction::Corner,
            Junction::Stop
        ]
    );
    let mut m = square(None);
    m.insert(1, mode(2, PathMode::ExactStop));
    let items = build(m, &SmoothOptions::default()).unwrap();
    assert!(segments(&items).iter().all(|s| s.end == Junction::Stop));
    assert_eq!(segments(&items).len(), 4);
    // Switching G61 → G64 mid-program: the corner between a G61 and a G64 move stays sharp,
    // later ones blend.
    let m = vec![
        feed(1, 600.0),
        mode(2, PathMode::ExactPath),
        g1(3, v(10.0, 0.0, 0.0)),
        mode(4, PathMode::Continuous { tolerance: None }),
        g1(5, v(10.0, 10.0, 0.0)),
        g1(6, v(0.0, 10.0, 0.0)),
    ];
    let items = build(m, &SmoothOptions::default()).unwrap();
    let ends: Vec<Junction> = segments(&items).iter().map(|s| s.end).collect();
    assert_eq!(
        ends,
        [
            Junction::Corner,
            Junction::Smooth,
            Junction::Smooth,
            Junction::Stop
        ]
    );
}

#[test]
fn tangent_collinear_and_reversal_junctions() {
    // Line into a tangent arc: tangent, curvature jumps (0 → 1/5): an acceleration step at
    // any speed, so the jump is spread over a G2 blend within the blend share.
    let m = vec![
        feed(1, 600.0),
        g1(2, v(10.0, 0.0, 0.0)),
        arc_xy(3, v(15.0, 5.0, 0.0), [10.0, 5.0], 1),
        // Collinear continuation of nothing: a line along +y from (15,5), tangent to the arc end.
        g1(4, v(15.0, 20.0, 0.0)),
        // Collinear line: smooth, no blend.
        g1(5, v(15.0, 30.0, 0.0)),
        // Reversal: a corner.
        g1(6, v(15.0, 25.0, 0.0)),
    ];
    let items = build(m.clone(), &SmoothOptions::default()).unwrap();
    let ends: Vec<Junction> = segments(&items).iter().map(|s| s.end).collect();
    // line, blend, arc, blend, line, the collinear line, the reversal.
    assert_eq!(
        ends,
        [
            Junction::Smooth,
            Junction::Smooth,
            Junction::Smooth,
            Junction::Smooth,
            Junction::Smooth,
            Junction::Corner,
            Junction::Stop
        ]
    );
    let verts = [
        v(0., 0., 0.),
        v(10., 0., 0.),
        v(15., 5., 0.),
        v(15., 20., 0.),
        v(15., 30., 0.),
        v(15., 25., 0.),
    ];
    check_path(&items, &verts).unwrap();
    let d = deviation(Pose::ZERO, &m, &items);
    // A line running into its own tangent arc spends no compression deviation, so its blend
    // takes the blend and compression shares (0.4 + 0.4 of ε = 0.01), and grows until it
    // uses most of them: the longest blend spreads the curvature jump thinnest.
    let share = 0.8 * 0.01;
    assert!(d <= share + 1e-9 && d > 0.5 * share, "deviation {d}");
    // Without a tolerance to spend (G61) the junctions stay tangent, curvature jumping.
    let mut exact = m.clone();
    exact.insert(1, mode(1, PathMode::ExactPath));
    let items = build(exact.clone(), &SmoothOptions::default()).unwrap();
    let ends: Vec<Junction> = segments(&items).iter().map(|s| s.end).collect();
    assert_eq!(ends[..2], [Junction::Tangent, Junction::Tangent]);
    assert!(deviation(Pose::ZERO, &exact, &items) < 1e-12);
}

#[test]
fn line_arc_and_arc_arc_corners_are_g2_within_share() {
    let m = vec![
        feed(1, 600.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(0.05),
            },
        ),
        g1(3, v(10.0, 0.0, 0.0)),
        // Arc leaving at 45° to the line: centre up-left of the start.
        arc_xy(4, v(10.0, 10.0, 0.0), [5.0, 5.0], 1),
        // Arc turning the other way, not tangent.
        arc_xy(5, v(10.0, 20.0, 0.0), [12.0, 15.0], -1),
        g1(6, v(0.0, 20.0, 1.0)),
    ];
    let items = build(m.clone(), &SmoothOptions::default()).unwrap();
    let segs = segments(&items);
    assert_eq!(segs.len(), 7, "{segs:#?}");
    assert!(segs[..6].iter().all(|s| s.end == Junction::Smooth));
    let verts = [
        v(0., 0., 0.),
        v(10., 0., 0.),
        v(10., 10., 0.),
        v(10., 20., 0.),
        v(0., 20., 1.),
    ];
    check_path(&items, &verts).unwrap();
    let d = deviation(Pose::ZERO, &m, &items);
    assert!(d <= 0.4 * 0.05 + 1e-9 && d > 0.01, "deviation {d}");
}

#[test]
fn zero_length_and_rotary_only_moves() {
    let m = vec![
        feed(1, 600.0),
        g1(2, v(10.0, 0.0, 0.0)),
        g1(3, v(10.0, 0.0, 0.0)),        // goes nowhere: dropped
        g1a(4, v(10.0, 0.0, 0.0), 30.0), // rotary only: corners either side
        g1a(5, v(10.0, 10.0, 0.0), 30.0),
    ];
    let items = build(m, &SmoothOptions::default()).unwrap();
    let segs = segments(&items);
    assert_eq!(segs.len(), 3);
    assert!(segs[1].rotary_only());
    assert_eq!(segs[1].rotary, [[0.0; 3], [30.0, 0.0, 0.0]]);
    assert_eq!(segs[0].end, Junction::Corner);
    assert_eq!(segs[1].end, Junction::Corner);
}

#[test]
fn rotary_axes_run_through_blends_in_step() {
    // A turns 0 → 10 → 20 over two 10 mm lines: across the blend it stays continuous and
    // close to the programmed value at the corner (within the angular tolerance).
    let m = vec![
        feed(1, 600.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(0.1),
            },
        ),
        g1a(3, v(10.0, 0.0, 0.0), 10.0),
        g1a(4, v(10.0, 10.0, 0.0), 25.0),
    ];
    let opts = SmoothOptions::default();
    let items = build(m, &opts).unwrap();
    let segs = segments(&items);
    assert_eq!(segs.len(), 3);
    assert_eq!(segs[0].rotary[1], segs[1].rotary[0]);
    assert_eq!(segs[1].rotary[1], segs[2].rotary[0]);
    assert_eq!(segs[2].rotary[1], [25.0, 0.0, 0.0]);
    let mid = 0.5 * (segs[1].rotary[0][0] + segs[1].rotary[1][0]);
    assert!((mid - 10.0).abs() <= opts.angular_tolerance, "{mid}");
    // Rotary per mm of tip stays the programmed 1 °/mm on the trimmed first line.
    assert!(((segs[0].rotary[1][0] - segs[0].rotary[0][0]) / segs[0].length - 1.0).abs() < 1e-9);
}

#[test]
fn dwell_stop_and_inverse_time() {
    let m = vec![
        Move {
            line: 1,
            kind: MoveKind::FeedMode(FeedMode::InverseTime),
        },
        feed(2, 60.0), // 1 s per move
        g1(3, v(10.0, 0.0, 0.0)),
        g1(4, v(10.0, 10.0, 0.0)),
        Move {
            line: 5,
            kind: MoveKind::Dwell { seconds: 0.5 },
        },
        g1(6, v(0.0, 10.0, 0.0)),
        Move {
            line: 7,
            kind: MoveKind::Stop(StopKind::End),
        },
    ];
    let items = build(m, &SmoothOptions::default()).unwrap();
    let total: f64 = segments(&items)
        .iter()
        .map(|s| match s.feed {
            SegmentFeed::InverseTime(t) => t,
            f => panic!("{f:?}"),
        })
        .sum();
    assert!((total - 3.0).abs() < 1e-12, "{total}");
    assert!(matches!(items[3], PathItem::Dwell { seconds, line: 5 } if seconds == 0.5));
    assert!(matches!(items.last(), Some(PathItem::Stop { line: 7 })));
    let segs = segments(&items);
    assert_eq!(segs[2].end, Junction::Stop);
}

#[test]
fn errors_are_typed() {
    let bad_arc = vec![feed(1, 600.0), arc_xy(2, v(1.0, 0.0, 0.0), [0.0, 0.0], 1)];
    assert!(matches!(
        build(bad_arc, &SmoothOptions::default()),
        Err(PathError::Curve { line: 2, .. })
    ));
    assert!(matches!(
        build(vec![g1(1, v(1.0, 0.0, 0.0))], &SmoothOptions::default()),
        Err(PathError::Feed { line: 1, .. })
    ));
    let g95 = vec![
        Move {
            line: 1,
            kind: MoveKind::FeedMode(FeedMode::UnitsPerRevolution),
        },
        feed(2, 0.1),
        g1(3, v(1.0, 0.0, 0.0)),
    ];
    assert!(matches!(
        build(g95, &SmoothOptions::default()),
        Err(PathError::FeedPerRevolution { line: 3 })
    ));
    let bad_tol = vec![mode(
        1,
        PathMode::Continuous {
            tolerance: Some(-1.0),
        },
    )];
    assert!(matches!(
        build(bad_tol, &SmoothOptions::default()),
        Err(PathError::Tolerance { line: 1, .. })
    ));
    let opts = SmoothOptions {
        blend_share: 0.7,
        ..SmoothOptions::default()
    };
    assert!(matches!(
        build(vec![], &opts),
        Err(PathError::Option { .. })
    ));
    let nan = vec![feed(1, 600.0), g1(2, v(f64::NAN, 0.0, 0.0))];
    assert!(build(nan, &SmoothOptions::default()).is_err());
    assert!(build(vec![], &SmoothOptions::default()).unwrap().is_empty());
}

/// A raster over the surface `z = 2 sin(x/7) cos(y/5)`: rows 2 mm apart, points 0.05–0.3 mm
/// apart along each row (a CAM surfacing program), 90° turns at the row ends.
fn surfacing(rows: usize, row_len: f64, seed: u64) -> (Vec<Move>, Vec<Vec3>) {
    surfacing_with(rows, row_len, seed, 1.0, None)
}

/// The same raster over `z = 2 sin(k·x/7) cos(y/5)`, coordinates optionally rounded to
/// `decimals` places as CAM posts print them (rounding is noise the splines must absorb).
fn surfacing_with(
    rows: usize,
    row_len: f64,
    seed: u64,
    k: f64,
    decimals: Option<i32>,
) -> (Vec<Move>, Vec<Vec3>) {
    let mut rng = seed;
    let mut rand = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let round = |c: f64| match decimals {
        Some(d) => (c * 10f64.powi(d)).round() / 10f64.powi(d),
        None => c,
    };
    let z = |x: f64, y: f64| round(2.0 * (k * x / 7.0).sin() * (y / 5.0).cos());
    let start = v(0.0, 0.0, z(0.0, 0.0));
    let mut moves = vec![
        feed(1, 3000.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(0.01),
            },
        ),
    ];
    let mut verts = vec![start];
    let mut line = 3;
    for r in 0..rows {
        let y = 2.0 * r as f64;
        let mut s = 0.0;
        loop {
            s = (s + 0.05 + 0.25 * rand()).min(row_len);
            let x = round(if r % 2 == 0 { s } else { row_len - s });
            let p = v(x, y, z(x, y));
            moves.push(g1(line, p));
            verts.push(p);
            line += 1;
            if s >= row_len {
                break;
            }
        }
        if r + 1 < rows {
            let x = if r % 2 == 0 { row_len } else { 0.0 };
            let p = v(x, y + 2.0, z(x, y + 2.0));
            moves.push(g1(line, p));
            verts.push(p);
            line += 1;
        }
    }
    (moves, verts)
}

/// Segments in, pieces out (splines + lines, blends and spline cuts not counted), and the
/// measured deviation.
fn ratio(moves: &[Move], verts: &[Vec3]) -> (usize, usize, usize, f64) {
    let mut start = Pose::ZERO;
    start.0[2] = verts[0].z;
    let opts = SmoothOptions {
        start,
        ..SmoothOptions::default()
    };
    let mut sm = Smoother::new(moves.iter().cloned(), opts).unwrap();
    let items: Vec<PathItem> = sm.by_ref().collect::<Result<_, _>>().unwrap();
    let stats = sm.stats();
    check_path(&items, verts).unwrap();
    // Splines are cut at knots for the planner (Smooth joints inside one spline): those cuts
    // are not pieces.
    let pieces = segments(&items).len() - stats.blends - stats.spline_cuts;
    (
        stats.moves,
        pieces,
        stats.control_points,
        deviation(start, moves, &items),
    )
}

#[test]
fn compression_ratio_on_dense_surfacing() {
    // Segments 0.05–0.3 mm, tolerance 0.01 mm (compression share 0.004 mm).
    let cases = [
        // (name, waviness, decimals, least segments per control point)
        ("smooth surface, exact coordinates", 1.0, None, 10.0),
        ("smooth surface, 4 decimals", 1.0, Some(4), 10.0),
        ("smooth surface, 3 decimals", 1.0, Some(3), 10.0),
        ("5x wavier surface, 3 decimals", 5.0, Some(3), 1.5),
    ];
    for (name, k, decimals, min_ratio) in cases {
        let (moves, verts) = surfacing_with(6, 60.0, 7, k, decimals);
        let (n_in, pieces, ctrl, d) = ratio(&moves, &verts);
        let r = n_in as f64 / pieces as f64;
        println!(
            "surfacing ({name}): {n_in} segments in, {pieces} pieces out (ratio {r:.1}), \
             {ctrl} spline control points ({:.1} segments per control point), \
             max deviation {d:.6} mm (budget 0.008)",
            n_in as f64 / ctrl as f64
        );
        assert!(d <= 0.008 + 1e-9, "{name}: {d}");
        assert!(r >= 50.0, "{name}: ratio {r}");
        assert!(
            n_in as f64 / ctrl as f64 >= min_ratio,
            "{name}: {ctrl} control points"
        );
    }
}

#[test]
fn small_windows_give_a_valid_path() {
    let (moves, verts) = surfacing(2, 20.0, 3);
    let mut start = Pose::ZERO;
    start.0[2] = verts[0].z;
    for window in [1, 2, 7, 50] {
        let opts = SmoothOptions {
            start,
            window,
            ..SmoothOptions::default()
        };
        let items = build(moves.clone(), &opts).unwrap();
        check_path(&items, &verts).unwrap();
        let d = deviation(start, &moves, &items);
        assert!(d <= 0.008 + 1e-9, "window {window}: {d}");
    }
}

#[test]
fn streams_an_endless_program() {
    // A zigzag that never ends: the builder must hand out items after reading one window, so
    // a planner can start before the program is read (and memory stays bounded).
    let zigzag = (0u32..).map(|i| {
        let x = f64::from(i);
        g1(i + 2, v(x, if i % 2 == 0 { 0.0 } else { 1.0 }, 0.0))
    });
    let moves = std::iter::once(feed(1, 600.0)).chain(zigzag);
    let opts = SmoothOptions {
        window: 64,
        ..SmoothOptions::default()
    };
    let items: Vec<_> = Smoother::new(moves, opts).unwrap().take(1000).collect();
    assert_eq!(items.len(), 1000);
    let ends = items.iter().filter_map(|i| match i {
        Ok(PathItem::Segment(s)) => Some(s.end),
        _ => None,
    });
    assert!(ends.take(999).all(|e| e == Junction::Smooth));
}

#[test]
fn blends_never_eat_more_than_their_share_of_a_neighbour() {
    // Tolerance 1 mm would want legs of 1.5 mm at 90°; the 1 mm moves allow 0.4 mm each side,
    // leaving 0.2 mm of the middle move.
    let m = vec![
        feed(1, 600.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(1.0),
            },
        ),
        g1(3, v(1.0, 0.0, 0.0)),
        g1(4, v(1.0, 1.0, 0.0)),
        g1(5, v(0.0, 1.0, 0.0)),
    ];
    let opts = SmoothOptions {
        compress: false,
        ..SmoothOptions::default()
    };
    let items = build(m, &opts).unwrap();
    let segs = segments(&items);
    assert_eq!(segs.len(), 5);
    assert!((segs[0].length - 0.6).abs() < 1e-12);
    assert!((segs[2].length - 0.2).abs() < 1e-12);
    assert!((segs[4].length - 0.6).abs() < 1e-12);
}

#[test]
fn compression_off_keeps_every_move() {
    let (moves, verts) = surfacing(1, 10.0, 5);
    let mut start = Pose::ZERO;
    start.0[2] = verts[0].z;
    let opts = SmoothOptions {
        start,
        compress: false,
        ..SmoothOptions::default()
    };
    let mut sm = Smoother::new(moves.clone().into_iter(), opts).unwrap();
    let items: Vec<PathItem> = sm.by_ref().collect::<Result<_, _>>().unwrap();
    let stats = sm.stats();
    assert_eq!(stats.splines, 0);
    assert_eq!(segments(&items).len(), stats.moves + stats.blends);
    check_path(&items, &verts).unwrap();
    assert!(deviation(start, &moves, &items) <= 0.004 + 1e-12);
}

/// Largest curvature of the built path over the rows' interiors (1 mm clear of the row-end
/// blends), per knot span with golden-section refinement, ends included.
fn row_curvature(items: &[PathItem], row_len: f64) -> f64 {
    let mut kmax = 0.0f64;
    for s in segments(items) {
        for w in s.curve.breakpoints().windows(2) {
            let p = tezgah_geom::deviation::maximise(|u| s.curve.curvature(u), w[0], w[1], 8);
            let x = s.curve.point(p.u).x;
            if x >= 1.0 && x <= row_len - 1.0 {
                kmax = kmax.max(p.distance);
            }
        }
    }
    kmax
}

/// Menger curvature `4·area/(|ab||bc||ca|)` at every vertex inside a row: the polyline's own
/// discrete curvature, the yardstick for the splines' fairness.
fn polyline_curvature(verts: &[Vec3]) -> f64 {
    verts
        .windows(3)
        .filter(|w| w[0].y == w[1].y && w[1].y == w[2].y)
        .map(|w| {
            let (a, b, c) = (w[0], w[1], w[2]);
            2.0 * (b - a).cross(&(c - a)).norm()
                / ((b - a).norm() * (c - b).norm() * (c - a).norm())
        })
        .fold(0.0, f64::max)
}

#[test]
fn splines_stay_fair_on_uneven_spacing() {
    // Uneven 0.05–0.3 mm spacing, 3 decimals: on the 5× wavier surface the chords sag up to
    // 0.0115 mm, more than the 0.004 mm compression share, so the splines must bend toward
    // the chords. With centripetal parameters the splines folded into the vertices (1.02/mm
    // on the smooth surface, whose true curvature is 0.04/mm; 117/mm on the 40-row wavy
    // program); chord-length parameters keep them at the surface's curvature, and the fairing
    // term of the fit (geom `fit::approximate`) under 2.5× the polyline's discrete curvature
    // on the wavy one (10× without it).
    // The planner sees each curvature level separately (splines are cut at knots), so the
    // rows are not slowed as a whole either.
    for (k, factor) in [(1.0, 1.0), (5.0, 2.5)] {
        let (moves, verts) = surfacing_with(6, 60.0, 7, k, Some(3));
        let mut start = Pose::ZERO;
        start.0[2] = verts[0].z;
        let opts = SmoothOptions {
            start,
            window: 4096,
            ..SmoothOptions::default()
        };
        let mut sm = Smoother::new(moves.iter().cloned(), opts).unwrap();
        let items: Vec<PathItem> = sm.by_ref().collect::<Result<_, _>>().unwrap();
        check_path(&items, &verts).unwrap();
        let d = deviation(start, &moves, &items);
        let (kp, ks) = (polyline_curvature(&verts), row_curvature(&items, 60.0));
        println!(
            "waviness {k}: polyline {kp:.3}/mm, path {ks:.3}/mm, {} splines cut into {} more \
             segments, deviation {d:.6} mm",
            sm.stats().splines,
            sm.stats().spline_cuts
        );
        assert!(d <= 0.008 + 1e-9, "{d}");
        assert!(
            ks <= factor * kp,
            "waviness {k}: {ks} against the polyline's {kp}"
        );
    }
}

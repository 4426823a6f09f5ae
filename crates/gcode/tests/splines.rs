//! Spline blocks end to end, program text to moves: Fanuc's G06.2 on the golden NURBS of
//! Kelekçi (2021, data (2.39) and (2.48), Table 2.4: the move's curve length), the frames applied
//! to control points, LinuxCNC's G5/G5.1/G5.2 as Bézier and NURBS moves, and G06.2's errors with
//! line and column.

use tezgah_gcode::{program_moves, Config, ErrorKind, GcodeError};
use tezgah_geom::{Curve, Move, MoveKind, Nurbs};

/// A G06.2 program drawing one NURBS from its data; the tool first goes to the first point.
fn g06_2(order: usize, x: &[f64], y: &[f64], w: &[f64], knots: &[f64], preamble: &str) -> String {
    let mut s = format!("G21 G90 G17\n{preamble}G0 X{} Y{} Z0\nF600\n", x[0], y[0]);
    for i in 0..x.len() {
        let head = if i == 0 {
            format!("G06.2 P{order} ")
        } else {
            String::new()
        };
        s += &format!("{head}K{} X{} Y{} Z0 R{}\n", knots[i], x[i], y[i], w[i]);
    }
    for k in &knots[x.len()..] {
        s += &format!("K{k}\n");
    }
    s + "G1 X0 Y0\nM2\n"
}

fn nurbs_moves(moves: &[Move]) -> Vec<&Nurbs> {
    moves
        .iter()
        .filter_map(|m| match &m.kind {
            MoveKind::Nurbs(n) => Some(n.curve.as_ref()),
            _ => None,
        })
        .collect()
}

/// The single NURBS move of a program.
fn the_nurbs(program: &str) -> Nurbs {
    let moves = program_moves(program, Config::default()).unwrap();
    let n = nurbs_moves(&moves);
    assert_eq!(n.len(), 1, "{program}");
    n[0].clone()
}

fn error(program: &str) -> GcodeError {
    program_moves(program, Config::default()).unwrap_err()
}

const X_239: [f64; 10] = [0.0, 2.5, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0];
const Y_239: [f64; 10] = [0.0, 2.3, 1.5, 2.4, 1.0, 2.0, 1.0, 2.0, 0.0, 1.0];
const K_239: [f64; 14] = [
    0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 7.0, 7.0, 7.0,
];

const X_248: [f64; 7] = [50.0, 100.0, 60.0, 50.0, 40.0, 0.0, 50.0];
const Y_248: [f64; 7] = [0.0, 100.0, 40.0, 100.0, 40.0, 100.0, 0.0];
const K_248: [f64; 11] = [0.0, 0.0, 0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0, 1.0, 1.0];

#[test]
fn g06_2_thesis_curve_has_the_golden_length() {
    // Kelekçi (2021), data (2.39), weights 1, clamped cubic: L = 19.0203 mm.
    let c = the_nurbs(&g06_2(4, &X_239, &Y_239, &[1.0; 10], &K_239, ""));
    assert_eq!(c.degree(), 3);
    assert!((c.length() - 19.0203).abs() < 5e-5, "{}", c.length());
}

#[test]
fn g06_2_weighted_curves_have_the_golden_lengths() {
    // Kelekçi (2021), data (2.48), Table 2.4 lengths for W1, W2, W3.
    let cases = [
        ([1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 244.9780),
        ([1.0, 1.0, 5.0, 5.0, 5.0, 1.0, 1.0], 200.6809),
        ([1.0, 1.0, 10.0, 10.0, 10.0, 1.0, 1.0], 186.7727),
    ];
    for (w, golden) in cases {
        let c = the_nurbs(&g06_2(4, &X_248, &Y_248, &w, &K_248, ""));
        assert!((c.length() - golden).abs() < 5e-5, "{w:?}: {}", c.length());
    }
}

#[test]
fn control_points_go_through_units_offsets_and_rotation() {
    let base = the_nurbs(&g06_2(4, &X_248, &Y_248, &[1.0; 7], &K_248, ""));
    // Inches: every control point scales by 25.4, so does the length.
    let inch = g06_2(4, &X_248, &Y_248, &[1.0; 7], &K_248, "").replace("G21", "G20");
    let c = the_nurbs(&inch);
    assert!((c.length() - 25.4 * base.length()).abs() < 1e-6 * c.length());
    // A rotated, shifted work system moves the curve rigidly: same length, the mid point
    // rotated by 90° about the origin and shifted.
    let c = the_nurbs(&g06_2(
        4,
        &X_248,
        &Y_248,
        &[1.0; 7],
        &K_248,
        "G10 L2 P1 X10 Y-5 R90\n",
    ));
    assert!((c.length() - base.length()).abs() < 1e-9 * base.length());
    let (p, q) = (base.point(0.5), c.point(0.5));
    assert!((q.x - (10.0 - p.y)).abs() < 1e-9, "{p:?} {q:?}");
    assert!((q.y - (-5.0 + p.x)).abs() < 1e-9, "{p:?} {q:?}");
}

#[test]
fn g06_2_end_point_is_the_current_point_after_it() {
    let moves = program_moves(
        &g06_2(4, &X_239, &Y_239, &[1.0; 10], &K_239, ""),
        Config::default(),
    )
    .unwrap();
    let i = moves
        .iter()
        .position(|m| matches!(m.kind, MoveKind::Nurbs(_)))
        .unwrap();
    let MoveKind::Nurbs(n) = &moves[i].kind else {
        unreachable!()
    };
    assert_eq!(n.end.xyz(), [18.0, 1.0, 0.0]);
    // The move belongs to the G06.2 line (line 4), and the G1 after it starts at its end.
    assert_eq!(moves[i].line, 4);
    let c = &n.curve;
    let end = c.point(c.domain().1);
    assert!((end.x - 18.0).abs() < 1e-12 && (end.y - 1.0).abs() < 1e-12);
}

#[test]
fn linuxcnc_g5_and_g5_1_are_bezier_moves() {
    // G5: from (1, 0) with I J = (1, 1), P Q = (1, −1) to (5, 5): control points
    // (1,0) (2,1) (6,4) (5,5). The second G5 takes I J = −(P, Q) of the first: (−1, 1).
    let moves = program_moves(
        "G21 G0 X1 Y0\nF100\nG5 I1 J1 P1 Q-1 X5 Y5\nG5 P1 Q-1 X10 Y0\nG5.1 I2 J3 X12 Y1\nM2\n",
        Config::default(),
    )
    .unwrap();
    let n = nurbs_moves(&moves);
    assert_eq!(n.len(), 3);
    let pts =
        |c: &Nurbs| -> Vec<[f64; 2]> { c.control_points().iter().map(|p| [p.x, p.y]).collect() };
    assert_eq!(n[0].degree(), 3);
    assert_eq!(pts(n[0]), [[1.0, 0.0], [2.0, 1.0], [6.0, 4.0], [5.0, 5.0]]);
    assert_eq!(
        pts(n[1]),
        [[5.0, 5.0], [4.0, 6.0], [11.0, -1.0], [10.0, 0.0]]
    );
    assert_eq!(n[2].degree(), 2);
    assert_eq!(pts(n[2]), [[10.0, 0.0], [12.0, 3.0], [12.0, 1.0]]);
    // A Bézier's knots: clamped, no inner knot.
    assert_eq!(n[0].knots(), [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
}

#[test]
fn linuxcnc_g5_2_collects_weighted_points_until_g5_3() {
    let c =
        the_nurbs("G21 G0 X1\nF100\nG5.2 P1 L3 X1 Y1\nX2 Y1 P2\nX3 Y0 P1\nX4 Y2 P1\nG5.3\nM2\n");
    assert_eq!(c.degree(), 2);
    assert_eq!(c.weights(), [1.0, 1.0, 2.0, 1.0, 1.0]);
    assert_eq!(c.knots(), [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0]);
}

/// The error's message, line and column.
fn located(program: &str) -> (String, u32, u32) {
    let e = error(program);
    (e.kind.to_string(), e.span.line, e.span.column)
}

#[test]
fn g06_2_errors_name_line_and_column() {
    let ok = g06_2(4, &X_248, &Y_248, &[1.0; 7], &K_248, "");
    // Lines: 1 G21, 2 G0, 3 F600, 4 G06.2, 5–10 points, 11–14 closing knots, 15 G1, 16 M2.
    let lines: Vec<&str> = ok.lines().collect();
    let with = |k: usize, text: &str| {
        let mut l = lines.clone();
        l[k - 1] = text;
        l.join("\n") + "\n"
    };
    let without = |k: usize| {
        let mut l = lines.clone();
        l.remove(k - 1);
        l.join("\n") + "\n"
    };

    // Missing closing knot: the G1 comes after three of four.
    let (msg, line, col) = located(&without(14));
    assert_eq!(
        msg,
        "G6.2 NURBS begun on line 4 is unfinished: it has 3 of its 4 closing knot lines \
         (K alone); a NURBS of n control points and order P needs n + P knots"
    );
    assert_eq!((line, col), (14, 1));
    assert_eq!(error(&without(14)).kind, ErrorKind::G62Unfinished(4, 3, 4));

    // One knot too many: a fifth line of K alone.
    let extra = with(14, "K1\nK1");
    assert_eq!(error(&extra).kind, ErrorKind::G62StrayKnot);
    assert_eq!(error(&extra).span.line, 15);

    // A control point without its knot.
    let (msg, line, col) = located(&with(6, "X60 Y40 Z0 R1"));
    assert_eq!(
        msg,
        "G6.2 control point without its knot: every control point line needs a K word"
    );
    assert_eq!((line, col), (6, 1));

    // Decreasing knots: the column is the K word's.
    let (msg, line, col) = located(&with(9, "K0.2 X0 Y100 Z0 R1"));
    assert_eq!(msg, "G6.2 knots must not decrease: K0.2 follows K0.25");
    assert_eq!((line, col), (9, 1));
    let (_, _, col) = located(&with(9, "X0 Y100 Z0 K0.2"));
    assert_eq!(col, 12);

    // Bad order: P5, P1, P2.5.
    for p in ["5", "1", "2.5"] {
        let text = format!("G06.2 P{p} K0 X50 Y0 Z0 R1");
        let (msg, line, col) = located(&with(4, &text));
        assert_eq!(
            msg,
            format!("G6.2 order P{p} must be 2, 3 or 4 (P4 = cubic, the default)")
        );
        assert_eq!((line, col), (4, 7));
    }

    // Weight zero or negative, column of R.
    let (msg, line, col) = located(&with(7, "K0 X60 Y40 Z0 R0"));
    assert_eq!(msg, "G6.2 weight R0 must be positive");
    assert_eq!((line, col), (7, 15));
    let (msg, _, _) = located(&with(7, "K0 X60 Y40 Z0 R-2"));
    assert_eq!(msg, "G6.2 weight R-2 must be positive");

    // Unclamped start: the first four knots must be equal.
    let (msg, line, _) = located(
        &with(7, "K0.1 X60 Y40 Z0 R1").replace("K0 X50 Y100 Z0 R1\n", "K0.1 X50 Y100 Z0 R1\n"),
    );
    assert_eq!(
        msg,
        "G6.2 knots must be clamped: the first 4 knots must be equal (order P4)"
    );
    assert_eq!(line, 14);
    // Unclamped end.
    let (msg, line, _) = located(&with(11, "K0.9"));
    assert_eq!(
        msg,
        "G6.2 knots must be clamped: the last 4 knots must be equal (order P4)"
    );
    assert_eq!(line, 14);

    // The first control point is where the tool is.
    let (msg, line, col) = located(&with(4, "G06.2 P4 K0 X51 Y0 Z0 R1"));
    assert_eq!(
        msg,
        "G6.2 first control point must be the current point (X50.0000 Y0.0000 Z0.0000)"
    );
    assert_eq!((line, col), (4, 13));

    // A control point after the closing knots began.
    let (msg, line, _) = located(&with(12, "K1 X1 Y1 Z0"));
    assert_eq!(
        msg,
        "G6.2 control point after the closing knot lines (K alone) began"
    );
    assert_eq!(line, 12);

    // Too few control points for the order: two points of a cubic.
    let short = "G21 G0 X0 Y0 Z0\nF100\nG06.2 P4 K0 X0 Y0 Z0\nK0 X1 Y1 Z0\nK0\nK0\nK1\nK1\nM2\n";
    let (msg, line, _) = located(short);
    assert_eq!(
        msg,
        "G6.2 order P4 needs at least 4 control points; the NURBS has 2"
    );
    assert_eq!(line, 8);

    // No feed.
    let (msg, line, _) = located(&ok.replace("F600\n", ""));
    assert_eq!(msg, "Cannot make a NURBS with 0 feedrate");
    assert_eq!(line, 3);
}

#[test]
fn g06_2_takes_comment_lines_and_incremental_points() {
    // Comments between the lines do not end the NURBS; under G91 each point is relative to
    // the one before, and the knots stay absolute.
    let abs = the_nurbs(&g06_2(4, &X_248, &Y_248, &[1.0; 7], &K_248, ""));
    let mut s = String::from("G21 G90 G0 X50 Y0 Z0\nF600\nG91\n");
    for i in 0..7 {
        let head = if i == 0 { "G06.2 P4 " } else { "" };
        let (dx, dy) = if i == 0 {
            (0.0, 0.0)
        } else {
            (X_248[i] - X_248[i - 1], Y_248[i] - Y_248[i - 1])
        };
        s += &format!("{head}K{} X{dx} Y{dy}\n(point {i})\n", K_248[i]);
    }
    for k in &K_248[7..] {
        s += &format!("K{k}\n");
    }
    s += "M2\n";
    let inc = the_nurbs(&s);
    assert!((inc.length() - abs.length()).abs() < 1e-9);
}

#[test]
fn g06_2_in_inverse_time_runs_its_length_in_one_over_f_minutes() {
    // F2 under G93: half a minute for 19.0203 mm, a rate of 38.0406 mm/min, set before the move.
    let text = g06_2(4, &X_239, &Y_239, &[1.0; 10], &K_239, "")
        .replace("F600\n", "G93\n")
        .replace("G06.2 P4 K0 ", "G06.2 P4 F2 K0 ")
        .replace("G1 X0 Y0", "G1 X0 Y0 F1");
    let moves = program_moves(&text, Config::default()).unwrap();
    let i = moves
        .iter()
        .position(|m| matches!(m.kind, MoveKind::Nurbs(_)))
        .unwrap();
    let MoveKind::FeedRate { value } = moves[i - 1].kind else {
        panic!("{:?}", moves[i - 1]);
    };
    assert!((value - 2.0 * 19.0203).abs() < 1e-3, "{value}");
    let (msg, line, _) = located(&text.replace(" F2 ", " "));
    assert_eq!(msg, "F word missing with inverse time G6.2 move");
    assert_eq!(line, 4);
}

mod random {
    //! Random G06.2 blocks, valid or not: never a panic; when accepted, the move's curve starts
    //! where the tool was and ends on the move's end point. A fair share must be accepted, so
    //! the property is not met by rejecting everything.

    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::{Config as RunnerConfig, RngSeed, TestRunner};
    use tezgah_geom::Vec3;

    type Block = (usize, Vec<f64>, Vec<(f64, f64, f64, f64)>, bool, bool);

    fn blocks() -> impl Strategy<Value = Block> {
        let order = prop_oneof![9 => 2usize..=4, 1 => Just(5usize)];
        (order, 0usize..=5).prop_flat_map(|(order, extra)| {
            let n = (order + extra).saturating_sub(1).max(1);
            let weight = prop_oneof![15 => 0.1..4.0f64, 1 => -0.5..0.0f64];
            let point = (-50.0..50.0f64, -50.0..50.0f64, -5.0..5.0f64, weight);
            (
                Just(order),
                proptest::collection::vec(0.0..3.0f64, n + order),
                proptest::collection::vec(point, n),
                proptest::bool::weighted(0.9),
                proptest::bool::weighted(0.9),
            )
        })
    }

    fn program((order, mut knots, points, sorted, clamp): Block) -> (String, Vec3) {
        if sorted {
            knots.sort_by(f64::total_cmp);
        }
        let n = knots.len();
        if clamp && n >= 2 * order {
            let (lo, hi) = (knots[0], knots[n - 1]);
            knots[..order].fill(lo);
            knots[n - order..].fill(hi);
        }
        let mut s = String::from("G21 G90 G0 X1 Y2 Z3\nF500\n");
        let mut end = Vec3::new(1.0, 2.0, 3.0);
        for (i, &(x, y, z, w)) in points.iter().enumerate() {
            let head = if i == 0 {
                format!("G06.2 P{order} ")
            } else {
                String::new()
            };
            let r4 = |v: f64| (v * 1e4).round() / 1e4;
            if i > 0 {
                end = Vec3::new(r4(x), r4(y), r4(z));
            }
            s += &format!(
                "{head}K{:.4} X{:.4} Y{:.4} Z{:.4} R{w:.4}\n",
                knots[i], end.x, end.y, end.z
            );
        }
        for k in &knots[points.len()..] {
            s += &format!("K{k:.4}\n");
        }
        (s + "G1 X0\nM2\n", end)
    }

    #[test]
    fn g06_2_never_panics_and_keeps_its_ends() {
        let config = RunnerConfig {
            rng_seed: RngSeed::Fixed(0x6062),
            failure_persistence: None,
            ..RunnerConfig::with_cases(512)
        };
        let mut runner = TestRunner::new(config);
        let accepted = std::cell::Cell::new(0);
        runner
            .run(&blocks(), |block| {
                let (text, end) = program(block);
                let Ok(moves) = program_moves(&text, Config::default()) else {
                    return Ok(());
                };
                accepted.set(accepted.get() + 1);
                let n = nurbs_moves(&moves);
                prop_assert_eq!(n.len(), 1);
                let (a, b) = n[0].domain();
                let start = Vec3::new(1.0, 2.0, 3.0);
                prop_assert!((n[0].point(a) - start).norm() < 1e-9, "{text}");
                prop_assert!((n[0].point(b) - end).norm() < 1e-9, "{text}");
                Ok(())
            })
            .unwrap();
        assert!(accepted.get() > 512 / 4, "only {} accepted", accepted.get());
    }
}

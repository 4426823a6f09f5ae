//! Golden cases from Kelekçi (2021): the controller's listing (Fig. 4.36) must
//! read into alternating lines and R-format fillet arcs with exact trailing-dot numbers.

use tezgah_gcode::{Canon, Config, Interpreter, Origin};

const LISTING: &str = "G17 G21 G90 F1000
G0 X-80. Y95.
N310 G2X-92.501Y95.R12.499
N320 G1X92.501
N330 G2X105.Y82.501R12.499
N340 G1Y-82.501
N350 G2X92.501Y-95.R12.499
N360 G1X43.301
N370 G2X40.189Y-92.152R3.125
N380 G1X38.468Y-72.848
N390 G3X35.355Y-70.R3.125
N400 G1X-67.501
N410 G2X-80.Y-57.501R12.499
N420 G1Y57.501
N430 G2X-67.501Y70.R12.499
N440 G1X67.501
N450 G2X80.Y57.501R12.499
N460 G1Y-57.501
N470 G2X67.501Y-70.R12.499
N480 G1X35.355
M2
";

#[test]
fn kelekci_fig_4_36_listing() {
    let mut calls: Vec<(Origin, Canon)> = Vec::new();
    Interpreter::new(Config::default())
        .run(LISTING, &mut calls)
        .unwrap();
    let moves: Vec<&(Origin, Canon)> = calls
        .iter()
        .filter(|(_, c)| matches!(c, Canon::StraightFeed(_) | Canon::ArcFeed { .. }))
        .collect();
    assert_eq!(moves.len(), 18);
    // Blocks alternate arc, line, arc, … and keep their N words and source lines.
    for (k, (origin, call)) in moves.iter().enumerate() {
        assert_eq!(origin.n, Some(310 + 10 * k as i64));
        assert_eq!(origin.line, 3 + k as u32);
        assert_eq!(
            matches!(call, Canon::ArcFeed { .. }),
            k % 2 == 0,
            "block {k}"
        );
    }
    // `Y95.` is exactly 95, and each fillet's end lies on its circle of radius R.
    let mut start = (-80.0, 95.0);
    for (_, call) in &moves {
        match call {
            Canon::ArcFeed {
                first_end,
                second_end,
                first_axis,
                second_axis,
                ..
            } => {
                let r0 = (start.0 - first_axis).hypot(start.1 - second_axis);
                let r1 = (first_end - first_axis).hypot(second_end - second_axis);
                assert!((r0 - r1).abs() < 1e-9);
                assert!(
                    (r0 - 12.499).abs() < 1e-9 || (r0 - 3.125).abs() < 1e-9,
                    "{r0}"
                );
                start = (*first_end, *second_end);
            }
            Canon::StraightFeed(p) => start = (p.x(), p.y()),
            _ => unreachable!(),
        }
    }
    // The first fillet, N310 G2 Y95. R12.499 from (-80, 95): clockwise, so the centre
    // lies right of the chord (travel is along −X, right is +Y), √(R² − (c/2)²) from its middle.
    let Canon::ArcFeed {
        first_axis,
        second_axis,
        rotation,
        ..
    } = moves[0].1
    else {
        unreachable!()
    };
    let rise = (12.499f64.powi(2) - 6.2505f64.powi(2)).sqrt();
    assert!((first_axis - -86.2505).abs() < 1e-9);
    assert!((second_axis - (95.0 + rise)).abs() < 1e-9, "{second_axis}");
    assert_eq!(rotation, -1);
}

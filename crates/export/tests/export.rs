//! `tezgah export` checked by reading its output back: tezgah's interpreter reads the written
//! program as joint moves, the forward kinematics puts the tip of each joint-linear move at
//! 64 steps within the written blocks' share of the tolerance of the path `run` builds, each
//! segment's last move ends on its end point, and each block's G93 time is its share of the
//! programmed block's time at the programmed feed (closed forms per source line under G61).

mod support;

use std::f64::consts::PI;

use proptest::prelude::*;
use support::programs::{
    delta_program, table_ac_program, DELTA_ARCS, SAG, TABLE_AC, TABLE_AC_TOOLS,
};
use support::{export_program, measure, minutes_per_line, motion_blocks, read_back};
use tezgah_export::Block;
use tezgah_geom::Vec3;
use tezgah_kinematics::segment::joint_line_deviation;
use tezgah_kinematics::Tool;
use tezgah_motion::path::smooth::CHORD_SHARE;

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs()
}

#[test]
fn delta_sag_case_is_split_within_tolerance_and_keeps_its_feed() {
    let case = export_program(SAG, "linear-delta", "", 0.01);
    let m = measure(&case);
    assert!(m.worst_ratio <= 1.0, "{m:?}");
    assert!(m.worst_time_error < 1e-8, "{m:?}");
    // The diagonal's blocks (line 3): end point to end point they would sag 4.646 mm; the
    // bow of each is ∝ its length², so about √(4.646 / split tolerance) are needed.
    let joints_of = |want: u32| -> Vec<_> {
        motion_blocks(&case)
            .into_iter()
            .filter_map(|b| match b {
                Block::Rapid { joints, line, .. } | Block::Feed { joints, line, .. } => {
                    (*line == want).then_some(*joints)
                }
                _ => None,
            })
            .collect()
    };
    let line3 = joints_of(3);
    // Where the rapid of line 2 leaves the joints: the diagonal's start.
    let rapid_end = *joints_of(2).last().unwrap();
    let (a, b) = (
        Vec3::new(-31.654, -28.911, -0.2),
        Vec3::new(39.057, 41.8, -0.2),
    );
    let unsplit = joint_line_deviation(
        &case.machine.kinematics,
        &Tool::default(),
        &rapid_end,
        line3.last().unwrap(),
        &a,
        &b,
        999,
    )
    .unwrap()
    .0;
    assert!((unsplit - 4.646).abs() < 5e-4, "{unsplit}");
    let budget = CHORD_SHARE * 0.01;
    let need = (4.646 / budget).sqrt();
    let n = line3.len() as f64;
    assert!(
        n >= 0.7 * need && n <= 2.5 * need,
        "{n} blocks, ~{need} needed"
    );
    // 100 mm at F1000: 0.1 min in all, whatever the split.
    let per_line = minutes_per_line(&case);
    assert!(
        close(per_line[&3], (b - a).norm() / 1000.0, 1e-8),
        "{per_line:?}"
    );
    let s = case.exported.summary;
    assert_eq!((s.blocks_in, s.blocks_out), (2, motion_blocks(&case).len()));
    assert!(
        s.worst_deviation <= budget && s.worst_deviation > 0.3 * budget,
        "{s:?}"
    );
}

#[test]
fn delta_arcs_and_helices_within_tolerance_at_their_closed_form_times() {
    let case = export_program(DELTA_ARCS, "linear-delta", "", 0.01);
    let m = measure(&case);
    assert!(m.worst_ratio <= 1.0, "{m:?}");
    assert!(m.worst_time_error < 1e-8, "{m:?}");
    let per_line = minutes_per_line(&case);
    let helix = ((PI / 2.0 * 40.0).powi(2) + 25.0).sqrt();
    let line = (Vec3::new(-30.0, 10.0, 0.0) - Vec3::new(0.0, 40.0, -5.0)).norm();
    for (n, want) in [
        (4, 2.0 * PI * 40.0 / 1200.0),
        (6, helix / 900.0),
        (7, line / 1500.0),
        (8, PI * 10.0 / 800.0),
    ] {
        assert!(close(per_line[&n], want, 1e-7), "line {n}: {per_line:?}");
    }
    // Spindle and coolant words stand where the program had them, in its order.
    let lines: Vec<&str> = case.text.lines().collect();
    let pos = |pat: &str| lines.iter().position(|l| l.contains(pat)).unwrap();
    assert!(pos("N2 S12000") < pos("N2 M3") && pos("N2 M3") < pos("N3 G0"));
    let last_circle = lines.iter().rposition(|l| l.starts_with("N4 G1")).unwrap();
    assert!(last_circle < pos("N5 M8") && pos("N5 M8") < pos("N6 G1"));
    assert!(pos("N9 G4 P0.5") < pos("N10 M9") && pos("N10 M5") < pos("N11 M2"));
    let (_, words) = read_back(&case);
    let names: Vec<&str> = words.iter().map(|w| w.split('(').next().unwrap()).collect();
    // The last stop is the read-back's own M2.
    assert_eq!(
        names,
        [
            "START_SPINDLE_CLOCKWISE",
            "FLOOD_ON",
            "STOP_SPINDLE_TURNING",
            "STOP_SPINDLE_TURNING"
        ],
        "{words:?}"
    );
}

fn tool_axis(a_deg: f64, c_deg: f64) -> Vec3 {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    Vec3::new(a.sin() * c.sin(), a.sin() * c.cos(), a.cos())
}

#[test]
fn table_ac_five_axis_within_tolerance_with_unwrapped_rotaries() {
    let case = export_program(TABLE_AC, "table-ac", TABLE_AC_TOOLS, 0.01);
    let m = measure(&case);
    assert!(m.worst_ratio <= 1.0, "{m:?}");
    assert!(
        m.worst_axis_ratio > 0.0 && m.worst_axis_ratio <= 1.0,
        "{m:?}"
    );
    let (axis, budget) = case.exported.summary.axis.unwrap();
    assert!(
        axis <= budget && (budget - 0.02).abs() < 1e-12,
        "{axis}° of {budget}°"
    );
    assert!(m.worst_time_error < 1e-8, "{m:?}");
    let per_line = minutes_per_line(&case);
    let p = |x, y, z| Vec3::new(x, y, z);
    // The turn of the tool axis alone, at F3600 degrees per minute of that turn.
    let turn = tool_axis(30.0, 60.0)
        .angle(&tool_axis(10.0, -90.0))
        .to_degrees();
    for (n, want) in [
        (5, 23.0 / 600.0),
        (
            6,
            (p(40.0, -10.0, -3.0) - p(10.0, 5.0, -3.0)).norm() / 800.0,
        ),
        (7, PI / 2.0 * 20.0 / 700.0),
        (8, turn / 3600.0),
        (9, (p(0.0, 0.0, 5.0) - p(20.0, -30.0, -3.0)).norm() / 1000.0),
    ] {
        assert!(close(per_line[&n], want, 1e-7), "line {n}: {per_line:?}");
    }
    // The tilting moves are split (the tip bows off a joint-linear move), the rotaries are
    // written as continuous angles: no step of more than a few degrees between blocks.
    let blocks = motion_blocks(&case);
    let count = |n: u32| {
        blocks
            .iter()
            .filter(|b| matches!(b, Block::Feed { line, .. } if *line == n))
            .count()
    };
    assert!(count(6) > 5 && count(8) > 5, "{} {}", count(6), count(8));
    let (read, _) = read_back(&case);
    for w in read.windows(2) {
        let (q0, q1) = (w[0].joints.as_slice(), w[1].joints.as_slice());
        assert!(
            (q1[3] - q0[3]).abs() < 0.2 && (q1[4] - q0[4]).abs() < 0.5,
            "{w:?}"
        );
    }
    // G49: the take-up to the TCP-off reading of the point is a G0 of its own.
    assert!(case.exported.blocks.iter().any(|b| matches!(
        b,
        Block::Rapid {
            piece: None,
            line: 11,
            ..
        }
    )));
    // M6 stops the spindle first, as LinuxCNC does.
    assert!(
        case.text.contains("N2 T1\nN2 M5\nN2 M6\n"),
        "{}",
        &case.text[..400]
    );
    assert!(case
        .text
        .lines()
        .nth(1)
        .unwrap()
        .contains("x=X y=Y z=Z a=A c=C"));
}

/// Every feed segment's G93 times add up to its length (its rotary travel, for a turn of
/// the axis alone) at its feed.
fn assert_segment_times(case: &support::Case, m: &support::Measured) -> Result<(), TestCaseError> {
    for (i, minutes) in &m.minutes {
        let seg = support::segment(case, *i);
        let tezgah_motion::SegmentFeed::Feed(v) = seg.feed else {
            unreachable!()
        };
        if seg.rotary_only() {
            continue;
        }
        let want = seg.length / (v * 60.0);
        prop_assert!(
            close(*minutes, want, 1e-7),
            "segment {i}: {minutes} vs {want}"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Whatever the program, the read-back tip stays within budget of the built path and
    /// every feed segment's G93 times add up to its length at its feed.
    #[test]
    fn random_delta_programs_within_tolerance_and_on_time((text, tol) in delta_program()) {
        let case = export_program(&text, "linear-delta", "", tol);
        let m = measure(&case);
        prop_assert!(m.worst_ratio <= 1.0, "{m:?}\n{text}");
        prop_assert!(m.worst_time_error < 1e-7, "{m:?}\n{text}");
        assert_segment_times(&case, &m).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    /// Five-axis programs under TCP on table-ac: the same, with the rotaries unwrapped
    /// (consecutive C values never jump by a turn).
    #[test]
    fn random_table_ac_programs_within_tolerance_and_on_time(text in table_ac_program()) {
        let case = export_program(&text, "table-ac", TABLE_AC_TOOLS, 0.01);
        let m = measure(&case);
        prop_assert!(m.worst_ratio <= 1.0, "{m:?}\n{text}");
        prop_assert!(m.worst_axis_ratio <= 1.0, "{m:?}\n{text}");
        prop_assert!(m.worst_time_error < 1e-7, "{m:?}\n{text}");
        assert_segment_times(&case, &m).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        let (read, _) = read_back(&case);
        for w in read.windows(2) {
            let (c0, c1) = (w[0].joints[4], w[1].joints[4]);
            prop_assert!((c1 - c0).abs() < 0.2, "C jumps {c0} → {c1}\n{text}");
        }
    }
}

/// The table-ac program with the tilt on B: the same code path for the other trunnion.
#[test]
fn table_bc_five_axis_within_tolerance() {
    let program = TABLE_AC.replace(" A", " B");
    let case = export_program(&program, "table-bc", TABLE_AC_TOOLS, 0.01);
    let m = measure(&case);
    assert!(m.worst_ratio <= 1.0, "{m:?}");
    assert!(
        m.worst_axis_ratio > 0.0 && m.worst_axis_ratio <= 1.0,
        "{m:?}"
    );
    assert!(m.worst_time_error < 1e-8, "{m:?}");
    // The tilting move is split: a joint-linear B-C move bows the tip off the line.
    let tilting = motion_blocks(&case)
        .iter()
        .filter(|b| matches!(b, Block::Feed { line: 6, .. }))
        .count();
    assert!(tilting > 5, "{tilting} blocks for the tilting move");
}

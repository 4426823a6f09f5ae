//! LinuxCNC's own interpreter `rs274` reads every exported program: it accepts it, its
//! traverses and feeds are the written joints (to its 4 printed decimals), and the time of each
//! feed at the rate it derives from G93 (`SET_FEED_RATE` = length × F) is the block's time.
//! Programs: the three of `tests/export.rs`, eight random delta and four random table-ac ones.
//! The oracle is found as in the G-code crate's tests (`TEZGAH_RS274`, see `.ci/install-rs274`).

#[path = "../../gcode/tests/support/mod.rs"]
mod oracle;
mod support;

use std::path::Path;
use std::process::{Command, Stdio};

use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config as ProptestConfig, RngSeed, TestRunner};
use support::programs::{
    delta_program, table_ac_program, DELTA_ARCS, SAG, TABLE_AC, TABLE_AC_TOOLS,
};
use support::{export_program, motion_blocks, Case};
use tezgah_export::Block;

/// The numbers of `CALL(a, b, …)`.
fn numbers(call: &str) -> Vec<f64> {
    let inner = &call[call.find('(').unwrap() + 1..call.rfind(')').unwrap()];
    inner
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect()
}

fn check_with_rs274(rs274: &Path, dir: &Path, name: &str, case: &Case) {
    let program = dir.join(format!("{name}.ngc"));
    std::fs::write(&program, &case.text).unwrap();
    // rs274 reads tool tables in inches; only the tool numbers matter here.
    let table = dir.join("tools.tbl");
    std::fs::write(&table, "T1 P1 Z1.0 D0.25\nT2 P2 Z1.0 D0.25\n").unwrap();
    let out = Command::new(rs274)
        .arg("-t")
        .arg(&table)
        .arg("-g")
        .arg(&program)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stderr.lines().all(|l| l == "executing"),
        "{name}: rs274 refused it: {stderr}"
    );
    let calls: Vec<&str> = stdout
        .lines()
        .filter_map(|l| l.trim_start().splitn(3, char::is_whitespace).nth(2))
        .map(str::trim)
        .collect();
    let blocks = motion_blocks(case);
    let mut rate = 0.0;
    let mut at = vec![0.0; 6];
    let mut k = 0;
    for call in calls {
        if call.starts_with("SET_FEED_RATE(") {
            rate = numbers(call)[0];
            continue;
        }
        let feed = call.starts_with("STRAIGHT_FEED(");
        if !(feed || call.starts_with("STRAIGHT_TRAVERSE(")) {
            continue;
        }
        let p = numbers(call);
        let (joints, minutes) = match blocks[k] {
            Block::Rapid { joints, .. } => (joints, None),
            Block::Feed {
                joints, minutes, ..
            } => (joints, Some(*minutes)),
            _ => unreachable!(),
        };
        assert_eq!(feed, minutes.is_some(), "{name}: move {k}: {call}");
        for ((v, l), s) in joints
            .as_slice()
            .iter()
            .zip(&case.letters.letters)
            .zip(&case.letters.scale)
        {
            let i = "XYZABC".find(*l).unwrap();
            assert!((p[i] - v * s).abs() <= 0.6e-4, "{name}: move {k}: {call}");
        }
        if let Some(want) = minutes {
            let d: Vec<f64> = (0..6).map(|i| p[i] - at[i]).collect();
            let range = if d[..3].iter().any(|v| v.abs() > 1e-7) {
                0..3
            } else {
                3..6
            };
            let length = d[range].iter().map(|v| v * v).sum::<f64>().sqrt();
            // The printed coordinates (4 decimals) limit the length, hence the time.
            let slack = 2e-4 / rate + 1e-4 * want;
            assert!(
                (length / rate - want).abs() <= slack,
                "{name}: move {k}: {} min at rs274's rate, {want} written",
                length / rate
            );
        }
        at = p;
        k += 1;
    }
    assert_eq!(k, blocks.len(), "{name}: moves rs274 read");
}

#[test]
#[ignore = "needs LinuxCNC's rs274: set TEZGAH_RS274 (see .ci/install-rs274)"]
fn rs274_reads_every_exported_program() {
    let rs274 = oracle::rs274();
    let dir = std::env::temp_dir().join(format!("tezgah-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        ("sag", export_program(SAG, "linear-delta", "", 0.01)),
        (
            "delta-arcs",
            export_program(DELTA_ARCS, "linear-delta", "", 0.01),
        ),
        (
            "table-ac",
            export_program(TABLE_AC, "table-ac", TABLE_AC_TOOLS, 0.01),
        ),
    ];
    for (name, case) in &cases {
        check_with_rs274(&rs274, &dir, name, case);
    }
    let mut runner = TestRunner::new(ProptestConfig {
        rng_seed: RngSeed::Fixed(0x7e27_a600_e0e0_0026),
        ..ProptestConfig::default()
    });
    for i in 0..8 {
        let (text, tol) = delta_program().new_tree(&mut runner).unwrap().current();
        let case = export_program(&text, "linear-delta", "", tol);
        check_with_rs274(&rs274, &dir, &format!("random-{i}"), &case);
    }
    for i in 0..4 {
        let text = table_ac_program().new_tree(&mut runner).unwrap().current();
        let case = export_program(&text, "table-ac", TABLE_AC_TOOLS, 0.01);
        check_with_rs274(&rs274, &dir, &format!("random-table-ac-{i}"), &case);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

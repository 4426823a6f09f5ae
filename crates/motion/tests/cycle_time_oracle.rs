//! Cycle time against a time-optimal lower bound, on `mill3`: G61.1 programs, where every
//! block starts and ends at rest.
//!
//! * Lines: a rest-to-rest straight move's time-optimal jerk-limited timing is Ruckig's
//!   one-axis optimum under the path limits the joints allow (V = min(F, minᵢ Vᵢ/|uᵢ|),
//!   A = minᵢ Aᵢ/|uᵢ|, J = minᵢ Jᵢ/|uᵢ|): ours must equal the sum over blocks (1e-6).
//! * Arcs: each block is bounded below by the slowest joint's own rest-to-rest optimum over its
//!   net travel, and by length/feed; ours must not be below the sum.
//!
//! Run with `$TEZGAH_PYTHON` (`.ci/install-ruckig`); skipped with a message without it. The
//! ratios ours/bound are printed (`--nocapture`) and recorded in NOTES-plan.md.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

use tezgah_geom::{Curve, Move, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::{PathItem, SegmentFeed};

fn python(var: &str, module: &str, install: &str) -> Option<std::ffi::OsString> {
    let Some(python) = std::env::var_os(var) else {
        println!("skipped: {var} is not set (see {install})");
        return None;
    };
    let probe = Command::new(&python)
        .args(["-c", &format!("import {module}")])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        println!("skipped: {python:?} cannot import {module} (see {install})");
        return None;
    }
    Some(python)
}

/// Runs `script` with `input` on stdin and returns its stdout lines.
fn ask(python: &std::ffi::OsString, script: &str, input: String) -> Vec<String> {
    let mut child = Command::new(python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the oracle");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let lines: Vec<String> = BufReader::new(child.stdout.take().unwrap())
        .lines()
        .map(|l| l.unwrap())
        .collect();
    writer.join().unwrap().unwrap();
    assert!(child.wait().unwrap().success(), "oracle failed");
    lines
}

fn moves_of(text: &str) -> Vec<Move> {
    tezgah_gcode::program_moves(text, tezgah_gcode::Config::default()).unwrap()
}

fn items_of(moves: &[Move], machine: &Machine) -> Vec<PathItem> {
    smooth::build(
        moves.iter().copied(),
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap()
}

/// Our duration of the items (plan + interpolate, as `tezgah run`).
fn ours(items: Vec<PathItem>, machine: &Machine) -> f64 {
    run(
        items,
        &machine.kinematics,
        PlanMachine::from_machine(machine).unwrap(),
        PlanOptions {
            period: machine.motion.period_s,
            chord_share: smooth::CHORD_SHARE,
            ..PlanOptions::default()
        },
        (Vec3::zeros(), [0.0; 3]),
        |_, _| {},
    )
    .unwrap()
}

/// A pocket outline of long lines and R10 arcs at a few depths.
fn pocket() -> String {
    let mut s = String::from("G21 G90 G94 G17 G61.1\nF2400\nG1 X-50 Y-60 Z2\n");
    for k in 0..3 {
        let d = -0.5 * (k + 1) as f64;
        s.push_str(&format!(
            "G1 Z{d}\nG1 X50\nG3 X60 Y-50 R10\nG1 Y50\nG3 X50 Y60 R10\nG1 X-50\nG3 X-60 Y50 R10\n\
             G1 Y-50\nG3 X-50 Y-60 R10\n"
        ));
    }
    s.push_str("M2\n");
    s
}

/// Ruckig's one-axis rest-to-rest durations of `(distance, V, A, J)` cases.
fn ruckig_rest_to_rest(python: &std::ffi::OsString, cases: &[[f64; 4]]) -> Vec<f64> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/oracle/ruckig_batch.py");
    let input: String = cases
        .iter()
        .map(|[l, v, a, j]| format!("{l:?} 0.0 0.0 {v:?} {a:?} {j:?}\n"))
        .collect();
    ask(python, script, input)
        .iter()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn g61_1_cycle_time_against_per_block_ruckig() {
    let Some(python) = python("TEZGAH_PYTHON", "ruckig", ".ci/install-ruckig") else {
        return;
    };
    let machine = Machine::default_machine();
    let j = &machine.joints;
    let (vj, aj, jj): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        j.iter().map(|x| x.max_velocity * x.to_internal()).collect(),
        j.iter()
            .map(|x| x.max_acceleration * x.to_internal())
            .collect(),
        j.iter().map(|x| x.max_jerk * x.to_internal()).collect(),
    );
    // Random 3D lines with random feeds, every block ending at rest.
    let mut seed: u64 = 0x61_1e55;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("G21 G90 G94 G61.1\n");
    let mut p = Vec3::zeros();
    let mut lines = vec![];
    for _ in 0..60 {
        let q = Vec3::new(
            (next() - 0.5) * 100.0,
            (next() - 0.5) * 100.0,
            (next() - 0.5) * 20.0,
        );
        let f = ((60.0 + next() * 12_000.0) * 10.0).round() / 10.0;
        text.push_str(&format!("G1 X{:.4} Y{:.4} Z{:.4} F{f:.1}\n", q.x, q.y, q.z));
        let q4 = Vec3::new(
            (q.x * 1e4).round() / 1e4,
            (q.y * 1e4).round() / 1e4,
            (q.z * 1e4).round() / 1e4,
        );
        let d = q4 - p;
        let len = d.norm();
        let u = d / len;
        let g = |lim: &[f64]| {
            (0..3)
                .map(|i| lim[i] / u[i].abs())
                .fold(f64::INFINITY, f64::min)
        };
        lines.push([len, g(&vj).min(f / 60.0), g(&aj), g(&jj)]);
        p = q4;
    }
    text.push_str("M2\n");
    let items = items_of(&moves_of(&text), &machine);
    let ours_lines = ours(items, &machine);
    let bound: f64 = ruckig_rest_to_rest(&python, &lines).iter().sum();
    println!(
        "G61.1 lines: ours {ours_lines:.6} s, sum of Ruckig {bound:.6} s, ratio {:.9}",
        ours_lines / bound
    );
    assert!(
        (ours_lines / bound - 1.0).abs() <= 1e-6,
        "ours {ours_lines} against {bound}"
    );

    // Arcs: a pocket under G61.1. Per block, the slowest joint's own rest-to-rest optimum over
    // its net travel, and length/feed, each bound the block from below.
    let text = pocket();
    let moves = moves_of(&text);
    let items = items_of(&moves, &machine);
    let mut cases = vec![];
    let mut per_block = vec![];
    let mut last = Vec3::zeros();
    for item in &items {
        if let PathItem::Segment(seg) = item {
            let (a, b) = seg.curve.domain();
            let (p0, p1) = (seg.curve.point(a), seg.curve.point(b));
            let feed = match seg.feed {
                SegmentFeed::Feed(f) => f,
                _ => f64::INFINITY,
            };
            let first = cases.len();
            for i in 0..3 {
                let d = (p1[i] - p0[i]).abs();
                if d > 1e-9 {
                    cases.push([d, vj[i], aj[i], jj[i]]);
                }
            }
            per_block.push((first, cases.len(), seg.length / feed));
            last = p1;
        }
    }
    assert!(last.norm() > 0.0);
    let t = ruckig_rest_to_rest(&python, &cases);
    let bound: f64 = per_block
        .iter()
        .map(|&(a, b, lf)| t[a..b].iter().copied().fold(lf, f64::max))
        .sum();
    let ours_arcs = ours(items, &machine);
    println!(
        "G61.1 pocket: ours {ours_arcs:.4} s, per-block bound {bound:.4} s, ratio {:.3}",
        ours_arcs / bound
    );
    assert!(
        ours_arcs >= bound * (1.0 - 1e-9),
        "ours {ours_arcs} below {bound}"
    );
}

//! Cycle time against time-optimal lower bounds, on `mill3` (joints = tip coordinates).
//!
//! * G64 programs: the same smoothed path (the builder `tezgah run` uses) is handed to TOPP-RA
//!   (hungpham2511/toppra, Pham & Pham 2018) with the joints' velocity and acceleration limits
//!   and the feed as a limit on ds/dt, jerk unlimited; where our path comes to rest (corners
//!   kept sharp, stops, the end) the path is cut and each run is solved rest to rest. Any
//!   jerk-limited plan of the path takes at least that long, so ours ≥ TOPP-RA (1 % for
//!   TOPP-RA's grid and spline). Run with `$TEZGAH_TOPPRA_PYTHON` (`.ci/install-toppra`);
//!   ignored by a plain `cargo test`, failing without it when run.
//! * G61.1 programs of lines: every block is a rest-to-rest straight move, whose time-optimal
//!   jerk-limited timing is Ruckig's one-axis optimum under the path limits the joints allow
//!   (V = min(F, minᵢ Vᵢ/|uᵢ|), A = minᵢ Aᵢ/|uᵢ|, J = minᵢ Jᵢ/|uᵢ|): ours must equal the sum
//!   (1e-6). With arcs, each block is bounded below by the slowest joint's own rest-to-rest
//!   optimum and by length/feed. Run with `$TEZGAH_PYTHON` (`.ci/install-ruckig`).
//!
//! The ratios ours/bound are printed (`--nocapture`), not
//! asserted beyond the bound itself and a generous ceiling for the lines-and-arcs pocket.

#[path = "../benches/common/mod.rs"]
mod common;
mod python_oracle;

use python_oracle::{ask, python};

use tezgah_geom::{ArcLengthMap, Curve, Move, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::{Junction, PathItem, SegmentFeed};

/// Waypoint spacing along the path handed to TOPP-RA, mm (at least 8 per segment).
const STEP: f64 = 0.05;

fn moves_of(text: &str) -> Vec<Move> {
    // The demo's tool table, for the demo (the other programs use no tool).
    let tools = include_str!("../../../examples/tools.tbl");
    let config = tezgah_gcode::Config {
        tool_table: tezgah_gcode::ToolTable::parse(tools).unwrap(),
        ..tezgah_gcode::Config::default()
    };
    tezgah_gcode::program_moves(text, config).unwrap()
}

/// Our duration of the items (plan + interpolate, as `tezgah run`).
fn ours(items: Vec<PathItem>, machine: &Machine) -> f64 {
    run(
        items,
        PlanMachine::from_machine(machine).unwrap(),
        common::plan_options(machine),
        (Vec3::zeros(), [0.0; 3]),
        |_, _| {},
    )
    .unwrap()
}

/// TOPP-RA's duration of the path: the sum over runs between rests, plus dwells.
fn toppra_bound(python: &std::ffi::OsString, items: &[PathItem], machine: &Machine) -> f64 {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/oracle/toppra_duration.py"
    );
    let j = &machine.joints;
    let limits: Vec<String> = j
        .iter()
        .map(|x| x.max_velocity * x.to_internal())
        .chain(j.iter().map(|x| x.max_acceleration * x.to_internal()))
        .map(|x| format!("{x:?}"))
        .collect();
    let header = format!(
        "3\n{}\n",
        limits[..3].join(" ") + " " + &limits[j.len()..j.len() + 3].join(" ")
    );
    let mut total = 0.0;
    let mut run = String::new();
    let mut s = 0.0;
    let mut count = 0usize;
    let flush = |run: &mut String, count: &mut usize, total: &mut f64| {
        if *count >= 2 {
            let out = ask(python, script, header.clone() + run);
            let d: f64 = out[0].split_whitespace().next().unwrap().parse().unwrap();
            assert!(
                d.is_finite(),
                "TOPP-RA failed on a run of {count} waypoints"
            );
            *total += d;
        }
        run.clear();
        *count = 0;
    };
    for item in items {
        match item {
            PathItem::Segment(seg) => {
                assert!(!seg.rotary_only(), "mill3 programs only");
                let feed = match seg.feed {
                    SegmentFeed::Feed(f) => f,
                    SegmentFeed::InverseTime(t) => seg.length / t,
                    SegmentFeed::Rapid => 1e9,
                };
                let n = ((seg.length / STEP).ceil() as usize).max(8);
                let (ua, ub) = seg.curve.domain();
                let map = ArcLengthMap::new(&*seg.curve, 1e-10).ok();
                for k in usize::from(count > 0)..=n {
                    let f = k as f64 / n as f64;
                    let u = match &map {
                        Some(m) => m.u_at(&*seg.curve, f * m.length()),
                        None => ua + (ub - ua) * f,
                    };
                    let p = seg.curve.point(u);
                    run.push_str(&format!(
                        "{:?} {feed:?} {:?} {:?} {:?}\n",
                        s + f * seg.length,
                        p.x,
                        p.y,
                        p.z
                    ));
                    count += 1;
                }
                s += seg.length;
                if matches!(seg.end, Junction::Corner | Junction::Stop) {
                    flush(&mut run, &mut count, &mut total);
                }
            }
            PathItem::Dwell { seconds, .. } => {
                flush(&mut run, &mut count, &mut total);
                total += seconds;
            }
            PathItem::Stop { .. } => flush(&mut run, &mut count, &mut total),
        }
    }
    flush(&mut run, &mut count, &mut total);
    total
}

/// A pocket outline of long lines and R10 arcs at a few depths.
fn pocket() -> String {
    let mut s = String::from("G21 G90 G94 G17 G64\nF2400\nG1 X-50 Y-60 Z2\n");
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

/// Dense surfacing as the benches generate it: 4 passes, no approach or retract.
fn surfacing() -> String {
    common::Surfacing {
        opening: "G21 G90 G94 G64\nF3000\n",
        passes: 4,
        closing: "M2\n",
    }
    .program()
}

/// A saw-tooth of 2 mm moves turning 90° at every vertex (all blended under G64).
fn saw() -> String {
    let mut s = String::from("G21 G90 G94 G64\nF3000\n");
    for k in 1..=40 {
        let y = if k % 2 == 1 { 1.414 } else { 0.0 };
        s.push_str(&format!("G1 X{:.4} Y{y}\n", k as f64 * 1.414));
    }
    s.push_str("M2\n");
    s
}

#[test]
#[ignore = "needs TOPP-RA: set TEZGAH_TOPPRA_PYTHON (see .ci/install-toppra)"]
fn g64_cycle_time_is_at_least_the_toppra_bound() {
    let python = python("TEZGAH_TOPPRA_PYTHON", "toppra", ".ci/install-toppra");
    let machine = Machine::default_machine();
    let programs = [
        ("pocket", pocket(), Some(3.0)),
        ("surfacing", surfacing(), None),
        ("saw 90°", saw(), None),
        (
            "demo",
            include_str!("../../../examples/demo.ngc").to_owned(),
            None,
        ),
    ];
    for (name, text, ceiling) in programs {
        let moves = moves_of(&text);
        let items = common::smooth_items(&moves, &machine);
        let bound = toppra_bound(&python, &items, &machine);
        let ours = ours(items, &machine);
        let ratio = ours / bound;
        println!("{name}: ours {ours:.4} s, TOPP-RA {bound:.4} s, ratio {ratio:.3}");
        assert!(
            ours >= 0.99 * bound,
            "{name}: ours {ours} below the bound {bound}"
        );
        // Long lines and large arcs leave jerk little to cost: the jerk ramps at each end of
        // a 100 mm line are a small part of it.
        if let Some(c) = ceiling {
            assert!(ratio <= c, "{name}: ratio {ratio} above {c}");
        }
    }
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
#[ignore = "needs Ruckig: set TEZGAH_PYTHON (see .ci/install-ruckig)"]
fn g61_1_cycle_time_against_per_block_ruckig() {
    let python = python("TEZGAH_PYTHON", "ruckig", ".ci/install-ruckig");
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
    let items = common::smooth_items(&moves_of(&text), &machine);
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
    let text = pocket().replace("G64", "G61.1");
    let moves = moves_of(&text);
    let items = common::smooth_items(&moves, &machine);
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

//! One pass of each stage of the pipeline bench's programs, for instruction counts on a shared
//! machine (`perf stat -e instructions:u` or `valgrind --tool=callgrind` per stage; wall time
//! is too noisy there). `cargo run --profile bench -p tezgah-motion --example stages -- STAGE
//! [PROGRAM]`: STAGE is `gen` (the program text only), `parse`, `smooth`, `plan` or `whole`
//! (each runs the stages before it too, so a stage's cost is its count minus the previous
//! one's), PROGRAM `surfacing` (default), `lines_arcs` or `surfacing_1m` (the path bench's
//! 1 M-move raster, smoothing only; `gen` and `smooth` apply).

use std::fmt::Write;
use std::hint::black_box;

use tezgah_geom::{Move, MoveKind, PathMode, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions, Smoother};
use tezgah_motion::plan::lookahead::plan_all;
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::PathItem;

/// The pipeline bench's dense surfacing program (same generator and seed).
fn surfacing() -> String {
    let mut s = String::from("G21 G90 G94 G64\nF3000\nG0 X0 Y0 Z2\nG1 Z0\n");
    let mut seed: u64 = 12345;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let z = |x: f64, y: f64| 2.0 * (-(x - 30.0).powi(2) / 400.0 - (y - 5.0).powi(2) / 100.0).exp();
    for pass in 0..20 {
        let y = pass as f64 * 0.5;
        let (mut x, dir) = if pass % 2 == 0 {
            (0.0, 1.0)
        } else {
            (60.0, -1.0)
        };
        let _ = writeln!(s, "G1 X{x:.4} Y{y:.4} Z{:.4}", z(x, y));
        while (0.0..=60.0).contains(&x) {
            x += dir * (0.05 + 0.25 * next());
            let _ = writeln!(s, "G1 X{x:.4} Y{y:.4} Z{:.4}", z(x, y));
        }
    }
    s.push_str("G0 Z5\nM2\n");
    s
}

/// The pipeline bench's long lines and arcs.
fn lines_and_arcs() -> String {
    let mut s = String::from("G21 G90 G94 G17 G64\nF2400\nG0 X-50 Y-60 Z2\n");
    for k in 0..10 {
        let d = -0.5 * (k + 1) as f64;
        let _ = writeln!(
            s,
            "G1 Z{d}\nG1 X50\nG3 X60 Y-50 R10\nG1 Y50\nG3 X50 Y60 R10\nG1 X-50\nG3 X-60 Y50 R10\n\
             G1 Y-50\nG3 X-50 Y-60 R10"
        );
    }
    s.push_str("G0 Z5\nM2\n");
    s
}

/// The path bench's 1 M-move raster (xorshift64*, same seed).
fn surfacing_1m() -> Vec<Move> {
    let mut state: u64 = 0x0bad_5eed;
    let mut unit = || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut m = vec![
        Move {
            line: 1,
            kind: MoveKind::FeedRate { value: 3000.0 },
        },
        Move {
            line: 2,
            kind: MoveKind::PathMode(PathMode::Continuous {
                tolerance: Some(0.01),
            }),
        },
    ];
    let z = |x: f64, y: f64| 2.0 * (x / 7.0).sin() * (y / 5.0).cos();
    let (mut row, mut s) = (0usize, 0.0f64);
    for i in 0..1_000_000usize {
        s += 0.05 + 0.25 * unit();
        if s >= 60.0 {
            s = 0.0;
            row += 1;
        }
        let x = if row % 2 == 0 { s } else { 60.0 - s };
        let y = 2.0 * row as f64;
        m.push(Move {
            line: i as u32 + 3,
            kind: MoveKind::Feed {
                end: Pose::new(x, y, z(x, y), 0.0, 0.0, 0.0),
            },
        });
    }
    m
}

fn smooth_items(moves: &[Move], machine: &Machine) -> Vec<PathItem> {
    smooth::build(
        moves.iter().cloned(),
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("smoothing failed: {e}"))
}

fn plan_options(machine: &Machine) -> PlanOptions {
    PlanOptions {
        period: machine.motion.period_s,
        chord_share: smooth::CHORD_SHARE,
        ..PlanOptions::default()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let stage = args.get(1).map(String::as_str).unwrap_or("whole");
    let program = args.get(2).map(String::as_str).unwrap_or("surfacing");
    let machine = Machine::default_machine();
    if program == "surfacing_1m" {
        let moves = surfacing_1m();
        if stage == "gen" {
            black_box(moves);
            return;
        }
        let sm = Smoother::new(
            moves.into_iter(),
            SmoothOptions {
                start: Pose::ZERO,
                ..SmoothOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut n = 0usize;
        for item in sm {
            black_box(item.unwrap_or_else(|e| panic!("{e}")));
            n += 1;
        }
        eprintln!("surfacing_1m: {n} items");
        return;
    }
    let text = match program {
        "lines_arcs" => lines_and_arcs(),
        _ => surfacing(),
    };
    if stage == "gen" {
        black_box(text);
        return;
    }
    let moves = tezgah_gcode::program_moves(&text, tezgah_gcode::Config::default())
        .unwrap_or_else(|e| panic!("parse failed: {e:?}"));
    if stage == "parse" {
        black_box(moves);
        return;
    }
    let items = smooth_items(&moves, &machine);
    if stage == "smooth" {
        eprintln!("{} moves -> {} items", moves.len(), items.len());
        black_box(items);
        return;
    }
    let pm = PlanMachine::from_machine(&machine).unwrap_or_else(|e| panic!("{e}"));
    if stage == "plan" {
        black_box(
            plan_all(items, pm, plan_options(&machine))
                .map(|p| p.len())
                .ok(),
        );
        return;
    }
    let mut n = 0u64;
    let mut acc = 0.0;
    let d = run(
        items,
        pm,
        plan_options(&machine),
        (Vec3::zeros(), [0.0; 3]),
        |s, _| {
            n += 1;
            acc += s.joints[0];
        },
    )
    .unwrap_or_else(|e| panic!("run failed: {e}"));
    black_box(acc);
    eprintln!("program {d:.3} s, {n} samples");
}

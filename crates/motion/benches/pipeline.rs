//! The `tezgah run` pipeline without writing: parse (tezgah-gcode, a dev-dependency only) →
//! smoothing builder (compression and corner blends, as `run` uses it) → plan → interpolate at
//! 1 ms with the machine's inverse kinematics, on `mill3`. Reported as × real time = program
//! duration / wall time per run, and stage by stage:
//! * `parse`: G-code text → moves;
//! * `smooth`: moves → path items (collected);
//! * `plan`: path items → timed pieces (collected), the look-ahead alone;
//! * `plan_interpolate`: plan + interpolate + inverse kinematics from the same items (so
//!   interpolation = this − `plan`);
//! * `whole`: all of it, as `run` does.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench pipeline -- --warm-up-time 1
//! --measurement-time 3`. Each program first prints its duration and one timed run per stage.

use std::fmt::Write;
use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use tezgah_geom::{Move, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::lookahead::plan_all;
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::PathItem;

/// Dense 3-axis surfacing: zig-zag passes of 0.05–0.3 mm segments over a smooth bump.
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

/// Long lines and arcs: a pocket outline of 100 mm lines and R10 corners, several depths.
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

fn parse(text: &str) -> Vec<Move> {
    tezgah_gcode::program_moves(text, tezgah_gcode::Config::default()).unwrap()
}

/// The smoothing builder as `tezgah run` sets it up.
fn smooth_items(moves: &[Move], machine: &Machine) -> Vec<PathItem> {
    smooth::build(
        moves.iter().cloned(),
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap()
}

fn plan_options(machine: &Machine) -> PlanOptions {
    PlanOptions {
        period: machine.motion.period_s,
        chord_share: smooth::CHORD_SHARE,
        ..PlanOptions::default()
    }
}

/// Plan, interpolate and solve the inverse kinematics; returns (program duration, samples).
fn plan_interpolate(items: Vec<PathItem>, machine: &Machine) -> (f64, u64) {
    let pm = PlanMachine::from_machine(machine).unwrap();
    let mut n = 0u64;
    let mut acc = 0.0;
    let d = run(
        items,
        pm,
        plan_options(machine),
        (Vec3::zeros(), [0.0; 3]),
        |s, _| {
            n += 1;
            acc += s.joints[0];
        },
    )
    .unwrap();
    black_box(acc);
    (d, n)
}

fn plan_only(items: Vec<PathItem>, machine: &Machine) -> usize {
    let pm = PlanMachine::from_machine(machine).unwrap();
    plan_all(items, pm, plan_options(machine)).unwrap().len()
}

fn whole(text: &str, machine: &Machine) -> (f64, u64) {
    let moves = parse(text);
    plan_interpolate(smooth_items(&moves, machine), machine)
}

fn bench(c: &mut Criterion) {
    let machine = Machine::default_machine();
    for (name, text) in [("surfacing", surfacing()), ("lines_arcs", lines_and_arcs())] {
        let moves = parse(&text);
        let items = smooth_items(&moves, &machine);
        let time = |f: &mut dyn FnMut()| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        };
        let t_parse = time(&mut || {
            black_box(parse(&text));
        });
        let t_smooth = time(&mut || {
            black_box(smooth_items(&moves, &machine));
        });
        let fresh = || smooth_items(&moves, &machine);
        let mut it = Some(fresh());
        let t_plan = time(&mut || {
            black_box(plan_only(it.take().unwrap(), &machine));
        });
        let mut it = Some(fresh());
        let mut d = 0.0;
        let mut n = 0;
        let t_pi = time(&mut || {
            (d, n) = plan_interpolate(it.take().unwrap(), &machine);
        });
        let t_whole = time(&mut || {
            black_box(whole(&text, &machine));
        });
        eprintln!(
            "{name}: {} lines, {} path items, program {d:.3} s, {n} samples; one run: parse \
             {:.2} ms, smooth {:.2} ms, plan {:.2} ms, interpolate+kinematics {:.2} ms, whole \
             {:.2} ms = {:.0}x real time",
            text.lines().count(),
            items.len(),
            t_parse * 1e3,
            t_smooth * 1e3,
            t_plan * 1e3,
            (t_pi - t_plan) * 1e3,
            t_whole * 1e3,
            d / t_whole
        );
        let mut g = c.benchmark_group(name);
        g.bench_function("parse", |b| b.iter(|| black_box(parse(&text))));
        g.bench_function("smooth", |b| {
            b.iter(|| black_box(smooth_items(&moves, &machine)))
        });
        // The items are not `Clone` (boxed curves): each iteration gets a fresh set, built
        // outside the timing.
        g.bench_function("plan", |b| {
            b.iter_batched(fresh, |i| plan_only(i, &machine), BatchSize::LargeInput)
        });
        g.bench_function("plan_interpolate", |b| {
            b.iter_batched(
                fresh,
                |i| plan_interpolate(i, &machine),
                BatchSize::LargeInput,
            )
        });
        g.bench_function("whole", |b| b.iter(|| black_box(whole(&text, &machine))));
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);

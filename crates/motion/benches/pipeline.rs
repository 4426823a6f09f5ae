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

use std::hint::black_box;
use std::time::Instant;

#[path = "common/mod.rs"]
mod common;

use common::{lines_and_arcs, parse, plan_options, smooth_items, surfacing};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use tezgah_geom::Vec3;
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::plan::lookahead::plan_all;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::PathItem;

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

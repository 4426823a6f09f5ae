//! The verification stage of `tezgah run`: plan + interpolate on the dense surfacing program
//! (mill3, 1 ms), with the samples going nowhere (`interpolate`), to the replay against the
//! smoothed path only (`verify_smoothed`), and to the replay against the program as `run`
//! does it (`verify_program`). The replay's cost is the difference from `interpolate`.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench verify -- --warm-up-time 1
//! --measurement-time 3`. Each variant first prints one timed run and the cost per sample.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

#[path = "common/mod.rs"]
mod common;

use common::{parse, plan_options, smooth_items, surfacing};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use tezgah_geom::{Move, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::Verifier;
use tezgah_motion::{PathItem, Segment};

#[derive(Clone, Copy)]
enum Replay {
    None,
    Smoothed,
    Program,
}

/// Plan, interpolate and replay; returns (program duration, samples).
fn stage(items: Vec<PathItem>, moves: &[Move], machine: &Machine, replay: Replay) -> (f64, u64) {
    let pm = PlanMachine::from_machine(machine).unwrap();
    let mut verifier = match replay {
        Replay::None => None,
        Replay::Smoothed => Some(Verifier::new(&pm, machine.motion.period_s)),
        Replay::Program => Some(
            Verifier::new(&pm, machine.motion.period_s)
                .against(&pm, ProgramPath::new(Pose::ZERO, pm.initial, moves)),
        ),
    };
    let mut n = 0u64;
    let d = run(
        items,
        pm,
        plan_options(machine),
        (Vec3::zeros(), [0.0; 3]),
        |s, seg: &[Arc<Segment>]| {
            n += 1;
            if let Some(v) = verifier.as_mut() {
                v.push(s, seg);
            }
        },
    )
    .unwrap();
    if let Some(v) = verifier {
        black_box(v.finish());
    }
    (d, n)
}

fn bench(c: &mut Criterion) {
    let machine = Machine::default_machine();
    let text = surfacing();
    let moves = parse(&text);
    let fresh = || smooth_items(&moves, &machine);
    let variants = [
        ("interpolate", Replay::None),
        ("verify_smoothed", Replay::Smoothed),
        ("verify_program", Replay::Program),
    ];
    let mut base = 0.0;
    for (name, r) in variants {
        let items = fresh();
        let t = Instant::now();
        let (d, n) = stage(items, &moves, &machine, r);
        let wall = t.elapsed().as_secs_f64();
        if matches!(r, Replay::None) {
            base = wall;
        }
        eprintln!(
            "{name}: program {d:.3} s, {n} samples, one run {:.1} ms = {:.0}x real time; \
             replay {:.1} ms, {:.0} ns per sample",
            wall * 1e3,
            d / wall,
            (wall - base) * 1e3,
            (wall - base) / n as f64 * 1e9
        );
    }
    let mut g = c.benchmark_group("verify");
    for (name, r) in variants {
        g.bench_function(name, |b| {
            b.iter_batched(
                fresh,
                |i| stage(i, &moves, &machine, r),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);

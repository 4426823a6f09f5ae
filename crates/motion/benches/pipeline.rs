//! The whole run pipeline without writing: parse (tezgah-gcode, a dev-dependency only) →
//! direct path → plan → interpolate at 1 ms with the machine's inverse kinematics, on `mill3`.
//! Reported as × real time = program duration / wall time per run.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench pipeline -- --warm-up-time 1
//! --measurement-time 5`. Each benchmark first prints its program's duration and one timed run.

use std::fmt::Write;
use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use tezgah_geom::{Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::direct::{build, DirectOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};

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

/// One full run; returns (program duration, samples).
fn pipeline(text: &str, machine: &Machine) -> (f64, u64) {
    let moves = tezgah_gcode::program_moves(text, tezgah_gcode::Config::default()).unwrap();
    let items = build(&moves, Pose::ZERO, DirectOptions::default()).unwrap();
    let pm = PlanMachine::from_machine(machine).unwrap();
    let mut n = 0u64;
    let mut acc = 0.0;
    let d = run(
        items,
        pm,
        PlanOptions::default(),
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

fn bench(c: &mut Criterion) {
    let machine = Machine::default_machine();
    for (name, text) in [("surfacing", surfacing()), ("lines_arcs", lines_and_arcs())] {
        let t = Instant::now();
        let (d, n) = pipeline(&text, &machine);
        let wall = t.elapsed().as_secs_f64();
        eprintln!(
            "{name}: {} lines, program {d:.3} s, {n} samples; one run {:.4} s = {:.0}x real time",
            text.lines().count(),
            wall,
            d / wall
        );
        c.bench_function(name, |b| b.iter(|| black_box(pipeline(&text, &machine))));
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);

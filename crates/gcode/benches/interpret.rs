//! Lex + parse + interpret throughput on a dense 3D-surfacing program.
//!
//! The program is generated in memory: a header, a rapid to the start, 1,000,000 `G1` lines
//! with X, Y and Z all changing, and `M2`. Set `TEZGAH_BENCH_NGC=/path/file.ngc` to also write
//! it out, e.g. to time LinuxCNC's `rs274` or `tezgah canon` on the same input.

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tezgah_gcode::{canon::Discard, Config, Interpreter};

/// Number of `G1` lines in the generated program.
const MOVES: usize = 1_000_000;

/// A point on the surfacing path: a circle of radius 50 mm stepping down 0.0001 mm per move,
/// back up every 100 moves.
fn point(i: usize) -> (f64, f64, f64) {
    let t = i as f64 * 0.001;
    (
        50.0 * t.cos(),
        50.0 * t.sin(),
        -1.0 - 0.0001 * (i % 100) as f64,
    )
}

fn surfacing_program(moves: usize) -> String {
    let mut p = String::with_capacity(moves * 40);
    p.push_str("G21 G90 G17 F1000\n");
    let (x, y, _) = point(0);
    writeln!(p, "G0 X{x:.4} Y{y:.4} Z5.0000").unwrap();
    for i in 0..moves {
        let (x, y, z) = point(i);
        writeln!(p, "G1 X{x:.4} Y{y:.4} Z{z:.4}").unwrap();
    }
    p.push_str("M2\n");
    p
}

fn bench_interpret(c: &mut Criterion) {
    let program = surfacing_program(MOVES);
    if let Ok(path) = std::env::var("TEZGAH_BENCH_NGC") {
        std::fs::write(&path, &program).expect("writing TEZGAH_BENCH_NGC");
    }
    // The program must run to completion, or the benchmark would time an early error.
    Interpreter::new(Config::default())
        .run(&program, &mut Discard)
        .expect("the generated program runs");

    let mut group = c.benchmark_group("interpret");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    group.throughput(Throughput::Bytes(program.len() as u64));
    group.bench_function("surfacing_1M_lines", |b| {
        b.iter(|| {
            let mut interp = Interpreter::new(Config::default());
            interp
                .run(black_box(&program), &mut Discard)
                .expect("the generated program runs");
        })
    });
    group.finish();
}

criterion_group!(benches, bench_interpret);
criterion_main!(benches);

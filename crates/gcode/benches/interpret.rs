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

/// Passes of the loop in the control-flow benchmark.
const LOOP_PASSES: usize = 100_000;

/// A program dominated by O-word control flow and expressions: a subroutine called in a while
/// loop, an if/else in the body, and a G1 move computed from parameters on every pass. Each
/// pass executes 10 lines.
fn loop_program(passes: usize) -> String {
    format!(
        "G21 G90 F1000\n\
         o100 sub\n\
         #<r> = [#1 * 0.001 + 10]\n\
         o100 return [#<r> * COS[#1 * 0.36]]\n\
         o100 endsub\n\
         #1 = 0\n\
         o1 while [#1 LT {passes}]\n\
         o100 call [#1]\n\
         o2 if [[#1 MOD 2] EQ 0]\n\
         G1 X#<_value> Y[#1 * 0.001] Z[-1 - [#1 MOD 7] * 0.01]\n\
         o2 else\n\
         G1 X[#<_value> + 0.05] Y[#1 * 0.001]\n\
         o2 endif\n\
         #1 = [#1 + 1]\n\
         o1 endwhile\n\
         M2\n"
    )
}

fn bench_control_flow(c: &mut Criterion) {
    let program = loop_program(LOOP_PASSES);
    let mut interp = Interpreter::new(Config::default());
    interp
        .run(&program, &mut Discard)
        .expect("the loop program runs");
    let mut group = c.benchmark_group("interpret");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    // Lines executed, not lines of text: 10 per pass.
    group.throughput(Throughput::Elements((LOOP_PASSES * 10) as u64));
    group.bench_function("oword_loop_100k_passes", |b| {
        b.iter(|| {
            let mut interp = Interpreter::new(Config::default());
            interp
                .run(black_box(&program), &mut Discard)
                .expect("the loop program runs");
        })
    });
    group.finish();
}

criterion_group!(benches, bench_interpret, bench_control_flow);
criterion_main!(benches);

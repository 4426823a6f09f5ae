//! Export throughput on `examples/delta.ngc` (the diagonal of Ayyıldız, 2017, §5.4, a circle, a helix and
//! an arc on the linear delta, 936 blocks out at the default tolerance): interpretation
//! excluded, path building, segmentation and the deviation figure included.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use tezgah_gcode::{program_moves, Config};
use tezgah_kinematics::Machine;

const PROGRAM: &str = include_str!("../../../examples/delta.ngc");

fn bench(c: &mut Criterion) {
    let machine = Machine::builtin("linear-delta").unwrap();
    let moves = program_moves(PROGRAM, Config::default()).unwrap();
    let blocks = tezgah_export::export(moves.clone(), &[], &machine, 0.01, &|k| k)
        .unwrap()
        .summary
        .blocks_out;
    let mut group = c.benchmark_group("export");
    group.throughput(Throughput::Elements(blocks as u64));
    group.bench_function("delta", |b| {
        b.iter(|| {
            tezgah_export::export(black_box(moves.clone()), &[], &machine, 0.01, &|k| k).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

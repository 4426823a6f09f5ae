//! Inverse kinematics throughput (poses per second, one core) for each closed-form model,
//! through the same `Model` dispatch the interpolator uses. Target: ≥ 20 M poses/s.
//! Each iteration solves a batch of 1024 poses, continuity chained through `previous`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use tezgah_kinematics::{Kinematics, Machine, Tool};

mod poses;
use poses::{poses, BATCH};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("inverse");
    group.throughput(Throughput::Elements(BATCH as u64));
    for name in ["mill3", "yzca", "table-ac", "table-bc", "linear-delta"] {
        let m = Machine::builtin(name).unwrap();
        let tool = Tool::with_length(25.0);
        let ps = poses(&m, &tool);
        let q0 = m.kinematics.inverse(&ps[0], &tool, &m.home()).unwrap();
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut q = q0;
                for p in &ps {
                    q = m.kinematics.inverse(black_box(p), &tool, &q).unwrap();
                }
                black_box(q)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

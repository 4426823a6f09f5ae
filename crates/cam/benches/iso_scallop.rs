//! The speed target: an iso-scallop finishing path for a 100 × 100 mm free-form patch
//! at h = 0.01 mm with a 6 mm ball cutter, gouge checks included (< 2 s on two cores).

use criterion::{criterion_group, criterion_main, Criterion};
use tezgah_cam::{plan, testing, Cutter, CutterShape, Settings, StrategyKind};

fn iso_scallop_freeform(c: &mut Criterion) {
    let surface = testing::freeform(0.0);
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let settings = Settings::new(StrategyKind::IsoScallop, 0.01, 0.01);
    let mut group = c.benchmark_group("cam");
    group.sample_size(10);
    group.bench_function("iso_scallop_100mm_h0.01_ball6", |b| {
        b.iter(|| plan(&surface, &cutter, &settings).expect("plan"))
    });
    group.finish();
}

criterion_group!(benches, iso_scallop_freeform);
criterion_main!(benches);

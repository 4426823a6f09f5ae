//! Smoothing path builder throughput on 1 M-segment programs (issue 4's target: 1 M segments
//! per second on one core): a mixed-corner program of 1–5 mm lines (blending only), and a
//! dense surfacing raster of 0.05–0.3 mm moves at 0.01 mm tolerance (compression dominates).
//! The built items are consumed as the planner would (streaming), not collected.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench path -- --warm-up-time 1
//! --measurement-time 10`.

use std::hint::black_box;

#[path = "common/mod.rs"]
mod common;

use common::{corners, raster_1m, SEGMENTS};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tezgah_geom::Pose;
use tezgah_motion::path::smooth::{SmoothOptions, Smoother};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("smooth_path_1M");
    g.sample_size(10);
    g.throughput(Throughput::Elements(SEGMENTS as u64));
    for (name, program) in [
        ("corners_1_5mm", corners()),
        ("surfacing_10um", raster_1m()),
    ] {
        let opts = SmoothOptions {
            start: Pose::ZERO,
            ..SmoothOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| {
                let sm = Smoother::new(program.iter().cloned(), opts.clone()).unwrap();
                let mut n = 0usize;
                for item in sm {
                    black_box(item.unwrap());
                    n += 1;
                }
                n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Smoothing path builder throughput on 1 M-segment programs (issue 4's target: 1 M segments
//! per second on one core): a mixed-corner program of 1–5 mm lines (blending only), and a
//! dense surfacing raster of 0.05–0.3 mm moves at 0.01 mm tolerance (compression dominates).
//! The built items are consumed as the planner would (streaming), not collected.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench path -- --warm-up-time 1
//! --measurement-time 10`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tezgah_geom::{Move, MoveKind, PathMode, Pose};
use tezgah_motion::path::smooth::{SmoothOptions, Smoother};

const SEGMENTS: usize = 1_000_000;

/// xorshift64* (Vigna 2016).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn header() -> Vec<Move> {
    vec![
        Move {
            line: 1,
            kind: MoveKind::FeedRate { value: 3000.0 },
        },
        Move {
            line: 2,
            kind: MoveKind::PathMode(PathMode::Continuous {
                tolerance: Some(0.01),
            }),
        },
    ]
}

fn g1(line: usize, x: f64, y: f64, z: f64) -> Move {
    Move {
        line: line as u32,
        kind: MoveKind::Feed {
            end: Pose::new(x, y, z, 0.0, 0.0, 0.0),
        },
    }
}

/// 1–5 mm lines turning 5°–150° at every vertex: every junction is blended.
fn corners() -> Vec<Move> {
    let mut rng = Rng(0x005e_ed0f_bec4);
    let mut m = header();
    let (mut x, mut y, mut h) = (0.0, 0.0, 0.0f64);
    for i in 0..SEGMENTS {
        let turn = (5.0 + 145.0 * rng.unit()).to_radians();
        h += if rng.unit() < 0.5 { turn } else { -turn };
        let len = 1.0 + 4.0 * rng.unit();
        x += len * h.cos();
        y += len * h.sin();
        m.push(g1(i + 3, x, y, 0.0));
    }
    m
}

/// Raster rows 60 mm long over `z = 2 sin(x/7) cos(y/5)`, points 0.05–0.3 mm apart.
fn surfacing() -> Vec<Move> {
    let mut rng = Rng(0x0bad_5eed);
    let mut m = header();
    let z = |x: f64, y: f64| 2.0 * (x / 7.0).sin() * (y / 5.0).cos();
    let (mut row, mut s) = (0usize, 0.0f64);
    for i in 0..SEGMENTS {
        s += 0.05 + 0.25 * rng.unit();
        if s >= 60.0 {
            s = 0.0;
            row += 1;
        }
        let x = if row % 2 == 0 { s } else { 60.0 - s };
        let y = 2.0 * row as f64;
        m.push(g1(i + 3, x, y, z(x, y)));
    }
    m
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("smooth_path_1M");
    g.sample_size(10);
    g.throughput(Throughput::Elements(SEGMENTS as u64));
    for (name, program) in [
        ("corners_1_5mm", corners()),
        ("surfacing_10um", surfacing()),
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

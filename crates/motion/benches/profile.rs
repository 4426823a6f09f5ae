//! Profile solver throughput: solves per second on a random mix of moves (the same kind of mix
//! as the Ruckig oracle test: limits over decades, end speeds often 0 or V, distances from
//! out-of-reach to long cruises), and `state_at` evaluations per second on the solved profiles.
//!
//! Run briefly with `cargo bench -p tezgah-motion --bench profile -- --warm-up-time 1
//! --measurement-time 3`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tezgah_motion::profile::{solve, speed_change_distance, Limits, Profile};

const MOVES: usize = 4096;

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

fn moves() -> Vec<(f64, f64, f64, Limits)> {
    let mut rng = Rng(0x005e_ed0f_bec4);
    (0..MOVES)
        .map(|_| {
            let l = Limits::new(
                10f64.powf(rng.unit() * 3.0),
                10f64.powf(1.0 + rng.unit() * 3.0),
                10f64.powf(2.0 + rng.unit() * 4.0),
            )
            .unwrap();
            let vmax = l.max_velocity();
            let speed = |r: &mut Rng| match r.unit() {
                p if p < 0.2 => 0.0,
                p if p < 0.3 => vmax,
                _ => r.unit() * vmax,
            };
            let (v0, v1) = (speed(&mut rng), speed(&mut rng));
            let scale = speed_change_distance(v0, v1, &l).unwrap()
                + speed_change_distance(0.0, vmax, &l).unwrap();
            (scale * 10f64.powf(rng.unit() * 3.0 - 1.5), v0, v1, l)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let moves = moves();
    let mut g = c.benchmark_group("profile");
    g.throughput(Throughput::Elements(MOVES as u64));
    g.bench_function("solve (random mix)", |b| {
        b.iter(|| {
            for &(d, v0, v1, ref l) in &moves {
                let _ = black_box(solve(black_box(d), black_box(v0), black_box(v1), l));
            }
        })
    });
    let profiles: Vec<Profile> = moves
        .iter()
        .filter_map(|&(d, v0, v1, ref l)| solve(d, v0, v1, l).ok())
        .collect();
    const SAMPLES: usize = 64;
    g.throughput(Throughput::Elements((profiles.len() * SAMPLES) as u64));
    g.bench_function("state_at", |b| {
        b.iter(|| {
            for p in &profiles {
                let dt = p.duration() / SAMPLES as f64;
                for i in 0..SAMPLES {
                    black_box(p.state_at(black_box(dt * i as f64)));
                }
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

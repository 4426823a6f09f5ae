//! Inverse kinematics throughput (poses per second, one core) for each closed-form model,
//! through the same `Model` dispatch the interpolator uses. Target: ≥ 20 M poses/s.
//! Each iteration solves a batch of 1024 poses, continuity chained through `previous`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::Vector3;
use tezgah_kinematics::{Kinematics, Machine, Tool, ToolPose};

const BATCH: usize = 1024;

/// Poses along a smooth 5-axis-ish path that every built-in machine can reach.
fn poses(machine: &Machine, tool: &Tool) -> Vec<ToolPose> {
    let k = &machine.kinematics;
    let mut q = machine.home();
    (0..BATCH)
        .map(|i| {
            let t = i as f64 / BATCH as f64 * std::f64::consts::TAU;
            let mut v = machine.to_file_units(&q);
            match machine.name.as_str() {
                "linear-delta" => {
                    // a 60 mm circle at z = −20 via the inverse itself
                    let p = ToolPose::vertical(Vector3::new(60.0 * t.cos(), 60.0 * t.sin(), -20.0));
                    q = k.inverse(&p, tool, &q).unwrap();
                    return p;
                }
                "yzca" => v.copy_from_slice(&[
                    40.0 + 10.0 * t.sin(),
                    5.0 * t.cos(),
                    360.0 * t / 3.0,
                    30.0 * t.sin(),
                ]),
                "mill3" => v.copy_from_slice(&[50.0 * t.cos(), 50.0 * t.sin(), -5.0]),
                _ => v.copy_from_slice(&[
                    30.0 * t.cos(),
                    20.0 * t.sin(),
                    -10.0,
                    10.0 + 40.0 * (1.0 + t.sin()),
                    2.0 * t.to_degrees(),
                ]),
            }
            q = machine.from_file_units(&v).unwrap();
            k.forward(&q, tool).unwrap()
        })
        .collect()
}

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

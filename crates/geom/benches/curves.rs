//! Curve-layer throughput: NURBS evaluation with derivatives, arc-length map build per knot
//! span, s→u lookups, and fitting a 1000-point polyline (interpolation and the
//! tolerance-bounded approximation the compression stage will use).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use tezgah_geom::fit::{approximate, interpolate, Parameterisation};
use tezgah_geom::{ArcLengthMap, Curve, Nurbs, Vec3};

/// A weighted clamped cubic with `n` control points on a wavy 3-D path.
fn wavy_nurbs(n: usize) -> Nurbs {
    let pts: Vec<Vec3> = (0..n)
        .map(|i| {
            let x = i as f64;
            Vec3::new(x, 5.0 * (0.7 * x).sin(), 2.0 * (0.3 * x).cos())
        })
        .collect();
    let w: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * ((i % 3) as f64)).collect();
    let mut knots = vec![0.0; 4];
    knots.extend((1..n - 3).map(|i| i as f64));
    knots.extend([(n - 3) as f64; 4]);
    Nurbs::new(3, &pts, &w, knots).unwrap()
}

/// A CAM-like polyline: `n` points, chords 0.05–0.3 mm, on a smooth 3-D curve.
fn cam_polyline(n: usize) -> Vec<Vec3> {
    let mut s = 0.0;
    (0..n)
        .map(|i| {
            s += 0.05 + 0.25 * (((i * 7919) % 101) as f64 / 100.0);
            let w = std::f64::consts::TAU * s / 40.0;
            Vec3::new(s, 3.0 * w.sin(), 2.0 * w.cos() + 0.05 * s)
        })
        .collect()
}

fn eval(c: &mut Criterion) {
    let curve = wavy_nurbs(200);
    let (a, b) = curve.domain();
    let us: Vec<f64> = (0..1000).map(|i| a + (b - a) * i as f64 / 999.0).collect();
    let mut g = c.benchmark_group("nurbs");
    g.throughput(Throughput::Elements(us.len() as u64));
    g.bench_function("derivs_cubic_weighted", |bch| {
        bch.iter(|| {
            let mut acc = Vec3::zeros();
            for &u in &us {
                acc += curve.derivs(black_box(u))[3];
            }
            acc
        })
    });
    g.bench_function("point_cubic_weighted", |bch| {
        bch.iter(|| us.iter().map(|&u| curve.point(black_box(u)).x).sum::<f64>())
    });
    g.finish();
}

fn arclen(c: &mut Criterion) {
    let curve = wavy_nurbs(200);
    let spans = curve.breakpoints().len() as u64 - 1;
    let mut g = c.benchmark_group("arc_length_map");
    for tol in [1e-6, 1e-9] {
        g.throughput(Throughput::Elements(spans));
        g.bench_with_input(BenchmarkId::new("build_per_span", tol), &tol, |bch, &t| {
            bch.iter(|| ArcLengthMap::new(&curve, t).unwrap().length())
        });
    }
    let map = ArcLengthMap::new(&curve, 1e-9).unwrap();
    let ss: Vec<f64> = (0..1000).map(|i| map.length() * i as f64 / 999.0).collect();
    g.throughput(Throughput::Elements(ss.len() as u64));
    g.bench_function("s_to_u", |bch| {
        bch.iter(|| {
            ss.iter()
                .map(|&s| map.u_at(&curve, black_box(s)))
                .sum::<f64>()
        })
    });
    g.finish();
}

fn fitting(c: &mut Criterion) {
    let q = cam_polyline(1000);
    let mut g = c.benchmark_group("fit_1000_points");
    g.sample_size(10);
    g.throughput(Throughput::Elements(q.len() as u64));
    g.bench_function("interpolate_centripetal_cubic", |bch| {
        bch.iter(|| interpolate(&q, 3, Parameterisation::Centripetal).unwrap())
    });
    g.bench_function("approximate_cubic_10um", |bch| {
        bch.iter(|| approximate(&q, 3, 0.01, Parameterisation::Centripetal).unwrap())
    });
    g.finish();
    let a = approximate(&q, 3, 0.01, Parameterisation::Centripetal).unwrap();
    eprintln!(
        "fit of {} points at 10 µm: {} control points, {} rounds, max deviation {:.6} mm",
        q.len(),
        a.curve.control_points().len(),
        a.rounds,
        a.max_deviation
    );
}

criterion_group!(benches, eval, arclen, fitting);
criterion_main!(benches);

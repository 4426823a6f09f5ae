//! The verifying dexel simulation at issue 7's cell (a twentieth of the step-over): a zig-zag
//! finishing path with a 6 mm ball over the 100 × 100 mm free-form test patch at h = 0.1,
//! swept at the sweep spacing `tezgah cam` uses for a 0.01 mm tolerance. Planning is outside
//! the timed loop.

use criterion::{criterion_group, criterion_main, Criterion};
use tezgah_cam::verify::{path_poses, simulate, step_over, MachinedRegion, VerifyOptions};
use tezgah_cam::{plan, testing, Cutter, CutterShape, Settings, StrategyKind};

fn verify_freeform(c: &mut Criterion) {
    let surface = testing::freeform(0.0);
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let settings = Settings::new(StrategyKind::ZigZag, 0.1, 0.01);
    let path = plan(&surface, &cutter, &settings).expect("plan").path;
    // δ²/(8R) a tenth of the 0.01 mm tolerance, as `tezgah cam`'s finish.
    let spacing = (0.8 * 3.0 * 0.01_f64).sqrt();
    let poses = path_poses(&path, spacing);
    let options = VerifyOptions {
        cell_mm: step_over(&path).expect("passes") / 20.0,
        sweep_spacing_mm: spacing,
        region: MachinedRegion::ContactBox,
    };
    let v = simulate(&surface, &path, &poses, &options).expect("simulate");
    eprintln!(
        "{} dexels at cell {:.4} mm, {} poses; scallop {:.4} mm, gouge {:.4} mm",
        v.dexels, v.cell_mm, v.poses, v.max_scallop_mm, v.gouge_depth_mm
    );
    let mut group = c.benchmark_group("cam");
    group.sample_size(10);
    group.bench_function("verify_100mm_h0.1_ball6_cell_stepover_20", |b| {
        b.iter(|| simulate(&surface, &path, &poses, &options).expect("simulate"))
    });
    group.finish();
}

criterion_group!(benches, verify_freeform);
criterion_main!(benches);

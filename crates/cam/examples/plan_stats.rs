//! Plans the benchmark's case (100 × 100 mm free-form patch, 6 mm ball, h = 0.01 mm) with
//! both strategies and prints the figures: passes, contact points, length, refusals, time.
//!
//! cargo run --release -p tezgah-cam --example plan_stats [STRATEGY]   (STRATEGY: only that one,
//! gouge checks on — for timing it alone, e.g. under `time` for its CPU seconds)

use std::time::Instant;

use tezgah_cam::{plan, testing, Cutter, CutterShape, Settings, StrategyKind};

fn main() {
    let surface = testing::freeform(0.0);
    let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
    let only: Option<StrategyKind> = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("strategy"));
    let kinds = match only {
        Some(k) => vec![k],
        None => vec![StrategyKind::ZigZag, StrategyKind::IsoScallop],
    };
    let checks: &[bool] = if only.is_some() {
        &[true]
    } else {
        &[true, false]
    };
    for kind in kinds {
        for &gouge in checks {
            let mut settings = Settings::new(kind, 0.01, 0.01);
            settings.gouge.rear = gouge;
            settings.gouge.global = gouge;
            let start = Instant::now();
            let p = plan(&surface, &cutter, &settings).expect("plan");
            let secs = start.elapsed().as_secs_f64();
            println!(
                "{kind:>13} gouge checks {:>3}: {:>4} passes, {:>6} CL points, {:>8.0} mm, {} refused, {} corrected, {secs:.3} s",
                if gouge { "on" } else { "off" },
                p.path.passes.len(),
                p.path.contact_count(),
                p.path.cutting_length(),
                p.refused.len(),
                p.corrected,
            );
        }
    }
}

//! Issue 23's machine figures for the fixture faces (saddle with bump, wavy patch, bowl): a
//! 6 mm ball at the command's default 10° lead, zig-zag and iso-scallop, posted for table-ac
//! and table-bc with the tryout on; prints the cycle the runner plans, path/feed, the rapid
//! (link) length and the rotary travel (tilt and table, degrees, over the whole program).
//!
//! cargo run --profile test -p tezgah-cam --example machine_cycle [H_MM]   (default h 0.5)

use std::path::PathBuf;

use tezgah_cam::post::{post, PostOptions};
use tezgah_cam::{Cutter, CutterShape, Settings, StrategyKind, ToleranceShares, ToolAxis};
use tezgah_kinematics::Machine;

fn main() {
    let h: f64 = std::env::args()
        .nth(1)
        .map(|a| a.parse().expect("h in mm"))
        .unwrap_or(0.5);
    let tolerance = 0.05;
    let shares = ToleranceShares::of(tolerance);
    println!("face strategy machine: cycle s, path/feed s, ratio, rapid mm, tilt °, table °");
    for name in ["saddle_bump", "wavy_patch", "bowl_patch"] {
        let file = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(format!("{name}.stp"));
        let model = tezgah_cam::step::read_file(file).expect("fixture");
        let face = &model.faces[0];
        for kind in [StrategyKind::ZigZag, StrategyKind::IsoScallop] {
            let mut settings = Settings::new(kind, h, shares.chord);
            if let ToolAxis::Surface { lead_deg, .. } = &mut settings.axis {
                *lead_deg = 10.0;
            }
            settings.reverse_normal = !face.same_sense;
            settings.band = Some(shares.band());
            let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
            let path = tezgah_cam::plan(&face.surface, &cutter, &settings)
                .expect("plan")
                .path;
            for machine in ["table-ac", "table-bc"] {
                let m = Machine::builtin(machine).expect("machine");
                let options = PostOptions::new(4000.0, shares.linearisation);
                match post(&path, &m, &options) {
                    Ok(p) => {
                        let (mut tilt, mut table) = (0.0, 0.0);
                        for w in p.points.windows(2) {
                            tilt += (w[1].angles.tilt - w[0].angles.tilt).abs().to_degrees();
                            table += (w[1].angles.c - w[0].angles.c).abs().to_degrees();
                        }
                        let s = &p.stats;
                        let cycle = s.cycle_time_s.unwrap_or(f64::NAN);
                        println!(
                            "{name} {kind} {machine}: {cycle:.1} s, {:.1} s, {:.2}, {:.0} mm, \
                             {tilt:.0}°, {table:.0}°",
                            s.feed_time_s,
                            cycle / s.feed_time_s,
                            s.rapid_length_mm
                        );
                    }
                    Err(e) => println!("{name} {kind} {machine}: refused: {e}"),
                }
            }
        }
    }
}

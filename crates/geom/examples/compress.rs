//! Compression of a CAM-like run: 1000 points with chords of 0.05–0.3 mm on a smooth 3-D curve,
//! fitted within 10 µm with each parameterisation. Prints control points, rounds, deviation
//! and time. `cargo run --release -p tezgah-geom --example compress`

use tezgah_geom::fit::{approximate, Parameterisation};
use tezgah_geom::Vec3;

fn main() {
    let mut s = 0.0;
    let q: Vec<Vec3> = (0..1000)
        .map(|i| {
            s += 0.05 + 0.25 * (((i * 7919) % 101) as f64 / 100.0);
            let w = std::f64::consts::TAU * s / 40.0;
            Vec3::new(s, 3.0 * w.sin(), 2.0 * w.cos() + 0.05 * s)
        })
        .collect();
    let methods = [
        Parameterisation::ChordLength,
        Parameterisation::Centripetal,
        Parameterisation::Uniform,
    ];
    for m in methods {
        let start = std::time::Instant::now();
        match approximate(&q, 3, 0.01, m) {
            Ok(a) => println!(
                "{m:?}: {} points -> {} control points, {} rounds, max deviation {:.6} mm, {:?}",
                q.len(),
                a.curve.control_points().len(),
                a.rounds,
                a.max_deviation,
                start.elapsed()
            ),
            Err(e) => println!("{m:?}: {e}"),
        }
    }
}

//! Dense surfacing programs for the smoothing figures (BENCHMARKS.md): raster
//! rows 60 mm long, 2 mm apart, over `z = 2 sin(w·x/7) cos(w·y/5)`, points every 0.2 mm
//! (`uniform`) or 0.05–0.3 mm apart (`random`), coordinates rounded as a CAM post would.
//!
//! `cargo run --release -p tezgah-motion --example surfacing -- ngc random 40 3 5 > p.ngc`
//! writes a program for `tezgah run`; `… -- diag random 40 3 5` builds the smooth path and
//! compares the splines' largest curvature with the polyline's discrete (Menger) curvature.

use tezgah_geom::deviation::maximise;
use tezgah_geom::{Curve, Move, MoveKind, PathMode, Pose, Vec3};
use tezgah_motion::path::smooth::{SmoothOptions, Smoother};
use tezgah_motion::PathItem;

/// xorshift64* (Vigna 2016): the same numbers on every platform.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The programmed points (after the first, which is where the feed starts).
fn points(random: bool, rows: usize, decimals: i32, wave: f64) -> Vec<Vec3> {
    let mut rng = Rng(0x5eed_0f5a_11ce);
    let z = |x: f64, y: f64| 2.0 * (wave * x / 7.0).sin() * (wave * y / 5.0).cos();
    let scale = 10f64.powi(decimals);
    let round = |v: f64| (v * scale).round() / scale;
    let mut out = vec![Vec3::new(0.0, 0.0, round(z(0.0, 0.0)))];
    for r in 0..rows {
        let y = 2.0 * r as f64;
        let at = |s: f64| {
            let x = if r % 2 == 0 { s } else { 60.0 - s };
            Vec3::new(round(x), round(y), round(z(x, y)))
        };
        if r > 0 {
            out.push(at(0.0));
        }
        let mut s = 0.0;
        while s < 60.0 {
            s = (s + if random {
                0.05 + 0.25 * rng.unit()
            } else {
                0.2
            })
            .min(60.0);
            out.push(at(s));
        }
    }
    out.dedup();
    out
}

/// Menger curvature of three points: `4·area / (|ab|·|bc|·|ca|)`.
fn menger(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    let area2 = (b - a).cross(&(c - a)).norm();
    2.0 * area2 / ((b - a).norm() * (c - b).norm() * (c - a).norm())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let random = arg(1, "random") == "random";
    let rows: usize = arg(2, "40").parse().unwrap_or(40);
    let decimals: i32 = arg(3, "4").parse().unwrap_or(4);
    let wave: f64 = arg(4, "1").parse().unwrap_or(1.0);
    let pts = points(random, rows, decimals, wave);
    if arg(0, "ngc") == "ngc" {
        println!("G21 G90 G17\nG64 P0.01\nF3000");
        if arg(5, "") == "q0" {
            println!("G05.1 Q0");
        }
        println!("G0 X0 Y0 Z5");
        for p in &pts {
            println!("G1 X{:.6} Y{:.6} Z{:.6}", p.x, p.y, p.z);
        }
        println!("M2");
        eprintln!("{} feed moves", pts.len());
        return;
    }
    let mut moves = vec![
        Move {
            line: 1,
            kind: MoveKind::FeedRate { value: 3000.0 },
        },
        Move {
            line: 2,
            kind: MoveKind::PathMode(PathMode::Continuous {
                tolerance: Some(arg(5, "0.01").parse().unwrap_or(0.01)),
            }),
        },
    ];
    moves.extend(pts.iter().enumerate().map(|(i, p)| Move {
        line: i as u32 + 3,
        kind: MoveKind::Feed {
            end: Pose::new(p.x, p.y, p.z, 0.0, 0.0, 0.0),
        },
    }));
    let polyline_max = pts
        .windows(3)
        .filter(|w| (w[1].y - w[0].y).abs() < 1e-9 && (w[2].y - w[1].y).abs() < 1e-9)
        .map(|w| menger(&w[0], &w[1], &w[2]))
        .fold(0.0, f64::max);
    let opts = SmoothOptions {
        start: Pose::new(0.0, 0.0, pts[0].z, 0.0, 0.0, 0.0),
        ..SmoothOptions::default()
    };
    let t = std::time::Instant::now();
    let mut sm = Smoother::new(moves.into_iter(), opts).expect("options");
    let items: Vec<PathItem> = sm.by_ref().map(|i| i.expect("path")).collect();
    let built = t.elapsed();
    let stats = sm.stats();
    let (mut kmax, mut peaks_over) = (0.0f64, 0usize);
    for item in &items {
        if let PathItem::Segment(s) = item {
            if s.curve.curvature(s.curve.domain().0) > 0.0 || s.curve.breakpoints().len() > 2 {
                // Largest curvature per knot span, ends included (a cut spline's peak may sit
                // at a segment end).
                for w in s.curve.breakpoints().windows(2) {
                    let p = maximise(|u| s.curve.curvature(u), w[0], w[1], 8);
                    // Rows only: the row ends are blended corners, not fitted.
                    let x = s.curve.point(p.u).x;
                    if !(1.0..=59.0).contains(&x) {
                        continue;
                    }
                    if p.distance > 20.0 * polyline_max && std::env::var("PEAKS").is_ok() {
                        let q = s.curve.point(p.u);
                        println!(
                            "peak {:.1}/mm at {:.3} {:.3} {:.4} (line {}, span {:.3e})",
                            p.distance,
                            q.x,
                            q.y,
                            q.z,
                            s.line,
                            w[1] - w[0]
                        );
                    }
                    kmax = kmax.max(p.distance);
                    peaks_over += usize::from(p.distance > 2.0 * polyline_max);
                }
            }
        }
    }
    println!(
        "{} moves -> {} splines (+{} cuts) + {} other pieces ({} control points), built in {:?}",
        stats.moves,
        stats.splines,
        stats.spline_cuts,
        items.len() - stats.splines - stats.spline_cuts,
        stats.control_points,
        built
    );
    println!(
        "max curvature: polyline (Menger, along rows) {polyline_max:.4}/mm, splines {kmax:.4}/mm; \
         spline knot spans with curvature above 2x the polyline's: {peaks_over}"
    );
}

//! The programs the motion benches and the `stages` example run, in one place so that every
//! figure in BENCHMARKS.md is measured on the same input: the `run` pipeline's dense surfacing
//! and lines-and-arcs programs, and the path bench's 1 M-move programs, with the stage set-ups
//! `tezgah run` uses. Included with `#[path]` (benches, examples and tests cannot share a
//! module); the cycle-time oracle test takes its surfacing program from here too.
#![allow(dead_code)]

use std::fmt::Write;

use tezgah_geom::{Move, MoveKind, PathMode, Pose};
use tezgah_kinematics::Machine;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::PlanOptions;
use tezgah_motion::PathItem;

/// Moves in the 1 M-move programs.
pub const SEGMENTS: usize = 1_000_000;

/// Dense 3-axis surfacing: zig-zag passes of 0.05–0.3 mm segments over a smooth bump.
pub fn surfacing() -> String {
    Surfacing {
        opening: "G21 G90 G94 G64\nF3000\nG0 X0 Y0 Z2\nG1 Z0\n",
        passes: 20,
        closing: "G0 Z5\nM2\n",
    }
    .program()
}

/// The dense surfacing program's frame: the lines before the first pass and after the last,
/// and how many 60 mm passes (0.5 mm apart in Y) lie between. The benches run 20 passes
/// with an approach and a retract; the cycle-time oracle test 4 passes without them (the
/// TOPP-RA ratios in BENCHMARKS.md were measured on that program).
pub struct Surfacing<'a> {
    pub opening: &'a str,
    pub passes: usize,
    pub closing: &'a str,
}

impl Surfacing<'_> {
    /// The program text; the same seed every time, so every run measures the same moves.
    pub fn program(&self) -> String {
        let mut s = String::from(self.opening);
        let mut seed: u64 = 12345;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let z =
            |x: f64, y: f64| 2.0 * (-(x - 30.0).powi(2) / 400.0 - (y - 5.0).powi(2) / 100.0).exp();
        for pass in 0..self.passes {
            let y = pass as f64 * 0.5;
            let (mut x, dir) = if pass % 2 == 0 {
                (0.0, 1.0)
            } else {
                (60.0, -1.0)
            };
            let _ = writeln!(s, "G1 X{x:.4} Y{y:.4} Z{:.4}", z(x, y));
            while (0.0..=60.0).contains(&x) {
                x += dir * (0.05 + 0.25 * next());
                let _ = writeln!(s, "G1 X{x:.4} Y{y:.4} Z{:.4}", z(x, y));
            }
        }
        s.push_str(self.closing);
        s
    }
}

/// Long lines and arcs: a pocket outline of 100 mm lines and R10 corners, several depths.
pub fn lines_and_arcs() -> String {
    let mut s = String::from("G21 G90 G94 G17 G64\nF2400\nG0 X-50 Y-60 Z2\n");
    for k in 0..10 {
        let d = -0.5 * (k + 1) as f64;
        let _ = writeln!(
            s,
            "G1 Z{d}\nG1 X50\nG3 X60 Y-50 R10\nG1 Y50\nG3 X50 Y60 R10\nG1 X-50\nG3 X-60 Y50 R10\n\
             G1 Y-50\nG3 X-50 Y-60 R10"
        );
    }
    s.push_str("G0 Z5\nM2\n");
    s
}

pub fn parse(text: &str) -> Vec<Move> {
    tezgah_gcode::program_moves(text, tezgah_gcode::Config::default()).unwrap()
}

/// The smoothing builder as `tezgah run` sets it up.
pub fn smooth_items(moves: &[Move], machine: &Machine) -> Vec<PathItem> {
    smooth::build(
        moves.iter().cloned(),
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap()
}

/// The mill of issue 22's figures: `mill3` with every axis at 250 mm/s, 2 500 mm/s²,
/// 50 000 mm/s³.
pub fn issue_mill() -> Machine {
    let mut m = Machine::default_machine();
    for j in &mut m.joints {
        j.max_velocity = 250.0;
        j.max_acceleration = 2500.0;
        j.max_jerk = 50_000.0;
    }
    m
}

/// Every joint's peak velocity, acceleration and jerk (finite differences at the period)
/// within 0.5 % of its limit, else a panic naming the joint, the peaks and their lines.
pub fn assert_joints_within(report: &tezgah_motion::verify::Report) {
    for (i, j) in report.joints.iter().enumerate() {
        assert!(
            j.worst_ratio() <= 1.005,
            "joint {i}: v {} / {}, a {} / {}, j {} / {} (lines {} {} {})",
            j.velocity,
            j.max_velocity,
            j.acceleration,
            j.max_acceleration,
            j.jerk,
            j.max_jerk,
            j.velocity_line,
            j.acceleration_line,
            j.jerk_line
        );
    }
}

pub fn plan_options(machine: &Machine) -> PlanOptions {
    PlanOptions {
        period: machine.motion.period_s,
        ..PlanOptions::default()
    }
}

/// xorshift64* (Vigna 2016).
pub struct Rng(pub u64);

impl Rng {
    pub fn unit(&mut self) -> f64 {
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
pub fn corners() -> Vec<Move> {
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
pub fn raster_1m() -> Vec<Move> {
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

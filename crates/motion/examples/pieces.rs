//! Prints the planner's pieces of a program, one line each: first source line, segments,
//! length, the profile's limits (V, A, J), entry, peak and exit speed, and duration, so a user
//! sees where a plan runs below the feed and what limits it there.
//!
//! `cargo run --release -p tezgah-motion --example pieces -- PROGRAM.ngc [MACHINE.toml [TOOLS.tbl]]`

#[path = "../benches/common/mod.rs"]
mod common;

use tezgah_geom::Pose;
use tezgah_kinematics::Machine;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::lookahead::plan_all;
use tezgah_motion::plan::{PlanMachine, Planned};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let text = std::fs::read_to_string(&args[0]).expect("program");
    let machine = match args.get(1) {
        Some(p) => Machine::from_toml_str(&std::fs::read_to_string(p).expect("machine"))
            .expect("machine file"),
        None => Machine::default_machine(),
    };
    let config = tezgah_gcode::Config {
        tool_table: match args.get(2) {
            Some(p) => tezgah_gcode::ToolTable::parse(&std::fs::read_to_string(p).expect("tools"))
                .expect("tool table"),
            None => Default::default(),
        },
        ..tezgah_gcode::Config::default()
    };
    let moves = tezgah_gcode::program_moves(&text, config).expect("program");
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let options =
        SmoothOptions::for_machine(&machine.path, &pm, machine.motion.tolerance_mm, Pose::ZERO);
    let items = smooth::build(moves, &options).expect("path");
    let planned = plan_all(items, pm, common::plan_options(&machine)).expect("plan");
    let mut total = 0.0;
    for p in planned {
        match p {
            Planned::Motion(piece) => {
                let pr = &piece.profile;
                let peak = pr.knots().iter().map(|k| k.1.v).fold(0.0, f64::max);
                total += pr.duration();
                println!(
                    "line {:6} segs {:4} len {:9.3} V {:8.2} A {:9.1} J {:10.0} v0 {:7.2} peak {:7.2} v1 {:7.2} t {:8.4}",
                    piece.segments[0].line,
                    piece.segments.len(),
                    piece.length(),
                    piece.limits.max_velocity(),
                    piece.limits.max_acceleration(),
                    piece.limits.max_jerk(),
                    pr.start().v,
                    peak,
                    pr.end().v,
                    pr.duration()
                );
            }
            Planned::Dwell { seconds, line } => {
                total += seconds;
                println!("line {line:6} dwell {seconds}");
            }
            Planned::Stop { line } => println!("line {line:6} stop"),
        }
    }
    println!("total {total:.4} s");
}

//! One pass of each stage of the pipeline bench's programs, for instruction counts on a shared
//! machine (`perf stat -e instructions:u` or `valgrind --tool=callgrind` per stage; wall time
//! is too noisy there). `cargo run --profile bench -p tezgah-motion --example stages -- STAGE
//! [PROGRAM]`: STAGE is `gen` (the program text only), `parse`, `smooth`, `plan` or `whole`
//! (each runs the stages before it too, so a stage's cost is its count minus the previous
//! one's), PROGRAM `surfacing` (default), `lines_arcs` or `surfacing_1m` (the path bench's
//! 1 M-move raster, smoothing only; `gen` and `smooth` apply). With `STAGES_DUMP=FILE` the
//! `smooth` stage writes every path item (`{:?}`) to FILE, to check that a speed change leaves
//! the built path bit for bit the same (`cmp` two dumps).

use std::hint::black_box;

#[path = "../benches/common/mod.rs"]
mod common;
use common::{lines_and_arcs, plan_options, raster_1m, smooth_items, surfacing};

use tezgah_geom::{Curve, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{SmoothOptions, Smoother};
use tezgah_motion::plan::lookahead::plan_all;
use tezgah_motion::plan::PlanMachine;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let stage = args.get(1).map(String::as_str).unwrap_or("whole");
    let program = args.get(2).map(String::as_str).unwrap_or("surfacing");
    let machine = Machine::default_machine();
    if program == "surfacing_1m" {
        let moves = raster_1m();
        if stage == "gen" {
            black_box(moves);
            return;
        }
        let sm = Smoother::new(
            moves.into_iter(),
            SmoothOptions {
                start: Pose::ZERO,
                ..SmoothOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut n = 0usize;
        let mut dump = Dump::open();
        for item in sm {
            let item = item.unwrap_or_else(|e| panic!("{e}"));
            dump.item(&item);
            black_box(item);
            n += 1;
        }
        eprintln!("surfacing_1m: {n} items");
        return;
    }
    let text = match program {
        "lines_arcs" => lines_and_arcs(),
        _ => surfacing(),
    };
    if stage == "gen" {
        black_box(text);
        return;
    }
    let moves = tezgah_gcode::program_moves(&text, tezgah_gcode::Config::default())
        .unwrap_or_else(|e| panic!("parse failed: {e:?}"));
    if stage == "parse" {
        black_box(moves);
        return;
    }
    let items = smooth_items(&moves, &machine);
    if stage == "smooth" {
        eprintln!("{} moves -> {} items", moves.len(), items.len());
        let mut dump = Dump::open();
        items.iter().for_each(|i| dump.item(i));
        black_box(items);
        return;
    }
    let pm = PlanMachine::from_machine(&machine).unwrap_or_else(|e| panic!("{e}"));
    if stage == "plan" {
        black_box(
            plan_all(items, pm, plan_options(&machine))
                .map(|p| p.len())
                .ok(),
        );
        return;
    }
    let mut n = 0u64;
    let mut acc = 0.0;
    let d = run(
        items,
        pm,
        plan_options(&machine),
        (Vec3::zeros(), [0.0; 3]),
        |s, _| {
            n += 1;
            acc += s.joints[0];
        },
    )
    .unwrap_or_else(|e| panic!("run failed: {e}"));
    black_box(acc);
    eprintln!("program {d:.3} s, {n} samples");
}

/// The optional `STAGES_DUMP` file of built path items.
struct Dump(Option<std::io::BufWriter<std::fs::File>>);

impl Dump {
    fn open() -> Dump {
        Dump(std::env::var_os("STAGES_DUMP").map(|p| {
            std::io::BufWriter::new(
                std::fs::File::create(&p).unwrap_or_else(|e| panic!("STAGES_DUMP: {e}")),
            )
        }))
    }

    fn item(&mut self, item: &tezgah_motion::path::PathItem) {
        if let Some(w) = &mut self.0 {
            use std::io::Write;
            writeln!(w, "{item:?}").unwrap_or_else(|e| panic!("STAGES_DUMP: {e}"));
            // And the curve itself, at a few parameters (the item's Debug leaves it out).
            if let tezgah_motion::path::PathItem::Segment(s) = item {
                let (u0, u1) = s.curve.domain();
                for i in 0..=4 {
                    let p = s.point(u0 + (u1 - u0) * f64::from(i) / 4.0);
                    writeln!(w, "  {:?}", [p.x, p.y, p.z])
                        .unwrap_or_else(|e| panic!("STAGES_DUMP: {e}"));
                }
            }
        }
    }
}

//! Inverse kinematics throughput per model in CPU time of this thread (Linux
//! `/proc/thread-self/schedstat`), not wall time: on a machine shared with other jobs the
//! wall-clock benchmark (`benches/inverse.rs`) moves by 2× with the load, the CPU time much
//! less. `cargo run --profile bench -p tezgah-kinematics --example inverse_cpu`.

use std::hint::black_box;

use tezgah_kinematics::{Kinematics, Machine, Tool};

#[path = "../benches/poses.rs"]
mod poses;
use poses::poses;

/// Nanoseconds this thread has run on a CPU (the first field of schedstat).
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn main() {
    const ROUNDS: usize = 20_000; // × 1024 poses: about a second per model
    if cpu_ns().is_none() {
        eprintln!("no /proc/thread-self/schedstat: Linux only");
        std::process::exit(1);
    }
    for name in ["mill3", "yzca", "table-ac", "table-bc", "linear-delta"] {
        let m = Machine::builtin(name).expect("built-in machine");
        let tool = Tool::with_length(25.0);
        let ps = poses(&m, &tool);
        let q0 = m
            .kinematics
            .inverse(&ps[0], &tool, &m.home())
            .expect("reachable");
        let mut best = f64::INFINITY;
        // Best of five: what is left of the noise only ever adds time.
        for _ in 0..5 {
            let t0 = cpu_ns().unwrap_or(0);
            for _ in 0..ROUNDS / 5 {
                let mut q = q0;
                for p in &ps {
                    q = m
                        .kinematics
                        .inverse(black_box(p), &tool, &q)
                        .expect("reachable");
                }
                black_box(q);
            }
            let dt = (cpu_ns().unwrap_or(0) - t0) as f64 * 1e-9;
            best = best.min(dt / (ROUNDS / 5 * ps.len()) as f64);
        }
        println!(
            "{name:<13} {:6.1} M poses/s of CPU time ({:.1} ns/pose)",
            1e-6 / best,
            best * 1e9
        );
    }
}

//! The soak of issue 27: three emulated drives on a veth pair between two network namespaces,
//! a path at 1 ms for a minute (or the seconds given as the first argument), every set-point
//! checked once and in order, the cycle's timing figures printed; the master's thread and the
//! drives' at SCHED_FIFO as the executor's real-time thread is. Needs root:
//!
//! ```sh
//! cargo run --release -p tezgah-ethercat --example veth_soak -- 60
//! ```

#[path = "../tests/common/mod.rs"]
mod common;

use common::veth::{can_run, run, Veth};

fn main() {
    let seconds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    if !can_run("veth soak") {
        std::process::exit(2);
    }
    // The master's thread as the executor's real-time thread is: SCHED_FIFO, memory locked.
    let applied =
        tezgah_executor::realtime::apply(&tezgah_executor::realtime::RealtimeSettings::BEST_EFFORT);
    for w in applied.warnings() {
        eprintln!("warning: {w}");
    }
    let v = Veth::new("s").expect("namespaces and veth");
    let cycles = seconds * 1000;
    let (f, _, _) = run(&v, cycles, true);
    println!("veth soak, 3 drives, {cycles} cycles at 1 ms: {f:?}");
}

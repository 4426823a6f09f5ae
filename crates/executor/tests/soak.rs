//! The real clock: the planner thread and the real-time thread running programs back to back
//! (1.5 s here; `TEZGAH_SOAK_SECONDS=60 TEZGAH_SOAK_LOAD=2` for the minute under load the
//! notes report). The real-time thread asks for SCHED_FIFO and locked memory, best effort
//! (`TEZGAH_SOAK_REALTIME=0` leaves it time-shared). Asserts only what timing cannot change: every set-point the planner pushed
//! is applied once, in order, and the real-time thread never allocates (a counting
//! allocator, armed on that thread only). Underruns and jitter are printed, not asserted.

mod support;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use support::*;
use tezgah_executor::command::{Command, RunState};
use tezgah_executor::drive::IdealDrive;
use tezgah_executor::drive::{Drive, DriveStatus};
use tezgah_executor::realtime::{self, RealtimeSettings};
use tezgah_executor::ring::rings;
use tezgah_executor::rt::{RealClock, RtLoop, StopLimits};
use tezgah_executor::threads::PlannerSide;
use tezgah_executor::SetPoint;
use tezgah_kinematics::Joints;

struct Counting;

thread_local! {
    static ON_RT: Cell<bool> = const { Cell::new(false) };
}
static RT_ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

fn count() {
    if ON_RT.try_with(Cell::get).unwrap_or(false) {
        RT_ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Records the indices applied into pre-allocated room (no allocation in `apply`).
struct Recording {
    indices: Vec<u64>,
    moving: Vec<bool>,
}

impl Drive for Recording {
    fn apply(&mut self, sp: &SetPoint) -> DriveStatus {
        if self.indices.len() < self.indices.capacity() {
            self.indices.push(sp.index);
            self.moving
                .push(sp.velocity.as_slice().iter().any(|v| *v != 0.0));
        }
        IdealDrive.apply(sp)
    }
}

#[test]
fn real_clock_soak() {
    let seconds: f64 = std::env::var("TEZGAH_SOAK_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.5);
    let load: usize = std::env::var("TEZGAH_SOAK_LOAD")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let exec = executor();
    let period = exec.period();
    let limits = StopLimits::of(exec.machine());
    let start = Joints::from_slice(&exec.status().joints).unwrap();
    let capacity = 32;
    let (planner_rings, rt_ends) = rings(capacity, 8192);
    let quit = Arc::new(AtomicBool::new(false));
    let room = (seconds / period) as usize + 10_000;
    let drive = Recording {
        indices: Vec::with_capacity(room),
        moving: Vec::with_capacity(room),
    };
    let settings = match std::env::var("TEZGAH_SOAK_REALTIME").as_deref() {
        Ok("0") => RealtimeSettings::OFF,
        _ => RealtimeSettings::BEST_EFFORT,
    };
    let q = quit.clone();
    let rt = std::thread::spawn(move || {
        // Before the allocation count is armed: the outcome's messages allocate.
        let applied = realtime::apply(&settings);
        println!("real-time scheduling: {applied:?}");
        let mut rt = RtLoop::new(rt_ends, drive, period, limits, start);
        ON_RT.with(|c| c.set(true));
        let figures = rt.run(&mut RealClock::new(period), &q);
        ON_RT.with(|c| c.set(false));
        (figures, rt)
    });
    let busy: Vec<_> = (0..load)
        .map(|_| {
            let q = quit.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !q.load(Ordering::Relaxed) {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
                    std::hint::black_box(x);
                }
            })
        })
        .collect();
    // This thread is the planner: it asks for its priority as `spawn`'s planner does.
    let planner = realtime::apply(&settings.for_planner());
    println!("planner scheduling: {planner:?}");
    let mut side = PlannerSide::new(exec, planner_rings, capacity);
    let mut pushed = 0usize;
    let mut programs = 0u64;
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < seconds {
        if side.executor().state() == RunState::Idle {
            side.command(Command::Load {
                program: random_program(programs, 30),
            })
            .unwrap();
            side.command(Command::CycleStart).unwrap();
            programs += 1;
        }
        if side.executor().state() == RunState::Fault {
            side.command(Command::Abort).unwrap();
        }
        pushed += side.pump();
        std::thread::sleep(Duration::from_secs_f64(period / 4.0));
    }
    quit.store(true, Ordering::Relaxed);
    let ((counters, jitter), rt) = rt.join().unwrap();
    for b in busy {
        b.join().unwrap();
    }
    let lead = side.lead();
    println!(
        "soak {seconds} s, load {load}: {} periods, {} set-points delivered of {pushed} pushed, \
         {} underruns, {} discarded; jitter worst {:.1} µs mean {:.1} µs, {} periods over half \
         a period late; lead min {} mean {:.1} max {} set-points; {programs} programs",
        counters.periods,
        counters.delivered,
        counters.underruns,
        counters.discarded,
        jitter.worst * 1e6,
        jitter.mean() * 1e6,
        jitter.over_half,
        lead.min,
        lead.mean(),
        lead.max
    );
    assert_eq!(
        RT_ALLOCATIONS.load(Ordering::Relaxed),
        0,
        "the RT thread allocated"
    );
    // Every set-point pushed was either applied or, after an underrun, discarded; left in
    // the ring at most its capacity.
    let applied = counters.delivered + counters.discarded;
    assert!(applied as usize <= pushed && pushed - applied as usize <= capacity);
    // In order, each once: indices never go back (idle periods and an underrun's stop repeat
    // the last index), and without underruns they step by one while moving (after one, the
    // set-points discarded while halted leave a gap).
    let rec = &rt.drive().indices;
    for w in rec.windows(2) {
        assert!(w[1] >= w[0], "index went back: {} after {}", w[1], w[0]);
    }
    if counters.underruns == 0 {
        let mv = &rt.drive().moving;
        for (k, w) in rec.windows(2).enumerate() {
            if mv[k] {
                assert_eq!(
                    w[1],
                    w[0] + 1,
                    "a set-point lost or repeated after {}",
                    w[0]
                );
            } else {
                assert!(w[1] - w[0] <= 1);
            }
        }
    }
}

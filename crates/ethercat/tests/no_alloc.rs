//! The cyclic exchange allocates nothing on the real-time thread: a counting allocator watches
//! this thread while the bus runs a few hundred cycles (the emulated drives' target logs are
//! reserved beforehand: they are the test's, not the master's).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use common::*;
use tezgah_executor::{Drive, SetPoint};
use tezgah_kinematics::Joints;

struct Counting;

thread_local! {
    static WATCHING: Cell<bool> = const { Cell::new(false) };
}
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if WATCHING.try_with(|w| w.get()).unwrap_or(false) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if WATCHING.try_with(|w| w.get()).unwrap_or(false) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_cycle_does_not_allocate() {
    let (bus, mut d) = open(1.0, 1.0);
    for s in &mut bus.lock().unwrap().slaves {
        s.targets.reserve(1000);
    }
    // warm up: the first cycles may touch lazily made statics (the timer reactor)
    for k in 1..10u64 {
        d.apply(&SetPoint::at_rest(
            k,
            0,
            Joints::new([k as f64 * 0.01, 0.0, 0.0]),
        ));
    }
    WATCHING.with(|w| w.set(true));
    for k in 10..500u64 {
        let st = d.apply(&SetPoint::at_rest(
            k,
            0,
            Joints::new([k as f64 * 0.01, 0.0, 0.0]),
        ));
        assert!(st.fault.is_none());
    }
    WATCHING.with(|w| w.set(false));
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0);
}

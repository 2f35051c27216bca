//! No allocation in the steady-state time step: a counting allocator shows that advancing many
//! steps allocates no more than advancing one step once per window of the run guard's energy
//! balance (the cost of a window is starting the thread team).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn steady_state_steps_allocate_nothing() {
    let case = common::quick_case();
    let mut e = common::engine(
        &case,
        Some(&common::data("states/mercury_t143.85.data")),
        Default::default(),
    );
    // warm up: several pair-list rebuilds size every buffer
    e.advance(20_000).unwrap();
    let count = |e: &mut Box<dyn verdem::step::Engine>, steps| {
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        e.advance(steps).unwrap();
        ALLOCATIONS.load(Ordering::Relaxed) - before
    };
    let one = count(&mut e, 1);
    let many = count(&mut e, 10_000);
    let rebuilds = e.counters().rebuilds;
    assert!(
        rebuilds > 20,
        "the measured steps include pair-list rebuilds ({rebuilds})"
    );
    let windows = 10_000usize.div_ceil(verdem::step::ENERGY_WINDOW as usize);
    assert!(
        many <= one * windows,
        "10000 steps ({windows} windows) allocated {many} times, 1 step {one} times"
    );
}

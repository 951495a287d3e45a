//! Fuzzes `coin-log verify`'s streaming reader and checks with arbitrary bytes: it must never panic, must
//! classify every input with an exit code of 0, 1 or 2, and must stay within the reader's memory budget:
//! the heap it holds at its peak, counted by the allocator below, stays under
//! `coin_log_mcap::READ_MEMORY_BOUND` whatever the input claims.
#![no_main]

use coin_log::verify::{verify_bytes, Options};
use libfuzzer_sys::fuzz_target;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// The system allocator, counting the bytes held now and at the peak.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grow(by: usize) {
    let held = HELD.fetch_add(by, Relaxed) + by;
    PEAK.fetch_max(held, Relaxed);
}

// SAFETY: every call goes to `System` unchanged; only the counters are added.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        HELD.fetch_sub(layout.size(), Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            grow(new_size - layout.size());
        } else {
            HELD.fetch_sub(layout.size() - new_size, Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fuzz_target!(|data: &[u8]| {
    let before = HELD.load(Relaxed);
    PEAK.store(before, Relaxed);
    let report = verify_bytes("fuzz.mcap", data, &Options::default());
    assert!(report.exit_code <= 2);
    let peak = PEAK.load(Relaxed) - before;
    assert!(
        (peak as u64) < coin_log_mcap::READ_MEMORY_BOUND,
        "verify held {peak} bytes of heap at its peak, over the reader's bound of {} on an input of {} bytes",
        coin_log_mcap::READ_MEMORY_BOUND,
        data.len()
    );
});

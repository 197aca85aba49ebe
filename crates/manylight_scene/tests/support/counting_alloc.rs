//! A global allocator for test binaries that counts live heap bytes, records the peak, and
//! refuses (returns null for) any allocation that would take the live total over a cap, so a
//! runaway allocation aborts the test binary instead of exhausting the machine.
//!
//! Include it with `#[path = "support/counting_alloc.rs"] mod counting_alloc;` and install it
//! with `#[global_allocator] static ALLOC: counting_alloc::Counting = counting_alloc::Counting;`.

#![allow(dead_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// Live heap bytes.
static LIVE: AtomicUsize = AtomicUsize::new(0);
/// Highest `LIVE` since the last [`reset_peak`].
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Largest `LIVE` an allocation may reach.
static CAP: AtomicUsize = AtomicUsize::new(usize::MAX);

/// The counting allocator (wraps [`System`]).
pub struct Counting;

/// Adds `size` live bytes unless that goes over the cap.
fn charge(size: usize) -> bool {
    let cap = CAP.load(Relaxed);
    let mut live = LIVE.load(Relaxed);
    loop {
        let Some(next) = live.checked_add(size).filter(|&n| n <= cap) else { return false };
        match LIVE.compare_exchange_weak(live, next, Relaxed, Relaxed) {
            Ok(_) => {
                PEAK.fetch_max(next, Relaxed);
                return true;
            }
            Err(now) => live = now,
        }
    }
}

// SAFETY: every method forwards to `System` with the same arguments; the counters are only
// bookkeeping.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !charge(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded unchanged.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Relaxed);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !charge(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded unchanged.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let old = layout.size();
        if new_size > old && !charge(new_size - old) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded unchanged.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            if new_size > old {
                LIVE.fetch_sub(new_size - old, Relaxed);
            }
        } else if new_size < old {
            LIVE.fetch_sub(old - new_size, Relaxed);
        }
        p
    }
}

/// Live heap bytes now.
pub fn live() -> usize {
    LIVE.load(Relaxed)
}

/// Starts a new peak measurement; returns the live bytes now (the baseline).
pub fn reset_peak() -> usize {
    let live = LIVE.load(Relaxed);
    PEAK.store(live, Relaxed);
    live
}

/// Highest live heap bytes since the last [`reset_peak`].
pub fn peak() -> usize {
    PEAK.load(Relaxed)
}

/// Sets the cap on live heap bytes (allocations over it fail, which aborts the process).
pub fn set_cap(bytes: usize) {
    CAP.store(bytes, Relaxed);
}

/// Runs `work` on a worker thread and returns its result with the peak heap growth (bytes above
/// the live total when it started) and the time it took; `None` when it did not finish within
/// `timeout` (the worker is left behind, so a hang fails the caller instead of freezing it).
pub fn measure<T: Send + 'static>(
    timeout: std::time::Duration,
    work: impl FnOnce() -> T + Send + 'static,
) -> Option<(T, usize, std::time::Duration)> {
    let (tx, rx) = std::sync::mpsc::channel();
    let base = reset_peak();
    let start = std::time::Instant::now();
    std::thread::spawn(move || {
        let _ = tx.send(work());
    });
    let result = rx.recv_timeout(timeout).ok()?;
    Some((result, peak().saturating_sub(base), start.elapsed()))
}

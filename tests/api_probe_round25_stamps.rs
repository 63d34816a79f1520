//! Round 25, probe C's finding E: each thread's orbit-walk marks (4 bytes per dart slot of the
//! largest map it walked) were never released. Now `release_thread_caches` frees them, and they
//! shrink by themselves after many walks on much smaller maps. Counted with a global allocator
//! that tracks the net bytes of the test's own thread: deterministic, no timing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use topomech::generate::kuhn_cube;
use topomech::gmap::release_thread_caches;
use topomech::{AlphaMask, GMap};

thread_local! {
    /// Whether this thread's allocations are counted.
    static COUNTED: Cell<bool> = const { Cell::new(false) };
    /// This thread's net bytes (each test counts its own thread only).
    static NET: Cell<isize> = const { Cell::new(0) };
}

/// Adds the sizes the counted thread allocates and subtracts those it frees.
struct ThreadNet;

fn count(delta: isize) {
    if COUNTED.try_with(Cell::get).unwrap_or(false) {
        let _ = NET.try_with(|n| n.set(n.get() + delta));
    }
}

unsafe impl GlobalAlloc for ThreadNet {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count(-(layout.size() as isize));
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: ThreadNet = ThreadNet;

/// Builds a Kuhn cube of side k on this thread, walks one whole orbit, drops it; returns the
/// bytes still held by the thread.
fn walk_and_drop(k: usize) -> isize {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let d = map.darts().next().unwrap();
    assert_eq!(map.orbit(d, AlphaMask::all(3)).len(), map.dart_count());
    drop(map);
    NET.with(Cell::get)
}

/// A 12-cube (248 832 darts): about 1 MB of marks stays on the thread after the map is dropped,
/// and `release_thread_caches` frees them.
#[test]
fn released_walk_marks_return_their_memory() {
    let (kept, released) = std::thread::spawn(|| {
        COUNTED.with(|c| c.set(true));
        let kept = walk_and_drop(12);
        release_thread_caches();
        (kept, NET.with(Cell::get))
    })
    .join()
    .unwrap();
    assert!(kept >= 4 * 248_832, "{kept} bytes kept: the marks were expected to stay until released");
    assert!(released < 64 * 1024, "{released} bytes still held after release_thread_caches");
}

/// After 4 096 walks in a row on a map below a quarter of the marks, the marks shrink.
#[test]
fn walk_marks_shrink_after_many_small_walks() {
    let (kept, after) = std::thread::spawn(|| {
        COUNTED.with(|c| c.set(true));
        let kept = walk_and_drop(12);
        let (points, tets) = kuhn_cube(2); // 1 152 darts: each whole orbit is a stamped walk
        let (small, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let d = small.darts().next().unwrap();
        for _ in 0..4100 {
            assert_eq!(small.orbit(d, AlphaMask::all(3)).len(), small.dart_count());
        }
        drop(small);
        (kept, NET.with(Cell::get))
    })
    .join()
    .unwrap();
    assert!(after < kept / 2, "{kept} bytes before the small walks, {after} after");
}

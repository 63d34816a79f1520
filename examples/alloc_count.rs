//! Counts heap allocations (alloc + realloc calls) made by one face dissociation with its
//! projection update on liver_547, over the cut bench's random inner faces (the same selection
//! as `examples/cut_probe.rs`), each undone uncounted. A counting global allocator; prints the
//! mean and maximum per dissociation.
//!
//! `cargo run --release --example alloc_count`

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

#[path = "../benches/common/cut_select.rs"]
mod cut_select;

use topomech::cut;
use topomech::mechanics::{Body, Material, Projection, TouchedCells};

struct Counting;

static CALLS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        CALLS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn main() {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh"));
    let mesh = topomech::io::read_mesh(path).expect("liver_547.msh");
    let (z, _) = mesh.spatially_ordered();
    let (mut body, _) = Body::from_tets(&z.points, &z.tets, Material::default()).expect("mesh");
    let mut projection = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
    let (faces, _) = cut_select::faces_and_vertices(body.map());
    let (mut total, mut max) = (0, 0);
    for pass in 0..2 {
        for &d in &faces {
            let before = CALLS.load(Ordering::Relaxed);
            let dis = cut::dissociate_face(&mut body, d).expect("inner face");
            projection.update(&body, &dis.touched);
            let n = CALLS.load(Ordering::Relaxed) - before;
            if pass == 1 {
                total += n;
                max = max.max(n);
            }
            let changes = body.sew3(dis.dart, dis.opposite).expect("sew back");
            let mut touched = TouchedCells::default();
            touched.record_change(&body, &changes);
            projection.update(&body, &touched);
        }
    }
    println!(
        "ALLOC per dissociate_face+projection (2nd pass): mean {:.2} max {max} ({} faces)",
        total as f64 / faces.len() as f64,
        faces.len()
    );
}

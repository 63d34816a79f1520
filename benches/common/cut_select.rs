//! The cut benchmark's selection of darts, shared by `benches/cut.rs` and `examples/cut_probe.rs`
//! (a `#[path]` module) so that both time the same operations.

use topomech::generate::SplitMix64;
use topomech::{DartId, GMap};

/// Up to 4 096 inner faces and 256 interior vertices (one dart each), shuffled with SplitMix64
/// seeded 547 (faces first, then vertices, from one generator). O(darts).
pub fn faces_and_vertices(map: &GMap<3>) -> (Vec<DartId>, Vec<DartId>) {
    let mut rng = SplitMix64(547);
    let mut faces: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
    for i in (1..faces.len()).rev() {
        faces.swap(i, rng.below(i + 1));
    }
    faces.truncate(4096);
    let interior = |d: DartId| map.cell_darts(0, d).iter().all(|&x| !map.is_free(3, x));
    let mut vertices: Vec<DartId> = map.one_dart_per_cell(0).into_iter().filter(|&d| interior(d)).collect();
    for i in (1..vertices.len()).rev() {
        vertices.swap(i, rng.below(i + 1));
    }
    vertices.truncate(256);
    (faces, vertices)
}

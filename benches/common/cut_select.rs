//! The cut benchmark's selection of darts, shared by `benches/cut.rs` and `examples/cut_probe.rs`
//! (a `#[path]` module) so that both time the same operations.

use topomech::cut;
use topomech::generate::SplitMix64;
use topomech::mechanics::{Body, Vec3};
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

/// The inner faces that the plane through the bounding box's centre with normal (1, 0.3, 0.2)
/// separates, in `incise_plane`'s order (its own selection rule, on the body's map): the cut
/// bench's incision faces. O(darts).
#[allow(dead_code)] // this module is shared by targets that do not all use every selection
pub fn incision_faces(body: &Body, points: &[Vec3]) -> Vec<DartId> {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let plane = cut::Plane { point: std::array::from_fn(|c| (lo[c] + hi[c]) / 2.0), normal: [1.0, 0.3, 0.2] };
    let side = cut::tet_sides(body, &plane).expect("finite positions");
    let map = body.map();
    map.one_dart_per_cell(2)
        .into_iter()
        .filter(|&d| {
            let other = map.alpha::<3>(d);
            other != d && side[map.cell_id(3, d).index()] != side[map.cell_id(3, other).index()]
        })
        .collect()
}

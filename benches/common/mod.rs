//! Shared by the kernel benches: the seeded Kuhn-cube factory and a small criterion config.

use std::time::Duration;

use criterion::Criterion;
use topomech::generate::kuhn_cube;
use topomech::GMap;

/// Cube sizes benched: 41 472 and 995 328 darts (k = 40, the CGAL comparison size, is run by
/// `examples/bench_kernel.rs` and `scripts/bench_cgal.sh`).
pub const SIZES: [usize; 2] = [6, 18];

/// Few samples and short windows, so `cargo bench` takes a few minutes on a shared machine.
pub fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
}

/// The Kuhn cube of size k and its 3-G-map.
pub fn cube(k: usize) -> (Vec<[u32; 4]>, usize, GMap<3>) {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).expect("the Kuhn cube builds");
    (tets, points.len(), map)
}

//! One kernel phase in a loop, for `perf record` and for A/B runs of two builds of the library:
//! prints the thread's CPU time (and wall time) per dart.
//!
//!     cargo run --release --example prof_kernel -- PHASE K REPS     # Kuhn cube of size K
//!     cargo run --release --example prof_kernel -- PHASE MESH REPS  # a mesh file (Z-ordered if PHASE ends in _z)
//!
//! PHASE: build | validate | count | count_all (+ `_z` for a mesh file in Z-order).

use std::time::Instant;

use topomech::generate::kuhn_cube;
use topomech::GMap;

/// The thread's user + system CPU time in seconds (10 ms ticks; 0 where /proc is missing).
fn thread_cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let tick = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let phase = args.get(1).map_or("validate", String::as_str);
    let source = args.get(2).map_or("40", String::as_str);
    let reps: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let (points, tets) = match source.parse::<usize>() {
        Ok(k) => {
            let (p, t) = kuhn_cube(k);
            (p.len(), t)
        }
        Err(_) => {
            let mut mesh = topomech::io::read_mesh(std::path::Path::new(source)).expect("mesh reads");
            if phase.ends_with("_z") {
                mesh = mesh.spatially_ordered().0;
            }
            (mesh.points.len(), mesh.tets)
        }
    };
    let phase = phase.trim_end_matches("_z");
    let (map, _) = GMap::<3>::from_tets(points, &tets).expect("builds");
    let (c0, t) = (thread_cpu(), Instant::now());
    for _ in 0..reps {
        match phase {
            "build" => drop(std::hint::black_box(GMap::<3>::from_tets(points, &tets))),
            "validate" => assert!(map.validate().is_ok()),
            "count" => drop(std::hint::black_box(map.count_cells_by_traversal())),
            "count_all" => drop(std::hint::black_box((map.count_cells_by_traversal(), map.components().len()))),
            p => panic!("unknown phase {p}"),
        }
    }
    let per = |s: f64| s * 1e9 / (reps * map.dart_count()) as f64;
    let (cpu, wall) = (thread_cpu() - c0, t.elapsed().as_secs_f64());
    println!(
        "{phase} {source}: {:.1} ns/dart cpu, {:.1} wall; {:.0} ms cpu per call",
        per(cpu),
        per(wall),
        cpu * 1e3 / reps as f64
    );
}

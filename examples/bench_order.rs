//! Build time of a 3-G-map from a mesh in file order and in Z-order (`TetMesh::spatially_ordered`),
//! in the same run, interleaved (`ROUNDS` rounds, default 2). Wall-clock milliseconds and the
//! thread's CPU milliseconds (`/proc/thread-self/stat`, 10 ms ticks; the CPU figure is the one to
//! compare on a shared, loaded machine).
//!
//!     cargo run --release --example bench_order -- ../shared/meshes/liver_547.msh
//!     cargo run --release --example bench_order -- /work/liver_1M.msh 3   # see docs/BENCHMARKS.md

use std::path::Path;
use std::time::Instant;

use topomech::GMap;

/// The thread's user + system CPU time in milliseconds (0 where /proc is missing).
fn thread_cpu_ms() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let tick = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) * 10.0
}

/// Wall and CPU milliseconds of `op`, and its result.
fn timed<T>(op: impl FnOnce() -> T) -> (T, f64, f64) {
    let (c0, t) = (thread_cpu_ms(), Instant::now());
    let out = op();
    (out, t.elapsed().as_secs_f64() * 1e3, thread_cpu_ms() - c0)
}

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: bench_order MESH");
        std::process::exit(2);
    };
    let mesh = match topomech::io::read_mesh(Path::new(&path)) {
        Ok(mesh) => mesh,
        Err(e) => {
            eprintln!("bench_order: {e}");
            std::process::exit(1);
        }
    };
    let rounds: usize = std::env::args().nth(2).and_then(|r| r.parse().ok()).unwrap_or(2);
    for round in 1..=rounds {
        let (file, file_ms, file_cpu) =
            timed(|| GMap::<3>::from_tets(mesh.points.len(), &mesh.tets).expect("the mesh builds").0);
        let darts = file.dart_count();
        drop(file);
        let ((ordered, _), reorder_ms, reorder_cpu) = timed(|| mesh.spatially_ordered());
        let (z, z_ms, z_cpu) =
            timed(|| GMap::<3>::from_tets(ordered.points.len(), &ordered.tets).expect("the mesh builds").0);
        assert_eq!(darts, z.dart_count());
        println!(
            "round {round}: build {file_ms:.0} ms wall / {file_cpu:.0} ms cpu in file order, {z_ms:.0} ms wall / \
             {z_cpu:.0} ms cpu in Z-order (+ {reorder_ms:.0} / {reorder_cpu:.0} ms to reorder): {:.2}x cpu",
            file_cpu / z_cpu
        );
    }
}

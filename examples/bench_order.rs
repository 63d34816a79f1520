//! Build time of a 3-G-map from a mesh in file order and in Z-order (`TetMesh::spatially_ordered`),
//! in the same run, twice each, interleaved. Wall-clock milliseconds.
//!
//!     cargo run --release --example bench_order -- ../shared/meshes/liver_547.msh
//!     cargo run --release --example bench_order -- target/liver_1M.msh   # see docs/BENCHMARKS.md

use std::path::Path;
use std::time::Instant;

use topomech::GMap;

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
    for round in 1..=2 {
        let t = Instant::now();
        let (file, _) = GMap::<3>::from_tets(mesh.points.len(), &mesh.tets).expect("the mesh builds");
        let file_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let (ordered, _) = mesh.spatially_ordered();
        let reorder_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let (z, _) = GMap::<3>::from_tets(ordered.points.len(), &ordered.tets).expect("the mesh builds");
        let z_ms = t.elapsed().as_secs_f64() * 1e3;
        assert_eq!(file.dart_count(), z.dart_count());
        println!(
            "round {round}: build {file_ms:.0} ms in file order, {z_ms:.0} ms in Z-order (+ {reorder_ms:.0} ms to \
             reorder): {:.2}x",
            file_ms / z_ms
        );
    }
}

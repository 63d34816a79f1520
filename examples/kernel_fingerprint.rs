//! Fingerprint of everything `from_tets` produces (every α link, every cell id, the id
//! allocators, the build report, the error values) on Kuhn cubes with tets removed (pinched
//! vertices, split edges), reference meshes and non-manifold inputs: compare the output before
//! and after a change of the build code.
//!
//!     cargo run --release --example kernel_fingerprint -- [MESH ...]

use std::hash::{DefaultHasher, Hash, Hasher};

use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::{CellId, DartId, GMap};

fn fingerprint(points: usize, tets: &[[u32; 4]]) -> String {
    match GMap::<3>::from_tets(points, tets) {
        Err(e) => format!("error {e:?}"),
        Ok((map, report)) => {
            let mut h = DefaultHasher::new();
            for d in map.darts() {
                for i in 0..=3 {
                    map.alpha_dyn(i, d).hash(&mut h);
                    map.cell_id(i, d).hash(&mut h);
                }
            }
            for i in 0..=3 {
                map.cell_id_bound(i).hash(&mut h);
                (0..map.cell_id_bound(i) as u32).filter(|&c| map.is_live_cell(i, CellId(c))).count().hash(&mut h);
            }
            format!("{:016x} cells {:?} report {report:?}", h.finish(), map.count_cells().0)
        }
    }
}

fn main() {
    for k in [1, 3, 6] {
        let (points, tets) = kuhn_cube(k);
        for percent in [0, 30, 60, 85] {
            let mut rng = SplitMix64(k as u64 * 100 + percent as u64);
            let kept: Vec<[u32; 4]> = tets.iter().copied().filter(|_| rng.below(100) >= percent).collect();
            if kept.is_empty() {
                continue;
            }
            println!("kuhn {k} -{percent}%: {}", fingerprint(points.len(), &kept));
        }
    }
    let bad: [(&str, usize, Vec<[u32; 4]>); 4] = [
        ("three on a face", 6, vec![[0, 1, 2, 3], [0, 1, 2, 4], [2, 1, 0, 5]]),
        ("out of range", 4, vec![[0, 1, 2, 9]]),
        ("repeated", 4, vec![[0, 1, 1, 3]]),
        ("pinched pair", 7, vec![[0, 1, 2, 3], [4, 0, 5, 6]]),
    ];
    for (name, points, tets) in bad {
        println!("{name}: {}", fingerprint(points, &tets));
    }
    for path in std::env::args().skip(1) {
        let mesh = topomech::io::read_mesh(std::path::Path::new(&path)).expect("mesh reads");
        println!("{path}: {}", fingerprint(mesh.points.len(), &mesh.tets));
        let (z, _) = mesh.spatially_ordered();
        println!("{path} z-order: {}", fingerprint(z.points.len(), &z.tets));
    }
    let _ = DartId(0);
}

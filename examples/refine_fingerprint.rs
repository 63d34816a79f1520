//! Fingerprint of everything the bulk uniform refinement (`LeveledMap::refine_uniform`) produces:
//! every α link and cell id of every dart slot, the cell-id bounds and live cell counts, the
//! dart levels, μ, flat flags and link histories (`to_parts`), the split logs, the midpoints, the
//! tet masses and the returned figures, or the error value — after one to three levels on
//! triangle grids, a fan, Kuhn cubes and sub-complexes of them with boundary and several
//! components. Compare the output before and after a change of the bulk path: the numbering of
//! darts and cells is part of the result and must not move.
//!
//!     cargo run --release --example refine_fingerprint            # one hash line per case
//!     cargo run --release --example refine_fingerprint -- --full  # also every record, as text

use std::hash::{DefaultHasher, Hash, Hasher};

use topomech::generate::{disk_fan, grid_triangles, kuhn_cube, SplitMix64};
use topomech::mechanics::{Body, Material};
use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::{CellId, GMap};

#[path = "../tests/subdivide_common/mod.rs"]
mod subdivide_common;

/// Text of every record of `m` (one line per dart slot, then the logs).
fn records<const N: usize>(m: &LeveledMap<N>) -> String {
    let map = m.map();
    let mut out = subdivide_common::dart_rows(map);
    for i in 0..=N {
        let live = (0..map.cell_id_bound(i) as u32).filter(|&c| map.is_live_cell(i, CellId(c))).count();
        out.push_str(&format!("dim {i}: bound {} live {live}\n", map.cell_id_bound(i)));
    }
    out.push_str(&format!("parts {:?}\n", m.to_parts()));
    out.push_str(&format!("splits {:?}\nedge splits {:?}\n", m.split_log(), m.edge_split_log()));
    out
}

fn hash(text: &str) -> u64 {
    let mut h = DefaultHasher::new();
    text.hash(&mut h);
    h.finish()
}

fn report(name: &str, text: String, full: bool) {
    println!("{name}: {:016x} ({} bytes)", hash(&text), text.len());
    if full {
        println!("{text}");
    }
}

fn run_2d(name: &str, points: Vec<[f64; 3]>, tris: &[[u32; 3]], levels: &[u8], full: bool) {
    let (map, _) = GMap::<2>::from_triangles(points.len(), tris).expect("the triangles build");
    let mut m = LeveledMap::new(map, points);
    let mut text = String::new();
    for &level in levels {
        text.push_str(&format!("level {level}: {:?}\n", m.refine_uniform(level)));
    }
    text.push_str(&records(&m));
    report(name, text, full);
}

fn run_3d(name: &str, points: Vec<[f64; 3]>, tets: &[[u32; 4]], levels: &[u8], full: bool) {
    // Positions by vertex id (a point whose tets form several fans is several vertices).
    let (body, _) = Body::from_tets(&points, tets, Material::default()).expect("the tets build");
    let mut m = LeveledMap::new(body.map().clone(), body.attrs().position().as_slice().to_vec());
    let mut masses = TetMasses::from_density(&m, 1.0).expect("tets");
    let mut text = String::new();
    for &level in levels {
        let r = m.refine_uniform(level, &mut masses);
        let bits: Vec<u64> = masses.mass.iter().map(|x| x.to_bits()).collect();
        text.push_str(&format!("level {level}: {r:?}\nmasses {bits:?}\n"));
    }
    text.push_str(&records(&m));
    report(name, text, full);
}

/// Kuhn cube k with each tet kept with probability `keep`% and jittered points.
fn sub_kuhn(k: usize, keep: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut rng = SplitMix64(seed);
    let (mut points, tets) = kuhn_cube(k);
    for p in &mut points {
        for c in p.iter_mut() {
            *c += 0.2 * ((rng.below(2001) as f64) / 1000.0 - 1.0);
        }
    }
    let kept: Vec<[u32; 4]> = tets.into_iter().filter(|_| rng.below(100) < keep).collect();
    (points, kept)
}

fn main() {
    let full = std::env::args().any(|a| a == "--full");
    for (n, levels) in [(1, vec![1, 2, 3]), (3, vec![1, 2]), (6, vec![2, 3]), (20, vec![1])] {
        let (p, t) = grid_triangles(n);
        run_2d(&format!("grid {n} levels {levels:?}"), p, &t, &levels, full);
    }
    let (pts, tris) = disk_fan(7);
    run_2d("fan 7 levels [1, 2]", pts, &tris, &[1, 2], full);
    let (p, t) = grid_triangles(3);
    run_2d("grid 3 refused at level 0", p, &t, &[0], full);
    for (k, levels) in [(1, vec![1, 2]), (2, vec![1, 2]), (4, vec![1])] {
        let (p, t) = kuhn_cube(k);
        run_3d(&format!("kuhn {k} levels {levels:?}"), p, &t, &levels, full);
    }
    for (seed, keep) in [(1, 30), (2, 60), (3, 85)] {
        let (p, t) = sub_kuhn(3, keep, seed);
        run_3d(&format!("sub-kuhn 3 keep {keep}% seed {seed} levels [1, 2]"), p, &t, &[1, 2], full);
    }
}

//! Round 25's cost probe (docs/BENCHMARKS.md, "Round 25"): the spring coupling's `check` beside a
//! face split to levels 4–6 (law 6's gather, finding 234), and one tet refined by
//! `refine_around` beside an edge of valence K (the edge split's partner search, finding 241).
//! Each time is paired with `validate()` of the same map, a baseline measured in the same run.
//! The file uses only API that existed before round 25, so the same file built against the
//! previous commit gives the "before" figures.
//!
//! `vertex` (round 26, finding 248): operations at the centre vertex of a double cone of 2K tets
//! (valence 2K): a spoke's `split_edge`, and `refine_around` of every tet at the centre.
//!
//! `cargo run --release --example probe_round25 [check|valence|vertex]` (the first two without an
//! argument).

use std::time::Instant;
use topomech::subdivide::{LeveledMap, TetMasses};
use topomech::GMap;

#[path = "common/round25_meshes.rs"]
mod round25_meshes;
use round25_meshes::{double_cone, split_face};

/// A dart of the edge from vertex `a` to vertex `b`. O(darts).
fn edge_dart(m: &LeveledMap<3>, a: u32, b: u32) -> topomech::DartId {
    let map = m.map();
    map.darts().find(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha_dyn(0, d)).0 == b).unwrap()
}

/// The shortest of `reps` timings of `f`, in seconds.
fn best<T>(reps: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::MAX, f64::min)
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    if which == "check" || which.is_empty() {
        for levels in [4u8, 5, 6] {
            let (m, mech) = split_face(levels);
            let reps = if levels == 6 { 2 } else { 5 };
            let check = best(reps, || mech.check(&m).is_ok());
            let validate = best(reps, || m.map().validate().is_ok());
            println!(
                "check level {levels}: darts {} check {:.2} ms validate {:.3} ms ratio {:.1}",
                m.map().dart_count(),
                check * 1e3,
                validate * 1e3,
                check / validate
            );
        }
    }
    if which == "valence" || which.is_empty() {
        for k in [2000usize, 10_000, 20_000] {
            let (pts, tets) = double_cone(k);
            let (map, _) = GMap::<3>::from_tets(pts.len(), &tets).unwrap();
            let base = LeveledMap::new(map, pts.clone());
            let masses = TetMasses::from_density(&base, 1.0).unwrap();
            let p = [0.25 * (pts[3][0] + pts[4][0]), 0.25 * (pts[3][1] + pts[4][1]), 0.25];
            let mut splits = Vec::new();
            for _ in 0..3 {
                let (mut m, mut ms) = (base.clone(), masses.clone());
                let t = Instant::now();
                m.refine_around(p, 0.0, 1, &mut ms).unwrap();
                splits.push(t.elapsed().as_secs_f64());
            }
            let split = splits.iter().copied().fold(f64::MAX, f64::min);
            let validate = best(3, || base.map().validate().is_ok());
            println!(
                "valence {k}: refine one tet {:.2} ms validate {:.2} ms ratio {:.2}",
                split * 1e3,
                validate * 1e3,
                split / validate
            );
        }
    }
    if which == "vertex" {
        for k in [2000usize, 8000, 32_000] {
            let (pts, tets) = double_cone(k);
            let (map, _) = GMap::<3>::from_tets(pts.len(), &tets).unwrap();
            let base = LeveledMap::new(map, pts);
            let mut m = base.clone();
            let spokes: Vec<_> = (0..10).map(|i| edge_dart(&m, 0, 3 + (i * k / 10) as u32)).collect();
            let t = Instant::now();
            for &d in &spokes {
                m.split_edge(d, 1).unwrap();
            }
            let split = t.elapsed().as_secs_f64() / 10.0;
            let validate = best(3, || base.map().validate().is_ok());
            println!(
                "centre valence {}: split_edge of a spoke {:.3} ms validate {:.2} ms ratio {:.3}",
                2 * k,
                split * 1e3,
                validate * 1e3,
                split / validate
            );
        }
        for k in [500usize, 1000, 2000] {
            let (pts, tets) = double_cone(k);
            let (map, _) = GMap::<3>::from_tets(pts.len(), &tets).unwrap();
            let mut m = LeveledMap::new(map, pts);
            let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
            let validate = best(3, || m.map().validate().is_ok());
            let t = Instant::now();
            let r = m.refine_around([0.0; 3], 0.0, 1, &mut masses).unwrap();
            let refine = t.elapsed().as_secs_f64();
            println!(
                "centre valence {}: refine_around the centre, {} tets in {:.3} s validate {:.2} ms ratio {:.0}",
                2 * k,
                r.subdivided_per_level[1],
                refine,
                validate * 1e3,
                refine / validate
            );
        }
    }
}

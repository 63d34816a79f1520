//! Bulk uniform refinement (`LeveledMap::refine_uniform`, issue 5 performance) against the
//! op-by-op path (`subdivide_tet` / `subdivide_triangle` on every cell). The two must give the
//! same leveled map up to dart and cell numbering. Checked on every mesh, from the explicit dart
//! correspondence f (the finest-map isomorphism that fixes the level-0 darts, which keep their ids
//! in both paths):
//! - both maps keep every law (`check_all`), same cell counts at every level, and every extracted
//!   level G_i of one is isomorphic to the other's;
//! - f commutes with αj^i for every level i and j (so f restricted to B_i is an isomorphism of
//!   G_i), and preserves dart level, μ and vertex positions;
//! - link history: for every dart, its entries above its own level, mapped by f, are the same;
//! - split log: the same midpoints with the same end positions;
//! - tet masses: same total (1e-12 relative) and the same mass on corresponding children;
//! - refusals leave the map (and masses) unchanged.

use proptest::prelude::*;
use topomech::generate::{disk_fan, grid_triangles, kuhn_cube, SplitMix64};
use topomech::subdivide::{LeveledMap, Refinement, SubdivideError, TetMasses};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::triangle_mesh;

/// The leveled map of `tets` with one position per vertex id (a point whose tets form several
/// fans becomes several vertex ids: each gets the point's position). Dart 24t + 6f + k of
/// `from_tets` lies at the local vertex [a, b, b, c, c, a][k] of face f's corners (a, b, c).
fn tets_map(points: Vec<[f64; 3]>, tets: &[[u32; 4]]) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    let mut by_vid: Vec<Option<[f64; 3]>> = vec![None; map.cell_id_bound(0)];
    for (t, tet) in tets.iter().enumerate() {
        for f in 0..4 {
            let abc: Vec<usize> = (0..4).filter(|&x| x != f).collect();
            for (k, &local) in [abc[0], abc[1], abc[1], abc[2], abc[2], abc[0]].iter().enumerate() {
                let v = map.vertex_id(DartId((24 * t + 6 * f + k) as u32)).index();
                let p = points[tet[local] as usize];
                assert!(by_vid[v].is_none_or(|q| q == p), "one position per vertex id");
                by_vid[v] = Some(p);
            }
        }
    }
    LeveledMap::new(map, by_vid.into_iter().map(|p| p.unwrap_or([0.0; 3])).collect())
}

/// The correspondence f: bulk dart → per-op dart, from the level-0 darts (same ids in both).
fn correspondence<const N: usize>(bulk: &LeveledMap<N>, perop: &LeveledMap<N>) -> Vec<u32> {
    let mut f = vec![u32::MAX; bulk.map().capacity()];
    for d in bulk.map().darts().filter(|&d| bulk.dart_level(d) == 0) {
        if f[d.index()] != u32::MAX {
            continue;
        }
        let pairs = bulk.map().isomorphism_from(d, perop.map(), d).expect("the finest maps are isomorphic");
        for (x, y) in pairs {
            f[x.index()] = y.0;
        }
    }
    assert!(bulk.map().darts().all(|d| f[d.index()] != u32::MAX), "every component has a level-0 dart");
    f
}

fn assert_equivalent<const N: usize>(bulk: &LeveledMap<N>, perop: &LeveledMap<N>) {
    bulk.check_all().unwrap();
    perop.check_all().unwrap();
    assert_eq!(bulk.max_level(), perop.max_level());
    assert_eq!(bulk.map().count_cells(), perop.map().count_cells());
    let f = correspondence(bulk, perop);
    let fx = |d: DartId| DartId(f[d.index()]);
    for d in bulk.map().darts() {
        let e = fx(d);
        assert_eq!(bulk.dart_level(d), perop.dart_level(e), "dart level of {d}");
        assert_eq!(bulk.mu(d), perop.mu(e), "μ of {d}");
        assert_eq!(bulk.position(d), perop.position(e), "position of {d}");
        for i in 0..=bulk.max_level() {
            if bulk.dart_level(d) > i {
                continue;
            }
            for j in 0..=N {
                assert_eq!(fx(bulk.alpha_at(i, j, d)), perop.alpha_at(i, j, e), "α{j} at level {i} of {d}");
            }
        }
    }
    for i in 0..=bulk.max_level() {
        let (a, b) = (bulk.level(i).unwrap(), perop.level(i).unwrap());
        assert_eq!(a.map.count_cells(), b.map.count_cells(), "cells at level {i}");
        assert!(a.map.is_isomorphic(&b.map), "level {i} not isomorphic");
    }
    let (pa, pb) = (bulk.to_parts(), perop.to_parts());
    for d in bulk.map().darts() {
        let e = fx(d);
        let own = bulk.dart_level(d);
        let mapped: Vec<(u8, u8, u32)> = pa.darts[d.index()]
            .history
            .iter()
            .filter(|h| h.level > own)
            .map(|h| (h.level, h.j, f[h.old as usize]))
            .collect();
        let theirs: Vec<(u8, u8, u32)> =
            pb.darts[e.index()].history.iter().filter(|h| h.level > own).map(|h| (h.level, h.j, h.old)).collect();
        assert_eq!(mapped, theirs, "history of {d}");
    }
    assert_eq!(split_set(bulk), split_set(perop));
}

/// The split log as sorted (midpoint, end, end) positions (ids differ between the paths).
fn split_set<const N: usize>(m: &LeveledMap<N>) -> Vec<[u64; 9]> {
    let pos = |v: u32| m.points().get(v as usize).copied().unwrap_or([0.0; 3]);
    let mut out: Vec<[u64; 9]> = m
        .split_log()
        .iter()
        .map(|&[v, a, b]| {
            let (mut x, mut y) = (pos(a), pos(b));
            if y < x {
                std::mem::swap(&mut x, &mut y);
            }
            let p = pos(v);
            [p[0], p[1], p[2], x[0], x[1], x[2], y[0], y[1], y[2]].map(f64::to_bits)
        })
        .collect();
    out.sort_unstable();
    out
}

/// The ids of the edge cells joining vertex ids a and b in `map` (darts whose vertex is a and
/// whose α0 image's is b), sorted: two when an edge was cut apart but its ends were not. O(darts).
fn edges_between<const N: usize>(map: &GMap<N>, a: u32, b: u32) -> Vec<u32> {
    let mut ids: Vec<u32> = map
        .darts()
        .filter(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha::<0>(d)).0 == b)
        .map(|d| map.cell_id(1, d).0)
        .collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// The edge split log entries from `start` on, written by one refinement step from `before`:
/// same vertices as the split log, `edge` = the id the split edge had before the step, `halves`
/// = the ids of the two new edges at ends[0] and ends[1] after it. O(entries · darts).
fn assert_edge_splits<const N: usize>(before: &GMap<N>, m: &LeveledMap<N>, start: usize) {
    let (log, splits) = (m.edge_split_log(), m.split_log());
    assert_eq!(log.len(), splits.len(), "one edge split per inserted vertex");
    assert!(log.len() > start, "the step split edges");
    for (s, &[v, a, b]) in log[start..].iter().zip(&splits[start..]) {
        assert_eq!((s.vertex, s.ends), (v, [a, b]), "edge split log vs split log");
        assert!(edges_between(before, a, b).contains(&s.edge), "id of the split edge {a}-{b}");
        for k in 0..2 {
            assert_eq!(vec![s.halves[k]], edges_between(m.map(), s.ends[k], v), "half at {}", s.ends[k]);
        }
        assert_ne!(s.halves[0], s.halves[1]);
    }
}

/// Refines `m` to `levels` both ways (3D) and compares everything, masses included.
fn compare_tets(m: LeveledMap<3>, levels: u8) {
    let mut bulk = m.clone();
    let mut perop = m;
    let mut mb = TetMasses::from_density(&bulk, 2.5).unwrap();
    let mut mp = mb.clone();
    for level in 1..=levels {
        let (before, start) = (bulk.map().clone(), bulk.edge_split_log().len());
        let r = bulk.refine_uniform(level, &mut mb).unwrap();
        assert_edge_splits(&before, &bulk, start);
        let rel = (r.total_mass_after - r.total_mass_before).abs() / r.total_mass_before.max(1e-300);
        assert!(rel < 1e-12, "mass residual {rel}");
    }
    perop.refine_around_per_op([0.0; 3], f64::MAX, levels, &mut mp).unwrap();
    assert_equivalent(&bulk, &perop);
    let (tb, tp) = (mb.total(&bulk), mp.total(&perop));
    assert!((tb - tp).abs() <= 1e-12 * tp.abs(), "totals {tb} vs {tp}");
    let f = correspondence(&bulk, &perop);
    for d in bulk.map().one_dart_per_cell(3) {
        let x = mb.mass[bulk.map().cell_id(3, d).index()];
        let y = mp.mass[perop.map().cell_id(3, DartId(f[d.index()])).index()];
        assert!((x - y).abs() <= 1e-12 * y.abs().max(1e-300), "child mass {x} vs {y}");
        assert!(x > 0.0);
    }
}

/// Refines `m` to `levels` both ways (2D) and compares everything.
fn compare_tris(m: LeveledMap<2>, levels: u8) {
    let mut bulk = m.clone();
    let mut perop = m;
    for level in 1..=levels {
        let faces = perop.map().one_dart_per_cell(2);
        let (before, start) = (bulk.map().clone(), bulk.edge_split_log().len());
        assert_eq!(bulk.refine_uniform(level).unwrap(), faces.len());
        assert_edge_splits(&before, &bulk, start);
        for d in faces {
            perop.subdivide_triangle(d, level).unwrap();
        }
    }
    assert_equivalent(&bulk, &perop);
}

fn unit_tet() -> LeveledMap<3> {
    tets_map(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], &[[0, 1, 2, 3]])
}

#[test]
fn single_tet_matches_per_op_to_level_two() {
    compare_tets(unit_tet(), 1);
    compare_tets(unit_tet(), 2);
    let mut m = unit_tet();
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    m.refine_uniform(1, &mut masses).unwrap();
    m.refine_uniform(2, &mut masses).unwrap();
    assert_eq!(m.map().count_cells().0[3], 64);
    assert_eq!(m.level(1).unwrap().map.count_cells().0[3], 8);
}

#[test]
fn two_tets_and_skipped_level_match_per_op() {
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.9, 0.8, 0.7]];
    let m = tets_map(pts, &[[0, 1, 2, 3], [1, 2, 3, 4]]);
    compare_tets(m.clone(), 2);
    // A first level above 1 (level 0 → 3) is one step in both paths.
    let mut bulk = m.clone();
    let mut perop = m;
    let mut mb = TetMasses::from_density(&bulk, 1.0).unwrap();
    let mut mp = mb.clone();
    bulk.refine_uniform(3, &mut mb).unwrap();
    for d in perop.map().one_dart_per_cell(3) {
        perop.subdivide_tet_with_mass(d, 3, &mut mp).unwrap();
    }
    assert_equivalent(&bulk, &perop);
}

#[test]
fn kuhn_cubes_match_per_op() {
    for k in 2..=3 {
        let (points, tets) = kuhn_cube(k);
        compare_tets(tets_map(points, &tets), 1);
    }
    let (points, tets) = kuhn_cube(1);
    compare_tets(tets_map(points, &tets), 2);
}

#[test]
fn liver_piece_matches_per_op() {
    let mesh = topomech::load::load_builtin().unwrap().mesh;
    // The first 40 tets of the built-in liver, vertices renumbered densely.
    let tets: Vec<[u32; 4]> = mesh.tets.iter().take(40).copied().collect();
    let mut ids: Vec<u32> = tets.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let points: Vec<[f64; 3]> = ids.iter().map(|&v| mesh.points[v as usize]).collect();
    let local = |v: u32| ids.binary_search(&v).unwrap() as u32;
    let tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(local)).collect();
    compare_tets(tets_map(points, &tets), 1);
}

/// A random sub-complex of a jittered Kuhn cube (several components, boundary everywhere).
fn random_complex(seed: u64, k: usize, keep: usize, jitter: f64) -> LeveledMap<3> {
    let mut rng = SplitMix64(seed);
    let (mut points, tets) = kuhn_cube(k);
    for p in &mut points {
        for c in p.iter_mut() {
            *c += jitter * ((rng.below(2001) as f64) / 1000.0 - 1.0);
        }
    }
    let chosen: Vec<[u32; 4]> = tets.into_iter().filter(|_| rng.below(100) < keep).collect();
    let chosen = if chosen.is_empty() { vec![[0, 1, 3, 7]] } else { chosen };
    let mut ids: Vec<u32> = chosen.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let pts: Vec<[f64; 3]> = ids.iter().map(|&v| points[v as usize]).collect();
    let t: Vec<[u32; 4]> = chosen.iter().map(|t| t.map(|v| ids.binary_search(&v).unwrap() as u32)).collect();
    tets_map(pts, &t)
}

#[test]
fn triangles_grids_and_disk_match_per_op() {
    compare_tris(triangle_mesh(vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]], &[[0, 1, 2]]), 2);
    for n in [1, 3, 5] {
        let (p, t) = grid_triangles(n);
        compare_tris(triangle_mesh(p, &t), 1);
    }
    let (p, t) = grid_triangles(2);
    compare_tris(triangle_mesh(p, &t), 3);
    // A disk: a fan of 7 triangles around the centre.
    let (pts, tris) = disk_fan(7);
    compare_tris(triangle_mesh(pts, &tris), 2);
}

#[test]
fn refusals_leave_the_map_unchanged() {
    // Not uniform: one tet already refined.
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.9, 0.8, 0.7]];
    let mut m = tets_map(pts, &[[0, 1, 2, 3], [1, 2, 3, 4]]);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    let d = m.map().darts().next().unwrap();
    m.subdivide_tet(d, 1).unwrap();
    let (before, mass_before) = (m.to_parts(), masses.clone());
    let e = m.refine_uniform(2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::NotUniform { .. }), "{e}");
    assert_eq!((m.to_parts(), &masses), (before, &mass_before));
    // Level order and level bounds.
    let mut u = unit_tet();
    let mut mu = TetMasses::from_density(&u, 1.0).unwrap();
    u.refine_uniform(2, &mut mu).unwrap();
    let snapshot = u.to_parts();
    assert!(matches!(u.refine_uniform(1, &mut mu), Err(SubdivideError::LevelBelowMax { level: 1, max_level: 2 })));
    assert!(matches!(u.refine_uniform(2, &mut mu), Err(SubdivideError::AlreadyAtLevel { dim: 3, .. })));
    assert!(matches!(u.refine_uniform(251, &mut mu), Err(SubdivideError::LevelTooHigh(251))));
    assert_eq!(u.to_parts(), snapshot);
    // 2D: an inserted vertex (split edge) is refused.
    let mut t = triangle_mesh(vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]], &[[0, 1, 2]]);
    let d = t.map().darts().next().unwrap();
    t.split_edge(d, 1).unwrap();
    let snap = t.to_parts();
    assert!(matches!(t.refine_uniform(2), Err(SubdivideError::NotUniform { .. })));
    assert_eq!(t.to_parts(), snap);
    // 2D: an open face (a lone dart pair is not a triangle).
    let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let mut open = map.clone();
    let d = open.darts().next().unwrap();
    open.unsew::<1>(d).unwrap();
    let mut o = LeveledMap::new(open, vec![]);
    assert!(matches!(o.refine_uniform(1), Err(SubdivideError::OpenEdge(_))));
    // 3D: a tet with one α2-free edge is refused, map and masses unchanged.
    let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let d = map.darts().next().unwrap();
    map.unsew::<2>(d).unwrap();
    let mut open3 = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let mut masses = TetMasses { mass: vec![1.0] };
    let snap = open3.to_parts();
    assert!(matches!(open3.refine_uniform(1, &mut masses), Err(SubdivideError::OpenEdge(_))));
    assert_eq!((open3.to_parts(), masses.mass), (snap, vec![1.0]));
}

/// The Kuhn cube k = 2 refined around a ball by `refine_around` (bulk path when the ball holds
/// everything) and by `refine_around_per_op`: both maps and both reports.
fn refine_both_ways(center: [f64; 3], radius: f64, levels: u8) -> [(LeveledMap<3>, Refinement); 2] {
    let (points, tets) = kuhn_cube(2);
    let m = tets_map(points, &tets);
    let (mut a, mut b) = (m.clone(), m);
    let mut ma = TetMasses::from_density(&a, 1.0).unwrap();
    let mut mb = ma.clone();
    let ra = a.refine_around(center, radius, levels, &mut ma).unwrap();
    let rb = b.refine_around_per_op(center, radius, levels, &mut mb).unwrap();
    [(a, ra), (b, rb)]
}

#[test]
fn refine_around_takes_the_bulk_path_with_the_same_result() {
    let [(a, ra), (b, rb)] = refine_both_ways([0.5; 3], 100.0, 2);
    assert_eq!(ra.subdivided_per_level, rb.subdivided_per_level);
    assert!((ra.total_mass_after - rb.total_mass_after).abs() < 1e-12);
    assert_equivalent(&a, &b);
    // A small ball: not every tet, the per-op path; same counts as per-op.
    let [(_, ra), (_, rb)] = refine_both_ways([0.1; 3], 0.2, 1);
    assert_eq!(ra.subdivided_per_level, rb.subdivided_per_level);
    assert!(ra.subdivided_per_level[1] < kuhn_cube(2).1.len());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn random_tet_complexes_match_per_op(seed in 0u64..10_000, keep in 10usize..100, jitter in 0usize..3, levels in 1u8..3) {
        let m = random_complex(seed, 2, keep, [0.0, 0.05, 0.2][jitter]);
        compare_tets(m, if levels == 2 && keep > 40 { 1 } else { levels });
    }

    #[test]
    fn random_grids_match_per_op(n in 1usize..5, seed in 0u64..1000, levels in 1u8..3) {
        let (mut p, t) = grid_triangles(n);
        let mut rng = SplitMix64(seed);
        for q in &mut p {
            q[0] += 0.2 * ((rng.below(1001) as f64) / 1000.0 - 0.5);
        }
        compare_tris(triangle_mesh(p, &t), levels);
    }
}

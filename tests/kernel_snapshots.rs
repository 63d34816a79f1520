//! Snapshots of `summary()` for small maps. Each snapshot was reviewed by hand against the
//! closed forms asserted next to it (V, E, F, T, χ, boundary, orientability), so a snapshot
//! change is either a deliberate change of `MapSummary` or a bug.
//!
//! Run with `INSTA_UPDATE=no` (the default under `CI=true`) so a mismatch fails.

use topomech::generate::{grid_triangles, kuhn_cube};
use topomech::gmap::MapSummary;
use topomech::{DartId, GMap};

/// Asserts the closed forms, then the snapshot.
fn check(summary: &MapSummary, cells: &[usize], boundary: usize, chi: i64, orientable: bool) {
    assert!(summary.valid);
    assert_eq!(summary.cells.0, cells);
    assert_eq!(summary.boundary_faces, boundary);
    assert_eq!(summary.euler_characteristic, chi);
    assert_eq!(summary.orientable, orientable);
    assert_eq!(summary.components, 1);
}

/// Points of a w × h grid, index x + (w + 1)·y.
fn strip(w: u32, h: u32) -> (usize, Vec<[u32; 3]>) {
    let id = |x: u32, y: u32| x + (w + 1) * y;
    let mut t = Vec::new();
    for y in 0..h {
        for x in 0..w {
            t.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            t.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    (((w + 1) * (h + 1)) as usize, t)
}

/// The 2-free dart at point p on the boundary edge {p, q}.
fn boundary_dart(map: &GMap<2>, p: u32, q: u32) -> DartId {
    map.boundary_darts()
        .find(|&d| map.vertex_id(d).0 == p && map.vertex_id(map.alpha::<0>(d)).0 == q)
        .unwrap_or_else(|| panic!("no boundary dart on {p}-{q}"))
}

#[test]
fn one_tet() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let s = map.summary();
    check(&s, &[4, 6, 4, 1], 4, 1, true);
    assert_eq!(s.darts, 24);
    insta::assert_json_snapshot!(s);
}

#[test]
fn two_tets_sharing_a_face() {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let s = map.summary();
    check(&s, &[5, 9, 7, 2], 6, 1, true);
    assert_eq!(s.darts, 48);
    insta::assert_json_snapshot!(s);
}

#[test]
fn kuhn_cube_1() {
    let (points, tets) = kuhn_cube(1);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let s = map.summary();
    check(&s, &[8, 19, 18, 6], 12, 1, true);
    assert_eq!(s.darts, 144);
    insta::assert_json_snapshot!(s);
}

#[test]
fn kuhn_cube_2() {
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let s = map.summary();
    check(&s, &[27, 98, 120, 48], 48, 1, true);
    assert_eq!(s.darts, 1152);
    insta::assert_json_snapshot!(s);
}

#[test]
fn triangle_grid_3x3() {
    let (points, triangles) = grid_triangles(3);
    let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    let s = map.summary();
    check(&s, &[16, 33, 18], 12, 1, true);
    assert_eq!(s.darts, 108);
    insta::assert_json_snapshot!(s);
}

/// A strip of 3 squares (6 triangles) whose end edges are 2-sewn with a half twist.
/// V = 8 − 2, E = 13 − 1, F = 6, χ = 0, one boundary circle of 6 edges, non-orientable.
#[test]
fn mobius_strip() {
    let (points, triangles) = strip(3, 1);
    let (mut map, _) = GMap::<2>::from_triangles(points, &triangles).unwrap();
    let left = boundary_dart(&map, 0, 4);
    let right = boundary_dart(&map, 7, 3);
    map.sew::<2>(left, right).unwrap();
    let s = map.summary();
    check(&s, &[6, 12, 6], 6, 0, false);
    assert_eq!(s.darts, 36);
    insta::assert_json_snapshot!(s);
}

/// The same strip sewn without the twist is a cylinder: same counts, orientable, 2 circles.
#[test]
fn cylinder_is_the_untwisted_control() {
    let (points, triangles) = strip(3, 1);
    let (mut map, _) = GMap::<2>::from_triangles(points, &triangles).unwrap();
    map.sew::<2>(boundary_dart(&map, 0, 4), boundary_dart(&map, 3, 7)).unwrap();
    let s = map.summary();
    check(&s, &[6, 12, 6], 6, 0, true);
}

/// A 3 × 3 grid with opposite sides 2-sewn: V = 9, E = 27, F = 18, χ = 0, closed, orientable.
#[test]
fn torus_from_a_grid() {
    let n = 3;
    let (points, triangles) = strip(n, n);
    let (mut map, _) = GMap::<2>::from_triangles(points, &triangles).unwrap();
    let id = |x: u32, y: u32| x + (n + 1) * y;
    // Find every pair before sewing: sews merge vertices, so point indices stop naming them.
    let mut pairs = Vec::new();
    for k in 0..n {
        pairs.push((boundary_dart(&map, id(0, k), id(0, k + 1)), boundary_dart(&map, id(n, k), id(n, k + 1))));
        pairs.push((boundary_dart(&map, id(k, 0), id(k + 1, 0)), boundary_dart(&map, id(k, n), id(k + 1, n))));
    }
    for (a, b) in pairs {
        map.sew::<2>(a, b).unwrap();
    }
    let s = map.summary();
    check(&s, &[9, 27, 18], 0, 0, true);
    assert_eq!(s.darts, 108);
    insta::assert_json_snapshot!(s);
}

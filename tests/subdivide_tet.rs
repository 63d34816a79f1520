//! Tetrahedron 1→8 subdivision with levels (seed 004, §4.3.3, §5.2), checked after every
//! operation against the laws (finest map valid, μt ≤ μf ≤ μa, every level a valid G-map, level k
//! isomorphic to the finest map, B_{i−1} ⊂ B_i, Euler characteristic), against closed-form cell
//! counts derived below, and against volume conservation computed from the stored positions.

use proptest::prelude::*;
use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::{check_levels, cube, level_counts, tet_mesh};

fn one_tet(points: Vec<[f64; 3]>) -> LeveledMap<3> {
    tet_mesh(points, &[[0, 1, 2, 3]])
}

/// Refines every tet of level < L at level L, for L = 1..=levels, checking after every operation.
fn refine_uniformly(m: &mut LeveledMap<3>, levels: u8) {
    for level in 1..=levels {
        let tets: Vec<DartId> = m.map().one_dart_per_cell(3).into_iter().filter(|&d| m.mu(d).tet < level).collect();
        for d in tets {
            m.subdivide_tet(d, level).unwrap();
            check_levels(m);
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn tet_volume(p: [[f64; 3]; 4]) -> f64 {
    let (u, v, w) = (sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0]));
    let det =
        u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    det.abs() / 6.0
}

/// The volume of every tet of the finest map, from the positions of its 4 distinct vertices
/// (asserting that each volume has exactly 4: true after uniform refinement, where no face keeps
/// an inserted flat vertex).
fn tet_volumes(m: &LeveledMap<3>) -> Vec<f64> {
    let mut out = Vec::new();
    for d in m.map().one_dart_per_cell(3) {
        let mut vids: Vec<usize> = m.map().cell_darts(3, d).iter().map(|&x| m.map().vertex_id(x).index()).collect();
        vids.sort_unstable();
        vids.dedup();
        assert_eq!(vids.len(), 4, "volume of {d:?} is not a plain tet");
        out.push(tet_volume([0, 1, 2, 3].map(|k| m.points()[vids[k]])));
    }
    out
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let s = sub(a, b);
    (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
}

const IRREGULAR: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [3.0, 0.2, 0.0], [0.4, 2.0, 0.1], [0.3, 0.5, 1.7]];

#[test]
fn one_tet_refined_to_level_2_has_64_tets_of_equal_volume() {
    let mut m = one_tet(IRREGULAR.to_vec());
    let parent = tet_volume(IRREGULAR);
    refine_uniformly(&mut m, 2);
    for i in 0..=2u32 {
        // Red refinement cuts every edge into n = 2^i parts: the vertices are the lattice points
        // of the tet, V = (n+1)(n+2)(n+3)/6; T = n³; each tet has 4 faces, the boundary has 4n²,
        // so F = (4n³ − 4n²)/2 + 4n² = 2n³ + 2n²; a ball has V − E + F − T = 1, so
        // E = V + F − T − 1. Level 1: [10, 25, 24, 8]; level 2: [35, 130, 160, 64].
        let n = 1usize << i;
        let (v, t, f) = ((n + 1) * (n + 2) * (n + 3) / 6, n * n * n, 2 * n * n * n + 2 * n * n);
        let counts = m.level(i as u8).unwrap().map.count_cells().0;
        assert_eq!(counts, vec![v, v + f - t - 1, f, t], "level {i}");
    }
    insta::assert_json_snapshot!("subdivide_tet_single_counts", level_counts(&m));
    // Every child of a red refinement has 1/8 of its parent's volume, whatever the diagonal.
    let vols = tet_volumes(&m);
    let total: f64 = vols.iter().sum();
    assert!((total - parent).abs() <= 1e-12 * parent, "total {total} vs {parent}");
    for v in vols {
        assert!((v - parent / 64.0).abs() <= 1e-12 * parent, "child volume {v}");
    }
    assert!(m.map().darts().all(|d| m.mu(d).tet == 2));
}

#[test]
fn the_octahedron_is_split_along_its_shortest_diagonal() {
    let mut m = one_tet(IRREGULAR.to_vec());
    m.subdivide_tet(DartId(0), 1).unwrap();
    check_levels(&m);
    // The only edge of level 1 with no boundary dart is the diagonal.
    let inner: Vec<DartId> = m
        .map()
        .one_dart_per_cell(1)
        .into_iter()
        .filter(|&e| m.map().cell_darts(1, e).iter().all(|&x| !m.map().is_free(3, x)))
        .collect();
    assert_eq!(inner.len(), 1);
    let a = m.position(inner[0]);
    let b = m.position(m.map().alpha::<0>(inner[0]));
    let mid = |x: usize, y: usize| [0, 1, 2].map(|k| 0.5 * (IRREGULAR[x][k] + IRREGULAR[y][k]));
    let candidates = [dist(mid(0, 1), mid(2, 3)), dist(mid(0, 2), mid(1, 3)), dist(mid(0, 3), mid(1, 2))];
    let shortest = candidates.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((dist(a, b) - shortest).abs() < 1e-12, "diagonal {} vs candidates {candidates:?}", dist(a, b));
    assert!(candidates.iter().filter(|&&c| (c - shortest).abs() < 1e-9).count() == 1, "test tet must have no tie");
}

#[test]
fn kuhn_cube_refined_to_level_1_is_conforming() {
    let mut m = cube(1);
    refine_uniformly(&mut m, 1);
    // Level 1: V = 8 + 19 edge midpoints = 27; F = 4·18 + 8·6 = 120; T = 48;
    // E = 2·19 + 3·18 (inner edges of split faces) + 6 (diagonals) = 98; V − E + F − T = 1.
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![27, 98, 120, 48]);
    // Conforming: the only α3-free darts are those of the 4·12 boundary triangles.
    assert_eq!(m.map().boundary_cell_count(), 48);
    assert_eq!(m.map().darts().filter(|&d| m.map().is_free(3, d)).count(), 48 * 6);
    let total: f64 = tet_volumes(&m).iter().sum();
    assert!((total - 1.0).abs() < 1e-12, "cube volume {total}");
}

#[test]
fn neighbour_reuses_the_split_face_and_errors_leave_the_map_unchanged() {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, -2.0]];
    let mut m = LeveledMap::new(map, pts);
    m.subdivide_tet(DartId(0), 1).unwrap();
    check_levels(&m);
    // The neighbour (tet 1, darts 24..48) sees the shared face split in 4 and keeps μt = 0.
    assert_eq!(m.mu(DartId(24)).tet, 0);
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![11, 28, 27, 9]);
    let before = m.clone();
    assert!(matches!(m.subdivide_tet(DartId(0), 1), Err(SubdivideError::AlreadyAtLevel { dim: 3, .. })));
    assert!(m.map().is_isomorphic(before.map()));
    m.subdivide_tet(DartId(24), 1).unwrap();
    check_levels(&m);
    // Both refined: V = 5 + 9 = 14, F = 4·7 + 16 = 44, T = 16, E = 2·9 + 3·7 + 2 = 41 (χ = 1).
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![14, 41, 44, 16]);
    assert_eq!(m.level(0).unwrap().map.count_cells().0, vec![5, 9, 7, 2]);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_edge_face_tet_refinement_keeps_every_law(
        steps in prop::collection::vec((any::<usize>(), 0u8..3, any::<bool>()), 1..7)
    ) {
        let mut m = cube(1);
        for (k, op, up) in steps {
            let darts: Vec<DartId> = m.map().darts().collect();
            let d = darts[k % darts.len()];
            let level = (m.max_level() + up as u8).max(1);
            let r = match op {
                0 => m.split_edge(d, level).map(|_| ()),
                1 => m.subdivide_triangle(d, level).map(|_| ()),
                _ => m.subdivide_tet(d, level).map(|_| ()),
            };
            match r {
                Ok(()) => check_levels(&m),
                Err(SubdivideError::AlreadyAtLevel { .. } | SubdivideError::FaceRefinedTooFar { .. }) => {}
                Err(e) => prop_assert!(false, "unexpected error {e}"),
            }
        }
    }
}

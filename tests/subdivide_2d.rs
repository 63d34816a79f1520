//! Adaptive-resolution subdivision of triangle meshes (seed 004, §4.3.1–§4.3.2, §5.1): edge
//! splits and triangle 1→4 with levels, checked after every operation against the laws — the
//! finest map valid, μf ≤ μa, every level a valid G-map, nesting, Euler characteristic — and
//! against cell counts derived by hand.

use proptest::prelude::*;
use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::{check_levels, grid, level_counts, triangle_mesh};

fn single_triangle() -> LeveledMap<2> {
    triangle_mesh(vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]], &[[0, 1, 2]])
}

/// One dart of every face whose face level is below `level`.
fn faces_below(m: &LeveledMap<2>, level: u8) -> Vec<DartId> {
    m.map().one_dart_per_cell(2).into_iter().filter(|&d| m.mu(d).face < level).collect()
}

fn refine_uniformly(m: &mut LeveledMap<2>, levels: u8) {
    for level in 1..=levels {
        for d in faces_below(m, level) {
            m.subdivide_triangle(d, level).unwrap();
            check_levels(m);
        }
    }
}

#[test]
fn a_triangle_refined_to_level_k_has_4_pow_k_triangles() {
    let mut m = single_triangle();
    refine_uniformly(&mut m, 3);
    for i in 0..=3u32 {
        let counts = m.level(i as u8).unwrap().map.count_cells().0;
        // V = (2^i + 1)(2^i + 2)/2, E = 3·2^i(2^i + 1)/2, F = 4^i on a triangle cut 2^i per side.
        let s = 1usize << i;
        assert_eq!(counts, vec![(s + 1) * (s + 2) / 2, 3 * s * (s + 1) / 2, 4usize.pow(i)], "level {i}");
    }
    insta::assert_json_snapshot!("subdivide_2d_single_triangle_counts", level_counts(&m));
}

#[test]
fn edge_split_makes_the_neighbour_a_quad_at_the_new_level_only() {
    let (map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [1, 3, 2]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]]);
    let inner = m.map().darts().find(|&d| !m.map().is_free(2, d)).unwrap();
    let mid = m.split_edge(inner, 1).unwrap();
    check_levels(&m);
    assert_eq!(m.level(0).unwrap().map.count_cells().0, vec![4, 5, 2]);
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![5, 6, 2]);
    // Both faces now have 4 vertices (8 darts) at level 1 and keep face level 0.
    for f in m.map().one_dart_per_cell(2) {
        assert_eq!(m.map().cell_darts(2, f).len(), 8);
        assert_eq!(m.mu(f).face, 0);
    }
    assert_eq!(m.position(mid), [1.0, 1.0, 0.0]);
    assert_eq!(m.mu(mid).edge, 1);
    // Splitting the same edge again at level 1 is refused; the map is unchanged.
    let before = m.map().dart_count();
    assert!(matches!(m.split_edge(inner, 1), Err(SubdivideError::AlreadyAtLevel { dim: 1, .. })));
    assert_eq!(m.map().dart_count(), before);
}

#[test]
fn neighbour_keeps_the_shared_midpoint_and_levels_follow_the_paper() {
    let (map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [1, 3, 2]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]]);
    let faces = m.map().one_dart_per_cell(2);
    m.subdivide_triangle(faces[0], 1).unwrap();
    check_levels(&m);
    // Level 1: 4 children + the neighbour (a quad, face level 0, shared edge level 1).
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![7, 11, 5]);
    let neighbour = m.map().darts().find(|&d| m.mu(d).face == 0).unwrap();
    assert_eq!(m.map().cell_darts(2, neighbour).len(), 8);
    m.subdivide_triangle(neighbour, 1).unwrap();
    check_levels(&m);
    // Level 1 is now the uniform refinement of the square: 9 vertices, 16 edges, 8 triangles.
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![9, 16, 8]);
    assert!(m.map().darts().all(|d| m.mu(d).face == 1 && m.mu(d).edge == 1));
    let child = m.map().one_dart_per_cell(2)[0];
    m.subdivide_triangle(child, 2).unwrap();
    check_levels(&m);
    assert_eq!(m.level(2).unwrap().map.count_cells().0, vec![9 + 3, 16 + 3 + 3, 8 - 1 + 4]);
}

#[test]
fn level_order_and_bad_input_are_errors() {
    let mut m = single_triangle();
    let d = m.map().darts().next().unwrap();
    let kids = m.subdivide_triangle(d, 2).unwrap();
    assert_eq!(m.max_level(), 2);
    assert!(matches!(m.subdivide_triangle(kids[0], 1), Err(SubdivideError::LevelBelowMax { level: 1, max_level: 2 })));
    assert!(matches!(m.subdivide_triangle(kids[0], 2), Err(SubdivideError::AlreadyAtLevel { dim: 2, .. })));
    assert!(matches!(m.subdivide_triangle(DartId(9999), 3), Err(SubdivideError::NoSuchDart(_))));
    assert!(matches!(m.subdivide_triangle(kids[0], 251), Err(SubdivideError::LevelTooHigh(251))));
    // Levels 0 and 1 are both the single triangle (nothing happened at level 1).
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![3, 3, 1]);
    check_levels(&m);
}

#[test]
fn new_vertices_are_edge_midpoints_and_corner_ids_are_kept() {
    let mut m = single_triangle();
    let d = m.map().darts().next().unwrap();
    let corners: Vec<_> = m.map().one_dart_per_cell(0).iter().map(|&v| m.map().vertex_id(v)).collect();
    m.subdivide_triangle(d, 1).unwrap();
    let mut pts: Vec<[f64; 3]> = m.map().one_dart_per_cell(0).iter().map(|&v| m.position(v)).collect();
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let expect = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 4.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [4.0, 0.0, 0.0]];
    assert_eq!(pts, expect);
    for c in corners {
        assert!(m.map().is_live_cell(0, c));
        assert!(c.0 < 3);
    }
}

/// One random step: split an edge or subdivide a face at the current level or one above.
#[derive(Clone, Debug)]
enum Step {
    Split(usize, bool),
    Face(usize, bool),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        (any::<usize>(), any::<bool>()).prop_map(|(d, up)| Step::Split(d, up)),
        (any::<usize>(), any::<bool>()).prop_map(|(d, up)| Step::Face(d, up)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_adaptive_sequences_keep_every_law(steps in prop::collection::vec(step(), 1..14)) {
        let mut m = grid(2);
        for s in steps {
            let darts: Vec<DartId> = m.map().darts().collect();
            let (k, up, face) = match s { Step::Split(k, up) => (k, up, false), Step::Face(k, up) => (k, up, true) };
            let d = darts[k % darts.len()];
            let level = (m.max_level() + up as u8).max(1);
            let before = m.map().clone();
            let r = if face { m.subdivide_triangle(d, level).map(|_| ()) } else { m.split_edge(d, level).map(|_| ()) };
            match r {
                Ok(()) => check_levels(&m),
                Err(SubdivideError::AlreadyAtLevel { .. }) => prop_assert!(before.is_isomorphic(m.map())),
                Err(e) => prop_assert!(false, "unexpected error {e}"),
            }
        }
    }
}

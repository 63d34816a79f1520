//! Adaptive-resolution subdivision in tetrahedral meshes (seed 004, §4.3.2–§4.3.3): edge splits
//! and face 1→4 in 3-G-maps, with the α2 and α3 neighbours updated, checked after every
//! operation (finest map valid, μt ≤ μf ≤ μa, every level a valid G-map, Euler characteristic).
//! Tetrahedron 1→8 has its own suite (`subdivide_tet.rs`).

use proptest::prelude::*;
use topomech::generate::kuhn_cube;
use topomech::subdivide::{LeveledMap, SubdivideError};
use topomech::{DartId, GMap};

mod subdivide_common;
use subdivide_common::{check_levels, tet_mesh};

fn two_tets() -> LeveledMap<3> {
    let pts = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, -2.0]];
    tet_mesh(pts, &[[0, 1, 2, 3], [0, 1, 2, 4]])
}

#[test]
fn shared_face_split_is_seen_by_both_tets() {
    let mut m = two_tets();
    let shared = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    m.subdivide_triangle(shared, 1).unwrap();
    check_levels(&m);
    assert_eq!(m.level(0).unwrap().map.count_cells().0, vec![5, 9, 7, 2]);
    // +3 midpoints, +3 half edges, +3 inserted edges; the shared face becomes 4 faces.
    assert_eq!(m.level(1).unwrap().map.count_cells().0, vec![8, 15, 10, 2]);
    // Face level 1 on both sides of the four faces, tet level 0 everywhere: μt ≤ μf ≤ μa.
    let on_face: Vec<DartId> = m.map().darts().filter(|&d| m.mu(d).face == 1).collect();
    assert_eq!(on_face.len(), 4 * 12);
    assert!(m.map().darts().all(|d| m.mu(d).tet == 0));
    // An α2-adjacent face (not split) got its edge split: 4 vertices, face level 0, μa = 1.
    let side = m.map().darts().find(|&d| m.mu(d).face == 0 && m.mu(d).edge == 1).unwrap();
    assert_eq!(m.map().cell_darts(2, side).len(), 8);
}

#[test]
fn boundary_face_then_edge_of_its_child() {
    let mut m = two_tets();
    let boundary = m.map().darts().find(|&d| m.map().is_free(3, d)).unwrap();
    let kids = m.subdivide_triangle(boundary, 1).unwrap();
    check_levels(&m);
    m.split_edge(kids[3], 2).unwrap();
    check_levels(&m);
    let grand = m.subdivide_triangle(kids[0], 2).unwrap();
    check_levels(&m);
    assert!(matches!(m.subdivide_triangle(grand[0], 2), Err(SubdivideError::AlreadyAtLevel { dim: 2, .. })));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_face_and_edge_refinement_keeps_every_law(steps in prop::collection::vec((any::<usize>(), any::<bool>(), any::<bool>()), 1..8)) {
        let (points, tets) = kuhn_cube(1);
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut m = LeveledMap::new(map, points);
        for (k, face, up) in steps {
            let darts: Vec<DartId> = m.map().darts().collect();
            let d = darts[k % darts.len()];
            let level = (m.max_level() + up as u8).max(1);
            let r = if face { m.subdivide_triangle(d, level).map(|_| ()) } else { m.split_edge(d, level).map(|_| ()) };
            match r {
                Ok(()) => check_levels(&m),
                Err(SubdivideError::AlreadyAtLevel { .. }) => {}
                Err(e) => prop_assert!(false, "unexpected error {e}"),
            }
        }
    }
}

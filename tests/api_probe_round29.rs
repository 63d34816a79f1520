//! Round 29's probes: faces sewn onto themselves (finding 270), the α0-unsew of a
//! high-valence edge (271, fixed in the next session), masses too small for f64 in the
//! subdivision layer (268), and the CLI's tear threshold (269, in `tests/cli.rs`).

use topomech::mechanics::Material;
use topomech::subdivide::{LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::{DartId, GMap};

/// One triangle of six darts (α0 pairs 0-1, 2-3, 4-5; α1 pairs 1-2, 3-4, 5-0).
fn triangle<const N: usize>() -> (GMap<N>, Vec<DartId>) {
    let mut map = GMap::<N>::new();
    let d: Vec<DartId> = (0..6).map(|_| map.create_dart().unwrap()).collect();
    for (a, b) in [(0, 1), (2, 3), (4, 5)] {
        map.sew::<0>(d[a], d[b]).unwrap();
    }
    for (a, b) in [(1, 2), (3, 4), (5, 0)] {
        map.sew::<1>(d[a], d[b]).unwrap();
    }
    (map, d)
}

/// Finding 270: a triangle of a 3-map folded onto itself by α3 (a valid map) made
/// `subdivide_triangle` loop for ever; with two sides glued by α2 (a cone) the split returned
/// `Ok` and `check_all` then failed on the flat law (a glued side split twice). Both are refused
/// now, from every start dart, with nothing changed.
#[test]
fn a_face_sewn_onto_itself_is_refused_not_split() {
    let (mut map, d) = triangle::<3>();
    map.sew::<3>(d[0], d[1]).unwrap();
    map.validate().unwrap();
    for &s in &d {
        let mut m = LeveledMap::new(map.clone(), vec![]);
        let before = format!("{:?}", m.to_parts());
        let e = m.subdivide_triangle(s, 1).unwrap_err();
        assert!(matches!(e, SubdivideError::SelfGluedFace { alpha: 3, .. }), "{e:?}");
        assert_eq!(format!("{:?}", m.to_parts()), before);
        assert_eq!(m.map().dart_count(), 6);
    }
    let (mut cone, d) = triangle::<2>();
    cone.sew::<2>(d[0], d[3]).unwrap();
    cone.validate().unwrap();
    for &s in &d {
        let mut m = LeveledMap::new(cone.clone(), vec![]);
        let e = m.subdivide_triangle(s, 1).unwrap_err();
        assert!(matches!(e, SubdivideError::SelfGluedFace { alpha: 2, .. }), "{e:?}");
        m.check_all().unwrap();
        assert_eq!(m.map().dart_count(), 6);
    }
    // An ordinary triangle still splits.
    let (map, d) = triangle::<2>();
    let mut m = LeveledMap::new(map, vec![]);
    m.subdivide_triangle(d[0], 1).unwrap();
    m.check_all().unwrap();
}

/// Finding 271 (the α0-unsew of an edge of valence k was O(k²); linear now, guarded by the unit
/// test `a_high_valence_edge_unsews_in_linear_walks`): the fix must keep the cells exact;
/// checked here against the traversal count on a fan of k tets around one edge, small and
/// large k.
#[test]
fn the_unsew_of_a_high_valence_edge_keeps_exact_cells() {
    for k in [3u32, 10, 40, 300] {
        let tets: Vec<[u32; 4]> = (0..k).map(|i| [0, 1, 2 + i, 2 + (i + 1) % k]).collect();
        let (mut m, _) = GMap::<3>::from_tets(k as usize + 2, &tets).unwrap();
        let d = m.darts().find(|&d| m.vertex_id(d).0 == 0 && m.vertex_id(m.alpha_dyn(0, d)).0 == 1).unwrap();
        m.unsew_dyn(0, d).unwrap();
        m.validate().unwrap();
        assert_eq!(m.count_cells(), m.count_cells_by_traversal(), "k = {k}");
        // The unsewn orbit is its own edge now: one edge more than the fan had.
        assert_eq!(m.count_cells().0[1], 3 * k as usize + 1 + 1, "k = {k}");
    }
}

fn unit_tet() -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
}

/// Finding 268: a density whose tet masses are below the normal range of f64 was accepted by the
/// subdivision layer, and a refinement then broke its own mass laws (Σ tet mass off by 6e-4
/// relative on the liver at ρ = 1e-320; the coupling failed its centre-of-mass law). Such masses
/// are refused now, as a body refuses them: at construction (their quarter has no finite
/// inverse) and before a split (a child's quarter would not).
#[test]
fn masses_too_small_for_f64_are_refused_by_the_subdivision_layer() {
    let m = unit_tet();
    for density in [1e-315, 5e-324, 1e-307] {
        let e = TetMasses::from_density(&m, density).unwrap_err();
        assert!(matches!(e, SubdivideError::MassTooSmall { volume: 0, .. }), "{density}: {e:?}");
        let material = Material { density, ..Material::default() };
        assert!(LeveledMechanics::new(&m, material).is_err(), "{density}");
    }
    // 1e-306 / 6 has a quarter with an inverse, but its children's eighths would not.
    let mut m = unit_tet();
    let mut masses = TetMasses::from_density(&m, 1e-306).unwrap();
    let d = m.map().darts().next().unwrap();
    let e = m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::MassTooSmall { .. }), "{e:?}");
    assert_eq!(m.map().dart_count(), 24);
    let e = m.refine_around([0.1; 3], 1.0, 1, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::MassTooSmall { .. }), "{e:?}");
    let e = m.refine_uniform(1, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::MassTooSmall { .. }), "{e:?}");
    assert_eq!(m.map().dart_count(), 24);
    // The smallest density the layer takes splits with its laws.
    let mut masses = TetMasses::from_density(&m, 1e-290).unwrap();
    let total = masses.total(&m);
    m.refine_around([0.1; 3], 1.0, 2, &mut masses).unwrap();
    assert!((masses.total(&m) - total).abs() <= 1e-12 * total);
    masses.check(&m).unwrap();
}

//! Findings of the thirteenth API probing round (docs/VERIFICATION.md, "Findings"). Each test
//! fails on the code before its fix.

use topomech::subdivide::{LeveledMap, SubdivideError, TetMasses};
use topomech::GMap;

fn two_tets() -> (GMap<3>, Vec<[f64; 3]>) {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    (map, pts)
}

/// Finding 70: the bulk mass-coupled `refine_uniform` is documented as giving the result of
/// `subdivide_tet_with_mass` on every tet, which refuses a corner with a NaN position or none;
/// the bulk pass accepted both (NaN midpoints, masses shared by m/8 as if the volumes were zero).
/// Now both refuse, with the map and the masses unchanged.
#[test]
fn bulk_mass_refinement_refuses_what_the_per_tet_one_refuses() {
    let (map, pts) = two_tets();
    let reference = LeveledMap::new(map.clone(), pts.clone());
    let masses = TetMasses::from_density(&reference, 6.0).unwrap();

    let mut nan_pts = pts.clone();
    nan_pts[4] = [f64::NAN, 0.0, 1.0];
    let mut per_tet = LeveledMap::new(map.clone(), nan_pts.clone());
    let mut m1 = masses.clone();
    let d = per_tet.map().darts().find(|&d| per_tet.map().vertex_id(d).0 == 4).unwrap();
    let per_tet_err = per_tet.subdivide_tet_with_mass(d, 1, &mut m1).unwrap_err();
    assert!(matches!(per_tet_err, SubdivideError::NonFinitePosition { vertex: 4, .. }), "{per_tet_err:?}");

    let mut bulk = LeveledMap::new(map.clone(), nan_pts);
    let mut m2 = masses.clone();
    let e = bulk.refine_uniform(1, &mut m2).unwrap_err();
    assert!(matches!(e, SubdivideError::NonFinitePosition { vertex: 4, .. }), "{e:?}");
    assert_eq!((bulk.map().dart_count(), bulk.max_level(), bulk.points().len()), (48, 0, 5));
    assert_eq!(m2, masses);

    // No positions at all: the per-tet operation names a missing position, so does the bulk one.
    let mut none = LeveledMap::new(map, Vec::new());
    let mut m3 = masses.clone();
    let e = none.refine_uniform(1, &mut m3).unwrap_err();
    assert!(matches!(e, SubdivideError::NoPosition { points: 0, .. }), "{e:?}");
    assert_eq!((none.map().dart_count(), none.max_level()), (48, 0));
    assert_eq!(m3, masses);

    // Finite positions: still accepted, and the same masses as tet by tet.
    let mut ok = LeveledMap::new(reference.map().clone(), pts);
    let mut m4 = masses.clone();
    let r = ok.refine_uniform(1, &mut m4).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 2]);
    assert!((r.total_mass_after - r.total_mass_before).abs() <= 1e-15 * r.total_mass_before);
}

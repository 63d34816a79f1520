//! Round 25, probe A's findings on the spring coupling's checker and its mass totals:
//! F1 law 3 against rounded midpoints far from the origin, F3 an overflowing compensated total,
//! F4 `TetMasses::vertex_masses` lumping as the coupling does, F5 law 6's gather per volume.

use topomech::cut::ops::jittered_cube;
use topomech::mechanics::Material;
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, SpringLawError, SubdivideError, TetMasses};
use topomech::{DartId, GMap};

#[path = "../examples/common/round25_meshes.rs"]
mod round25_meshes;

/// The jittered cube `jittered_cube(1, 7)` scaled by `scale` and moved by `offset` on every axis.
fn moved_cube(offset: f64, scale: f64) -> (LeveledMap<3>, LeveledMechanics) {
    let (points, tets) = jittered_cube(1, 7);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|x| x * scale + offset)).collect();
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let m = LeveledMap::new(map, points);
    let mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    (m, mech)
}

fn edge_dart(m: &LeveledMap<3>, a: u32, b: u32) -> DartId {
    let map = m.map();
    map.darts().find(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha_dyn(0, d)).0 == b).unwrap()
}

/// F1: a unit cube 1000 units from the origin refined around a corner: its rounded midpoints
/// are up to ulp(1000)/2 from the exact middles, more than 1e-12 of a half edge from level 4;
/// the coupling's own refinement must pass its own check (it failed law 3 at level 4, and under
/// `expensive-checks` the refinement panicked as a "topomech bug").
#[test]
fn a_far_cube_refined_passes_check() {
    for levels in 1..=6u8 {
        let (mut m, mut mech) = moved_cube(1000.1, 1.0);
        let c = m.points()[0];
        mech.refine_around(&mut m, c, 0.05, levels).unwrap();
        assert_eq!(mech.check(&m), Ok(()), "levels {levels}");
    }
}

/// F1: a 1 mm cube at 0.1 m refined to 8 µm edges (failed at level 7).
#[test]
fn a_millimetre_cube_at_a_decimetre_refined_passes_check() {
    for levels in [4u8, 7, 8] {
        let (mut m, mut mech) = moved_cube(0.1, 1e-3);
        let c = m.points()[0];
        mech.refine_around(&mut m, c, 1e-5, levels).unwrap();
        assert_eq!(mech.check(&m), Ok(()), "levels {levels}");
    }
}

/// F1: edge splits one by one on a jittered cube 1e4 from the origin (failed at the first).
#[test]
fn edge_splits_far_from_the_origin_pass_check() {
    let (mut m, mut mech) = moved_cube(1e4, 1.0);
    for (a, b) in [(0u32, 1u32), (1, 2), (0, 3), (2, 3)] {
        let Some(d) = m.map().darts().find(|&d| {
            let map = m.map();
            map.vertex_id(d).0 == a && map.vertex_id(map.alpha_dyn(0, d)).0 == b
        }) else {
            continue;
        };
        mech.split_edge(&mut m, d, 1).unwrap();
        assert_eq!(mech.check(&m), Ok(()), "after splitting ({a}, {b})");
    }
}

/// F1: the allowance is for rounding only: a half whose rest length is off by 1e-9 of the edge
/// is still reported far from the origin.
#[test]
fn a_wrong_rest_length_far_from_the_origin_is_still_reported() {
    let (mut m, mut mech) = moved_cube(1000.1, 1.0);
    let c = m.points()[0];
    mech.refine_around(&mut m, c, 0.05, 2).unwrap();
    let (e, s) = mech.springs().find(|(e, _)| e.b >= 8).unwrap();
    mech.spring_mut(e).unwrap().rest = s.rest * (1.0 + 1e-9);
    assert!(matches!(mech.check(&m), Err(SpringLawError::RestLength { .. }) | Err(SpringLawError::Series { .. })));
}

/// F3: masses whose sum overflows total +∞ (the compensated sum gave NaN), and the coupling's
/// refusal names +∞.
#[test]
fn an_overflowing_mass_total_is_infinite() {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let m = LeveledMap::new(map, pts);
    let huge = TetMasses { mass: vec![f64::MAX, f64::MAX] };
    assert_eq!(huge.total(&m), f64::INFINITY);
    match LeveledMechanics::with_masses(&m, Material::default(), huge).unwrap_err() {
        CouplingError::Subdivide(SubdivideError::MassOverflow { total }) => assert_eq!(total, f64::INFINITY),
        other => panic!("{other:?}"),
    }
}

/// F4: `TetMasses::vertex_masses` lumps as the coupling does: a hanging midpoint has its share
/// (it had none), and both agree vertex by vertex.
#[test]
fn tet_masses_lump_as_the_coupling() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let mut mech = LeveledMechanics::new(&m, Material { density: 6.0, ..Material::default() }).unwrap();
    let d = edge_dart(&m, 0, 1);
    mech.split_edge(&mut m, d, 1).unwrap();
    let d = edge_dart(&m, 0, 2);
    mech.split_edge(&mut m, d, 1).unwrap();
    let coupling = mech.vertex_masses(&m).unwrap();
    let tets = mech.masses.vertex_masses(&m).unwrap();
    assert_eq!(coupling, tets);
    assert!(tets.iter().all(|&x| x > 0.0), "{tets:?}");
    assert!((tets.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

/// F5: law 6's gather beside a face split to level 5 (each coarse tet holds ~500 hanging
/// vertices) passes, and a changed volume mass is still reported.
#[test]
fn law_six_beside_a_deeply_split_face() {
    let (m, mut mech) = round25_meshes::split_face(5);
    assert!(m.map().count_cells().0[0] > 500);
    assert_eq!(mech.check(&m), Ok(()));
    mech.masses.mass[0] *= 1.5;
    assert!(matches!(mech.check(&m), Err(SpringLawError::TotalMass { .. })));
}

/// A unit Kuhn cube (k = 1) as a leveled map, scaled by `s`.
fn leveled_cube(s: f64) -> LeveledMap<3> {
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|x| x * s)).collect();
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    LeveledMap::new(map, points)
}

/// Probe B's F2: a coupling built for one map is refused on another of the same mesh, size and
/// version (it refined it with `Ok` and the first map's rest lengths), before the map changes;
/// a clone taken together with the coupling is followed, a clone changed on its own is not.
#[test]
fn a_coupling_refuses_another_map_of_the_same_size() {
    let a = leveled_cube(1.0);
    let mut b = leveled_cube(3.0);
    let mut mech = LeveledMechanics::new(&a, Material::default()).unwrap();
    let before = (b.version(), b.map().dart_count());
    let e = mech.refine_around(&mut b, [0.5; 3], 10.0, 1).unwrap_err();
    assert_eq!(e, CouplingError::OtherMap);
    assert_eq!((b.version(), b.map().dart_count()), before);
    assert!(mech.spring_system(&b, [0.0; 3], &[]).is_err());
    assert!(matches!(mech.check(&b), Err(SpringLawError::NotFollowed { .. })));

    // the pair cloned together: the copy follows the copy
    let (mut a2, mut mech2) = (a.clone(), mech.clone());
    mech2.refine_around(&mut a2, [0.5; 3], 10.0, 1).unwrap();
    assert_eq!(mech2.check(&a2), Ok(()));
    // the original coupling on the changed copy: refused (same version as a refined original)
    let mut a3 = a.clone();
    let d = a3.map().darts().next().unwrap();
    a3.split_edge(d, 1).unwrap();
    assert!(mech.split_edge(&mut a3, d, 1).is_err());
    let mut mine = a.clone();
    mech.refine_around(&mut mine, [0.5; 3], 10.0, 1).unwrap();
    assert_eq!(mech.check(&mine), Ok(()));
    assert_eq!(mech.refine_around(&mut a2, [0.5; 3], 10.0, 2).unwrap_err(), CouplingError::OtherMap);
}

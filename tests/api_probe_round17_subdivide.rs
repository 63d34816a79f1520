//! API probe round 17, subdivision and coupling (findings 122–125 of `docs/VERIFICATION.md`):
//! every test states a law the code before the round broke.
//!
//! - 122: `LeveledMechanics::new` / `with_masses` built couplings whose springs were ∞ or NaN
//!   (rest length |b − a|² overflowed at edge 1e160; E·V/L² overflowed with E = 1e300 at edge
//!   1e100), and a later split doubled a stiffness past `f64::MAX`; `refine_around` then panicked
//!   in its own law check.
//! - 123: a regular tet of edge 1e-110 was refused as "zero volume" by the coupling and by
//!   `Body::from_tets` (its volume underflows f64), and `Body::from_tets` refused E·V/L² as an
//!   overflow when only E·V overflowed.
//! - 124: `TetMasses::from_density` formed ρ·V after V under- or overflowed: mass 0 for ρ = 1e300
//!   at edge 1e-110, a false `MassOverflow` for ρ = 1e-100 at edge 1e110.
//! - 125: a second `refine_around` whose ball met a tet two levels below the map's max level left
//!   it coarse and returned `Ok` (its levels start at the max level).

use topomech::gmap::GMap;
use topomech::mechanics::{Body, Material, ModelError};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, SubdivideError, TetMasses};

/// A leveled map of one tet with corners 0, s·x, s·y, s·z.
fn tet(s: f64) -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    LeveledMap::new(map, vec![[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]])
}

/// Every spring of the coupling has finite rest length, stiffness and damping.
fn all_finite(mech: &LeveledMechanics) -> bool {
    mech.springs().all(|(_, s)| s.rest.is_finite() && s.stiffness.is_finite() && s.damping.is_finite())
}

/// Finding 122: a coupling at edge 1e160 has finite springs (E·V/L² ≈ 1.7e162, L measured
/// scale-safely), keeps its laws, and refines without a panic.
#[test]
fn f122_coupling_at_edge_1e160_has_finite_springs_and_refines() {
    let mut m = tet(1e160);
    let mut mech = LeveledMechanics::with_masses(&m, Material::default(), TetMasses { mass: vec![1.0] }).unwrap();
    assert!(all_finite(&mech));
    mech.check(&m).unwrap();
    let k = mech.spring(0, 1).unwrap().stiffness;
    assert!((k / (1000.0 * 1e160 / 6.0) - 1.0).abs() < 1e-12, "k = {k:e}");
    mech.refine_around(&mut m, [0.0; 3], 0.0, 2).unwrap();
    assert!(all_finite(&mech));
    mech.check(&m).unwrap();
}

/// Finding 122: a stiffness or a rest length past `f64::MAX` is refused before the coupling
/// exists, naming the volume, the edge and the quantity (as `Body::from_tets` refuses it).
#[test]
fn f122_coupling_refuses_springs_past_f64() {
    let m = tet(1e100);
    let mat = Material { density: 1e-10, young: 1e300, ..Material::default() };
    let pts = m.points().to_vec();
    assert!(matches!(Body::from_tets(&pts, &[[0, 1, 2, 3]], mat), Err(ModelError::Overflow { .. })));
    let e = LeveledMechanics::new(&m, mat).unwrap_err();
    assert!(
        matches!(e, CouplingError::Overflow { volume: 0, quantity: "stiffness", value, .. } if value.is_infinite()),
        "{e}"
    );
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let far = vec![[-1e308, 0.0, 0.0], [1e308, 0.0, 0.0], [0.0, 1e308, 0.0], [0.0, 0.0, 1e308]];
    let m = LeveledMap::new(map, far);
    let e = LeveledMechanics::with_masses(&m, Material::default(), TetMasses { mass: vec![1.0] }).unwrap_err();
    assert!(matches!(e, CouplingError::Overflow { quantity: "rest length", .. }), "{e}");
}

/// Finding 122: a split whose halves (2k) or children's terms would pass `f64::MAX` is refused
/// before the map changes; refinement never stores a non-finite spring, and the coupling keeps its
/// laws whatever the outcome.
#[test]
fn f122_splits_never_make_a_spring_past_f64() {
    // Edge (0, 1) of length 0.01: k = E·V/L² = E · (0.01/6) / 1e-4 ≈ 1.67e308 for E = 1e307.
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0; 3], [0.01, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let mat = Material { young: 1e307, ..Material::default() };
    let mut mech = LeveledMechanics::new(&m, mat).unwrap();
    assert!(all_finite(&mech));
    let d = m.map().darts().find(|&d| mech.edge(0, 1) == Some(topomech::subdivide::EdgeKey::of(m.map(), d))).unwrap();
    let (version, darts) = (m.version(), m.map().dart_count());
    let e = mech.split_edge(&mut m, d, 1).unwrap_err();
    assert!(matches!(e, CouplingError::SplitOverflow { .. }), "{e}");
    assert_eq!((m.version(), m.map().dart_count()), (version, darts));
    mech.check(&m).unwrap();
    let e = mech.subdivide_tet(&mut m, d, 1).unwrap_err();
    assert!(matches!(e, CouplingError::SplitOverflow { .. }), "{e}");
    let r = mech.refine_around(&mut m, [0.0; 3], 1.0, 1);
    assert!(matches!(r, Err(CouplingError::SplitOverflow { .. })), "{r:?}");
    assert_eq!((m.version(), m.map().dart_count()), (version, darts));
    mech.check(&m).unwrap();
    // A unit tet with E = 1.5e308: the halves double at every level until one would overflow.
    let mut m = tet(1.0);
    let mut mech = LeveledMechanics::new(&m, Material { young: 1.5e308, ..Material::default() }).unwrap();
    let r = mech.refine_around(&mut m, [0.1; 3], 10.0, 6);
    assert!(matches!(r, Err(CouplingError::SplitOverflow { .. })), "{r:?}");
    assert!(all_finite(&mech));
    mech.check(&m).unwrap();
}

/// Finding 123: a regular tet of edge 1e-110 is no degenerate tet. The coupling takes it, with
/// k = E·V/L² = 1000 · 1e-110 / 6 on its axis edges, and refines it; a flat tet at that scale is
/// still refused.
#[test]
fn f123_tiny_regular_tet_is_not_degenerate() {
    let s = 1e-110;
    let mut m = tet(s);
    let mut mech = LeveledMechanics::with_masses(&m, Material::default(), TetMasses { mass: vec![1.0] }).unwrap();
    let k = mech.spring(0, 1).unwrap().stiffness;
    assert!((k / (1000.0 * s / 6.0) - 1.0).abs() < 1e-12, "k = {k:e}");
    assert!(mech.springs().all(|(_, sp)| sp.stiffness > 0.0 && sp.rest > 0.0));
    mech.check(&m).unwrap();
    mech.refine_around(&mut m, [0.1 * s; 3], 0.0, 2).unwrap();
    mech.check(&m).unwrap();
    assert!(mech.springs().all(|(_, sp)| sp.stiffness.is_finite()));

    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let flat = vec![[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [s, s, 0.0]];
    let e = LeveledMechanics::with_masses(
        &LeveledMap::new(map, flat.clone()),
        Material::default(),
        TetMasses { mass: vec![1.0] },
    );
    assert!(matches!(e, Err(CouplingError::DegenerateTet { volume: 0, .. })), "{e:?}");
    let e = Body::from_tets(&flat, &[[0, 1, 2, 3]], Material::default()).map(|_| ()).unwrap_err();
    assert!(matches!(e, ModelError::DegenerateTet { tet: 0 }), "{e}");
}

/// Finding 123 for a body: a tiny regular tet is refused for what it is (its rest volume, which a
/// body stores, underflows f64), not as a zero-volume tet; and E·V/L² is finite when only E·V is
/// past `f64::MAX` (E = 1e300, edge 1e5: k ≈ 1.7e304).
#[test]
fn f123_body_measures_tiny_tets_and_large_moduli_right() {
    let m = tet(1e-110);
    let pts = m.points().to_vec();
    let e = Body::from_tets(&pts, &[[0, 1, 2, 3]], Material::default()).map(|_| ()).unwrap_err();
    assert!(matches!(e, ModelError::VolumeUnderflow { tet: 0, .. }), "{e}");

    let m = tet(1e5);
    let pts = m.points().to_vec();
    let mat = Material { young: 1e300, damping: 1e-3, ..Material::default() };
    let (body, _) = Body::from_tets(&pts, &[[0, 1, 2, 3]], mat).unwrap();
    let k = body.attrs().edge_stiffness(body.map().cell_id(1, topomech::DartId(0)));
    assert!(k.is_finite() && k > 1e303, "k = {k:e}");
    topomech::mechanics::check_conservation(body.map(), body.attrs()).unwrap();
    let mech = LeveledMechanics::new(&m, mat).unwrap();
    let k = mech.spring(0, 1).unwrap().stiffness;
    assert!((k / (1e300 * 1e5 / 6.0) - 1.0).abs() < 1e-12, "k = {k:e}");
}

/// Finding 124: ρ·V is formed without V under- or overflowing first: ρ = 1e300 at edge 1e-110
/// weighs 1e300 · 1e-330 / 6, ρ = 1e-100 at edge 1e110 weighs 1e-100 · 1e330 / 6; a real overflow
/// is still refused, and ordinary masses keep their bits.
#[test]
fn f124_from_density_is_scale_safe() {
    let m = tet(1e-110);
    let total = TetMasses::from_density(&m, 1e300).unwrap().total(&m);
    assert!((total / (1e300 * 1e-110 * 1e-110 * 1e-110 / 6.0) - 1.0).abs() < 1e-12, "mass {total:e}");
    let m = tet(1e110);
    let total = TetMasses::from_density(&m, 1e-100).unwrap().total(&m);
    assert!((total / (1e-100 * 1e110 * 1e110 * 1e110 / 6.0) - 1.0).abs() < 1e-12, "mass {total:e}");
    let e = TetMasses::from_density(&m, 1e100).unwrap_err(); // 1e100 · 1e330 / 6
    assert!(matches!(e, SubdivideError::MassOverflow { total } if total.is_infinite()), "{e}");
    let m = tet(1.0);
    let p = m.points();
    let plain = 6.0 * topomech::mesh::signed_volume(p[0], p[1], p[2], p[3]).abs();
    assert_eq!(TetMasses::from_density(&m, 6.0).unwrap().mass, vec![plain]);
}

/// Two unit tets ten apart; the first refined to level 2 around a point inside it.
fn two_tets_first_at_level_2() -> (LeveledMap<3>, TetMasses) {
    let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    let mut pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    pts.extend(pts.clone().iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
    let mut m = LeveledMap::new(map, pts);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    m.refine_around([0.1; 3], 0.0, 2, &mut masses).unwrap();
    (m, masses)
}

/// Every tet of the finest map meeting the ball B(c, r) is at μt = `level`.
fn ball_at_level(m: &LeveledMap<3>, c: [f64; 3], r: f64, level: u8) -> bool {
    m.map().one_dart_per_cell(3).into_iter().all(|d| !m.tet_in_ball(d, c, r).unwrap() || m.mu(d).tet == level)
}

/// Finding 125 and its follow-up: `refine_around` never returns `Ok` with a tet of its ball left
/// below its levels. A ball meeting a tet at μt < k − 1 (k the map's max level), which the levels
/// L = k.. cannot reach one at a time, first catches it up by a level skip (split at level k),
/// on the plain, the per-op and the coupled path alike; mass is conserved.
#[test]
fn f125_refine_around_catches_up_a_tet_below_its_levels() {
    let far = [10.1, 0.1, 0.1];
    for per_op in [false, true] {
        let (mut m, mut masses) = two_tets_first_at_level_2();
        let before: f64 = masses.total(&m);
        let r = if per_op {
            m.refine_around_per_op(far, 0.0, 3, &mut masses).unwrap()
        } else {
            m.refine_around(far, 0.0, 3, &mut masses).unwrap()
        };
        assert_eq!(r.subdivided_per_level[2], 1, "the catch-up: {r:?}");
        assert!(r.subdivided_per_level[3] >= 1, "{r:?}");
        assert!(ball_at_level(&m, far, 0.0, 3));
        assert!((r.total_mass_before - before).abs() <= 1e-15 && (r.total_mass_after / before - 1.0).abs() < 1e-12);
        m.check_all().unwrap();
    }

    let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    let mut pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    pts.extend(pts.clone().iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
    let mut m = LeveledMap::new(map, pts);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    mech.refine_around(&mut m, [0.1; 3], 0.0, 2).unwrap();
    let r = mech.refine_around(&mut m, far, 0.0, 3).unwrap();
    assert_eq!(r.subdivided_per_level[2], 1, "{r:?}");
    assert!(ball_at_level(&m, far, 0.0, 3));
    mech.check(&m).unwrap();
    m.check_all().unwrap();
}

/// The catch-up reaches every μt below k − 1 at once: tets A, B, C far apart, A refined to
/// level 3, B to level 1, C left at 0; a ball over B and C ends with every tet in it at μt = 3.
#[test]
fn catch_up_reaches_tets_of_several_levels() {
    let (map, _) = GMap::<3>::from_tets(12, &[[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11]]).unwrap();
    let unit = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let pts: Vec<[f64; 3]> = (0..3).flat_map(|k| unit.map(|p| [p[0] + 10.0 * k as f64, p[1], p[2]])).collect();
    let mut m = LeveledMap::new(map, pts);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    m.refine_around([10.1, 0.1, 0.1], 0.0, 1, &mut masses).unwrap(); // B to level 1
    m.refine_around([0.1; 3], 0.0, 3, &mut masses).unwrap(); // A to level 3
    assert_eq!(m.max_level(), 3);
    let (c, r) = ([15.0, 0.1, 0.1], 5.5);
    let tets_in_ball = |m: &LeveledMap<3>| {
        m.map().one_dart_per_cell(3).into_iter().filter(|&d| m.tet_in_ball(d, c, r).unwrap()).count()
    };
    let coarse = tets_in_ball(&m);
    let out = m.refine_around(c, r, 3, &mut masses).unwrap();
    assert!(ball_at_level(&m, c, r, 3));
    assert!(out.subdivided_per_level[3] >= coarse, "{out:?}");
    assert!((out.total_mass_after / out.total_mass_before - 1.0).abs() < 1e-12);
    m.check_all().unwrap();
}

/// The catch-up is all or nothing: tets T1 = (0,1,2,3) and T2 = (1,2,3,4) share a face; T2 is
/// refined twice next to it, so the shared face is refined twice and T1 can no longer be split.
/// A ball over T1 and a far tet F (both at μt = 0 < k − 1) is refused (`FaceRefinedTooFar`),
/// and the map and the masses are what they were, even if F was split first. Since round 29
/// (finding 264) `refine_around` never refines a face twice (first part: its zone takes T1 at
/// level 1, and the second ball then succeeds), so the stuck state is made by single operations.
#[test]
fn catch_up_refused_leaves_everything_unchanged() {
    let (map, _) = GMap::<3>::from_tets(9, &[[4, 1, 2, 3], [0, 1, 2, 3], [5, 6, 7, 8]]).unwrap();
    let pts = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [-20.0, 0.0, 0.0],
        [-19.0, 0.0, 0.0],
        [-20.0, 1.0, 0.0],
        [-20.0, 0.0, 1.0],
    ];
    let mut m = LeveledMap::new(map, pts);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    let shared_face_centre = [1.0 / 3.0; 3];
    let near = [shared_face_centre[0] + 0.01, shared_face_centre[1] + 0.01, shared_face_centre[2] + 0.01];
    let (mut balanced, mut balanced_masses) = (m.clone(), masses.clone());
    balanced.refine_around(near, 0.0, 2, &mut balanced_masses).unwrap();
    balanced.check_faces_refinable().unwrap();
    balanced.refine_around([-9.0, 0.2, 0.2], 11.5, 2, &mut balanced_masses).unwrap();
    balanced.check_faces_refinable().unwrap();
    // By hand: T2 at level 1, then its child on the shared face at level 2.
    let t2 = m.map().darts().find(|&d| m.tet_vertices(d).unwrap() == [1, 2, 3, 4]).unwrap();
    let children = m.subdivide_tet_with_mass(t2, 1, &mut masses).unwrap();
    let on_face = children.iter().copied().find(|&c| {
        let volume = m.map().orbit(c, topomech::AlphaMask::of(&[0, 1, 2]));
        volume.iter().any(|&x| !m.map().is_free(3, x) && m.mu(m.map().alpha::<3>(x)).tet == 0)
    });
    m.subdivide_tet_with_mass(on_face.unwrap(), 2, &mut masses).unwrap();
    assert!(m.check_faces_refinable().is_err());
    assert_eq!(m.max_level(), 2);
    let (version, darts, before) = (m.version(), m.map().dart_count(), masses.clone());
    let e = m.refine_around([-9.0, 0.2, 0.2], 11.5, 2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::FaceRefinedTooFar { .. }), "{e}");
    assert_eq!((m.version(), m.map().dart_count(), &masses), (version, darts, &before));
    m.check_all().unwrap();
}

/// A survivor of the 36th mutation sample (`2.0 * at + 8.0 * bt` read as `2.0 * at + 8.0 + bt` in
/// the per-tet bound): a refused refinement names the tet whose own bound 2A + 8B is the largest.
/// A sliver (a square of diagonals 1.41, 0.1 apart) has children's terms far above its springs
/// (its inner segment is 0.1 long); a regular-ish tet three times larger has the stiffer springs.
/// With B counted once instead of eight times the larger tet would be named.
#[test]
fn split_overflow_names_the_tet_with_the_largest_bound() {
    let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    let h = 0.1;
    let mut pts = vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, h], [0.0, 1.0, h]];
    pts.extend([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|p| p.map(|c| 10.0 + 3.0 * c)));
    let mut m = LeveledMap::new(map, pts);
    let mut mech = LeveledMechanics::new(&m, Material { young: 1e308, ..Material::default() }).unwrap();
    let (version, darts) = (m.version(), m.map().dart_count());
    let e = mech.refine_around(&mut m, [5.0; 3], 100.0, 1).unwrap_err();
    let CouplingError::SplitOverflow { dart, .. } = e else { panic!("{e}") };
    let corners = m.tet_vertices(dart).unwrap();
    assert!(corners.iter().all(|&v| v < 4), "named the larger tet: {corners:?}");
    assert_eq!((m.version(), m.map().dart_count()), (version, darts));
}

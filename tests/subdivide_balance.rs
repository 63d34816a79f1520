//! Finding 264: `refine_around` balances its zones across faces (2:1), so that no call leaves a
//! tet whose face a neighbour refined twice — such a tet could never be split again, and a later
//! ball meeting it was refused with `FaceRefinedTooFar`.

use topomech::generate::kuhn_cube;
use topomech::mechanics::Material;
use topomech::subdivide::{LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::GMap;

#[path = "rng_common/mod.rs"]
mod rng_common;

fn cube(n: usize) -> LeveledMap<3> {
    let (p, t) = kuhn_cube(n);
    let (map, _) = GMap::<3>::from_tets(p.len(), &t).unwrap();
    LeveledMap::new(map, p)
}

/// The state every call must leave: a valid leveled map, masses that cover it and sum to the
/// start, and every tet still splittable as far as its faces go.
fn assert_balanced(m: &LeveledMap<3>, masses: &TetMasses, total: f64, what: &str) {
    m.check_all().unwrap_or_else(|e| panic!("{what}: {e}"));
    masses.check(m).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!((masses.total(m) - total).abs() <= 1e-12 * total, "{what}: mass {} against {total}", masses.total(m));
    m.check_faces_refinable().unwrap_or_else(|e| panic!("{what}: {e}"));
}

/// Round 27's probe: two balls at the centres of the unit cells of `kuhn_cube(2)` (all 64
/// ordered pairs), the first refined to level 2, the second to level 2 or 3. Before the balance,
/// 35 of the 64 second calls at level 2 were refused with `FaceRefinedTooFar`.
#[test]
fn a_second_ball_is_never_refused_for_a_face_the_first_refined_twice() {
    let centres: Vec<[f64; 3]> =
        (0..8).map(|i| [0.5 + (i & 1) as f64, 0.5 + (i >> 1 & 1) as f64, 0.5 + (i >> 2) as f64]).collect();
    for (i, &a) in centres.iter().enumerate() {
        for (j, &b) in centres.iter().enumerate() {
            let mut m = cube(2);
            let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
            let total = masses.total(&m);
            m.refine_around(a, 0.0, 2, &mut masses).unwrap();
            assert_balanced(&m, &masses, total, &format!("first ball {i}"));
            let levels = 2 + ((i + j) % 2) as u8;
            let r = m.refine_around(b, 0.0, levels, &mut masses);
            assert!(r.is_ok(), "ball {j} after ball {i}, {levels} levels: {r:?}");
            assert_balanced(&m, &masses, total, &format!("ball {j} after {i}"));
        }
    }
}

/// The faces of the tets around a zone end one level coarser per ring: after one call on an
/// unrefined map, the finest tets meeting the ball are at `levels`, and no tet has a face split
/// twice. Checked against an independent count: with the ball inside one Kuhn cube of
/// `kuhn_cube(3)`, every level adds tets (the rings reach out).
#[test]
fn one_call_refines_rings_one_level_coarser_each() {
    let mut m = cube(3);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    let total = masses.total(&m);
    let r = m.refine_around([1.5; 3], 0.0, 3, &mut masses).unwrap();
    assert_balanced(&m, &masses, total, "one call");
    let per_level = r.subdivided_per_level;
    assert!(per_level[1..].iter().all(|&n| n > 0), "{per_level:?}");
    // The finest tets meeting the ball are at level 3.
    for (t, level, _) in m.finest_tets().unwrap() {
        let p = t.map(|v| m.points()[v as usize]);
        if topomech::subdivide::tet_distance([1.5; 3], p) == 0.0 {
            assert_eq!(level, 3, "tet {t:?} meets the ball");
        }
    }
}

/// Random sequences of balls (centres in the cube, radii up to half a cell, levels from the
/// map's maximum to two past it, at most 4), on the plain map and on the coupled one: every call
/// succeeds, leaves the map balanced and the mass where it was.
#[test]
fn random_ball_sequences_stay_refinable() {
    let mut state = 0x264_2026_u64;
    let mut unit = || rng_common::next_unit(&mut state);
    for case in 0..12 {
        let mut m = cube(2);
        let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
        let mut plain = (m.clone(), TetMasses::from_density(&m, 1.0).unwrap());
        let total = mech.masses.total(&m);
        let plain_total = plain.1.total(&plain.0);
        for call in 0..3 {
            let c = [0; 3].map(|_| 2.0 * unit());
            let radius = 0.5 * unit();
            let levels = (m.max_level() + (3.0 * unit()) as u8).clamp(1, 4);
            let r = mech.refine_around(&mut m, c, radius, levels);
            assert!(r.is_ok(), "case {case}, call {call}: {r:?}");
            mech.check(&m).unwrap();
            assert_balanced(
                &m,
                &mech.masses,
                total,
                &format!("coupled case {case}, call {call}, {c:?} r {radius} levels {levels}"),
            );
            let levels = levels.max(plain.0.max_level());
            let r = plain.0.refine_around(c, radius, levels, &mut plain.1);
            assert!(r.is_ok(), "plain case {case}, call {call}: {r:?}");
            assert_balanced(&plain.0, &plain.1, plain_total, &format!("plain case {case}, call {call}"));
        }
    }
}

/// A face refined twice by single operations (no balance) is named by
/// `check_faces_refinable`, and a ball meeting that tet is refused with the map and the masses
/// unchanged.
#[test]
fn a_face_refined_twice_by_hand_is_named_and_refused_cleanly() {
    let mut m = cube(2);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    let d = m.map().darts().next().unwrap();
    let children = m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    // A child with a face on a sewn face of the parent, split again: the neighbour's face twice.
    let outer = children
        .iter()
        .copied()
        .find(|&c| {
            m.map()
                .orbit(c, topomech::AlphaMask::of(&[0, 1, 2]))
                .iter()
                .any(|&x| !m.map().is_free(3, x) && m.mu(m.map().alpha::<3>(x)).tet == 0)
        })
        .expect("a child next to a coarse tet");
    m.subdivide_tet_with_mass(outer, 2, &mut masses).unwrap();
    let e = m.check_faces_refinable().unwrap_err();
    assert!(matches!(e, SubdivideError::FaceRefinedTooFar { .. }), "{e}");
    let before = (format!("{m:?}"), format!("{masses:?}"));
    let e = m.refine_around([1.0; 3], 2.0, 2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::FaceRefinedTooFar { .. }), "{e}");
    assert_eq!((format!("{m:?}"), format!("{masses:?}")), before, "refused, nothing changed");
}

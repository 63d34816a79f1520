//! API probe round 15, subdivision (findings 92–93 of `docs/VERIFICATION.md`): every test states a
//! law that the code before the round broke.
//!
//! - 92: `refine_around` (plain and through `LeveledMechanics`) returned `AlreadyAtLevel` after
//!   splitting part of the zone, although `SubdivideError` promises an unchanged map on error:
//!   after a level skip, a zone tet's unsplit face can carry μf = L from a finer neighbour.
//! - 93: the zone geometry squared unscaled coordinate differences: a point inside a tet of edge
//!   1e110 was 1.4e109 away from it, a unit tet 1e200 away was at distance ∞ (never in any ball).

use std::path::Path;
use std::process::Command;

use topomech::mechanics::Material;
use topomech::subdivide::{tet_distance, LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::{DartId, GMap};

const UNIT: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Two tets A = [0, 1, 2, 3] and B = [1, 2, 3, 4] sharing the face (1, 2, 3).
fn two_tets() -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    LeveledMap::new(map, pts)
}

/// A dart of the live tet whose corners are `corners` (sorted).
fn tet_with(m: &LeveledMap<3>, corners: [u32; 4]) -> DartId {
    m.map().one_dart_per_cell(3).into_iter().find(|&d| m.tet_vertices(d).unwrap() == corners).unwrap()
}

/// A split at level 1 from its dart `a` (0..24: the numbering of the children, hence the order
/// of the zone, depends on it), then B at level 2 (a level skip), with masses: B's level-2
/// children raise μf of the faces they share with A's level-1 children to 2, so those children
/// cannot be split at level 2.
fn skipped_levels(a: u32) -> (LeveledMap<3>, TetMasses) {
    let mut m = two_tets();
    let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    assert_eq!(m.tet_vertices(DartId(a)).unwrap(), [0, 1, 2, 3]);
    m.subdivide_tet_with_mass(DartId(a), 1, &mut masses).unwrap();
    m.subdivide_tet_with_mass(tet_with(&m, [1, 2, 3, 4]), 2, &mut masses).unwrap();
    m.check_all().unwrap();
    (m, masses)
}

/// [`skipped_levels`] through the spring coupling.
fn skipped_levels_coupled(a: u32) -> (LeveledMap<3>, LeveledMechanics) {
    let mut m = two_tets();
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    mech.subdivide_tet(&mut m, DartId(a), 1).unwrap();
    let b = tet_with(&m, [1, 2, 3, 4]);
    mech.subdivide_tet(&mut m, b, 2).unwrap();
    mech.check(&m).unwrap();
    (m, mech)
}

/// Everything a caller can see of a leveled map, as text (it has no `PartialEq`, and a NaN
/// position is equal to itself only so).
fn snapshot(m: &LeveledMap<3>) -> String {
    let counts = (m.map().dart_count(), m.map().capacity(), m.version(), m.max_level(), m.map().count_cells().0);
    format!("{counts:?} {:?}", m.to_parts())
}

/// Finding 92 made `refine_around` all or nothing at a level where some zone tet was refused:
/// here A's level-1 children next to B's level-2 children (a level skip) have unsplit faces of
/// μf = 2 and could not be split at level 2 (`AlreadyAtLevel`). Since round 29 (finding 264) a
/// call on a map above level 0 reads the faces: those children wait one level and are split at
/// level 3, whatever the order of the zone, on both paths; the laws hold after it.
#[test]
fn refine_around_next_to_a_level_skip_defers_to_the_next_level() {
    for (a, per_op) in (0..24).flat_map(|a| [(a, false), (a, true)]) {
        let (mut m, mut masses) = skipped_levels(a);
        assert_eq!(m.map().dart_count(), 384);
        let total = masses.total(&m);
        let r = if per_op {
            m.refine_around_per_op([0.5; 3], 10.0, 2, &mut masses).unwrap()
        } else {
            m.refine_around([0.5; 3], 10.0, 2, &mut masses).unwrap()
        };
        assert_eq!(r.subdivided_per_level, vec![0, 0, 4, 4], "dart {a}, per op {per_op}");
        assert_eq!(m.max_level(), 3);
        m.check_all().unwrap();
        m.check_faces_refinable().unwrap();
        assert!((masses.total(&m) - total).abs() <= 1e-12 * total);
        assert!(m.finest_tets().unwrap().iter().all(|&(_, level, _)| level >= 2), "every tet meets the ball");
    }
}

/// The same through the spring coupling: the springs follow the deferred splits.
#[test]
fn coupled_refine_around_next_to_a_level_skip_defers_to_the_next_level() {
    for a in 0..24 {
        let (mut m, mut mech) = skipped_levels_coupled(a);
        assert_eq!(mech.springs().count(), 41);
        let r = mech.refine_around(&mut m, [0.5; 3], 10.0, 2).unwrap();
        assert_eq!(r.subdivided_per_level, vec![0, 0, 4, 4], "dart {a}");
        mech.check(&m).unwrap();
        m.check_faces_refinable().unwrap();
    }
}

/// Finding 92, one level ahead: the tets already at μt = L when level L starts are looked at by
/// the zone of level L + 1; a corner of one without a finite position is refused before level L
/// splits anything (level 1 split A, then level 2 refused C's children). Since round 29 every
/// tet's corners are read by the ball test of the balanced zone, so a one-level call is refused
/// too, with nothing changed.
#[test]
fn refine_around_checks_the_next_zone_before_the_first_split() {
    let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    let mut pts = UNIT.to_vec();
    pts.extend(UNIT.map(|p| [p[0] + 5.0, p[1], p[2]]));
    let mut m = LeveledMap::new(map, pts);
    let c = tet_with(&m, [4, 5, 6, 7]);
    // C (far from the ball) is put at level 1, then one of its corners made NaN (since round 27
    // a split refuses a NaN end, so the point is put in after it, through the parts).
    m.subdivide_tet(c, 1).unwrap();
    let mut parts = m.to_parts();
    parts.points[7][2] = f64::NAN;
    let mut m = LeveledMap::from_parts(m.map().clone(), parts).unwrap();
    let mut masses = TetMasses { mass: vec![1.0; 16] };
    let (before, masses_before) = (snapshot(&m), masses.clone());
    let e = m.refine_around([0.1; 3], 1.0, 2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::NonFinitePosition { .. }), "{e:?}");
    let darts = (m.map().dart_count(), m.version());
    assert!(snapshot(&m) == before, "(darts, version) {darts:?}");
    assert_eq!(masses, masses_before);
    let e = m.refine_around([0.1; 3], 1.0, 1, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::NonFinitePosition { vertex: 7, .. }), "{e:?}");
    assert!(snapshot(&m) == before);
}

/// Finding 92, the other side: a refused call changes nothing of what follows. On a map above
/// level 0 the call is all or nothing by a copy: with a dart limit one short of what the deferred
/// level 3 needs, the call is refused after level 2 was split, everything is put back, and the
/// next call gives what it gives on a fresh copy.
#[test]
fn refine_around_after_a_refusal_is_refine_around_alone() {
    let (mut fresh, mut fresh_masses) = skipped_levels(6);
    let total = fresh_masses.total(&fresh);
    let expected = fresh.refine_around([0.75; 3], 0.1, 3, &mut fresh_masses).unwrap();
    assert!(expected.subdivided_per_level[3] >= 1, "{expected:?}");
    fresh.check_all().unwrap();
    assert!((fresh_masses.total(&fresh) - total).abs() < 1e-12 * total);

    let (mut m, mut masses) = skipped_levels(6);
    let darts_needed = {
        let (mut probe, mut probe_masses) = (m.clone(), masses.clone());
        probe.refine_around([0.5; 3], 10.0, 2, &mut probe_masses).unwrap();
        probe.map().dart_count()
    };
    m.set_max_darts(darts_needed - 1);
    let (before, masses_before) = (snapshot(&m), masses.clone());
    let e = m.refine_around([0.5; 3], 10.0, 2, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::DartLimit { level: 3, .. }), "{e:?}");
    assert!(snapshot(&m) == before);
    assert_eq!(masses, masses_before);
    m.set_max_darts(fresh.max_darts());
    let r = m.refine_around([0.75; 3], 0.1, 3, &mut masses).unwrap();
    assert_eq!(r, expected);
    assert_eq!(
        (m.map().dart_count(), m.map().count_cells().0),
        (fresh.map().dart_count(), fresh.map().count_cells().0)
    );
}

/// Finding 93: a point strictly inside a tet of edge 1e110 is at distance 0 (it was 1.4e109), and so
/// is one inside a tet of edge 1e-200 and one inside a tet whose coordinates span past `f64::MAX`;
/// distances outside them are exact where the scaled computation is.
#[test]
fn tet_distance_is_zero_inside_a_huge_or_tiny_tet() {
    let big = UNIT.map(|p| p.map(|c| c * 1e110));
    assert_eq!(tet_distance([1e109; 3], big), 0.0);
    assert_eq!(tet_distance([-1e110, 0.0, 0.0], big), 1e110);
    let tiny = UNIT.map(|p| p.map(|c| c * 1e-200));
    assert_eq!(tet_distance([1e-201; 3], tiny), 0.0);
    assert_eq!(tet_distance([0.0, 0.0, -3e-200], tiny), 3e-200);
    let wide = [[-f64::MAX, -1.0, -1.0], [f64::MAX, -1.0, -1.0], [0.0, f64::MAX, -1.0], [0.0, 0.0, f64::MAX]];
    assert_eq!(tet_distance([0.0; 3], wide), 0.0);
    assert_eq!(tet_distance([0.0, 0.0, -f64::MAX], wide), f64::MAX - 1.0);
}

/// Finding 93: a unit tet 1e200 away is at a finite distance, so a ball of radius 2e200 meets it
/// and `refine_around` refines it (it refined nothing), plain, coupled and through the CLI.
#[test]
fn a_far_away_ball_meets_a_small_tet() {
    let center = [1e200, 3e199, -2e199];
    let d = tet_distance(center, UNIT);
    assert!(d.is_finite() && (d / 1e200 - (1.0f64 + 0.09 + 0.04).sqrt()).abs() < 1e-12, "{d}");

    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, UNIT.to_vec());
    let dart = m.map().darts().next().unwrap();
    assert!(m.tet_in_ball(dart, center, 2e200).unwrap());
    assert!(!m.tet_in_ball(dart, center, 1e200).unwrap());
    let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    let mut per_op = m.clone();
    let r = m.refine_around(center, 2e200, 1, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 1]);
    let mut masses = TetMasses::from_density(&per_op, 6.0).unwrap();
    let r = per_op.refine_around_per_op(center, 2e200, 2, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 1, 8]);

    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, UNIT.to_vec());
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    let r = mech.refine_around(&mut m, center, 2e200, 1).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 1]);

    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/liver_547_v22.msh");
    let out = Command::new(env!("CARGO_BIN_EXE_topomech"))
        .args(["refine", mesh.to_str().unwrap(), "--around", "1e200,0,0", "--radius", "2e200", "--levels", "1"])
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json = String::from_utf8_lossy(&out.stdout);
    assert!(json.contains("\"subdivided_per_level\":[0,1852]"), "{json}"); // every tet (it was [0,0])
}

/// Finding 93, ordinary sizes: the exact distances of the plain computation are kept (no
/// translation or scaling below 2²⁵⁰, so the same bits).
#[test]
fn ordinary_tet_distances_keep_their_exact_values() {
    assert_eq!(tet_distance([2.0, 0.0, 0.0], UNIT), 1.0);
    assert_eq!(tet_distance([0.0, 0.0, -3.0], UNIT), 3.0);
    assert_eq!(tet_distance([-3.0, -4.0, 0.5], UNIT), 5.0);
    assert_eq!(tet_distance([0.1, 0.1, 0.1], UNIT), 0.0);
    assert_eq!(tet_distance([0.25, 0.25, -0.5], UNIT), 0.5);
    let shifted = UNIT.map(|p| [p[0] + 1e6, p[1], p[2]]);
    assert_eq!(tet_distance([1e6 - 2.0, 0.0, 0.0], shifted), 2.0);
    assert!(tet_distance([f64::NAN, 0.0, 0.0], UNIT).is_nan());
    assert!(tet_distance([0.0; 3], [UNIT[0], UNIT[1], UNIT[2], [f64::NAN; 3]]).is_nan());
}

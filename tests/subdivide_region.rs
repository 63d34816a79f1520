//! Refinement driven by a ball (`LeveledMap::refine_around`, issue 5) and the `topomech refine`
//! command. Laws checked after every refinement:
//! - every law of the leveled map (`check_all`: finest map valid, μt ≤ μf ≤ μa, every level valid);
//! - zone law: every tet of the finest map that meets the ball has μt = L (a tet meeting it at a
//!   lower level would have been refined at the next level); tets far from the ball keep μt = 0;
//! - mass laws: Σ tet masses unchanged; Σ vertex masses = Σ tet masses; every tet's mass equals
//!   ρ · its volume (children share the parent's mass by volume and midpoint subdivision divides
//!   volume exactly);
//! - the laws of every leveled map (`check_levels`: level k is the finest map, B_{i−1} ⊂ B_i, the
//!   Euler characteristic of every extracted level equals that of level 0).

use std::process::Command;

use proptest::prelude::*;
use topomech::mechanics::Material;
use topomech::subdivide::{tet_distance, CouplingError, LeveledMap, LeveledMechanics, SubdivideError, TetMasses};
use topomech::GMap;

mod subdivide_common;
use subdivide_common::{check_levels, cube};

const RHO: f64 = 3.0;

fn check_laws(m: &LeveledMap<3>, masses: &TetMasses, center: [f64; 3], radius: f64, levels: u8, mass0: f64) {
    check_levels(m);
    let map = m.map();
    for d in map.one_dart_per_cell(3) {
        let corners = m.tet_vertices(d).unwrap().map(|v| m.points()[v as usize]);
        let dist = tet_distance(center, corners);
        let mu = m.mu(d).tet;
        if dist <= radius {
            assert_eq!(mu, levels, "a tet meeting the ball (distance {dist}) stayed at level {mu}");
        }
        let expected = RHO * m.tet_volume(d).unwrap().abs();
        let got = masses.mass[map.cell_id(3, d).index()];
        assert!((got - expected).abs() <= 1e-12 * mass0, "tet of {d}: mass {got}, ρ·V = {expected}");
    }
    let total = masses.total(m);
    assert!((total - mass0).abs() <= 1e-12 * mass0, "Σ tet mass {total} ≠ {mass0}");
    let vertex_total: f64 = masses.vertex_masses(m).unwrap().iter().sum();
    assert!((vertex_total - total).abs() <= 1e-12 * mass0, "Σ vertex mass {vertex_total} ≠ {total}");
}

#[test]
fn one_tet_to_level_two_has_64_tets_and_keeps_its_mass() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let mut m = LeveledMap::new(map, vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]);
    let mut masses = TetMasses::from_density(&m, RHO).unwrap();
    let mass0 = masses.total(&m);
    assert!((mass0 - RHO * 8.0 / 6.0).abs() < 1e-12);
    let r = m.refine_around([0.5, 0.5, 0.5], 10.0, 2, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 1, 8]);
    let per_level: Vec<usize> = (0..=2).map(|i| m.level(i).unwrap().map.count_cells().0[3]).collect();
    assert_eq!(per_level, vec![1, 8, 64]);
    check_laws(&m, &masses, [0.5, 0.5, 0.5], 10.0, 2, mass0);
}

#[test]
fn a_corner_zone_of_a_cube_refines_only_near_the_corner() {
    let mut m = cube(3);
    let mut masses = TetMasses::from_density(&m, RHO).unwrap();
    let mass0 = masses.total(&m);
    // kuhn_cube(3) spans [0, 3]³ in unit cells.
    let (center, radius) = ([0.0, 0.0, 0.0], 0.2);
    let r = m.refine_around(center, radius, 3, &mut masses).unwrap();
    assert!(r.subdivided_per_level[1] > 0 && r.subdivided_per_level[3] > 0, "{r:?}");
    check_laws(&m, &masses, center, radius, 3, mass0);
    // The opposite corner is far away: its tets are untouched.
    let far = m.map().one_dart_per_cell(3).into_iter().filter(|&d| {
        let c = m.tet_vertices(d).unwrap().map(|v| m.points()[v as usize]);
        tet_distance([3.0, 3.0, 3.0], c) == 0.0
    });
    for d in far {
        assert_eq!(m.mu(d).tet, 0);
    }
}

#[test]
fn refinement_continues_from_the_current_level_and_refuses_going_back() {
    let mut m = cube(2);
    let mut masses = TetMasses::from_density(&m, RHO).unwrap();
    let mass0 = masses.total(&m);
    m.refine_around([1.0, 1.0, 1.0], 0.2, 2, &mut masses).unwrap();
    // A second zone at the same top level: only level-1 tets there can be refined at level 2.
    m.refine_around([0.8, 0.8, 0.8], 0.5, 2, &mut masses).unwrap();
    m.check_all().unwrap();
    assert!((masses.total(&m) - mass0).abs() <= 1e-12 * mass0);
    let before = m.map().dart_count();
    let err = m.refine_around([0.5, 0.5, 0.5], 1.0, 1, &mut masses).unwrap_err();
    assert!(matches!(err, SubdivideError::LevelBelowMax { level: 1, max_level: 2 }), "{err:?}");
    assert_eq!(m.map().dart_count(), before, "a refused refinement changes nothing");
    let err = m.refine_around([0.5, 0.5, 0.5], 1.0, 251, &mut masses).unwrap_err();
    assert!(matches!(err, SubdivideError::LevelTooHigh(251)), "{err:?}");
    // A ball no tet can be compared with: refused, not an empty refinement.
    for (center, radius) in
        [([f64::NAN, 0.5, 0.5], 1.0), ([0.5; 3], f64::NAN), ([0.5; 3], -0.1), ([0.5; 3], f64::INFINITY)]
    {
        let err = m.refine_around(center, radius, 3, &mut masses).unwrap_err();
        assert!(matches!(err, SubdivideError::BadBall { .. }), "{center:?} {radius}: {err:?}");
        let err = m.refine_around_per_op(center, radius, 3, &mut masses).unwrap_err();
        assert!(matches!(err, SubdivideError::BadBall { .. }), "{center:?} {radius}: {err:?}");
    }
    assert_eq!((m.map().dart_count(), m.max_level()), (before, 2), "a refused refinement changes nothing");
}

/// The dart limit refuses a level before it starts, on the bulk path (the ball holds the whole
/// cube), on the per-op path (a corner zone), through the spring coupling and for 2D uniform
/// refinement; the levels done before are kept and valid, and a limit just large enough lets
/// the same refinement through.
#[test]
fn the_dart_limit_refuses_a_level_before_it_starts_and_keeps_the_levels_before() {
    let refused = |e: &SubdivideError, level: u8| match *e {
        SubdivideError::DartLimit { level: l, darts, estimate, limit, .. } => {
            l == level && estimate > limit && darts <= limit
        }
        _ => false,
    };
    // Bulk: the Kuhn cube k = 1 (6 tets, 144 darts) to level 2 = 384 tets, 9 216 darts.
    for (limit, done) in [(1_000, 0u8), (9_215, 1), (9_216, 2)] {
        let mut m = cube(1);
        let mut masses = TetMasses::from_density(&m, RHO).unwrap();
        let mass0 = masses.total(&m);
        m.set_max_darts(limit);
        match m.refine_around([0.5; 3], 10.0, 2, &mut masses) {
            Ok(_) => assert_eq!(done, 2, "limit {limit} accepted level 2"),
            Err(e) => assert!(refused(&e, done + 1), "limit {limit}: {e:?}"),
        }
        assert_eq!(m.max_level(), done, "limit {limit}");
        assert_eq!(m.map().dart_count(), 144 * 8usize.pow(u32::from(done)), "limit {limit}");
        check_laws(&m, &masses, [0.5; 3], if done == 0 { -1.0 } else { 10.0 }, done, mass0);
    }
    // Per op: a corner zone of the cube k = 2, estimated per tet of the zone.
    let mut m = cube(2);
    let mut masses = TetMasses::from_density(&m, RHO).unwrap();
    m.set_max_darts(m.map().dart_count() + 10);
    let before = m.map().dart_count();
    let e = m.refine_around([0.0; 3], 0.3, 1, &mut masses).unwrap_err();
    assert!(refused(&e, 1), "{e:?}");
    assert!(e.to_string().contains("--max-darts"), "{e}");
    assert_eq!((m.max_level(), m.map().dart_count()), (0, before));
    let e = m.refine_around_per_op([0.0; 3], 10.0, 1, &mut masses).unwrap_err();
    assert!(refused(&e, 1), "{e:?}");
    m.set_max_darts(usize::MAX);
    m.refine_around([0.0; 3], 0.3, 1, &mut masses).unwrap();
    // The spring coupling's own zone loop.
    let mut m = cube(2);
    let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    m.set_max_darts(m.map().dart_count() + 10);
    let e = mech.refine_around(&mut m, [0.0; 3], 0.3, 1).unwrap_err();
    assert!(matches!(&e, CouplingError::Subdivide(s) if refused(s, 1)), "{e:?}");
    assert_eq!(m.max_level(), 0);
    // 2D uniform refinement: every triangle becomes four.
    let (map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    let mut m2 = LeveledMap::new(map, vec![]);
    m2.set_max_darts(12 * 4 - 1);
    let e = m2.refine_uniform(1).unwrap_err();
    assert!(refused(&e, 1), "{e:?}");
    m2.set_max_darts(12 * 4);
    assert_eq!(m2.refine_uniform(1).unwrap(), 2);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    #[test]
    fn random_zones_keep_every_law(
        k in 1usize..=2,
        c in prop::array::uniform3(-0.5f64..2.5),
        radius in 0.0f64..1.0,
        levels in 1u8..=2,
    ) {
        let mut m = cube(k);
        let mut masses = TetMasses::from_density(&m, RHO).unwrap();
        let mass0 = masses.total(&m);
        m.refine_around(c, radius, levels, &mut masses).unwrap();
        check_laws(&m, &masses, c, radius, levels, mass0);
    }
}

const BIN: &str = env!("CARGO_BIN_EXE_topomech");

fn liver() -> String {
    format!("{}/data/liver_547_v22.msh", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_refine_command_reports_the_documented_json() {
    let out = Command::new(BIN)
        .args(["refine", &liver(), "--around", "-2.2,3.2,0.6", "--radius", "0.4", "--levels", "2", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "volumes",
        "darts",
        "tets_per_level",
        "valid",
        "mu_order_ok",
        "levels_valid",
        "total_mass_before",
        "total_mass_after",
        "refine_ms",
    ] {
        assert!(v.get(key).is_some(), "missing key {key} in {v}");
    }
    let per_level: Vec<u64> = v["tets_per_level"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect();
    assert_eq!(per_level.len(), 3);
    assert_eq!(per_level[0], 1852);
    assert!(per_level[0] < per_level[1] && per_level[1] < per_level[2], "{per_level:?}");
    assert_eq!(v["volumes"].as_u64().unwrap(), per_level[2]);
    assert!(
        v["valid"].as_bool().unwrap() && v["mu_order_ok"].as_bool().unwrap() && v["levels_valid"].as_bool().unwrap()
    );
    let (a, b) = (v["total_mass_before"].as_f64().unwrap(), v["total_mass_after"].as_f64().unwrap());
    assert!((a - b).abs() <= 1e-12 * a, "{a} vs {b}");
}

#[test]
fn the_refine_command_rejects_bad_arguments_with_a_message() {
    for (args, needle) in [
        (vec!["--around", "0,0,0", "--radius", "-1"], "--radius"),
        (vec!["--around", "0,0,0", "--radius", "NaN"], "--radius"),
        (vec!["--around", "0,nan,0", "--radius", "1"], "not finite"),
        (vec!["--around", "0,0", "--radius", "1"], "X,Y,Z"),
    ] {
        let liver = liver();
        let mut all = vec!["refine", liver.as_str()];
        all.extend(args.iter().copied());
        let out = Command::new(BIN).args(&all).output().unwrap();
        assert!(!out.status.success(), "{all:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{all:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A ball holding the whole liver to level 12 (1 852 · 8¹² tets; the default limit stops it at
    // level 4, 182 M darts, after three levels: here a lower limit stops it at level 2, 2.8 M)
    // is refused before that level starts, with the limit named; it used to allocate until the
    // machine ran out of memory.
    for (levels, limit, needle) in [("12", "1000000", "level 2"), ("1", "1000", "level 1")] {
        let liver = liver();
        let all = [
            "refine",
            liver.as_str(),
            "--around",
            "0,0,0",
            "--radius",
            "1e9",
            "--levels",
            levels,
            "--max-darts",
            limit,
        ];
        let out = Command::new(BIN).args(all).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{all:?}: {err}");
        assert!(err.contains(needle) && err.contains("--max-darts"), "{all:?}: {err}");
    }
    let out =
        Command::new(BIN).args(["refine", "/no/such.msh", "--around", "0,0,0", "--radius", "1"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/no/such.msh"));
}

/// Finding 30 (docs/VERIFICATION.md): masses without an entry for some live volume (made for a
/// smaller map, or missing the volumes of a plain `subdivide_tet`) were taken as 0: a
/// refinement of the cube with the masses of one tet reported equal totals before and after
/// while five of its six tets weighed nothing, and a NaN mass was shared as NaN. Each
/// operation that shares masses now refuses them before any change.
#[test]
fn masses_that_miss_a_volume_or_are_not_finite_are_refused_before_any_change() {
    use topomech::generate::kuhn_cube;
    let leveled = |points: Vec<[f64; 3]>, tets: &[[u32; 4]]| {
        let (map, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
        LeveledMap::new(map, points)
    };
    let one = leveled(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], &[[0, 1, 2, 3]]);
    let (points, tets) = kuhn_cube(1);
    let cube = leveled(points, &tets);
    let small = TetMasses::from_density(&one, 1.0).unwrap();
    let no_mass = Err(SubdivideError::NoMass { volume: 1, masses: 1 });
    let last = cube.map().darts().last().unwrap(); // a dart of the last volume
    let unchanged = |m: &LeveledMap<3>, masses: &TetMasses| {
        assert_eq!((m.map().dart_count(), m.max_level()), (144, 0));
        assert_eq!(masses, &small);
    };
    let (mut m, mut masses) = (cube.clone(), small.clone());
    assert_eq!(m.subdivide_tet_with_mass(last, 1, &mut masses).map(|_| ()), no_mass);
    unchanged(&m, &masses);
    assert_eq!(m.refine_uniform(1, &mut masses).map(|_| ()), no_mass);
    unchanged(&m, &masses);
    assert_eq!(m.refine_around([0.5; 3], 2.0, 1, &mut masses).map(|_| ()), no_mass);
    unchanged(&m, &masses);
    assert_eq!(m.refine_around_per_op([0.5; 3], 2.0, 1, &mut masses).map(|_| ()), no_mass);
    unchanged(&m, &masses);
    assert_eq!(masses.vertex_masses(&m).map(|_| ()), no_mass);

    // Volumes made by an operation without masses have none to share.
    let mut full = TetMasses::from_density(&m, 1.0).unwrap();
    let first = m.map().darts().next().unwrap();
    let children = m.subdivide_tet(first, 1).unwrap();
    let e = m.subdivide_tet_with_mass(last, 1, &mut full).unwrap_err();
    let SubdivideError::NoMass { volume, masses: 6 } = e else { panic!("{e:?}") };
    assert!(volume >= 6 && children.iter().any(|&c| m.map().cell_id(3, c).0 == volume), "{volume}");

    // A non-finite or negative mass.
    let (mut m, mut masses) = (cube.clone(), TetMasses::from_density(&cube, 1.0).unwrap());
    let t = m.map().cell_id(3, last);
    masses.mass[t.index()] = f64::NAN;
    let e = m.subdivide_tet_with_mass(last, 1, &mut masses).unwrap_err();
    assert!(matches!(e, SubdivideError::BadMass { volume, .. } if volume == t.0), "{e:?}");
    masses.mass[t.index()] = -1.0;
    assert!(matches!(m.refine_uniform(1, &mut masses), Err(SubdivideError::BadMass { mass, .. }) if mass == -1.0));
    assert_eq!(m.map().dart_count(), 144);

    // Masses that cover the map still refine and conserve.
    let mut masses = TetMasses::from_density(&cube, 1.0).unwrap();
    let mut m = cube.clone();
    let r = m.refine_around([0.5; 3], 2.0, 1, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level, vec![0, 6]);
    assert!((r.total_mass_after - 1.0).abs() < 1e-12 && (r.total_mass_before - 1.0).abs() < 1e-12);
}

/// A flat tet (four coplanar corners, zero volume) still shares its mass: with no volume to
/// share by, each of the eight children gets an equal part, and the parts sum to the parent's
/// (not 0/0 = NaN shares).
#[test]
fn a_flat_tet_shares_its_mass_equally_among_its_children() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let flat = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let mut m = LeveledMap::new(map, flat);
    let mut masses = TetMasses { mass: vec![2.0] };
    let d = m.map().darts().next().unwrap();
    let children = m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    assert_eq!(children.len(), 8);
    for &c in &children {
        let share = masses.mass[m.map().cell_id(3, c).index()];
        assert_eq!(share, 0.25, "child {c:?}");
    }
}

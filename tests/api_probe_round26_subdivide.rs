//! Round 26 (a): the momentum correction with non-finite or huge velocities, the coupled
//! catch-up's dart count, `BelowPrecision` on an axis tie, a level that adds nothing under a
//! lowered dart limit.

use topomech::mechanics::{Material, Vec3};
use topomech::subdivide::{LeveledMap, LeveledMechanics, TetMasses};
use topomech::DartId;

mod subdivide_common;
use subdivide_common::{cube, jitter, tet_mesh};

fn material() -> Material {
    Material { density: 2.0, young: 500.0, damping: 0.01, viscosity: 0.0 }
}

fn edge_dart(m: &LeveledMap<3>, a: u32, b: u32) -> DartId {
    let map = m.map();
    map.darts().find(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha_dyn(0, d)).0 == b).unwrap()
}

/// Σ_v m_v u_v per component, each over the vertices whose velocity component is finite.
fn momentum(m: &LeveledMap<3>, mech: &LeveledMechanics) -> Vec3 {
    let mass = mech.vertex_masses(m).unwrap();
    [0, 1, 2].map(|k| mass.iter().zip(&mech.velocity).map(|(&mv, u)| mv * u[k]).sum())
}

/// One tet, random velocities, an edge split, the midpoint given another velocity, `poison`
/// applied, then a second split in the same tet (which moves mass: E ≠ 0). Returns the momentum
/// before and after the second split.
fn split_twice(poison: impl Fn(&mut LeveledMechanics)) -> (Vec3, Vec3) {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.1], [0.1, 0.3, 1.0]];
    let mut m = tet_mesh(points, &[[0, 1, 2, 3]]);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    for (v, u) in mech.velocity.iter_mut().enumerate() {
        *u = jitter(77 + v as u64);
    }
    let d = edge_dart(&m, 0, 1);
    let mid = mech.split_edge(&mut m, d, 1).unwrap();
    mech.velocity[m.map().vertex_id(mid).index()] = [5.0, 5.0, 5.0];
    poison(&mut mech);
    let before = momentum(&m, &mech);
    let d = edge_dart(&m, 0, 2);
    mech.split_edge(&mut m, d, 1).unwrap();
    (before, momentum(&m, &mech))
}

/// A NaN in one vertex's x velocity leaves x uncorrected but y and z are kept (the whole
/// correction was dropped: Σ m v_y −0.0340 → −0.0475).
#[test]
fn a_nan_velocity_component_does_not_stop_the_others_correction() {
    let (before, after) = split_twice(|mech| mech.velocity[0][0] = f64::NAN);
    for k in [1, 2] {
        assert!((after[k] - before[k]).abs() <= 1e-14, "component {k}: {} -> {}", before[k], after[k]);
    }
    let (before, after) = split_twice(|_| {});
    assert!((0..3).all(|k| (after[k] - before[k]).abs() <= 1e-14), "{before:?} -> {after:?}");
}

/// Finite velocities of ±1.5e308, whose differences overflow, are corrected all the same (the
/// correction was skipped: Σ m v_x −1.19e306 → −0.99e306).
#[test]
fn huge_finite_velocities_are_corrected() {
    let (before, after) = split_twice(|mech| {
        mech.velocity[0][0] = 1.5e308;
        mech.velocity[2][0] = -1.5e308;
    });
    assert!(before.iter().all(|x| x.is_finite()));
    assert!((after[0] - before[0]).abs() <= 1e-12 * before[0].abs(), "{:e} -> {:e}", before[0], after[0]);
}

/// The coupled catch-up counts darts exactly: a call that ends at exactly the limit is accepted,
/// as the plain refinement accepts it (it was refused with the old estimate, "about 5856" for
/// 4 752), and one dart less is refused with the map and coupling unchanged.
#[test]
fn the_coupled_catch_up_accepts_a_call_that_ends_at_the_limit() {
    let m0 = cube(2);
    let mut mech = LeveledMechanics::new(&m0, material()).unwrap();
    let mut m = m0.clone();
    mech.refine_around(&mut m, [0.05; 3], 0.01, 2).unwrap();
    let (c, r) = ([1.9; 3], 0.05);
    let (mut plain, mut masses) = (m.clone(), mech.masses.clone());
    plain.refine_around(c, r, 2, &mut masses).unwrap();
    let fits = plain.map().dart_count();
    let (mut under, mut under_mech) = (m.clone(), mech.clone());
    under.set_max_darts(fits - 1);
    assert!(under_mech.refine_around(&mut under, c, r, 2).is_err());
    assert_eq!(under.map().dart_count(), m.map().dart_count());
    m.set_max_darts(fits);
    mech.refine_around(&mut m, c, r, 2).unwrap();
    assert_eq!(m.map().dart_count(), fits);
    assert_eq!(mech.check(&m), Ok(()));
}

/// An edge and its mirror image in x ↔ y are split alike: (1, 0, 0)–(1 + ε, ε, 0) has its
/// midpoint strictly between its ends in y, and is split (it was refused, its mirror accepted).
#[test]
fn below_precision_does_not_depend_on_the_order_of_the_axes() {
    let u = f64::EPSILON;
    let split = |a: [f64; 3], b: [f64; 3]| {
        let mut m = tet_mesh(vec![a, b, [0.5, 0.5, 1.0], [0.5, -0.5, -1.0]], &[[0, 1, 2, 3]]);
        let d = edge_dart(&m, 0, 1);
        m.split_edge(d, 1).is_ok()
    };
    assert!(split([1.0, 0.0, 0.0], [1.0 + u, u, 0.0]));
    assert!(split([0.0, 1.0, 0.0], [u, 1.0 + u, 0.0]));
    assert!(!split([1.0, 0.0, 0.0], [1.0 + u, 0.0, 0.0]), "one ulp along its only axis: refused");
}

/// A refinement whose zone is empty adds no dart and is accepted under a limit lowered below
/// the map's size (it was refused "from 144 to about 144 darts").
#[test]
fn a_level_that_adds_nothing_is_not_refused_by_the_limit() {
    let mut m = cube(1);
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    m.set_max_darts(10);
    let r = m.refine_around([100.0; 3], 0.0, 1, &mut masses).unwrap();
    assert_eq!(r.subdivided_per_level.iter().sum::<usize>(), 0);
    assert!(m.refine_around([0.5; 3], 0.1, 1, &mut masses).is_err(), "a level that adds darts still is");
}

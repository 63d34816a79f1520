//! Findings 52–59 of the tenth API probing round (docs/VERIFICATION.md, "Findings"): the
//! kernel's queries past the dimension, the combinatorial-map export, the pins, velocities and
//! force accumulator of a running simulation, and masses too small for f64. Each test fails on
//! the code before its fix.

use std::panic::catch_unwind;
use topomech::cut::dissociate_face;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{
    forces_by_coverage, Body, Integrator, Material, ModelError, Projection, Simulation, SpringSystem, StepConfig,
    SystemError,
};
use topomech::{AlphaMask, CellId, DartId, GMap};

fn cube_body(k: usize) -> (Vec<[f64; 3]>, Body) {
    let (points, tets) = kuhn_cube(k);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    (points, body)
}

fn config(integrator: Integrator) -> StepConfig {
    StepConfig::new(integrator, 1e-3)
}

/// Finding 52: an edge 2-sewn (or 3-sewn) onto its own reverse is a lawful G-map, but its
/// β2 = α0α2 would fix a dart: the export answers `None` instead of an invalid combinatorial map,
/// and every map it does export passes `is_valid`.
#[test]
fn a_folded_edge_has_no_combinatorial_map() {
    let (mut m, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    let whole = m.to_combinatorial_map().unwrap();
    assert!(whole.is_valid());
    let a = DartId(0);
    m.sew_dyn(2, a, m.alpha::<0>(a)).unwrap();
    m.validate().unwrap();
    assert!(m.to_combinatorial_map().is_none());
    let (points, tets) = kuhn_cube(2);
    let (cube, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let sewn = cube.to_combinatorial_map().expect("a Kuhn cube is orientable, with no fold");
    assert!(sewn.is_valid() && sewn.beta[0].iter().all(Option::is_some)); // β2 everywhere
    let (mut t, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    t.sew_dyn(3, a, t.alpha::<0>(a)).unwrap();
    t.validate().unwrap();
    assert!(t.to_combinatorial_map().is_none());
}

/// Finding 53: the kernel's per-index queries answer for i > n (no cells, no pairs) instead of
/// panicking, and the traversal oracle agrees with the id version there.
#[test]
fn queries_past_the_dimension_find_nothing() {
    let (m, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    for i in [3, 4, 8, 9, 64] {
        assert_eq!(m.sewn_pairs(i).count(), 0, "sewn_pairs({i})");
        assert_eq!(m.one_dart_per_cell(i), Vec::<DartId>::new(), "one_dart_per_cell({i})");
        assert_eq!(m.one_dart_per_cell_by_traversal(i), Vec::<DartId>::new(), "by traversal ({i})");
    }
    for i in 0..=2 {
        assert_eq!(m.one_dart_per_cell(i), m.one_dart_per_cell_by_traversal(i), "i = {i}");
    }
}

/// Finding 54: an `AlphaMask` holds α0..=α7. Queries past 7 answer (not contained; a cell mask
/// removes nothing), and a constructor given α8 or more panics in every build instead of
/// wrapping α9 onto α1 in release builds.
#[test]
fn alpha_masks_never_wrap_an_index_past_seven() {
    let nine = std::hint::black_box(9usize);
    assert!(!AlphaMask::all(7).contains(8) && !AlphaMask::of(&[0]).contains(nine));
    assert_eq!(AlphaMask::cell(2, nine), AlphaMask::all(2));
    assert_eq!(AlphaMask::cell(3, 8), AlphaMask::all(3));
    assert!(catch_unwind(|| AlphaMask::of(&[nine])).is_err());
    assert!(catch_unwind(|| AlphaMask::all(nine)).is_err());
    assert!(catch_unwind(|| AlphaMask::commuting_with(nine, 0)).is_err());
    assert_eq!(AlphaMask::all(7).0, 0xFF);
}

/// Finding 55 (a): a vertex pinned after the simulation was built is held from the next step
/// on, and one unpinned is freed; the projection is not current until a step (or `update`)
/// takes the pins up.
#[test]
fn pins_written_after_the_simulation_was_built_take_effect() {
    let (points, mut body) = cube_body(1);
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config(Integrator::Symplectic)).unwrap();
    body.attrs_mut().pinned_mut()[CellId(7)] = true;
    assert!(!sim.projection.is_current(&body));
    for _ in 0..10 {
        sim.step(&mut body).unwrap();
    }
    assert!(sim.projection.is_current(&body));
    assert_eq!(body.attrs().position()[CellId(7)], points[7], "a pinned vertex moved");
    assert!(body.attrs().position()[CellId(6)][2] < points[6][2], "a free vertex did not fall");
    body.attrs_mut().pin_where(|_, _| false);
    sim.step(&mut body).unwrap();
    assert!(body.attrs().position()[CellId(7)][2] < points[7][2], "an unpinned vertex stayed");
    let fresh = Projection::build(&body, [0.0, 0.0, -9.81]).unwrap();
    assert!(sim.projection.equivalent(&fresh).is_ok());
}

/// Finding 55 (b): a pinned vertex given a velocity does not move, with every integrator.
#[test]
fn a_pinned_vertex_given_a_velocity_stays() {
    for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
        let (points, mut body) = cube_body(1);
        body.attrs_mut().pinned_mut()[CellId(0)] = true;
        let mut sim = Simulation::new(&mut body, [0.0; 3], config(integrator)).unwrap();
        body.attrs_mut().velocity_mut()[CellId(0)] = [1.0, 0.0, 0.0];
        body.attrs_mut().velocity_mut()[CellId(1)] = [1.0, 0.0, 0.0];
        sim.step(&mut body).unwrap();
        assert_eq!(body.attrs().position()[CellId(0)], points[0], "{integrator:?}: the pinned vertex moved");
        assert_eq!(body.attrs().velocity()[CellId(0)], [0.0; 3], "{integrator:?}");
        assert!(body.attrs().position()[CellId(1)][0] > points[1][0], "{integrator:?}: the free vertex stayed");
    }
}

/// Finding 55 (c): the incremental update after a pin change and a cut equals a fresh build.
#[test]
fn the_incremental_update_takes_up_pin_changes() {
    let (_, mut body) = cube_body(2);
    let mut sim = Simulation::new(&mut body, [0.0; 3], config(Integrator::Euler)).unwrap();
    body.attrs_mut().pin_where(|_, r| r[2] == 0.0);
    let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    let cut = dissociate_face(&mut body, d).unwrap();
    sim.update(&mut body, &cut.touched).unwrap();
    let fresh = Projection::build(&body, [0.0; 3]).unwrap();
    assert_eq!(sim.projection.equivalent(&fresh), Ok(()));
    assert!(sim.projection.is_current(&body));
}

/// Finding 56: the force accumulator holds the forces of the last evaluation once
/// `write_forces` is called: the same, vertex by vertex, as the covering of the map (seed §4.2).
#[test]
fn written_forces_equal_the_forces_by_covering_the_map() {
    let g = [0.0, 0.0, -9.81];
    let (_, mut body) = cube_body(2);
    body.attrs_mut().pin_where(|_, r| r[2] == 0.0);
    let mut sim = Simulation::new(&mut body, g, config(Integrator::Symplectic)).unwrap();
    for _ in 0..20 {
        sim.step(&mut body).unwrap();
    }
    assert!(body.attrs().force().as_slice().iter().all(|f| *f == [0.0; 3]), "the step loop writes no forces");
    sim.write_forces(&mut body).unwrap();
    let oracle = forces_by_coverage(&body, g);
    let written = body.attrs().force().as_slice();
    assert_eq!(written.len(), oracle.len());
    let scale = oracle.iter().flat_map(|f| f.iter()).fold(0.0f64, |m, c| m.max(c.abs()));
    for (v, (w, o)) in written.iter().zip(&oracle).enumerate() {
        for k in 0..3 {
            assert!((w[k] - o[k]).abs() <= 1e-12 * scale, "vertex {v}: {w:?} against {o:?}");
        }
    }
    assert!(written.iter().any(|f| *f != [0.0; 3]));
}

/// Finding 57: a NaN position is reported as NaN, not hidden by the maximum.
#[test]
fn a_nan_position_makes_the_largest_displacement_nan() {
    let (_, mut body) = cube_body(1);
    let sim = Simulation::new(&mut body, [0.0; 3], config(Integrator::Euler)).unwrap();
    assert_eq!(sim.max_displacement(&body), Ok(0.0));
    body.attrs_mut().position_mut()[CellId(5)] = [f64::NAN, 0.0, 1.0];
    assert!(sim.max_displacement(&body).unwrap().is_nan());
}

/// Finding 58: a refused `Simulation::new` leaves the body as it was.
#[test]
fn a_refused_simulation_leaves_the_body_unchanged() {
    let (_, mut body) = cube_body(1);
    body.attrs_mut().pinned_mut()[CellId(0)] = true;
    body.attrs_mut().velocity_mut()[CellId(0)] = [1.0, 2.0, 3.0];
    assert!(Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Rk4, -1.0)).is_err());
    assert!(Simulation::new(&mut body, [f64::NAN; 3], config(Integrator::Rk4)).is_err());
    assert_eq!(body.attrs().velocity()[CellId(0)], [1.0, 2.0, 3.0]);
    Simulation::new(&mut body, [0.0; 3], config(Integrator::Rk4)).unwrap();
    assert_eq!(body.attrs().velocity()[CellId(0)], [0.0; 3], "accepted: the pinned vertex starts still");
}

/// Finding 59: masses too small for f64 (a subnormal mass, whose inverse overflows, or a tet mass
/// that rounds to 0) are refused with the slot or tet named, and every system that a slot
/// constructor accepts passes `check`.
#[test]
fn masses_whose_inverse_overflows_are_refused() {
    let mut sys = SpringSystem::default();
    assert_eq!(sys.push_slot(5e-324, false, 0.0), Err(SystemError::MassTooSmall { slot: 0, mass: 5e-324 }));
    assert_eq!(sys.push_slot(5e-324, true, 0.0), Err(SystemError::MassTooSmall { slot: 0, mass: 5e-324 }));
    assert_eq!(sys.slots(), 0);
    for m in [0.0, 1e-300, 1.0, 1e300] {
        let v = sys.push_slot(m, false, 0.0).unwrap();
        assert!(sys.check().is_ok(), "mass {m}");
        assert!(sys.set_slot(v, 1e-310, false, 0.0).is_err());
    }
    let (points, tets) = kuhn_cube(1);
    for density in [1e-310, 5e-324] {
        let material = Material { density, ..Material::default() };
        let err = Body::from_tets(&points, &tets, material).map(|_| ()).unwrap_err();
        assert!(matches!(err, ModelError::MassTooSmall { tet: 0, .. }), "density {density}: {err}");
    }
    let small = Material { density: 1e-290, ..Material::default() };
    let (mut body, _) = Body::from_tets(&points, &tets, small).unwrap();
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config(Integrator::Symplectic)).unwrap();
    sim.step(&mut body).unwrap();
    assert!(body.attrs().position()[CellId(7)][2] < points[7][2], "a light body still falls");
    assert!(body.total_vertex_mass() > 0.0);
}

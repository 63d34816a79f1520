//! Tearing really happens: a Kuhn cube pulled apart by its pinned, displaced ends has tensed
//! springs; [`cut::tear_step`] splits the most stressed vertices, and the body stays valid and
//! conservative with the incrementally updated projection equal to a fresh one. A body at rest has
//! no tension and tears nothing (the test can fail both ways).

use topomech::cut;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, Integrator, Material, Projection, Simulation, StepConfig, Vec3};

const K: usize = 3;

fn material() -> Material {
    Material { density: 1.0, young: 1000.0, damping: 0.001, viscosity: 0.1 }
}

/// The cube [0, K]³ with both x-ends pinned; the x = K end displaced by `stretch` along x.
fn stretched_cube(stretch: f64) -> (Body, Simulation) {
    let (points, tets) = kuhn_cube(K);
    let (mut body, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let k = K as f64;
    let mut mech = body.attrs_mut();
    mech.pin_where(|_, p| p[0] <= 0.0 || p[0] >= k);
    let rest = mech.rest_position().as_slice().to_vec();
    for (x, r) in mech.position_mut().as_mut_slice().iter_mut().zip(&rest) {
        // Affine stretch: every spring with an x component is tensed.
        x[0] = r[0] * (1.0 + stretch / k);
    }
    let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-4)).unwrap();
    (body, sim)
}

fn total_mass(body: &Body) -> f64 {
    body.total_vertex_mass()
}

fn check(body: &Body, sim: &Simulation, mass: f64) {
    body.map().validate().unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    let m = total_mass(body);
    assert!((m - mass).abs() <= 1e-12 * mass, "mass {m} vs {mass}");
    let fresh = Projection::build(body, [0.0; 3]).unwrap();
    sim.projection.equivalent(&fresh).unwrap();
    assert!(sim.projection.is_current(body));
}

#[test]
fn stretched_cube_tears() {
    let (mut body, mut sim) = stretched_cube(1.5);
    let mass = total_mass(&body);
    let vertices = body.map().count_cells().0[0];
    let stress = cut::principal_stress(&body, &sim).unwrap();
    let max = stress.iter().map(|s| s.magnitude).fold(0.0, f64::max);
    assert!(max > 0.0, "a stretched body must be under tension");
    // The stress of an affine stretch along x points along x.
    let top = stress.iter().max_by(|a, b| a.magnitude.total_cmp(&b.magnitude)).unwrap();
    assert!(top.direction[0].abs() > 0.9, "principal direction {:?}", top.direction);

    let step = cut::tear_step(&mut body, &mut sim, 0.5 * max, 3).unwrap();
    assert!(!step.tears.is_empty(), "no vertex over half the largest stress was torn");
    assert!(step.tears.iter().any(|t| t.split), "no tear split its vertex: {:?}", step.tears);
    for t in &step.tears {
        assert!(!t.fan.is_empty() && t.dissociations.len() <= t.fan.len());
    }
    assert!(body.map().count_cells().0[0] > vertices, "vertex count did not grow");
    check(&body, &sim, mass);

    // The simulation keeps running on the torn body, and tearing can go on inside the loop.
    for _ in 0..20 {
        sim.step(&mut body).unwrap();
        cut::tear_step(&mut body, &mut sim, 0.5 * max, 2).unwrap();
    }
    check(&body, &sim, mass);
}

#[test]
fn body_at_rest_does_not_tear() {
    let (mut body, mut sim) = stretched_cube(0.0);
    let stress = cut::principal_stress(&body, &sim).unwrap();
    assert!(stress.iter().all(|s| s.magnitude == 0.0), "a body at rest has no tension");
    let version = body.version();
    let step = cut::tear_step(&mut body, &mut sim, 0.0, 10).unwrap();
    assert!(step.tears.is_empty());
    assert_eq!(version, body.version());
}

/// Tearing one interior vertex by hand along x splits it: the vertex count grows and the fan's
/// dissociations name it.
#[test]
fn tear_vertex_splits_an_interior_vertex() {
    let (mut body, _) = stretched_cube(0.0);
    let mass = total_mass(&body);
    // Point (1, 1, 1) of the 4×4×4 grid has index 1 + 4 + 16.
    let v = topomech::CellId(21);
    let before = body.map().count_cells().0[0];
    let tear = cut::tear_vertex(&mut body, v, [1.0, 0.0, 0.0] as Vec3, None).unwrap();
    assert!(tear.split, "fan of {} faces did not split vertex {v}", tear.fan.len());
    assert!(body.map().count_cells().0[0] > before);
    body.map().validate().unwrap();
    check_conservation(body.map(), body.attrs()).unwrap();
    assert!((total_mass(&body) - mass).abs() <= 1e-12 * mass);
}

/// A tear direction that is NaN, infinite or zero picks no face (every score ties or is NaN): it
/// is refused and the body is left as it was; the simulation refuses a non-finite gravity and
/// stepping parameters whose tests would never fire (NaN runaway factor, zero CG tolerance).
#[test]
fn bad_directions_gravity_and_step_parameters_are_refused() {
    use topomech::cut::CutError;
    use topomech::mechanics::{SimError, StepError};
    let (mut body, _) = stretched_cube(0.0);
    let darts = body.map().dart_count();
    let v = topomech::CellId(21);
    for dir in [[f64::NAN, 0.0, 0.0], [0.0, f64::INFINITY, 0.0], [0.0; 3]] {
        let err = cut::tear_vertex(&mut body, v, dir, None).unwrap_err();
        assert!(
            matches!(err, CutError::BadDirection(d) if d.iter().zip(&dir).all(|(a, b)| a.to_bits() == b.to_bits()))
        );
        assert_eq!(body.map().dart_count(), darts);
    }
    body.map().validate().unwrap();
    let config = StepConfig::new(Integrator::Rk4, 1e-3);
    let err = Simulation::new(&mut body, [0.0, f64::NAN, 0.0], config).err().unwrap();
    assert!(matches!(err, SimError::BadGravity(_)), "{err}");
    let bad = [
        ("runaway_factor", StepConfig { runaway_factor: f64::NAN, ..config }),
        ("cg_tolerance", StepConfig { cg_tolerance: 0.0, ..config }),
    ];
    for (name, config) in bad {
        let err = Simulation::new(&mut body, [0.0, 0.0, -9.81], config).err().unwrap();
        assert!(matches!(err, SimError::Step(StepError::BadParameter { name: n, .. }) if n == name), "{err}");
    }
    assert!(Simulation::new(&mut body, [0.0, 0.0, -9.81], config).is_ok());
}

/// Finding 35 (docs/VERIFICATION.md): the simulation's read-outs trusted the body they were
/// given. `kinetic_energy` and `max_displacement` of a simulation built for a larger body
/// panicked on a smaller one ("range end index 27 out of range for slice of length 8") and
/// summed a prefix of a larger one; `principal_stress` and `tear_step` on a simulation the body
/// had left behind (volumes removed since) reported the stress of a vertex that no longer
/// existed and tore along springs that were gone. All four now refuse another body
/// (`SimError::OtherBody`) and a stale projection (`SimError::StaleProjection`), like `step`.
#[test]
fn read_outs_refuse_another_body_and_a_stale_simulation() {
    use topomech::cut::CutError;
    use topomech::mechanics::SimError;
    let (mut big, sim) = stretched_cube(1.0);
    let (points, tets) = kuhn_cube(1);
    let (small, _) = Body::from_tets(&points, &tets, material()).unwrap();
    let other = |r: Result<f64, SimError>| matches!(r, Err(SimError::OtherBody { .. }));
    assert!(other(sim.kinetic_energy(&small)) && other(sim.max_displacement(&small)));
    assert!(matches!(cut::principal_stress(&small, &sim), Err(SimError::OtherBody { .. })));
    // The small body's simulation given the big one: refused, not a sum over 8 of its 64 vertices.
    let mut small = small;
    let small_sim = Simulation::new(&mut small, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
    assert!(other(small_sim.kinetic_energy(&big)));
    // The body's own simulation works, then goes stale when a volume is removed.
    let before = sim.max_displacement(&big).unwrap();
    assert!(before > 0.0 && sim.kinetic_energy(&big).unwrap() == 0.0);
    assert!(!cut::principal_stress(&big, &sim).unwrap().is_empty());
    cut::remove_volume(&mut big, topomech::CellId(0)).unwrap();
    let stale = |r: Result<f64, SimError>| matches!(r, Err(SimError::StaleProjection { .. }));
    assert!(stale(sim.kinetic_energy(&big)) && stale(sim.max_displacement(&big)));
    assert!(matches!(cut::principal_stress(&big, &sim), Err(SimError::StaleProjection { .. })));
    let (version, mut sim) = (big.version(), sim);
    let refused = cut::tear_step(&mut big, &mut sim, 0.0, 5);
    assert!(matches!(refused, Err(CutError::Sim(SimError::StaleProjection { .. }))), "{refused:?}");
    assert_eq!(big.version(), version, "nothing torn");
    // Once the simulation follows the body again, every read-out answers.
    sim.rebuild(&mut big).unwrap();
    assert!(sim.max_displacement(&big).unwrap() > 0.0);
    assert!(cut::tear_step(&mut big, &mut sim, 0.0, 1).is_ok());
}

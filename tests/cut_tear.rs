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
    let mech = body.attrs_mut();
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
    let fresh = Projection::build(body, [0.0; 3]);
    sim.projection.equivalent(&fresh).unwrap();
    assert!(sim.projection.is_current(body));
}

#[test]
fn stretched_cube_tears() {
    let (mut body, mut sim) = stretched_cube(1.5);
    let mass = total_mass(&body);
    let vertices = body.map().count_cells().0[0];
    let stress = cut::principal_stress(&body, &sim);
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
    let stress = cut::principal_stress(&body, &sim);
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

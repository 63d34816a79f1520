//! Round 25, probe C's finding D: `tear_step` spent its `max_vertices` budget on vertices with no
//! inner face (empty tears that change nothing) and never reached a tearable vertex behind them.

use topomech::cut::tear_step;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{check_conservation, Body, Integrator, Material, Simulation, StepConfig};

/// A Kuhn cube whose centre vertex 13 is pulled (tearable: the doc example of `tear_step`) beside
/// a separate tet stretched harder (its vertices have the larger stress but no inner face).
fn cube_beside_a_loose_tet() -> (Body, Simulation, usize) {
    let (mut points, mut tets) = kuhn_cube(2);
    let b = points.len() as u32;
    points.extend([[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0], [5.0, 0.0, 1.0]]);
    tets.push([b, b + 1, b + 2, b + 3]);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
    body.attrs_mut().position_mut().as_mut_slice()[13][0] += 0.5;
    body.attrs_mut().position_mut().as_mut_slice()[b as usize + 1][0] += 3.0;
    (body, sim, b as usize)
}

/// The first pass with a budget of one tears vertex 13 (it made 10 empty tears before), and
/// lists only tears that dissociated faces.
#[test]
fn empty_tears_do_not_spend_the_budget() {
    let (mut body, mut sim, _) = cube_beside_a_loose_tet();
    let before = body.map().count_cells().0[0];
    let step = tear_step(&mut body, &mut sim, 1.0, 1).unwrap();
    assert_eq!(step.tears.len(), 1);
    assert_eq!(step.tears[0].vertex.0, 13);
    assert!(step.tears.iter().all(|t| !t.dissociations.is_empty()));
    assert!(body.map().count_cells().0[0] > before);
    check_conservation(body.map(), body.attrs()).unwrap();
    sim.step(&mut body).unwrap();
}

/// The loose tet's vertices are over the threshold but never listed (nothing to tear there).
#[test]
fn a_pass_over_loose_vertices_alone_lists_nothing() {
    let (points, tets) = ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [[0u32, 1, 2, 3]]);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
    body.attrs_mut().position_mut().as_mut_slice()[1][0] += 3.0;
    let step = tear_step(&mut body, &mut sim, 1.0, 4).unwrap();
    assert!(step.tears.is_empty(), "{:?}", step.tears.len());
    assert_eq!(body.map().count_cells().0[0], 4);
}

//! Findings 63–67 of the eleventh API probing round (cross-module and metamorphic laws over
//! operation sequences; docs/VERIFICATION.md, "Findings"). Each test fails on the code before
//! its fix.

use topomech::cut::{dissociate_face, incise_plane, principal_stress, remove_volume, tear_step, Plane};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Integrator, Material, Projection, Simulation, StepConfig, TouchedCells};
use topomech::store::Document;
use topomech::CellId;

const G: [f64; 3] = [0.0, 0.0, -9.81];

fn cube_body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

fn config() -> StepConfig {
    StepConfig::new(Integrator::Symplectic, 1e-4)
}

/// Finding 63: the totals of a body whose every tet was removed are +0.0, not −0.0 (an empty
/// float sum), as the kinetic energy already was.
#[test]
fn an_emptied_body_weighs_plus_zero() {
    let mut body = cube_body(1);
    for t in 0..6 {
        remove_volume(&mut body, CellId(t)).unwrap();
    }
    for (name, total) in [("tet mass", body.total_tet_mass()), ("vertex mass", body.total_vertex_mass())] {
        assert!(total == 0.0 && total.is_sign_positive(), "{name}: {total}");
    }
    let p = Projection::build(&body, G).unwrap();
    let x = body.attrs().position().as_slice();
    let (elastic, gravity) = (p.system().elastic_energy(x).unwrap(), p.system().gravity_energy(x).unwrap());
    assert!(elastic.is_sign_positive() && gravity.is_sign_positive(), "{elastic} {gravity}");
}

/// Finding 64: a pin written between steps is no topological change: the read-outs answer
/// (by the body's pins now) instead of failing with `StaleProjection { built: 0, now: 0 }`,
/// and the kinetic energy no longer counts the vertex just pinned.
#[test]
fn read_outs_answer_after_a_pin_write() {
    let mut body = cube_body(2);
    body.attrs_mut().velocity_mut().as_mut_slice().fill([0.0, 1.0, 0.0]);
    let mut sim = Simulation::new(&mut body, G, config()).unwrap();
    sim.step(&mut body).unwrap();
    let before = sim.kinetic_energy(&body).unwrap();
    body.attrs_mut().pinned_mut()[CellId(0)] = true;
    let after = sim.kinetic_energy(&body).unwrap();
    let m0 = sim.projection.system().mass()[0];
    let v0 = body.attrs().velocity()[CellId(0)];
    let expected = before - 0.5 * m0 * (v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]);
    assert!((after - expected).abs() <= 1e-12 * before, "{after} against {expected}");
    assert!(sim.max_displacement(&body).is_ok());
    assert!(principal_stress(&body, &sim).is_ok());
    assert!(tear_step(&mut body, &mut sim, f64::MAX, 1).is_ok());
    sim.step(&mut body).unwrap();
    assert_eq!(body.attrs().velocity()[CellId(0)], [0.0; 3]);
}

/// Finding 65: a projection is handed to another body only if that body is an untouched clone
/// of the one it follows — not to any body at the same version, nor to a clone that changed.
#[test]
fn a_projection_goes_only_to_an_untouched_clone() {
    let a = cube_body(1);
    let b = cube_body(3);
    let p = Projection::build(&a, G).unwrap();
    assert!(p.for_clone(&a, &b).is_none(), "b is no clone of a (both merely at version 0)");
    let copy = a.clone();
    let q = p.for_clone(&a, &copy).unwrap();
    assert!(q.is_current(&copy) && q.equivalent(&Projection::build(&copy, G).unwrap()).is_ok());
    let mut cut_copy = a.clone();
    let d = cut_copy.map().darts().find(|&d| !cut_copy.map().is_free(3, d)).unwrap();
    dissociate_face(&mut cut_copy, d).unwrap();
    let mut other_original = a.clone();
    let e = other_original.map().darts().find(|&d| !other_original.map().is_free(3, d)).unwrap();
    dissociate_face(&mut other_original, e).unwrap();
    let p1 = Projection::build(&other_original, G).unwrap();
    assert!(p1.for_clone(&other_original, &cut_copy).is_none(), "two clones at version 1 are not one body");
    let mut pinned = a.clone();
    pinned.attrs_mut().pinned_mut()[CellId(0)] = true;
    assert!(p.for_clone(&a, &pinned).is_none(), "a clone whose pins changed");
}

/// Finding 66: the lists of a stamped `TouchedCells` are read-only from outside, so they cannot
/// be emptied and still be taken as complete; lists given by hand are rebuilt from, and a
/// cut's own lists are taken incrementally and give a fresh build.
#[test]
fn touched_lists_cannot_be_altered_behind_their_stamp() {
    let mut body = cube_body(2);
    let mut sim = Simulation::new(&mut body, G, config()).unwrap();
    let cut = incise_plane(&mut body, &Plane { point: [1.0; 3], normal: [1.0, 0.0, 0.0] }).unwrap();
    let edges = cut.touched.edges().to_vec();
    assert!(!edges.is_empty());
    let partial = TouchedCells::by_hand(Vec::new(), Vec::new());
    let mut p = sim.projection.clone();
    assert!(!p.update(&body, &partial), "lists without a stamp are not trusted");
    assert!(p.equivalent(&Projection::build(&body, G).unwrap()).is_ok());
    sim.update(&mut body, &cut.touched).unwrap();
    assert!(sim.projection.equivalent(&Projection::build(&body, G).unwrap()).is_ok());
}

/// Finding 67: following a change by a rebuild or by an incremental update leaves the same
/// body: dead vertex ids are fixed slots with zero velocity either way (a rebuild zeroed only
/// the pinned ones, so a dead id drifted with its old velocity into the store and VTU files).
#[test]
fn rebuild_and_update_leave_the_same_body() {
    let (_, tets) = kuhn_cube(2);
    let mut a = cube_body(2);
    a.attrs_mut().velocity_mut().as_mut_slice().fill([1.0, 0.0, 0.0]);
    for (t, tet) in tets.iter().enumerate() {
        if tet.contains(&0) {
            remove_volume(&mut a, CellId(t as u32)).unwrap();
        }
    }
    assert!(!a.map().darts().any(|d| a.map().vertex_id(d) == CellId(0)), "vertex 0 is dead");
    let mut b = a.clone();
    let mut sa = Simulation::new(&mut a, G, config()).unwrap();
    let mut sb = Simulation::new(&mut b, G, config()).unwrap();
    let d = b.map().darts().find(|&d| !b.map().is_free(3, d)).unwrap();
    dissociate_face(&mut a, d).unwrap();
    let cut = dissociate_face(&mut b, d).unwrap();
    sa.rebuild(&mut a).unwrap();
    sb.update(&mut b, &cut.touched).unwrap();
    for _ in 0..3 {
        sa.step(&mut a).unwrap();
        sb.step(&mut b).unwrap();
    }
    assert_eq!(a.attrs().velocity()[CellId(0)], [0.0; 3]);
    assert!(Document::from_body(&a) == Document::from_body(&b), "the two paths leave different bodies");
}

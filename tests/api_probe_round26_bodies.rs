//! Round 26 (b): a body's attributes replaced as a whole, boundary normals at extreme scales, a
//! sew that moved a pinned vertex by one ulp, a simulation moved to another body through its
//! public projection.

use topomech::cut::dissociate_face;
use topomech::generate::kuhn_cube;
use topomech::mechanics::{
    Body, ConservationError, Integrator, Material, Projection, SimError, Simulation, StepConfig,
};
use topomech::store::{self, Format};
use topomech::DartId;

fn cube_with(k: usize, material: Material) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, material).unwrap().0
}

fn cube(k: usize) -> Body {
    cube_with(k, Material::default())
}

fn inner(b: &Body) -> DartId {
    b.map().darts().find(|&d| !b.map().is_free(3, d)).unwrap()
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("topomech-r26-{}-{name}", std::process::id()))
}

/// F1a: attributes from before a cut do not cover the map. Since round 27 they cannot be put
/// back into the body (`Body::attrs_mut` opens the free state only; `AttrsMut`'s compile-fail
/// examples); the one way to pair them with the map, `Body::new`, refuses them.
#[test]
fn short_attributes_cannot_be_paired_with_the_cut_map() {
    let mut a = cube(2);
    let snap = a.attrs().clone();
    let d = inner(&a);
    dissociate_face(&mut a, d).unwrap();
    assert!(matches!(snap.check_covers(a.map()), Err(ConservationError::MissingAttributes { .. })));
    let (map, _) = a.clone().into_parts();
    // `Body::new` grows the arrays to the map, then the laws fail on the split cells.
    let e = Body::new(map, snap).unwrap_err().error;
    assert!(matches!(e, ConservationError::EdgeStiffness { .. } | ConservationError::VertexMass { .. }), "{e:?}");
    assert!(Projection::build(&a, [0.0; 3]).is_ok(), "the body itself is untouched");
}

/// F1b: another body's attributes of the same mesh (density 3) paired with the map make a new
/// body: the projection and the simulation built before are not for it.
#[test]
fn another_bodys_attributes_make_a_body_projections_are_not_for() {
    let mut a = cube(2);
    let b = cube_with(2, Material { density: 3.0, ..Material::default() });
    let p = Projection::build(&a, [0.0; 3]).unwrap();
    let mut sim = Simulation::new(&mut a, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    let mut c = Body::new(a.map().clone(), b.attrs().clone()).unwrap();
    assert!(c.check().is_ok());
    assert!(!p.is_for(&c) && !p.is_current(&c));
    assert!(matches!(sim.step(&mut c), Err(SimError::OtherBody { .. })));
    sim.step(&mut a).unwrap();
    let q = Projection::build(&c, [0.0; 3]).unwrap();
    assert!(q.equivalent(&p).is_err(), "the masses are three times a's");
}

/// F2: boundary normals at every scale are unit vectors (or zero for a degenerate face), the
/// same as at scale 1 up to rounding, and the body saves: at 1e-79 they were 1 + 8e-9 long,
/// from 1e78 zero, from 1e155 NaN, and `save_body` refused the body.
#[test]
fn boundary_normals_are_unit_at_every_scale_and_the_body_saves() {
    let reference = {
        let b = cube(1);
        let m = b.map();
        m.one_dart_per_cell(2).into_iter().map(|d| b.attrs().face_normal(m.cell_id(2, d))).collect::<Vec<_>>()
    };
    for s in [1e-300, 1e-150, 1e-81, 1e-79, 1e78, 1e100, 1e155, 1e300] {
        let mut b = cube(1);
        b.attrs_mut().position_mut().as_mut_slice().iter_mut().for_each(|p| *p = p.map(|c| c * s));
        b.update_normals().unwrap();
        let m = b.map();
        for (k, d) in m.one_dart_per_cell(2).into_iter().enumerate() {
            let n = b.attrs().face_normal(m.cell_id(2, d));
            let diff = (0..3).map(|i| (n[i] - reference[k][i]).abs()).fold(0.0, f64::max);
            assert!(diff <= 1e-15, "scale {s:e}, face {k}: {n:?} vs {:?}", reference[k]);
        }
        assert!(b.check().is_ok());
        let path = temp("scale.tmapb");
        store::save_body(&b, &path, Format::Binary).unwrap_or_else(|e| panic!("scale {s:e}: {e}"));
        assert!(store::load_body(&path).is_ok());
        let _ = std::fs::remove_file(path);
    }
}

/// F3: sewing back two sides at the same position keeps the position bit for bit (a pinned
/// vertex moved by one ulp: w1·p + w2·p with w1 + w2 ≠ 1).
#[test]
fn a_sew_of_two_sides_at_one_position_keeps_it_exactly() {
    let mut b = cube(2);
    b.attrs_mut().pin_where(|_, _| true);
    let before = b.attrs().position().as_slice().to_vec();
    let (d1, d2) = (DartId(15), DartId(28));
    let e1 = b.map().alpha::<3>(d1);
    b.unsew3(d1).unwrap();
    b.unsew3(d2).unwrap();
    b.sew3(d1, e1).unwrap();
    let after = b.attrs().position().as_slice();
    for v in b.map().one_dart_per_cell(0).into_iter().map(|d| b.map().vertex_id(d)) {
        assert_eq!(after[v.index()], before[v.index()], "vertex {}", v.0);
    }
    assert!(b.attrs().pinned().as_slice()[1]);
}

/// F4: a simulation whose public projection was rebuilt for another body refuses that body
/// (it stepped it without `Simulation::rebuild`'s reset, moving a pinned vertex), and its own.
#[test]
fn a_simulation_does_not_follow_its_projection_to_another_body() {
    let mut b = cube(1);
    b.attrs_mut().pinned_mut().as_mut_slice()[0] = true;
    let mut a = cube(1);
    let mut sim = Simulation::new(&mut a, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-2)).unwrap();
    sim.projection.rebuild(&b);
    assert!(matches!(sim.step(&mut b), Err(SimError::OtherBody { .. })));
    assert!(matches!(sim.step(&mut a), Err(SimError::ProjectionNotForBody { .. })));
    sim.rebuild(&mut b).unwrap();
    b.attrs_mut().velocity_mut().as_mut_slice()[0] = [1.0, 0.0, 0.0];
    for _ in 0..10 {
        sim.step(&mut b).unwrap();
    }
    assert_eq!(sim.stepper.steps_done(), 10);
    assert_eq!(b.attrs().position().as_slice()[0], [0.0; 3], "the pinned vertex stays");
}

/// F1b through `Projection::for_clone`: a clone whose attributes were replaced after cloning by
/// others is not given the original's projection (it would describe the old masses); an
/// untouched clone is.
#[test]
fn for_clone_refuses_a_clone_whose_attributes_were_replaced() {
    let a = cube(2);
    let b = cube_with(2, Material { density: 3.0, ..Material::default() });
    let p = Projection::build(&a, [0.0; 3]).unwrap();
    let copy = a.clone();
    let q = p.for_clone(&a, &copy).expect("an untouched clone");
    assert!(q.equivalent(&Projection::build(&copy, [0.0; 3]).unwrap()).is_ok());
    let replaced = Body::new(a.map().clone(), b.attrs().clone()).unwrap();
    assert!(p.for_clone(&a, &replaced).is_none());
}

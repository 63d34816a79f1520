//! Round 23 of API probing: error atomicity (findings 203–205). A public mutating call that
//! returns `Err` leaves every piece of state as it was; each test compares the whole object's
//! `Debug` text (raw arrays, counters, epochs) before and after a refused call, and then checks
//! that a following accepted call does what it does on a copy that never saw the refusal.

use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics};
use topomech::vtk::{Frame, Series};
use topomech::GMap;

fn cube_body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

/// Finding 203: a step (or `write_forces`) refused for its start state had already copied the
/// pins written since the last step into the projection.
#[test]
fn f203_a_refused_step_leaves_the_simulations_pins_as_they_were() {
    type Bad = fn(&mut Body);
    let nan_velocity: Bad = |b| b.attrs_mut().velocity_mut().as_mut_slice()[5] = [f64::NAN, 0.0, 0.0];
    let huge_position: Bad = |b| b.attrs_mut().position_mut().as_mut_slice()[9] = [1e200, 0.0, 0.0];
    for (bad, via_forces) in [(nan_velocity, false), (nan_velocity, true), (huge_position, false)] {
        let mut body = cube_body(3);
        let config = StepConfig::new(Integrator::Euler, 1e-4);
        let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config).unwrap();
        bad(&mut body);
        body.attrs_mut().pinned_mut().as_mut_slice()[7] = true; // a pin written since the last step
        let before = format!("{sim:?}");
        let inv_mass = sim.projection.system().inv_mass()[7];
        assert!(inv_mass > 0.0);
        let refused = if via_forces { sim.write_forces(&mut body).is_err() } else { sim.step(&mut body).is_err() };
        assert!(refused, "the bad start state must be refused");
        assert_eq!(sim.projection.system().inv_mass()[7], inv_mass, "slot 7 was fixed by a refused call");
        assert!(format!("{sim:?}") == before, "the simulation changed on a refused call");
        // The pin is taken up by the next accepted step.
        let fresh = cube_body(3);
        body.attrs_mut().velocity_mut().as_mut_slice()[5] = fresh.attrs().velocity().as_slice()[5];
        body.attrs_mut().position_mut().as_mut_slice()[9] = fresh.attrs().position().as_slice()[9];
        sim.step(&mut body).unwrap();
        assert_eq!(sim.projection.system().inv_mass()[7], 0.0);
        assert_eq!(body.attrs().velocity().as_slice()[7], [0.0; 3]);
    }
}

/// Finding 204: `Series::push` appended the frame to the series when the `.pvd` could not be
/// rewritten, so a retry took the next number and the `.pvd` listed the refused frame.
#[test]
fn f204_a_push_whose_pvd_cannot_be_written_leaves_the_series_as_it_was() {
    let dir = std::env::temp_dir().join(format!("topomech-f204-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let frame = Frame { points: &points, tets: &[[0, 1, 2, 3]], vectors: vec![] };
    let mut series = Series::new(&dir, "run").unwrap();
    series.push(0.0, &frame).unwrap();
    std::fs::remove_file(series.pvd_path()).unwrap();
    std::fs::create_dir(series.pvd_path()).unwrap(); // the .pvd cannot be replaced now
    std::fs::write(series.pvd_path().join("x"), b"x").unwrap();
    let before = format!("{series:?}");
    assert!(series.push(0.1, &frame).is_err());
    assert_eq!(format!("{series:?}"), before, "the series changed on a refused push");
    assert!(!dir.join("run_000001.vtu").exists(), "the refused frame's file was left behind");
    std::fs::remove_dir_all(series.pvd_path()).unwrap();
    let retry = series.push(0.1, &frame).unwrap();
    assert!(retry.ends_with("run_000001.vtu"), "{retry:?}");
    let pvd = std::fs::read_to_string(series.pvd_path()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 2, "{pvd}");
}

fn coupled(k: usize) -> (LeveledMap<3>, LeveledMechanics) {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let m = LeveledMap::new(map, points.to_vec());
    let mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    (m, mech)
}

/// The spring on the edge of the map's first dart.
fn first_edge(mech: &LeveledMechanics, m: &LeveledMap<3>) -> topomech::subdivide::EdgeKey {
    let d = m.map().darts().next().unwrap();
    let (a, b) = (m.map().vertex_id(d).0, m.map().vertex_id(m.map().alpha_dyn(0, d)).0);
    mech.edge(a, b).unwrap()
}

/// Finding 205: a NaN material constant (a public field) or a NaN spring (through `spring_mut`)
/// passed the split's headroom check, which folds with `f64::max`; the split then failed half
/// way, with the map split and the coupling partly followed.
#[test]
fn f205_a_nan_material_or_spring_is_refused_before_the_map_changes() {
    type Poison = fn(&mut LeveledMechanics, &LeveledMap<3>);
    let poisons: [(&str, Poison); 4] = [
        ("damping", |mech, _| mech.material.damping = f64::NAN),
        ("young", |mech, _| mech.material.young = f64::NAN),
        ("spring stiffness", |mech, m| {
            let e = first_edge(mech, m);
            mech.spring_mut(e).unwrap().stiffness = f64::NAN;
        }),
        ("spring damping", |mech, m| {
            let e = first_edge(mech, m);
            mech.spring_mut(e).unwrap().damping = f64::NAN;
        }),
    ];
    type Op = fn(&mut LeveledMechanics, &mut LeveledMap<3>) -> Result<(), CouplingError>;
    let ops: [(&str, Op); 4] = [
        ("subdivide_tet", |mech, m| {
            let d = m.map().darts().next().unwrap();
            mech.subdivide_tet(m, d, 1).map(drop)
        }),
        ("refine_around, bulk", |mech, m| mech.refine_around(m, [1.0; 3], 10.0, 1).map(drop)),
        ("refine_around, per op", |mech, m| {
            let v = m.map().vertex_id(m.map().darts().next().unwrap()).0;
            mech.refine_around(m, m.points()[v as usize], 0.3, 2).map(drop)
        }),
        ("split_edge", |mech, m| {
            let d = m.map().darts().next().unwrap();
            mech.split_edge(m, d, 1).map(drop)
        }),
    ];
    for (what, poison) in poisons {
        for (name, op) in ops {
            let (mut m, mut mech) = coupled(2);
            poison(&mut mech, &m);
            // Debug text, not `==`: a NaN material is not equal to itself.
            let (m0, mech0) = (format!("{m:?}"), format!("{mech:?}"));
            let e = op(&mut mech, &mut m);
            let is_material = matches!(e, Err(CouplingError::Material(_)));
            let is_headroom = matches!(e, Err(CouplingError::SplitOverflow { .. }));
            assert!(is_material || is_headroom, "{what} NaN, {name}: {e:?}");
            assert!(format!("{m:?}") == m0, "{what} NaN, {name}: the map changed");
            assert!(format!("{mech:?}") == mech0, "{what} NaN, {name}: the coupling changed");
        }
    }
    // Without the poison every one of these operations is accepted.
    for (name, op) in ops {
        let (mut m, mut mech) = coupled(2);
        assert!(op(&mut mech, &mut m).is_ok(), "{name}");
        mech.check(&m).unwrap();
    }
}

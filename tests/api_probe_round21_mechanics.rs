//! Round 21, finding 177: a topology update (`Simulation::update`, `Simulation::rebuild`) must
//! not restart the step count nor re-take the runaway test's energy scale — a cut puts no energy
//! in, so a blow-up that runs on while the body is cut is still caught, named by its step since
//! the start. And the update keeps the law "a fixed slot does not move" among the cells it
//! touches without a pass over the mesh.

use topomech::cut::{dissociate_face, remove_volume};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Integrator, Material, SimError, Simulation, StepConfig, StepError};
use topomech::CellId;

/// A Kuhn cube of side `n`, bottom pinned, under gravity, stepped by symplectic Euler at
/// `factor` times its stability limit.
fn unstable_cube(n: usize, factor: f64) -> (Body, Simulation) {
    let (points, tets) = kuhn_cube(n);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    body.attrs_mut().pin_where(|_, rest| rest[2] == 0.0);
    let probe = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Symplectic, 1e-6)).unwrap();
    let limit = Integrator::Symplectic.stable_dt(&probe.projection.system().mode_bounds()).unwrap();
    let config = StepConfig::new(Integrator::Symplectic, factor * limit);
    let sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config).unwrap();
    (body, sim)
}

/// An inner face's dart, if any is left.
fn inner_face(body: &Body) -> Option<topomech::DartId> {
    body.map().darts().find(|&d| !body.map().is_free(3, d))
}

/// Steps until an error (at most `max` steps), cutting one inner face and updating the
/// simulation before every step when `cut` holds. Returns the error and the steps done before.
fn run_until_error(body: &mut Body, sim: &mut Simulation, cut: bool, max: u64) -> (SimError, u64) {
    for done in 0..max {
        if cut {
            if let Some(d) = inner_face(body) {
                let dis = dissociate_face(body, d).unwrap();
                sim.update(body, &dis.touched).unwrap();
            }
        }
        if let Err(e) = sim.step(body) {
            return (e, done);
        }
    }
    panic!("no error in {max} steps at an unstable time step");
}

#[test]
fn a_runaway_while_cutting_every_step_is_still_caught_at_its_global_step() {
    // Reference: the same unstable run without cuts is stopped by the runaway test.
    let (mut body, mut sim) = unstable_cube(3, 4.0);
    let (e, done) = run_until_error(&mut body, &mut sim, false, 5_000);
    let SimError::Step(StepError::BlowUp { step, reason, .. }) = e else { panic!("{e}") };
    assert!(reason.contains("runaway"), "{reason}");
    assert_eq!(step, done);
    // With one face dissociated and the simulation updated before every step, the kinetic
    // energy was measured against the energy of the moment: it grew to NaN unnoticed.
    let (mut body, mut sim) = unstable_cube(3, 4.0);
    let (e, done) = run_until_error(&mut body, &mut sim, true, 5_000);
    let SimError::Step(StepError::BlowUp { step, reason, .. }) = e else { panic!("{e}") };
    assert!(reason.contains("runaway"), "{reason}");
    assert_eq!(step, done, "the step since the start, not since the last cut");
    assert_eq!(sim.stepper.steps_done(), done);
    let x = body.attrs().position().as_slice();
    assert!(x.iter().flatten().all(|c| c.is_finite()), "caught while the state is finite");
}

#[test]
fn update_and_rebuild_keep_the_step_count() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], StepConfig::new(Integrator::Rk4, 1e-4)).unwrap();
    for _ in 0..7 {
        sim.step(&mut body).unwrap();
    }
    let d = inner_face(&body).unwrap();
    let dis = dissociate_face(&mut body, d).unwrap();
    sim.update(&mut body, &dis.touched).unwrap();
    assert_eq!(sim.stepper.steps_done(), 7);
    sim.step(&mut body).unwrap();
    remove_volume(&mut body, CellId(0)).unwrap();
    sim.rebuild(&mut body).unwrap();
    assert_eq!(sim.stepper.steps_done(), 8);
    for _ in 0..3 {
        sim.step(&mut body).unwrap();
    }
    assert_eq!(sim.stepper.steps_done(), 11);
}

#[test]
fn after_updates_every_fixed_slot_is_still() {
    // Every vertex moving, a third pinned; cuts and removals split pinned vertices and kill
    // vertex ids: after each update a fixed slot (pinned or dead) has zero velocity, as a
    // fresh simulation would give it.
    let (points, tets) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    body.attrs_mut().pin_where(|v, _| v.0 % 3 == 0);
    let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-5)).unwrap();
    body.attrs_mut().velocity_mut().as_mut_slice().iter_mut().for_each(|v| *v = [0.0, 0.0, 1e-3]);
    sim.step(&mut body).unwrap();
    for round in 0..12u32 {
        let touched = if round % 3 == 2 {
            remove_volume(&mut body, CellId(round * 7)).unwrap().touched
        } else {
            let d = inner_face(&body).unwrap();
            dissociate_face(&mut body, d).unwrap().touched
        };
        sim.update(&mut body, &touched).unwrap();
        let sys = sim.projection.system();
        let v = body.attrs().velocity().as_slice();
        for (slot, (&w, vel)) in sys.inv_mass().iter().zip(v).enumerate() {
            if w == 0.0 {
                assert_eq!(*vel, [0.0; 3], "fixed slot {slot} moves after update {round}");
            }
        }
        let free_moving = (0..sys.slots()).any(|s| sys.inv_mass()[s] > 0.0 && v[s] != [0.0; 3]);
        assert!(free_moving, "the free vertices keep their velocities");
        sim.step(&mut body).unwrap();
    }
}

/// A Kuhn cube scaled by `s` (Young's modulus `young`, no damping), vertex 7 pulled up by s/5.
fn scaled_cube(s: f64, young: f64) -> Body {
    let (points, tets) = kuhn_cube(1);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c * s)).collect();
    let material = Material { young, damping: 0.0, viscosity: 0.0, ..Material::default() };
    let (body, _) = Body::from_tets(&points, &tets, material).unwrap();
    body
}

#[test]
fn the_inner_force_scales_with_the_body() {
    // Finding 178: σ_v = Σ T n nᵀ with T = k (l − L), k = E V / L² ∝ E s: a body scaled by s
    // has σ/s² the same at every scale where σ is an ordinary number. T dᵢ dⱼ / l² overflowed
    // at s = 1e80 (NaN) and underflowed at 1e-90 (0: nothing would ever tear there).
    let magnitude = |s: f64| {
        let mut body = scaled_cube(s, 1e3);
        let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3 * s)).unwrap();
        body.attrs_mut().position_mut().as_mut_slice()[7][2] += 0.5 * s;
        topomech::cut::principal_stress(&body, &sim).unwrap()[7].magnitude / (s * s)
    };
    let unit = magnitude(1.0);
    assert!(unit > 0.0 && unit.is_finite());
    for s in [1e-90, 1e-60, 1e60, 1e80] {
        let m = magnitude(s);
        assert!((m - unit).abs() <= 1e-12 * unit, "scale {s:e}: σ/s² = {m:e}, at scale 1 {unit:e}");
    }
}

#[test]
fn the_implicit_scheme_steps_a_body_of_any_size() {
    // Finding 179: the same physics at scale s (dt ∝ s, every frequency ∝ 1/s) gives the same
    // x/s. Conjugate gradient on unscaled norms failed beyond about 1e±33 and, below 1e-55,
    // returned Δv = 0: the forces of the step silently dropped, the body frozen.
    let run = |s: f64| {
        let mut body = scaled_cube(s, 1e3);
        let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Implicit, 1e-4 * s)).unwrap();
        body.attrs_mut().position_mut().as_mut_slice()[7][2] += 0.2 * s;
        for _ in 0..10 {
            sim.step(&mut body).unwrap();
        }
        body.attrs().position().as_slice()[7].map(|c| c / s)
    };
    let unit = run(1.0);
    assert!(unit[2] < 1.2 - 1e-5, "the pulled corner springs back: {unit:?}");
    for s in [1e-100, 1e-60, 1e-35, 1e35, 1e60, 1e90] {
        let x = run(s);
        for (a, b) in x.iter().zip(&unit) {
            assert!((a - b).abs() <= 1e-9, "scale {s:e}: x7/s = {x:?}, at scale 1 {unit:?}");
        }
    }
}

/// A chain of `n` free slots of mass `m` joined by springs of stiffness `m` (so k/m = 1 at any
/// scale), rest length 1, stretched unevenly (spacings 1.5 to 2.1) so that every slot is pulled.
fn heavy_chain(n: u32, m: f64) -> (topomech::mechanics::SpringSystem, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut sys = topomech::mechanics::SpringSystem::default();
    for _ in 0..n {
        sys.push_slot(m, false, 0.0).unwrap();
    }
    for i in 0..n - 1 {
        sys.push_spring([i, i + 1], 1.0, m, 0.0).unwrap();
    }
    let x = (0..n).map(|i| [1.5 * f64::from(i) + 0.3 * f64::from(i % 3) * f64::from(i % 2), 0.0, 0.0]).collect();
    (sys, x, vec![[0.0; 3]; n as usize])
}

#[test]
fn the_implicit_solve_takes_masses_near_the_ends_of_f64() {
    // Finding 179, the matrix side: with masses and stiffnesses near the ends of f64 (5e306 on
    // 30 slots, a total mass still below f64::MAX; 1e-308) the step lengths rᵀr / pᵀAp leave
    // f64's range unless A is scaled too; the motion is the unit chain's (k/m = 1).
    use topomech::mechanics::Stepper;
    let step = |m: f64| {
        let (sys, mut x, mut v) = heavy_chain(30, m);
        let mut st = Stepper::new(StepConfig::new(Integrator::Implicit, 0.1), &sys, &x, &v).unwrap();
        st.step(&sys, &mut x, &mut v).unwrap();
        v
    };
    let unit = step(1.0);
    let scale = unit.iter().fold(0.0f64, |m, v| m.max(v[0].abs()));
    assert!(unit[0][0] > 0.0, "the stretched chain contracts");
    for m in [5e306, 1e-300, 1e-308] {
        for (a, b) in unit.iter().zip(&step(m)) {
            assert!((a[0] - b[0]).abs() <= 1e-9 * scale, "m = {m:e}: {a:?} against {b:?}");
        }
    }
}

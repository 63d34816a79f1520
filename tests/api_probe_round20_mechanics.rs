//! Round 20 probing of the mechanics (findings 168, 169): spring forces of needles whose l² is
//! subnormal or underflows (and of lengths whose l² overflows), checked against Hooke's law
//! k (l − L) n, through `spring_force`, a needle body's `write_forces`, `SpringSystem` forces and
//! every kernel; and the runaway test of `Stepper`, which counts free slots only, so that a fixed
//! slot with a velocity (a driven pin) is no false `BlowUp` while a free slot's runaway still is.

use topomech::load::load_builtin;
use topomech::mechanics::force::spring_force;
use topomech::mechanics::{
    Body, FlatModel, Integrator, Kernel, Material, Simulation, SpringSystem, StepConfig, StepError, Stepper, Vec3,
};

/// Whether `a` and `b` agree to the relative tolerance `rel`.
fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

/// Finding 168: a spring of rest length e stretched to 2e with k = 1 pulls with exactly e, for
/// every scale; before, l² subnormal (e < 1.5e-154) was divided by 2.2e-308 (1e-155 gave 0.018×
/// its force, 1e-160 1e-12×), l² = 0 (e < 1e-162) gave 0, and l² = ∞ (e > 1.3e154) gave NaN.
#[test]
fn spring_force_follows_hookes_law_at_every_scale() {
    let still = [0.0; 3];
    for e in [1.0, 1e-100, 1e-154, 1e-155, 1e-156, 1e-160, 1e-170, 1e-200, 1e-300, 1e-305, 1e155, 1e200, 1e300] {
        let f = spring_force([0.0; 3], [2.0 * e, 0.0, 0.0], still, still, e, 1.0, 0.0);
        assert!(close(f[0], e, 1e-12) && f[1] == 0.0 && f[2] == 0.0, "e = {e:e}: {f:?}");
        // Compressed to half its rest length along a diagonal: |F| = k L / 2, pushing a away.
        let s = e / 3f64.sqrt();
        let f = spring_force([0.0; 3], [s, s, s], still, still, 2.0 * e, 3.0, 0.0);
        for (c, fc) in f.iter().enumerate() {
            assert!(close(*fc, -3.0 * e / 3f64.sqrt(), 1e-12), "e = {e:e}, component {c}: {f:?}");
        }
        // At its rest length a spring pulls with exactly nothing.
        assert_eq!(spring_force([0.0; 3], [e, 0.0, 0.0], still, still, e, 7.0, 0.0), [0.0; 3], "e = {e:e}");
    }
}

/// Finding 168: the damping term c (dv·n) n of a needle at its rest length is the unit-scale one
/// (it does not depend on l); before, a 1e-160 spring closing at 1 m/s with c = 0.5 gave 5e-13,
/// not −0.5 (and 0 below 1e-162).
#[test]
fn needle_damping_is_scale_free() {
    for e in [1.0, 1e-155, 1e-160, 1e-170, 1e-250] {
        let f = spring_force([0.0; 3], [0.0, e, 0.0], [0.0, 1.0, 0.0], [0.0; 3], e, 2.0, 0.5);
        assert!(close(f[1], -0.5, 1e-12) && f[0] == 0.0 && f[2] == 0.0, "e = {e:e}: {f:?}");
    }
}

/// Coincident ends still give exactly zero (no NaN), through the cold path too.
#[test]
fn zero_length_spring_has_zero_force() {
    let f = spring_force([1e-170, 2.0, 3.0], [1e-170, 2.0, 3.0], [1.0; 3], [0.0; 3], 1.0, 5.0, 0.5);
    assert_eq!(f, [0.0; 3]);
}

/// The needle tet of the report: corner 1 at distance e from corner 0 on the x axis, the others at
/// unit distance.
fn needle_body(e: f64) -> Body {
    let p = [[0.0, 0.0, 0.0], [e, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mat = Material { damping: 0.0, viscosity: 0.0, ..Material::default() };
    Body::from_tets(&p, &[[0, 1, 2, 3]], mat).unwrap().0
}

/// The forces on a needle body written by `write_forces` with vertex 1 at `x1` (no gravity).
fn needle_forces(e: f64, x1: Vec3) -> Vec<Vec3> {
    let mut body = needle_body(e);
    let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    body.attrs_mut().position_mut().as_mut_slice()[1] = x1;
    sim.write_forces(&mut body).unwrap();
    body.attrs().force().as_slice().to_vec()
}

/// Finding 168: a needle body in its rest shape without gravity feels exactly zero force (the
/// ordinary-scale law); before, needles of 1e-155 to 1e-160 felt 1.09e-15 at vertex 1.
#[test]
fn needle_body_at_rest_feels_no_force() {
    for e in [1e-3, 1e-100, 1e-154, 1e-155, 1e-157, 1e-160, 1e-170, 1e-200] {
        let forces = needle_forces(e, [e, 0.0, 0.0]);
        assert!(forces.iter().all(|f| *f == [0.0; 3]), "e = {e:e}: {forces:?}");
    }
}

/// Finding 168: stretched to twice its length, the needle's spring dominates vertex 1's force,
/// k e with k ∝ 1/e: the same force at every scale (−166.7 for this tet). Before: −3.0 at 1e-155,
/// −3.0e-4 at 1e-157, −3.0e-10 at 1e-160.
#[test]
fn stretched_needle_body_force_is_scale_free() {
    let reference = needle_forces(1e-100, [2e-100, 0.0, 0.0])[1][0];
    assert!(close(reference, -166.7, 1e-3), "{reference}");
    for e in [1e-154, 1e-155, 1e-157, 1e-160, 1e-170, 1e-200] {
        let f = needle_forces(e, [2.0 * e, 0.0, 0.0])[1][0];
        assert!(close(f, reference, 1e-9), "e = {e:e}: {f} vs {reference}");
    }
}

/// Finding 168 through a `SpringSystem`: the spring forces of a chain of needles of every scale
/// (some beside ordinary springs in one block of the vectorised pass) are k (l − L) n on every
/// kernel, serial and parallel, and the elastic energy is ½ k (l − L)² (before: off by 2e-5 at 1e-160).
#[test]
fn system_forces_and_energy_of_needles_follow_hookes_law_on_every_kernel() {
    let scales = [1.0, 1e-155, 2.0, 1e-160, 1e-170, 0.5, 1e-300, 1e200];
    let mut sys = SpringSystem::default();
    let (mut x, mut expected) = (Vec::new(), Vec::new());
    for (i, &e) in scales.iter().enumerate() {
        let (a, b) = (sys.push_slot(1.0, false, 0.0).unwrap(), sys.push_slot(1.0, false, 0.0).unwrap());
        x.push([10.0 * i as f64, 0.0, 0.0]);
        x.push([10.0 * i as f64, 3.0 * e, 0.0]);
        sys.push_spring([a as u32, b as u32], e, 2.0, 0.0).unwrap();
        let l = x[b][1] - x[a][1];
        expected.push((2.0 * (l - e), 0.5 * 2.0 * (l - e) * (l - e)));
    }
    let v = vec![[0.0; 3]; x.len()];
    let mut sf = vec![[0.0; 3]; scales.len()];
    for kernel in Kernel::available() {
        for parallel in [false, true] {
            sys.spring_forces_with(kernel, &x, &v, &mut sf, parallel).unwrap();
            for (s, (f, &(mag, _))) in sf.iter().zip(&expected).enumerate() {
                assert!(close(f[1], mag, 1e-12) && f[0] == 0.0, "{} spring {s}: {f:?} vs {mag:e}", kernel.name());
            }
        }
    }
    for (s, &(_, energy)) in expected.iter().enumerate() {
        let (a, b) = (2 * s, 2 * s + 1);
        let mut one = SpringSystem::default();
        (0..2).for_each(|_| drop(one.push_slot(1.0, false, 0.0)));
        one.push_spring([0, 1], scales[s], 2.0, 0.0).unwrap();
        let got = one.elastic_energy(&[x[a], x[b]]).unwrap();
        if energy.is_finite() {
            assert!(close(got, energy, 1e-12), "spring {s}: {got:e} vs {energy:e}");
        }
    }
}

/// Finding 168 in the step loop: a needle body stepped with RK4 (the one-pass spring sums, every
/// kernel) from its rest shape without gravity does not move at all.
#[test]
fn needle_body_at_rest_stays_at_rest_under_rk4() {
    for e in [1e-155, 1e-170] {
        let mut body = needle_body(e);
        let start = body.attrs().position().as_slice().to_vec();
        let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Rk4, 1e-9)).unwrap();
        for _ in 0..5 {
            sim.step(&mut body).unwrap();
        }
        assert_eq!(body.attrs().position().as_slice(), &start[..], "e = {e:e}");
    }
}

/// The two-slot system of the report: slot 0 fixed and driven at `speed` along x, slot 1 free at
/// rest one unit away, joined by a unit spring at its rest length.
fn driven_pair(speed: f64) -> (SpringSystem, Vec<Vec3>, Vec<Vec3>) {
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(1.0, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
    (sys, vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![[speed, 0.0, 0.0], [0.0; 3]])
}

const SCHEMES: [Integrator; 4] = [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit];

/// Finding 169: a fixed slot driven at 100 m/s (½ m v² = 5e3, ten times the limit 1e3 × ½ k L²)
/// is no runaway in any scheme; it moves at its constant velocity, and the kinetic energy (free
/// slots) stays that of the free slot. Before: `BlowUp` at step 0 naming slot 0.
#[test]
fn driven_fixed_slot_is_no_runaway() {
    for scheme in SCHEMES {
        let (sys, mut x, mut v) = driven_pair(100.0);
        assert_eq!(sys.kinetic_energy(&v), Ok(0.0));
        let h = 1e-4;
        let mut st = Stepper::new(StepConfig::new(scheme, h), &sys, &x, &v).unwrap();
        for n in 1..=20 {
            st.step(&sys, &mut x, &mut v).unwrap_or_else(|e| panic!("{scheme:?} step {n}: {e}"));
            assert_eq!(v[0], [100.0, 0.0, 0.0], "{scheme:?}: the pin keeps its velocity");
        }
        assert!(close(x[0][0], 20.0 * h * 100.0, 1e-12), "{scheme:?}: {:?}", x[0]);
        assert!(sys.kinetic_energy(&v).unwrap() < 1e3, "{scheme:?}");
    }
}

/// Finding 169: a genuine runaway of a free slot is still caught beside a driven pin whose
/// ½ m v² is larger, and the free slot is named. Energy written by hand (not a new start) on the
/// free slot, then explicit Euler on a stiff spring at ω h = 10 (an exponential instability).
#[test]
fn free_runaway_beside_a_driven_pin_names_the_free_slot() {
    for scheme in SCHEMES {
        let (sys, mut x, mut v) = driven_pair(1000.0); // ½ m v² = 5e5 on the pin
        let mut st = Stepper::new(StepConfig::new(scheme, 1e-4), &sys, &x, &v).unwrap();
        st.step(&sys, &mut x, &mut v).unwrap_or_else(|e| panic!("{scheme:?}: {e}"));
        v[1] = [0.0, 40.0, 0.0]; // ½ m v² = 800 > 500 = limit
        match st.step(&sys, &mut x, &mut v) {
            Err(StepError::BlowUp { step: 1, slot: 1, reason }) => assert!(reason.contains("runaway"), "{reason}"),
            other => panic!("{scheme:?}: {other:?}"),
        }
    }
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(1.0, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, 1e6, 0.0).unwrap();
    let (mut x, mut v) = (vec![[0.0; 3], [1.01, 0.0, 0.0]], vec![[0.0, 0.0, 1.0], [0.0; 3]]);
    let mut st = Stepper::new(StepConfig::new(Integrator::Euler, 1e-2), &sys, &x, &v).unwrap();
    let err = (0..100).find_map(|_| st.step(&sys, &mut x, &mut v).err()).expect("Euler at ω h = 10 runs away");
    assert!(matches!(err, StepError::BlowUp { slot: 1, .. }), "{err}");
}

/// Finding 169, the realistic case: the built-in liver as a flat model, its low-x tenth pinned
/// and driven at 2 m/s along x (a grasp), the free slots drifting at 1 cm/s, no gravity. Before:
/// `BlowUp` at step 0 naming a pinned slot ("kinetic energy 7.66 exceeds 1.72"); now 10 steps of
/// symplectic Euler and RK4 run, and the pins move at 2 m/s.
#[test]
fn grasped_liver_is_no_runaway() {
    let loaded = load_builtin().unwrap();
    let (points, tets) = (&loaded.mesh.points, &loaded.mesh.tets);
    let lo = points.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
    let pinned: Vec<bool> = points.iter().map(|p| p[0] < lo + 0.1 * (hi - lo)).collect();
    for scheme in [Integrator::Symplectic, Integrator::Rk4] {
        let flat = FlatModel::from_tets(points, tets, Material::default(), [0.0; 3], &pinned).unwrap();
        let (sys, mut x) = (flat.system, flat.position);
        let mut v: Vec<Vec3> = pinned.iter().map(|&p| if p { [2.0, 0.0, 0.0] } else { [0.01, 0.0, 0.0] }).collect();
        let start = x.clone();
        let mut st = Stepper::new(StepConfig::new(scheme, 1e-3), &sys, &x, &v).unwrap();
        for n in 0..10 {
            st.step(&sys, &mut x, &mut v).unwrap_or_else(|e| panic!("{scheme:?} step {n}: {e}"));
        }
        for (i, _) in pinned.iter().enumerate().filter(|(_, &p)| p) {
            assert!(close(x[i][0] - start[i][0], 0.02, 1e-9), "{scheme:?} slot {i}");
        }
    }
}

/// The slot a runaway names is the smallest of the free slots of largest ½ m|v|² (docs/MECHANICS.md
/// §8): two free slots flying apart symmetrically have bitwise equal energies at every step
/// (equal and opposite forces), and the report names slot 0 (a thirty-ninth-sample survivor
/// named the last one on ties).
#[test]
fn a_runaway_tie_names_the_smallest_slot() {
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, false, 0.0).unwrap();
    sys.push_slot(1.0, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, 1e6, 0.0).unwrap();
    let (mut x, mut v) = (vec![[0.0; 3], [1.0, 0.0, 0.0]], vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
    let mut st = Stepper::new(StepConfig::new(Integrator::Euler, 1.0), &sys, &x, &v).unwrap();
    let err = (0..10).find_map(|_| st.step(&sys, &mut x, &mut v).err()).expect("Euler at ω h ≈ 1400 runs away");
    assert_eq!(v[0][0], -v[1][0], "the two energies are equal");
    match err {
        StepError::BlowUp { slot: 0, reason, .. } => assert!(reason.contains("runaway"), "{reason}"),
        other => panic!("{other:?}"),
    }
}

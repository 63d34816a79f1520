//! The run-time dispatched kernels (`mechanics::Kernel`) and the fused RK4 step: every kernel
//! gives the same bits as the portable build, and the fused RK4 gives the same bits as the
//! textbook composition of `accelerations` calls, on the built-in liver and on random systems,
//! serial and on several threads; blow-ups are still reported with their slot.

use topomech::load::load_builtin;
use topomech::mechanics::force::PARALLEL_CHUNK;
use topomech::mechanics::{
    FlatModel, Integrator, Kernel, Material, SpringSystem, StepConfig, StepError, Stepper, SystemError, Vec3,
};

/// A small deterministic generator (64-bit LCG, top bits): uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
    fn vec(&mut self, scale: f64) -> Vec3 {
        [(self.next() - 0.5) * scale, (self.next() - 0.5) * scale, (self.next() - 0.5) * scale]
    }
}

/// A system with a state (positions, velocities).
type Case = (SpringSystem, Vec<Vec3>, Vec<Vec3>);

/// The built-in liver as a flat model (pinned on its low-x tenth), with a perturbed state.
fn liver() -> Case {
    let loaded = load_builtin().expect("built-in mesh loads");
    let (points, tets) = (&loaded.mesh.points, &loaded.mesh.tets);
    let lo = points.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
    let pinned: Vec<bool> = points.iter().map(|p| p[0] < lo + 0.1 * (hi - lo)).collect();
    let flat = FlatModel::from_tets(points, tets, Material::default(), [0.0, 0.0, -9.81], &pinned).unwrap();
    let mut rng = Lcg(7);
    let x = flat.position.iter().map(|p| add(*p, rng.vec(0.05 * (hi - lo)))).collect();
    let v = (0..points.len()).map(|_| rng.vec(0.3)).collect();
    (flat.system, x, v)
}

/// `slots` random slots (a tenth fixed), `springs` random springs between distinct slots, a few
/// of zero length (both ends at the same point) and a few with zero stiffness or damping.
fn random_system(seed: u64, slots: usize, springs: usize) -> Case {
    let mut rng = Lcg(seed);
    let mut sys = SpringSystem::default();
    sys.set_gravity([0.1, -0.2, -9.81]).unwrap();
    let mut x: Vec<Vec3> = (0..slots).map(|_| rng.vec(10.0)).collect();
    let v: Vec<Vec3> = (0..slots).map(|_| rng.vec(2.0)).collect();
    for _ in 0..slots {
        sys.push_slot(0.1 + rng.next(), rng.next() < 0.1, 0.5 * rng.next()).unwrap();
    }
    for s in 0..springs {
        let a = rng.below(slots);
        let b = (a + 1 + rng.below(slots - 1)) % slots;
        if s % 97 == 0 {
            x[b] = x[a]; // zero length: the force must be 0, not NaN
        }
        let k = if s % 13 == 0 { 0.0 } else { 100.0 * rng.next() };
        let c = if s % 7 == 0 { 0.0 } else { rng.next() };
        sys.push_spring([a as u32, b as u32], 2.0 * rng.next(), k, c).unwrap();
    }
    (sys, x, v)
}

/// Like [`random_system`], but built at once by `SpringSystem::new` from springs sorted by first
/// end with a < b (the layout of a fresh `FlatModel`), so RK4 takes the one-pass spring sums.
/// Large enough to be split into several slot ranges on any thread count, with springs that
/// reach over one or more later ranges.
fn sorted_system(seed: u64, slots: usize, springs: usize) -> Case {
    let (random, mut x, v) = random_system(seed, slots, springs);
    let mut order: Vec<usize> = (0..springs).collect();
    let key = |s: usize| {
        let [a, b] = random.ends()[s];
        (a.min(b), a.max(b))
    };
    order.sort_by_key(|&s| key(s));
    let ends: Vec<[u32; 2]> = order.iter().map(|&s| [key(s).0, key(s).1]).collect();
    let pick = |field: &[f64]| order.iter().map(|&s| field[s]).collect::<Vec<f64>>();
    let fixed: Vec<bool> = random.inv_mass().iter().map(|&w| w == 0.0).collect();
    let sys = SpringSystem::new(
        ends,
        pick(random.rest()),
        pick(random.stiffness()),
        pick(random.damping()),
        random.mass().to_vec(),
        &fixed,
        random.viscosity().to_vec(),
        random.gravity(),
    )
    .unwrap();
    x[sys.ends()[0][1] as usize] = x[sys.ends()[0][0] as usize]; // a zero-length spring in the sorted order too
    (sys, x, v)
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn madd(a: Vec3, s: f64, b: Vec3) -> Vec3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

fn bits(a: &[Vec3]) -> Vec<[u64; 3]> {
    a.iter().map(|p| p.map(f64::to_bits)).collect()
}

fn systems() -> Vec<(&'static str, Case)> {
    vec![
        ("liver", liver()),
        ("random", random_system(3, 300, 2000)),
        ("random large", random_system(5, 5000, 9000)),
        ("sorted large", sorted_system(17, 3 * PARALLEL_CHUNK, 40_000)),
    ]
}

#[test]
fn spring_sums_and_the_gather_step_the_same_bits_on_every_kernel_and_thread_count() {
    for (name, (sys, x0, v0)) in systems() {
        let sorted = name == "liver" || name.starts_with("sorted");
        assert_eq!(sys.sorted_by_first_end(), sorted, "{name}");
        let h = 0.2 / sys.omega_max();
        let run = |kernel, threads, sums| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let (mut x, mut v) = (x0.clone(), v0.clone());
                let config = StepConfig { parallel: threads > 1, ..StepConfig::new(Integrator::Rk4, h) };
                let mut stepper = Stepper::new(config, &sys, &x, &v).unwrap();
                stepper.set_kernel(kernel);
                stepper.set_spring_sums(sums);
                assert_eq!(stepper.takes_spring_sums(&sys), sums && sorted, "{name}: the path compared");
                for _ in 0..2 {
                    stepper.step(&sys, &mut x, &mut v).unwrap();
                }
                (bits(&x), bits(&v))
            })
        };
        let reference = run(Kernel::portable(), 1, false);
        assert!(reference.0 != bits(&x0), "{name}: the state must move");
        for kernel in Kernel::available() {
            for threads in [1, 2, 3] {
                let got = run(kernel, threads, true);
                assert!(got == reference, "{name}: sums, kernel {} on {threads} threads", kernel.name());
            }
        }
    }
    // A mutator leaves the order of the packed lists: the stepper falls back to the gather.
    let (mut sys, _, _) = sorted_system(19, 50, 200);
    let (rest, k, c) = (sys.rest()[0], sys.stiffness()[0], sys.damping()[0]);
    sys.set_spring(0, sys.ends()[0], rest, 2.0 * k, c).unwrap();
    assert!(sys.sorted_by_first_end(), "same ends: the lists are untouched");
    sys.swap_remove_spring(0).unwrap();
    assert!(!sys.sorted_by_first_end());
}

#[test]
fn every_kernel_gives_the_portable_forces_bit_for_bit() {
    assert!(Kernel::available().contains(&Kernel::detect()));
    for (name, (sys, x, v)) in systems() {
        let eval = |kernel, parallel| {
            let (mut sf, mut acc) = (vec![[0.0; 3]; sys.springs()], vec![[0.0; 3]; sys.slots()]);
            sys.accelerations_with(kernel, &x, &v, &mut sf, &mut acc, parallel).unwrap();
            (bits(&sf), bits(&acc))
        };
        let reference = eval(Kernel::portable(), false);
        assert!(reference.1.iter().flatten().any(|&b| f64::from_bits(b) != 0.0), "{name}: all zero");
        assert!(reference.0.iter().flatten().all(|&b| f64::from_bits(b).is_finite()), "{name}: non-finite");
        // The portable pass agrees with the one-spring law.
        for (s, &[a, b]) in sys.ends().iter().enumerate().step_by(17) {
            let (a, b) = (a as usize, b as usize);
            let f = topomech::mechanics::force::spring_force(
                x[a],
                x[b],
                v[a],
                v[b],
                sys.rest()[s],
                sys.stiffness()[s],
                sys.damping()[s],
            );
            assert_eq!(f.map(f64::to_bits), reference.0[s], "{name}: spring {s}");
        }
        for kernel in Kernel::available() {
            for parallel in [false, true] {
                assert!(eval(kernel, parallel) == reference, "{name}: kernel {} parallel {parallel}", kernel.name());
            }
        }
    }
}

/// RK4 as four `accelerations` calls and the per-slot combinations, in the documented order.
fn textbook_rk4(sys: &SpringSystem, h: f64, x: &mut [Vec3], v: &mut [Vec3]) {
    let n = x.len();
    let mut sf = vec![[0.0; 3]; sys.springs()];
    let mut a = vec![[0.0; 3]; n];
    sys.accelerations_with(Kernel::portable(), x, v, &mut sf, &mut a, false).unwrap();
    let (mut ax, mut av) = (v.to_vec(), a.clone());
    let mut xs: Vec<Vec3> = (0..n).map(|i| madd(x[i], 0.5 * h, v[i])).collect();
    let mut vs: Vec<Vec3> = (0..n).map(|i| madd(v[i], 0.5 * h, a[i])).collect();
    for c in [0.5 * h, h] {
        sys.accelerations_with(Kernel::portable(), &xs, &vs, &mut sf, &mut a, false).unwrap();
        for i in 0..n {
            ax[i] = madd(ax[i], 2.0, vs[i]);
            av[i] = madd(av[i], 2.0, a[i]);
            xs[i] = madd(x[i], c, vs[i]);
            vs[i] = madd(v[i], c, a[i]);
        }
    }
    sys.accelerations_with(Kernel::portable(), &xs, &vs, &mut sf, &mut a, false).unwrap();
    for i in 0..n {
        x[i] = madd(x[i], h / 6.0, add(ax[i], vs[i]));
        v[i] = madd(v[i], h / 6.0, add(av[i], a[i]));
    }
}

#[test]
fn fused_rk4_equals_the_textbook_composition_for_every_kernel_and_thread_count() {
    for (name, (sys, x0, v0)) in systems() {
        let h = 0.2 / sys.omega_max();
        let (mut x, mut v) = (x0.clone(), v0.clone());
        for _ in 0..3 {
            textbook_rk4(&sys, h, &mut x, &mut v);
        }
        assert!(bits(&x) != bits(&x0), "{name}: the state must move");
        let expected = (bits(&x), bits(&v));
        for kernel in Kernel::available() {
            for (threads, parallel) in [(1, false), (1, true), (2, true), (3, true)] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let got = pool.install(|| {
                    let (mut x, mut v) = (x0.clone(), v0.clone());
                    let config = StepConfig { parallel, ..StepConfig::new(Integrator::Rk4, h) };
                    let mut stepper = Stepper::new(config, &sys, &x, &v).unwrap();
                    stepper.set_kernel(kernel);
                    for _ in 0..3 {
                        stepper.step(&sys, &mut x, &mut v).unwrap();
                    }
                    (bits(&x), bits(&v))
                });
                assert!(got == expected, "{name}: kernel {} on {threads} threads ({parallel})", kernel.name());
            }
        }
    }
    // The large random system spans several slot and spring chunks, so the parallel split runs.
    assert!(random_system(5, 5000, 9000).0.slots() > PARALLEL_CHUNK);
}

#[test]
fn every_integrator_steps_the_same_bits_with_every_kernel() {
    let (sys, x0, v0) = random_system(11, 200, 900);
    let h = 0.1 / sys.omega_max();
    for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
        let run = |kernel| {
            let (mut x, mut v) = (x0.clone(), v0.clone());
            let mut stepper = Stepper::new(StepConfig::new(integrator, h), &sys, &x, &v).unwrap();
            stepper.set_kernel(kernel);
            assert_eq!(stepper.kernel(), kernel);
            for _ in 0..4 {
                stepper.step(&sys, &mut x, &mut v).unwrap();
            }
            (bits(&x), bits(&v))
        };
        let reference = run(Kernel::portable());
        assert!(reference.0 != bits(&x0));
        for kernel in Kernel::available() {
            assert!(run(kernel) == reference, "{integrator:?} with kernel {}", kernel.name());
        }
    }
}

#[test]
fn rk4_reports_a_runaway_at_the_most_energetic_slot_and_a_nan_at_its_slot() {
    let (sys, x0, v0) = random_system(13, 50, 150);
    let h = 0.1 / sys.omega_max();
    let free = (0..sys.slots()).filter(|&i| sys.inv_mass()[i] > 0.0).nth(7).unwrap();
    for kernel in Kernel::available() {
        let (mut x, mut v) = (x0.clone(), v0.clone());
        let mut stepper = Stepper::new(StepConfig::new(Integrator::Rk4, h), &sys, &x, &v).unwrap();
        stepper.set_kernel(kernel);
        stepper.step(&sys, &mut x, &mut v).unwrap();
        let mut kicked = v.clone();
        kicked[free] = [1e9, 0.0, 0.0];
        let (mut xk, mut vk) = (x.clone(), kicked);
        match stepper.clone().step(&sys, &mut xk, &mut vk) {
            Err(StepError::BlowUp { step: 1, slot, reason }) => {
                assert_eq!(slot, free, "{}", kernel.name());
                assert!(reason.contains("runaway"), "{reason}");
            }
            other => panic!("runaway not reported with {}: {other:?}", kernel.name()),
        }
        let last = sys.slots() - 1;
        x[last][1] = f64::INFINITY;
        match stepper.step(&sys, &mut x, &mut v) {
            Err(StepError::BlowUp { step: 1, slot, reason }) => {
                assert!(reason.contains("non-finite"), "{reason}");
                assert!(x[slot].iter().chain(&v[slot]).any(|c| !c.is_finite()));
                assert!((0..slot).all(|i| x[i].iter().chain(&v[i]).all(|c| c.is_finite())), "first bad slot");
            }
            other => panic!("infinity not reported with {}: {other:?}", kernel.name()),
        }
    }
}

/// The runaway law is strict: a kinetic energy *equal* to `runaway_factor` × the starting energy
/// scale is not a blow-up, one just above it is. Two free unit-speed slots of mass 2 with no
/// spring, no gravity and no viscosity keep their kinetic energy 2 exactly under every scheme,
/// and their energy scale is that same 2, so the limit is met with equality at factor 1.
#[test]
fn a_kinetic_energy_at_the_runaway_limit_is_not_a_blow_up() {
    let mut sys = SpringSystem::default();
    sys.set_gravity([0.0; 3]).unwrap();
    for _ in 0..2 {
        sys.push_slot(2.0, false, 0.0).unwrap();
    }
    let x0: Vec<Vec3> = vec![[0.0; 3], [1.0, 0.0, 0.0]];
    let v0: Vec<Vec3> = vec![[1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
    assert_eq!(sys.kinetic_energy(&v0), Ok(2.0));
    let schemes = [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit];
    for (integrator, kernel) in schemes.into_iter().flat_map(|s| Kernel::available().into_iter().map(move |k| (s, k))) {
        let run = |factor: f64| {
            let mut config = StepConfig::new(integrator, 1e-2);
            config.runaway_factor = factor;
            let mut stepper = Stepper::new(config, &sys, &x0, &v0).unwrap();
            stepper.set_kernel(kernel);
            let (mut x, mut v) = (x0.clone(), v0.clone());
            let outcome = stepper.step(&sys, &mut x, &mut v);
            (outcome, v)
        };
        let (at_limit, v) = run(1.0);
        assert_eq!(v, v0, "{integrator:?}: no force, so the velocities stay exactly");
        assert!(at_limit.is_ok(), "{integrator:?} with {}: energy at the limit: {at_limit:?}", kernel.name());
        match run(1.0 - f64::EPSILON).0 {
            Err(StepError::BlowUp { step: 0, reason, .. }) => assert!(reason.contains("runaway"), "{reason}"),
            other => panic!("{integrator:?} with {}: energy above the limit not reported: {other:?}", kernel.name()),
        }
    }
}

/// A chain of `n` unit masses on springs, the first pinned, hanging under gravity.
fn chain(n: usize) -> (SpringSystem, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut sys = SpringSystem::default();
    sys.set_gravity([0.0, 0.0, -10.0]).unwrap();
    for i in 0..n {
        sys.push_slot(1.0, i == 0, 0.1).unwrap();
    }
    for i in 1..n {
        sys.push_spring([(i - 1) as u32, i as u32], 1.0, 100.0, 0.1).unwrap();
    }
    let x = (0..n).map(|i| [0.0, 0.0, -(i as f64)]).collect();
    (sys, x, vec![[0.0; 3]; n])
}

/// Finding 25 (docs/VERIFICATION.md): a stepper given a system of another shape panicked on its
/// buffer sizes, and NaN or negative parameters were only found as a blow-up after the first
/// step (or, for the implicit scheme with a NaN mass, not at all).
#[test]
fn a_stepper_refuses_another_system_and_input_it_cannot_step() {
    for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
        for parallel in [false, true] {
            let config = StepConfig { parallel, ..StepConfig::new(integrator, 1e-3) };
            let (sys, x, v) = chain(4);
            let mut stepper = Stepper::new(config, &sys, &x, &v).unwrap();
            for n in [2, 10] {
                let (other, mut x2, mut v2) = chain(n);
                let before = x2.clone();
                let e = stepper.step(&other, &mut x2, &mut v2).unwrap_err();
                let expected = StepError::OtherSystem { slots: 4, springs: 3, got_slots: n, got_springs: n - 1 };
                assert_eq!(e, expected, "{integrator:?} parallel {parallel}");
                assert_eq!(x2, before);
            }
            let (mut x, mut v) = (x, v);
            stepper.step(&sys, &mut x, &mut v).unwrap(); // its own system still steps
        }
    }
    // Start states the stepper cannot step. (A system with a NaN, negative or misplaced value
    // cannot be made from outside since finding 36: every way in checks; the same refusals of a
    // system broken inside the crate are the unit test `stepper_new_refuses_a_broken_system`.)
    type Tamper = fn(&mut Vec<[f64; 3]>, &mut Vec<[f64; 3]>);
    let cases: [(Tamper, &str); 2] = [
        (|x, _| x[1][2] = f64::NEG_INFINITY, "start position of slot 1"),
        (|_, v| v[3][0] = f64::NAN, "start velocity of slot 3"),
    ];
    for (tamper, expected) in cases {
        let (sys, mut x, mut v) = chain(4);
        tamper(&mut x, &mut v);
        for integrator in [Integrator::Euler, Integrator::Rk4, Integrator::Implicit] {
            match Stepper::new(StepConfig::new(integrator, 1e-3), &sys, &x, &v) {
                Err(StepError::BadInput(text)) => assert!(text.starts_with(expected), "{expected}: {text}"),
                other => panic!("{expected}: {other:?}"),
            }
        }
    }
}

/// Finding 28 (docs/VERIFICATION.md): `SpringSystem`'s constructor and mutators panicked on an
/// array of the wrong length, a spring end past the slots, a spring from a slot to itself or an
/// index past the last slot or spring, and took a NaN mass; its force and energy passes panicked
/// on a short position array, and `kinetic_energy` of a short velocity array silently summed a
/// prefix. Each now returns a `SystemError` naming the array, spring or slot, and changes nothing.
#[test]
fn a_spring_system_refuses_bad_arrays_indices_and_values_and_changes_nothing() {
    let new = |ends: Vec<[u32; 2]>, rest: Vec<f64>, mass: Vec<f64>, fixed: &[bool]| {
        let (s, n) = (ends.len(), mass.len());
        SpringSystem::new(ends, rest, vec![1.0; s], vec![0.0; s], mass, fixed, vec![0.0; n], [0.0; 3])
    };
    fn length<T>(array: &'static str, len: usize, expected: usize, of: &'static str) -> Result<T, SystemError> {
        Err(SystemError::Length { array, len, expected, of })
    }
    assert_eq!(new(vec![[0, 1]], vec![], vec![1.0; 2], &[false; 2]), length("rest length", 0, 1, "springs"));
    assert_eq!(new(vec![[0, 1]], vec![1.0], vec![1.0; 2], &[false; 3]), length("fixed", 3, 2, "slots"));
    assert_eq!(
        new(vec![[0, 1], [1, 5]], vec![1.0; 2], vec![1.0; 2], &[false; 2]),
        Err(SystemError::BadEnds { spring: 1, ends: [1, 5], slots: 2 })
    );
    assert_eq!(
        new(vec![[1, 1]], vec![1.0], vec![1.0; 2], &[false; 2]),
        Err(SystemError::BadEnds { spring: 0, ends: [1, 1], slots: 2 })
    );
    let bad_mass = new(vec![[0, 1]], vec![1.0], vec![1.0, f64::NAN], &[false; 2]);
    assert!(
        matches!(bad_mass, Err(SystemError::BadValue { quantity: "mass", of: "slot", index: 1, .. })),
        "{bad_mass:?}"
    );
    let bad_rest = new(vec![[0, 1]], vec![-1.0], vec![1.0; 2], &[false; 2]);
    assert!(matches!(bad_rest, Err(SystemError::BadValue { quantity: "rest length", index: 0, .. })), "{bad_rest:?}");

    // The mutators: each refusal leaves the system as it was.
    let mut sys = new(vec![[0, 1], [1, 2]], vec![1.0; 2], vec![1.0; 3], &[false; 3]).unwrap();
    let before = sys.clone();
    assert_eq!(sys.push_spring([0, 3], 1.0, 1.0, 0.0), Err(SystemError::BadEnds { spring: 2, ends: [0, 3], slots: 3 }));
    assert_eq!(sys.push_spring([2, 2], 1.0, 1.0, 0.0), Err(SystemError::BadEnds { spring: 2, ends: [2, 2], slots: 3 }));
    assert!(sys.push_spring([0, 2], 1.0, f64::INFINITY, 0.0).is_err());
    assert_eq!(sys.set_slot(3, 1.0, false, 0.0), Err(SystemError::NoSuchSlot { slot: 3, slots: 3 }));
    assert!(sys.set_slot(0, -1.0, false, 0.0).is_err());
    assert_eq!(sys.set_spring(2, [0, 1], 1.0, 1.0, 0.0), Err(SystemError::NoSuchSpring { spring: 2, springs: 2 }));
    assert!(sys.set_spring(0, [0, 9], 1.0, 1.0, 0.0).is_err());
    assert_eq!(sys.swap_remove_spring(2), Err(SystemError::NoSuchSpring { spring: 2, springs: 2 }));
    assert!(sys.push_slot(f64::NAN, false, 0.0).is_err());
    assert!(sys.push_slot(1.0, false, -0.5).is_err());
    assert_eq!(sys, before);
    sys.check_incidence().unwrap();

    // The passes: a state of the wrong length is named and nothing is written.
    let (x, v) = (vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 3.0, 0.0]], vec![[1.0, 0.0, 0.0]; 3]);
    let (mut sf, mut out) = (vec![[7.0; 3]; 2], vec![[7.0; 3]; 3]);
    assert_eq!(sys.spring_forces(&x[..2], &v, &mut sf, false), length("positions", 2, 3, "slots"));
    assert_eq!(sys.forces(&x, &v[..1], &mut sf, &mut out, false), length("velocities", 1, 3, "slots"));
    assert_eq!(sys.forces(&x, &v, &mut sf[..1], &mut out, false), length("spring forces", 1, 2, "springs"));
    assert_eq!(sys.forces(&x, &v, &mut sf, &mut out[..2], false), length("forces", 2, 3, "slots"));
    assert_eq!(sys.accelerations(&x, &v, &mut sf, &mut out[..1], false), length("accelerations", 1, 3, "slots"));
    assert!((sf.clone(), out.clone()) == (vec![[7.0; 3]; 2], vec![[7.0; 3]; 3]), "a refused pass wrote");
    assert_eq!(sys.kinetic_energy(&v[..2]), length("velocities", 2, 3, "slots"));
    assert_eq!(sys.kinetic_energy(&v), Ok(1.5)); // ½ · 1 · 1² over three free slots
    assert_eq!(sys.elastic_energy(&x[..1]), length("positions", 1, 3, "slots"));
    assert_eq!(sys.gravity_energy(&x[..1]), length("positions", 1, 3, "slots"));
    assert_eq!(sys.vertex_force(3, &v, &sf), Err(SystemError::NoSuchSlot { slot: 3, slots: 3 }));
    assert_eq!(sys.incident(3).count(), 0);
    sys.forces(&x, &v, &mut sf, &mut out, false).unwrap();
    assert_eq!(sf[0], [1.0, 0.0, 0.0]); // stretched from 1 to 2 with k = 1: pulled towards b
    assert_eq!(sys.vertex_force(1, &v, &sf), Ok(out[1]));

    // (The arrays were public then; a system broken inside the crate is refused by the passes and
    // `check`: unit test `passes_and_check_refuse_a_system_broken_inside_the_crate`.)
    assert_eq!(sys.check(), Ok(()));

    // The energies count free slots only: a fixed slot has no kinetic or gravitational energy.
    let mut held = sys.clone();
    held.set_gravity([0.0, 0.0, -10.0]).unwrap();
    held.set_slot(2, 1.0, true, 0.0).unwrap();
    let high = [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 100.0]];
    assert_eq!(held.gravity_energy(&high), Ok(10.0 * (1.0 + 2.0))); // m g h of slots 0 and 1
    assert_eq!(held.kinetic_energy(&v), Ok(1.0)); // ½ · 1 · 1² for slots 0 and 1
}

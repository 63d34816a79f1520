//! Round 23 (implicit Euler), findings 208 and 209.
//!
//! 208: the implicit step's conjugate gradient had no preconditioner and stopped at
//! ‖r‖₂ ≤ tol ‖b‖₂, a norm over the whole system in force units: a free slot (or part) whose share
//! of b was below tol of the largest — a light slot beside a heavy one, a lightly loaded slot
//! beside a strongly damped one — was never solved for, and the step returned `Ok` with its Δv
//! 1e10× too small or 0. Now Jacobi-preconditioned, with a stop test in velocity units on every
//! coordinate of every free slot.
//!
//! 209: the right-hand side b = h f₀ − h² K ẋ₀ was formed again in wide floats only when its f64
//! evaluation overflowed; when a term of it underflowed (to 0 or a subnormal) while the forces
//! and Δv are ordinary numbers, the step dropped or distorted every force.
//!
//! Every expected value below is computed independently of the crate: in closed form (one slot,
//! or a 2-slot chain whose coordinates decouple) or by a small dense solve of the backward Euler
//! system assembled here from the formulas of docs/MECHANICS.md §8.

use topomech::mechanics::{Integrator, SpringSystem, StepConfig, Stepper};

mod rng_common;

type V3 = [f64; 3];

/// One implicit step of h from (x, v); the runaway test is off (the laws are about Δv).
fn step(sys: &SpringSystem, h: f64, x: &[V3], v: &[V3]) -> (Vec<V3>, Vec<V3>, usize) {
    let config = StepConfig { runaway_factor: f64::MAX, ..StepConfig::new(Integrator::Implicit, h) };
    let (mut x, mut v) = (x.to_vec(), v.to_vec());
    let mut st = Stepper::new(config, sys, &x, &v).unwrap();
    st.step(sys, &mut x, &mut v).unwrap();
    (x, v, st.last_cg_iterations)
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs()
}

// ---------------------------------------------------------------------------------------------
// Finding 208

/// Two free slots that no spring joins, masses R and 1, under gravity: each is a free particle,
/// and backward Euler gives it Δv = h g whatever its mass (A is diagonal, b = h m g). Before the
/// fix the light slot's Δv was h g / R for R ≥ 1e10 (its b below 1e-10 of the heavy one's).
#[test]
fn f208_an_unconnected_light_slot_falls_beside_a_heavy_one() {
    let (h, g) = (0.01, -9.81);
    for r in [1e10, 1e12, 1e20] {
        for order in [[r, 1.0], [1.0, r]] {
            let mut sys = SpringSystem::default();
            sys.set_gravity([0.0, 0.0, g]).unwrap();
            sys.push_slot(order[0], false, 0.0).unwrap();
            sys.push_slot(order[1], false, 0.0).unwrap();
            let (_, v, _) = step(&sys, h, &[[0.0; 3], [1.0, 0.0, 0.0]], &[[0.0; 3]; 2]);
            for (i, vi) in v.iter().enumerate() {
                assert!(close(vi[2], h * g, 1e-12), "R = {r:e}, masses {order:?}: slot {i} Δv_z {:e}", vi[2]);
                assert_eq!([vi[0], vi[1]], [0.0, 0.0]);
            }
        }
    }
}

/// A slot under gravity beside an unconnected slot whose viscosity dominates its mass (h ν ≫ m)
/// and which moves: b of the damped slot is −h ν v ≈ −1e10, the other's h m g ≈ −0.1. Closed
/// forms: Δv = h g for the free faller, Δv = −h ν v / (m + h ν) for the damped one (the oracle
/// case of round 23 where a slot kept its velocity).
#[test]
fn f208_a_lightly_loaded_slot_beside_a_strongly_damped_one_is_solved() {
    let (h, g, nu, vx) = (0.01, -9.81, 1e14, 3.0);
    let mut sys = SpringSystem::default();
    sys.set_gravity([0.0, 0.0, g]).unwrap();
    sys.push_slot(1.0, false, 0.0).unwrap();
    sys.push_slot(1.0, false, nu).unwrap();
    let (_, v, _) = step(&sys, h, &[[0.0; 3], [1.0, 0.0, 0.0]], &[[0.0; 3], [vx, 0.0, 0.0]]);
    assert!(close(v[0][2], h * g, 1e-12), "free faller Δv_z {:e}", v[0][2]);
    let damped = -h * nu * vx / (1.0 + h * nu);
    assert!(close(v[1][0] - vx, damped, 1e-12), "damped slot Δv_x {:e} vs {damped:e}", v[1][0] - vx);
    let fall = h * g / (1.0 + h * nu);
    assert!(close(v[1][2], fall, 1e-9), "damped slot Δv_z {:e} vs {fall:e}", v[1][2]);
}

/// A hanging chain: a fixed anchor at the origin, a heavy slot (mass M) 1 below it, a light one
/// (mass 1) 1 below that, springs of rest length 1 and stiffness k (at rest, so no transverse
/// stiffness and the vertical coordinates decouple), gravity. Backward Euler's vertical system
/// is the 2×2 [[M + 2h²k, −h²k], [−h²k, 1 + h²k]] Δv = h g [M, 1], solved here by Cramer's rule
/// (no cancellation: every product has the sign of its sum). The light slot is coupled to the
/// heavy one and its b is 1/M of the heavy one's: before the fix it kept Δv ≈ 0.
#[test]
fn f208_a_light_slot_hanging_from_a_heavy_one_is_solved() {
    let (h, g, k) = (0.01, -9.81, 100.0);
    for heavy in [1e10, 1e12, 1e20] {
        let mut sys = SpringSystem::default();
        sys.set_gravity([0.0, 0.0, g]).unwrap();
        sys.push_slot(1.0, true, 0.0).unwrap();
        sys.push_slot(heavy, false, 0.0).unwrap();
        sys.push_slot(1.0, false, 0.0).unwrap();
        sys.push_spring([0, 1], 1.0, k, 0.0).unwrap();
        sys.push_spring([1, 2], 1.0, k, 0.0).unwrap();
        let x = [[0.0; 3], [0.0, 0.0, -1.0], [0.0, 0.0, -2.0]];
        let (_, v, _) = step(&sys, h, &x, &[[0.0; 3]; 3]);
        let s = h * h * k;
        let (a11, a12, a22) = (heavy + 2.0 * s, -s, 1.0 + s);
        let (b1, b2) = (h * g * heavy, h * g);
        let det = a11 * a22 - a12 * a12;
        let (dv1, dv2) = ((b1 * a22 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det);
        assert!(close(v[2][2], dv2, 1e-10), "M = {heavy:e}: light Δv_z {:e} vs {dv2:e}", v[2][2]);
        assert!(close(v[1][2], dv1, 1e-10), "M = {heavy:e}: heavy Δv_z {:e} vs {dv1:e}", v[1][2]);
        assert!(v.iter().all(|vi| vi[0] == 0.0 && vi[1] == 0.0), "{v:?}");
    }
}

/// A deterministic generator (xorshift64*, `rng_common`).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        rng_common::next_unit(&mut self.0)
    }
}

/// A small system: slot i of mass `masses[i]` (None: fixed), viscosity, springs (a, b, rest, k, c).
struct Case {
    masses: Vec<Option<f64>>,
    nu: Vec<f64>,
    springs: Vec<(usize, usize, f64, f64, f64)>,
    gravity: V3,
    x: Vec<V3>,
    v: Vec<V3>,
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Backward Euler's Δv for `case` at step h, assembled densely from MECHANICS.md §8 (A = M +
/// h(Γ + C) + h² K over the free slots, K_s = k n nᵀ + k max(0, 1 − L/l)(I − n nᵀ), C_s = c n nᵀ;
/// b = h f₀ − h² K ẋ₀ with f₀ = Σ springs (k (l − L) + c n·(ẋ_b − ẋ_a)) n at a, minus at b,
/// plus m g − ν ẋ) and solved by Gaussian elimination with partial pivoting on the rows divided
/// by their diagonal entries (so that a light slot's row is as exact as a heavy one's).
#[allow(clippy::needless_range_loop)]
fn dense_dv(case: &Case, h: f64) -> Vec<V3> {
    let n = case.masses.len();
    let free: Vec<usize> = (0..n).filter(|&i| case.masses[i].is_some()).collect();
    let col = |i: usize| free.iter().position(|&f| f == i);
    let dim = 3 * free.len();
    let mut a = vec![vec![0.0; dim]; dim];
    let mut f0: Vec<V3> = (0..n)
        .map(|i| {
            let m = case.masses[i].unwrap_or(0.0);
            [0, 1, 2].map(|j| m * case.gravity[j] - case.nu[i] * case.v[i][j])
        })
        .collect();
    let mut kv = vec![[0.0; 3]; n]; // K ẋ₀
    for (fi, &i) in free.iter().enumerate() {
        for j in 0..3 {
            a[3 * fi + j][3 * fi + j] += case.masses[i].unwrap() + h * case.nu[i];
        }
    }
    for &(sa, sb, rest, k, c) in &case.springs {
        let d = sub(case.x[sb], case.x[sa]);
        let l = dot(d, d).sqrt();
        let nn = d.map(|t| t / l);
        let kt = k * (1.0 - rest / l).max(0.0);
        let force = k * (l - rest) + c * dot(nn, sub(case.v[sb], case.v[sa]));
        for j in 0..3 {
            f0[sa][j] += force * nn[j];
            f0[sb][j] -= force * nn[j];
        }
        let block = |p: usize, q: usize| (k - kt) * nn[p] * nn[q] + if p == q { kt } else { 0.0 };
        let damp = |p: usize, q: usize| c * nn[p] * nn[q];
        let w = sub(case.v[sb], case.v[sa]);
        for p in 0..3 {
            let kw: f64 = (0..3).map(|q| block(p, q) * w[q]).sum();
            kv[sa][p] -= kw;
            kv[sb][p] += kw;
        }
        for (r1, r2, sign) in [(sa, sa, 1.0), (sb, sb, 1.0), (sa, sb, -1.0), (sb, sa, -1.0)] {
            if let (Some(c1), Some(c2)) = (col(r1), col(r2)) {
                for p in 0..3 {
                    for q in 0..3 {
                        a[3 * c1 + p][3 * c2 + q] += sign * (h * h * block(p, q) + h * damp(p, q));
                    }
                }
            }
        }
    }
    let mut b: Vec<f64> = free.iter().flat_map(|&i| [0, 1, 2].map(|j| h * f0[i][j] - h * h * kv[i][j])).collect();
    for r in 0..dim {
        let d = a[r][r];
        a[r].iter_mut().for_each(|t| *t /= d);
        b[r] /= d;
    }
    for c in 0..dim {
        let piv = (c..dim).max_by(|&p, &q| a[p][c].abs().total_cmp(&a[q][c].abs())).unwrap();
        a.swap(c, piv);
        b.swap(c, piv);
        for r in c + 1..dim {
            let f = a[r][c] / a[c][c];
            for t in c..dim {
                a[r][t] -= f * a[c][t];
            }
            b[r] -= f * b[c];
        }
    }
    let mut y = vec![0.0; dim];
    for r in (0..dim).rev() {
        let s: f64 = (r + 1..dim).map(|t| a[r][t] * y[t]).sum();
        y[r] = (b[r] - s) / a[r][r];
    }
    let mut dv = vec![[0.0; 3]; n];
    for (fi, &i) in free.iter().enumerate() {
        dv[i] = [y[3 * fi], y[3 * fi + 1], y[3 * fi + 2]];
    }
    dv
}

/// A connected cluster of 7 slots (slot 0 fixed) whose masses span 1 to 1e12, with stretched
/// and compressed springs, damping, viscosity, random velocities and gravity.
fn mixed_masses(seed: u64) -> Case {
    let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let exps = [0, 12, 3, 10, 0, 8, 11];
    let masses: Vec<Option<f64>> =
        exps.iter().enumerate().map(|(i, &e)| (i > 0).then(|| 10f64.powi(e) * (0.5 + r.unit()))).collect();
    let n = masses.len();
    let nu = (0..n).map(|i| if i % 3 == 1 { r.unit() } else { 0.0 }).collect();
    let x: Vec<V3> = (0..n).map(|_| [3.0 * r.unit(), r.unit(), r.unit()]).collect();
    let mut springs = vec![];
    for i in 1..n {
        for j in [i - 1, (i * 5 + 3) % i] {
            let d = sub(x[i], x[j]);
            let rest = dot(d, d).sqrt() * (0.7 + 0.6 * r.unit());
            let c = if r.unit() < 0.5 { 0.0 } else { r.unit() };
            springs.push((j, i, rest, 1.0 + 100.0 * r.unit(), c));
        }
    }
    let v = (0..n).map(|_| [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5]).collect();
    Case { masses, nu, springs, gravity: [0.0, 0.0, -9.81], x, v }
}

/// The cluster's Δv against the dense solve: every coordinate of every free slot within 1e-8 of
/// the largest |Δv| (the stop test's measure, in velocity units). The light slots' share of b
/// is about 1e-12 of the heavy ones': before the fix they kept Δv ≈ 0 where the exact one is
/// about h g.
#[test]
fn f208_a_connected_cluster_of_light_and_heavy_slots_is_solved() {
    let h = 0.01;
    for seed in 1..=12 {
        let case = mixed_masses(seed);
        let mut sys = SpringSystem::default();
        sys.set_gravity(case.gravity).unwrap();
        for (m, nu) in case.masses.iter().zip(&case.nu) {
            sys.push_slot(m.unwrap_or(1.0), m.is_none(), *nu).unwrap();
        }
        for &(a, b, rest, k, c) in &case.springs {
            sys.push_spring([a as u32, b as u32], rest, k, c).unwrap();
        }
        let (_, v, _) = step(&sys, h, &case.x, &case.v);
        let exact = dense_dv(&case, h);
        let scale = exact.iter().flatten().fold(0.0f64, |m, t| m.max(t.abs()));
        for i in 1..case.masses.len() {
            for j in 0..3 {
                let got = v[i][j] - case.v[i][j];
                let slack = 1e-8 * scale + 4.0 * f64::EPSILON * case.v[i][j].abs();
                assert!(
                    (got - exact[i][j]).abs() <= slack,
                    "seed {seed} slot {i} (mass {:e}) coordinate {j}: Δv {got:e} vs {:e}",
                    case.masses[i].unwrap(),
                    exact[i][j]
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Finding 209

/// A slot pinned at the origin and a free slot of mass m on a spring (rest 1, stiffness k)
/// stretched to length 1.5, at rest: one implicit step of h. Δvₓ = h f / (m + h² k) with
/// f = −k/2; Δv_y = Δv_z = 0.
fn stretched(m: f64, k: f64, h: f64) -> V3 {
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(m, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, k, 0.0).unwrap();
    let (_, v, _) = step(&sys, h, &[[0.0; 3], [1.5, 0.0, 0.0]], &[[0.0; 3]; 2]);
    v[1]
}

/// h f = −5e-351 underflows to 0 in f64 while Δvₓ = (h / m)(−k/2) / (1 + h² k / m) ≈ −5e-51
/// (h² k / m = 1e-200 is below an ulp of 1, so Δvₓ = −(h / m)(k / 2) to rounding). Before the
/// fix: Δv = 0, 0 iterations, `Ok`.
#[test]
fn f209_a_right_hand_side_that_underflows_to_zero_is_solved() {
    let (m, k, h) = (1e-300, 1e-200, 1e-150);
    let v = stretched(m, k, h);
    let exact = -(h / m) * (k / 2.0);
    assert!(close(v[0], exact, 1e-12), "Δvₓ {:e} vs {exact:e}", v[0]);
    assert_eq!([v[1], v[2]], [0.0, 0.0]);
}

/// h f = 9.88e-324 · (−0.3) rounds to the subnormal −4.94e-324 (67 % off) while
/// Δvₓ = h f / (m + h² k) = −0.3 h / m ≈ −2.96e-24 (h² k underflows against m = 1e-300 and is
/// below an ulp of it anyway; h / m of a subnormal h is correctly rounded).
#[test]
fn f209_a_subnormal_right_hand_side_is_solved() {
    for (m, k, h) in [(1e-300, 0.6, 1e-323), (1e-300, 1.0, 1e-323), (1e-290, 0.6, 3e-320)] {
        let v = stretched(m, k, h);
        let exact = -(h / m) * (k / 2.0);
        assert!(close(v[0], exact, 1e-12), "m {m:e} k {k:e} h {h:e}: Δvₓ {:e} vs {exact:e}", v[0]);
    }
}

/// A light slot on a weak spring, at its rest length, under gravity (round 23's oracle case
/// m3-162): b = h m g ≈ −1e-459 underflows to 0; the spring has no transverse stiffness at rest,
/// so the slot falls freely: Δv_z = h g.
#[test]
fn f209_a_light_slot_under_gravity_at_a_tiny_step_falls() {
    let (m, k, h, g) = (1e-300, 1e-300, 1e-160, -9.81);
    let mut sys = SpringSystem::default();
    sys.set_gravity([0.0, 0.0, g]).unwrap();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(m, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, k, 0.0).unwrap();
    let (_, v, _) = step(&sys, h, &[[0.0; 3], [1.0, 0.0, 0.0]], &[[0.0; 3]; 2]);
    assert!(close(v[1][2], h * g, 1e-12), "Δv_z {:e} vs {:e}", v[1][2], h * g);
    assert_eq!([v[1][0], v[1][1]], [0.0, 0.0]);
}

/// A product of K ẋ₀ that underflows while b is normal: a slot at rest length moving along its
/// spring at vₓ = 1e-20, k = 1e-300, so k vₓ = 1e-320 is subnormal (11 bits), and h² k vₓ
/// (h = 1e10) is 1e-300. Backward Euler: Δvₓ = −vₓ h² k / (m + h² k) (no force at rest).
/// Before the fix Δvₓ was off by about 5e-5 of itself.
#[test]
fn f209_a_stiffness_product_that_underflows_is_solved() {
    let (m, k, h, vx) = (1e-300, 1e-300, 1e10, 1e-20);
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(m, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, k, 0.0).unwrap();
    let (_, v, _) = step(&sys, h, &[[0.0; 3], [1.0, 0.0, 0.0]], &[[0.0; 3], [vx, 0.0, 0.0]]);
    let hhk = h * h * k;
    let exact = -vx * hhk / (m + hhk);
    assert!(close(v[1][0] - vx, exact, 1e-10), "Δvₓ {:e} vs {exact:e}", v[1][0] - vx);
}

/// The scaling law where b underflows: the stretched spring with m = 2^e and k = 1e100 · 2^e
/// at h = 1e-150 is the unit system (m = 1, k = 1e100) with every force, b and A term times 2^e
/// exactly, so its step must be the unit one's bit for bit — for e down to −1000, where
/// h f ≈ 5e-51 · 2^e is far below f64's range (before the fix: Δv = 0 from 2^-700 or so on).
#[test]
fn f209_a_scaled_system_whose_right_hand_side_underflows_steps_as_the_unit_one() {
    let h = 1e-150;
    let unit = stretched(1.0, 1e100, h);
    assert!(close(unit[0], -0.5e100 * h, 1e-15), "{unit:?}");
    for e in [-700, -800, -900, -997, -1000] {
        let s = 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
        let v = stretched(s, 1e100 * s, h);
        assert_eq!(v.map(f64::to_bits), unit.map(f64::to_bits), "2^{e}: {v:?} vs {unit:?}");
    }
}

/// The diagonal m + h ν is "the plain formula with an unbounded exponent, rounded once": a system
/// scaled by 2^-1022, where h ν' falls below the normal range while m' + h ν' does not, steps bit
/// for bit as the unit one (mutation sample 42: taking the plain sum whenever ν ≠ 0 rounds h ν'
/// to the subnormal grid first, and about one case in thirteen then differs in the last bit).
#[test]
fn viscosity_whose_h_nu_is_subnormal_keeps_the_scaled_bits() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let scale = 2f64.powi(-1022);
    let system = |s: f64, m: f64, nu: f64| {
        let mut sys = SpringSystem::default();
        sys.set_gravity([0.0, 0.0, -1024.0]).unwrap();
        sys.push_slot(s, true, 0.0).unwrap();
        sys.push_slot(m * s, false, nu * s).unwrap();
        sys.push_spring([0, 1], 1.0, s, 0.0).unwrap();
        sys
    };
    let (x, v) = (vec![[0.0; 3], [0.0, 0.0, -1.0]], vec![[0.0; 3]; 2]);
    for _ in 0..200 {
        // m and ν with few bits (so m 2^-1022 and ν 2^-1022 are exact), h with many.
        let m = 1.0 + (next() * 1048576.0).floor() / 1048576.0;
        let nu = (1.0 + (next() * 1048576.0).floor()) / 1048576.0 * 8.0;
        let h = 0.01 + 0.89 * next();
        let (_, unit, _) = step(&system(1.0, m, nu), h, &x, &v);
        let (_, scaled, _) = step(&system(scale, m, nu), h, &x, &v);
        assert_eq!(unit[1].map(f64::to_bits), scaled[1].map(f64::to_bits), "m {m} ν {nu} h {h}");
    }
}

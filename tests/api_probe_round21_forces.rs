//! Round 21, finding C-F1: the branch-free spring scale s = [k (l − L) l + c (dv·d)] / l² kept its
//! plain result for every l² in [2⁻⁴⁹⁸, 2⁵⁰⁰], where the numerator, the damping product or the
//! quotient can still over- or underflow for extreme but accepted k, L, c or dv (±∞ and NaN, or 0,
//! where the force is an ordinary number). These tests compare every pass against an oracle of
//! their own: exact power-of-two rescaling of d and dv, k, L and c split into mantissa and
//! exponent, the formula evaluated in `f64` on the scaled values (the plain operation order), the
//! exponents added back with one rounding.

use topomech::generate::kuhn_cube;
use topomech::mechanics::force::spring_force;
use topomech::mechanics::{forces_by_coverage, Body, Integrator, Kernel, Material, SpringSystem, StepConfig, Stepper};

type Vec3 = [f64; 3];

/// The smallest positive subnormal, 2⁻¹⁰⁷⁴.
const TINY: f64 = 5e-324;

/// e with 2^e ≤ |x| < 2^(e+1), x finite and nonzero (subnormals included).
fn expo(x: f64) -> i32 {
    let biased = ((x.abs().to_bits() >> 52) & 0x7ff) as i32;
    if biased == 0 {
        expo(x * 2f64.powi(64)) - 64
    } else {
        biased - 1023
    }
}

/// x · 2^e rounded once (to nearest, ties to even), for any finite x and any e.
fn pow2(x: f64, e: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let ex = expo(x);
    let m = x.abs() / 2f64.powi(ex) * x.signum(); // exact: a power of two (normal for |ex| ≤ 1022)
    let m = if ex < -1022 { x * 2f64.powi(64) / 2f64.powi(ex + 64) } else { m };
    let t = ex as i64 + e as i64;
    if t > 1023 {
        return f64::INFINITY * x.signum();
    }
    if t >= -1022 {
        return m * f64::from_bits(((t + 1023) as u64) << 52);
    }
    if t < -1080 {
        return 0.0 * x.signum();
    }
    // subnormal: the integer multiple of 2⁻¹⁰⁷⁴, rounded once
    let y = m * 2f64.powi((t + 1074) as i32); // exact: |m| in [1, 2), t + 1074 in [-6, 52)
    y.round_ties_even() * TINY
}

/// One spring as the tests pose it: d = x_b − x_a, dv = v_b − v_a, its parameters, and whether the
/// rest length is the measured length (then l − L is exactly 0).
#[derive(Clone, Copy, Debug)]
struct Case {
    d: Vec3,
    dv: Vec3,
    rest: f64,
    k: f64,
    c: f64,
    at_rest: bool,
}

/// The oracle (module docs): F on end a.
fn oracle(s: &Case) -> Vec3 {
    let dm = s.d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if dm == 0.0 {
        return [0.0; 3];
    }
    let a = -expo(dm);
    let dp = s.d.map(|x| pow2(x, a)); // exact: the components are within 2^1000 of the largest
    let l2p = dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2];
    let lp = l2p.sqrt();
    // (l − L) = dm · 2^de
    let (dlm, dle) = if s.at_rest {
        (0.0, 0)
    } else {
        let rp = pow2(s.rest, a);
        if rp.abs() <= 2f64.powi(900) {
            (lp - rp, -a)
        } else {
            (-s.rest, 0) // l below 2^-900 L: l − L rounds to −L
        }
    };
    // elastic term k (l − L) l = em · 2^ee
    let (em, ee) = if s.k == 0.0 || dlm == 0.0 {
        (0.0, 0)
    } else {
        let ek = expo(s.k);
        ((pow2(s.k, -ek) * dlm) * lp, ek + dle - a)
    };
    // damping term c (dv·d) = cm · 2^ce
    let vm = s.dv.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (cm, ce) = if s.c == 0.0 || vm == 0.0 {
        (0.0, 0)
    } else {
        let b = -expo(vm);
        let dvp = s.dv.map(|x| pow2(x, b));
        let dot = dvp[0] * dp[0] + dvp[1] * dp[1] + dvp[2] * dp[2];
        let ec = expo(s.c);
        (pow2(s.c, -ec) * dot, ec - b - a)
    };
    // numerator nm · 2^ne
    let (nm, ne) = if em == 0.0 {
        (cm, ce)
    } else if cm == 0.0 {
        (em, ee)
    } else {
        let top = (ee + expo(em)).max(ce + expo(cm));
        (pow2(em, ee - top) + pow2(cm, ce - top), top)
    };
    // s = nm 2^ne / (l2p 2^-2a); F_k = s d_k = (nm / l2p) dp_k 2^(ne + a)
    let q = nm / l2p;
    dp.map(|x| pow2(q * x, ne + a))
}

/// Asserts `got` is the oracle's `want` to a few ulps of |want| where that is normal, and exactly
/// 0 or ±∞ only where the oracle says so (up to one subnormal step for a rounding tie).
fn assert_close(got: Vec3, want: Vec3, what: &str) {
    let size = want.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for k in 0..3 {
        let (g, w) = (got[k], want[k]);
        assert!(!g.is_nan(), "{what}: component {k} is NaN: got {got:?}, want {want:?}");
        if w.is_infinite() || g.is_infinite() {
            assert_eq!(g, w, "{what}: component {k}: got {got:?}, want {want:?}");
            continue;
        }
        let tol = 16.0 * f64::EPSILON * size + 2.0 * TINY;
        assert!((g - w).abs() <= tol, "{what}: component {k}: got {got:?}, want {want:?}");
        if w.abs() > TINY {
            assert!(g != 0.0, "{what}: component {k} is 0: got {got:?}, want {want:?}");
        }
    }
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A direction with all three components of comparable size (none below 0.1).
    fn direction(&mut self) -> Vec3 {
        let u = [0, 1, 2].map(|_| {
            let x = 0.1 + 0.9 * self.next();
            if self.next() < 0.5 {
                -x
            } else {
                x
            }
        });
        let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        u.map(|x| x / n)
    }
}

/// The length the library measures for a rest length (`mechanics::geom::rest_length`): the plain
/// √(Σ dₖ²) for a largest component in [2⁻²⁵⁰, 2²⁵⁰], else `mesh::distance`.
fn measured(d: Vec3) -> f64 {
    let largest = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if (5.527147875260445e-76..=1.8092513943330656e75).contains(&largest) {
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    } else {
        topomech::mesh::distance(d, [0.0; 3])
    }
}

/// The grid of the finding: l = 1.37 · 10^e for e = −320 … 300 step 5, rest ∈ {0, l/2, l, 2l,
/// 1e-300, 1, 1e300}, k ∈ {1e-200, 1, 3, 1e200}, c ∈ {0, 0.5}; random directions, a unit relative
/// velocity whose damping adds to the elastic force (no cancellation).
fn grid() -> Vec<Case> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut cases = Vec::new();
    for e in (-320..=300).step_by(5) {
        let l = 1.37 * 10f64.powi(e);
        if l == 0.0 || !l.is_finite() {
            continue;
        }
        let u = rng.direction();
        let d = u.map(|x| x * l);
        if d.iter().all(|&x| x == 0.0) {
            continue;
        }
        let lm = measured(d);
        for (rest, at_rest) in [
            (0.0, false),
            (lm / 2.0, false),
            (lm, true),
            (2.0 * lm, false),
            (1e-300, false),
            (1.0, false),
            (1e300, false),
        ] {
            let w = rng.direction();
            let side = (lm - rest).signum() * (w[0] * u[0] + w[1] * u[1] + w[2] * u[2]).signum();
            let dv = w.map(|x| x * side);
            for k in [1e-200, 1.0, 3.0, 1e200] {
                for c in [0.0, 0.5] {
                    cases.push(Case { d, dv, rest, k, c, at_rest });
                }
            }
        }
    }
    cases
}

/// The finding's single cases and more damping extremes.
fn extremes() -> Vec<Case> {
    let x = |l: f64| [l, 0.0, 0.0];
    let case = |d: Vec3, dv: Vec3, rest: f64, k: f64, c: f64| Case { d, dv, rest, k, c, at_rest: false };
    vec![
        case(x(1e10), [0.0; 3], 1e300, 1.0, 0.0),
        case(x(1e-70), [0.0; 3], 1e300, 1.0, 0.0),
        case(x(1e-70), [0.0; 3], 0.0, 1e-200, 0.0),
        case(x(1.37e-60), [0.0; 3], 0.0, 1e-200, 0.0),
        case(x(1e60), [0.0; 3], 0.0, 1e200, 0.0),
        case(x(1e70), [1e260, 0.0, 0.0], 1e70, 0.0, 1.0),
        case(x(1e-70), [1e-250, 0.0, 0.0], 1e-70, 0.0, 1.0), // c (dv·d) = 1e-320, a subnormal
        case(x(1e-70), [1e-300, 0.0, 0.0], 1e-70, 0.0, 1e300),
        case([1e-70, 2e-70, -3e-70], [1e-250, -1e-250, 1e-250], 1e-70, 1.0, 1e200),
        case([1e70, 2e70, -3e70], [1e300, 1e300, -1e300], 2e70, 1e-300, 1e-80),
        case([3.0, 4.0, 0.0], [0.0, 0.0, 1e308], 5.0, 1.0, 1.0), // dv ⟂ d: no damping force
        case([3.0, 4.0, 0.0], [1e308, 1e308, 0.0], 1.0, 1.0, 0.0), // dv·d overflows, times c = 0
        case([3.0, 4.0, 0.0], [1e-310, 0.0, 0.0], 5.0, 1.0, 1e300), // subnormal dv, at rest
    ]
}

/// The grid cases (first) and the extremes (after them).
fn all_cases() -> Vec<Case> {
    let mut all = grid();
    all.extend(extremes());
    all
}

fn force_of(s: &Case) -> Vec3 {
    spring_force([0.0; 3], s.d, [0.0; 3], s.dv, s.rest, s.k, s.c)
}

#[test]
fn spring_force_matches_the_rescaling_oracle_over_the_grid_and_the_extremes() {
    let mut bad = Vec::new();
    for s in all_cases() {
        let (got, want) = (force_of(&s), oracle(&s));
        if std::panic::catch_unwind(|| assert_close(got, want, "spring_force")).is_err() {
            bad.push(format!("{s:?}: got {got:?}, want {want:?}"));
        }
    }
    assert!(bad.is_empty(), "{} cases differ from the oracle, e.g.\n{}", bad.len(), bad[..bad.len().min(8)].join("\n"));
}

#[test]
fn the_cases_of_the_finding_give_the_true_force() {
    let still = [0.0; 3];
    assert_eq!(spring_force(still, [1e10, 0.0, 0.0], still, still, 1e300, 1.0, 0.0), [-1e300, 0.0, 0.0]);
    assert_eq!(spring_force(still, [1e-70, 0.0, 0.0], still, still, 1e300, 1.0, 0.0), [-1e300, 0.0, 0.0]);
    let f = spring_force(still, [1e-70, 0.0, 0.0], still, still, 0.0, 1e-200, 0.0);
    assert!((f[0] / 1e-270 - 1.0).abs() < 1e-15 && f[1] == 0.0 && f[2] == 0.0, "{f:?}");
    let f = spring_force(still, [1e60, 0.0, 0.0], still, still, 0.0, 1e200, 0.0);
    assert!((f[0] / 1e260 - 1.0).abs() < 1e-15 && f[1] == 0.0 && f[2] == 0.0, "{f:?}");
    let f = spring_force(still, [1e70, 0.0, 0.0], still, [1e260, 0.0, 0.0], 1e70, 0.0, 1.0);
    assert!((f[0] / 1e260 - 1.0).abs() < 1e-15 && f[1] == 0.0 && f[2] == 0.0, "{f:?}");
    let f = spring_force(still, [1e-70, 0.0, 0.0], still, [1e-250, 0.0, 0.0], 1e-70, 0.0, 1.0);
    assert!((f[0] / 1e-250 - 1.0).abs() < 1e-15 && f[1] == 0.0 && f[2] == 0.0, "{f:?}");
    // an ordinary spring keeps its bits
    assert_eq!(spring_force(still, [3.0, 0.0, 0.0], still, still, 1.0, 5.0, 0.0), [10.0, 0.0, 0.0]);
    assert_eq!(spring_force(still, [3.0, 0.0, 0.0], [1.0, 0.0, 0.0], still, 3.0, 5.0, 0.5), [-0.5, 0.0, 0.0]);
}

/// An ordinary spring: l = 1.5 along a random direction, k = 2, L = 1, c = 0.25.
fn ordinary(rng: &mut Rng) -> Case {
    let (u, w) = (rng.direction(), rng.direction());
    Case { d: u.map(|x| 1.5 * x), dv: w, rest: 1.0, k: 2.0, c: 0.25, at_rest: false }
}

/// A system of `springs.len()` independent springs, spring i between slots 2i and 2i + 1 (a at
/// the origin, at rest; b at d moving with dv), unit masses, no viscosity or gravity.
fn system(springs: &[Case]) -> (SpringSystem, Vec<Vec3>, Vec<Vec3>) {
    let n = springs.len();
    let ends = (0..n as u32).map(|i| [2 * i, 2 * i + 1]).collect();
    let sys = SpringSystem::new(
        ends,
        springs.iter().map(|s| s.rest).collect(),
        springs.iter().map(|s| s.k).collect(),
        springs.iter().map(|s| s.c).collect(),
        vec![1.0; 2 * n],
        &vec![false; 2 * n],
        vec![0.0; 2 * n],
        [0.0; 3],
    )
    .expect("the system builds");
    let x = springs.iter().flat_map(|s| [[0.0; 3], s.d]).collect();
    let v = springs.iter().flat_map(|s| [[0.0; 3], s.dv]).collect();
    (sys, x, v)
}

/// The grid cut into systems of `n` springs, every third spring an ordinary one, so that extreme
/// and ordinary springs share 4-lane groups and every lane position and remainder is hit.
fn mixed_systems(n: usize) -> Vec<Vec<Case>> {
    let mut rng = Rng(n as u64 * 7919 + 1);
    let mut cases = all_cases().into_iter();
    let mut out = Vec::new();
    loop {
        let mut springs = Vec::with_capacity(n);
        for j in 0..n {
            if j % 3 == 1 {
                springs.push(ordinary(&mut rng));
            } else if let Some(s) = cases.next() {
                springs.push(s);
            }
        }
        if springs.iter().all(|s| s.k == 2.0 && s.c == 0.25) {
            break;
        }
        while springs.len() < n {
            springs.push(ordinary(&mut rng));
        }
        out.push(springs);
    }
    out
}

#[test]
fn every_spring_pass_gives_the_oracle_force_for_systems_of_1_5_and_67_springs() {
    let bits = |f: &[Vec3]| f.iter().map(|v| v.map(f64::to_bits)).collect::<Vec<_>>();
    let mut bad = Vec::new();
    for n in [1, 5, 67] {
        for springs in mixed_systems(n) {
            let (sys, x, v) = system(&springs);
            let single: Vec<Vec3> = springs.iter().map(force_of).collect();
            for (i, s) in springs.iter().enumerate() {
                let want = oracle(s);
                if std::panic::catch_unwind(|| assert_close(single[i], want, "spring_force")).is_err() {
                    bad.push(format!("n = {n}, spring {i} {s:?}: got {:?}, want {want:?}", single[i]));
                }
            }
            for parallel in [false, true] {
                let mut sf = vec![[0.0; 3]; n];
                sys.spring_forces(&x, &v, &mut sf, parallel).unwrap();
                assert_eq!(bits(&sf), bits(&single), "spring_forces, n = {n}, parallel = {parallel}");
                for kernel in Kernel::available() {
                    let mut sk = vec![[0.0; 3]; n];
                    sys.spring_forces_with(kernel, &x, &v, &mut sk, parallel).unwrap();
                    assert_eq!(bits(&sk), bits(&single), "{} kernel, n = {n}, parallel = {parallel}", kernel.name());
                }
                let mut out = vec![[0.0; 3]; 2 * n];
                sys.forces(&x, &v, &mut sf, &mut out, parallel).unwrap();
                for (i, f) in single.iter().enumerate() {
                    assert_eq!(out[2 * i], f.map(|c| 0.0 + c), "forces at a, n = {n}, spring {i}");
                    assert_eq!(out[2 * i + 1], f.map(|c| 0.0 - c), "forces at b, n = {n}, spring {i}");
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{} springs differ from the oracle, e.g.\n{}",
        bad.len(),
        bad[..bad.len().min(8)].join("\n")
    );
}

#[test]
fn rk4_moves_the_formerly_forceless_springs_by_their_true_force() {
    // k = 1e-200 and rest 0 at 1e-75 ≤ l ≤ 1e-60: F = k l (1e-275 … 1e-260), a normal f64 the plain
    // path rounded to 0 or a few-bit subnormal; mixed with ordinary springs in the same groups.
    let mut rng = Rng(21);
    let mut springs = Vec::new();
    for e in -75..=-60 {
        let u = rng.direction();
        springs.push(Case {
            d: u.map(|x| x * 10f64.powi(e)),
            dv: [0.0; 3],
            rest: 0.0,
            k: 1e-200,
            c: 0.0,
            at_rest: false,
        });
        if e % 2 == 0 {
            springs.push(Case { dv: [0.0; 3], c: 0.0, ..ordinary(&mut rng) });
        }
    }
    let (sys, x0, v0) = system(&springs);
    let h = 1e-6;
    for sums in [true, false] {
        let mut stepper =
            Stepper::new(StepConfig::new(Integrator::Rk4, h), &sys, &x0, &v0).expect("the stepper builds");
        stepper.set_spring_sums(sums);
        let (mut x, mut v) = (x0.clone(), v0.clone());
        stepper.step(&sys, &mut x, &mut v).expect("the step is finite");
        for (i, s) in springs.iter().enumerate() {
            let f = oracle(s);
            for k in 0..3 {
                let got = v[2 * i][k] / h; // unit mass, from rest: v₁ = h F (1 + O(h² k))
                assert!(
                    (got - f[k]).abs() <= 1e-9 * f[k].abs(),
                    "sums = {sums}, spring {i} {s:?}: v/h = {got}, F = {}",
                    f[k]
                );
            }
        }
    }
}

#[test]
fn a_scaled_kuhn_cube_feels_the_same_dimensionless_force_at_every_scale() {
    let (points, tets) = kuhn_cube(1);
    let scaled = |s: f64, young: f64| {
        let pts: Vec<Vec3> = points.iter().map(|p| p.map(|c| c * s)).collect();
        let mat = Material { young, damping: 0.0, viscosity: 0.0, ..Material::default() };
        let (mut body, _) = Body::from_tets(&pts, &tets, mat).expect("the body builds");
        body.attrs_mut().position_mut().as_mut_slice()[7][2] += 0.5 * s;
        forces_by_coverage(&body, [0.0; 3])[7].map(|c| c / young / s / s)
    };
    let unit = scaled(1.0, 1e3);
    assert!(unit.iter().all(|c| c.is_finite() && *c != 0.0), "{unit:?}");
    for (s, young) in [(1e40, 1e180), (1e55, 1e145), (1e-60, 1e-180)] {
        let f = scaled(s, young);
        for k in 0..3 {
            assert!((f[k] - unit[k]).abs() <= 1e-12 * unit[k].abs(), "s = {s:e}, E = {young:e}: {f:?} vs {unit:?}");
        }
    }
}

#[test]
fn the_oracle_reproduces_ordinary_springs_bit_for_bit() {
    // the oracle's own check: where nothing over- or underflows it is the plain formula
    let mut rng = Rng(5);
    for _ in 0..1000 {
        let s = ordinary(&mut rng);
        assert_eq!(oracle(&s), force_of(&s), "{s:?}");
    }
    assert_eq!(pow2(1.5, -1074), 2.0 * TINY); // 1.5 ulp rounds to even
    assert_eq!(pow2(1.0, -1075), 0.0); // a tie, to even
    assert_eq!(pow2(1.0000001, -1075), TINY);
    assert_eq!(pow2(3.0, 1023), f64::INFINITY);
    assert_eq!(pow2(TINY, 1074), 1.0);
}

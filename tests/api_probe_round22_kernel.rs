//! Round 22 (kernel), findings 198 and 199.
//!
//! 198: the implicit scheme's scaled CG (finding 179) formed (M + h(Γ + C) + h² K) p unscaled and
//! scaled the product after, so mᵢ pᵢ overflowed for a free slot of mass ≈ 1e308 (and h² k, h c,
//! m + h ν for a stiffness, damping or viscosity near `f64::MAX`): `SolverFailed` with a NaN
//! residual. Its right-hand side h f₀ + h² K ẋ₀ overflowed the same way (K ẋ₀ of a stiffness
//! near `f64::MAX`) although the scaled b is ordinary.
//!
//! 199: `CombinatorialMap::is_valid` did not check that βi∘βj is a partial involution for
//! 1 ≤ i, i + 2 ≤ j ≤ n (β1∘β3 in 3D, β1∘β4 and β2∘β4 in 4D).

use topomech::cut::{dissociate_face, incise_plane, remove_volume, Plane};
use topomech::generate::kuhn_cube;
use topomech::gmap::CombinatorialMap;
use topomech::mechanics::{Body, Integrator, Material, SpringSystem, StepConfig, Stepper};
use topomech::{CellId, DartId, GMap};

// ---------------------------------------------------------------------------------------------
// Finding 198

/// A slot pinned at the origin and a free slot of mass m on a spring (rest 1, stiffness k,
/// damping c, slot viscosity ν) stretched to length 1.5 and moving across it at `vy`: its
/// velocity after one implicit step of h.
fn chain_step(m: f64, k: f64, h: f64, nu: f64, c: f64, vy: f64) -> Result<[f64; 3], String> {
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(m, false, nu).unwrap();
    sys.push_spring([0, 1], 1.0, k, c).unwrap();
    let (mut x, mut v) = (vec![[0.0; 3], [1.5, 0.0, 0.0]], vec![[0.0; 3], [0.0, vy, 0.0]]);
    let config = StepConfig::new(Integrator::Implicit, h);
    let mut st = Stepper::new(config, &sys, &x, &v).map_err(|e| e.to_string())?;
    st.step(&sys, &mut x, &mut v).map_err(|e| e.to_string())?;
    Ok(v[1])
}

/// The reproducer: k/m = 1 at every m, so the step is the unit chain's.
#[test]
fn f198_a_heavy_slot_steps_as_a_unit_one() {
    let step = |m: f64| -> Result<Vec<[f64; 3]>, String> {
        let mut sys = SpringSystem::default();
        sys.push_slot(1.0, true, 0.0).unwrap();
        sys.push_slot(m, false, 0.0).unwrap();
        sys.push_spring([0, 1], 1.0, m, 0.0).unwrap();
        let (mut x, mut v) = (vec![[0.0; 3], [1.5, 0.0, 0.0]], vec![[0.0; 3]; 2]);
        let config = StepConfig::new(Integrator::Implicit, 0.1);
        let mut st = Stepper::new(config, &sys, &x, &v).map_err(|e| e.to_string())?;
        st.step(&sys, &mut x, &mut v).map_err(|e| e.to_string())?;
        Ok(v)
    };
    let unit = step(1.0).unwrap();
    for m in [1e300, 1e307, 5e307, 1e308, 1.5e308, 1.7e308, f64::MAX] {
        let v = step(m).unwrap_or_else(|e| panic!("m = {m:e}: {e}"));
        assert!((v[1][0] - unit[1][0]).abs() <= 1e-12 * unit[1][0].abs(), "m = {m:e}: {v:?} vs {unit:?}");
    }
}

/// Σ over `num` of the products of its factors over the same for `den`, in log2 so that no
/// product over- or underflows (relative error ~1e-12 at exponents near ±3000).
fn quotient(num: &[&[f64]], den: &[&[f64]]) -> f64 {
    let lg = |t: &&[f64]| (!t.contains(&0.0)).then(|| t.iter().map(|f| f.log2()).sum::<f64>());
    let top = den.iter().filter_map(lg).fold(f64::NEG_INFINITY, f64::max);
    let sum = |ts: &[&[f64]]| ts.iter().filter_map(lg).map(|l| (l - top).exp2()).sum::<f64>();
    sum(num) / sum(den)
}

/// Masses, stiffnesses, dampings and viscosities at the ends of f64's range, checked against
/// the closed form of the one-slot system (A is diagonal in the spring's frame; f = −k/2 along
/// it, −ν v_y across; kt = k/3 at l = 1.5): Δv_x = −h k/2 / (m + h ν + h² k + h c),
/// Δv_y = −v_y (h ν + h² kt) / (m + h ν + h² kt). The comparison is norm-wise, as CG's
/// tolerance is.
#[test]
fn f198_extreme_masses_stiffnesses_and_dampings_step() {
    // (m, k, h, ν, c, v_y)
    let cases = [
        (1.0, f64::MAX, 1.0, 0.0, 0.0, 0.3),
        (1.0, f64::MAX, 0.1, 0.0, 0.0, 0.3),
        (5.57e-309, 1.0, 1.0, 0.0, 0.0, 0.3), // about the smallest mass with 1/m finite
        (2.3e-308, 1.0, 1.0, 0.0, 0.0, 0.3),
        (1e-300, 1e300, 1.0, 0.0, 0.0, 0.3),
        (f64::MAX, 1.0, 0.1, 0.0, 0.0, 0.3),
        (f64::MAX, f64::MAX, 1e-3, 0.0, 0.0, 0.3),
        (1e308, 1.0, 1.0, 1e308, 0.0, 0.3),
        (f64::MAX, 1.0, 1.0, f64::MAX, 0.0, 0.3), // m + h ν itself past f64::MAX
        (1.0, 1.0, 0.1, 0.0, 1e308, 0.3),
        (1.0, 1e-300, 1e160, 0.0, 0.0, 0.0), // h² past f64::MAX, h² k = 1e20
    ];
    for (m, k, h, nu, c, vy) in cases {
        let v = chain_step(m, k, h, nu, c, vy).unwrap_or_else(|e| panic!("m {m:e} k {k:e} h {h:e}: {e}"));
        let kt = k / 3.0;
        let ex = -quotient(&[&[0.5, h, k]], &[&[m], &[h, nu], &[h, h, k], &[h, c]]);
        let ey = -vy * quotient(&[&[h, nu], &[h, h, kt]], &[&[m], &[h, nu], &[h, h, kt]]);
        let err = (v[0] - ex).abs().max((v[1] - vy - ey).abs());
        let tol = 1e-9 * ex.abs().max(ey.abs()) + 1e-16 * vy;
        assert!(err <= tol, "m {m:e} k {k:e} h {h:e} ν {nu:e} c {c:e}: {v:?}, Δv ({ex:e}, {ey:e})");
    }
}

/// A stiffness near f64::MAX moving across its spring: K ẋ₀ is past f64::MAX while h² K ẋ₀
/// and the whole right-hand side are ordinary (h = 1e-3). The step damps the transverse motion
/// (Δv_y = −v_y h² kt / (m + h² kt), v_y → ~0) and pulls the slot in (Δv_x = h f / (m + h² k)
/// ≈ −1/(2h)); before, b was +∞ and the solve refused at iteration 0.
#[test]
fn f198_a_right_hand_side_whose_k_v0_overflows_is_solved() {
    let (m, k, h, vy) = (1.0, 1e308, 1e-3, 10.0);
    let v = chain_step(m, k, h, 0.0, 0.0, vy).unwrap();
    let ex = -0.5 * h * k / (m + h * h * k);
    let ey = -vy * (h * h * k / 3.0) / (m + h * h * k / 3.0);
    assert!((v[0] - ex).abs() <= 1e-9 * ex.abs(), "{v:?} vs Δv_x {ex:e}");
    assert!((v[1] - vy - ey).abs() <= 1e-9 * ex.abs(), "{v:?} vs Δv_y {ey:e}");
    assert!(v[1].abs() < 1e-12, "the transverse motion is damped: {v:?}");
}

/// The same stiffness with the slot moving along its spring: K ẋ₀ = k vₓ (the axial part
/// k − kt and the transverse kt together) is past f64::MAX, h² k vₓ is not. Backward Euler's
/// Δvₓ = (h f − h² k vₓ) / (m + h² k) with f = −k (l − L): the wide right-hand side must add
/// both parts of K (mutation sample 41: an axial part k / kt instead of k − kt went unseen by
/// the transverse test above).
#[test]
fn f198_a_right_hand_side_along_the_spring_is_solved() {
    let (m, k, h, vx) = (1.0, 1e308, 1e-3, 10.0);
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(m, false, 0.0).unwrap();
    sys.push_spring([0, 1], 1.0, k, 0.0).unwrap();
    let (mut x, mut v) = (vec![[0.0; 3], [1.5, 0.0, 0.0]], vec![[0.0; 3], [vx, 0.0, 0.0]]);
    let mut st = Stepper::new(StepConfig::new(Integrator::Implicit, h), &sys, &x, &v).unwrap();
    st.step(&sys, &mut x, &mut v).unwrap();
    let f = -k * 0.5;
    let expected = (h * f - h * (h * k) * vx) / (m + h * h * k);
    let dv = v[1][0] - vx;
    assert!((dv - expected).abs() <= 1e-9 * expected.abs(), "Δvₓ {dv:e} vs {expected:e}");
    assert_eq!([v[1][1], v[1][2]], [0.0, 0.0], "no motion across the spring");
}

/// A deterministic xorshift.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.unit() * n as f64) as usize
    }
}

/// A random system (some slots pinned, viscosity, damping, gravity) whose masses, viscosities,
/// stiffnesses and dampings are multiplied by 2^e: its forces, right-hand side and operator are
/// the unit one's times 2^e, exactly, so its velocities must be the unit one's, bit for bit, as
/// long as nothing of the scaled system's own is past f64's range (from 2^1012 on, the
/// right-hand side h f₀ + h² K ẋ₀ of some of these systems is itself past `f64::MAX`, which is
/// refused; below 2^-1010 their forces become subnormal). Velocities after 3 steps. Before the
/// fix, 36 of 40 seeds differed at 2^-1010 (mᵢ pᵢ and h² k w subnormal before the scaling).
fn scaled_system(seed: u64, e: i32) -> Result<Vec<[f64; 3]>, String> {
    let s = 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
    let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let n = 3 + r.below(30);
    let mut sys = SpringSystem::default();
    for i in 0..n {
        let fixed = i == 0 || r.unit() < 0.1;
        let nu = if r.unit() < 0.5 { 0.0 } else { r.unit() };
        sys.push_slot((0.1 + r.unit()) * s, fixed, nu * s).unwrap();
    }
    let mut x: Vec<[f64; 3]> = (0..n).map(|_| [r.unit() * 3.0, r.unit(), r.unit()]).collect();
    for i in 1..n {
        for _ in 0..1 + r.below(4) {
            let j = r.below(i);
            let d = (0..3).map(|k| (x[i][k] - x[j][k]).powi(2)).sum::<f64>().sqrt();
            let rest = d * (0.8 + 0.4 * r.unit());
            let c = if r.unit() < 0.5 { 0.0 } else { r.unit() };
            sys.push_spring([j as u32, i as u32], rest, (1.0 + 100.0 * r.unit()) * s, c * s).unwrap();
        }
    }
    sys.set_gravity([0.0, 0.0, -9.81]).unwrap();
    let mut v: Vec<[f64; 3]> = (0..n).map(|_| [r.unit() - 0.5, r.unit() - 0.5, r.unit() - 0.5]).collect();
    let h = [0.01, 0.1, 1.0][(seed % 3) as usize];
    let mut st = Stepper::new(StepConfig::new(Integrator::Implicit, h), &sys, &x, &v).map_err(|e| e.to_string())?;
    for _ in 0..3 {
        st.step(&sys, &mut x, &mut v).map_err(|e| e.to_string())?;
    }
    Ok(v)
}

#[test]
fn f198_power_of_two_scaled_systems_step_bit_identically() {
    for seed in 1..=40 {
        let unit = scaled_system(seed, 0).unwrap();
        for e in [-1010, -1000, -600, 600, 1000, 1010, 1011] {
            let v = scaled_system(seed, e).unwrap_or_else(|err| panic!("seed {seed}, 2^{e}: {err}"));
            let first = v.iter().flatten().zip(unit.iter().flatten()).position(|(a, b)| a.to_bits() != b.to_bits());
            assert!(
                first.is_none(),
                "seed {seed}, 2^{e}: coordinate {first:?} of {v:?} differs from the unit system's"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Finding 199

/// Whether βi∘βj (first βj) is a partial involution, by the definition.
fn law(cmap: &CombinatorialMap, i: usize, j: usize) -> bool {
    let beta = |k: usize, d: u32| if k == 1 { Some(cmap.beta1[d as usize]) } else { cmap.beta[k - 2][d as usize] };
    let step = |d: u32| beta(j, d).and_then(|e| beta(i, e));
    (0..cmap.origin.len() as u32).all(|d| step(d).is_none_or(|y| step(y) == Some(d)))
}

/// Re-pairs two pairs (p, q), (r, s) of `row` inside `darts` as (p, s), (r, q): still an
/// involution without fixed points.
fn re_pair(row: &mut [Option<u32>], darts: &[usize]) {
    let sewn: Vec<usize> = darts.iter().copied().filter(|&d| row[d].is_some()).collect();
    let p = sewn[0];
    let q = row[p].unwrap() as usize;
    let r = sewn.iter().copied().find(|&d| d != p && d != q).unwrap();
    let s = row[r].unwrap() as usize;
    (row[p], row[s], row[r], row[q]) = (Some(s as u32), Some(p as u32), Some(q as u32), Some(r as u32));
    assert!((0..row.len()).all(|d| row[d].is_none_or(|e| e as usize != d && row[e as usize] == Some(d as u32))));
}

/// The reproducer, after every export of several meshes (whole, cut, incised, 2D) keeps the law.
#[test]
fn f199_a_beta3_that_breaks_beta1_beta3_is_invalid() {
    let mut exports = Vec::new();
    for k in 1..=3 {
        let (points, tets) = kuhn_cube(k);
        exports.push(GMap::<3>::from_tets(points.len(), &tets).unwrap().0.to_combinatorial_map().unwrap());
        let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        let inner = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
        dissociate_face(&mut body, inner).unwrap();
        remove_volume(&mut body, CellId(0)).unwrap();
        let plane = Plane { point: [0.5, 0.5, 0.5], normal: [1.0, 0.3, 0.1] };
        incise_plane(&mut body, &plane).unwrap();
        exports.push(body.map().to_combinatorial_map().expect("a cut Kuhn cube stays orientable"));
    }
    let (two, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    exports.push(two.to_combinatorial_map().unwrap());
    for cmap in &exports {
        assert!(law(cmap, 1, 3), "an export breaks β1∘β3");
        assert!(cmap.is_valid());
    }
    let surface = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
    assert!(GMap::<2>::from_triangles(4, &surface).unwrap().0.to_combinatorial_map().unwrap().is_valid());

    let mut cmap = two.to_combinatorial_map().unwrap();
    let all: Vec<usize> = (0..cmap.origin.len()).collect();
    re_pair(&mut cmap.beta[1], &all);
    assert!(!law(&cmap, 1, 3), "the re-pairing breaks β1∘β3");
    assert!(!cmap.is_valid(), "β1∘β3 is no involution: not a combinatorial map");

    // And it stays panic-free on rows naming darts out of range or of the wrong length
    // (finding 187), now that it composes βs.
    let good = two.to_combinatorial_map().unwrap();
    let n = good.origin.len() as u32;
    let mut bad = good.clone();
    bad.beta[1][0] = Some(n + 7);
    assert!(!bad.is_valid());
    let mut bad = good.clone();
    bad.beta1[3] = n;
    assert!(!bad.is_valid());
    let mut bad = good.clone();
    bad.beta[0].pop();
    assert!(!bad.is_valid());
    let mut bad = good.clone();
    bad.beta.push(vec![None; n as usize - 1]);
    assert!(!bad.is_valid());
    let mut bad = good;
    bad.beta.push(vec![Some(u32::MAX); n as usize]);
    assert!(!bad.is_valid());
}

/// Two tetrahedra 4-sewn whole in a 4-G-map (every dart of one to its copy in the other): its
/// export is a 4-map with β4 everywhere. Re-pairing β2 inside the second tetrahedron keeps β2 a
/// fixed-point-free involution and leaves β1, β4 (so β1∘β4) alone, but breaks β2∘β4 — the law
/// for i ≥ 2, which is_valid must check as well.
#[test]
fn f199_a_beta2_that_breaks_beta2_beta4_is_invalid() {
    let (tet, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let darts: Vec<DartId> = tet.darts().collect();
    let at = |d: DartId| darts.iter().position(|&e| e == d).unwrap();
    let mut g = GMap::<4>::new();
    let a: Vec<DartId> = darts.iter().map(|_| g.create_dart().unwrap()).collect();
    let b: Vec<DartId> = darts.iter().map(|_| g.create_dart().unwrap()).collect();
    for i in 0..=2 {
        for (k, &d) in darts.iter().enumerate() {
            let e = at(tet.alpha_dyn(i, d));
            if e != k && g.is_free(i, a[k]) {
                g.sew_dyn(i, a[k], a[e]).unwrap();
                g.sew_dyn(i, b[k], b[e]).unwrap();
            }
        }
    }
    g.sew_dyn(4, a[0], b[0]).unwrap();
    g.validate().unwrap();
    let mut cmap = g.to_combinatorial_map().expect("two tets glued whole are orientable");
    assert_eq!(cmap.beta.len(), 3);
    assert!(cmap.beta[2].iter().all(Option::is_some), "β4 everywhere");
    for (i, j) in [(1, 3), (1, 4), (2, 4)] {
        assert!(law(&cmap, i, j), "the export breaks β{i}∘β{j}");
    }
    assert!(cmap.is_valid());
    let second: Vec<usize> = (0..cmap.origin.len()).filter(|&d| b.contains(&cmap.origin[d])).collect();
    re_pair(&mut cmap.beta[0], &second);
    assert!(law(&cmap, 1, 4) && law(&cmap, 1, 3), "β1, β3, β4 untouched");
    assert!(!law(&cmap, 2, 4), "the re-pairing breaks β2∘β4");
    assert!(!cmap.is_valid(), "β2∘β4 is no involution: not a combinatorial map");
}

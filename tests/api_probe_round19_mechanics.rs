//! Round 19 probing of the stable time step and the demo's summary (findings 165, 166): the limit
//! of a stiff, light vertex whose ω_max² passes `f64::MAX` (a needle edge), checked against the
//! same system with its time scaled by an exact power of two, through `simulate`'s warning and
//! the demo on a needle; and the demo's total mass column at masses of 1e-9 and 1e15.

use std::path::{Path, PathBuf};

use serde_json::Value;
use topomech::mechanics::{FlatModel, Integrator, Material, SpringSystem};

mod cli_common;
use cli_common::{run_in, text, write_msh};

/// A fresh scratch directory of this suite.
fn fresh_dir(name: &str) -> PathBuf {
    cli_common::fresh_dir("topomech-round19-mechanics", name)
}

/// 2^j, exactly.
fn pow2(j: i32) -> f64 {
    2f64.powi(j)
}

/// `sys` with its time scaled by 2^j: masses × 4^j, dampings and viscosities × 2^j, stiffnesses
/// and rest lengths kept. Every mode's ω and c scale by 2^-j, so every stable limit by 2^j
/// exactly (as a law; its computation in f64 to rounding).
fn time_scaled(sys: &SpringSystem, j: i32) -> SpringSystem {
    let fixed: Vec<bool> = sys.inv_mass().iter().zip(sys.mass()).map(|(&w, &m)| w == 0.0 && m > 0.0).collect();
    SpringSystem::new(
        sys.ends().to_vec(),
        sys.rest().to_vec(),
        sys.stiffness().to_vec(),
        sys.damping().iter().map(|&c| c * pow2(j)).collect(),
        sys.mass().iter().map(|&m| m * pow2(2 * j)).collect(),
        &fixed,
        sys.viscosity().iter().map(|&g| g * pow2(j)).collect(),
        sys.gravity(),
    )
    .unwrap()
}

/// The limits of `sys` (whose ω_max² overflows f64) are positive, normal and, scaled back by
/// 2^-j, those of its time-scaled copy (whose ω² is ordinary) to 1e-15.
fn assert_limits_scale(sys: &SpringSystem, j: i32, schemes: &[Integrator]) {
    let (b, scaled) = (sys.mode_bounds(), time_scaled(sys, j).mode_bounds());
    assert!(scaled.omega_max.powi(2).is_finite(), "the copy is ordinary: {scaled:?}");
    assert!(b.omega_max.is_finite(), "ω_max is finite although ω_max² is not: {b:?}");
    assert!((b.omega_max * pow2(-j) / scaled.omega_max - 1.0).abs() < 1e-15, "{b:?} vs {scaled:?}");
    for &scheme in schemes {
        let (h, h_scaled) = (scheme.stable_dt(&b).unwrap(), scheme.stable_dt(&scaled).unwrap());
        let expected = h_scaled * pow2(-j);
        assert!(h.is_normal() && expected.is_normal(), "{scheme:?}: {h:e} (expected {expected:e}); {b:?}");
        assert!((h / expected - 1.0).abs() < 1e-15, "{scheme:?}: {h:e} vs {expected:e}; {b:?}");
    }
}

/// Finding 165: a free slot of mass 1e-300 on a spring of stiffness 1e10 (ω² = 2e310 passes
/// `f64::MAX`) with viscosity only (ν = 1e150 /s): `stable_dt` gave 0 for symplectic Euler and
/// RK4 (ω_max = ∞) and for forward Euler (ν/ω² = ν/∞), though the limits are 1.4e-155 s,
/// 1.8e-155 s and ν/ω² = 5e-161 s. Checked against the system with its time scaled by 2^200.
#[test]
fn f165_stable_dt_of_a_stiff_light_vertex_is_its_limit() {
    let sys = SpringSystem::new(
        vec![[0, 1]],
        vec![1.0],
        vec![1e10],
        vec![0.0],
        vec![1.0, 1e-300],
        &[true, false],
        vec![0.0, 1e-150],
        [0.0; 3],
    )
    .unwrap();
    assert_limits_scale(&sys, 200, &[Integrator::Symplectic, Integrator::Rk4, Integrator::Euler]);
    // By hand, in logarithms: ω² = 2e10/1e-300, c = 1e150, and 4/(c + √(c² + 4ω²)) =
    // 4/(ω (r + √(r² + 4))) with r = c/ω.
    let ln_w = 0.5 * (2e10f64.ln() + 300.0 * 10f64.ln());
    let r = (150.0 * 10f64.ln() - ln_w).exp();
    let ln_limit = 4f64.ln() - ln_w - (r + (r * r + 4.0).sqrt()).ln();
    let h = Integrator::Symplectic.stable_dt(&sys.mode_bounds()).unwrap();
    assert!((h.ln() - ln_limit).abs() < 1e-12, "{h:e} vs {:e}", ln_limit.exp());
}

/// Finding 165 on a built body: the needle of the report (a unit tet whose short edge, 1e-153,
/// joins two free vertices; the material's damping c = ν + βω²), whose ω_max² ≈ 1.3e309. Its
/// limits are those of the time-scaled copy, and the symplectic one is near 1.6e-306 s.
#[test]
fn f165_stable_dt_of_a_needle_body_is_its_limit() {
    let points = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1e-153]];
    let flat =
        FlatModel::from_tets(&points, &[[0, 1, 2, 3]], Material::default(), [0.0; 3], &[true, true, false, false])
            .unwrap();
    let b = flat.system.mode_bounds();
    assert!(b.damping_max > 0.0 && b.damping_max.is_finite(), "{b:?}");
    assert_limits_scale(&flat.system, 300, &[Integrator::Symplectic, Integrator::Rk4, Integrator::Euler]);
    let h = Integrator::Symplectic.stable_dt(&b).unwrap();
    assert!(h > 1e-307 && h < 1e-305, "{h:e}");
}

/// The needle of finding 165 as TetGen files `needle.node`/`.ele` in `dir`, its short edge `e`.
fn needle_files(dir: &Path, e: &str) -> PathBuf {
    let node = dir.join("needle.node");
    std::fs::write(&node, format!("4 3 0 0\n0 0 0 0\n1 0 1 0\n2 1 0 0\n3 1 0 {e}\n")).unwrap();
    std::fs::write(dir.join("needle.ele"), "1 4 0\n0 0 1 2 3\n").unwrap();
    node
}

/// Finding 165: `demo --mesh` on the needle of edge 1e-153 failed at setup with "time step 0 must
/// be positive and finite"; it runs now, every stage, at a normal dt below half the body's limit.
#[test]
fn f165_demo_runs_on_a_needle_of_1e_153() {
    let dir = fresh_dir("needle-demo");
    let node = needle_files(&dir, "1e-153");
    let out = run_in(&dir, &["demo", "--json", "--mesh", node.to_str().unwrap(), "--steps", "20", "--out", "out"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s: Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    assert_eq!(s["all_checks_passed"], true);
    let (dt, refined_dt) = (s["scene"]["dt"].as_f64().unwrap(), s["refined_simulation"]["dt"].as_f64().unwrap());
    assert!(dt.is_normal() && dt < 1e-305, "dt = {dt:e}");
    assert!(refined_dt.is_normal() && refined_dt <= dt, "refined dt = {refined_dt:e}");
}

/// A Kuhn cube of edge `scale` written as MSH in `dir/name`.
fn cube(dir: &Path, name: &str, scale: f64) -> PathBuf {
    let (points, tets) = topomech::generate::kuhn_cube(1);
    let points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c * scale)).collect();
    let path = dir.join(name);
    write_msh(&path, &points, &tets);
    path
}

/// Finding 165: `simulate` read every zero limit as forward Euler on an undamped system. A Kuhn
/// cube of edge 1e-5 with E = 1e300, undamped (ω ≈ 1e155, ω² past `f64::MAX`): symplectic and
/// RK4 at dt = 1e-300, far inside their limits (≈ 1e-155 s), warn of nothing; forward Euler, the
/// one scheme unstable at every dt without damping, still gets that warning. A needle whose
/// damped limit is below the normal range (edge 1e-155: ≈ 1.6e-310 s) is named as such.
#[test]
fn f165_simulate_warns_only_of_real_instability() {
    let dir = fresh_dir("simulate");
    let path = cube(&dir, "cube_e5.msh", 1e-5);
    let undamped = |scheme: &str| {
        let args = ["simulate", path.to_str().unwrap(), "--young", "1e300", "--damping", "0", "--viscosity", "0"];
        let out = run_in(&dir, &[&args[..], &["--steps", "3", "--dt", "1e-300", "--integrator", scheme]].concat());
        assert!(out.status.success(), "{scheme}: {}", text(&out.stderr));
        text(&out.stderr)
    };
    for scheme in ["symplectic", "rk4"] {
        let err = undamped(scheme);
        assert!(!err.contains("stab"), "{scheme}: no stability warning: {err}");
        // (the cube has inverted tets)
    }
    let err = undamped("euler");
    assert!(err.contains("forward Euler is unstable at every dt") && err.contains("undamped"), "{err}");
    let node = needle_files(&dir, "1e-155");
    let out = run_in(
        &dir,
        &[
            "simulate",
            node.to_str().unwrap(),
            "--pin",
            "0,1",
            "--steps",
            "1",
            "--dt",
            "1e-300",
            "--integrator",
            "symplectic",
        ],
    );
    let err = text(&out.stderr);
    assert!(err.contains("below the normal range of f64") && !err.contains("forward Euler"), "{err}");
    assert!(err.contains("of symplectic"), "{err}");
}

/// The demo's summary rows that carry a total mass, split on whitespace, with the JSON stages.
fn mass_rows(dir: &Path, mesh: &Path) -> (Vec<Vec<String>>, Value) {
    let mesh = mesh.to_str().unwrap();
    let table = run_in(dir, &["demo", "--mesh", mesh, "--steps", "20", "--out", "out"]);
    assert!(table.status.success(), "{}", text(&table.stderr));
    let json = run_in(dir, &["demo", "--json", "--mesh", mesh, "--steps", "20", "--out", "out"]);
    assert!(json.status.success(), "{}", text(&json.stderr));
    let report = text(&table.stdout);
    let summary = report.split("\nsummary\n").nth(1).expect("a summary section");
    let rows = summary
        .lines()
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with("all "))
        .map(|l| l.split_whitespace().map(String::from).collect::<Vec<_>>())
        .filter(|t| t.len() > 7 && t[7] != "-")
        .collect();
    (rows, serde_json::from_str(&text(&json.stdout)).unwrap())
}

/// Finding 166: the total mass column printed `{:.6}` in 13 columns: a Kuhn cube of edge 1e-3
/// (mass 1e-9) showed "0.000000", one of edge 1e5 (mass 1e15) ran into the component count
/// ("11000000000000000.000000"). Every row's mass now parses back to the JSON total mass to 1e-6
/// and stands apart from the component count before it.
#[test]
fn f166_demo_table_shows_tiny_and_huge_masses() {
    let dir = fresh_dir("mass-column");
    for (name, scale, mass) in [("cube_milli.msh", 1e-3, 1e-9), ("cube_big.msh", 1e5, 1e15)] {
        let path = cube(&dir, name, scale);
        let (rows, s) = mass_rows(&dir, &path);
        assert!(rows.len() >= 5, "{name}: rows {rows:?}");
        for row in &rows {
            let stage = s["stages"].as_array().unwrap().iter().find(|r| r["stage"] == row[0].as_str()).unwrap();
            assert_eq!(row.len(), 12, "{name}: the cells of {row:?} stay apart");
            assert_eq!(row[6], stage["components"].to_string(), "{name}: {row:?}");
            let (shown, total) = (row[7].parse::<f64>().unwrap(), stage["total_mass"].as_f64().unwrap());
            assert!((shown / total - 1.0).abs() < 1e-6, "{name}: {shown:e} shown for {total:e}: {row:?}");
            assert!((total / mass - 1.0).abs() < 1e-6, "{name}: {total:e}");
        }
    }
}

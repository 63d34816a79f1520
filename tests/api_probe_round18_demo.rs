//! Round 18 probing of `demo` and `simulate` (findings 135, 143, 144, 149): the demo's time step
//! on small meshes and on the refined network, the frames of `simulate --frames N`, the scene
//! box from the points the tets use, and step counts that must not overflow.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use serde_json::Value;
use topomech::mechanics::{Integrator, SpringSystem, StepConfig, StepError, Stepper};

mod cli_common;
use cli_common::{run_in, text, write_msh, BIN};

/// A fresh scratch directory of this suite.
fn fresh_dir(name: &str) -> PathBuf {
    cli_common::fresh_dir("topomech-round18-demo", name)
}

/// The Kuhn cube of side `k` with every coordinate times `scale`, written to `dir/name`.
fn kuhn_file(dir: &Path, name: &str, k: usize, scale: f64, extra: &[[f64; 3]]) -> PathBuf {
    let (points, tets) = topomech::generate::kuhn_cube(k);
    let mut points: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c * scale)).collect();
    points.extend_from_slice(extra);
    let path = dir.join(name);
    write_msh(&path, &points, &tets);
    path
}

/// The built-in liver (MSH 2.2) with its node coordinates times `scale`.
fn scaled_liver(dir: &Path, scale: f64) -> PathBuf {
    let liver = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/liver_547_v22.msh");
    let src = std::fs::read_to_string(liver).unwrap();
    let (mut out, mut nodes) = (String::new(), 0);
    for line in src.lines() {
        match line {
            "$Nodes" => nodes = 1,
            "$EndNodes" => nodes = 0,
            _ if nodes == 1 => nodes = 2,
            _ if nodes == 2 => {
                let f: Vec<&str> = line.split_whitespace().collect();
                let c: Vec<String> =
                    f[1..].iter().map(|x| format!("{:e}", x.parse::<f64>().unwrap() * scale)).collect();
                out += &format!("{} {}\n", f[0], c.join(" "));
                continue;
            }
            _ => {}
        }
        out += line;
        out += "\n";
    }
    let path = dir.join(format!("liver_x{scale}.msh"));
    std::fs::write(&path, out).unwrap();
    path
}

/// `demo --json --steps STEPS --mesh MESH` in `dir`: the summary, or the failure's stderr.
fn demo(dir: &Path, mesh: &Path, steps: u64) -> Result<Value, String> {
    let (mesh, steps) = (mesh.to_str().unwrap(), steps.to_string());
    let out = run_in(dir, &["demo", "--json", "--mesh", mesh, "--steps", &steps, "--out", "out"]);
    if !out.status.success() {
        return Err(text(&out.stderr));
    }
    Ok(serde_json::from_str(&text(&out.stdout)).expect("valid JSON"))
}

/// One oscillator: a unit mass on a spring of stiffness k to a fixed point, damping c_s = β k.
fn oscillator(k: f64, beta: f64, nu: f64) -> SpringSystem {
    let mut sys = SpringSystem::default();
    sys.push_slot(1.0, true, 0.0).unwrap();
    sys.push_slot(1.0, false, nu).unwrap();
    sys.push_spring([0, 1], 1.0, k, beta * k).unwrap();
    sys
}

/// Steps the oscillator released at 1 % stretch `steps` times at `dt`; the final |stretch| or the
/// blow-up.
fn release(sys: &SpringSystem, dt: f64, steps: usize) -> Result<f64, StepError> {
    let (mut x, mut v) = (vec![[0.0; 3], [1.01, 0.0, 0.0]], vec![[0.0; 3]; 2]);
    let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, dt), sys, &x, &v)?;
    for _ in 0..steps {
        stepper.step(sys, &mut x, &mut v)?;
    }
    Ok((x[1][0] - 1.0).abs())
}

/// Finding 135, the law behind the fix: symplectic Euler on a damped mode ẍ + c ẋ + ω² x = 0 is
/// stable iff h²ω² + 2hc ≤ 4, i.e. h ≤ 4/(c + √(c² + 4ω²)) (`Integrator::stable_dt` of the
/// system's `mode_bounds`); with strong stiffness-proportional damping that is far below 2/ω, and
/// the old step 1/ω is unstable. Checked on one oscillator just below and just above the limit.
#[test]
fn f135_symplectic_euler_is_stable_exactly_below_its_damped_limit() {
    // ω = 100, β = 0.05 s: c = βω² = 500, limit 4/(500 + √(500² + 200²)) ≈ 3.7e-3 < 1/ω = 1e-2.
    let sys = oscillator(1e4, 0.05, 0.0);
    let b = sys.mode_bounds();
    assert!((b.omega_max - 100.0_f64 * 2f64.sqrt()).abs() < 1e-9, "ω_max bound √(2k/m): {b:?}");
    let limit = Integrator::Symplectic.stable_dt(&b).unwrap();
    let exact = 4.0 / (500.0 + (500.0f64 * 500.0 + 4.0 * 1e4).sqrt()); // the mode itself: ω² = k/m
                                                                       // The bounds over-estimate ω² and c by at most 2 (Σ 2k/m for a spring with one fixed end).
    assert!(limit <= exact && limit >= 0.5 * exact, "the bound {limit} is safe and near the mode's {exact}");
    let grows = |dt: f64| release(&sys, dt, 4000).map_or(true, |stretch| stretch > 1e-2);
    assert!(!grows(0.99 * exact) && !grows(limit), "below the limit the stretch decays");
    assert!(grows(1.05 * exact), "above it the step blows up");
    assert!(grows(1.0 / b.omega_max), "the old dt = 1/ω_max ignores the damping and blows up");
}

/// Finding 135: the demo runs on meshes smaller than unit size, in every stage, with a time step
/// inside the damped stability limit for the body and its own (smaller) one for the stiffer
/// refined network. Before, the liver at 1/20 scale blew up on the refined network (stepped with
/// the body's dt) and a Kuhn cube of edge 1e-6 in the sag (dt = 1/ω_max ignored β ω²).
#[test]
fn f135_demo_runs_on_small_meshes() {
    let dir = fresh_dir("small");
    for mesh in [scaled_liver(&dir, 0.05), kuhn_file(&dir, "k2_1e-6.msh", 2, 1e-6, &[])] {
        let s = demo(&dir, &mesh, 40).unwrap_or_else(|e| panic!("{}: {e}", mesh.display()));
        assert_eq!(s["all_checks_passed"], true);
        let (dt, refined_dt) = (s["scene"]["dt"].as_f64().unwrap(), s["refined_simulation"]["dt"].as_f64().unwrap());
        assert!(dt > 0.0 && refined_dt > 0.0 && refined_dt < dt, "{}: the refined network is stiffer", mesh.display());
        let ke = s["refined_simulation"]["kinetic_energy"].as_f64().unwrap();
        assert!(ke.is_finite(), "{ke}");
    }
}

/// Finding 135: `simulate` warns when dt is past the stability limit of its scheme with the
/// damping term (here symplectic Euler on a cube of edge 1e-6 at the step that blew up in the
/// probe, 1.262e-5 s: inside 2/ω_max, outside the damped limit), and not when it is inside (the
/// same step without damping).
#[test]
fn f135_simulate_warns_about_a_step_unstable_through_damping() {
    let dir = fresh_dir("warn");
    let mesh = kuhn_file(&dir, "k2_1e-6.msh", 2, 1e-6, &[]);
    let mesh = mesh.to_str().unwrap();
    let args = |damping: &'static str| {
        let base = ["simulate", mesh, "--integrator", "symplectic", "--steps", "2", "--dt", "1.262e-5"];
        let mut a: Vec<&str> = base.to_vec();
        a.extend([
            "--young",
            "3.1392e-4",
            "--viscosity",
            "5",
            "--pin-below",
            "x=2.4e-7",
            "--json",
            "--damping",
            damping,
        ]);
        a
    };
    let damped = run_in(&dir, &args("0.001"));
    assert!(text(&damped.stderr).contains("exceeds the stability limit"), "{}", text(&damped.stderr));
    let undamped = run_in(&dir, &args("0"));
    assert!(undamped.status.success(), "{}", text(&undamped.stderr));
    assert!(!text(&undamped.stderr).contains("stability"), "{}", text(&undamped.stderr));
}

/// The timesteps of the frames of `frame.pvd` in `dir`.
fn pvd_times(dir: &Path) -> Vec<f64> {
    let pvd = std::fs::read_to_string(dir.join("frame.pvd")).expect("the series file");
    pvd.split("timestep=\"").skip(1).map(|r| r.split('"').next().unwrap().parse().unwrap()).collect()
}

/// Finding 144: `simulate --steps S --frames N --out DIR` writes the initial state and N frames
/// at steps round(j·S/N), j = 1…N, so N + 1 files ending at the final state; one per step when
/// S < N; `--frames 0` is refused. Before, `--frames 3` of 10 steps wrote steps 0, 3, 6, 9 (no
/// final state) and `--frames 0` wrote two frames.
#[test]
fn f144_simulate_frames_are_evenly_spaced_and_end_at_the_final_state() {
    let dir = fresh_dir("frames");
    let mesh = kuhn_file(&dir, "k2.msh", 2, 1.0, &[]);
    let mesh = mesh.to_str().unwrap();
    let dt = 1e-4;
    for (steps, frames, at) in [
        (10u64, 3u64, vec![0u64, 3, 7, 10]),
        (10, 5, vec![0, 2, 4, 6, 8, 10]),
        (10, 1, vec![0, 10]),
        (3, 20, vec![0, 1, 2, 3]),
        (0, 4, vec![0]),
    ] {
        let out = dir.join(format!("s{steps}_f{frames}"));
        let (s, f) = (steps.to_string(), frames.to_string());
        let o = out.to_str().unwrap();
        let r = run_in(&dir, &["simulate", mesh, "--steps", &s, "--dt", "1e-4", "--frames", &f, "--out", o, "--json"]);
        assert!(r.status.success(), "{}", text(&r.stderr));
        let expected: Vec<f64> = at.iter().map(|&k| k as f64 * dt).collect();
        assert_eq!(pvd_times(&out), expected, "--steps {steps} --frames {frames}");
        let vtu = std::fs::read_dir(&out)
            .unwrap()
            .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "vtu"));
        assert_eq!(vtu.count(), at.len(), "one file per frame");
    }
    let o = dir.join("zero");
    let r = run_in(&dir, &["simulate", mesh, "--steps", "10", "--frames", "0", "--out", o.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(2), "refused as a bad value: {}", text(&r.stderr));
    assert!(text(&r.stderr).contains("--frames must be at least 1"), "{}", text(&r.stderr));
}

/// Finding 149: the scene's box (pin zone, incision, removal ball) comes from the points the tets
/// use: a far point that no tet uses changes nothing, the body is pinned as without it. Before,
/// a point at x = −100 left no vertex pinned (the body fell freely), one at x = 1e300 pinned
/// every vertex.
#[test]
fn f149_unused_points_do_not_move_the_scene() {
    let dir = fresh_dir("unused");
    let plain = demo(&dir, &kuhn_file(&dir, "k2.msh", 2, 1.0, &[]), 8).unwrap();
    for far in [[-100.0, 0.0, 0.0], [1e300, 0.0, 0.0]] {
        let mesh = kuhn_file(&dir, "k2_far.msh", 2, 1.0, &[far]);
        let s = demo(&dir, &mesh, 8).unwrap_or_else(|e| panic!("{far:?}: {e}"));
        assert!(plain["scene"]["pinned"].as_u64().unwrap() > 0);
        for key in ["pinned", "dt", "young"] {
            assert_eq!(s["scene"][key], plain["scene"][key], "{key} with an unused point at {far:?}");
        }
        let removed = |s: &Value| {
            s["stages"].as_array().unwrap().iter().find(|r| r["stage"] == "removal").unwrap()["operations"].clone()
        };
        assert_eq!(removed(&s), removed(&plain), "the same tets removed");
    }
}

/// Finding 143 (the demo part): a step count near u64::MAX is a long run, not an overflow. The
/// demo's progress length N + N/2 + N/2 + N/4 overflowed u64 for N > 7.3e18 (a panic in builds
/// with overflow checks, such as the debug test run). The demo is stopped once it has written its
/// rest frame, which it does after the progress bar is made, before the first step.
#[test]
fn f143_demo_with_a_huge_step_count_starts_stepping() {
    let dir = fresh_dir("huge");
    let mesh = kuhn_file(&dir, "k1.msh", 1, 1.0, &[]);
    let max = u64::MAX.to_string();
    let mut child = Command::new(BIN)
        .current_dir(&dir)
        .args(["demo", "--json", "--mesh", mesh.to_str().unwrap(), "--steps", &max, "--out", "out"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The rest frame and its series file follow the progress bar; then the sag steps start. Wait
    // for the series file or for the process to end (bounded: 20 minutes at most, far past either).
    let first = dir.join("out/scene.pvd");
    let mut ended = None;
    for _ in 0..12_000 {
        if let Some(status) = child.try_wait().unwrap() {
            ended = Some(status);
            break;
        }
        if first.is_file() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let _ = child.kill();
    let out = child.wait_with_output().unwrap();
    assert!(ended.is_none(), "the demo ended ({ended:?}): {}", text(&out.stderr));
    assert!(first.is_file(), "the demo wrote its first frame");
}

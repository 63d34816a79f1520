//! `topomech bench step MESH [--integrator rk4] [--json]`: median time of one step of the
//! map-driven simulation and of the flat-array baseline, measured in the same run, interleaved.
//! `topomech bench order MESH [--json]`: the same kind of same-run comparison between two point
//! orders of the flat model (Z-order vs Z-order + reverse Cuthill–McKee) and 1 vs 2 threads.
//!
//! Both models are built from the same mesh with the same material, gravity and pins (the tenth
//! of the mesh with the smallest x is fixed) and started at rest. Each round times a batch of
//! steps of the map-driven body, then a batch of the flat model; the per-step time of a round
//! is the batch time over its length, and the reported figure is the median over rounds, so slow
//! phases of a shared machine hit both sides alike.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use topomech::load;
use topomech::mechanics::{FlatModel, Integrator, Material, PinSpec, Simulation, SpringSystem, StepConfig, Stepper};
use topomech::mesh::TetMesh;

use super::simulate::{median, StepTimes};
use super::{at_least_one, build_body, other, print_report, print_warnings, CliError};

/// Arguments of `topomech bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// What to measure.
    #[command(subcommand)]
    pub what: BenchWhat,
}

/// The benchmarks.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum BenchWhat {
    /// Step time of the map-driven simulation vs the flat-array baseline.
    Step(StepBenchArgs),
    /// Step time of the flat model under two point orders (Z-order, then Z-order + reverse
    /// Cuthill–McKee) and of the second on 2 threads, batches interleaved in one run.
    Order(OrderBenchArgs),
}

/// Arguments of `topomech bench order`.
#[derive(Debug, Clone, clap::Args)]
pub struct OrderBenchArgs {
    /// Tetrahedral mesh file.
    pub mesh: PathBuf,
    /// euler, symplectic, rk4 or implicit.
    #[arg(long, default_value = "rk4")]
    pub integrator: Integrator,
    /// Rounds (each times one batch of each variant, the first variant rotating); at least 1,
    /// no upper bound (the run takes as long as asked).
    #[arg(long, default_value_t = 9, value_parser = at_least_one, allow_negative_numbers = true)]
    pub rounds: usize,
    /// Steps per batch; at least 1, no upper bound.
    #[arg(long, default_value_t = 3, value_parser = at_least_one, allow_negative_numbers = true)]
    pub batch: usize,
    /// Print one JSON object: zorder_step_us, rcm_step_us, rcm_2_threads_step_us,
    /// rcm_over_zorder, speedup_2_threads, rcm_ns_per_spring, springs, vertices, kernel.
    #[arg(long)]
    pub json: bool,
}

/// The JSON report of `bench order`: exactly these keys, in this order. Times are medians over
/// rounds of the per-step time of a batch (µs).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OrderJson {
    /// Z-order (`--spatial-order`), 1 thread.
    pub zorder_step_us: f64,
    /// Z-order then reverse Cuthill–McKee (`--spatial-order --rcm-order`), 1 thread.
    pub rcm_step_us: f64,
    /// The same on 2 threads.
    pub rcm_2_threads_step_us: f64,
    /// Median over rounds of the per-round ratio rcm / zorder.
    pub rcm_over_zorder: f64,
    /// Median over rounds of the per-round ratio 1 thread / 2 threads (the speedup).
    pub speedup_2_threads: f64,
    /// rcm_step_us per spring (ns).
    pub rcm_ns_per_spring: f64,
    /// Springs (edges).
    pub springs: usize,
    /// Points.
    pub vertices: usize,
    /// Instruction set of the hot loops.
    pub kernel: &'static str,
}

/// Arguments of `topomech bench step`.
#[derive(Debug, Clone, clap::Args)]
pub struct StepBenchArgs {
    /// Tetrahedral mesh file.
    pub mesh: PathBuf,
    /// euler, symplectic, rk4 or implicit.
    #[arg(long, default_value = "rk4")]
    pub integrator: Integrator,
    /// Rounds (each times one batch of each model); at least 1, no upper bound (the run takes
    /// as long as asked).
    #[arg(long, default_value_t = 200, value_parser = at_least_one, allow_negative_numbers = true)]
    pub rounds: usize,
    /// Steps per batch; at least 1, no upper bound.
    #[arg(long, default_value_t = 50, value_parser = at_least_one, allow_negative_numbers = true)]
    pub batch: usize,
    /// Print one JSON object: map_step_us, flat_step_us, ratio, springs, vertices, kernel.
    #[arg(long)]
    pub json: bool,
}

/// The JSON report: exactly these keys, in this order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BenchJson {
    /// Median step time of the map-driven simulation (µs).
    pub map_step_us: f64,
    /// Median step time of the flat baseline (µs).
    pub flat_step_us: f64,
    /// map_step_us / flat_step_us.
    pub ratio: f64,
    /// Springs (edges).
    pub springs: usize,
    /// Vertices.
    pub vertices: usize,
    /// Instruction set of the hot loops (`portable`, `avx2`, `avx512`; see `mechanics::Kernel`).
    pub kernel: &'static str,
}

/// Runs the benchmark and prints the report. Cost: 2 · rounds · batch steps (`step`),
/// 3 · rounds · batch steps (`order`).
///
/// # Errors
/// [`CliError::Load`] for a bad mesh, [`CliError::Other`] if a model cannot be built or a step
/// blows up.
pub fn run(args: BenchArgs) -> Result<(), CliError> {
    match args.what {
        BenchWhat::Step(args) => run_step(args),
        BenchWhat::Order(args) => run_order(args),
    }
}

/// The benchmark's time step for `integrator` on `sys`: [`Integrator::half_stable_dt`] of
/// [`SpringSystem::mode_bounds`] (half the stability limit, damping included; the implicit
/// scheme at the symplectic one's), so that every scheme times a run that stays bounded (a run
/// past its limit grows until the runaway test stops the benchmark); 1 ms when nothing bounds
/// the step. O(springs + slots).
///
/// # Errors
/// [`CliError::Other`] naming the scheme when the half limit is not a normal f64 (forward Euler
/// on an undamped system is unstable at every step; a needle below about 1e-154 of the body
/// leaves no step f64 can take).
pub fn bench_dt(integrator: Integrator, sys: &SpringSystem) -> Result<f64, CliError> {
    let b = sys.mode_bounds();
    let dt = match integrator.half_stable_dt(&b) {
        h if h.is_finite() => h,
        _ => 1e-3,
    };
    if dt.is_normal() {
        return Ok(dt);
    }
    let why = match integrator.stable_dt(&b) {
        Some(0.0) => "unstable at every time step on this system (no damping its bound can count on)",
        _ => "left with no time step in the normal range of f64 on this system (too stiff or too damped)",
    };
    Err(other(format!(
        "bench: the {} integrator is {why}: stability limit {:e} (ω_max = {:e}, c_max = {:e})",
        integrator.name(),
        2.0 * dt,
        b.omega_max,
        b.damping_max
    )))
}

/// The top of the low-x tenth of the points the tets use, lo + (hi − lo)/10 on x: an unreferenced
/// point (reported and ignored by the builder) does not move the band the benchmark pins, as in
/// `simulate` and `tear` (finding 229). O(tets).
fn low_x_tenth(points: &[[f64; 3]], tets: &[[u32; 4]]) -> f64 {
    let xs = tets.iter().flatten().filter_map(|&v| points.get(v as usize)).map(|p| p[0]);
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    lo + 0.1 * (hi - lo)
}

/// A flat model of `mesh` pinned on its low-x tenth, at rest, with its stepper ([`bench_dt`]).
fn flat_case(mesh: &TetMesh, integrator: Integrator, parallel: bool) -> Result<(FlatModel, Stepper), CliError> {
    let points = &mesh.points;
    let band = low_x_tenth(points, &mesh.tets);
    let pinned: Vec<bool> = points.iter().map(|p| p[0] <= band).collect();
    let flat =
        FlatModel::from_tets(points, &mesh.tets, Material::default(), [0.0, 0.0, -9.81], &pinned).map_err(other)?;
    let config = StepConfig { parallel, ..StepConfig::new(integrator, bench_dt(integrator, &flat.system)?) };
    let stepper = Stepper::new(config, &flat.system, &flat.position, &flat.velocity).map_err(other)?;
    Ok((flat, stepper))
}

/// Per-step time (µs) of a batch of `batch` steps of `case`.
fn time_batch(case: &mut (FlatModel, Stepper), batch: usize) -> Result<f64, CliError> {
    let (flat, stepper) = case;
    let start = Instant::now();
    for _ in 0..batch {
        stepper.step(&flat.system, &mut flat.position, &mut flat.velocity).map_err(other)?;
    }
    Ok(start.elapsed().as_secs_f64() * 1e6 / batch as f64)
}

fn run_order(args: OrderBenchArgs) -> Result<(), CliError> {
    let json = args.json;
    let report = order_report(args)?;
    let mut out = std::io::stdout().lock();
    if json {
        serde_json::to_writer(&mut out, &report)?;
        writeln!(out)?;
    } else {
        // One "key  value" line per field of the JSON object, sorted by key (not Rust's Debug form).
        if let serde_json::Value::Object(fields) = serde_json::to_value(&report)? {
            for (key, value) in fields {
                writeln!(out, "{key:<24} {value}")?;
            }
        }
    }
    out.flush()?;
    Ok(())
}

/// The measurements of `bench order` (see [`OrderJson`]). Cost: 3 · rounds · batch steps plus
/// three flat builds and two renumberings.
fn order_report(args: OrderBenchArgs) -> Result<OrderJson, CliError> {
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let (zorder, _) = loaded.mesh.spatially_ordered();
    let (rcm, _) = zorder.bandwidth_ordered();
    let mut z1 = flat_case(&zorder, args.integrator, false)?;
    let mut r1 = flat_case(&rcm, args.integrator, false)?;
    let mut r2 = flat_case(&rcm, args.integrator, true)?;
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().map_err(other)?;
    let batch = args.batch.max(1); // ≥ 1 from the command line; a struct built in code may hold 0
    let (mut zt, mut rt, mut r2t, mut ratio, mut speedup) = (vec![], vec![], vec![], vec![], vec![]);
    for round in 0..args.rounds.max(1) {
        // The variants take turns at going first, so that a bias of the position in the round
        // (a batch run right after another on the same thread absorbs more preemptions on a
        // loaded host) hits each alike.
        let mut t = [0.0; 3];
        for k in 0..3 {
            let v = (round % 3 + k) % 3; // no overflow on the last of usize::MAX rounds
            t[v] = match v {
                0 => time_batch(&mut z1, batch)?,
                1 => time_batch(&mut r1, batch)?,
                _ => two.install(|| time_batch(&mut r2, batch))?,
            };
        }
        let [z, r, r_two] = t;
        zt.push(z);
        rt.push(r);
        r2t.push(r_two);
        ratio.push(r / z);
        speedup.push(r / r_two);
    }
    let springs = r1.0.system.springs();
    let rcm_us = median(&mut rt);
    let report = OrderJson {
        zorder_step_us: median(&mut zt),
        rcm_step_us: rcm_us,
        rcm_2_threads_step_us: median(&mut r2t),
        rcm_over_zorder: median(&mut ratio),
        speedup_2_threads: median(&mut speedup),
        rcm_ns_per_spring: rcm_us * 1e3 / springs.max(1) as f64,
        springs,
        vertices: rcm.points.len(),
        kernel: r1.1.kernel().name(),
    };
    Ok(report)
}

fn run_step(args: StepBenchArgs) -> Result<(), CliError> {
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let (points, tets) = (&loaded.mesh.points, &loaded.mesh.tets);
    let material = Material::default();
    let gravity = [0.0, 0.0, -9.81];
    let pins = PinSpec { below: Some((0, low_x_tenth(points, tets))), ..PinSpec::default() };
    let (mut body, _) = build_body(&args.mesh, &loaded.mesh, material)?;
    body.attrs_mut().pin_where(|id, p| pins.pins(id, p));
    let pinned: Vec<bool> = points.iter().enumerate().map(|(i, &p)| pins.pins(topomech::CellId(i as u32), p)).collect();
    let mut flat = FlatModel::from_tets(points, tets, material, gravity, &pinned).map_err(other)?;
    let dt = bench_dt(args.integrator, &flat.system)?;
    let config = StepConfig::new(args.integrator, dt);
    let mut sim = Simulation::new(&mut body, gravity, config).map_err(other)?;
    let mut stepper = Stepper::new(config, &flat.system, &flat.position, &flat.velocity).map_err(other)?;
    let (mut map_t, mut flat_t) = (StepTimes::new(args.rounds as u64), StepTimes::new(args.rounds as u64));
    let batch = args.batch.max(1);
    for _ in 0..args.rounds.max(1) {
        let start = Instant::now();
        for _ in 0..batch {
            sim.step(&mut body).map_err(other)?;
        }
        map_t.push(start.elapsed().as_secs_f64() * 1e6 / batch as f64);
        let start = Instant::now();
        for _ in 0..batch {
            stepper.step(&flat.system, &mut flat.position, &mut flat.velocity).map_err(other)?;
        }
        flat_t.push(start.elapsed().as_secs_f64() * 1e6 / batch as f64);
    }
    let (map_us, flat_us) = (map_t.median(), flat_t.median());
    let report = BenchJson {
        map_step_us: map_us,
        flat_step_us: flat_us,
        ratio: map_us / flat_us,
        springs: sim.projection.system().springs(),
        vertices: body.map().count_cells().0[0],
        kernel: sim.stepper.kernel().name(),
    };
    print_report(args.json, &report, |out| {
        writeln!(
            out,
            "{} ({} integrator, dt = {dt:.3e}, {} rounds × {batch} steps)",
            args.mesh.display(),
            args.integrator.name(),
            args.rounds
        )?;
        writeln!(out, "  {:<22}{} springs, {} vertices", "system", report.springs, report.vertices)?;
        writeln!(out, "  {:<22}{}", "kernel", report.kernel)?;
        writeln!(out, "  {:<22}{:.2} µs", "map-driven step", map_us)?;
        writeln!(out, "  {:<22}{:.2} µs", "flat baseline step", flat_us)?;
        writeln!(out, "  {:<22}{:.3}", "ratio", report.ratio)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Finding 229: a point no tet uses, far from the mesh, does not move the pinned band.
    #[test]
    fn the_pinned_band_ignores_unreferenced_points() {
        let points = [[1.0, 0.0, 0.0], [5.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0], [-100.0, 0.0, 0.0]];
        let tets = [[0, 1, 2, 3]];
        assert_eq!(low_x_tenth(&points, &tets), 1.4); // x from 1 to 5: a tenth above 1
        assert_eq!(low_x_tenth(&points[..4], &tets), 1.4);
    }

    /// Finding 170: `bench order`'s flat cases step at half each scheme's own limit (they took
    /// 0.5/ω_max, 15 % past forward Euler's limit on the liver), and a scheme with no step is
    /// refused by name.
    #[test]
    fn flat_cases_step_at_half_their_own_limit() {
        let mesh = topomech::io::read_mesh(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/liver_547_v22.msh"));
        let mesh = mesh.unwrap();
        for integrator in [Integrator::Euler, Integrator::Symplectic, Integrator::Rk4, Integrator::Implicit] {
            let (flat, stepper) = flat_case(&mesh, integrator, false).unwrap();
            let scheme = if integrator == Integrator::Implicit { Integrator::Symplectic } else { integrator };
            let limit = scheme.stable_dt(&flat.system.mode_bounds()).unwrap();
            assert_eq!(stepper.config().dt, 0.5 * limit, "{}", integrator.name());
        }
        let mut undamped = SpringSystem::default();
        undamped.push_slot(1.0, false, 0.0).unwrap();
        undamped.push_slot(1.0, false, 0.0).unwrap();
        undamped.push_spring([0, 1], 1.0, 1.0, 0.0).unwrap();
        let e = bench_dt(Integrator::Euler, &undamped).unwrap_err().to_string();
        assert!(e.contains("euler") && e.contains("unstable at every time step"), "{e}");
        assert!((bench_dt(Integrator::Symplectic, &undamped).unwrap() - 1.0 / 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn bench_order_reports_the_liver_and_positive_times() {
        let mesh = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/liver_547_v22.msh");
        let args = OrderBenchArgs { mesh, integrator: Integrator::Rk4, rounds: 3, batch: 2, json: true };
        let r = order_report(args).unwrap();
        assert_eq!((r.springs, r.vertices), (2833, 547)); // renumbering keeps every spring and point
        let times = [r.zorder_step_us, r.rcm_step_us, r.rcm_2_threads_step_us, r.rcm_over_zorder, r.speedup_2_threads];
        assert!(times.iter().all(|t| t.is_finite() && *t > 0.0), "{r:?}");
        assert!((r.rcm_ns_per_spring - r.rcm_step_us * 1e3 / 2833.0).abs() < 1e-9);
        let missing = PathBuf::from("/nonexistent/mesh.msh");
        let args = OrderBenchArgs { mesh: missing, integrator: Integrator::Rk4, rounds: 1, batch: 1, json: false };
        assert!(matches!(order_report(args), Err(CliError::Load(_))));
    }
}

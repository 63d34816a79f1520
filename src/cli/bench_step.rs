//! `topomech bench step MESH [--integrator rk4] [--json]`: median time of one step of the
//! map-driven simulation and of the flat-array baseline, measured in the same run, interleaved.
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
use topomech::mechanics::{Body, FlatModel, Integrator, Material, PinSpec, Simulation, StepConfig, Stepper};

use super::simulate::median;
use super::{print_warnings, CliError};

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
}

/// Arguments of `topomech bench step`.
#[derive(Debug, Clone, clap::Args)]
pub struct StepBenchArgs {
    /// Tetrahedral mesh file.
    pub mesh: PathBuf,
    /// euler, symplectic, rk4 or implicit.
    #[arg(long, default_value = "rk4")]
    pub integrator: Integrator,
    /// Rounds (each times one batch of each model).
    #[arg(long, default_value_t = 200)]
    pub rounds: usize,
    /// Steps per batch.
    #[arg(long, default_value_t = 50)]
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

fn other(e: impl std::error::Error + Send + Sync + 'static) -> CliError {
    CliError::Other(Box::new(e))
}

/// Runs the benchmark and prints the report. Cost: 2 · rounds · batch steps.
///
/// # Errors
/// [`CliError::Load`] for a bad mesh, [`CliError::Other`] if a model cannot be built or a step
/// blows up.
pub fn run(args: BenchArgs) -> Result<(), CliError> {
    let BenchWhat::Step(args) = args.what;
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let (points, tets) = (&loaded.mesh.points, &loaded.mesh.tets);
    let material = Material::default();
    let gravity = [0.0, 0.0, -9.81];
    let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[0]), hi.max(p[0])));
    let pins = PinSpec { below: Some((0, lo + 0.1 * (hi - lo))), ..PinSpec::default() };
    let (mut body, _) = Body::from_tets(points, tets, material).map_err(other)?;
    body.attrs_mut().pin_where(|id, p| pins.pins(id, p));
    let pinned: Vec<bool> = points.iter().enumerate().map(|(i, &p)| pins.pins(topomech::CellId(i as u32), p)).collect();
    let mut flat = FlatModel::from_tets(points, tets, material, gravity, &pinned).map_err(other)?;
    let dt = 0.5 / flat.system.omega_max();
    let config = StepConfig::new(args.integrator, dt);
    let mut sim = Simulation::new(&mut body, gravity, config).map_err(other)?;
    let mut stepper = Stepper::new(config, &flat.system, &flat.position, &flat.velocity).map_err(other)?;
    let (mut map_t, mut flat_t) = (Vec::with_capacity(args.rounds), Vec::with_capacity(args.rounds));
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
    let (map_us, flat_us) = (median(&mut map_t), median(&mut flat_t));
    let report = BenchJson {
        map_step_us: map_us,
        flat_step_us: flat_us,
        ratio: map_us / flat_us,
        springs: sim.projection.system.springs(),
        vertices: body.map().count_cells().0[0],
        kernel: sim.stepper.kernel().name(),
    };
    let mut out = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer(&mut out, &report)?;
        writeln!(out)?;
    } else {
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
        writeln!(out, "  {:<22}{:.3}", "ratio", report.ratio)?;
    }
    out.flush()?;
    Ok(())
}

//! `topomech refine MESH --around X,Y,Z --radius R --levels L [--density D] [--out DIR] [--json]`:
//! adaptive 1→8 refinement of the tets meeting a ball, level by level (issue 5, seed 004), with
//! tet masses shared among the children by rest volume; every law checked at the end.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use topomech::load;
use topomech::mechanics::{Material, Vec3};
use topomech::subdivide::{LevelError, LeveledMap, TetMasses};
use topomech::vtk::Frame;

use super::{print_warnings, CliError};

/// Arguments of `topomech refine`.
#[derive(Debug, Clone, clap::Args)]
pub struct RefineArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads).
    pub mesh: PathBuf,
    /// Centre of the refinement zone `X,Y,Z`.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub around: Vec3,
    /// Radius of the zone: every tet meeting the ball is refined.
    #[arg(long, allow_hyphen_values = true)]
    pub radius: f64,
    /// Finest level to reach (1 = one 1→8 step).
    #[arg(long, default_value_t = 1)]
    pub levels: u8,
    /// Mass density ρ (tet mass = ρ · volume).
    #[arg(long, default_value_t = Material::default().density)]
    pub density: f64,
    /// Write `refined.vtu` (the finest level) into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object (keys of [`RefineJson`]).
    #[arg(long)]
    pub json: bool,
}

/// The JSON report: exactly these keys, in this order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RefineJson {
    /// Volumes of the finest map.
    pub volumes: usize,
    /// Darts of the finest map.
    pub darts: usize,
    /// Volumes of the extracted level i, i = 0..=k.
    pub tets_per_level: Vec<usize>,
    /// Tets subdivided at each level (index 0 is 0).
    pub subdivided_per_level: Vec<usize>,
    /// The finest map passes `validate()`.
    pub valid: bool,
    /// μt ≤ μf ≤ μa (and μ constant per cell) at every dart.
    pub mu_order_ok: bool,
    /// Every extracted level is a valid G-map.
    pub levels_valid: bool,
    /// Σ ρ·V before.
    pub total_mass_before: f64,
    /// Σ of tet masses after (the children share the parents' masses).
    pub total_mass_after: f64,
    /// Σ of vertex masses after (Σ_t m_t / 4 per vertex); equals `total_mass_after`.
    pub total_vertex_mass_after: f64,
    /// Wall time of the refinement in milliseconds.
    pub refine_ms: f64,
}

fn parse_point(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts.as_slice() else { return Err(format!("expected X,Y,Z, got {s:?}")) };
    let p = |t: &str| match t.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("coordinate {v} is not finite")),
        Err(e) => Err(format!("bad number {t:?}: {e}")),
    };
    Ok([p(x)?, p(y)?, p(z)?])
}

fn other(msg: String) -> CliError {
    CliError::Other(msg.into())
}

/// Loads, refines, checks and reports (see the [module docs](self)). Cost: one load, the
/// refinement, and `check_all` (O(levels · darts)).
///
/// # Errors
/// [`CliError::Load`] for a bad mesh; [`CliError::Other`] for a radius or density that is not a
/// positive finite number, a refinement the library refuses, or a law broken afterwards (after
/// printing the report); [`CliError::Output`] when stdout or the VTU file fails.
pub fn run(args: RefineArgs) -> Result<(), CliError> {
    if !(args.radius.is_finite() && args.radius >= 0.0) {
        return Err(other(format!("--radius must be a finite number ≥ 0, got {}", args.radius)));
    }
    if !(args.density.is_finite() && args.density > 0.0) {
        return Err(other(format!("--density must be a finite number > 0, got {}", args.density)));
    }
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let mut m = LeveledMap::new(loaded.map, loaded.mesh.points);
    let mut masses = TetMasses::from_density(&m, args.density).map_err(|e| other(e.to_string()))?;
    let start = Instant::now();
    let refinement = m.refine_around(args.around, args.radius, args.levels, &mut masses);
    let refine_ms = start.elapsed().as_secs_f64() * 1e3;
    let refinement = refinement.map_err(|e| other(format!("{}: refinement refused: {e}", args.mesh.display())))?;
    let report = report(&m, &masses, &refinement, refine_ms)?;
    if let Some(dir) = &args.out {
        write_vtu(&m, dir)?;
    }
    let mut out = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer(&mut out, &report)?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &report)?;
    }
    out.flush()?;
    match m.check_all() {
        Ok(()) => Ok(()),
        Err(e) => Err(other(format!("{}: the refined map breaks a law (a topomech bug): {e}", args.mesh.display()))),
    }
}

fn report(
    m: &LeveledMap<3>,
    masses: &TetMasses,
    r: &topomech::subdivide::Refinement,
    refine_ms: f64,
) -> Result<RefineJson, CliError> {
    let mut tets_per_level = Vec::new();
    let mut levels_valid = true;
    for i in 0..=m.max_level() {
        match m.level(i) {
            Ok(view) => {
                levels_valid &= view.map.validate().is_ok();
                tets_per_level.push(view.map.count_cells().0[3]);
            }
            Err(_) => levels_valid = false,
        }
    }
    let vertex = masses.vertex_masses(m).map_err(|e| other(e.to_string()))?;
    Ok(RefineJson {
        volumes: m.map().count_cells().0[3],
        darts: m.map().dart_count(),
        tets_per_level,
        subdivided_per_level: r.subdivided_per_level.clone(),
        valid: m.map().validate().is_ok(),
        mu_order_ok: !matches!(m.check_levels(), Err(LevelError::MuOrder { .. } | LevelError::MuNotConstant { .. })),
        levels_valid,
        total_mass_before: r.total_mass_before,
        total_mass_after: r.total_mass_after,
        total_vertex_mass_after: vertex.iter().sum(),
        refine_ms,
    })
}

fn write_table(out: &mut dyn Write, r: &RefineJson) -> std::io::Result<()> {
    writeln!(out, "adaptive refinement (seed 004): tets meeting the ball, level by level")?;
    writeln!(out, "  {:<26}{:?}", "tets per level", r.tets_per_level)?;
    writeln!(out, "  {:<26}{:?}", "subdivided per level", r.subdivided_per_level)?;
    writeln!(out, "  {:<26}{}", "darts", r.darts)?;
    writeln!(out, "  {:<26}{} / {} / {}", "valid / μ order / levels", r.valid, r.mu_order_ok, r.levels_valid)?;
    let residual = (r.total_mass_after - r.total_mass_before) / r.total_mass_before.abs().max(f64::MIN_POSITIVE);
    writeln!(
        out,
        "  {:<26}{:.9} -> {:.9} (relative {residual:.1e})",
        "total mass", r.total_mass_before, r.total_mass_after
    )?;
    writeln!(out, "  {:<26}{:.3} ms", "refine time", r.refine_ms)
}

fn write_vtu(m: &LeveledMap<3>, dir: &std::path::Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| other(format!("cannot create the output directory {}: {e}", dir.display())))?;
    let tets: Vec<[u32; 4]> =
        m.finest_tets().map_err(|e| other(e.to_string()))?.into_iter().map(|(t, _, _)| t).collect();
    let frame = Frame { points: m.points(), tets: &tets, vectors: Vec::new() };
    frame.write(&dir.join("refined.vtu")).map_err(|e| other(e.to_string()))
}

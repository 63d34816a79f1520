//! `topomech` (no arguments) or `topomech demo [--mesh FILE] [--out DIR] [--steps N] [--json]`:
//! the built-in surgical scene (issue 7).
//!
//! A liver (the built-in mesh, or any mesh file) pinned at one end of its longest axis:
//!
//! ```text
//!   rest ─► 1 sag ─► 2 incision ─► 3 tear ─► 4 removal ─► 5 refinement (masses and springs carried,
//!                                                             then N/4 steps on the refined network)
//!           N steps   cut + N/2     N/2 steps  ball + N/4   1→8 subdivision of the tets
//!                     steps         with tears steps        beside the incision, level 1
//! ```
//!
//! After every topological operation and every tenth of a stage the map is validated and the
//! conservation laws are recomputed from its orbits ([`checks`]); the first failure stops the demo
//! with exit status 1. It writes into `--out` (default `out/`) a ParaView series, the boundary
//! surface as OBJ and PNG pictures ([`output`]), and prints a summary table per stage
//! ([`report`]), or one JSON object with `--json`.
//!
//! Needs no file: the built-in mesh is compiled into the binary ([`load::BUILTIN_MESH`]).

pub mod checks;
pub mod output;
pub mod refine;
pub mod report;
pub mod scene;

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use topomech::cut::CutError;
use topomech::load::{self, Loaded};
use topomech::mechanics::{ConservationError, ModelError, SimError, StepError, Vec3};
use topomech::render::{Colormap, RenderError, Shading};
use topomech::subdivide::{CouplingError, LevelError, LeveledMap, SpringLawError};
use topomech::surface::{self, SurfaceError};
use topomech::vtk::VtkError;
use topomech::{CellId, InvariantViolation};

use self::output::Output;
use self::refine::RefinedSim;
use self::report::{DemoJson, FilesJson, SceneJson, SpringsJson, StageRow};
use self::scene::{Scene, StageRun};
use super::{model_error, print_warnings, Characteristics, CliError};

/// Default number of sag steps.
pub const DEFAULT_STEPS: u64 = 2000;

/// Arguments of `topomech demo`.
#[derive(Debug, Clone, clap::Args)]
pub struct DemoArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads); default: the built-in liver.
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// Output directory (created if needed).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Sag steps; the incision and tear stages run N/2 steps each, the removal N/4.
    #[arg(long, default_value_t = DEFAULT_STEPS, allow_negative_numbers = true)]
    pub steps: u64,
    /// Print one JSON object (the summary; its key "mesh" is `topomech info --json` of the mesh).
    #[arg(long)]
    pub json: bool,
}

impl Default for DemoArgs {
    /// What `topomech` with no arguments runs: the built-in mesh, `out/`, [`DEFAULT_STEPS`], text.
    fn default() -> Self {
        DemoArgs { mesh: None, out: PathBuf::from("out"), steps: DEFAULT_STEPS, json: false }
    }
}

/// Why the scene stopped. Every variant names the stage (and step) where it happened.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// The body could not be built from the mesh.
    #[error("cannot build the body: {0}")]
    Model(#[source] ModelError),
    /// The simulation failed (blow-up, stale projection).
    #[error("stage {stage}: simulation failed: {source}")]
    Sim {
        /// The stage.
        stage: &'static str,
        /// The cause.
        source: SimError,
    },
    /// The stable time step of a spring system is below the normal range of f64
    /// ([`scene::time_step`]): the mesh is too stiff or too damped for any f64 step.
    #[error(
        "stage {stage}: the time step {dt:.3e} s (half the stability limit) is below the normal range of f64 \
         (ω_max = {omega_max:.3e} /s, damping rate c_max = {damping_max:.3e} /s): the mesh is too stiff or too \
         damped for an f64 step (an edge far shorter than the body, a tet far lighter than its springs)"
    )]
    TimeStep {
        /// The stage ("setup" for the body, "refinement" for the refined network).
        stage: &'static str,
        /// The step: half the symplectic limit, subnormal or 0.
        dt: f64,
        /// The bound on the angular frequencies (1/s).
        omega_max: f64,
        /// The bound on the damping rates (1/s).
        damping_max: f64,
    },
    /// A cutting operation failed.
    #[error("stage {stage}: cutting failed: {source}")]
    Cut {
        /// The stage.
        stage: &'static str,
        /// The cause.
        source: CutError,
    },
    /// The map broke a law of n-G-maps (a topomech bug).
    #[error("stage {stage}, step {step}: the map breaks an n-G-map law: {violation}")]
    Invalid {
        /// The stage.
        stage: &'static str,
        /// Steps made in the stage.
        step: u64,
        /// The law broken.
        violation: InvariantViolation,
    },
    /// A conservation law recomputed from the orbits does not hold (a topomech bug).
    #[error("stage {stage}, step {step}: conservation check failed: {source}")]
    Conservation {
        /// The stage.
        stage: &'static str,
        /// Steps made in the stage.
        step: u64,
        /// The law broken.
        source: ConservationError,
    },
    /// Total mass or stiffness (plus what was removed) drifted from the initial body's.
    #[error("stage {stage}, step {step}: {quantity} residual {residual:e} exceeds {tol:e}", tol = checks::TOLERANCE)]
    Balance {
        /// The stage.
        stage: &'static str,
        /// Steps made in the stage.
        step: u64,
        /// Which balance.
        quantity: &'static str,
        /// Its relative residual.
        residual: f64,
    },
    /// The body could not be coupled (`tet: None`) or a tet of the incision zone could not be
    /// subdivided through the coupling.
    #[error("refinement: {}{source}", tet.map_or(String::new(), |t| format!("subdividing tet {t} failed: ")))]
    Coupling {
        /// The volume id, for a subdivision.
        tet: Option<CellId>,
        /// The cause.
        source: CouplingError,
    },
    /// A spring of the level-0 coupling differs from the body's spring on the same edge cell.
    #[error("refinement: edge {edge} {ends:?}: {quantity} {coupled} in the coupling, {body} in the body")]
    SpringMismatch {
        /// The edge cell id.
        edge: u32,
        /// Its end vertex ids.
        ends: (u32, u32),
        /// Rest length, stiffness or damping.
        quantity: &'static str,
        /// The coupling's value.
        coupled: f64,
        /// The body's value.
        body: f64,
    },
    /// The springs are not one per edge cell.
    #[error("refinement: {springs} springs for {edges} edge cells")]
    SpringCount {
        /// Springs.
        springs: usize,
        /// Edge cells.
        edges: usize,
    },
    /// The refined spring network breaks a law of `LeveledMechanics::check`.
    #[error("refinement: {0}")]
    SpringLaws(#[source] SpringLawError),
    /// The refined map breaks a level law.
    #[error("refinement: {0}")]
    Levels(#[source] LevelError),
    /// The simulation of the refined network failed (blow-up, size mismatch).
    #[error("refinement, step {step} on the refined network: {source}")]
    RefinedStep {
        /// Steps made on the refined network (0: the stepper could not start).
        step: u64,
        /// The cause.
        source: StepError,
    },
    /// A pinned vertex of the refined network moved.
    #[error("refinement: pinned vertex {vertex} moved from {at:?} to {now:?}")]
    RefinedPin {
        /// The vertex id.
        vertex: usize,
        /// Where it was.
        at: Vec3,
        /// Where it is.
        now: Vec3,
    },
    /// A ParaView file could not be written.
    #[error(transparent)]
    Vtk(#[from] VtkError),
    /// A picture could not be rendered or written.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// An OBJ file could not be written.
    #[error(transparent)]
    Surface(#[from] SurfaceError),
    /// The text report could not be written.
    #[error("cannot write the output: {0}")]
    Io(#[from] std::io::Error),
}

/// Runs the demo (see the [module docs](self)). Cost: O(steps · (springs + vertices)) for the
/// simulation plus O(darts · n²) per check; about a second for the defaults in release builds.
///
/// # Errors
/// [`CliError::Load`] if `--mesh` cannot be read (the message names the file), [`CliError::Invalid`]
/// if the loaded map breaks a law, [`CliError::Model`] if the mass/spring model cannot stand on
/// it, [`CliError::Other`] with a [`DemoError`] when a stage fails or a
/// file cannot be written, [`CliError::Output`] when stdout fails.
pub fn run(args: DemoArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let loaded = match &args.mesh {
        Some(path) => load::load_tet_map(path)?,
        None => load::load_builtin()?,
    };
    print_warnings(&loaded);
    let info = Characteristics::of(&loaded);
    info.ensure_valid(&loaded.path)?;
    let mut stdout = std::io::stdout().lock();
    let mut sink = std::io::sink();
    let summary = {
        let log: &mut dyn Write = if args.json { &mut sink } else { &mut stdout };
        write_header(log, &args, &loaded, &info)?;
        let played = play(&args, &loaded, log).map_err(|e| match e {
            DemoError::Model(source) => model_error(&loaded.path, &loaded.mesh, source),
            e => CliError::Other(Box::new(e)),
        })?;
        let summary = played.summary(&args, &loaded, &info, start);
        if !args.json {
            write_footer(log, &summary)?;
        }
        summary
    };
    if args.json {
        serde_json::to_writer(&mut stdout, &summary)?;
        writeln!(stdout)?;
    }
    stdout.flush()?;
    Ok(())
}

fn write_header(out: &mut dyn Write, args: &DemoArgs, loaded: &Loaded, info: &Characteristics) -> std::io::Result<()> {
    match &args.mesh {
        None => {
            writeln!(out, "topomech demo: a surgical scene on the built-in liver mesh {}", load::BUILTIN_NAME)?;
            writeln!(out, "  (Gmsh remesh of SOFA's liver, LGPL-2.1; the size of the seed paper's benchmark:")?;
            writeln!(out, "   564 nodes, 1856 tets, 2850 springs, 44544 darts)")?;
        }
        Some(_) => writeln!(out, "topomech demo: a surgical scene on {}", loaded.path.display())?,
    }
    info.write_table(out)
}

/// Everything a finished run has to report.
struct Played {
    scene: Scene,
    rows: Vec<StageRow>,
    output: Output,
    threshold: f64,
    springs: SpringsJson,
    refined_sim: RefinedSim,
}

/// The progress bar over all steps, on stderr; hidden with `--json` or when stdout or stderr is
/// not a terminal (a log or a test).
fn progress_bar(len: u64, json: bool) -> ProgressBar {
    if json || !std::io::stdout().is_terminal() || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{msg:<12} {bar:40} {pos}/{len}  eta {eta}") {
        bar.set_style(style);
    }
    bar
}

/// The five stages, each checked, recorded and pictured.
fn play(args: &DemoArgs, loaded: &Loaded, log: &mut dyn Write) -> Result<Played, DemoError> {
    let n = args.steps;
    let mut scene = Scene::new(&loaded.mesh.points, &loaded.mesh.tets, n)?;
    let mut output = Output::new(&args.out, &scene.config)?;
    write_setup(log, &scene)?;
    // Saturating: the four stages' steps (N + N/2 + N/2 + N/4) pass u64::MAX for N > 7.3e18.
    let total = [n / 2, n / 2, n / 4].iter().fold(n, |sum, &k| sum.saturating_add(k));
    let bar = progress_bar(total, args.json);
    let mut rows = Vec::new();
    let rest = StageRun { name: "rest", ..StageRun::default() };
    scene.checker.check(&scene.body, rest.name, 0)?;
    output.frame(&scene)?;
    rows.push(report::scene_row(&scene, &rest));

    let mut sag = StageRun { name: "sag", ..StageRun::default() };
    bar.set_message("sag");
    scene.simulate(&mut sag, n, None, &mut output, &bar)?;
    finish_stage(log, &scene, &sag, &mut rows, "1/5", format!("{} under gravity", plural(n, "step")))?;
    output.set_stress_scale(rows.last().and_then(|r| r.max_stress).unwrap_or(0.0));
    output.stress_picture("1_sag.png", &scene)?;

    let mut incision = StageRun { name: "incision", ..StageRun::default() };
    bar.set_message("incision");
    scene.incise(&mut incision)?;
    scene.simulate(&mut incision, n / 2, None, &mut output, &bar)?;
    let what = format!("{} cut, then {}", plural(incision.cut_faces as u64, "face"), plural(incision.steps, "step"));
    finish_stage(log, &scene, &incision, &mut rows, "2/5", what)?;
    output.stress_picture("2_incision.png", &scene)?;

    let threshold = scene.tear_threshold()?;
    let mut tear = StageRun { name: "tear", ..StageRun::default() };
    bar.set_message("tear");
    scene.simulate(&mut tear, n / 2, Some(threshold), &mut output, &bar)?;
    let torn = if tear.operations == 1 { "1 vertex".to_string() } else { format!("{} vertices", tear.operations) };
    let what = format!("{torn} torn above {threshold:.4e} ({})", plural(tear.cut_faces as u64, "face"));
    finish_stage(log, &scene, &tear, &mut rows, "3/5", what)?;
    output.stress_picture("3_tear.png", &scene)?;

    let mut removal = StageRun { name: "removal", ..StageRun::default() };
    bar.set_message("removal");
    scene.remove_ball(&mut removal)?;
    scene.simulate(&mut removal, n / 4, None, &mut output, &bar)?;
    let what = format!(
        "{} removed at the free tip, then {}",
        plural(removal.operations as u64, "tet"),
        plural(removal.steps, "step")
    );
    finish_stage(log, &scene, &removal, &mut rows, "4/5", what)?;
    output.stress_picture("4_removal.png", &scene)?;
    output.obj("surface.obj", &surface::boundary_surface(&scene.body))?;

    let mut refinement = StageRun { name: "refinement", ..StageRun::default() };
    bar.set_message("refinement");
    bar.set_length(total.saturating_add(scene.incision_tets.len() as u64));
    let mut refined = refine::refine(&scene.body, &scene.incision_tets, &mut refinement, &bar)?;
    scene.checker.passed += refined.checks;
    let sim = refine::simulate_refined(&mut refined, &scene.body, &scene.config, n / 4)?;
    scene.checker.passed += sim.checks;
    bar.finish_and_clear();
    rows.push(report::refined_row(&refined, &scene, &refinement));
    let springs = SpringsJson {
        before: refined.springs_before,
        after: refined.mech.springs().count(),
        doubled_edges: refined.doubled_edges,
        doubled_split: refined.doubled_split,
    };
    let (surface, levels) = refine::refined_surface(&refined.lm, &refined.mech.position);
    output.obj("refined.obj", &surface)?;
    let values = levels.into_iter().map(f64::from).collect();
    let range = (0.0, f64::from(refine::LEVEL));
    let shading = Shading::PerTriangle { values, range, colormap: Colormap::Sequential };
    output.picture("5_refined.png", &surface, &shading)?;
    write_refinement(log, &refined.lm, &springs, &refinement, &sim, scene.checker.passed)?;
    Ok(Played { scene, rows, output, threshold, springs, refined_sim: sim })
}

/// "1 step", "3 steps".
fn plural(n: u64, noun: &str) -> String {
    match n {
        1 => format!("1 {noun}"),
        n => format!("{n} {noun}s"),
    }
}

fn write_setup(out: &mut dyn Write, scene: &Scene) -> std::io::Result<()> {
    let c = &scene.config;
    let axis = ["x", "y", "z"];
    writeln!(out, "scene")?;
    writeln!(
        out,
        "  {:<22}{} vertices with {} ≤ {:.4} ({:.0} % of the longest extent)",
        "pinned",
        c.pinned,
        axis[c.long_axis],
        c.pin_limit,
        scene::PIN_FRACTION * 100.0
    )?;
    writeln!(out, "  {:<22}{:?}", "gravity", c.gravity)?;
    let m = &c.material;
    writeln!(
        out,
        "  {:<22}ρ = {}, E = {:.4}, β = {} s, ν = {} /s",
        "material", m.density, m.young, m.damping, m.viscosity
    )?;
    writeln!(out, "  {:<22}symplectic Euler, dt = {:.3e} s", "integrator", c.dt)?;
    writeln!(out, "stages (checks: validate + conservation + mass and stiffness balances)")
}

fn finish_stage(
    out: &mut dyn Write,
    scene: &Scene,
    run: &StageRun,
    rows: &mut Vec<StageRow>,
    number: &str,
    what: String,
) -> Result<(), DemoError> {
    let row = report::scene_row(scene, run);
    let mut sizes: Vec<usize> = topomech::cut::components(&scene.body).iter().map(|c| c.volumes).collect();
    sizes.sort_unstable_by(|a, b| b.cmp(a));
    let parts = match sizes.as_slice() {
        [] => "no tet left".to_string(),
        [_] => "1 component".to_string(),
        _ => format!(
            "{} components ({} tets)",
            sizes.len(),
            sizes.iter().map(usize::to_string).collect::<Vec<_>>().join(" + ")
        ),
    };
    writeln!(out, "  [{number}] {:<11}{what}; {parts}; checks passed: {}", run.name, row.checks_passed)?;
    rows.push(row);
    Ok(())
}

fn write_refinement(
    out: &mut dyn Write,
    lm: &LeveledMap<3>,
    springs: &SpringsJson,
    run: &StageRun,
    sim: &RefinedSim,
    checks: usize,
) -> std::io::Result<()> {
    writeln!(
        out,
        "  [5/5] {:<11}{} tets beside the incision split 1→8 at level {}; {} darts at level 0, {} at level {}; \
         levels valid, μt ≤ μf ≤ μa; checks passed: {checks}",
        run.name,
        run.operations,
        refine::LEVEL,
        lm.darts_at_level(0),
        lm.darts_at_level(refine::LEVEL),
        refine::LEVEL
    )?;
    writeln!(
        out,
        "        springs carried, one per edge cell: {} → {} ({} doubled edges from the tear, {} of them split); \
         series rule and law 2 checked",
        springs.before, springs.after, springs.doubled_edges, springs.doubled_split
    )?;
    writeln!(
        out,
        "        then {} of {:.3e} s on the refined network ({} slots, {} springs, {} pinned): {:.1} µs per step, \
         max displacement {:.4}; Σ slot mass = Σ tet mass, no blow-up, pins held",
        plural(sim.steps, "step"),
        sim.dt,
        sim.slots,
        sim.springs,
        sim.pinned,
        sim.step_us_median,
        sim.max_displacement
    )
}

impl Played {
    fn summary(&self, args: &DemoArgs, loaded: &Loaded, info: &Characteristics, start: Instant) -> DemoJson {
        let c = &self.scene.config;
        let path = |p: &PathBuf| p.display().to_string();
        DemoJson {
            mesh_name: loaded.path.display().to_string(),
            mesh: info.json.clone(),
            scene: SceneJson {
                sag_steps: args.steps,
                dt: c.dt,
                integrator: "symplectic",
                gravity: c.gravity,
                young: c.material.young,
                density: c.material.density,
                viscosity: c.material.viscosity,
                damping: c.material.damping,
                pinned: c.pinned,
                tear_threshold: self.threshold,
            },
            stages: self.rows.clone(),
            checks_passed: self.scene.checker.passed,
            all_checks_passed: true,
            initial_mass: self.scene.checker.initial_mass,
            final_mass: checks::total_mass(&self.scene.body),
            removed_mass: self.scene.checker.removed_mass,
            refinement_mechanics: true,
            refinement_springs: self.springs.clone(),
            refined_simulation: self.refined_sim.clone(),
            files: FilesJson {
                dir: path(&args.out),
                pvd: path(&self.output.pvd()),
                vtu: self.output.frames.iter().map(path).collect(),
                obj: self.output.objs.iter().map(path).collect(),
                png: self.output.pictures.iter().map(path).collect(),
            },
            wall_ms: start.elapsed().as_secs_f64() * 1e3,
        }
    }
}

fn write_footer(out: &mut dyn Write, s: &DemoJson) -> std::io::Result<()> {
    writeln!(out, "summary")?;
    report::write_table(out, &s.stages)?;
    writeln!(
        out,
        "  all {} checks passed; mass {:.9e} = {:.9e} kept + {:.9e} removed",
        s.checks_passed, s.initial_mass, s.final_mass, s.removed_mass
    )?;
    writeln!(out, "wrote {}/", s.files.dir)?;
    writeln!(out, "  {:<22}{} ({} frames; open it in ParaView)", "ParaView series", s.files.pvd, s.files.vtu.len())?;
    for obj in &s.files.obj {
        writeln!(out, "  {:<22}{obj}", "boundary surface")?;
    }
    for png in &s.files.png {
        writeln!(out, "  {:<22}{png}", "picture")?;
    }
    writeln!(out, "  ({:.0} ms in all)", s.wall_ms)
}

/// The body the demo modules' unit tests run on: the Kuhn cube k = 2 (48 tets) with the cut
/// material.
#[cfg(test)]
fn test_cube() -> topomech::mechanics::Body {
    let (points, tets) = topomech::generate::kuhn_cube(2);
    topomech::mechanics::Body::from_tets(&points, &tets, topomech::cut::ops::material()).unwrap().0
}

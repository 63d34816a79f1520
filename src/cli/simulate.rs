//! `topomech simulate MESH --steps N --dt DT --integrator euler|symplectic|rk4|implicit …`: run the
//! map-driven mass/spring simulation of a mesh, write ParaView frames, print a summary.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use topomech::load;
use topomech::mechanics::{Body, Integrator, Material, PinSpec, Simulation, SpringSystem, StepConfig, Vec3};
use topomech::mesh::TetMesh;
use topomech::vtk::{body_tets, Frame, Series};

use super::{
    build_body, check_ids, other, parse_finite, parse_vec3, print_report, print_warnings, with_extra_vertices, CliError,
};

/// Arguments of `topomech simulate`.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulateArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads).
    pub mesh: PathBuf,
    /// Number of time steps.
    #[arg(long, default_value_t = 1000, allow_negative_numbers = true)]
    pub steps: u64,
    /// Time step (seconds). Explicit schemes need dt below a limit set by the stiffness and the
    /// damping (about 2/ω_max when undamped); a warning on stderr names it when dt is past it.
    #[arg(long, default_value_t = 1e-4, allow_negative_numbers = true)]
    pub dt: f64,
    /// euler, symplectic, rk4 or implicit.
    #[arg(long, default_value = "rk4")]
    pub integrator: Integrator,
    /// Fix the vertices whose rest coordinate is at most VALUE, e.g. `x=0.5` or `z=-1`; a VALUE
    /// below the whole body (pinning no vertex) is refused, naming the body's range.
    #[arg(long, value_name = "AXIS=VALUE", value_parser = parse_pin_below)]
    pub pin_below: Option<(usize, f64)>,
    /// Fix these vertex ids (comma-separated; 0-based points of the file, each must exist).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub pin: Vec<u32>,
    /// Gravity acceleration `X,Y,Z`.
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,-9.81", allow_hyphen_values = true)]
    pub gravity: Vec3,
    /// Mass density ρ.
    #[arg(long, default_value_t = Material::default().density, allow_negative_numbers = true)]
    pub density: f64,
    /// Young's modulus E (spring stiffness k = Σ E·V_t/L²).
    #[arg(long, default_value_t = Material::default().young, allow_negative_numbers = true)]
    pub young: f64,
    /// Stiffness-proportional spring damping β in seconds (c = β·k).
    #[arg(long, default_value_t = Material::default().damping, allow_negative_numbers = true)]
    pub damping: f64,
    /// Ambient viscosity per unit mass ν in 1/s (γ = ν·m).
    #[arg(long, default_value_t = Material::default().viscosity, allow_negative_numbers = true)]
    pub viscosity: f64,
    /// Renumber points and tets along a Z-order curve before building (faster on large meshes:
    /// fewer cache misses). `--pin` ids still name the points of the file; frames use the new order.
    #[arg(long)]
    pub spatial_order: bool,
    /// Renumber points by reverse Cuthill–McKee (small bandwidth: the far end of each spring is
    /// read from a window that stays in cache; after --spatial-order if both are given). `--pin`
    /// ids still name the points of the file; frames use the new order.
    #[arg(long)]
    pub rcm_order: bool,
    /// Worker threads, 1 to 256 (1 = serial; more splits the force passes, same results bit for bit).
    #[arg(long, default_value_t = 1, value_parser = parse_threads, allow_negative_numbers = true)]
    pub threads: usize,
    /// Write `frame_NNNNNN.vtu` files and the series `frame.pvd` (for ParaView) into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Frames to write after the initial state when --out is given, at least 1: the run's steps
    /// split into N equal intervals, the state at the end of each written (the last at the final
    /// step) after the initial one, so N + 1 files (fewer when --steps < N: one per step).
    #[arg(long, default_value_t = 50, value_parser = parse_frames, allow_negative_numbers = true)]
    pub frames: u64,
    /// Print one JSON object: steps, dt, integrator, step_us_median, total_mass,
    /// kinetic_energy, max_displacement.
    #[arg(long)]
    pub json: bool,
}

/// The JSON summary: exactly these keys, in this order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SimulateJson {
    /// Steps made.
    pub steps: u64,
    /// Time step.
    pub dt: f64,
    /// Scheme name.
    pub integrator: &'static str,
    /// Median wall time of one step in microseconds.
    pub step_us_median: f64,
    /// Σ of vertex masses at the end (equal to ρ × volume).
    pub total_mass: f64,
    /// Kinetic energy at the end.
    pub kinetic_energy: f64,
    /// Largest distance of a vertex from its rest position at the end.
    pub max_displacement: f64,
}

fn parse_pin_below(s: &str) -> Result<(usize, f64), String> {
    let (axis, value) = s.split_once('=').ok_or_else(|| format!("expected AXIS=VALUE, got {s:?}"))?;
    let axis = match axis.trim().to_ascii_lowercase().as_str() {
        "x" | "0" => 0,
        "y" | "1" => 1,
        "z" | "2" => 2,
        other => return Err(format!("axis must be x, y or z, got {other:?}")),
    };
    Ok((axis, parse_finite(value)?))
}

/// `--frames`: a whole number ≥ 1 (0 would write only the initial state, or nothing: refused, so
/// that `--out` always gets the final state).
fn parse_frames(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(0) => {
            Err("--frames must be at least 1 (frames after the initial state; leave out --out to write none)".into())
        }
        Ok(n) => Ok(n),
        Err(_) => Err(format!("expected a whole number of frames, got {s:?}")),
    }
}

/// Most worker threads `--threads` takes: far above the cores of any machine this runs on, and
/// low enough that a slip of the keyboard (`--threads 20000`) is an error, not minutes spent
/// creating threads.
const MAX_THREADS: usize = 256;

/// `--threads`: a whole number from 1 to [`MAX_THREADS`] (0 is refused, not read as "serial").
fn parse_threads(s: &str) -> Result<usize, String> {
    let n: u64 = s.trim().parse().map_err(|_| format!("expected a whole number of threads, got {s:?}"))?;
    match usize::try_from(n) {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(format!("the thread count must be from 1 to {MAX_THREADS}, got {n}")),
    }
}

/// Loads the mesh, builds the body, runs `--steps` steps and prints the summary (a table, or
/// JSON). Cost: O(steps · (springs + vertices)) plus the frames.
///
/// # Errors
/// [`CliError::Load`] for a bad mesh; [`CliError::Other`] for a `--pin` id past the last point, a
/// `--pin-below` that pins no vertex, a bad material, a blow-up (naming the 1-based step of the
/// run and the file's node tag of the vertex), a thread pool the system refuses or an unwritable
/// output directory.
pub fn run(args: SimulateArgs) -> Result<(), CliError> {
    let threads = args.threads;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(other)?;
    pool.install(|| simulate(&args, threads > 1))
}

/// A point renumbering of a mesh: the new mesh and `new_of_old`.
type Renumbering = fn(&TetMesh) -> (TetMesh, Vec<u32>);

fn simulate(args: &SimulateArgs, parallel: bool) -> Result<(), CliError> {
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let material =
        Material { density: args.density, young: args.young, damping: args.damping, viscosity: args.viscosity };
    let (mut mesh, mut pin_ids) = (loaded.mesh, args.pin.clone());
    // A pinned id that names no point, or a point no tet uses, would pin nothing, silently:
    // refuse it.
    check_ids("--pin", ("vertex", "points"), &pin_ids, mesh.points.len())?;
    check_pins_used("--pin", &pin_ids, &loaded.build.unreferenced_points)?;
    // So would a --pin-below bound under the whole body (it fell unpinned: finding 182), the
    // body being the points its tets use (finding 201).
    if let Some((axis, value)) = args.pin_below {
        check_pin_region("--pin-below", axis, value, &used_points(&mesh.points, &loaded.build.unreferenced_points))?;
    }
    // file_point[slot]: the point of the file that vertex slot `slot` stands for, through the
    // reorderings (a blow-up names the file's point, not the slot, which each order moves).
    let mut file_point: Vec<u32> = (0..mesh.points.len() as u32).collect();
    let (file_tags, file_points) = (mesh.node_tags.clone(), mesh.points.len());
    let reorders: [(bool, Renumbering); 2] =
        [(args.spatial_order, TetMesh::spatially_ordered), (args.rcm_order, TetMesh::bandwidth_ordered)];
    for (_, reorder) in reorders.into_iter().filter(|(wanted, _)| *wanted) {
        let (ordered, new_of_old) = reorder(&mesh);
        pin_ids = pin_ids.iter().map(|&v| new_of_old.get(v as usize).copied().unwrap_or(v)).collect();
        let mut moved = file_point.clone();
        for (old, &new) in new_of_old.iter().enumerate() {
            if let (Some(slot), Some(&point)) = (moved.get_mut(new as usize), file_point.get(old)) {
                *slot = point;
            }
        }
        file_point = moved;
        mesh = ordered;
    }
    let (mut body, built) = build_body(&args.mesh, &mesh, material)?;
    // A pinched point became several vertices: a blow-up at any of them names the point, and
    // pinning the point holds each of them (finding 202).
    let file_point = with_extra_vertices(file_point, &built);
    pin_ids.extend(
        built.extra_vertices.iter().filter(|(_, p)| pin_ids.contains(p)).map(|&(id, _)| id).collect::<Vec<_>>(),
    );
    let pins = PinSpec { ids: pin_ids, below: args.pin_below, inside: None };
    body.attrs_mut().pin_where(|id, p| pins.pins(id, p));
    let mut config = StepConfig::new(args.integrator, args.dt);
    config.parallel = parallel;
    let mut sim = Simulation::new(&mut body, args.gravity, config).map_err(other)?;
    if let Some(warning) = stability_warning(args.integrator, args.dt, sim.projection.system()) {
        eprintln!("topomech: warning: {warning}");
    }
    let mut frames = FrameWriter::new(args, &body)?;
    frames.maybe_write(0, &body)?;
    let bar = progress_bar(args.steps);
    let mut times = StepTimes::new(args.steps);
    for step in 1..=args.steps {
        let start = Instant::now();
        sim.step(&mut body).map_err(|e| {
            step_error(e, step, args.steps, |slot| file_vertex(&file_tags, &file_point, file_points, slot))
        })?;
        times.push(start.elapsed().as_secs_f64() * 1e6);
        frames.maybe_write(step, &body)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let summary = SimulateJson {
        steps: args.steps,
        dt: args.dt,
        integrator: args.integrator.name(),
        step_us_median: times.median(),
        total_mass: body.total_vertex_mass(),
        kinetic_energy: sim.kinetic_energy(&body).map_err(other)?,
        max_displacement: sim.max_displacement(&body).map_err(other)?,
    };
    print_summary(args, &summary, &sim, frames.pvd())
}

fn print_summary(
    args: &SimulateArgs,
    s: &SimulateJson,
    sim: &Simulation,
    pvd: Option<PathBuf>,
) -> Result<(), CliError> {
    print_report(args.json, s, |out| {
        let sys = sim.projection.system();
        let fixed = sys.inv_mass().iter().zip(sys.mass()).filter(|(&w, &m)| w == 0.0 && m > 0.0).count();
        writeln!(out, "{}", args.mesh.display())?;
        let (springs, slots) = (sys.springs(), sys.slots());
        writeln!(out, "  {:<22}mass/spring ({springs} springs, {slots} vertex slots, {fixed} fixed)", "system")?;
        writeln!(out, "  {:<22}{} × {} s ({})", "steps", s.steps, super::number(s.dt), s.integrator)?;
        writeln!(out, "  {:<22}{:.2} µs", "median step", s.step_us_median)?;
        writeln!(out, "  {:<22}{:.6e}", "total mass", s.total_mass)?;
        writeln!(out, "  {:<22}{:.6e}", "kinetic energy", s.kinetic_energy)?;
        writeln!(out, "  {:<22}{:.6e}", "max displacement", s.max_displacement)?;
        if let Some(p) = pvd {
            writeln!(out, "  {:<22}{}", "ParaView series", p.display())?;
        }
        Ok(())
    })
}

/// The points of `points` that are not listed in `unreferenced` (sorted, as
/// [`topomech::BuildReport`] lists them): the body's rest positions. O(points).
pub(crate) fn used_points(points: &[Vec3], unreferenced: &[u32]) -> Vec<Vec3> {
    let mut unused = unreferenced.iter().peekable();
    let mut used = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        if unused.next_if(|&&u| u as usize == i).is_none() {
            used.push(p);
        }
    }
    used
}

/// Refuses a pinned point (`flag`) that no tet uses (in `unreferenced`, sorted): it is no vertex
/// of the body, so pinning it would pin nothing. O(ids · log unreferenced).
pub(crate) fn check_pins_used(flag: &str, ids: &[u32], unreferenced: &[u32]) -> Result<(), CliError> {
    match ids.iter().find(|id| unreferenced.binary_search(id).is_ok()) {
        Some(id) => Err(other(format!(
            "{flag}: point {id} is used by no tet (an unreferenced point of the file), so it is no vertex of the \
             body and pinning it would pin nothing"
        ))),
        None => Ok(()),
    }
}

/// Refuses a pin region of the command line (`flag` with `axis` ≤ `value`) that pins no point of
/// `points`: the body would fall unpinned while the run reported success. The message names the
/// flag, the value and the body's range on that axis. O(points).
pub(crate) fn check_pin_region(flag: &str, axis: usize, value: f64, points: &[Vec3]) -> Result<(), CliError> {
    let coord = |p: &Vec3| p.get(axis).copied().unwrap_or(f64::NAN);
    if points.iter().any(|p| coord(p) <= value) {
        return Ok(());
    }
    let (lo, hi) =
        points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(coord(p)), hi.max(coord(p))));
    let name = ["x", "y", "z"].get(axis).copied().unwrap_or("?");
    Err(other(format!(
        "{flag}: {name} ≤ {} pins no vertex: the body's {name} runs from {} to {} (give a value ≥ {})",
        super::number(value),
        super::number(lo),
        super::number(hi),
        super::number(lo)
    )))
}

/// How a blow-up names its vertex: the file's node tag (`tags`, indexed by the file's points) of
/// the point that vertex slot `slot` stands for (`file_point` maps slots to the file's points
/// through any renumbering or tear; `u32::MAX` for none), or the file's 0-based point when the
/// file has no tags; a slot past the file's `points` is one of several vertices at that point
/// (the extra vertex of a point pinched in the file, or a copy a tear split off). Only a slot
/// that stands for no point is named as a slot. O(1).
pub(crate) fn file_vertex(tags: &[u64], file_point: &[u32], points: usize, slot: usize) -> String {
    let Some(&point) = file_point.get(slot).filter(|&&p| (p as usize) < points) else {
        return format!("vertex slot {slot} (not a point of the file)");
    };
    let copy = if slot >= points {
        ", one of several vertices there: a point pinched in the file or split by tearing"
    } else {
        ""
    };
    match tags.get(point as usize) {
        Some(tag) => format!("file node tag {tag} (point {point} of the file, 0-based{copy})"),
        None => format!("point {point} of the file (0-based{copy})"),
    }
}

/// The CLI's message for a failed step: a blow-up or a failed implicit solve is stated in the
/// steps the user counts (step `step` of `steps`, 1-based as the progress bar and the frames count
/// them), a blow-up at the vertex `name_vertex` gives for its slot; other errors go through as
/// they are. O(1).
pub(crate) fn step_error(
    e: topomech::mechanics::SimError,
    step: u64,
    steps: u64,
    name_vertex: impl FnOnce(usize) -> String,
) -> CliError {
    use topomech::mechanics::{SimError, StepError};
    match e {
        SimError::Step(StepError::BlowUp { slot, reason, .. }) => other(format!(
            "simulation blew up in step {step} of {steps} (counted from 1, as the progress bar does), at {}: {reason}",
            name_vertex(slot)
        )),
        // The library counts steps from 0; the run from 1 (finding 280).
        SimError::Step(StepError::SolverFailed { iterations, residual, .. }) => other(format!(
            "implicit step {step} of {steps} (counted from 1, as the progress bar does): conjugate gradient stopped \
             after {iterations} iterations at relative residual {residual:e}"
        )),
        e => other(e),
    }
}

/// The warning for a `dt` past the stability limit of an explicit `integrator` on `sys`
/// ([`Integrator::stable_dt`] of [`SpringSystem::mode_bounds`]: the stiffness and the damping
/// terms, docs/MECHANICS.md "Time step"); `None` when dt is within it or the scheme is implicit.
/// The text says which limit it is: an ordinary one, forward Euler's 0 on a system without the
/// damping its bound needs (c_max = 0: undamped; else β_min = ν_min = 0), or one below the normal
/// range of f64 (a system too stiff or too damped for any f64 step). O(springs + slots).
pub fn stability_warning(integrator: Integrator, dt: f64, sys: &SpringSystem) -> Option<String> {
    let b = sys.mode_bounds();
    let limit = integrator.stable_dt(&b).filter(|&limit| dt > limit)?;
    let modes = format!("ω_max = {:.3e} /s, damping rate c_max = {:.3e} /s", b.omega_max, b.damping_max);
    let name = integrator.name();
    let euler_zero = limit == 0.0 && integrator == Integrator::Euler && b.beta_min == 0.0 && b.nu_min == 0.0;
    Some(if limit.is_normal() {
        format!("dt = {dt:.3e} exceeds the stability limit {limit:.3e} of {name} on this system ({modes}): the run may blow up")
    } else if euler_zero && b.damping_max == 0.0 {
        format!("forward Euler is unstable at every dt on this system ({modes}, undamped modes): the run may blow up")
    } else if euler_zero {
        format!(
            "forward Euler has no stable dt its bound can vouch for on this system ({modes}; a spring without \
             damping and a slot without viscosity: β_min = ν_min = 0): the run may blow up"
        )
    } else {
        format!(
            "dt = {dt:.3e} exceeds the stability limit {limit:.3e} of {name} on this system ({modes}), a limit \
             below the normal range of f64 (the system is too stiff or too damped for any f64 time step): the run \
             may blow up"
        )
    })
}

/// A progress bar on stderr, hidden when stderr is not a terminal.
fn progress_bar(steps: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}") {
        bar.set_style(style);
    }
    bar
}

/// Times of a run's steps (or rounds), kept for their median in bounded memory: at most
/// [`StepTimes::CAP`] of them. While a run is short every time is kept; when the sample fills,
/// every other kept time is dropped and from then on only every second (fourth, …) time is
/// taken, so the sample stays evenly spaced over the run whatever its length (a user's
/// `--steps 1e12` costs no more memory than 2¹⁶ steps). O(1) amortized per push.
#[derive(Debug, Clone, PartialEq)]
pub struct StepTimes {
    kept: Vec<f64>,
    stride: u64,
    seen: u64,
}

impl StepTimes {
    /// The most times kept.
    pub const CAP: usize = 1 << 16;

    /// An empty sample; reserves room for `expected` times, at most [`StepTimes::CAP`].
    pub fn new(expected: u64) -> Self {
        let room = usize::try_from(expected).unwrap_or(usize::MAX).min(Self::CAP);
        StepTimes { kept: Vec::with_capacity(room), stride: 1, seen: 0 }
    }

    /// Adds the time of the next step: kept when its index is a multiple of the stride.
    pub fn push(&mut self, t: f64) {
        if self.seen % self.stride == 0 {
            self.kept.push(t);
            if self.kept.len() == Self::CAP {
                let mut k = 0;
                self.kept.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }

    /// The median of the kept times; 0 for none.
    pub fn median(&mut self) -> f64 {
        median(&mut self.kept)
    }
}

impl Default for StepTimes {
    fn default() -> Self {
        StepTimes::new(0)
    }
}

/// Median of `v` (sorts it); 0 for an empty slice.
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Writes the frames of `--frames N` when `--out` is given: frame j (j = 0…N) at step
/// s_j = round(j · S / N) of an S-step run, so the initial state (j = 0) and the final one
/// (j = N, s_N = S) are written and the others evenly spaced between; a step that several j round
/// to (S < N) is written once. O(1) memory whatever N and S.
struct FrameWriter {
    series: Option<Series>,
    tets: Vec<[u32; 4]>,
    /// N (at most S, at least 1) and S.
    frames: u64,
    steps: u64,
    /// The next j to write.
    next: u64,
    dt: f64,
}

impl FrameWriter {
    fn new(args: &SimulateArgs, body: &Body) -> Result<Self, CliError> {
        let series = match &args.out {
            Some(dir) => Some(Series::new(dir, "frame").map_err(other)?),
            None => None,
        };
        let tets = if series.is_some() { body_tets(body) } else { Vec::new() };
        // N > S writes every step, as N = S does (the s_j are then 0, 1, …, S): taking N = S
        // keeps the s_j strictly increasing, one j per frame.
        let frames = args.frames.min(args.steps).max(1);
        Ok(FrameWriter { series, tets, frames, steps: args.steps, next: 0, dt: args.dt })
    }

    /// s_j = round(j · S / N) (halves up), in u128: j · S < 2¹²⁸ for any u64 j and S. ≤ S for j ≤ N.
    fn step_of(&self, j: u64) -> u64 {
        let (js, n) = (u128::from(j) * u128::from(self.steps), u128::from(self.frames));
        let rounded = js / n + u128::from(2 * (js % n) >= n);
        u64::try_from(rounded).unwrap_or(u64::MAX)
    }

    /// Writes the state of `step` when it is the next frame's step (steps come in order from 0).
    fn maybe_write(&mut self, step: u64, body: &Body) -> Result<(), CliError> {
        if self.next > self.frames || self.step_of(self.next) != step {
            return Ok(());
        }
        // Every j that rounds to this step is written now, once (only j = 0, 1 when S = 0).
        while self.next <= self.frames && self.step_of(self.next) <= step {
            self.next += 1;
        }
        let Some(series) = &mut self.series else { return Ok(()) };
        let m = body.attrs();
        let displacement: Vec<Vec3> = m
            .position()
            .as_slice()
            .iter()
            .zip(m.rest_position().as_slice())
            .map(|(p, r)| [p[0] - r[0], p[1] - r[1], p[2] - r[2]])
            .collect();
        let frame = Frame {
            points: m.position().as_slice(),
            tets: &self.tets,
            vectors: vec![("velocity", m.velocity().as_slice()), ("displacement", &displacement)],
        };
        series.push(step as f64 * self.dt, &frame).map_err(other)?;
        Ok(())
    }

    fn pvd(&self) -> Option<PathBuf> {
        self.series.as_ref().map(Series::pvd_path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A slot past the file's points is named as one of several vertices at its point; a slot
    /// that is a point of the file is not (mutation sample 42: the test of `slot >= points`
    /// flipped went unseen by the CLI tests, which read the tag only).
    #[test]
    fn file_vertex_marks_only_the_extra_vertices_as_copies() {
        let (tags, file_point) = ([101, 102, 103], [0, 1, 2, 0, u32::MAX]);
        for slot in 0..3 {
            let name = file_vertex(&tags, &file_point, 3, slot);
            assert!(name.starts_with(&format!("file node tag {}", tags[slot])), "{name}");
            assert!(!name.contains("one of several"), "{name}");
        }
        let extra = file_vertex(&tags, &file_point, 3, 3);
        assert!(extra.starts_with("file node tag 101") && extra.contains("one of several vertices there"), "{extra}");
        assert!(file_vertex(&tags, &file_point, 3, 4).contains("not a point of the file"));
        assert!(file_vertex(&[], &file_point, 3, 3).starts_with("point 0 of the file (0-based, one of several"));
    }

    /// A short run keeps every time: the median is the plain median.
    #[test]
    fn step_times_keep_a_short_run_whole() {
        let mut t = StepTimes::new(5);
        for x in [5.0, 1.0, 4.0, 2.0, 3.0] {
            t.push(x);
        }
        assert_eq!(t.kept, vec![5.0, 1.0, 4.0, 2.0, 3.0]);
        assert_eq!(t.median(), 3.0);
    }

    /// A long run keeps at most CAP times, evenly spaced: step k is kept iff k is a multiple of
    /// the stride, so the median of 0, 1, …, n−1 stays near (n−1)/2.
    #[test]
    fn step_times_stay_bounded_and_evenly_spaced() {
        let n = 3 * StepTimes::CAP as u64 + 5;
        let mut t = StepTimes::new(u64::MAX); // reserves CAP, not 2⁶⁴ slots
        assert!(t.kept.capacity() <= StepTimes::CAP);
        for k in 0..n {
            t.push(k as f64);
        }
        assert!(t.kept.len() < StepTimes::CAP);
        assert_eq!(t.stride, 4);
        assert!(t.kept.iter().enumerate().all(|(j, &x)| x == (j as u64 * t.stride) as f64));
        let m = t.median();
        assert!((m - (n - 1) as f64 / 2.0).abs() <= t.stride as f64, "median {m} of 0..{n}");
    }
}

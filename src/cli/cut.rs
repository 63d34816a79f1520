//! `topomech cut MESH --plane PX,PY,PZ,NX,NY,NZ`, `topomech remove MESH --tets ID,…|--sphere
//! X,Y,Z,R` and `topomech tear MESH --threshold F --steps N`: cut a body (issue 4, seed §3.2,
//! §4.3, §5.1), write the result as VTU and report before/after characteristics, optionally as
//! JSON `{"before": {…}, "after": {…}, "cut_faces": N, "timings_us": {…}}`.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use topomech::cut::{self, Plane, PolylineSweep};
use topomech::load;
use topomech::mechanics::{check_conservation, Body, Integrator, Material, Simulation, StepConfig, Vec3};
use topomech::mesh::TetMesh;
use topomech::vtk::{body_tets, Frame};
use topomech::{BuildReport, CellId};

use super::simulate::{check_pin_region, file_vertex, step_error, used_points};
use super::{
    at_least_one, build_body, check_ids, other, parse_finite, print_warnings, with_extra_vertices, CellCensus, CliError,
};

/// Options shared by the three subcommands.
#[derive(Debug, Clone, clap::Args)]
pub struct CommonArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads).
    pub mesh: PathBuf,
    /// Mass density ρ.
    #[arg(long, default_value_t = Material::default().density, allow_negative_numbers = true)]
    pub density: f64,
    /// Write the cut body to this VTU file.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `topomech cut`: exactly one of `--plane` and `--polyline` (a required group, so
/// that a missing or doubled surface is named as such), and `--sweep` with `--polyline` only.
#[derive(Debug, Clone, clap::Args)]
#[command(group(clap::ArgGroup::new("surface").required(true).multiple(false).args(["plane", "polyline"])))]
pub struct CutArgs {
    /// Mesh, density, output.
    #[command(flatten)]
    pub common: CommonArgs,
    /// The plane: a point and a normal, `PX,PY,PZ,NX,NY,NZ`. Exactly one of --plane and
    /// --polyline is required.
    #[arg(long, value_parser = parse_numbers::<6>, allow_hyphen_values = true)]
    pub plane: Option<[f64; 6]>,
    /// Instead of a plane, a scalpel path `X,Y,Z;X,Y,Z;…` swept along `--sweep` (a bounded cut).
    #[arg(long, value_parser = parse_polyline, allow_hyphen_values = true, requires = "sweep")]
    pub polyline: Option<Polyline>,
    /// The depth vector `WX,WY,WZ` the polyline is swept along (its length is the cut depth);
    /// only with --polyline.
    #[arg(
        long,
        value_parser = parse_numbers::<3>,
        allow_hyphen_values = true,
        requires = "polyline",
        conflicts_with = "plane"
    )]
    pub sweep: Option<[f64; 3]>,
}

/// Arguments of `topomech remove`: exactly one of `--tets` and `--sphere` (without either the
/// command would remove nothing and report success).
#[derive(Debug, Clone, clap::Args)]
#[command(group(clap::ArgGroup::new("selector").required(true).args(["tets", "sphere"])))]
pub struct RemoveArgs {
    /// Mesh, density, output.
    #[command(flatten)]
    pub common: CommonArgs,
    /// Tet ids to remove (0-based positions in the file), comma-separated; an id listed twice is
    /// removed once. Exactly one of --tets and --sphere is required.
    #[arg(long, value_delimiter = ',', conflicts_with = "sphere", allow_negative_numbers = true)]
    pub tets: Vec<u32>,
    /// Remove the tets whose centroid lies in the ball `X,Y,Z,R`.
    #[arg(long, value_parser = parse_numbers::<4>, allow_hyphen_values = true)]
    pub sphere: Option<[f64; 4]>,
}

/// Arguments of `topomech tear`.
#[derive(Debug, Clone, clap::Args)]
pub struct TearArgs {
    /// Mesh, density, output.
    #[command(flatten)]
    pub common: CommonArgs,
    /// Tear vertices whose largest principal tensile stress exceeds this force.
    #[arg(long, allow_negative_numbers = true)]
    pub threshold: f64,
    /// Time steps (symplectic Euler); tearing is checked after each.
    #[arg(long, default_value_t = 200, allow_negative_numbers = true)]
    pub steps: u64,
    /// Time step (seconds).
    #[arg(long, default_value_t = 1e-4, allow_negative_numbers = true)]
    pub dt: f64,
    /// Fix the vertices whose rest z is at most this value (default: the lowest 10% of the body);
    /// a value below the whole body (pinning no vertex) is refused.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    pub pin_z: Option<f64>,
    /// Gravity along z (negative pulls down); large values stretch the body. Must be finite.
    #[arg(long, default_value_t = -200.0, allow_hyphen_values = true, value_parser = parse_finite)]
    pub gravity_z: f64,
    /// Vertices torn per step at most (at least 1: 0 would never tear).
    #[arg(long, default_value_t = 4, value_parser = at_least_one, allow_negative_numbers = true)]
    pub per_step: usize,
}

/// The characteristics of a body in the JSON report (exactly these keys, in this order).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BodyStats {
    /// Cells, boundary faces, components.
    #[serde(flatten)]
    pub cells: CellCensus,
    /// Σ_v m_v.
    pub total_mass: f64,
    /// The mass of each connected component (`cut::components`), ascending (the order of the
    /// conformance suite's `component_masses`): one entry per component, summing to
    /// `total_mass` up to rounding. The parts are stepped in one spring
    /// system with no spring between them, the same dynamics as separate bodies.
    pub component_masses: Vec<f64>,
    /// Mass removed so far.
    pub removed_mass: f64,
    /// Σ_e k_e.
    pub stiffness_sum: f64,
    /// Whether `validate()` passed.
    pub valid: bool,
    /// Whether `check_conservation()` passed.
    pub conservation_ok: bool,
}

/// The JSON report of the three subcommands.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CutReport {
    /// Before the operation.
    pub before: BodyStats,
    /// After it.
    pub after: BodyStats,
    /// Faces dissociated.
    pub cut_faces: usize,
    /// Timings in microseconds by phase.
    pub timings_us: BTreeMap<String, u64>,
}

/// The statistics of `body`. O(darts).
pub fn stats(body: &Body, removed_mass: f64) -> BodyStats {
    let map = body.map();
    let mech = body.attrs();
    BodyStats {
        cells: CellCensus::of(map),
        total_mass: body.total_vertex_mass(),
        component_masses: component_masses(body),
        removed_mass,
        stiffness_sum: map
            .one_dart_per_cell(1)
            .into_iter()
            .map(|d| mech.edge_stiffness(map.cell_id(1, d)))
            .fold(0.0, |s, k| s + k), // +0 for an emptied body
        valid: map.validate().is_ok(),
        conservation_ok: check_conservation(map, mech).is_ok(),
    }
}

/// The masses of the connected components of `body` ([`cut::components`]), ascending, as the
/// conformance suite orders its `component_masses`. O(darts).
pub fn component_masses(body: &Body) -> Vec<f64> {
    let mut masses: Vec<f64> = cut::components(body).into_iter().map(|c| c.mass).collect();
    masses.sort_by(f64::total_cmp);
    masses
}

/// `topomech cut`.
///
/// # Errors
/// [`CliError`] when the mesh cannot be loaded, the plane is bad, or the output cannot be written.
pub fn run(args: CutArgs) -> Result<(), CliError> {
    let (mut body, _, _, load_us) = load_body(&args.common)?;
    let before = stats(&body, 0.0);
    let t = Instant::now();
    let inc = match (args.plane, args.polyline) {
        (Some([px, py, pz, nx, ny, nz]), _) => {
            cut::incise_plane(&mut body, &Plane { point: [px, py, pz], normal: [nx, ny, nz] })
        }
        // clap requires exactly one of --plane and --polyline, and --sweep with --polyline; a
        // missing --sweep would be a zero sweep, which the library refuses with a clear error.
        (None, points) => {
            let surface = PolylineSweep {
                points: points.map(|p| p.0).unwrap_or_default(),
                sweep: args.sweep.unwrap_or_default(),
            };
            cut::incise_sweep(&mut body, &surface)
        }
    }
    .map_err(other)?;
    let cut_us = t.elapsed().as_micros() as u64;
    let timings = BTreeMap::from([("load".to_string(), load_us), ("cut".to_string(), cut_us)]);
    finish(&args.common, &body, before, 0.0, inc.cut_faces(), timings)
}

/// `topomech remove`.
///
/// # Errors
/// As [`run`]; also a tet id that does not exist.
pub fn run_remove(args: RemoveArgs) -> Result<(), CliError> {
    let (mut body, _, _, load_us) = load_body(&args.common)?;
    let before = stats(&body, 0.0);
    // A fresh body's volume ids are the tets' positions in the file: check them all before the
    // first removal, so that a bad id is named as such (not as "already removed" after an
    // earlier part of the list went through).
    check_ids("--tets", ("tet", "tets"), &args.tets, before.cells.volumes)?;
    let mut ids: Vec<u32> = args.tets.clone();
    if let Some([x, y, z, r]) = args.sphere {
        if !(r.is_finite() && r >= 0.0) {
            return Err(CliError::Other(format!("--sphere radius must be a finite number ≥ 0, got {r}").into()));
        }
        ids.extend(tets_in_ball(&body, [x, y, z], r));
    }
    // Each listed tet removed once, in order of first mention.
    let mut seen = std::collections::HashSet::new();
    ids.retain(|&id| seen.insert(id));
    let t = Instant::now();
    let (mut removed, mut faces) = (0.0, 0);
    for id in ids {
        let r = cut::remove_volume(&mut body, CellId(id)).map_err(other)?;
        removed += r.removed_mass;
        faces += r.dissociations.len();
    }
    let cut_us = t.elapsed().as_micros() as u64;
    let timings = BTreeMap::from([("load".to_string(), load_us), ("remove".to_string(), cut_us)]);
    finish(&args.common, &body, before, removed, faces, timings)
}

/// `topomech tear`.
///
/// # Errors
/// As [`run`]; also a bad time step or a blow-up.
pub fn run_tear(args: TearArgs) -> Result<(), CliError> {
    // Before loading and stepping: `--steps 0` would otherwise never meet the check of
    // `tear_step` (finding 269).
    cut::check_threshold(args.threshold).map_err(other)?;
    let (mut body, mesh, built, load_us) = load_body(&args.common)?;
    let before = stats(&body, 0.0);
    // The rest positions of the vertices the tets use: an unreferenced point keeps a vertex
    // slot whose rest position is never set (the origin), which would move the range and pin a
    // phantom (finding 206, as 201 in `simulate`). Extra vertices of pinched points are kept.
    let rest = used_points(body.attrs().rest_position().as_slice(), &built.unreferenced_points);
    let (lo, hi) = rest.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p[2]), hi.max(p[2])));
    // An explicit --pin-z under the whole body would let it fall unpinned: refuse it.
    if let Some(z) = args.pin_z {
        check_pin_region("--pin-z", 2, z, &rest)?;
    }
    let pin_z = args.pin_z.unwrap_or(lo + 0.1 * (hi - lo));
    body.attrs_mut().pin_where(|_, p| p[2] <= pin_z);
    let config = StepConfig::new(Integrator::Symplectic, args.dt);
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, args.gravity_z], config).map_err(other)?;
    let (mut faces, mut step_us, mut tear_us) = (0, 0u64, 0u64);
    // file_point[slot]: the point of the file a vertex slot stands for (a fresh body's slots are
    // the file's points and the extra vertices of its pinched points; a torn-off copy stands for
    // the point it was split from).
    let (tags, points) = (&mesh.node_tags, mesh.points.len());
    let mut file_point = with_extra_vertices((0..points as u32).collect(), &built);
    for step in 1..=args.steps {
        let t = Instant::now();
        sim.step(&mut body)
            .map_err(|e| step_error(e, step, args.steps, |slot| file_vertex(tags, &file_point, points, slot)))?;
        step_us += t.elapsed().as_micros() as u64;
        let t = Instant::now();
        let torn = cut::tear_step(&mut body, &mut sim, args.threshold, args.per_step).map_err(other)?;
        tear_us += t.elapsed().as_micros() as u64;
        faces += torn.tears.iter().map(|t| t.dissociations.len()).sum::<usize>();
        for split in torn.tears.iter().flat_map(|t| &t.dissociations).flat_map(|d| &d.vertices) {
            let (kept, new) = (split.kept.0 as usize, split.new.0 as usize);
            let from = file_point.get(kept).copied().unwrap_or(u32::MAX);
            if file_point.len() <= new {
                file_point.resize(new + 1, u32::MAX);
            }
            file_point[new] = from;
        }
    }
    let timings =
        BTreeMap::from([("load".to_string(), load_us), ("steps".to_string(), step_us), ("tear".to_string(), tear_us)]);
    finish(&args.common, &body, before, 0.0, faces, timings)
}

/// The body of `common.mesh`, the mesh it was built on (its points are the body's first vertex
/// slots), the build's report and the load time in µs.
fn load_body(common: &CommonArgs) -> Result<(Body, TetMesh, BuildReport, u64), CliError> {
    let t = Instant::now();
    let loaded = load::load_tet_map(&common.mesh)?;
    print_warnings(&loaded);
    let material = Material { density: common.density, ..Material::default() };
    let (body, built) = build_body(&common.mesh, &loaded.mesh, material)?;
    Ok((body, loaded.mesh, built, t.elapsed().as_micros() as u64))
}

/// Tet (volume) ids whose centroid at rest is within distance r of c.
fn tets_in_ball(body: &Body, c: Vec3, r: f64) -> Vec<u32> {
    let map = body.map();
    let rest = body.attrs().rest_position();
    let mut out = Vec::new();
    for d in map.one_dart_per_cell(3) {
        let mut ids: Vec<CellId> = map.cell_darts(3, d).into_iter().map(|x| map.vertex_id(x)).collect();
        ids.sort_unstable();
        ids.dedup();
        let pts: Vec<Vec3> = ids.iter().map(|&v| rest[v]).collect();
        let g = topomech::mesh::centroid(&pts); // divided first: no overflow for huge coordinates
                                                // Scaled distance: Σ dₖ² and r² overflow to ∞ ≤ ∞ for a far ball (finding 80).
        if topomech::mesh::distance(g, c) <= r {
            out.push(map.cell_id(3, d).0);
        }
    }
    out.sort_unstable();
    out
}

/// The text summary's part masses: all of them up to [`PARTS_LISTED`], else the smallest and
/// the largest with the count (the JSON always lists every part). O(parts).
fn part_masses_text(masses: &[f64]) -> String {
    let masses: Vec<String> = masses.iter().map(|&m| super::number(m)).collect();
    match masses.as_slice() {
        [first, .., last] if masses.len() > PARTS_LISTED => {
            format!("{first} … {last} ({} parts, ascending; all in --json)", masses.len())
        }
        _ => format!("{} (ascending)", masses.join(", ")),
    }
}

/// How many part masses the text summary lists one by one.
const PARTS_LISTED: usize = 8;

fn finish(
    common: &CommonArgs,
    body: &Body,
    before: BodyStats,
    removed: f64,
    cut_faces: usize,
    mut timings_us: BTreeMap<String, u64>,
) -> Result<(), CliError> {
    if let Some(path) = &common.out {
        let t = Instant::now();
        write_vtu(body, path)?;
        timings_us.insert("write".to_string(), t.elapsed().as_micros() as u64);
    }
    let report = CutReport { before, after: stats(body, removed), cut_faces, timings_us };
    let mut out = std::io::stdout().lock();
    if common.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
    } else {
        let (b, a) = (&report.before, &report.after);
        let (bc, ac) = (&b.cells, &a.cells);
        writeln!(out, "cut faces      {}", report.cut_faces)?;
        writeln!(
            out,
            "cells V/E/F/T  {}/{}/{}/{} -> {}/{}/{}/{}",
            bc.vertices, bc.edges, bc.faces, bc.volumes, ac.vertices, ac.edges, ac.faces, ac.volumes
        )?;
        writeln!(out, "boundary faces {} -> {}", bc.boundary_faces, ac.boundary_faces)?;
        writeln!(out, "components     {} -> {}", bc.components, ac.components)?;
        writeln!(out, "part masses    {}", part_masses_text(&a.component_masses))?;
        let mass = [b.total_mass, a.total_mass, a.removed_mass].map(super::number);
        writeln!(out, "total mass     {} -> {} (removed {})", mass[0], mass[1], mass[2])?;
        writeln!(out, "valid {}  conservation {}", a.valid, a.conservation_ok)?;
    }
    Ok(())
}

/// The live part of `body` as a VTU: one point per live vertex (the vertex cells of the map, in
/// increasing id; a removal or a merge leaves dead slots in the attribute arrays, which are not
/// written), the tets renumbered onto them, and the velocity of each written point, so that
/// `NumberOfPoints` is the report's `after.vertices` and every point belongs to a tet.
/// O(darts + slots).
fn write_vtu(body: &Body, path: &Path) -> Result<(), CliError> {
    let live = live_mesh(body)?;
    let frame = Frame { points: &live.points, tets: &live.tets, vectors: vec![("velocity", &live.velocity)] };
    frame.write(path).map_err(other)
}

/// The live vertices of a body renumbered compactly ([`live_mesh`]): positions, tets in the
/// new numbering, velocities.
struct LiveMesh {
    points: Vec<Vec3>,
    tets: Vec<[u32; 4]>,
    velocity: Vec<Vec3>,
}

/// Positions, tets (in the written numbering) and velocities of the live vertices of `body`, in
/// increasing vertex id ([`write_vtu`]): the attribute slots that no live tet uses are dropped by
/// [`TetMesh::compact`], and the velocities follow its renumbering. O(darts + slots).
fn live_mesh(body: &Body) -> Result<LiveMesh, CliError> {
    let (position, velocity) = (body.attrs().position().as_slice(), body.attrs().velocity().as_slice());
    let slots = TetMesh { points: position.to_vec(), tets: body_tets(body), ..Default::default() };
    let (live, old_to_new) = slots.compact().map_err(|e| other(format!("{e} (a topomech bug)")))?;
    let mut live_velocity = vec![[0.0; 3]; live.points.len()];
    for (old, &new) in old_to_new.iter().enumerate().filter(|&(_, &new)| new != u32::MAX) {
        live_velocity[new as usize] =
            *velocity.get(old).ok_or_else(|| other(format!("vertex {old} has no velocity slot (a topomech bug)")))?;
    }
    Ok(LiveMesh { points: live.points, tets: live.tets, velocity: live_velocity })
}

fn parse_numbers<const K: usize>(s: &str) -> Result<[f64; K], String> {
    let parts: Vec<f64> = s.split(',').map(parse_finite).collect::<Result<_, _>>()?;
    <[f64; K]>::try_from(parts.as_slice()).map_err(|_| format!("expected {K} comma-separated numbers, got {s:?}"))
}

/// The points of `--polyline` (one clap value).
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline(pub Vec<Vec3>);

/// `X,Y,Z;X,Y,Z;…` → points (the cut checks their number and shape).
fn parse_polyline(s: &str) -> Result<Polyline, String> {
    s.split(';').filter(|t| !t.trim().is_empty()).map(parse_numbers::<3>).collect::<Result<_, _>>().map(Polyline)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Up to eight parts are listed one by one; from nine on, the smallest, the largest and the
    /// count.
    #[test]
    fn part_masses_are_listed_up_to_eight() {
        let masses: Vec<f64> = (1..=9).map(f64::from).collect();
        assert_eq!(part_masses_text(&masses[..1]), "1 (ascending)");
        let eight = part_masses_text(&masses[..PARTS_LISTED]);
        assert_eq!(eight, "1, 2, 3, 4, 5, 6, 7, 8 (ascending)");
        let nine = part_masses_text(&masses);
        assert_eq!(nine, "1 … 9 (9 parts, ascending; all in --json)");
    }
}

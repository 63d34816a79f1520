//! The demo's summary: one row per stage (cells per dimension, boundary, components, mass and
//! stiffness balances, step time), printed as a table or as one JSON object.

use std::io::Write;

use topomech::cut;
use topomech::gmap::GMap;
use topomech::mechanics::Vec3;

use super::checks::{total_mass, total_stiffness};
use super::refine::{Refined, RefinedSim};
use super::scene::{Scene, StageRun};

use crate::cli::{CellCensus, InfoJson};

/// One stage of the summary (JSON keys in this order). For the refinement, the mass is Σ tet mass
/// of the finest level, the stiffness sum Σ k over its springs and the stiffness residual `None`
/// (a 1→8 adds the stiffness of its inner springs: nothing to conserve).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StageRow {
    /// Stage name: rest, sag, incision, tear, removal, refinement.
    pub stage: &'static str,
    /// Cells, boundary faces, components.
    #[serde(flatten)]
    pub cells: CellCensus,
    /// Σ_v m_v.
    pub total_mass: Option<f64>,
    /// Mass removed with tets so far.
    pub removed_mass: Option<f64>,
    /// (Σ m_v + removed − M0) / M0.
    pub mass_residual: Option<f64>,
    /// Σ_e k_e.
    pub stiffness_sum: Option<f64>,
    /// (Σ k_e + removed − K0) / K0.
    pub stiffness_residual: Option<f64>,
    /// Time steps of the stage.
    pub steps: u64,
    /// Median wall time of a step (a subdivision for the refinement) in µs.
    pub step_us_median: f64,
    /// Faces cut, vertices torn, tets removed or tets refined.
    pub operations: usize,
    /// Faces dissociated.
    pub cut_faces: usize,
    /// Wall time of the stage's topological operations in ms.
    pub operation_ms: f64,
    /// Largest principal tensile stress of a vertex at the end of the stage.
    pub max_stress: Option<f64>,
    /// Largest distance of a vertex from its rest position.
    pub max_displacement: Option<f64>,
    /// Checks passed since the start (cumulative).
    pub checks_passed: usize,
}

fn counts_row(stage: &'static str, map: &GMap<3>, run: &StageRun) -> StageRow {
    let mut times = run.step_us.clone();
    StageRow {
        stage,
        cells: CellCensus::of(map),
        total_mass: None,
        removed_mass: None,
        mass_residual: None,
        stiffness_sum: None,
        stiffness_residual: None,
        steps: run.steps,
        step_us_median: times.median(),
        operations: run.operations,
        cut_faces: run.cut_faces,
        operation_ms: run.operation_us / 1e3,
        max_stress: None,
        max_displacement: None,
        checks_passed: 0,
    }
}

/// The row of a mechanical stage, from the scene as the stage left it. O(darts).
pub fn scene_row(scene: &Scene, run: &StageRun) -> StageRow {
    let body = &scene.body;
    let ch = &scene.checker;
    let stress = cut::principal_stress(body, &scene.sim).ok(); // None: the simulation does not follow the body
    StageRow {
        total_mass: Some(total_mass(body)),
        removed_mass: Some(ch.removed_mass),
        mass_residual: Some(ch.last.mass),
        stiffness_sum: Some(total_stiffness(body)),
        stiffness_residual: Some(ch.last.stiffness),
        max_stress: stress.map(|stress| stress.iter().map(|s| s.magnitude).fold(0.0, topomech::mesh::nan_max)),
        max_displacement: scene.sim.max_displacement(body).ok(),
        checks_passed: ch.passed,
        ..counts_row(run.name, body.map(), run)
    }
}

/// The row of the refinement: cell counts of the finest level, Σ tet mass (the children share
/// their parents' masses) and Σ k over the springs carried (no residual: a 1→8 adds stiffness).
/// O(darts + E).
pub fn refined_row(r: &Refined, scene: &Scene, run: &StageRun) -> StageRow {
    let ch = &scene.checker;
    let total = r.mech.masses.total(&r.lm);
    StageRow {
        total_mass: Some(total),
        removed_mass: Some(ch.removed_mass),
        mass_residual: Some((total + ch.removed_mass - ch.initial_mass) / ch.initial_mass),
        stiffness_sum: Some(r.mech.springs().map(|(_, s)| s.stiffness).sum()),
        checks_passed: ch.passed,
        ..counts_row(run.name, r.lm.map(), run)
    }
}

/// The springs the refinement carried, for the JSON summary.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SpringsJson {
    /// Springs before the refinement (one per edge cell of the final body).
    pub before: usize,
    /// Springs after it (one per edge cell of the finest level).
    pub after: usize,
    /// Edge cells of the final body sharing both ends with another edge cell (cut edges whose ends
    /// stayed joined): each has its own spring.
    pub doubled_edges: usize,
    /// How many of those the refinement split (each into its own chain).
    pub doubled_split: usize,
}

/// The parameters and files of the run, for the JSON summary.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SceneJson {
    /// Sag steps.
    pub sag_steps: u64,
    /// Time step.
    pub dt: f64,
    /// The integrator.
    pub integrator: &'static str,
    /// Gravity.
    pub gravity: Vec3,
    /// Young's modulus.
    pub young: f64,
    /// Density.
    pub density: f64,
    /// Ambient viscosity.
    pub viscosity: f64,
    /// The damping ratio β of the springs (c = β·k), in seconds.
    pub damping: f64,
    /// Pinned vertices.
    pub pinned: usize,
    /// Tear threshold (a force).
    pub tear_threshold: f64,
}

/// The files written, as paths.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FilesJson {
    /// The output directory.
    pub dir: String,
    /// The ParaView series.
    pub pvd: String,
    /// Its frames.
    pub vtu: Vec<String>,
    /// The OBJ surfaces (the final body's first).
    pub obj: Vec<String>,
    /// The pictures.
    pub png: Vec<String>,
}

/// The JSON summary of `topomech demo --json` (exactly these keys, in this order).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DemoJson {
    /// The mesh's name or path.
    pub mesh_name: String,
    /// `topomech info --json` of the mesh (what `demo --json` printed before the scene).
    pub mesh: InfoJson,
    /// Parameters.
    pub scene: SceneJson,
    /// One row per stage.
    pub stages: Vec<StageRow>,
    /// Checks passed in all.
    pub checks_passed: usize,
    /// Whether every check passed (a failed check stops the demo with exit status 1).
    pub all_checks_passed: bool,
    /// Σ m_v of the initial body.
    pub initial_mass: f64,
    /// Σ m_v at the end.
    pub final_mass: f64,
    /// Mass removed.
    pub removed_mass: f64,
    /// Whether the whole mechanics follows the refinement: the tet masses and springs are carried
    /// (`refinement_springs`) and the simulation goes on on the refined network
    /// (`refined_simulation`).
    pub refinement_mechanics: bool,
    /// The springs carried through the refinement.
    pub refinement_springs: SpringsJson,
    /// The steps made on the refined network after the refinement.
    pub refined_simulation: RefinedSim,
    /// Output files.
    pub files: FilesJson,
    /// Wall time of the whole run in ms.
    pub wall_ms: f64,
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or_else(|| "-".to_string(), f)
}

/// A total mass for the table, with at least 7 significant digits and at most 13 characters at
/// any magnitude: six decimals in [1, 10⁵) (the liver's 38.165235; 99999.9999996 rounds to the
/// 13 characters of 100000.000000), else the exponent form of the Δm/M0 column (1.000000e-9,
/// 1.000000e15, 2.225074e-308). O(1).
fn mass_cell(m: f64) -> String {
    if (1.0..1e5).contains(&m) {
        format!("{m:.6}")
    } else {
        format!("{m:.6e}")
    }
}

/// The summary table: one row per stage. The total mass column is 14 wide for cells of at most
/// 13 characters ([`mass_cell`]), so a mass never runs into the component count. O(stages).
pub fn write_table(out: &mut dyn Write, rows: &[StageRow]) -> std::io::Result<()> {
    writeln!(
        out,
        "  {:<11}{:>6}{:>7}{:>7}{:>7}{:>6}{:>5}{:>14}{:>10}{:>10}{:>7}{:>9}",
        "stage", "V", "E", "F", "T", "bnd", "cmp", "total mass", "Δm/M0", "Δk/K0", "steps", "step µs"
    )?;
    for r in rows {
        writeln!(
            out,
            "  {:<11}{:>6}{:>7}{:>7}{:>7}{:>6}{:>5}{:>14}{:>10}{:>10}{:>7}{:>9}",
            r.stage,
            r.cells.vertices,
            r.cells.edges,
            r.cells.faces,
            r.cells.volumes,
            r.cells.boundary_faces,
            r.cells.components,
            opt(r.total_mass, mass_cell),
            opt(r.mass_residual, |x| format!("{x:.1e}")),
            opt(r.stiffness_residual, |x| format!("{x:.1e}")),
            r.steps,
            if r.step_us_median > 0.0 { format!("{:.1}", r.step_us_median) } else { "-".to_string() },
        )?;
    }
    Ok(())
}

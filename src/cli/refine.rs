//! `topomech refine MESH --around X,Y,Z --radius R --levels L [--conforming]
//! [--cut PX,PY,PZ,NX,NY,NZ] [--springs] [--density D] [--out DIR] [--json]`:
//! adaptive 1→8 refinement of the tets meeting a ball, level by level (issue 5, seed 004), with
//! tet masses shared among the children by rest volume; every law checked at the end.
//! `--conforming` builds the conforming closure (a tet mesh without hanging vertices) and a
//! mechanical body on it; `--cut` also incises the unrefined and the refined bodies along the
//! plane and reports the distance of the cut faces to the plane inside the zone, before and after.
//! `--springs` refines through the spring coupling (`subdivide::LeveledMechanics`: series rule on
//! split edges, springs for new edges) and reports its springs and laws.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use topomech::cut::Plane;
use topomech::load;
use topomech::mechanics::{check_conservation, Body, Material, Vec3};
use topomech::subdivide::{
    cut_error, ConformingMesh, CutSurfaceError, LevelError, LeveledMap, LeveledMechanics, Refinement, TetMasses,
};
use topomech::vtk::Frame;

use super::{other, parse_finite, parse_vec3, print_report, print_warnings, CliError};

/// Arguments of `topomech refine`.
#[derive(Debug, Clone, clap::Args)]
pub struct RefineArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads).
    pub mesh: PathBuf,
    /// Centre of the refinement zone `X,Y,Z`.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub around: Vec3,
    /// Radius of the zone: every tet meeting the ball is refined.
    #[arg(long, allow_hyphen_values = true)]
    pub radius: f64,
    /// Finest level to reach (1 = one 1→8 step).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true,
          value_parser = clap::value_parser!(u8).range(0..=i64::from(topomech::subdivide::MAX_LEVEL)))]
    pub levels: u8,
    /// Refuse a level that would grow the map past this many darts (about 91 bytes each): the
    /// command stops with an error naming the estimate before that level starts.
    #[arg(long, default_value_t = topomech::subdivide::DEFAULT_MAX_DARTS, allow_negative_numbers = true)]
    pub max_darts: usize,
    /// Mass density ρ (tet mass = ρ · volume).
    #[arg(long, default_value_t = Material::default().density, allow_negative_numbers = true)]
    pub density: f64,
    /// Build the conforming closure (tets only, no hanging vertex) and a body on it.
    #[arg(long)]
    pub conforming: bool,
    /// Incise the unrefined and the (conforming) refined body along the plane `PX,PY,PZ,NX,NY,NZ`
    /// and report the cut error against the plane inside the zone, before and after (implies
    /// `--conforming`).
    #[arg(long, value_parser = parse_plane, allow_hyphen_values = true)]
    pub cut: Option<[f64; 6]>,
    /// Refine through the spring coupling and report `springs_before`, `springs_after`,
    /// `stiffness_series_ok`, `spring_laws_ok` (`refine_ms` then includes the coupling).
    #[arg(long)]
    pub springs: bool,
    /// Write `refined.vtu` (the finest level; with `--conforming` also `conforming.vtu`) into this
    /// directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object: volumes, darts, tets_per_level, subdivided_per_level, valid,
    /// mu_order_ok, levels_valid, total_mass_before, total_mass_after, total_vertex_mass_after,
    /// refine_ms, and the keys of --conforming, --cut and --springs.
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
    /// Volumes of the extracted level i, i = 0..=M with M = max(L, the finest level made), L =
    /// `--levels` (as many entries as `subdivided_per_level`): at least L + 1 entries, more when a
    /// tet held back by a coarser neighbour was split past level L (findings 275, 285); a level at which
    /// nothing was refined (an empty zone) repeats the count of the level before it, since
    /// G_i = G_{i−1} then.
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
    /// Tets of the conforming closure (`--conforming` or `--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conforming_tets: Option<usize>,
    /// Faces the incision dissociated in the unrefined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_faces_before: Option<usize>,
    /// Faces the incision dissociated in the conforming refined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_faces_after: Option<usize>,
    /// Cut faces with their centroid in the zone, unrefined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_zone_faces_before: Option<usize>,
    /// Cut faces with their centroid in the zone, refined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_zone_faces_after: Option<usize>,
    /// Largest distance to the plane of a vertex of a cut face in the zone, unrefined (`--cut`;
    /// absent when no face in the zone was cut, as are the other three error figures).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_error_max_before: Option<f64>,
    /// The same on the refined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_error_max_after: Option<f64>,
    /// Mean over the cut faces in the zone of their mean vertex distance to the plane, unrefined.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_error_mean_before: Option<f64>,
    /// The same on the refined body (`--cut`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cut_error_mean_after: Option<f64>,
    /// Springs (edges) before the refinement (`--springs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub springs_before: Option<usize>,
    /// Springs after: one per edge of the finest level (`--springs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub springs_after: Option<usize>,
    /// Every split spring's chain has Σ 1/k_i = 1/k, Σ 1/c_i = 1/c, Σ L_i = L (`--springs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness_series_ok: Option<bool>,
    /// Every law of `LeveledMechanics::check` holds (`--springs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spring_laws_ok: Option<bool>,
}

fn parse_plane(s: &str) -> Result<[f64; 6], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 6 {
        return Err(format!("expected PX,PY,PZ,NX,NY,NZ, got {s:?}"));
    }
    let mut out = [0.0; 6];
    for (o, t) in out.iter_mut().zip(&parts) {
        *o = parse_finite(t)?;
    }
    if out[3..].iter().all(|&c| c == 0.0) {
        return Err(format!("the normal of {s:?} is zero"));
    }
    Ok(out)
}

/// Loads, refines, checks and reports (see the [module docs](self)). Cost: one load, the
/// refinement, and the laws of `check_all`, each checked once ([`Laws`], O(levels · darts)).
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
    let material = Material { density: args.density, ..Material::default() };
    let before_cut = match args.cut {
        Some(plane) => Some(cut_body(&loaded.mesh.points, &loaded.mesh.tets, material, plane, &args, "unrefined")?),
        None => None,
    };
    // One position per vertex id: the extra vertices of pinched points take their point's
    // (finding 207; without them the refinement refused every such mesh).
    let positions = loaded
        .build
        .per_vertex(&loaded.mesh.points)
        .ok_or_else(|| other("the build report names a point the mesh lacks"))?;
    let mut m = LeveledMap::new(loaded.map, positions);
    m.set_max_darts(args.max_darts);
    let (refinement, masses, mech, refine_ms) = refine(&args, &mut m, material)?;
    let laws = Laws::check(&m);
    let mut report = report(&m, &masses, &refinement, refine_ms, &laws)?;
    pad_levels(&mut report.tets_per_level, usize::from(args.levels) + 1);
    if args.levels > 0 && refinement.subdivided_per_level.iter().all(|&n| n == 0) {
        eprintln!(
            "topomech: warning: the zone (ball at {:?}, radius {}) meets no tet: nothing was refined, every level \
             is the input mesh",
            args.around,
            super::number(args.radius)
        );
    }
    if let Some(first) = first_empty_level(&refinement.subdivided_per_level) {
        eprintln!(
            "topomech: warning: levels {first}..={} refined nothing: no tet of level {} is left in the zone",
            args.levels,
            first - 1
        );
    }
    let spring_laws = mech.as_ref().map(|(before, x)| fill_springs(&mut report, *before, x, &m));
    let closure = if args.conforming || args.cut.is_some() {
        let c = m.conforming_tets().map_err(|e| other(format!("{}: conforming closure: {e}", args.mesh.display())))?;
        report.conforming_tets = Some(c.tets.len());
        Some(c)
    } else {
        None
    };
    if let (Some(plane), Some(c), Some(before)) = (args.cut, &closure, before_cut) {
        let after = cut_body(&c.points, &c.tets, material, plane, &args, "refined")?;
        fill_cut(&mut report, &before, &after);
    }
    if let Some(dir) = &args.out {
        write_vtu(&m, dir)?;
        if let Some(c) = &closure {
            write_conforming(c, dir)?;
        }
    }
    print_report(args.json, &report, |out| write_table(out, &report))?;
    if let Some(Err(e)) = spring_laws {
        return Err(other(format!("{}: the spring coupling breaks a law (a topomech bug): {e}", args.mesh.display())));
    }
    match laws.first_error() {
        None => Ok(()),
        Some(e) => Err(other(format!("{}: the refined map breaks a law (a topomech bug): {e}", args.mesh.display()))),
    }
}

/// The first level that refined nothing after one that refined something (the zone ran out
/// of tets: e.g. a radius-0 ball whose point the children no longer tile). O(levels).
fn first_empty_level(per_level: &[usize]) -> Option<usize> {
    let first_busy = per_level.iter().position(|&n| n > 0)?;
    (first_busy + 1..per_level.len()).find(|&k| per_level[k] == 0)
}

/// Pads `tets_per_level` to `levels` entries (levels 0..levels−1) with its last count: a level the
/// refinement did not reach (nothing left to refine) is the level before it. O(levels).
fn pad_levels(tets_per_level: &mut Vec<usize>, levels: usize) {
    if let Some(&last) = tets_per_level.last() {
        tets_per_level.resize(tets_per_level.len().max(levels), last);
    }
}

/// Every law of [`LeveledMap::check_all`], each checked once and kept for both the report's
/// flags and the exit status (the report and `check_all` used to extract and validate every
/// level twice: half of the command's time on a large refinement). O(levels · darts).
struct Laws {
    /// `validate()` of the finest map.
    finest: Result<(), topomech::InvariantViolation>,
    /// `check_levels()`: the μ laws and the nesting of the levels.
    levels: Result<(), LevelError>,
    /// Per level i: the volumes of the extracted G_i, or why it is not a valid G-map.
    per_level: Vec<Result<usize, LevelError>>,
}

impl Laws {
    fn check(m: &LeveledMap<3>) -> Laws {
        let per_level = (0..=m.max_level())
            .map(|i| {
                let view = m.level(i)?;
                view.map.validate().map_err(|source| LevelError::InvalidLevel { level: i, source })?;
                Ok(view.map.count_cells().0[3])
            })
            .collect();
        Laws { finest: m.map().validate(), levels: m.check_levels(), per_level }
    }

    /// The error `check_all` would return: the finest map, then the level laws, then the first
    /// level that is not a valid G-map.
    fn first_error(&self) -> Option<LevelError> {
        if let Err(e) = &self.finest {
            return Some(LevelError::InvalidMap(e.clone()));
        }
        if let Err(e) = &self.levels {
            return Some(e.clone());
        }
        self.per_level.iter().find_map(|r| r.as_ref().err().cloned())
    }
}

/// What [`refine`] returns: the refinement, the tet masses, the coupling with its spring count
/// before (`--springs`), and the wall time in ms.
type Refined = (Refinement, TetMasses, Option<(usize, LeveledMechanics)>, f64);

/// Refines `m` as `args` says, through the spring coupling with `--springs`.
fn refine(args: &RefineArgs, m: &mut LeveledMap<3>, material: Material) -> Result<Refined, CliError> {
    let refused = |e: String| other(format!("{}: refinement refused: {e}", args.mesh.display()));
    let mut masses = TetMasses::from_density(m, args.density).map_err(|e| other(e.to_string()))?;
    let start = Instant::now();
    if args.springs {
        let mut mech = LeveledMechanics::new(m, material).map_err(|e| refused(e.to_string()))?;
        let before = mech.springs().count();
        let r = mech.refine_around(m, args.around, args.radius, args.levels).map_err(|e| refused(e.to_string()))?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        return Ok((r, mech.masses.clone(), Some((before, mech)), ms));
    }
    let r = m.refine_around(args.around, args.radius, args.levels, &mut masses).map_err(|e| refused(e.to_string()))?;
    Ok((r, masses, None, start.elapsed().as_secs_f64() * 1e3))
}

/// The `--springs` keys; returns the result of the full check.
fn fill_springs(
    r: &mut RefineJson,
    before: usize,
    mech: &LeveledMechanics,
    m: &LeveledMap<3>,
) -> Result<(), topomech::subdivide::SpringLawError> {
    let laws = mech.check(m);
    r.springs_before = Some(before);
    r.springs_after = Some(mech.springs().count());
    r.stiffness_series_ok = Some(mech.check_series().is_ok());
    r.spring_laws_ok = Some(laws.is_ok());
    laws
}

/// Builds a body on `tets`, incises it along `plane` and measures the cut in the zone of `args`;
/// the body's map and conservation laws are checked after the cut.
fn cut_body(
    points: &[Vec3],
    tets: &[[u32; 4]],
    material: Material,
    plane: [f64; 6],
    args: &RefineArgs,
    what: &str,
) -> Result<CutSurfaceError, CliError> {
    let name = args.mesh.display();
    let (mut body, _) = Body::from_tets(points, tets, material)
        .map_err(|e| other(format!("{name}: cannot build the {what} body: {e}")))?;
    let plane = Plane { point: [plane[0], plane[1], plane[2]], normal: [plane[3], plane[4], plane[5]] };
    let e = cut_error(&mut body, &plane, Some((args.around, args.radius)))
        .map_err(|e| other(format!("{name}: cutting the {what} body: {e}")))?;
    body.map().validate().map_err(|e| other(format!("{name}: the cut {what} map is invalid (a bug): {e}")))?;
    check_conservation(body.map(), body.attrs())
        .map_err(|e| other(format!("{name}: the cut {what} body breaks a conservation law (a bug): {e}")))?;
    Ok(e)
}

fn fill_cut(r: &mut RefineJson, before: &CutSurfaceError, after: &CutSurfaceError) {
    r.cut_faces_before = Some(before.faces);
    r.cut_faces_after = Some(after.faces);
    r.cut_zone_faces_before = Some(before.measured);
    r.cut_zone_faces_after = Some(after.measured);
    // No cut face in the zone: no error to measure (the figures would be 0/0).
    let measured = |s: &CutSurfaceError, x: f64| (s.measured > 0).then_some(x);
    r.cut_error_max_before = measured(before, before.max);
    r.cut_error_max_after = measured(after, after.max);
    r.cut_error_mean_before = measured(before, before.mean);
    r.cut_error_mean_after = measured(after, after.mean);
}

fn report(
    m: &LeveledMap<3>,
    masses: &TetMasses,
    r: &topomech::subdivide::Refinement,
    refine_ms: f64,
    laws: &Laws,
) -> Result<RefineJson, CliError> {
    // A level that cannot be extracted or is not valid counts 0 volumes (levels_valid is false).
    let tets_per_level = laws.per_level.iter().map(|r| *r.as_ref().unwrap_or(&0)).collect();
    let levels_valid = laws.per_level.iter().all(Result::is_ok);
    let vertex = masses.vertex_masses(m).map_err(|e| other(e.to_string()))?;
    Ok(RefineJson {
        volumes: m.map().count_cells().0[3],
        darts: m.map().dart_count(),
        tets_per_level,
        subdivided_per_level: r.subdivided_per_level.clone(),
        valid: laws.finest.is_ok(),
        mu_order_ok: !matches!(laws.levels, Err(LevelError::MuOrder { .. } | LevelError::MuNotConstant { .. })),
        levels_valid,
        total_mass_before: r.total_mass_before,
        total_mass_after: r.total_mass_after,
        total_vertex_mass_after: vertex.iter().sum(),
        refine_ms,
        conforming_tets: None,
        cut_faces_before: None,
        cut_faces_after: None,
        cut_zone_faces_before: None,
        cut_zone_faces_after: None,
        cut_error_max_before: None,
        cut_error_max_after: None,
        cut_error_mean_before: None,
        cut_error_mean_after: None,
        springs_before: None,
        springs_after: None,
        stiffness_series_ok: None,
        spring_laws_ok: None,
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
        "  {:<26}{} -> {} (relative {residual:.1e})",
        "total mass",
        super::number(r.total_mass_before),
        super::number(r.total_mass_after)
    )?;
    writeln!(out, "  {:<26}{:.3} ms", "refine time", r.refine_ms)?;
    if let (Some(b), Some(a)) = (r.springs_before, r.springs_after) {
        let ok = (r.stiffness_series_ok.unwrap_or(false), r.spring_laws_ok.unwrap_or(false));
        writeln!(out, "  {:<26}{b} -> {a} (series rule {}, all laws {})", "springs", ok.0, ok.1)?;
    }
    if let Some(n) = r.conforming_tets {
        writeln!(out, "  {:<26}{n}", "conforming tets")?;
    }
    if let (Some(fb), Some(fa)) = (r.cut_faces_before, r.cut_faces_after) {
        let (zb, za) = (r.cut_zone_faces_before.unwrap_or(0), r.cut_zone_faces_after.unwrap_or(0));
        writeln!(out, "  {:<26}{fb} -> {fa} (in the zone {zb} -> {za})", "cut faces")?;
        let f = |x: Option<f64>| x.map_or("none".to_string(), |v| super::rounded(v, 6));
        writeln!(
            out,
            "  {:<26}max {} -> {}, mean {} -> {}",
            "cut error in the zone",
            f(r.cut_error_max_before),
            f(r.cut_error_max_after),
            f(r.cut_error_mean_before),
            f(r.cut_error_mean_after)
        )?;
    }
    Ok(())
}

fn write_conforming(c: &ConformingMesh, dir: &std::path::Path) -> Result<(), CliError> {
    let frame = Frame { points: &c.points, tets: &c.tets, vectors: Vec::new() };
    frame.write(&dir.join("conforming.vtu")).map_err(|e| other(e.to_string()))
}

fn write_vtu(m: &LeveledMap<3>, dir: &std::path::Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| other(format!("cannot create the output directory {}: {e}", dir.display())))?;
    let tets: Vec<[u32; 4]> =
        m.finest_tets().map_err(|e| other(e.to_string()))?.into_iter().map(|(t, _, _)| t).collect();
    let frame = Frame { points: m.points(), tets: &tets, vectors: Vec::new() };
    frame.write(&dir.join("refined.vtu")).map_err(|e| other(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// A level that refined nothing after a busy one is named; none before the first busy one.
    #[test]
    fn the_first_empty_level_after_a_busy_one_is_named() {
        assert_eq!(first_empty_level(&[0, 1, 8, 0, 0]), Some(3));
        assert_eq!(first_empty_level(&[0, 0, 4, 32]), None);
        assert_eq!(first_empty_level(&[0, 0, 0]), None);
        assert_eq!(first_empty_level(&[2, 0, 16]), Some(1));
    }

    /// `--levels` above the maximum level is a usage error naming the range (251 was accepted
    /// by the parser and refused later with another message).
    #[test]
    fn levels_past_the_maximum_are_a_usage_error() {
        #[derive(Debug, Parser)]
        struct Line {
            #[command(flatten)]
            args: RefineArgs,
        }
        let parse = |levels: &str| {
            Line::try_parse_from(["refine", "m.msh", "--around", "0,0,0", "--radius", "1", "--levels", levels])
        };
        assert!(parse("250").is_ok());
        let e = parse("251").unwrap_err().to_string();
        assert!(e.contains("0..=250"), "{e}");
    }
}

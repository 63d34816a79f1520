//! `topomech ambiguity [MESH] [--cuts K] [--seed S] [--subdivide P] [--json]`: the random cut
//! campaign of `docs/ambiguity.md` — the g-map and the naive indexed model cut side by side —,
//! with `--subdivide P` the mixed campaign (cuts and tet subdivisions interleaved, each op a
//! subdivision with probability P, on the leveled g-map and the refined indexed model) and, with
//! `--catalogue`, the exhaustive search for maps sharing an adjacency graph.

use std::io::Write;
use std::path::{Path, PathBuf};

use topomech::ambiguity::campaign::{campaign_k, KStats, Run};
use topomech::ambiguity::catalogue::{campaign_vectors, catalogue, symptom_name, Bounds, Catalogue};
use topomech::ambiguity::mixed::{campaign_mixed, MixedError, MixedRun, MixedStats};
use topomech::ambiguity::vector::Vector;
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::mesh::TetMesh;

use super::{other, print_report, CliError};

/// Arguments of `topomech ambiguity`.
#[derive(Debug, Clone, clap::Args)]
pub struct AmbiguityArgs {
    /// Tetrahedral mesh file (any format `topomech info` reads). Default: the built-in liver_547
    /// (547 points, 1852 tets); `kuhn:K` builds a Kuhn cube with 6K³ tets instead.
    pub mesh: Option<PathBuf>,
    /// Cuts per sequence (each at least 1); several values separated by commas.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1usize, 5, 10, 50], value_parser = cut_count, allow_negative_numbers = true)]
    pub cuts: Vec<usize>,
    /// Seed of the random cut sequences.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Random sequences per number of cuts (at least 1; no upper bound: the run takes as long
    /// as asked).
    #[arg(long, default_value_t = 100, value_parser = super::at_least_one, allow_negative_numbers = true)]
    pub sequences: usize,
    /// Also run the mixed campaign: sequences of K ops (K from --cuts), each a tet subdivision
    /// with probability P (in 0..=1) and a cut otherwise.
    #[arg(long, value_name = "P", value_parser = probability, allow_negative_numbers = true)]
    pub subdivide: Option<f64>,
    /// Print one JSON object (keys pairs_found, graph_kind, sequences_tried, mesh, tets, per_k,
    /// first_pairs, subdivide with --subdivide, and catalogue with --catalogue).
    #[arg(long)]
    pub json: bool,
    /// Also run the exhaustive search over small 2D and 3D complexes.
    #[arg(long)]
    pub catalogue: bool,
    /// Write the test vectors (catalogue and shrunk campaign findings) as JSON files into DIR,
    /// each atomically (a failed write leaves an earlier file whole; a name taken by a
    /// directory is refused before any file is written).
    #[arg(long, value_name = "DIR")]
    pub write_vectors: Option<PathBuf>,
    /// Most tests per delta-debugging pass when shrinking a finding for --write-vectors.
    #[arg(long, default_value_t = 4000, allow_negative_numbers = true)]
    pub shrink_budget: usize,
}

/// A finding of the campaign, shrunk when asked.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Finding {
    /// Cuts of the sequence.
    pub k: usize,
    /// Its symptoms.
    pub symptoms: Vec<&'static str>,
    /// The cuts `[t1, t2]`.
    pub cuts: Vec<[u32; 2]>,
}

/// The JSON report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AmbiguityJson {
    /// Sequences where the cut g-map and the uncut one share their vertex–edge graph while the
    /// maps differ (summed over every k).
    pub pairs_found: usize,
    /// The graph of those pairs.
    pub graph_kind: &'static str,
    /// Random sequences run.
    pub sequences_tried: usize,
    /// Sequences after which the indexed model is ambiguous (summed over every k).
    pub indexed_ambiguous: usize,
    /// The mesh (a path, the built-in mesh's name, or `kuhn:K`).
    pub mesh: String,
    /// Its tets.
    pub tets: usize,
    /// The seed.
    pub seed: u64,
    /// Statistics per number of cuts.
    pub per_k: Vec<KStats>,
    /// The first sequence showing each symptom.
    pub first_pairs: Vec<Finding>,
    /// The mixed campaign, with --subdivide.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subdivide: Option<SubdivideJson>,
    /// The exhaustive search, with --catalogue.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub catalogue: Option<CatalogueJson>,
}

/// The mixed cut/subdivide campaign part of the JSON report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SubdivideJson {
    /// Probability of a subdivision per op.
    pub probability: f64,
    /// Sequences where the tet list means another map whose incidence graph is isomorphic to
    /// the g-map's (final state or some level), summed over every k.
    pub pairs_found: usize,
    /// The graph of those pairs.
    pub graph_kind: &'static str,
    /// Mixed sequences run.
    pub sequences_tried: usize,
    /// Sequences after which the indexed model cannot represent the g-map (summed over every k).
    pub indexed_ambiguous: usize,
    /// Sequences with a skeleton pair: a cut splitting no g-map vertex or edge, so the maps before
    /// and after it share their vertex–edge graph (summed over every k).
    pub skeleton_pairs: usize,
    /// Statistics per number of ops.
    pub per_k: Vec<MixedStats>,
    /// The first ambiguous run and the first run with a graph pair (ops and comparisons).
    pub first_runs: Vec<MixedRun>,
}

/// Parses a number of cuts per sequence: at least 1 (a sequence of no cut changes nothing).
fn cut_count(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("a sequence needs at least 1 cut".into()),
        Ok(k) => Ok(k),
        Err(e) => Err(format!("{s:?} is not a count: {e}")),
    }
}

/// Parses a probability in 0..=1.
fn probability(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..=1.0).contains(&p) => Ok(p),
        Ok(p) => Err(format!("{p} is not a probability in 0..=1")),
        Err(e) => Err(format!("{s:?} is not a number: {e}")),
    }
}
/// The catalogue part of the JSON report (counts and names, not the darts).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CatalogueJson {
    /// Per dimension and graph.
    pub counts: Vec<topomech::ambiguity::catalogue::GroupCount>,
    /// (name, description) of each pair vector.
    pub pairs: Vec<(String, String)>,
}

/// Runs the campaign (and the catalogue) and prints the report.
///
/// # Errors
/// [`CliError::Load`] when the mesh cannot be read or built; [`CliError::Other`] when a cut fails
/// (a bug) or the vectors cannot be written; [`CliError::Output`] / [`CliError::Json`] on output.
pub fn run(args: AmbiguityArgs) -> Result<(), CliError> {
    let (name, mesh) = load_mesh(args.mesh.as_deref())?;
    let (positions, tets) = (&mesh.points, &mesh.tets);
    let points = positions.len();
    let mut rng = SplitMix64(args.seed);
    let mut per_k = Vec::new();
    let mut firsts: Vec<(usize, Run)> = Vec::new();
    for &k in &args.cuts {
        let (stats, runs) = campaign_k(points, tets, k, args.sequences, &mut rng)
            .map_err(|e| other(format!("{name}: the cut campaign cannot run: {e}")))?;
        per_k.push(stats);
        firsts.extend(runs.into_iter().map(|r| (k, r)));
    }
    let subdivide = match args.subdivide {
        Some(p) => Some(
            mixed_campaign(positions, tets, &args.cuts, p, args.sequences, args.seed)
                .map_err(|e| mixed_error(&name, &mesh, e))?,
        ),
        None => None,
    };
    let cat = args.catalogue.then(|| catalogue(Bounds::CATALOGUE));
    if let Some(dir) = &args.write_vectors {
        write_vectors(dir, points, tets, &firsts, cat.as_ref(), args.shrink_budget)?;
    }
    let report = AmbiguityJson {
        pairs_found: per_k.iter().map(|s| count(s, "skeleton_unchanged")).sum(),
        graph_kind: "vertex_edge",
        sequences_tried: per_k.iter().map(|s| s.sequences).sum(),
        indexed_ambiguous: per_k.iter().map(|s| s.ambiguous).sum(),
        mesh: name,
        tets: tets.len(),
        seed: args.seed,
        per_k,
        first_pairs: firsts.iter().map(|(k, r)| finding(*k, r)).collect(),
        subdivide,
        catalogue: cat.map(|c| CatalogueJson {
            counts: c.counts,
            pairs: c.pairs.into_iter().map(|p| (p.name, p.description)).collect(),
        }),
    };
    print_report(args.json, &report, |out| write_table(out, &report))
}

/// A mixed campaign's error as the CLI reports it: a degenerate tet is named in the mesh's own
/// terms (the mesh name and the file's node tags of its corners, when the file had tags).
fn mixed_error(name: &str, mesh: &TetMesh, e: MixedError) -> CliError {
    let tags = match &e {
        MixedError::Degenerate { tet, .. } => mesh.tets.get(*tet).and_then(|t| mesh.file_tags(t)),
        _ => None,
    };
    let at = tags.map_or(String::new(), |t| format!(" (file node tags {t:?})"));
    CliError::Other(format!("{name}: the mixed campaign cannot run: {e}{at}").into())
}

/// The mixed campaign for every k, with its own generator (seeded by `seed`), so adding
/// `--subdivide` leaves the cut campaign's figures unchanged.
fn mixed_campaign(
    positions: &[[f64; 3]],
    tets: &[[u32; 4]],
    ks: &[usize],
    p: f64,
    sequences: usize,
    seed: u64,
) -> Result<SubdivideJson, MixedError> {
    let mut rng = SplitMix64(seed);
    let mut per_k = Vec::new();
    let mut first_runs = Vec::new();
    for &k in ks {
        let (stats, runs) = campaign_mixed(positions, tets, k, p, sequences, &mut rng)?;
        per_k.push(stats);
        first_runs.extend(runs);
    }
    Ok(SubdivideJson {
        probability: p,
        pairs_found: per_k.iter().map(|s| s.graph_pairs).sum(),
        graph_kind: "incidence",
        sequences_tried: per_k.iter().map(|s| s.sequences).sum(),
        indexed_ambiguous: per_k.iter().map(|s| s.ambiguous).sum(),
        skeleton_pairs: per_k.iter().map(|s| s.skeleton_pairs).sum(),
        per_k,
        first_runs,
    })
}

fn count(s: &KStats, symptom: &str) -> usize {
    s.symptoms.iter().filter(|(x, _)| symptom_name(*x) == symptom).map(|x| x.1).sum()
}

/// A mesh for the campaigns and its name (a Kuhn cube has no file node tags).
type NamedMesh = (String, TetMesh);

/// The mesh: the file given, `kuhn:K`, or the built-in liver.
fn load_mesh(path: Option<&Path>) -> Result<NamedMesh, CliError> {
    let kuhn = path.and_then(|p| p.to_str()).and_then(|s| s.strip_prefix("kuhn:")).map(str::parse::<usize>);
    match (path, kuhn) {
        (_, Some(Ok(k))) if (1..=16).contains(&k) => {
            let (points, tets) = kuhn_cube(k);
            Ok((format!("kuhn:{k}"), TetMesh { points, tets, ..TetMesh::default() }))
        }
        (_, Some(_)) => Err(CliError::Other("kuhn:K needs K in 1..=16".into())),
        (Some(p), None) => from_loaded(topomech::load::load_tet_map(p)?),
        (None, None) => from_loaded(topomech::load::load_builtin()?),
    }
}

fn from_loaded(loaded: topomech::load::Loaded) -> Result<NamedMesh, CliError> {
    Ok((loaded.path.display().to_string(), loaded.mesh))
}

/// A run as a finding (shrinking is `--write-vectors`'s job).
fn finding(k: usize, run: &Run) -> Finding {
    Finding { k, symptoms: run.symptoms().into_iter().map(symptom_name).collect(), cuts: run.cuts.clone() }
}

fn write_vectors(
    dir: &Path,
    points: usize,
    tets: &[[u32; 4]],
    firsts: &[(usize, Run)],
    cat: Option<&Catalogue>,
    budget: usize,
) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| other(format!("cannot create the vector directory {}: {e}", dir.display())))?;
    let runs: Vec<Run> = firsts.iter().map(|(_, r)| r.clone()).collect();
    let (indexed, pairs) = campaign_vectors(points, tets, &runs, budget.max(1)).map_err(other)?;
    let mut vectors: Vec<Vector> = indexed.into_iter().map(|i| Vector::Indexed(Box::new(i))).collect();
    vectors.extend(pairs.into_iter().map(|p| Vector::Pair(Box::new(p))));
    if let Some(c) = cat {
        vectors.extend(c.pairs.iter().cloned().map(|p| Vector::Pair(Box::new(p))));
    }
    let mut files = Vec::with_capacity(vectors.len());
    for v in &vectors {
        files.push((dir.join(format!("{}.json", v.name())), (serde_json::to_string_pretty(v)? + "\n").into_bytes()));
    }
    super::write_files(&files).map_err(|(file, e)| other(format!("cannot write {}: {e}", file.display())))
}

fn write_table(out: &mut dyn Write, r: &AmbiguityJson) -> std::io::Result<()> {
    writeln!(out, "{} ({} tets), seed {}", r.mesh, r.tets, r.seed)?;
    writeln!(
        out,
        "  {:>4} {:>6} {:>10} {:>7} {:>12} {:>10} {:>9} {:>12} {:>10}",
        "k", "seqs", "ambiguous", "wrong", "face_shared", "pinched", "nm_edge", "gluing_diff", "skeleton"
    )?;
    for s in &r.per_k {
        let c = |name| count(s, name);
        writeln!(
            out,
            "  {:>4} {:>6} {:>10} {:>7} {:>12} {:>10} {:>9} {:>12} {:>10}",
            s.k,
            s.sequences,
            s.ambiguous,
            s.wrong,
            c("face_still_shared"),
            c("pinched_point"),
            c("non_manifold_edge"),
            c("gluing_differs"),
            c("skeleton_unchanged")
        )?;
    }
    writeln!(
        out,
        "pairs_found {} (graph_kind {}), sequences_tried {}",
        r.pairs_found, r.graph_kind, r.sequences_tried
    )?;
    for f in &r.first_pairs {
        let shown: Vec<[u32; 2]> = f.cuts.iter().take(5).copied().collect();
        writeln!(
            out,
            "  first with {:?}: k = {}, cuts {:?}{}",
            f.symptoms,
            f.k,
            shown,
            if f.cuts.len() > 5 { " …" } else { "" }
        )?;
    }
    if let Some(m) = &r.subdivide {
        write_mixed(out, m)?;
    }
    if let Some(c) = &r.catalogue {
        writeln!(out, "exhaustive search:")?;
        for g in &c.counts {
            writeln!(
                out,
                "  {}D {:<12} {:?}: {} classes, {} ambiguous groups",
                g.dim,
                g.graph_kind.name(),
                g.multiplicity,
                g.classes,
                g.groups
            )?;
        }
        for (name, text) in &c.pairs {
            writeln!(out, "  {name}: {text}")?;
        }
    }
    Ok(())
}

fn write_mixed(out: &mut dyn Write, m: &SubdivideJson) -> std::io::Result<()> {
    writeln!(out, "cuts and subdivisions interleaved, P(subdivide) = {}", m.probability)?;
    writeln!(
        out,
        "  {:>4} {:>6} {:>10} {:>7} {:>8} {:>8} {:>6} {:>8} {:>9} {:>6} {:>5} {:>6} {:>7} {:>8} {:>9}",
        "k",
        "seqs",
        "ambiguous",
        "wrong",
        "hanging",
        "inexpr",
        "lost",
        "non_mfd",
        "vert_diff",
        "pairs",
        "skel",
        "subdiv",
        "refused",
        "levels",
        "lvl_ambig"
    )?;
    for s in &m.per_k {
        writeln!(
            out,
            "  {:>4} {:>6} {:>10} {:>7} {:>8} {:>8} {:>6} {:>8} {:>9} {:>6} {:>5} {:>6} {:>7} {:>8} {:>9}",
            s.k,
            s.sequences,
            s.ambiguous,
            s.wrong,
            s.hanging,
            s.inexpressible,
            s.lost,
            s.non_manifold,
            s.vertices_differ,
            s.graph_pairs,
            s.skeleton_pairs,
            s.subdivisions,
            s.refused,
            s.levels_compared,
            s.levels_ambiguous
        )?;
        let broken = s.level_law_broken + s.gmap_invalid + s.first_moment_moved;
        if broken + s.graph_undecided + s.skeleton_violations > 0 {
            writeln!(
                out,
                "       level law broken {}, g-map invalid {}, first moment moved {}, graph pairs undecided {}, skeleton violations {}",
                s.level_law_broken, s.gmap_invalid, s.first_moment_moved, s.graph_undecided, s.skeleton_violations
            )?;
        }
    }
    writeln!(
        out,
        "pairs_found {} (graph_kind {}), skeleton_pairs {} (graph_kind vertex_edge), sequences_tried {}",
        m.pairs_found, m.graph_kind, m.skeleton_pairs, m.sequences_tried
    )?;
    for r in &m.first_runs {
        let shown: Vec<_> = r.ops.iter().take(6).collect();
        writeln!(
            out,
            "  first {}: ops {:?}{}",
            if r.ambiguous() { "ambiguous" } else { "graph pair" },
            shown,
            if r.ops.len() > 6 { " …" } else { "" }
        )?;
    }
    Ok(())
}

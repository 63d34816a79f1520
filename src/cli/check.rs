//! `topomech check FILE [--json] [--limit N]`: validate a map file written by anyone in the
//! documented format (`docs/FILE_FORMAT.md`) and list each broken law with its darts.
//!
//! Exit status: 0 when every law holds, 1 when laws are broken (after printing them), 2 when the
//! file cannot be read or decoded (one line `topomech: error: …` on stderr), 3 when every law
//! holds but the report could not be written to stdout (a pipe whose reader has gone, a full
//! device; one line on stderr). A broken map exits with 1 whether or not its report was written:
//! the status is the map's verdict first (`check m.tmap | head -1` never turns a broken map into
//! 0, nor a failed write into "laws are broken").

use std::io::Write;
use std::path::PathBuf;

use topomech::gmap::InvariantViolation;
use topomech::store::{self, CheckReport, Finding};
use topomech::subdivide::{LevelError, LevelPartsError};

use super::{print_report, CliError};

/// Arguments of `topomech check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// A `.tmap` (text) or `.tmapb` (binary) map file; the form is told by its first bytes.
    pub file: PathBuf,
    /// Print one JSON object: file, dimension, darts, max_level (null without levels), valid,
    /// findings [{law, darts, message}], truncated.
    #[arg(long)]
    pub json: bool,
    /// List at most this many broken laws.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    pub limit: usize,
}

/// Decodes the file, runs [`store::check_all_laws`], prints the report and exits with 0, 1, 2 or
/// 3 (see the module docs). Cost: O(file size + darts · n²).
///
/// # Errors
/// None returned: an unreadable file, a broken law and a report that could not be written end
/// the process with status 2, 1 and 3 instead of returning.
pub fn run(args: CheckArgs) -> Result<(), CliError> {
    let doc = match store::read_document(&args.file) {
        Ok(doc) => doc,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "topomech: error: {}", super::named(&args.file, e.to_string()));
            std::process::exit(2);
        }
    };
    let report = store::check_all_laws(&doc, args.limit);
    let darts = doc.map.capacity as usize - doc.map.free_darts.len();
    let levels = doc.levels.as_ref().map(|l| l.max_level);
    let value = json_report(&args, doc.map.dimension, darts, levels, &report);
    let printed =
        print_report(args.json, &value, |out| write_table(out, &args, (doc.map.dimension, darts, levels), &report));
    if let Err(e) = &printed {
        let _ = writeln!(std::io::stderr(), "topomech: error: {e}");
    }
    match (report.valid, printed) {
        (false, _) => std::process::exit(1),
        (true, Err(_)) => std::process::exit(3),
        (true, Ok(())) => Ok(()),
    }
}

fn write_table(
    out: &mut dyn Write,
    args: &CheckArgs,
    (dim, darts, levels): (usize, usize, Option<u8>),
    report: &CheckReport,
) -> std::io::Result<()> {
    let verdict = if report.valid { "valid" } else { "INVALID" };
    let levels = levels.map_or(String::new(), |k| format!(", levels 0..={k}"));
    writeln!(out, "{}: {dim}-G-map, {darts} darts{levels}: {verdict}", args.file.display())?;
    for f in &report.findings {
        writeln!(out, "  [{}] {f}", law_name(f))?;
    }
    if report.truncated {
        writeln!(out, "  … more broken laws not listed (--limit {})", args.limit)?;
    }
    Ok(())
}

fn json_report(
    args: &CheckArgs,
    dim: usize,
    darts: usize,
    levels: Option<u8>,
    report: &CheckReport,
) -> serde_json::Value {
    let findings: Vec<serde_json::Value> = report
        .findings
        .iter()
        .map(|f| serde_json::json!({ "law": law_name(f), "darts": darts_of(f), "message": f.to_string() }))
        .collect();
    serde_json::json!({
        "file": args.file.display().to_string(),
        "dimension": dim,
        "darts": darts,
        "max_level": levels,
        "valid": report.valid,
        "findings": findings,
        "truncated": report.truncated,
    })
}

/// Stable law names: involution, quasi_manifold, cell_id_constant, cell_id_unique, body_state,
/// conservation, and for levels: level_record, mu_order, mu_constant, level_closed, level_valid,
/// flat_flag, own_level, split_log, vertex_origin (and structure, which a decoded file never has).
fn law_name(f: &Finding) -> &'static str {
    match f {
        Finding::Map(v) => map_law_name(v),
        Finding::Conservation(_) => "conservation",
        Finding::Level(LevelPartsError::Law(e)) => match e {
            LevelError::MuOrder { .. } | LevelError::AboveMaxLevel { .. } => "mu_order",
            LevelError::MuNotConstant { .. } => "mu_constant",
            LevelError::NotClosed { .. } => "level_closed",
            LevelError::InvalidLevel { .. } | LevelError::InvalidMap(_) => "level_valid",
            LevelError::FlatFlag { .. } => "flat_flag",
            LevelError::SplitLog { .. } => "split_log",
            LevelError::NotAtOwnLevel { .. } | LevelError::AboveOwnLevel { .. } => "own_level",
            LevelError::OriginNotRoot { .. }
            | LevelError::OriginElsewhere { .. }
            | LevelError::OriginTwiceInCell { .. } => "vertex_origin",
        },
        Finding::Level(_) => "level_record",
        Finding::LevelMap { .. } => "level_valid",
        Finding::Structure(_) => "structure",
        Finding::BodyState(_) => "body_state",
    }
}

fn map_law_name(v: &InvariantViolation) -> &'static str {
    match v.law() {
        topomech::gmap::Law::Involution => "involution",
        topomech::gmap::Law::QuasiManifold => "quasi_manifold",
        topomech::gmap::Law::CellIdConstant => "cell_id_constant",
        topomech::gmap::Law::CellIdUnique => "cell_id_unique",
        topomech::gmap::Law::TetLayout => "tet_layout",
    }
}

/// The darts a finding names (the first is the dart the law fails at).
fn darts_of(f: &Finding) -> Vec<u32> {
    match f {
        Finding::Map(v) | Finding::LevelMap { violation: v, .. } => violation_darts(v),
        Finding::Conservation(_) | Finding::Structure(_) | Finding::BodyState(_) => Vec::new(),
        Finding::Level(e) => level_darts(e),
    }
}

fn violation_darts(v: &InvariantViolation) -> Vec<u32> {
    use InvariantViolation::*;
    match v {
        DanglingLink { dart, .. } => vec![dart.0],
        NotInvolution { dart, image, .. } => vec![dart.0, image.0],
        QuasiManifold { dart, .. } => vec![dart.0],
        CellIdDiffers { dart, other, .. } => vec![dart.0, other.0],
        CellIdNotLive { dart, .. } => vec![dart.0],
        CellIdShared { first, second, .. } => vec![first.0, second.0],
        CellIdOrphan { .. } => Vec::new(),
        TetLayout { dart, .. } => vec![dart.0],
    }
}

fn level_darts(e: &LevelPartsError) -> Vec<u32> {
    match e {
        LevelPartsError::DartLevelAboveMax { dart, .. }
        | LevelPartsError::MuAboveMax { dart, .. }
        | LevelPartsError::BadHistory { dart, .. } => vec![dart.0],
        LevelPartsError::Law(
            LevelError::MuOrder { dart, .. }
            | LevelError::AboveMaxLevel { dart, .. }
            | LevelError::FlatFlag { dart, .. }
            | LevelError::OriginTwiceInCell { dart, .. }
            | LevelError::AboveOwnLevel { dart, .. },
        ) => vec![dart.0],
        LevelPartsError::Law(LevelError::NotAtOwnLevel { dart, escape, .. }) => {
            std::iter::once(dart.0).chain(escape.map(|y| y.0)).collect()
        }
        LevelPartsError::Law(LevelError::MuNotConstant { dart, other, .. }) => vec![dart.0, other.0],
        LevelPartsError::Law(LevelError::NotClosed { dart, image, .. }) => vec![dart.0, image.0],
        LevelPartsError::Law(LevelError::InvalidLevel { source: v, .. } | LevelError::InvalidMap(v)) => {
            violation_darts(v)
        }
        LevelPartsError::WrongLength { .. }
        | LevelPartsError::MaxLevelTooHigh(_)
        | LevelPartsError::BadOrigin { .. }
        | LevelPartsError::Law(
            LevelError::SplitLog { .. } | LevelError::OriginNotRoot { .. } | LevelError::OriginElsewhere { .. },
        ) => Vec::new(),
    }
}

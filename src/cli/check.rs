//! `topomech check FILE [--json] [--limit N]`: validate a map file written by anyone in the
//! documented format (`docs/FILE_FORMAT.md`) and list each broken law with its darts.
//!
//! Exit status: 0 when every law holds, 1 when laws are broken (after printing them), 2 when the
//! file cannot be read or decoded (one line `topomech: error: …` on stderr).

use std::io::Write;
use std::path::PathBuf;

use topomech::gmap::InvariantViolation;
use topomech::store::{self, CheckReport, Finding};

use super::CliError;

/// Arguments of `topomech check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// A `.tmap` (text) or `.tmapb` (binary) map file; the form is told by its first bytes.
    pub file: PathBuf,
    /// Print one JSON object: file, dimension, darts, valid, findings [{law, darts, message}],
    /// truncated.
    #[arg(long)]
    pub json: bool,
    /// List at most this many broken laws.
    #[arg(long, default_value_t = 100)]
    pub limit: usize,
}

/// Decodes the file, runs [`store::check_all_laws`], prints the report and exits with 0, 1 or 2
/// (see the module docs). Cost: O(file size + darts · n²).
///
/// # Errors
/// [`CliError::Output`] when stdout fails; an unreadable file and a broken law end the process
/// with status 2 and 1 instead of returning.
pub fn run(args: CheckArgs) -> Result<(), CliError> {
    let doc = match store::read_document(&args.file) {
        Ok(doc) => doc,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "topomech: error: {}: {e}", args.file.display());
            std::process::exit(2);
        }
    };
    let report = store::check_all_laws(&doc, args.limit);
    let darts = doc.map.capacity as usize - doc.map.free_darts.len();
    let mut out = std::io::stdout().lock();
    if args.json {
        let value = json_report(&args, doc.map.dimension, darts, &report);
        serde_json::to_writer(&mut out, &value)?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &args, doc.map.dimension, darts, &report)?;
    }
    out.flush()?;
    if !report.valid {
        std::process::exit(1);
    }
    Ok(())
}

fn write_table(
    out: &mut dyn Write,
    args: &CheckArgs,
    dim: usize,
    darts: usize,
    report: &CheckReport,
) -> std::io::Result<()> {
    let verdict = if report.valid { "valid" } else { "INVALID" };
    writeln!(out, "{}: {dim}-G-map, {darts} darts: {verdict}", args.file.display())?;
    for f in &report.findings {
        writeln!(out, "  [{}] {f}", law_name(f))?;
    }
    if report.truncated {
        writeln!(out, "  … more broken laws not listed (--limit {})", args.limit)?;
    }
    Ok(())
}

fn json_report(args: &CheckArgs, dim: usize, darts: usize, report: &CheckReport) -> serde_json::Value {
    let findings: Vec<serde_json::Value> = report
        .findings
        .iter()
        .map(|f| serde_json::json!({ "law": law_name(f), "darts": darts_of(f), "message": f.to_string() }))
        .collect();
    serde_json::json!({
        "file": args.file.display().to_string(),
        "dimension": dim,
        "darts": darts,
        "valid": report.valid,
        "findings": findings,
        "truncated": report.truncated,
    })
}

/// Stable law names: involution, quasi_manifold, cell_id_constant, cell_id_unique, conservation.
fn law_name(f: &Finding) -> &'static str {
    match f {
        Finding::Map(v) => match v.law() {
            topomech::gmap::Law::Involution => "involution",
            topomech::gmap::Law::QuasiManifold => "quasi_manifold",
            topomech::gmap::Law::CellIdConstant => "cell_id_constant",
            topomech::gmap::Law::CellIdUnique => "cell_id_unique",
        },
        Finding::Conservation(_) => "conservation",
    }
}

/// The darts a finding names (the first is the dart the law fails at).
fn darts_of(f: &Finding) -> Vec<u32> {
    use InvariantViolation::*;
    match f {
        Finding::Map(DanglingLink { dart, .. }) => vec![dart.0],
        Finding::Map(NotInvolution { dart, image, .. }) => vec![dart.0, image.0],
        Finding::Map(QuasiManifold { dart, .. }) => vec![dart.0],
        Finding::Map(CellIdDiffers { dart, other, .. }) => vec![dart.0, other.0],
        Finding::Map(CellIdNotLive { dart, .. }) => vec![dart.0],
        Finding::Map(CellIdShared { first, second, .. }) => vec![first.0, second.0],
        Finding::Map(CellIdOrphan { .. }) | Finding::Conservation(_) => Vec::new(),
    }
}

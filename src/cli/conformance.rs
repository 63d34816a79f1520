//! `topomech conformance generate DIR` and `topomech conformance check FILE_OR_DIR`: write the
//! standard conformance vectors, or replay vector files and report one line per vector
//! (`docs/CONFORMANCE.md`).
//!
//! `check` exits with 0 when every vector replays, 1 when one mismatches (or breaks a law, or is
//! refused by [`Vector::check_fields`](topomech::conformance::Vector::check_fields), or is
//! ambiguous: an `incise` plane within the margin of a tet centroid, reported as "ambiguous
//! vector", not as "expected …, got …"; or its name is not its file stem), 2 when a file cannot be read or parsed (wrong format or version) or the
//! directory holds none, and 3 when every vector passed but the report could not be written
//! (a write to stdout failed: a pipe whose reader has gone, a full device). A stdout that was
//! closed before the process started (`>&-`) is not seen: Rust's runtime opens /dev/null in its
//! place, so the report is discarded and the status is the vectors' own.
//! A write error does not stop the check: every vector is still replayed, and the status is the
//! worst vector's when one failed. Report lines show control characters escaped (`\n`, `\u{1b}`),
//! so no path or message can start a line of its own.

use std::io::Write;
use std::path::{Path, PathBuf};

use topomech::conformance::{self, standard, ConformanceError};

use super::CliError;

/// Arguments of `topomech conformance`.
#[derive(Debug, Clone, clap::Args)]
pub struct ConformanceArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: Action,
}

/// `generate` or `check`.
#[derive(Debug, Clone, clap::Subcommand)]
pub enum Action {
    /// Write the standard set as DIR/NAME.json (review the diff before committing); each file
    /// atomically, so a failed write leaves the earlier file whole.
    Generate {
        /// Output directory (created if missing).
        dir: PathBuf,
        /// Repository root that mesh paths of file vectors are relative to.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
    /// Replay one vector file, or every `*.json` of a directory.
    Check {
        /// A vector file or a directory of them.
        path: PathBuf,
        /// Repository root that mesh paths of file vectors are relative to.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
}

/// Runs the action (see the module docs for exit statuses). Cost: that of generating or
/// replaying every vector.
///
/// # Errors
/// [`CliError::Output`] when stdout fails (`generate`), [`CliError::Other`] when generation fails
/// or a file cannot be written; `check` ends the process with status 1, 2 or 3 (module docs)
/// instead of returning an error.
pub fn run(args: ConformanceArgs) -> Result<(), CliError> {
    match args.action {
        Action::Generate { dir, root } => generate(&dir, &root),
        Action::Check { path, root } => check(&path, &root),
    }
}

fn generate(dir: &Path, root: &Path) -> Result<(), CliError> {
    let vectors = standard::generate_all(root).map_err(|e| CliError::Other(Box::new(e)))?;
    std::fs::create_dir_all(dir)
        .map_err(|source| CliError::Other(Box::new(ConformanceError::Io { path: dir.to_path_buf(), source })))?;
    let files: Vec<(PathBuf, Vec<u8>)> =
        vectors.iter().map(|v| (dir.join(format!("{}.json", v.name)), v.to_json().into_bytes())).collect();
    super::write_files(&files)
        .map_err(|(path, source)| CliError::Other(Box::new(ConformanceError::Io { path, source })))?;
    let mut out = std::io::stdout().lock();
    for (v, (path, _)) in vectors.iter().zip(&files) {
        writeln!(out, "wrote {} ({} steps)", path.display(), v.steps.len())?;
    }
    writeln!(out, "review the changes (git diff {}) before committing them", dir.display())?;
    Ok(())
}

/// 0 ok, 1 mismatch, 2 unreadable.
fn status(e: &ConformanceError) -> u8 {
    match e {
        ConformanceError::Io { .. }
        | ConformanceError::Json { .. }
        | ConformanceError::Format { .. }
        | ConformanceError::Version { .. } => 2,
        _ => 1,
    }
}

/// The report on stdout: each line with its control characters escaped. The first write error
/// is kept and later lines are dropped (the check goes on).
struct Report<W: Write> {
    out: W,
    error: Option<std::io::Error>,
}

impl<W: Write> Report<W> {
    fn line(&mut self, text: &str) {
        if self.error.is_none() {
            let escaped: String = text
                .chars()
                .map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() })
                .collect();
            if let Err(e) = writeln!(self.out, "{escaped}") {
                self.error = Some(e);
            }
        }
    }

    /// Flushes; the first write error, if any.
    fn finish(mut self) -> Option<std::io::Error> {
        if self.error.is_none() {
            self.error = self.out.flush().err();
        }
        self.error
    }
}

fn check(path: &Path, root: &Path) -> Result<(), CliError> {
    let files = if path.is_dir() {
        conformance::vector_files(path).map_err(|e| CliError::Other(Box::new(e)))?
    } else {
        vec![path.to_path_buf()]
    };
    if files.is_empty() {
        let _ = writeln!(std::io::stderr(), "topomech: error: {}: no *.json vectors", path.display());
        std::process::exit(2);
    }
    let mut report = Report { out: std::io::stdout().lock(), error: None };
    let (mut worst, mut failed) = (0, 0);
    for file in &files {
        match conformance::check_file(file, root) {
            Ok(v) => report.line(&format!("ok    {} ({} steps)", v.name, v.steps.len())),
            Err(e) => {
                worst = worst.max(status(&e));
                failed += 1;
                report.line(&format!("FAIL  {}", super::named(file, e.to_string())));
            }
        }
    }
    report.line(&format!("{} vector(s) checked, {failed} failed", files.len()));
    if let Some(e) = report.finish() {
        let _ = writeln!(std::io::stderr(), "topomech: error: the report could not be written to stdout: {e}");
        std::process::exit(if worst > 0 { worst.into() } else { 3 });
    }
    if worst > 0 {
        std::process::exit(worst.into());
    }
    Ok(())
}

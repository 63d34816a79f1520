//! The subcommands of the `topomech` binary, one file each, and what they share: the error type
//! and the report of a map's characteristics (as a table or as JSON).
//!
//! Every subcommand is `pub fn run(args: XArgs) -> Result<(), CliError>` in its own file; `main`
//! prints a returned error as one line on stderr and exits with status 1.

pub mod ambiguity;
pub mod bench_step;
pub mod check;
pub mod conformance;
pub mod cut;
pub mod demo;
pub mod info;
pub mod refine;
pub mod simulate;

use std::io::Write;
use std::path::{Path, PathBuf};

use topomech::load::{self, LoadError, Loaded};
use topomech::mechanics::{Body, Material, ModelError};
use topomech::mesh::TetMesh;
use topomech::{BuildReport, GMap, InvariantViolation};

/// Why a subcommand failed. `main` prints it as `topomech: error: {self}`.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The mesh could not be read, checked or built; the message names the file (and the line or
    /// byte when the reader knows it).
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The map was built but breaks a law of n-G-maps: a bug in topomech, reported, not hidden.
    #[error("{}: the map breaks an n-G-map law (a topomech bug): {violation}", .path.display())]
    Invalid {
        /// The mesh file.
        path: PathBuf,
        /// The first law found broken.
        violation: InvariantViolation,
    },
    /// Writing to stdout failed (a closed pipe is not reported: see `main`), while writing a
    /// table or a JSON report alike.
    #[error("cannot write the output: {0}")]
    Output(#[from] std::io::Error),
    /// The JSON report could not be encoded (never an I/O error: `From<serde_json::Error>` makes
    /// a failed write an [`CliError::Output`]).
    #[error("cannot encode the JSON report: {0}")]
    Json(serde_json::Error),
    /// The mesh loaded, but the mass/spring model cannot stand on it (a zero-volume tet, a bad
    /// material): the message names the file and the element.
    #[error("{}: cannot build the mass/spring model: {source}{at}", .path.display())]
    Model {
        /// The mesh file.
        path: PathBuf,
        /// Why the model refused it.
        source: ModelError,
        /// The file's node tags of the points named, when the mesh knows them (empty otherwise):
        /// they survive the point reorderings, the tet index does not.
        at: String,
    },
    /// Any other failure of a subcommand, with its own message (for subcommands whose errors are
    /// defined in the library, e.g. the mechanics).
    #[error(transparent)]
    Other(Box<dyn std::error::Error + Send + Sync>),
}

/// A serde_json error as the CLI reports it: a failed write of the JSON text (a full device, a
/// closed pipe) is an [`CliError::Output`] with the write's own error kind, so that it is treated
/// as every other output error (`main` exempts a closed pipe); anything else is
/// [`CliError::Json`]. O(1).
impl From<serde_json::Error> for CliError {
    fn from(e: serde_json::Error) -> Self {
        match e.io_error_kind() {
            Some(_) => CliError::Output(e.into()),
            None => CliError::Json(e),
        }
    }
}

/// [`CliError::Other`] from a library error or a message. O(1).
pub(crate) fn other(e: impl Into<Box<dyn std::error::Error + Send + Sync>>) -> CliError {
    CliError::Other(e.into())
}

/// The mass/spring body of `mesh`, read from `path`, and the build's report (which vertex ids
/// past the points stand for which pinched point); a model error names the file and the file's
/// node tags of the points at fault ([`model_error`]). O(tets).
pub(crate) fn build_body(path: &Path, mesh: &TetMesh, material: Material) -> Result<(Body, BuildReport), CliError> {
    Body::from_tets(&mesh.points, &mesh.tets, material).map_err(|e| model_error(path, mesh, e))
}

/// `point_of[id]` for every vertex id of a body built on `points` points with `report`: the
/// point each id stands for (`point_of` given for the points themselves, e.g. the identity or
/// the file's point through a renumbering), extended to the extra vertices of pinched points.
/// O(points + extra vertices).
pub(crate) fn with_extra_vertices(mut point_of: Vec<u32>, report: &BuildReport) -> Vec<u32> {
    for &(id, p) in &report.extra_vertices {
        let point = point_of.get(p as usize).copied().unwrap_or(u32::MAX);
        if point_of.len() <= id as usize {
            point_of.resize(id as usize + 1, u32::MAX);
        }
        point_of[id as usize] = point;
    }
    point_of
}

/// [`CliError::Model`] for a model built on `mesh`, read from `path`: names the file's node tags
/// of the points of the tet or the point at fault, when the mesh knows them. O(1).
pub(crate) fn model_error(path: &Path, mesh: &TetMesh, source: ModelError) -> CliError {
    let points: Vec<u32> = match &source {
        ModelError::DegenerateTet { tet }
        | ModelError::Overflow { tet, .. }
        | ModelError::VolumeUnderflow { tet, .. }
        | ModelError::MassTooSmall { tet, .. } => mesh.tets.get(*tet).map_or(Vec::new(), |t| t.to_vec()),
        ModelError::NonFinitePoint { point, .. } => vec![*point as u32],
        _ => Vec::new(),
    };
    let at = mesh.file_tags(&points).map_or(String::new(), |tags| format!(" (file node tags {tags:?})"));
    CliError::Model { path: path.to_path_buf(), source, at }
}

/// The cell census of a 3-map that every report carries (flattened into its JSON object: these
/// keys, in this order): cells per dimension, boundary faces, connected components.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct CellCensus {
    /// 0-cells.
    pub vertices: usize,
    /// 1-cells (the springs of a mass/spring model).
    pub edges: usize,
    /// 2-cells.
    pub faces: usize,
    /// 3-cells (the tets).
    pub volumes: usize,
    /// 2-cells made of α3-free darts.
    pub boundary_faces: usize,
    /// Connected components (orbits of all involutions).
    pub components: usize,
}

impl CellCensus {
    /// The census of `map`: counts from the cell-id allocators, one pass over the boundary and one
    /// over the components. O(darts).
    pub fn of(map: &GMap<3>) -> Self {
        let cells = map.count_cells().0;
        CellCensus {
            vertices: cells[0],
            edges: cells[1],
            faces: cells[2],
            volumes: cells[3],
            boundary_faces: map.boundary_cell_count(),
            components: map.components().len(),
        }
    }
}

/// The characteristics `topomech info --json` prints: exactly these keys, in this order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InfoJson {
    /// Live darts (24 per tet).
    pub darts: usize,
    /// Cells, boundary faces, components.
    #[serde(flatten)]
    pub cells: CellCensus,
    /// V − E + F − T.
    pub euler_characteristic: i64,
    /// Whether `validate()` passed.
    pub valid: bool,
    /// Time of `GMap::from_tets` in milliseconds, rounded to the microsecond.
    pub build_ms: f64,
}

/// Everything `info` and the demo report about a loaded mesh.
#[derive(Debug, Clone)]
pub struct Characteristics {
    /// The fields of the JSON report.
    pub json: InfoJson,
    /// Points in the file.
    pub points: usize,
    /// Tetrahedra in the file.
    pub tets: usize,
    /// Whether every component is orientable.
    pub orientable: bool,
    /// Memory of topology and cell ids per live dart.
    pub bytes_per_dart: f64,
    /// The first broken law, when `valid` is false.
    pub violation: Option<InvariantViolation>,
}

impl Characteristics {
    /// Measures `loaded.map`: cell counts from the id allocators, boundary, components,
    /// orientability and a full `validate()`. O(darts · n²).
    pub fn of(loaded: &Loaded) -> Self {
        let map: &GMap<3> = &loaded.map;
        let cells = map.count_cells();
        let violation = map.validate().err();
        Characteristics {
            json: InfoJson {
                darts: map.dart_count(),
                cells: CellCensus::of(map),
                euler_characteristic: cells.euler_characteristic(),
                valid: violation.is_none(),
                build_ms: (loaded.build_ms * 1e3).round() / 1e3,
            },
            points: loaded.mesh.points.len(),
            tets: loaded.mesh.tets.len(),
            orientable: map.is_orientable(),
            bytes_per_dart: map.bytes_per_dart(),
            violation,
        }
    }

    /// `Err(CliError::Invalid)` when the map failed validation. O(1).
    pub fn ensure_valid(&self, path: &std::path::Path) -> Result<(), CliError> {
        match &self.violation {
            Some(v) => Err(CliError::Invalid { path: path.to_path_buf(), violation: v.clone() }),
            None => Ok(()),
        }
    }

    /// The report as `label  value` rows, one per line. O(1).
    pub fn write_table(&self, out: &mut dyn Write) -> std::io::Result<()> {
        let j = &self.json;
        let yes_no = |b: bool| if b { "yes" } else { "NO" };
        let rows: [(&str, String); 14] = [
            ("file points / tets", format!("{} / {}", self.points, self.tets)),
            ("darts", j.darts.to_string()),
            ("vertices", j.cells.vertices.to_string()),
            ("edges", j.cells.edges.to_string()),
            ("faces", j.cells.faces.to_string()),
            ("volumes", j.cells.volumes.to_string()),
            ("boundary faces", j.cells.boundary_faces.to_string()),
            ("components", j.cells.components.to_string()),
            ("Euler characteristic", j.euler_characteristic.to_string()),
            ("orientable", yes_no(self.orientable).to_string()),
            ("valid", yes_no(j.valid).to_string()),
            ("build time", format!("{:.2} ms", j.build_ms)),
            ("bytes per dart", format!("{:.1}", self.bytes_per_dart)),
            ("memory (topology)", format!("{:.2} MiB", self.bytes_per_dart * j.darts as f64 / (1024.0 * 1024.0))),
        ];
        for (label, value) in rows {
            writeln!(out, "  {label:<22}{value}")?;
        }
        Ok(())
    }

    /// The JSON object of [`InfoJson`] on one line. O(1).
    pub fn write_json(&self, out: &mut dyn Write) -> Result<(), CliError> {
        serde_json::to_writer(&mut *out, &self.json)?;
        writeln!(out)?;
        Ok(())
    }
}

/// Prints a command's report on stdout: the JSON object of `report` on one line when `json`,
/// else what `table` writes (the human-readable form). O(size of the report).
pub(crate) fn print_report(
    json: bool,
    report: &impl serde::Serialize,
    table: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    if json {
        serde_json::to_writer(&mut out, report)?;
        writeln!(out)?;
    } else {
        table(&mut out)?;
    }
    out.flush()?;
    Ok(())
}

/// Writes each `(path, bytes)` through [`topomech::store::write_atomically`] (a temporary file
/// beside the target and a rename; a symbolic link is followed and keeps being a link, the old
/// file's permissions are kept), so a failed write (a full disk) leaves the earlier file at that
/// path whole, never truncated — unless its directory takes no new file and it is written in
/// place (see `write_atomically`). Every path is checked before the first write: one that exists
/// and is not a regular file (a directory, a device), or a file that cannot be opened for writing
/// (read-only for this user), is refused then, so such a run replaces nothing. A later write
/// failing (the disk filling up) leaves the files before it new and the rest as they were.
/// O(total bytes).
///
/// # Errors
/// The path and the cause of the first refusal or failed write.
pub(crate) fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<(), (PathBuf, std::io::Error)> {
    for (path, _) in files {
        refuse_unwritable(path).map_err(|why| (path.clone(), why))?;
    }
    for (path, bytes) in files {
        topomech::store::write_atomically(path, bytes).map_err(|e| match e {
            topomech::store::StoreError::Io { source, .. } => (path.clone(), source),
            other => (path.clone(), std::io::Error::other(other.to_string())),
        })?;
    }
    Ok(())
}

/// `Err` when `path` exists and is not a regular file, or is a regular file that does not open
/// for writing (opened without truncation; nothing is written). O(1).
fn refuse_unwritable(path: &Path) -> std::io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => {
            Err(std::io::Error::other("it exists and is not a regular file (nothing was written)"))
        }
        Ok(_) => match std::fs::OpenOptions::new().write(true).open(path) {
            Ok(_) => Ok(()),
            Err(e) => Err(std::io::Error::new(
                e.kind(),
                format!("it exists and cannot be opened for writing ({e}); nothing was written"),
            )),
        },
        Err(_) => Ok(()),
    }
}

/// Refuses the first of `ids` that is not below `n`, naming the flag, the id and the range
/// (e.g. `--pin: vertex 547 does not exist: the mesh has 547 points (ids 0 to 546)`), so that a
/// bad id is neither ignored nor reported as something else later. O(ids).
pub(crate) fn check_ids(flag: &str, (one, many): (&str, &str), ids: &[u32], n: usize) -> Result<(), CliError> {
    match ids.iter().find(|&&id| id as usize >= n) {
        Some(bad) => Err(CliError::Other(
            format!("{flag}: {one} {bad} does not exist: the mesh has {n} {many} (ids 0 to {})", n.saturating_sub(1))
                .into(),
        )),
        None => Ok(()),
    }
}

/// `message` prefixed with `path`, unless it starts with it already (I/O errors name their file):
/// one mention of the file per line. O(message).
pub(crate) fn named(path: &Path, message: String) -> String {
    let name = path.display().to_string();
    if message.starts_with(&name) {
        message
    } else {
        format!("{name}: {message}")
    }
}

/// `x` for a human-readable table: the shortest decimal that reads back as `x` when
/// 10⁻⁴ ≤ |x| < 10¹⁵ (or x is 0, ±∞ or NaN), else the same digits in exponent form (`{}` alone
/// writes 10³⁰⁰ with 301 digits). O(1).
pub(crate) fn number(x: f64) -> String {
    match plain(x) {
        true => format!("{x}"),
        false => format!("{x:e}"),
    }
}

/// `x` rounded to `places` decimals for a human-readable table, in exponent form with `places`
/// decimals outside 10⁻⁴ ≤ |x| < 10¹⁵ (as [`number`]). O(1).
pub(crate) fn rounded(x: f64, places: usize) -> String {
    match plain(x) {
        true => format!("{x:.places$}"),
        false => format!("{x:.places$e}"),
    }
}

/// Whether `x` reads well as a plain decimal: 0, ±∞, NaN, or 10⁻⁴ ≤ |x| < 10¹⁵. O(1).
fn plain(x: f64) -> bool {
    x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs())
}

/// One number of a command-line value: NaN and ±∞ are refused with the value named (they
/// would run silently or blow up far from the argument that caused it).
pub(crate) fn parse_finite(t: &str) -> Result<f64, String> {
    match t.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("number {v} is not finite")),
        Err(e) => Err(format!("bad number {t:?}: {e}")),
    }
}

/// A count of at least 1, for a flag whose 0 would run nothing (or be read as 1) while the report
/// went on as if it had run: refused with the value named, as a usage error. O(1).
pub(crate) fn at_least_one(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1 (0 would run nothing)".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{s:?} is not a count: {e}")),
    }
}

/// `X,Y,Z`: three finite numbers ([`parse_finite`]).
pub(crate) fn parse_vec3(s: &str) -> Result<topomech::mechanics::Vec3, String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts.as_slice() else { return Err(format!("expected X,Y,Z, got {s:?}")) };
    Ok([parse_finite(x)?, parse_finite(y)?, parse_finite(z)?])
}

/// Prints the warnings of a load (mesh check, build report) to stderr, one line each.
pub fn print_warnings(loaded: &Loaded) {
    let mut err = std::io::stderr().lock();
    for line in load::warning_lines(loaded) {
        // A closed stderr leaves nobody to tell; the warning is dropped.
        let _ = writeln!(err, "{line}");
    }
}

#[cfg(test)]
mod tests {
    use super::{number, rounded};

    /// Table numbers: plain decimals in the everyday range, exponent form outside it, and each
    /// reads back as the same f64.
    #[test]
    fn numbers_are_short_and_read_back_exactly() {
        assert_eq!((number(0.0), number(2.5), number(-1234.5)), ("0".into(), "2.5".into(), "-1234.5".into()));
        assert_eq!((number(1e300), number(-1e-7), number(1e15)), ("1e300".into(), "-1e-7".into(), "1e15".into()));
        assert_eq!((number(1e-4), number(999999999999999.0)), ("0.0001".into(), "999999999999999".into()));
        assert_eq!((number(f64::NAN), number(f64::INFINITY)), ("NaN".into(), "inf".into()));
        for x in [1.0 / 3.0, 7.25e18, 3.0e-300, f64::MAX, f64::MIN_POSITIVE, 5e-324] {
            assert_eq!(number(x).parse::<f64>().unwrap(), x);
            assert!(number(x).len() <= 24, "{x}: {}", number(x));
        }
    }

    /// Rounded numbers keep their decimals in range and switch to exponent form outside it.
    #[test]
    fn rounded_numbers_switch_to_exponent_form_outside_the_plain_range() {
        assert_eq!((rounded(0.0123456789, 6), rounded(2.0, 3)), ("0.012346".into(), "2.000".into()));
        assert_eq!((rounded(1e300, 6), rounded(1.5e-9, 2)), ("1.000000e300".into(), "1.50e-9".into()));
        assert_eq!(rounded(f64::NAN, 6), "NaN");
    }
}

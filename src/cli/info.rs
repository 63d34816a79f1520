//! `topomech info MESH [--json]`: load a tetrahedral mesh file into a 3-G-map and print its
//! characteristics.

use std::io::Write;
use std::path::PathBuf;

use topomech::load;

use super::{print_warnings, Characteristics, CliError};

/// Arguments of `topomech info`.
#[derive(Debug, Clone, clap::Args)]
pub struct InfoArgs {
    /// Mesh file: Gmsh MSH 4.1 (ASCII or binary), 2.2 or v1, or a TetGen `.node`/`.ele` pair
    /// (give either file).
    pub mesh: PathBuf,
    /// Print one JSON object with the keys darts, vertices, edges, faces, volumes,
    /// boundary_faces, components, euler_characteristic, valid, build_ms.
    #[arg(long)]
    pub json: bool,
}

/// Loads `args.mesh`, prints its warnings on stderr and its characteristics on stdout (a table,
/// or JSON with `--json`). Cost: that of [`load::load_tet_map`] plus one `validate()`.
///
/// # Errors
/// [`CliError::Load`] for a file that cannot be read, checked or built; [`CliError::Invalid`]
/// (after printing the report) when the map breaks a law; [`CliError::Output`] when stdout fails.
pub fn run(args: InfoArgs) -> Result<(), CliError> {
    let loaded = load::load_tet_map(&args.mesh)?;
    print_warnings(&loaded);
    let report = Characteristics::of(&loaded);
    let mut out = std::io::stdout().lock();
    if args.json {
        report.write_json(&mut out)?;
    } else {
        writeln!(out, "{}", args.mesh.display())?;
        report.write_table(&mut out)?;
    }
    out.flush()?;
    report.ensure_valid(&args.mesh)
}

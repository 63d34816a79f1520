//! `topomech` (no arguments) or `topomech demo`: build the built-in liver mesh, validate it, print
//! its characteristics, then dissociate one interior face (seed 000, §3.2) and sew it back.
//!
//! Needs no file: the mesh is compiled into the binary ([`load::BUILTIN_MESH`]).

use std::io::Write;
use std::path::Path;

use topomech::gmap::CellCounts;
use topomech::load::{self, Loaded};
use topomech::{DartId, GMap};

use super::{print_warnings, Characteristics, CliError};

/// Arguments of `topomech demo`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct DemoArgs {
    /// Print only the JSON object of `topomech info --json` for the built-in mesh.
    #[arg(long)]
    pub json: bool,
}

/// Runs the demo (see the [module docs](self)). Cost: one build and three `validate()` of a
/// 44 448-dart map, a few milliseconds in release builds.
///
/// # Errors
/// [`CliError::Load`] if the built-in mesh does not load (a broken build of the crate),
/// [`CliError::Invalid`] if a map breaks a law, [`CliError::Other`] if the face sew/unsew is
/// refused, [`CliError::Output`] when stdout fails.
pub fn run(args: DemoArgs) -> Result<(), CliError> {
    let loaded = load::load_builtin()?;
    print_warnings(&loaded);
    let report = Characteristics::of(&loaded);
    let mut out = std::io::stdout().lock();
    if args.json {
        report.write_json(&mut out)?;
        return report.ensure_valid(&loaded.path);
    }
    writeln!(out, "topomech demo: the built-in liver mesh {}", load::BUILTIN_NAME)?;
    writeln!(out, "  (Gmsh remesh of SOFA's liver, LGPL-2.1; the size of the seed paper's benchmark:")?;
    writeln!(out, "   564 nodes, 1856 tets, 2850 springs, 44544 darts)")?;
    report.write_table(&mut out)?;
    report.ensure_valid(&loaded.path)?;
    match dissociate_one_face(&loaded)? {
        Some(d) => d.write(&mut out)?,
        None => writeln!(out, "  (no interior face: nothing to dissociate)")?,
    }
    out.flush()?;
    Ok(())
}

/// The outcome of 3-unsewing one interior face and 3-sewing it back.
#[derive(Debug, Clone, PartialEq)]
pub struct Dissociation {
    /// The dart whose face was dissociated.
    pub dart: DartId,
    /// The volume (tet) ids on both sides.
    pub tets: (u32, u32),
    /// Cell counts before, after the unsew, after the sew back.
    pub counts: [CellCounts; 3],
    /// Boundary faces before, after the unsew, after the sew back.
    pub boundary: [usize; 3],
    /// Vertex and edge splits the unsew reported (0 for a face whose vertices and edges stay
    /// connected through other faces).
    pub vertex_splits: usize,
    /// See `vertex_splits`.
    pub edge_splits: usize,
    /// Whether the map after the sew back is isomorphic to the original.
    pub restored: bool,
}

impl Dissociation {
    fn write(&self, out: &mut dyn Write) -> std::io::Result<()> {
        let [before, cut, back] = &self.counts;
        writeln!(out, "face dissociation (seed 000, section 3.2): 3-unsew the face of {}", self.dart)?;
        writeln!(out, "  between tets {} and {}, then 3-sew it back", self.tets.0, self.tets.1)?;
        writeln!(out, "  {:<22}{} -> {} -> {}", "faces", before.0[2], cut.0[2], back.0[2])?;
        let [b0, b1, b2] = self.boundary;
        writeln!(out, "  {:<22}{b0} -> {b1} -> {b2}", "boundary faces")?;
        writeln!(out, "  {:<22}{} vertices, {} edges", "split by the unsew", self.vertex_splits, self.edge_splits)?;
        let restored = if self.restored { "yes" } else { "NO" };
        writeln!(out, "  {:<22}{restored} (every step validated)", "isomorphic after sew")?;
        Ok(())
    }
}

/// Dissociates the first interior face of `loaded.map` on a copy, validating after each step.
/// O(darts · n²). `Ok(None)` when every face is on the boundary.
///
/// # Errors
/// [`CliError::Invalid`] when a step leaves an invalid map, [`CliError::Other`] when the kernel
/// refuses the unsew or the sew.
pub fn dissociate_one_face(loaded: &Loaded) -> Result<Option<Dissociation>, CliError> {
    let original: &GMap<3> = &loaded.map;
    let Some(dart) = original.darts().find(|&d| !original.is_free(3, d)) else {
        return Ok(None);
    };
    let partner = original.alpha::<3>(dart);
    let mut map = original.clone();
    let unsewn = map.unsew::<3>(dart).map_err(|e| CliError::Other(Box::new(e)))?;
    validated(&map, &loaded.path)?;
    let cut = (map.count_cells(), map.boundary_cell_count());
    map.sew::<3>(dart, partner).map_err(|e| CliError::Other(Box::new(e)))?;
    validated(&map, &loaded.path)?;
    Ok(Some(Dissociation {
        dart,
        tets: (original.cell_id(3, dart).0, original.cell_id(3, partner).0),
        counts: [original.count_cells(), cut.0, map.count_cells()],
        boundary: [original.boundary_cell_count(), cut.1, map.boundary_cell_count()],
        vertex_splits: unsewn.splits(0).count(),
        edge_splits: unsewn.splits(1).count(),
        restored: map.is_isomorphic(original),
    }))
}

fn validated(map: &GMap<3>, path: &Path) -> Result<(), CliError> {
    map.validate().map_err(|violation| CliError::Invalid { path: path.to_path_buf(), violation })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dissociating_an_interior_face_adds_one_face_and_two_boundary_faces() {
        let loaded = load::load_builtin().unwrap();
        let d = dissociate_one_face(&loaded).unwrap().expect("the liver has interior faces");
        let [before, cut, back] = &d.counts;
        assert_eq!(cut.0[2], before.0[2] + 1);
        assert_eq!(d.boundary[1], d.boundary[0] + 2);
        assert_eq!(back, before);
        assert_eq!(d.boundary[2], d.boundary[0]);
        assert_ne!(d.tets.0, d.tets.1);
        assert!(d.restored);
        // The face's vertices and edges stay joined through the other tets around them.
        assert_eq!((d.vertex_splits, d.edge_splits), (0, 0));
        assert_eq!(cut.0[0], before.0[0]);
    }
}

//! From a mesh file to a checked 3-G-map in one call: read, check, build, time.
//!
//! ```text
//!   file ──io::read_mesh──▶ TetMesh ──TetMesh::check──▶ warnings ──GMap::<3>::from_tets──▶ GMap<3>
//!          (ReadError)                 (MeshError)                  (BuildError, build_ms)
//! ```
//!
//! Every failure is a [`LoadError`] that names the file; reader errors also name the line (text
//! files) or byte offset (binary files). Nothing here panics on bad input.
//!
//! The crate carries one mesh of its own, [`BUILTIN_MESH`] (a 547-node liver, Gmsh MSH 2.2, LGPL-2.1,
//! see `data/LICENSE-liver.txt`), so the demo and the tests need no file on disk: [`load_builtin`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::build::{BuildError, BuildReport};
use crate::gmap::GMap;
use crate::io::{self, ReadError};
use crate::mesh::{MeshError, MeshReport, TetMesh};

/// The bytes of `data/liver_547_v22.msh`: a Gmsh remesh of SOFA's `liver-smooth.obj`
/// (LGPL-2.1; provenance and licence in `data/LICENSE-liver.txt`).
///
/// 547 nodes, 1852 tetrahedra, 2833 edges, 870 boundary triangles, total volume ≈ 38.17.
pub const BUILTIN_MESH: &[u8] = include_bytes!("../data/liver_547_v22.msh");

/// The name [`load_builtin`] gives the built-in mesh in messages and reports.
pub const BUILTIN_NAME: &str = "<built-in>/liver_547_v22.msh";

/// A mesh file turned into a 3-G-map, with everything learnt on the way.
///
/// # Examples
///
/// ```
/// let loaded = topomech::load::load_builtin().unwrap();
/// assert_eq!(loaded.mesh.points.len(), 547);
/// assert_eq!(loaded.map.dart_count(), 24 * loaded.mesh.tets.len());
/// assert_eq!(loaded.map.count_cells().0[0], 547); // vertex id = point index
/// assert!(loaded.warnings.is_clean());
/// ```
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The file the mesh came from ([`BUILTIN_NAME`] for the built-in mesh).
    pub path: PathBuf,
    /// The indexed mesh as read (points, tets, file triangles, node tags).
    pub mesh: TetMesh,
    /// The 3-G-map of `mesh.tets`: 24 darts per tet, vertex id = point index
    /// (see [`GMap::from_tets`]).
    pub map: GMap<3>,
    /// Warnings of [`TetMesh::check`]: degenerate or inverted tets, unreferenced points,
    /// file triangles that disagree with the boundary.
    pub warnings: MeshReport,
    /// What the build found: pinched vertices and split edges (non-manifold points and edges that
    /// became several cells), unreferenced points.
    pub build: BuildReport,
    /// Wall-clock time of [`GMap::from_tets`] alone, in milliseconds.
    pub build_ms: f64,
}

/// Why a mesh file could not be loaded. Every variant names the file.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::load::{load_tet_map, LoadError};
///
/// let err = load_tet_map(Path::new("/no/such/dir/liver.msh")).unwrap_err();
/// assert!(matches!(err, LoadError::Read(_)));
/// assert!(err.to_string().contains("/no/such/dir/liver.msh"));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The reader failed; its message already names the file and the line or byte.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The mesh was read but is unusable (see [`TetMesh::check`]).
    #[error("{}: invalid mesh: {source}", .path.display())]
    Check {
        /// The file.
        path: PathBuf,
        /// The defect.
        #[source]
        source: MeshError,
    },
    /// The mesh is not a quasi-manifold (a face shared by three tets) or is too large.
    #[error("{}: cannot build the map: {source}{hint}", .path.display())]
    Build {
        /// The file.
        path: PathBuf,
        /// The build error (element and point indices are 0-based positions in the file's order).
        #[source]
        source: BuildError,
        /// Extra context, e.g. the file's node tags of the points named by `source` (may be empty).
        hint: String,
    },
}

/// Reads the tetrahedral mesh at `path` (any format [`io::read_mesh`] knows: MSH 4.1 ASCII and
/// binary, 2.2, v1, TetGen `.node`/`.ele`), checks it and builds its 3-G-map.
///
/// Cost: O(file size) to read, O(T log T) to check, O(T) expected to build (T tets).
///
/// # Errors
/// [`LoadError::Read`] when the file cannot be read or parsed, [`LoadError::Check`] when the mesh
/// has a defect [`TetMesh::check`] rejects, [`LoadError::Build`] when a face is shared by more
/// than two tets or the mesh exceeds 32-bit dart ids.
///
/// # Examples
///
/// ```
/// use topomech::load::{load_tet_map, BUILTIN_MESH};
///
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}.msh", std::process::id()));
/// std::fs::write(&path, BUILTIN_MESH).unwrap();
/// let loaded = load_tet_map(&path).unwrap();
/// std::fs::remove_file(&path).unwrap();
/// assert_eq!(loaded.path, path);
/// assert_eq!(loaded.mesh.tets.len(), 1852);
/// ```
pub fn load_tet_map(path: &Path) -> Result<Loaded, LoadError> {
    let mesh = io::read_mesh(path)?;
    build_loaded(mesh, path)
}

/// Like [`load_tet_map`], for the bytes of a Gmsh MSH file already in memory; `name` is used in
/// messages only. O(bytes).
///
/// # Errors
/// As [`load_tet_map`], except that no I/O error can occur.
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::load::load_tet_map_from_msh_bytes;
///
/// let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\
///            $EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n";
/// let loaded = load_tet_map_from_msh_bytes(msh.as_bytes(), Path::new("one.msh")).unwrap();
/// assert_eq!(loaded.map.count_cells().0, vec![4, 6, 4, 1]);
/// assert_eq!(loaded.mesh.node_tags, vec![1, 2, 3, 4]);
/// assert!(loaded.warnings.is_clean());
/// ```
pub fn load_tet_map_from_msh_bytes(bytes: &[u8], name: &Path) -> Result<Loaded, LoadError> {
    let mesh = io::parse_msh(bytes, name)?;
    build_loaded(mesh, name)
}

/// Loads the built-in liver mesh ([`BUILTIN_MESH`]) without touching the file system. O(T).
///
/// # Errors
/// None in practice (the tests load it); the `Result` is kept so a corrupted build of the crate
/// reports instead of panicking.
///
/// # Examples
///
/// ```
/// use topomech::load::load_builtin;
///
/// let liver = load_builtin().unwrap();
/// assert_eq!(liver.mesh.tets.len(), 1852);
/// assert_eq!(liver.map.count_cells().0[1], 2833); // edges
/// assert_eq!(liver.map.boundary_cell_count(), 870);
/// assert_eq!(liver.map.euler_characteristic(), 1); // one solid ball
/// assert!((liver.mesh.total_volume().unwrap() - 38.17).abs() < 0.01);
/// ```
pub fn load_builtin() -> Result<Loaded, LoadError> {
    load_tet_map_from_msh_bytes(BUILTIN_MESH, Path::new(BUILTIN_NAME))
}

/// Checks `mesh` and builds its map; `path` names it in errors. O(T log T).
///
/// # Errors
/// [`LoadError::Check`], [`LoadError::Build`].
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::load::{build_loaded, LoadError};
/// use topomech::mesh::TetMesh;
///
/// let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mesh = TetMesh { points: unit.clone(), tets: vec![[0, 1, 2, 3]], ..Default::default() };
/// assert_eq!(build_loaded(mesh, Path::new("mem")).unwrap().map.dart_count(), 24);
/// let bad = TetMesh { points: unit, tets: vec![[0, 1, 2, 9]], ..Default::default() };
/// assert!(matches!(build_loaded(bad, Path::new("mem")), Err(LoadError::Check { .. })));
/// ```
pub fn build_loaded(mesh: TetMesh, path: &Path) -> Result<Loaded, LoadError> {
    let warnings = mesh.check().map_err(|source| LoadError::Check { path: path.to_path_buf(), source })?;
    let start = Instant::now();
    let built = GMap::<3>::from_tets(mesh.points.len(), &mesh.tets);
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    let (map, build) = built.map_err(|source| {
        let hint = build_hint(&source, &mesh);
        LoadError::Build { path: path.to_path_buf(), source, hint }
    })?;
    Ok(Loaded { path: path.to_path_buf(), mesh, map, warnings, build, build_ms })
}

/// The file's node tags of the points a build error names, when the mesh knows them.
fn build_hint(err: &BuildError, mesh: &TetMesh) -> String {
    let points: &[u32] = match err {
        BuildError::NonManifold { points, .. } => points,
        BuildError::RepeatedVertex { point, .. } => std::slice::from_ref(point),
        _ => return String::new(),
    };
    match mesh.file_tags(points) {
        Some(tags) => format!(" (file node tags {tags:?}; element numbers are 0-based tets)"),
        None => String::new(),
    }
}

/// One line per kind of warning in `loaded` (mesh check and build report), each naming the file
/// and at most the first five ids. Empty when the mesh is clean. O(warnings).
///
/// # Examples
///
/// ```
/// use std::path::Path;
/// use topomech::load::{build_loaded, warning_lines};
/// use topomech::mesh::TetMesh;
///
/// // Point 4 is used by no tet.
/// let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [5.0; 3]];
/// let mesh = TetMesh { points, tets: vec![[0, 1, 2, 3]], ..Default::default() };
/// let lines = warning_lines(&build_loaded(mesh, Path::new("m.msh")).unwrap());
/// assert_eq!(lines.len(), 1);
/// assert!(lines[0].starts_with("m.msh: warning: 1 unreferenced points"), "{}", lines[0]);
/// ```
pub fn warning_lines(loaded: &Loaded) -> Vec<String> {
    let w = &loaded.warnings;
    let b = &loaded.build;
    let name = loaded.path.display();
    let mut lines = Vec::new();
    let mut push = |what: &str, ids: Vec<String>| {
        if !ids.is_empty() {
            lines.push(format!("{name}: warning: {} {what} ({})", ids.len(), first_ids(&ids)));
        }
    };
    push("zero-volume tets", ids(&w.zero_volume_tets));
    push("inverted tets (negative signed volume)", ids(&w.inverted_tets));
    push("tets whose volume overflows f64 (coordinates too large)", ids(&w.unmeasurable_tets));
    push("unreferenced points", ids(&w.unreferenced_points));
    push("file triangles that are not boundary faces", ids(&w.file_triangles_not_on_boundary));
    push(
        "pinched vertices (point: g-map vertices)",
        b.pinched_vertices.iter().map(|(p, k)| format!("{p}: {k}")).collect(),
    );
    push("split edges (points: g-map edges)", b.split_edges.iter().map(|(e, k)| format!("{e:?}: {k}")).collect());
    if w.boundary_faces_missing_from_file > 0 {
        lines.push(format!(
            "{name}: warning: {} boundary faces of the tets are missing from the file's triangles",
            w.boundary_faces_missing_from_file
        ));
    }
    lines
}

fn ids<T: std::fmt::Display>(v: &[T]) -> Vec<String> {
    v.iter().map(ToString::to_string).collect()
}

fn first_ids(ids: &[String]) -> String {
    const SHOWN: usize = 5;
    let mut s = ids.iter().take(SHOWN).cloned().collect::<Vec<_>>().join(", ");
    if ids.len() > SHOWN {
        s.push_str(", …");
    }
    format!("first: {s}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_mesh_loads_with_the_documented_counts() {
        let loaded = load_builtin().expect("built-in mesh loads");
        assert_eq!(loaded.mesh.points.len(), 547);
        assert_eq!(loaded.mesh.tets.len(), 1852);
        let counts = loaded.map.count_cells();
        assert_eq!(counts.0, vec![547, 2833, (4 * 1852 + 870) / 2, 1852]);
        assert_eq!(loaded.map.boundary_cell_count(), 870);
        assert!(loaded.warnings.is_clean(), "{:?}", loaded.warnings);
        assert!(warning_lines(&loaded).is_empty());
    }

    #[test]
    fn three_tets_on_one_face_is_a_build_error_with_file_tags() {
        let mesh = TetMesh {
            points: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [0., 0., -1.], [1., 1., 1.]],
            tets: vec![[0, 1, 2, 3], [0, 2, 1, 4], [0, 1, 2, 5]],
            boundary_triangles: vec![],
            node_tags: vec![10, 11, 12, 13, 14, 15],
        };
        let err = build_loaded(mesh, Path::new("x.msh")).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, LoadError::Build { source: BuildError::NonManifold { .. }, .. }), "{msg}");
        assert!(msg.starts_with("x.msh: "), "{msg}");
        assert!(msg.contains("[10, 11, 12]"), "{msg}");
    }

    #[test]
    fn warnings_name_the_file_and_the_first_ids() {
        let mut loaded = load_builtin().unwrap();
        loaded.warnings.inverted_tets = (0..7).collect();
        let lines = warning_lines(&loaded);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(lines[0].contains("7 inverted tets"), "{}", lines[0]);
        assert!(lines[0].contains("first: 0, 1, 2, 3, 4, …"), "{}", lines[0]);
        assert!(lines[0].starts_with(BUILTIN_NAME), "{}", lines[0]);
    }
}

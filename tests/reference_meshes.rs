//! Every reference mesh of `../shared/meshes` loaded into a 3-G-map, checked against the counts of
//! that directory's README (made by meshio and an independent reader, not by topomech).
//!
//! Skipped, with a note, when the directory is absent (e.g. a checkout outside the workspace).

use std::path::Path;

use topomech::gmap::AlphaMask;
use topomech::load::{load_tet_map, Loaded};

const SHARED_MESHES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/meshes");

/// A row of the README table.
struct Reference {
    file: &'static str,
    nodes: usize,
    tets: usize,
    edges: usize,
    boundary_faces: usize,
    /// Total volume, as printed (two decimals).
    volume: f64,
}

const fn r(
    file: &'static str,
    nodes: usize,
    tets: usize,
    edges: usize,
    boundary_faces: usize,
    volume: f64,
) -> Reference {
    Reference { file, nodes, tets, edges, boundary_faces, volume }
}

/// The table of `../shared/meshes/README.md`, one row per file (the liver_547 row covers three
/// formats of one mesh; the TetGen pair is named by its `.node` file).
const TABLE: [Reference; 8] = [
    r("liver_547.msh", 547, 1852, 2833, 870, 38.17),
    r("liver_547_v22.msh", 547, 1852, 2833, 870, 38.17),
    r("liver_547.node", 547, 1852, 2833, 870, 38.17),
    r("liver_1814.msh", 1814, 7453, 10409, 2286, 38.89),
    r("box_458.msh", 458, 1566, 2377, 708, 1.0),
    r("box_458_v22.msh", 458, 1566, 2377, 708, 1.0),
    r("sfepy_cube_medium_tetra.msh", 448, 1782, 2493, 528, 1.0),
    r("sofa_liver_v1.msh", 181, 596, 914, 276, 36.56),
];

/// Loads every mesh of the table, or `None` (after a note) when the directory is absent.
fn loaded_meshes() -> Option<Vec<(&'static Reference, Loaded)>> {
    let dir = Path::new(SHARED_MESHES);
    if !dir.is_dir() {
        println!("note: {} is absent; skipping the reference meshes", dir.display());
        return None;
    }
    let load = |row: &'static Reference| {
        let path = dir.join(row.file);
        let loaded = load_tet_map(&path).unwrap_or_else(|e| panic!("{} loads: {e}", path.display()));
        (row, loaded)
    };
    Some(TABLE.iter().map(load).collect())
}

#[test]
fn cell_counts_equal_the_readme() {
    let Some(meshes) = loaded_meshes() else { return };
    for (row, loaded) in &meshes {
        let name = row.file;
        assert_eq!(loaded.mesh.points.len(), row.nodes, "{name}: nodes");
        assert_eq!(loaded.mesh.tets.len(), row.tets, "{name}: tets");
        let counts = loaded.map.count_cells();
        // Every tet has 4 faces; interior faces are shared by 2 tets, boundary faces by 1.
        let faces = (4 * row.tets + row.boundary_faces) / 2;
        assert_eq!(counts.0, vec![row.nodes, row.edges, faces, row.tets], "{name}: V, E, F, T");
        assert_eq!(loaded.map.boundary_cell_count(), row.boundary_faces, "{name}: boundary faces");
        assert_eq!(loaded.map.dart_count(), 24 * row.tets, "{name}: darts");
        // The edge list computed from the index arrays alone agrees with the map's 1-cells.
        assert_eq!(loaded.mesh.edges().len(), row.edges, "{name}: edges of the index arrays");
        let volume = loaded.mesh.total_volume().unwrap();
        assert!((volume - row.volume).abs() <= 0.0051, "{name}: volume {volume} vs {}", row.volume);
    }
}

#[test]
fn maps_are_valid_connected_balls() {
    let Some(meshes) = loaded_meshes() else { return };
    for (row, loaded) in &meshes {
        let (name, map) = (row.file, &loaded.map);
        if let Err(e) = map.validate() {
            panic!("{name}: {e}");
        }
        assert_eq!(map.components().len(), 1, "{name}: one component");
        // All these meshes are solid balls without cavities or tunnels: V − E + F − T = 1.
        // (A mesh with k cavities would give 1 + k; one with g tunnels 1 − g.)
        assert_eq!(map.euler_characteristic(), 1, "{name}: Euler characteristic");
        assert!(map.is_orientable(), "{name}: a ball is orientable");
        assert!(loaded.warnings.is_clean(), "{name}: {:?}", loaded.warnings);
        assert!(loaded.build.pinched_vertices.is_empty() && loaded.build.split_edges.is_empty(), "{name}: manifold");
    }
}

#[test]
fn cell_ids_agree_with_orbit_traversal() {
    let Some(meshes) = loaded_meshes() else { return };
    for (row, loaded) in &meshes {
        let map = &loaded.map;
        assert_eq!(map.count_cells(), map.count_cells_by_traversal(), "{}", row.file);
        for dim in 0..=3 {
            // One dart per orbit, found without ids: their ids must be pairwise distinct (no two
            // orbits share an id) and as many as the live ids (no id without an orbit).
            let by_walk = map.one_dart_per_cell_by_traversal(dim);
            let mut ids: Vec<u32> = by_walk.iter().map(|&d| map.cell_id(dim, d).0).collect();
            ids.sort_unstable();
            ids.dedup();
            assert_eq!(ids.len(), by_walk.len(), "{}: two {dim}-cells share an id", row.file);
            assert_eq!(ids.len(), map.one_dart_per_cell(dim).len(), "{}: {dim}-cell ids", row.file);
        }
    }
}

/// The boundary faces of the map as sorted vertex triples (vertex id = point index), sorted.
fn map_boundary_triples(loaded: &Loaded) -> Vec<[u32; 3]> {
    let map = &loaded.map;
    let face = AlphaMask::of(&[0, 1]);
    let mut seen = vec![false; map.cell_id_bound(2)];
    let mut triples = Vec::new();
    for d in map.boundary_darts() {
        let id = map.cell_id(2, d).index();
        if std::mem::replace(&mut seen[id], true) {
            continue;
        }
        let mut vertices: Vec<u32> = map.orbit(d, face).into_iter().map(|x| map.vertex_id(x).0).collect();
        vertices.sort_unstable();
        vertices.dedup();
        let triple: [u32; 3] = vertices.try_into().expect("a triangle has three vertices");
        triples.push(triple);
    }
    triples.sort_unstable();
    triples
}

#[test]
fn boundary_triangles_in_the_file_are_the_maps_boundary_faces() {
    let Some(meshes) = loaded_meshes() else { return };
    let mut compared = 0;
    for (row, loaded) in &meshes {
        let map_faces = map_boundary_triples(loaded);
        assert_eq!(map_faces.len(), row.boundary_faces, "{}", row.file);
        if loaded.mesh.boundary_triangles.is_empty() {
            println!("note: {} carries no triangles; nothing to compare", row.file);
            continue;
        }
        let mut file_faces: Vec<[u32; 3]> = loaded
            .mesh
            .boundary_triangles
            .iter()
            .map(|t| {
                let mut t = *t;
                t.sort_unstable();
                t
            })
            .collect();
        file_faces.sort_unstable();
        file_faces.dedup();
        assert_eq!(file_faces, map_faces, "{}", row.file);
        compared += 1;
    }
    assert!(compared >= 2, "at least the Gmsh 4.1 and 2.2 files carry their boundary triangles");
}

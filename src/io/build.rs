//! Shared assembly of a mesh from file records: node tags to point indices, Gmsh element
//! types, and the per-record checks that can name a line (duplicate tags, non-finite
//! coordinates, repeated vertices, undefined node tags).

use std::collections::hash_map::Entry;
use std::collections::HashMap;
use std::path::Path;

use super::{Location, ReadError};
use crate::mesh::{CellKind, MeshError, TetMesh, TriMesh};

/// What a reader does with an element of a given type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ElementUse {
    /// A linear tetrahedron: part of the volume.
    Tet,
    /// A linear triangle: kept as a boundary triangle.
    Triangle,
    /// A point, line or surface element other than a linear triangle (or, in a surface read,
    /// any volume element): ignored, once its node tags are found defined.
    Skip,
}

/// What a read makes: the volume mesh ([`TetMesh`]: tetrahedra, other volume elements are an
/// error) or the surface ([`TriMesh`]: triangles; volume elements of every type are skipped).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Target {
    /// A tet mesh.
    #[default]
    Volume,
    /// A triangle mesh.
    Surface,
}

/// A known Gmsh element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ElementKind {
    /// Number of nodes of one element.
    pub nodes: usize,
    /// What the readers do with it.
    pub usage: ElementUse,
}

/// Gmsh element types 1..=31: (type, dimension, nodes, name).
const GMSH_TYPES: [(i64, u8, usize, &str); 31] = [
    (1, 1, 2, "2-node line"),
    (2, 2, 3, "3-node triangle"),
    (3, 2, 4, "4-node quadrangle"),
    (4, 3, 4, "4-node tetrahedron"),
    (5, 3, 8, "8-node hexahedron"),
    (6, 3, 6, "6-node prism"),
    (7, 3, 5, "5-node pyramid"),
    (8, 1, 3, "3-node second-order line"),
    (9, 2, 6, "6-node second-order triangle"),
    (10, 2, 9, "9-node second-order quadrangle"),
    (11, 3, 10, "10-node second-order tetrahedron"),
    (12, 3, 27, "27-node second-order hexahedron"),
    (13, 3, 18, "18-node second-order prism"),
    (14, 3, 14, "14-node second-order pyramid"),
    (15, 0, 1, "1-node point"),
    (16, 2, 8, "8-node second-order quadrangle"),
    (17, 3, 20, "20-node second-order hexahedron"),
    (18, 3, 15, "15-node second-order prism"),
    (19, 3, 13, "13-node second-order pyramid"),
    (20, 2, 9, "9-node third-order incomplete triangle"),
    (21, 2, 10, "10-node third-order triangle"),
    (22, 2, 12, "12-node fourth-order incomplete triangle"),
    (23, 2, 15, "15-node fourth-order triangle"),
    (24, 2, 15, "15-node fifth-order incomplete triangle"),
    (25, 2, 21, "21-node fifth-order triangle"),
    (26, 1, 4, "4-node third-order line"),
    (27, 1, 5, "5-node fourth-order line"),
    (28, 1, 6, "6-node fifth-order line"),
    (29, 3, 20, "20-node third-order tetrahedron"),
    (30, 3, 35, "35-node fourth-order tetrahedron"),
    (31, 3, 56, "56-node fifth-order tetrahedron"),
];

/// Classifies Gmsh element type `t` found at `at` for a read of `target`.
///
/// # Errors
/// [`ReadError::UnknownElementType`] for a type outside 1..=31;
/// [`ReadError::UnsupportedElementType`], in a volume read, for a volume element other than the
/// 4-node tetrahedron (dropping it would silently leave a hole in the volume). A surface read
/// skips every volume element.
pub(crate) fn gmsh_element_kind(path: &Path, at: Location, t: i64, target: Target) -> Result<ElementKind, ReadError> {
    let Some(&(_, dim, nodes, name)) = GMSH_TYPES.iter().find(|e| e.0 == t) else {
        return Err(ReadError::UnknownElementType { path: path.to_path_buf(), at, element_type: t });
    };
    let usage = match (t, dim, target) {
        (_, 3, Target::Surface) => ElementUse::Skip,
        (4, _, _) => ElementUse::Tet,
        (2, _, _) => ElementUse::Triangle,
        (_, 3, _) => {
            return Err(ReadError::UnsupportedElementType { path: path.to_path_buf(), at, element_type: t, name })
        }
        _ => ElementUse::Skip,
    };
    Ok(ElementKind { nodes, usage })
}

/// No point: an empty slot of [`TagIndex::dense`] (point indices are below `u32::MAX`).
const NO_POINT: u32 = u32::MAX;

/// Node tag → point index. Tags below a bound proportional to the number of nodes (Gmsh and
/// TetGen number their nodes 1..n or 0..n−1, sometimes with gaps) are looked up in a vector
/// indexed by the tag; the first tag past the bound moves every entry to a hash table with
/// std's randomly keyed SipHash. A file cannot choose tags that collide in it (FxHash, which
/// this replaced, is invertible: tags `(C + i)·K⁻¹` all fell in one bucket and made every
/// reader quadratic). Either way a lookup is O(1) expected, and the vector holds at most
/// `4·max(n, reserved) + 1024` entries.
#[derive(Debug, Default)]
struct TagIndex {
    /// `dense[tag]`: the point index of `tag`, or [`NO_POINT`]; empty once `hashed` is used.
    dense: Vec<u32>,
    /// All entries, once a tag was too large for `dense`.
    hashed: Option<HashMap<u64, u32>>,
    /// Points reserved by the reader (bounded by the file size).
    reserved: usize,
}

impl TagIndex {
    /// The largest number of `dense` slots for `points` points read so far.
    fn dense_limit(&self, points: usize) -> usize {
        self.reserved.max(points.saturating_add(1)).saturating_mul(4).saturating_add(1024)
    }

    fn reserve(&mut self, total: usize) {
        self.reserved = self.reserved.max(total);
        if let Some(map) = &mut self.hashed {
            map.reserve(total.saturating_sub(map.len()));
        }
    }

    fn get(&self, tag: u64) -> Option<u32> {
        match &self.hashed {
            Some(map) => map.get(&tag).copied(),
            None => usize::try_from(tag).ok().and_then(|t| self.dense.get(t)).copied().filter(|&i| i != NO_POINT),
        }
    }

    /// Records `tag → i` (the `points`-th point); false when `tag` is already there.
    fn insert(&mut self, tag: u64, i: u32, points: usize) -> bool {
        if self.hashed.is_none() {
            match usize::try_from(tag) {
                Ok(t) if t < self.dense_limit(points) => {
                    if t >= self.dense.len() {
                        self.dense.resize(t + 1, NO_POINT);
                    }
                    if self.dense[t] != NO_POINT {
                        return false;
                    }
                    self.dense[t] = i;
                    return true;
                }
                _ => {
                    let mut map = HashMap::with_capacity(self.reserved.max(points + 1));
                    let dense = std::mem::take(&mut self.dense);
                    map.extend(
                        dense.into_iter().enumerate().filter(|&(_, i)| i != NO_POINT).map(|(t, i)| (t as u64, i)),
                    );
                    self.hashed = Some(map);
                }
            }
        }
        let Some(map) = &mut self.hashed else { return false };
        match map.entry(tag) {
            Entry::Occupied(_) => false,
            Entry::Vacant(slot) => {
                slot.insert(i);
                true
            }
        }
    }
}

/// The file's element numbers of the cells of one list, in order, kept as runs of consecutive
/// numbers: (cell where a run starts, its number). Files number their elements consecutively
/// (a Gmsh block, a TetGen `.ele`), so a few runs stand for millions of cells; any numbering is
/// kept exactly. `push` O(1), `get` O(log runs).
#[derive(Debug, Default)]
struct ElementNumbers {
    runs: Vec<(usize, u64)>,
    cells: usize,
}

impl ElementNumbers {
    fn push(&mut self, number: u64) {
        let next = self.runs.last().map(|&(cell, first)| first.wrapping_add((self.cells - cell) as u64));
        if next != Some(number) {
            self.runs.push((self.cells, number));
        }
        self.cells += 1;
    }

    /// The number of cell `cell` (< the cells pushed).
    fn get(&self, cell: usize) -> u64 {
        let (start, first) = self.runs[self.runs.partition_point(|&(c, _)| c <= cell) - 1];
        first.wrapping_add((cell - start) as u64)
    }
}

/// Collects points (by file tag) and cells, checking each record as it comes.
#[derive(Debug, Default)]
pub(crate) struct MeshBuilder {
    points: Vec<[f64; 3]>,
    tags: Vec<u64>,
    index: TagIndex,
    tets: Vec<[u32; 4]>,
    tet_numbers: ElementNumbers,
    triangles: Vec<[u32; 3]>,
    triangle_numbers: ElementNumbers,
    target: Target,
}

impl MeshBuilder {
    /// An empty builder for a volume read.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty builder for a read of `target`.
    pub fn for_target(target: Target) -> Self {
        MeshBuilder { target, ..Self::default() }
    }

    /// Classifies Gmsh element type `t` found at `at` for this read (see [`gmsh_element_kind`]).
    ///
    /// # Errors
    /// `UnknownElementType`, `UnsupportedElementType`.
    pub fn element_kind(&self, path: &Path, at: Location, t: i64) -> Result<ElementKind, ReadError> {
        gmsh_element_kind(path, at, t, self.target)
    }

    /// Number of points so far.
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Reserves room for `n` more points; callers bound `n` by the file size first.
    pub fn reserve_points(&mut self, n: usize) {
        self.points.reserve(n);
        self.tags.reserve(n);
        self.index.reserve(self.points.len().saturating_add(n));
    }

    /// Adds the point with file tag `tag`, whose record is at `at`.
    ///
    /// # Errors
    /// `DuplicateNode`, `NonFiniteCoordinate`, `TooManyNodes`.
    pub fn add_node(&mut self, path: &Path, at: Location, tag: u64, xyz: [f64; 3]) -> Result<(), ReadError> {
        self.add_node_split(path, at, at, tag, xyz)
    }

    /// Adds the point with file tag `tag`, for a format that stores the tag (at `tag_at`) apart
    /// from the coordinates (at `at`): a duplicate tag is reported at `tag_at`, everything else
    /// at `at`.
    ///
    /// # Errors
    /// `DuplicateNode`, `NonFiniteCoordinate`, `TooManyNodes`.
    pub fn add_node_split(
        &mut self,
        path: &Path,
        tag_at: Location,
        at: Location,
        tag: u64,
        xyz: [f64; 3],
    ) -> Result<(), ReadError> {
        if !xyz.iter().all(|c| c.is_finite()) {
            return Err(ReadError::NonFiniteCoordinate { path: path.to_path_buf(), at, tag, coords: xyz });
        }
        let Ok(i) = u32::try_from(self.points.len()) else {
            return Err(too_many(path, at));
        };
        if i == u32::MAX {
            return Err(too_many(path, at));
        }
        if !self.index.insert(tag, i, self.points.len()) {
            return Err(ReadError::DuplicateNode { path: path.to_path_buf(), at: tag_at, tag });
        }
        self.points.push(xyz);
        self.tags.push(tag);
        Ok(())
    }

    /// Point indices of the node tags of element `element`, checking that every tag is
    /// defined and none repeats.
    fn resolve<const N: usize>(
        &self,
        path: &Path,
        at: Location,
        element: u64,
        tags: &[u64],
    ) -> Result<[u32; N], ReadError> {
        let mut out = [0u32; N];
        for k in 0..N {
            let tag = tags.get(k).copied().unwrap_or(0);
            let index = self.index.get(tag).ok_or_else(|| ReadError::UndefinedNode {
                path: path.to_path_buf(),
                at,
                element,
                tag,
            })?;
            if out[..k].contains(&index) {
                return Err(ReadError::RepeatedVertex { path: path.to_path_buf(), at, element, tag });
            }
            out[k] = index;
        }
        Ok(out)
    }

    /// Adds element `element` (file tag) with node tags `nodes` according to `usage`. Every
    /// node tag must be defined, also those of a skipped element.
    ///
    /// # Errors
    /// `UndefinedNode`, `RepeatedVertex` (for tets and triangles only).
    pub fn add_element(
        &mut self,
        path: &Path,
        at: Location,
        element: u64,
        usage: ElementUse,
        nodes: &[u64],
    ) -> Result<(), ReadError> {
        match usage {
            ElementUse::Tet => {
                let t = self.resolve::<4>(path, at, element, nodes)?;
                self.tets.push(t);
                self.tet_numbers.push(element);
            }
            ElementUse::Triangle => {
                let t = self.resolve::<3>(path, at, element, nodes)?;
                self.triangles.push(t);
                self.triangle_numbers.push(element);
            }
            ElementUse::Skip => {
                if let Some(&tag) = nodes.iter().find(|&&tag| self.index.get(tag).is_none()) {
                    return Err(ReadError::UndefinedNode { path: path.to_path_buf(), at, element, tag });
                }
            }
        }
        Ok(())
    }

    /// The tet mesh, after [`TetMesh::check`] found no error.
    ///
    /// # Errors
    /// `DuplicateElement` (named by the file's element numbers and node tags), `InvalidMesh`
    /// for the check's other errors (e.g. no tetrahedra).
    pub fn into_tet_mesh(self, path: &Path) -> Result<TetMesh, ReadError> {
        let mesh =
            TetMesh { points: self.points, tets: self.tets, boundary_triangles: self.triangles, node_tags: self.tags };
        mesh.check().map_err(|source| in_file_terms(path, source, &self.tet_numbers, &mesh.node_tags))?;
        Ok(mesh)
    }

    /// The triangle mesh (tets are dropped), after [`TriMesh::check`] found no error.
    ///
    /// # Errors
    /// `DuplicateElement` (named by the file's element numbers and node tags), `InvalidMesh`
    /// for the check's other errors (e.g. no triangles).
    pub fn into_tri_mesh(self, path: &Path) -> Result<TriMesh, ReadError> {
        let mesh = TriMesh { points: self.points, triangles: self.triangles };
        mesh.check().map_err(|source| in_file_terms(path, source, &self.triangle_numbers, &self.tags))?;
        Ok(mesh)
    }
}

/// The read error for a mesh check's error: a duplicate cell as `DuplicateElement`, with the
/// file's element numbers (`numbers`) and node tags (`tags`, one per point) for the check's
/// 0-based indices; anything else as `InvalidMesh`. O(corners + log runs).
fn in_file_terms(path: &Path, source: MeshError, numbers: &ElementNumbers, tags: &[u64]) -> ReadError {
    let (kind, first, second, corners) = match &source {
        MeshError::DuplicateTet { first, second, corners } => (CellKind::Tet, *first, *second, &corners[..]),
        MeshError::DuplicateTriangle { first, second, corners } => (CellKind::Triangle, *first, *second, &corners[..]),
        _ => return ReadError::InvalidMesh { path: path.to_path_buf(), source },
    };
    ReadError::DuplicateElement {
        path: path.to_path_buf(),
        kind,
        first: numbers.get(first),
        second: numbers.get(second),
        nodes: corners.iter().map(|&p| tags[p as usize]).collect(),
    }
}

fn too_many(path: &Path, at: Location) -> ReadError {
    ReadError::TooManyNodes { path: path.to_path_buf(), at }
}

/// Fails with `CountTooLarge` unless `count` items of at least `min_bytes` each fit in the
/// `remaining` bytes; otherwise returns `count` as `usize` (safe to reserve).
pub(crate) fn bounded_count(
    path: &Path,
    at: Location,
    what: &'static str,
    count: u64,
    min_bytes: usize,
    remaining: usize,
) -> Result<usize, ReadError> {
    let fits =
        usize::try_from(count).ok().and_then(|c| c.checked_mul(min_bytes.max(1))).is_some_and(|need| need <= remaining);
    if fits {
        Ok(count as usize)
    } else {
        Err(ReadError::CountTooLarge { path: path.to_path_buf(), at, what, count, remaining })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at() -> Location {
        Location::Line(1)
    }

    #[test]
    fn element_kinds() {
        let p = Path::new("x");
        let tet = gmsh_element_kind(p, at(), 4, Target::Volume).unwrap();
        assert_eq!((tet.nodes, tet.usage), (4, ElementUse::Tet));
        assert_eq!(gmsh_element_kind(p, at(), 2, Target::Volume).unwrap().usage, ElementUse::Triangle);
        assert_eq!(gmsh_element_kind(p, at(), 15, Target::Volume).unwrap().usage, ElementUse::Skip);
        assert_eq!(gmsh_element_kind(p, at(), 3, Target::Volume).unwrap().nodes, 4);
        for t in [5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29, 30, 31] {
            let e = gmsh_element_kind(p, at(), t, Target::Volume).unwrap_err();
            assert!(matches!(e, ReadError::UnsupportedElementType { .. }), "{t}");
        }
        for t in [0, -1, 32, 93, i64::MAX] {
            let e = gmsh_element_kind(p, at(), t, Target::Volume).unwrap_err();
            assert!(matches!(e, ReadError::UnknownElementType { .. }), "{t}");
            let e = gmsh_element_kind(p, at(), t, Target::Surface).unwrap_err();
            assert!(matches!(e, ReadError::UnknownElementType { .. }), "{t}");
        }
        // A surface read skips every volume element, the linear tetrahedron included.
        for t in [4, 5, 6, 7, 11, 12, 13, 14, 17, 18, 19, 29, 30, 31] {
            let kind = gmsh_element_kind(p, at(), t, Target::Surface).unwrap();
            assert_eq!(kind.usage, ElementUse::Skip, "{t}");
            assert_eq!(kind.nodes, gmsh_element_kind(p, at(), t, Target::Surface).unwrap().nodes);
        }
        assert_eq!(gmsh_element_kind(p, at(), 2, Target::Surface).unwrap().usage, ElementUse::Triangle);
        assert_eq!(gmsh_element_kind(p, at(), 11, Target::Surface).unwrap().nodes, 10);
    }

    /// Small tags are indexed densely, a large one moves every entry to the hash table; both
    /// find every tag and refuse a duplicate.
    #[test]
    fn tag_index_is_dense_then_hashed() {
        let mut index = TagIndex::default();
        index.reserve(3);
        for (i, tag) in [7u64, 0, 1030].into_iter().enumerate() {
            assert!(index.insert(tag, i as u32, i));
        }
        assert!(index.hashed.is_none() && index.dense.len() == 1031);
        assert!(!index.insert(0, 9, 3));
        assert_eq!(
            (index.get(7), index.get(0), index.get(1030), index.get(5), index.get(1 << 40)),
            (Some(0), Some(1), Some(2), None, None)
        );
        assert!(index.insert(u64::MAX, 3, 3));
        assert!(index.hashed.is_some() && index.dense.is_empty());
        assert!(!index.insert(1030, 4, 4) && !index.insert(u64::MAX, 4, 4));
        assert_eq!(
            (index.get(7), index.get(0), index.get(1030), index.get(u64::MAX), index.get(5)),
            (Some(0), Some(1), Some(2), Some(3), None)
        );
    }

    /// Element numbers are kept exactly, whatever the numbering, in one run per break.
    #[test]
    fn element_numbers_are_runs() {
        let numbers = [5u64, 6, 7, 10, 11, 3, u64::MAX, 0, 1, 1];
        let mut kept = ElementNumbers::default();
        for n in numbers {
            kept.push(n);
        }
        assert_eq!(kept.runs.len(), 5);
        assert!(numbers.iter().enumerate().all(|(cell, &n)| kept.get(cell) == n));
    }

    #[test]
    fn counts_are_bounded_by_remaining_bytes() {
        let p = Path::new("x");
        assert_eq!(bounded_count(p, at(), "node", 2, 8, 16).unwrap(), 2);
        assert!(bounded_count(p, at(), "node", 3, 8, 16).is_err());
        assert!(bounded_count(p, at(), "node", u64::MAX, 8, usize::MAX).is_err());
    }

    #[test]
    fn builder_checks_records() {
        let p = Path::new("x");
        let mut b = MeshBuilder::new();
        for (i, tag) in [5u64, 9, 2, 70].into_iter().enumerate() {
            b.add_node(p, at(), tag, [i as f64, 0.0, (i % 2) as f64]).unwrap();
        }
        assert!(matches!(b.add_node(p, at(), 9, [0.0; 3]), Err(ReadError::DuplicateNode { tag: 9, .. })));
        let nan = b.add_node(p, at(), 1, [0.0, f64::NAN, 0.0]);
        assert!(matches!(nan, Err(ReadError::NonFiniteCoordinate { tag: 1, .. })));
        let undefined = b.add_element(p, at(), 7, ElementUse::Tet, &[5, 9, 2, 71]);
        assert!(matches!(undefined, Err(ReadError::UndefinedNode { element: 7, tag: 71, .. })));
        let repeated = b.add_element(p, at(), 8, ElementUse::Triangle, &[5, 9, 5]);
        assert!(matches!(repeated, Err(ReadError::RepeatedVertex { element: 8, tag: 5, .. })));
        b.add_element(p, at(), 1, ElementUse::Skip, &[5, 9]).unwrap();
        let skipped = b.add_element(p, at(), 3, ElementUse::Skip, &[5, 4]);
        assert!(matches!(skipped, Err(ReadError::UndefinedNode { element: 3, tag: 4, .. })));
        b.add_element(p, at(), 2, ElementUse::Tet, &[70, 2, 9, 5]).unwrap();
        assert_eq!(b.point_count(), 4);
        let m = b.into_tet_mesh(p).unwrap();
        assert_eq!(m.tets, vec![[3, 2, 1, 0]]);
        assert_eq!(m.node_tags, vec![5, 9, 2, 70]);
    }
}

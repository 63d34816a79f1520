//! Building n-G-maps from indexed meshes: tetrahedra into a 3-G-map, triangles into a 2-G-map.
//!
//! A tetrahedron becomes 24 darts, one per (vertex, edge, face) flag of the tet; α0, α1 and α2
//! are fixed by a template, and α3 links the darts of two tets that share a face, found by
//! matching sorted vertex triples. A triangle becomes 6 darts; α2 links triangles that share an
//! edge, found by matching sorted vertex pairs.
//!
//! Cell ids: volume id = tet index, face ids in order of first appearance, edge ids in order of
//! a flood fill over the darts in increasing order (so, scanning darts in increasing order, new
//! face and edge ids appear as 0, 1, 2, …). The vertex id of a g-map vertex is the index of its input point, so arrays of
//! points index vertex embeddings directly. Where the input is not a manifold at a point (the
//! tets around it form several fans joined only at the point) or along an edge, the g-map has
//! several vertices or edges there: the first keeps the point's index, the others get fresh ids,
//! and [`BuildReport`] lists them. Unreferenced points leave free vertex ids. An element listed
//! twice (the same points in any order) is refused, [`BuildError::DuplicateElement`]: its copies
//! would sew into a closed component of two cells. The matching finds it at no extra pass: two
//! tets that share two faces (two triangles that share an edge and a third point) are copies.
//!
//! Cost: O(tets · α(tets) + points) for tetrahedra: faces matched by a counting sort on their
//! smallest point, which also records where each corner of a face lands in the neighbouring tet;
//! edges and vertices labelled by a union-find over the 6 edges and 4 corners of each tet (not
//! over its 24 darts) that reads only the face matching, never the neighbour's points; every
//! dart's α row and cell row written once, in order. When the input order is scattered (far
//! face links, as in a mesh file whose tets and points are numbered at random), the union-finds
//! sweep the tets in a breadth-first order over shared faces, so their forests are read in a
//! small window, and the ids are written back in input order; the map is the same either way. O(triangles) expected for triangles (one
//! hash-map look-up per edge).

use rustc_hash::FxHashMap;

use crate::gmap::{join_with_smaller, AlphaMask, DartId, GMap};

/// Why a mesh could not be turned into a map. Nothing is built when one is returned.
///
/// # Examples
///
/// ```
/// use topomech::{BuildError, GMap};
///
/// assert_eq!(GMap::<3>::from_tets(4, &[]).unwrap_err(), BuildError::Empty("tetrahedra"));
/// let err = GMap::<3>::from_tets(4, &[[0, 1, 2, 7]]).unwrap_err();
/// assert_eq!(err, BuildError::IndexOutOfRange { element: 0, corner: 3, index: 7, points: 4 });
/// // three tets on one face: no quasi-manifold has that
/// let fan = [[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 2, 5]];
/// assert!(matches!(GMap::<3>::from_tets(6, &fan), Err(BuildError::NonManifold { what: "face", .. })));
/// // one tet listed twice (any corner order)
/// let err = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4], [3, 2, 0, 1]]).unwrap_err();
/// assert_eq!(err, BuildError::DuplicateElement { what: "tet", first: 0, second: 2, points: vec![0, 1, 2, 3] });
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BuildError {
    /// No element at all.
    #[error("the mesh has no {0}")]
    Empty(&'static str),
    /// An element refers to a point that does not exist.
    #[error("element {element}, corner {corner}: point index {index} is out of range (the mesh has {points} points)")]
    IndexOutOfRange {
        /// Element index.
        element: usize,
        /// Corner within the element.
        corner: usize,
        /// The bad index.
        index: u32,
        /// Number of points.
        points: usize,
    },
    /// An element uses one point twice.
    #[error("element {element} uses point {point} twice")]
    RepeatedVertex {
        /// Element index.
        element: usize,
        /// The repeated point.
        point: u32,
    },
    /// More than two tetrahedra share a face (or more than two triangles an edge): the complex is
    /// not a quasi-manifold and no g-map represents it.
    #[error("not a quasi-manifold: the {what} with points {points:?} is shared by elements {elements:?} (at most two allowed)")]
    NonManifold {
        /// "face" or "edge".
        what: &'static str,
        /// The points of the shared face or edge.
        points: Vec<u32>,
        /// Three of the elements sharing it.
        elements: [usize; 3],
    },
    /// Two elements have the same points, in any order: a cell listed twice. Its copies would
    /// sew into a closed component of their own (two tets glued on all four faces, two triangles
    /// on all three edges) and double its mass. `first` is the earliest copy, `second` the
    /// lowest element that repeats an earlier one.
    #[error("duplicate {what}: elements {first} and {second} have the same points {points:?} (a {what} listed twice)")]
    DuplicateElement {
        /// "tet" or "triangle".
        what: &'static str,
        /// The earliest element with these points.
        first: usize,
        /// The element that repeats it.
        second: usize,
        /// The points, as `first` lists them.
        points: Vec<u32>,
    },
    /// More darts than 32-bit ids can name.
    #[error("the mesh is too large: {0} darts exceed the 32-bit dart ids")]
    TooLarge(usize),
    /// More points than 32-bit vertex ids can name (vertex id = point index).
    #[error("the mesh has {0} points: vertex ids are 32-bit, at most 4294967294 points")]
    TooManyPoints(usize),
}

/// What the build found worth knowing about the input, besides the map.
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// // Two tets that touch only at point 0: the map gets two vertices there.
/// let (map, report) = GMap::<3>::from_tets(7, &[[0, 1, 2, 3], [0, 4, 5, 6]]).unwrap();
/// assert_eq!(report.pinched_vertices, vec![(0, 2)]);
/// assert_eq!(report.extra_vertices, vec![(7, 0)]); // vertex 7 is the other one at point 0
/// assert_eq!(map.count_cells().0[0], 8);
/// assert!(report.split_edges.is_empty() && report.unreferenced_points.is_empty());
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Points whose elements form several fans: (point, number of g-map vertices it became).
    pub pinched_vertices: Vec<(u32, usize)>,
    /// Point pairs whose elements around the edge form several fans: (points, g-map edges).
    pub split_edges: Vec<([u32; 2], usize)>,
    /// Points no element uses; their vertex ids are left free.
    pub unreferenced_points: Vec<u32>,
    /// The g-map vertices past the first at each pinched point, as (vertex id, point), by
    /// increasing vertex id (the first keeps the point's index as its id): with the identity on
    /// the other ids, which point each vertex id stands for.
    pub extra_vertices: Vec<(u32, u32)>,
}

impl BuildReport {
    /// Values given per point (positions, masses, tags) extended to every vertex id of the map:
    /// the first `per_point.len()` ids are the points themselves, and each extra vertex of a
    /// pinched point takes its point's value ([`BuildReport::extra_vertices`]). This is what
    /// [`crate::subdivide::LeveledMap::new`] needs as positions for a map built from a mesh with
    /// pinched points. The extra vertices' ids follow the points (the build hands them out from
    /// the point count up), so `None` when they do not follow `per_point.len()` or name a point
    /// past it: values for another mesh. O(points + extra vertices).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, report) = GMap::<3>::from_tets(7, &[[0, 1, 2, 3], [0, 4, 5, 6]]).unwrap();
    /// let tags: Vec<u32> = (100..107).collect();
    /// let per_vertex = report.per_vertex(&tags).unwrap();
    /// assert_eq!(per_vertex.len(), map.cell_id_bound(0));
    /// assert_eq!(per_vertex[7], 100); // the second vertex at point 0
    /// assert_eq!(report.per_vertex(&tags[..3]), None); // values for 3 points: another mesh
    /// assert_eq!(report.per_vertex(&[0; 8]), None);
    /// ```
    pub fn per_vertex<T: Copy>(&self, per_point: &[T]) -> Option<Vec<T>> {
        let mut out = per_point.to_vec();
        for &(id, point) in &self.extra_vertices {
            if id as usize != out.len() {
                return None;
            }
            out.push(*per_point.get(point as usize)?);
        }
        Some(out)
    }
}

/// The combinatorial template of one tetrahedron's 24 darts.
///
/// Dart `6f + k` lies on face f (the face opposite local vertex f), whose corners are the other
/// three local vertices (a, b, c) in increasing order; k runs over the flags
/// (a,ab) (b,ab) (b,bc) (c,bc) (c,ca) (a,ca).
struct TetTemplate {
    vertex: [u8; 24],
    other: [u8; 24],
    alpha2: [u8; 24],
}

const FLAG_VERTEX: [usize; 6] = [0, 1, 1, 2, 2, 0];
const FLAG_OTHER: [usize; 6] = [1, 0, 2, 1, 0, 2];

/// α0 and α1 inside one face or triangle: local flag k → partner.
const FLAG_ALPHA0: [usize; 6] = [1, 0, 3, 2, 5, 4];
const FLAG_ALPHA1: [usize; 6] = [5, 2, 1, 4, 3, 0];

const fn tet_template() -> TetTemplate {
    let mut t = TetTemplate { vertex: [0; 24], other: [0; 24], alpha2: [0; 24] };
    let mut f = 0;
    while f < 4 {
        let corners = face_corners(f);
        let mut k = 0;
        while k < 6 {
            t.vertex[f * 6 + k] = corners[FLAG_VERTEX[k]] as u8;
            t.other[f * 6 + k] = corners[FLAG_OTHER[k]] as u8;
            k += 1;
        }
        f += 1;
    }
    let mut d = 0;
    while d < 24 {
        let mut e = 0;
        while e < 24 {
            if e / 6 != d / 6 && t.vertex[e] == t.vertex[d] && t.other[e] == t.other[d] {
                t.alpha2[d] = e as u8;
            }
            e += 1;
        }
        d += 1;
    }
    t
}

const fn face_corners(f: usize) -> [usize; 3] {
    match f {
        0 => [1, 2, 3],
        1 => [0, 2, 3],
        2 => [0, 1, 3],
        _ => [0, 1, 2],
    }
}

const TET: TetTemplate = tet_template();

/// Checks the point count (32-bit vertex ids), the indices and repeated points of `K`-point
/// elements.
fn check_elements<const K: usize>(points: usize, elements: &[[u32; K]]) -> Result<(), BuildError> {
    if points > u32::MAX as usize - 1 {
        return Err(BuildError::TooManyPoints(points));
    }
    for (element, e) in elements.iter().enumerate() {
        for (corner, &index) in e.iter().enumerate() {
            if index as usize >= points {
                return Err(BuildError::IndexOutOfRange { element, corner, index, points });
            }
            if e[..corner].contains(&index) {
                return Err(BuildError::RepeatedVertex { element, point: index });
            }
        }
    }
    Ok(())
}

fn sorted<const K: usize>(mut key: [u32; K]) -> [u32; K] {
    key.sort_unstable();
    key
}

impl GMap<3> {
    /// The 3-G-map of a tetrahedral mesh with `points` points (see the [module docs](self)).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, report) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// assert_eq!(map.dart_count(), 2 * 24);
    /// assert_eq!(map.count_cells().0, vec![5, 9, 7, 2]);
    /// assert_eq!(map.darts().filter(|&d| !map.is_free(3, d)).count(), 12); // the shared face
    /// assert_eq!(report, Default::default()); // nothing unusual in the input
    /// ```
    ///
    /// # Errors
    /// Nothing is built when one is returned. [`BuildError::Empty`], [`BuildError::TooLarge`],
    /// [`BuildError::TooManyPoints`], [`BuildError::IndexOutOfRange`] and
    /// [`BuildError::RepeatedVertex`] (the first, in input order), then from the face matching:
    /// [`BuildError::DuplicateElement`] for a tet listed twice (the lowest repeating tet), else
    /// [`BuildError::NonManifold`] for a face of three tets.
    pub fn from_tets(points: usize, tets: &[[u32; 4]]) -> Result<(GMap<3>, BuildReport), BuildError> {
        if tets.is_empty() {
            return Err(BuildError::Empty("tetrahedra"));
        }
        check_elements(points, tets)?;
        let darts = tets.len().checked_mul(24).filter(|&n| n < u32::MAX as usize - 1);
        let darts = darts.ok_or(BuildError::TooLarge(tets.len().saturating_mul(24)))?;
        Self::from_tets_swept(points, tets, darts, None)
    }

    /// [`Self::from_tets`] after the checks, with the labelling union-finds swept in breadth-first
    /// order when `breadth_first` says so (`None`: when the input order is not local, see
    /// [`SweepOrder::choose`]). The map does not depend on the sweep order.
    fn from_tets_swept(
        points: usize,
        tets: &[[u32; 4]],
        darts: usize,
        breadth_first: Option<bool>,
    ) -> Result<(GMap<3>, BuildReport), BuildError> {
        let faces = match_tet_faces(points, tets)?;
        let sweep = SweepOrder::choose(&faces, breadth_first);
        let local = sweep.as_ref().map_or(&faces, |s| &s.faces);
        let tet_at = |s: usize| sweep.as_ref().map_or(s, |w| w.tet_at[s] as usize);
        let (edge_of, edges, edge_keys) = label_tet_edges(tets, local, tet_at);
        let (corner_of, vertex_ids, orbits_of, extra) = label_tet_corners(points, tets, local, tet_at);
        drop(sweep);
        let (face_of, face_count) = number_tet_faces(&faces.link);
        let (alpha, cell) = tet_rows(&faces, &face_of, &edge_of, &corner_of, darts);
        let mut map = GMap::<3>::from_rows_raw(alpha, cell);
        map.set_id_alloc_raw(1, edges, Vec::new());
        map.set_id_alloc_raw(2, face_count, Vec::new());
        map.set_id_alloc_raw(3, tets.len() as u32, Vec::new());
        let mut report = vertex_report(&orbits_of);
        report.extra_vertices = extra;
        map.set_id_alloc_raw(0, vertex_ids, report.unreferenced_points.clone());
        report.split_edges = split_edges(edge_keys);
        map.mark_tets_as_built();
        map.after_build();
        Ok((map, report))
    }
}

/// An internal order in which the labelling union-finds visit the tets, with the face matching
/// renumbered into it: tet at sweep position s is `tet_at[s]`, and `faces` is the [`FaceMatch`]
/// of the tets in that order (partner faces as 4·position + local face). A breadth-first walk
/// over shared faces puts the neighbours of a tet at nearby positions, so the union-find forests
/// are read in a small window even when the input order is scattered (a mesh file whose tets
/// and points are numbered at random); the ids do not depend on it.
struct SweepOrder {
    /// The tet at each sweep position.
    tet_at: Vec<u32>,
    /// The face matching in sweep positions.
    faces: FaceMatch,
}

/// A face link is "far" when its two tets are more than this many positions apart.
const FAR_LINK: usize = 4096;

impl SweepOrder {
    /// The breadth-first sweep order when `forced` asks for it (`Some(true)`), or, with `None`,
    /// when more than a quarter of a sample of the face links are far in the input order; `None`
    /// means "sweep in input order". O(tets).
    fn choose(faces: &FaceMatch, forced: Option<bool>) -> Option<SweepOrder> {
        let scattered = || {
            let (mut links, mut far) = (0usize, 0usize);
            for tf in (0..faces.link.len()).step_by(7) {
                let g = faces.link[tf].0;
                if g != NO_FACE {
                    links += 1;
                    far += usize::from((g as usize / 4).abs_diff(tf / 4) > FAR_LINK);
                }
            }
            far * 4 > links
        };
        forced.unwrap_or_else(scattered).then(|| Self::breadth_first(faces))
    }

    /// Tets in breadth-first order over shared faces (each component started at its first tet
    /// in input order), and the face matching renumbered. Each tet's partners are read once,
    /// when it leaves the queue. O(tets).
    fn breadth_first(faces: &FaceMatch) -> SweepOrder {
        let n = faces.link.len() / 4;
        let mut position = vec![u32::MAX; n];
        let mut tet_at: Vec<u32> = Vec::with_capacity(n);
        let mut link = vec![(NO_FACE, 0u8); 4 * n];
        let mut head = 0;
        for seed in 0..n {
            if position[seed] != u32::MAX {
                continue;
            }
            position[seed] = tet_at.len() as u32;
            tet_at.push(seed as u32);
            while head < tet_at.len() {
                let t = tet_at[head] as usize;
                for f in 0..4 {
                    let (g, map) = faces.link[t * 4 + f];
                    if g == NO_FACE {
                        continue;
                    }
                    let tg = g as usize / 4;
                    if position[tg] == u32::MAX {
                        position[tg] = tet_at.len() as u32;
                        tet_at.push(tg as u32);
                    }
                    link[head * 4 + f] = (position[tg] * 4 + g % 4, map);
                }
                head += 1;
            }
        }
        SweepOrder { tet_at, faces: FaceMatch { link } }
    }
}

/// Marks a tet face with no partner (a boundary face).
const NO_FACE: u32 = u32::MAX;

/// Marks "no related item" in the lists of `label_orbits`.
const NONE_ITEM: u32 = u32::MAX;

/// Marks a root's slot in `label_orbits`' forest (items and keys stay below 2^30: darts < 2^32).
const TAG: u32 = 1 << 31;

/// The flag k of a face with (vertex, other end of its edge) = (local corners v, o): the inverse
/// of (FLAG_VERTEX, FLAG_OTHER). The diagonal is unused.
const FLAG_OF: [[u8; 3]; 3] = [[u8::MAX, 0, 5], [1, u8::MAX, 2], [4, 3, u8::MAX]];

/// The six edges of a tet as pairs of local corners.
const TET_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

const fn tet_edge_index(u: usize, w: usize) -> usize {
    let (a, b) = if u < w { (u, w) } else { (w, u) };
    match (a, b) {
        (0, 1) => 0,
        (0, 2) => 1,
        (0, 3) => 2,
        (1, 2) => 3,
        (1, 3) => 4,
        _ => 5,
    }
}

/// The local corner (0..4) of each of the 24 darts of a tet: the corner's 6 darts are its
/// ⟨α1, α2⟩ orbit in the tet.
pub(crate) const TET_DART_CORNER: [u8; 24] = TET.vertex;

/// The local edge (0..6, [`TET_EDGES`] order) of each of the 24 darts of a tet: the edge's 4
/// darts are its ⟨α0, α2⟩ orbit in the tet.
pub(crate) const TET_DART_EDGE: [u8; 24] = {
    let mut e = [0u8; 24];
    let mut k = 0;
    while k < 24 {
        e[k] = tet_edge_index(TET.vertex[k] as usize, TET.other[k] as usize) as u8;
        k += 1;
    }
    e
};

/// α0, α1 and α2 of each of the 24 darts of a tet, as offsets from the tet's first dart.
pub(crate) const TET_LINKS: [[u32; 3]; 24] = {
    let mut links = [[0u32; 3]; 24];
    let mut k = 0;
    while k < 24 {
        let (f, j) = (k / 6, k % 6);
        links[k] = [(f * 6 + FLAG_ALPHA0[j]) as u32, (f * 6 + FLAG_ALPHA1[j]) as u32, TET.alpha2[k] as u32];
        k += 1;
    }
    links
};

/// αi(d) (i < 3) of dart d of a tet as [`GMap::from_tets`] lays it out: dart 24t + k is linked to
/// 24t + `TET_LINKS[k][i]`. With [`built_tet_links`], the one place the pattern is applied to a
/// dart id. O(1).
#[inline(always)]
pub(crate) fn built_tet_link(i: usize, d: u32) -> u32 {
    let k = d % 24;
    d - k + TET_LINKS[k as usize][i]
}

/// [α0(d), α1(d), α2(d)] of dart d of a tet as built (see [`built_tet_link`]). O(1).
#[inline(always)]
pub(crate) fn built_tet_links(d: u32) -> [u32; 3] {
    let k = d % 24;
    TET_LINKS[k as usize].map(|offset| d - k + offset)
}

/// The `count` local items (corners or edges) of a tet sorted by the smallest dart that carries
/// them, given the item of each dart: labelling items in this order within each tet, tets in
/// order, gives the ids a flood over darts in increasing order would give.
fn items_by_first_dart(count: usize, item_of_dart: impl Fn(usize) -> usize) -> Vec<usize> {
    let mut first = vec![usize::MAX; count];
    for k in (0..24).rev() {
        first[item_of_dart(k)] = k;
    }
    let mut items: Vec<usize> = (0..count).collect();
    items.sort_by_key(|&i| first[i]);
    items
}

/// The matched faces of a tet mesh: for every tet face 4t + f, the tet face with the same three
/// points (`NO_FACE` on the boundary), and where each local corner of t lands in the partner's
/// tet. With the corner map, sewing and labelling never read the partner tet's points.
struct FaceMatch {
    /// For every tet face 4t + f: the partner tet face (or `NO_FACE`), and the corner map: two
    /// bits per local corner v ≠ f of t, the local corner of the partner's tet that carries the
    /// same point (0 for boundary faces and for v = f). One pair per face, so that both are
    /// read from one cache line.
    link: Vec<(u32, u8)>,
}

impl FaceMatch {
    /// The tet face partnered with tet face tf and, for local corner v of tf's tet, the local
    /// corner of the partner's tet with the same point; `None` on the boundary.
    #[inline(always)]
    fn across(&self, tf: usize) -> Option<(u32, u8)> {
        let (g, map) = self.link[tf];
        (g != NO_FACE).then_some((g, map))
    }

    /// α3 of the six darts 6·tf + j of tet face tf: themselves on the boundary, else the dart of
    /// the partner face with the same (point, other point of its edge).
    #[inline(always)]
    fn alpha3(&self, tf: usize) -> [u32; 6] {
        let own = (tf * 6) as u32;
        let Some((g, map)) = self.across(tf) else {
            return std::array::from_fn(|j| own + j as u32);
        };
        let corners = face_corners(tf % 4);
        let fg = g as usize % 4;
        // Position of the partner's local corner w among the corners of its face fg.
        let position = |v: usize| {
            let w = corner_across(map, v);
            w - usize::from(w > fg)
        };
        std::array::from_fn(|j| {
            let kb = FLAG_OF[position(corners[FLAG_VERTEX[j]])][position(corners[FLAG_OTHER[j]])];
            g * 6 + u32::from(kb)
        })
    }
}

/// The partner tet's local corner of local corner v, from a face's corner map.
#[inline(always)]
fn corner_across(map: u8, v: usize) -> usize {
    usize::from(map >> (2 * v)) & 3
}

/// For every tet face 4t + f, the other tet face with the same three points (`NO_FACE` if none)
/// and the corner map between the two tets. Faces are bucketed by their smallest point (a
/// counting sort) and sorted within each bucket, so no hashing is needed. O(tets + points).
///
/// Errors: [`BuildError::DuplicateElement`] for a tet listed twice: two tets that share a second
/// face share all four corners, which [`first_repeated_tet`] sees in the links (a face of three
/// tets or more, left unlinked, is checked by [`duplicate_in_fan`]). Of all such pairs, the lowest repeating tet with its earliest copy.
/// Else [`BuildError::NonManifold`] for the first face (in input order) seen a third time.
fn match_tet_faces(points: usize, tets: &[[u32; 4]]) -> Result<FaceMatch, BuildError> {
    // The face's points in increasing order, and the local corners that carry them (2 bits each).
    let key = |tet: &[u32; 4], f: usize| {
        let mut pc = face_corners(f).map(|k| (tet[k], k as u8));
        pc.sort_unstable();
        (pc.map(|x| x.0), pc[0].1 | (pc[1].1 << 2) | (pc[2].1 << 4))
    };
    let mut start = vec![0u32; points + 1];
    for tet in tets {
        for f in 0..4 {
            start[face_corners(f).iter().map(|&k| tet[k]).min().expect("three corners") as usize + 1] += 1;
        }
    }
    for p in 0..points {
        start[p + 1] += start[p];
    }
    let mut fill = start.clone();
    let mut bucket = vec![(0u64, 0u32, 0u8); tets.len() * 4];
    for (t, tet) in tets.iter().enumerate() {
        for f in 0..4 {
            let ([a, b, c], corners) = key(tet, f);
            bucket[fill[a as usize] as usize] = ((u64::from(b) << 32) | u64::from(c), (t * 4 + f) as u32, corners);
            fill[a as usize] += 1;
        }
    }
    let mut link = vec![(NO_FACE, 0u8); tets.len() * 4];
    // (third face, points, first face, second face) of the earliest face seen three times.
    let mut third: Option<(u32, [u32; 3], u32, u32)> = None;
    // (second tet, first tet) of the lowest tet that repeats an earlier one.
    let mut duplicate: Option<(u32, u32)> = None;
    for a in 0..points {
        let faces = &mut bucket[start[a] as usize..start[a + 1] as usize];
        // Faces were bucketed in increasing tet-face order: a stable sort by points keeps it.
        faces.sort_by_key(|x| x.0);
        for run in faces.chunk_by(|x, y| x.0 == y.0) {
            match run {
                [_] => {}
                [(_, f1, c1), (_, f2, c2)] => {
                    let (mut m1, mut m2) = (0u8, 0u8);
                    for i in 0..3 {
                        let (v1, v2) = ((c1 >> (2 * i)) & 3, (c2 >> (2 * i)) & 3);
                        m1 |= v2 << (2 * v1);
                        m2 |= v1 << (2 * v2);
                    }
                    link[*f1 as usize] = (*f2, m1);
                    link[*f2 as usize] = (*f1, m2);
                }
                [(bc, f1, _), (_, f2, _), (_, f3, _), ..] => {
                    if third.is_none_or(|w| *f3 < w.0) {
                        third = Some((*f3, [a as u32, (bc >> 32) as u32, *bc as u32], *f1, *f2));
                    }
                    if let Some(pair) = duplicate_in_fan(tets, run) {
                        keep_lowest(&mut duplicate, pair);
                    }
                }
                [] => unreachable!("chunks are never empty"),
            }
        }
    }
    if let Some(pair) = first_repeated_tet(&link) {
        keep_lowest(&mut duplicate, pair);
    }
    match (duplicate, third) {
        (None, None) => Ok(FaceMatch { link }),
        (Some((second, first)), _) => Err(BuildError::DuplicateElement {
            what: "tet",
            first: first as usize,
            second: second as usize,
            points: tets[first as usize].to_vec(),
        }),
        (None, Some((f3, points, f1, f2))) => Err(BuildError::NonManifold {
            what: "face",
            points: points.to_vec(),
            elements: [f1 as usize / 4, f2 as usize / 4, f3 as usize / 4],
        }),
    }
}

/// (second, first) for the lowest tet that shares two faces with an earlier tet: two faces of a
/// tet cover its four corners, so it repeats that tet. One sequential read of the face links
/// after the matching (32 bytes per tet; a test inside the matching, a dependent load beside its
/// scattered writes, cost 5 % of the build). O(tets).
fn first_repeated_tet(link: &[(u32, u8)]) -> Option<(u32, u32)> {
    link.chunks_exact(4).enumerate().find_map(|(t, faces)| {
        let partner = |f: usize| (faces[f].0 != NO_FACE).then_some(faces[f].0 / 4).filter(|&u| (u as usize) < t);
        let earlier: [Option<u32>; 4] = std::array::from_fn(partner);
        let twice = (0..4).find_map(|f| earlier[f].filter(|&u| earlier[f + 1..].contains(&Some(u))))?;
        Some((t as u32, twice))
    })
}

/// `pair` into `slot` unless `slot` holds a lower one. O(1).
fn keep_lowest(slot: &mut Option<(u32, u32)>, pair: (u32, u32)) {
    *slot = Some(slot.map_or(pair, |p| p.min(pair)));
}

/// (second, first) for the lowest tet among those on one face of three tets or more that
/// repeats an earlier one (same sorted corners), with its earliest copy; `None` when they all
/// differ. Only on the way to an error. O(k log k) for k tets on the face.
#[cold]
fn duplicate_in_fan(tets: &[[u32; 4]], run: &[(u64, u32, u8)]) -> Option<(u32, u32)> {
    let mut keyed: Vec<([u32; 4], u32)> = run.iter().map(|&(_, f, _)| (sorted(tets[f as usize / 4]), f / 4)).collect();
    keyed.sort_unstable();
    keyed.windows(2).filter(|w| w[0].0 == w[1].0).map(|w| (w[1].1, w[0].1)).min()
}

/// Face ids of every tet face in order of first appearance (a matched pair shares the id of its
/// first face), and the number of faces. O(tets).
fn number_tet_faces(link: &[(u32, u8)]) -> (Vec<u32>, u32) {
    let mut face_of = vec![0u32; link.len()];
    let mut faces = 0u32;
    for (tf, &(other, _)) in link.iter().enumerate() {
        if other == NO_FACE || other as usize > tf {
            face_of[tf] = faces;
            faces += 1;
        } else {
            face_of[tf] = face_of[other as usize];
        }
    }
    (face_of, faces)
}

/// The α rows and cell rows of all darts (dart 24t + 6f + j: tet t, face f, flag j), written
/// once, in order, from the face matching and the face, edge and vertex ids of every (tet,
/// local item) in input order. O(darts).
fn tet_rows(
    faces: &FaceMatch,
    face_of: &[u32],
    edge_of: &[u32],
    corner_of: &[u32],
    darts: usize,
) -> (Vec<u32>, Vec<u32>) {
    let mut alpha = Vec::with_capacity(darts * 4);
    let mut cell = Vec::with_capacity(darts * 4);
    for t in 0..darts / 24 {
        let base = (t * 24) as u32;
        let (corners, edges_of_t) = (&corner_of[t * 4..t * 4 + 4], &edge_of[t * 6..t * 6 + 6]);
        for f in 0..4 {
            let (tf, face) = (t * 4 + f, face_of[t * 4 + f]);
            for (j, &a3) in faces.alpha3(tf).iter().enumerate() {
                let k = f * 6 + j;
                let [a0, a1, a2] = TET_LINKS[k];
                alpha.extend_from_slice(&[base + a0, base + a1, base + a2, a3]);
                let v = corners[TET.vertex[k] as usize];
                let e = edges_of_t[TET_DART_EDGE[k] as usize];
                cell.extend_from_slice(&[v, e, face, t as u32]);
            }
        }
    }
    (alpha, cell)
}

/// Labels `per_tet` local items of every tet (edges or corners) by the orbits of a relation
/// that joins items of tets sharing a face, with the tets visited in a sweep order (`tet_at(s)`
/// is the tet at sweep position s; items are numbered `s · per_tet + item`).
/// `neighbours(s, item)` lists the related items at earlier sweep positions (`NONE_ITEM` for
/// none; each relation is met once, from its later position).
///
/// A union-find forest over the swept items is built in one sweep, each item joining the trees
/// of its related items below it (roots are the smallest swept item of their tree). Each orbit
/// then gets the smallest input key `tet · per_tet + rank` of its items (`rank` = place of the
/// item in `order`), and orbits are named by `new_id(tet, item)` in increasing key order, i.e.
/// tet by tet in input order, in `order` within a tet. Since an orbit has at most one item per
/// tet, this numbers orbits exactly as a flood started at each unlabelled item in that visiting
/// order would, whatever the sweep order. Returns the id of every item `tet · per_tet + item`
/// (input order). O(items · α).
fn label_orbits(
    tets: usize,
    per_tet: usize,
    order: &[usize],
    tet_at: impl Fn(usize) -> usize,
    neighbours: impl Fn(usize, usize) -> [u32; 3],
    mut new_id: impl FnMut(usize, usize) -> u32,
) -> Vec<u32> {
    let items = tets * per_tet;
    let mut forest: Vec<u32> = (0..items as u32).collect();
    for s in 0..tets {
        for item in 0..per_tet {
            let x = (s * per_tet + item) as u32;
            // NONE_ITEM is never below x, so it is skipped.
            join_with_smaller(&mut forest, x, &neighbours(s, item), &[0, 1, 2]);
        }
    }
    let mut rank = [0u32; 6];
    for (r, &item) in order.iter().enumerate() {
        rank[item] = r as u32;
    }
    // Every root's slot becomes TAG | the smallest input key of its orbit, every other slot its
    // root. Slots point to smaller items and the items below x already point to their root or
    // are tagged roots, so one step from x finds its root.
    let mut roots = vec![0u64; items.div_ceil(64)];
    for s in 0..tets {
        let key = (tet_at(s) * per_tet) as u32;
        for (item, &r) in rank[..per_tet].iter().enumerate() {
            let (x, k) = (s * per_tet + item, key + r);
            let parent = forest[x] as usize;
            if parent == x {
                forest[x] = TAG | k;
                roots[x / 64] |= 1 << (x % 64);
            } else {
                let root = if forest[parent] & TAG != 0 { parent } else { forest[parent] as usize };
                forest[x] = root as u32;
                forest[root] = forest[root].min(TAG | k);
            }
        }
    }
    let is_root = |x: usize| roots[x / 64] >> (x % 64) & 1 != 0;
    // The root of the orbit whose smallest key is k, at k; then ids in increasing key order,
    // each written in its root's slot.
    let mut root_at_key = vec![NONE_ITEM; items];
    for (x, &slot) in forest.iter().enumerate() {
        if is_root(x) {
            root_at_key[(slot & !TAG) as usize] = x as u32;
        }
    }
    for (key, &root) in root_at_key.iter().enumerate() {
        if root != NONE_ITEM {
            forest[root as usize] = new_id(key / per_tet, order[key % per_tet]);
        }
    }
    // The ids in input order, written over the key table (whose index space is the input's).
    let mut label = root_at_key;
    for s in 0..tets {
        let (t, x) = (tet_at(s) * per_tet, s * per_tet);
        for item in 0..per_tet {
            let slot = forest[x + item];
            label[t + item] = if is_root(x + item) { slot } else { forest[slot as usize] };
        }
    }
    label
}

/// Edge ids of every (tet, local edge) pair: the edge orbits ⟨α0, α2, α3⟩ of the built
/// map (tet edges joined across shared faces), numbered as a flood over darts in increasing
/// order would. `faces` is the face matching in sweep positions, `tet_at` the tet at each.
/// Returns the ids (6 per tet, input order), the number of edges and the sorted point pair of every
/// edge id packed in a u64. O(tets · α).
fn label_tet_edges(tets: &[[u32; 4]], faces: &FaceMatch, tet_at: impl Fn(usize) -> usize) -> (Vec<u32>, u32, Vec<u64>) {
    let order = items_by_first_dart(6, |k| TET_DART_EDGE[k] as usize);
    let mut keys: Vec<u64> = Vec::new();
    let neighbours = |t: usize, e: usize| {
        let [u, w] = TET_EDGES[e];
        let mut out = [NONE_ITEM; 3];
        for (slot, f) in (0..4).filter(|&f| f != u && f != w).enumerate() {
            if let Some((g, map)) = faces.across(t * 4 + f) {
                let tg = g as usize / 4;
                if tg < t {
                    out[slot] = (tg * 6 + tet_edge_index(corner_across(map, u), corner_across(map, w))) as u32;
                }
            }
        }
        out
    };
    let new_id = |t: usize, e: usize| {
        let [u, w] = TET_EDGES[e];
        let [a, b] = sorted([tets[t][u], tets[t][w]]);
        keys.push((u64::from(a) << 32) | u64::from(b));
        keys.len() as u32 - 1
    };
    let label = label_orbits(tets.len(), 6, &order, tet_at, neighbours, new_id);
    let edges = keys.len() as u32;
    (label, edges, keys)
}

/// Vertex ids of every (tet, corner) pair: the vertex orbits ⟨α1, α2, α3⟩ (tet corners
/// joined across shared faces); the first orbit of point p gets id p, any further one a fresh
/// id, in the order of a flood over darts in increasing order. `faces` and `tet_at` as for
/// [`label_tet_edges`]. Returns the ids (4 per tet, input order), the id bound, the number of
/// orbits of each point, and each fresh id with its point, by increasing id
/// ([`BuildReport::extra_vertices`]). O(tets · α + points).
#[allow(clippy::type_complexity)]
fn label_tet_corners(
    points: usize,
    tets: &[[u32; 4]],
    faces: &FaceMatch,
    tet_at: impl Fn(usize) -> usize,
) -> (Vec<u32>, u32, Vec<usize>, Vec<(u32, u32)>) {
    let order = items_by_first_dart(4, |k| TET.vertex[k] as usize);
    let mut orbits_of = vec![0usize; points];
    let mut next = points as u32;
    let neighbours = |t: usize, v: usize| {
        let mut out = [NONE_ITEM; 3];
        for (slot, f) in (0..4).filter(|&f| f != v).enumerate() {
            if let Some((g, map)) = faces.across(t * 4 + f) {
                let tg = g as usize / 4;
                if tg < t {
                    out[slot] = (tg * 4 + corner_across(map, v)) as u32;
                }
            }
        }
        out
    };
    let mut extra = Vec::new();
    let new_id = |t: usize, v: usize| {
        let p = tets[t][v];
        orbits_of[p as usize] += 1;
        if orbits_of[p as usize] == 1 {
            p
        } else {
            extra.push((next, p));
            (next, next += 1).0
        }
    };
    let label = label_orbits(tets.len(), 4, &order, tet_at, neighbours, new_id);
    (label, next, orbits_of, extra)
}

/// Point pairs carried by more than one edge, in increasing order, from the packed pair
/// `a << 32 | b` (a < b) of every edge: pairs bucketed by their first point (a counting sort),
/// then each bucket's second points sorted. O(E + points) and the sorts of the small buckets.
fn split_edges(keys: Vec<u64>) -> Vec<([u32; 2], usize)> {
    let first = |key: u64| (key >> 32) as usize;
    let points = keys.iter().map(|&key| first(key) + 1).max().unwrap_or(0);
    let mut start = vec![0u32; points + 1];
    for &key in &keys {
        start[first(key) + 1] += 1;
    }
    for a in 0..points {
        start[a + 1] += start[a];
    }
    let mut fill = start.clone();
    let mut second = vec![0u32; keys.len()];
    for &key in &keys {
        second[fill[first(key)] as usize] = key as u32;
        fill[first(key)] += 1;
    }
    let mut out: Vec<([u32; 2], usize)> = Vec::new();
    for a in 0..points {
        let bucket = &mut second[start[a] as usize..start[a + 1] as usize];
        bucket.sort_unstable();
        let repeated = bucket.chunk_by(|x, y| x == y).filter(|run| run.len() > 1);
        out.extend(repeated.map(|run| ([a as u32, run[0]], run.len())));
    }
    out
}

/// The vertex part of a build report, from the number of vertex orbits of each point.
fn vertex_report(orbits_of: &[usize]) -> BuildReport {
    BuildReport {
        pinched_vertices: (0..orbits_of.len())
            .filter(|&p| orbits_of[p] > 1)
            .map(|p| (p as u32, orbits_of[p]))
            .collect(),
        split_edges: Vec::new(),
        unreferenced_points: (0..orbits_of.len() as u32).filter(|&p| orbits_of[p as usize] == 0).collect(),
        extra_vertices: Vec::new(),
    }
}

impl GMap<2> {
    /// The 2-G-map of a triangle mesh with `points` points (see the [module docs](self)).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, triangles) = generate::grid_triangles(2);
    /// let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    /// assert_eq!(map.dart_count(), 6 * triangles.len());
    /// assert_eq!(map.count_cells().0, vec![9, 16, 8]);
    /// assert_eq!(map.boundary_cell_count(), 8); // 4n boundary edges
    /// assert!(GMap::<2>::from_triangles(3, &[[0, 1, 1]]).is_err()); // repeated point
    /// let twice = GMap::<2>::from_triangles(3, &[[0, 1, 2], [2, 1, 0]]).unwrap_err(); // not a closed pillow
    /// assert!(matches!(twice, topomech::BuildError::DuplicateElement { first: 0, second: 1, .. }));
    /// ```
    ///
    /// # Errors
    /// Nothing is built when one is returned. [`BuildError::Empty`], [`BuildError::TooLarge`],
    /// [`BuildError::TooManyPoints`], [`BuildError::IndexOutOfRange`],
    /// [`BuildError::RepeatedVertex`]; then, for the first triangle (in input order) at fault,
    /// [`BuildError::DuplicateElement`] when it repeats an earlier triangle, else
    /// [`BuildError::NonManifold`] for an edge of three triangles.
    pub fn from_triangles(points: usize, triangles: &[[u32; 3]]) -> Result<(GMap<2>, BuildReport), BuildError> {
        if triangles.is_empty() {
            return Err(BuildError::Empty("triangles"));
        }
        check_elements(points, triangles)?;
        let darts = triangles.len().checked_mul(6).filter(|&n| n < u32::MAX as usize - 1);
        let darts = darts.ok_or(BuildError::TooLarge(triangles.len().saturating_mul(6)))?;
        let mut map = GMap::<2>::new();
        map.alloc_darts_raw(darts);
        for t in 0..triangles.len() {
            for k in 0..6 {
                let d = DartId((t * 6 + k) as u32);
                map.link_raw(0, d, DartId((t * 6 + FLAG_ALPHA0[k]) as u32));
                map.link_raw(1, d, DartId((t * 6 + FLAG_ALPHA1[k]) as u32));
                map.set_cell_raw(2, d, t as u32);
            }
        }
        let edges = map.link_triangle_edges(triangles)?;
        map.set_id_alloc_raw(1, edges, Vec::new());
        map.set_id_alloc_raw(2, triangles.len() as u32, Vec::new());
        let corner = |d: DartId| triangles[d.index() / 6][FLAG_VERTEX[d.index() % 6]];
        let report = map.label_vertices(points, corner);
        map.after_build();
        Ok((map, report))
    }

    /// 2-links triangles sharing an edge and labels edges; returns the number of edges.
    fn link_triangle_edges(&mut self, triangles: &[[u32; 3]]) -> Result<u32, BuildError> {
        let mut first_seen: FxHashMap<[u32; 2], (u32, u32)> = FxHashMap::default();
        let mut edges = 0u32;
        for (t, tri) in triangles.iter().enumerate() {
            for e in 0..3 {
                let (k0, k1) = (2 * e as u32, 2 * e as u32 + 1);
                let d0 = DartId(t as u32 * 6 + k0);
                let d1 = DartId(t as u32 * 6 + k1);
                let key = sorted([tri[FLAG_VERTEX[k0 as usize]], tri[FLAG_VERTEX[k1 as usize]]]);
                match first_seen.get_mut(&key) {
                    None => {
                        first_seen.insert(key, (d0.0, u32::MAX));
                        self.set_cell_raw(1, d0, edges);
                        self.set_cell_raw(1, d1, edges);
                        edges += 1;
                    }
                    Some(slot) if slot.1 == u32::MAX => {
                        repeated_triangle(triangles, &[slot.0], t)?;
                        slot.1 = d0.0;
                        let a0 = DartId(slot.0);
                        let a1 = self.alpha_dyn(0, a0);
                        let id = self.cell_id(1, a0).0;
                        let same = |a: DartId, b: DartId| {
                            triangles[a.index() / 6][FLAG_VERTEX[a.index() % 6]] == tri[FLAG_VERTEX[b.index() % 6]]
                        };
                        let (b0, b1) = if same(a0, d0) { (d0, d1) } else { (d1, d0) };
                        self.link_raw(2, a0, b0);
                        self.link_raw(2, a1, b1);
                        self.set_cell_raw(1, d0, id);
                        self.set_cell_raw(1, d1, id);
                    }
                    Some(slot) => {
                        repeated_triangle(triangles, &[slot.0, slot.1], t)?;
                        let elements = [slot.0 as usize / 6, slot.1 as usize / 6, t];
                        return Err(BuildError::NonManifold { what: "edge", points: key.to_vec(), elements });
                    }
                }
            }
        }
        Ok(edges)
    }
}

/// [`BuildError::DuplicateElement`] when triangle `t` has the same points as the triangle of
/// one of `darts` (earlier triangles on one of its edges, in increasing order): a triangle that
/// shares an edge with `t` repeats it iff its third point is `t`'s too. O(darts).
fn repeated_triangle(triangles: &[[u32; 3]], darts: &[u32], t: usize) -> Result<(), BuildError> {
    let points = sorted(triangles[t]);
    match darts.iter().map(|&d| d as usize / 6).find(|&e| sorted(triangles[e]) == points) {
        Some(first) => {
            Err(BuildError::DuplicateElement { what: "triangle", first, second: t, points: triangles[first].to_vec() })
        }
        None => Ok(()),
    }
}

impl<const N: usize> GMap<N> {
    /// Labels the unlabelled orbit of d under the generators `gens` with `id`.
    fn flood_label(&mut self, dim: usize, d: DartId, gens: &[usize], id: u32, stack: &mut Vec<DartId>) {
        self.set_cell_raw(dim, d, id);
        stack.push(d);
        while let Some(x) = stack.pop() {
            for &j in gens {
                let y = self.alpha_dyn(j, x);
                if self.cell_id(dim, y).0 == u32::MAX {
                    self.set_cell_raw(dim, y, id);
                    stack.push(y);
                }
            }
        }
    }

    /// Vertex ids: the first vertex orbit of point p gets id p, any further one a fresh id.
    fn label_vertices(&mut self, points: usize, corner: impl Fn(DartId) -> u32) -> BuildReport {
        let mask = AlphaMask::cell(N, 0);
        let gens: Vec<usize> = mask.indices().filter(|&j| j <= N).collect();
        let mut orbits_of = vec![0usize; points];
        let mut next = points as u32;
        let mut stack = Vec::new();
        let mut extra = Vec::new();
        for d in 0..self.capacity() as u32 {
            let d = DartId(d);
            if self.cell_id(0, d).0 != u32::MAX {
                continue;
            }
            let p = corner(d);
            let id = if orbits_of[p as usize] == 0 {
                p
            } else {
                extra.push((next, p));
                (next, next += 1).0
            };
            orbits_of[p as usize] += 1;
            self.flood_label(0, d, &gens, id, &mut stack);
        }
        let mut report = vertex_report(&orbits_of);
        report.extra_vertices = extra;
        self.set_id_alloc_raw(0, next, report.unreferenced_points.clone());
        report
    }

    /// The checks every builder runs before handing a map out.
    fn after_build(&self) {
        debug_assert!(self.validate().is_ok(), "topomech bug: a built map is invalid: {:?}", self.validate());
        #[cfg(all(feature = "expensive-checks", not(debug_assertions)))]
        if let Err(e) = self.validate() {
            panic!("topomech bug: a built map is invalid: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{kuhn_cube, SplitMix64};

    /// Kuhn cube k with about `percent` % of its tets removed (pinched vertices and split edges
    /// appear), in a shuffled order when `shuffle` (far face links in the input order).
    fn damaged_cube(k: usize, percent: usize, shuffle: bool) -> (usize, Vec<[u32; 4]>) {
        let (points, tets) = kuhn_cube(k);
        let mut rng = SplitMix64(k as u64 * 1000 + percent as u64);
        let mut kept: Vec<[u32; 4]> = tets.into_iter().filter(|_| rng.below(100) >= percent).collect();
        if shuffle {
            for i in (1..kept.len()).rev() {
                kept.swap(i, rng.below(i + 1));
            }
        }
        (points.len(), kept)
    }

    /// Every α link and cell id of every dart, each id allocator (next, free list), the report.
    type Everything = (Vec<u32>, Vec<(u32, Vec<u32>)>, BuildReport);

    fn everything(built: &(GMap<3>, BuildReport)) -> Everything {
        let (map, report) = built;
        let rows =
            map.darts().flat_map(|d| (0..=3).flat_map(move |i| [map.alpha_dyn(i, d).0, map.cell_id(i, d).0])).collect();
        let allocs = (0..=3).map(|i| (map.id_alloc_raw(i).0, map.id_alloc_raw(i).1.to_vec())).collect();
        (rows, allocs, report.clone())
    }

    #[test]
    fn the_breadth_first_sweep_builds_the_same_map_as_the_input_order_sweep() {
        let mut pinched = 0;
        for (k, percent, shuffle) in [(3, 0, true), (3, 40, true), (5, 60, false), (6, 30, true), (6, 80, true)] {
            let (points, tets) = damaged_cube(k, percent, shuffle);
            let darts = tets.len() * 24;
            let input = GMap::<3>::from_tets_swept(points, &tets, darts, Some(false)).unwrap();
            let swept = GMap::<3>::from_tets_swept(points, &tets, darts, Some(true)).unwrap();
            assert_eq!(everything(&input), everything(&swept), "k = {k}, -{percent} %, shuffled {shuffle}");
            pinched += input.1.pinched_vertices.len() + input.1.split_edges.len();
        }
        assert!(pinched > 0, "the inputs exercise fresh vertex ids and split edges");
    }

    #[test]
    fn the_breadth_first_order_is_a_permutation_and_renumbers_the_face_matching() {
        let (points, tets) = damaged_cube(4, 50, true);
        let faces = match_tet_faces(points, &tets).unwrap();
        let sweep = SweepOrder::breadth_first(&faces);
        let mut seen = sweep.tet_at.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..tets.len() as u32).collect::<Vec<_>>());
        let mut position = vec![0u32; tets.len()];
        for (s, &t) in sweep.tet_at.iter().enumerate() {
            position[t as usize] = s as u32;
        }
        for (s, &t) in sweep.tet_at.iter().enumerate() {
            for f in 0..4 {
                let (g, map) = faces.link[t as usize * 4 + f];
                let expected = if g == NO_FACE { NO_FACE } else { position[g as usize / 4] * 4 + g % 4 };
                assert_eq!(sweep.faces.link[s * 4 + f], (expected, map), "tet {t} face {f}");
            }
        }
    }

    #[test]
    fn the_sweep_order_is_breadth_first_only_on_scattered_input() {
        let (points, tets) = damaged_cube(12, 0, false);
        let faces = match_tet_faces(points, &tets).unwrap();
        assert!(SweepOrder::choose(&faces, None).is_none(), "generation order is local");
        assert!(SweepOrder::choose(&faces, Some(true)).is_some());
        let (points, tets) = damaged_cube(12, 0, true);
        let faces = match_tet_faces(points, &tets).unwrap();
        assert!(SweepOrder::choose(&faces, None).is_some(), "a shuffled order is scattered");
        assert!(SweepOrder::choose(&faces, Some(false)).is_none());
    }
}

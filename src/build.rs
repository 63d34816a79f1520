//! Building n-G-maps from indexed meshes: tetrahedra into a 3-G-map, triangles into a 2-G-map.
//!
//! A tetrahedron becomes 24 darts, one per (vertex, edge, face) flag of the tet; α0, α1 and α2
//! are fixed by a template, and α3 links the darts of two tets that share a face, found by
//! matching sorted vertex triples. A triangle becomes 6 darts; α2 links triangles that share an
//! edge, found by matching sorted vertex pairs.
//!
//! Cell ids: volume id = tet index, face ids in order of first appearance, edge ids in order of
//! a flood fill. The vertex id of a g-map vertex is the index of its input point, so arrays of
//! points index vertex embeddings directly. Where the input is not a manifold at a point (the
//! tets around it form several fans joined only at the point) or along an edge, the g-map has
//! several vertices or edges there: the first keeps the point's index, the others get fresh ids,
//! and [`BuildReport`] lists them. Unreferenced points leave free vertex ids.
//!
//! Cost: O(tets) expected (one hash-map look-up per face, one flood fill per cell dimension).

use rustc_hash::FxHashMap;

use crate::gmap::{AlphaMask, DartId, GMap};

/// Why a mesh could not be turned into a map. Nothing is built when one is returned.
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
    /// More darts than 32-bit ids can name.
    #[error("the mesh is too large: {0} darts exceed the 32-bit dart ids")]
    TooLarge(usize),
}

/// What the build found worth knowing about the input, besides the map.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Points whose elements form several fans: (point, number of g-map vertices it became).
    pub pinched_vertices: Vec<(u32, usize)>,
    /// Point pairs whose elements around the edge form several fans: (points, g-map edges).
    pub split_edges: Vec<([u32; 2], usize)>,
    /// Points no element uses; their vertex ids are left free.
    pub unreferenced_points: Vec<u32>,
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

/// Checks indices and repeated points of `K`-point elements.
fn check_elements<const K: usize>(points: usize, elements: &[[u32; K]]) -> Result<(), BuildError> {
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
    pub fn from_tets(points: usize, tets: &[[u32; 4]]) -> Result<(GMap<3>, BuildReport), BuildError> {
        if tets.is_empty() {
            return Err(BuildError::Empty("tetrahedra"));
        }
        check_elements(points, tets)?;
        let darts = tets.len().checked_mul(24).filter(|&n| n < u32::MAX as usize - 1);
        let darts = darts.ok_or(BuildError::TooLarge(tets.len().saturating_mul(24)))?;
        let mut map = GMap::<3>::new();
        map.alloc_darts_raw(darts);
        for t in 0..tets.len() {
            map.link_tet_template(t);
        }
        let faces = map.link_tet_faces(tets)?;
        map.set_id_alloc_raw(2, faces, Vec::new());
        map.set_id_alloc_raw(3, tets.len() as u32, Vec::new());
        map.label_by_flood(1);
        let corner = |d: DartId| tets[d.index() / 24][TET.vertex[d.index() % 24] as usize];
        let mut report = map.label_vertices(points, corner);
        report.split_edges = map.split_edges(corner);
        map.after_build();
        Ok((map, report))
    }

    /// α0, α1, α2 and the volume id of the 24 darts of tet t.
    fn link_tet_template(&mut self, t: usize) {
        let base = t * 24;
        for f in 0..4 {
            for k in 0..6 {
                let d = DartId((base + f * 6 + k) as u32);
                self.link_raw(0, d, DartId((base + f * 6 + FLAG_ALPHA0[k]) as u32));
                self.link_raw(1, d, DartId((base + f * 6 + FLAG_ALPHA1[k]) as u32));
                self.link_raw(2, d, DartId((base + TET.alpha2[f * 6 + k] as usize) as u32));
                self.set_cell_raw(3, d, t as u32);
            }
        }
    }

    /// 3-links tets sharing a face and labels faces; returns the number of faces.
    fn link_tet_faces(&mut self, tets: &[[u32; 4]]) -> Result<u32, BuildError> {
        let mut first_seen: FxHashMap<[u32; 3], (u32, u32)> = FxHashMap::default();
        first_seen.reserve(tets.len() * 2 + 4);
        let mut faces = 0u32;
        for (t, tet) in tets.iter().enumerate() {
            for f in 0..4 {
                let c = face_corners(f).map(|k| tet[k]);
                let key = sorted(c);
                let tf = (t * 4 + f) as u32;
                match first_seen.get_mut(&key) {
                    None => {
                        first_seen.insert(key, (tf, u32::MAX));
                        self.label_face(tf, faces);
                        faces += 1;
                    }
                    Some(slot) if slot.1 == u32::MAX => {
                        slot.1 = tf;
                        let other = slot.0;
                        self.sew_tet_faces(tets, other, tf);
                    }
                    Some(slot) => {
                        let elements = [slot.0 as usize / 4, slot.1 as usize / 4, t];
                        return Err(BuildError::NonManifold { what: "face", points: key.to_vec(), elements });
                    }
                }
            }
        }
        Ok(faces)
    }

    fn label_face(&mut self, tf: u32, id: u32) {
        for k in 0..6 {
            self.set_cell_raw(2, DartId(tf * 6 + k), id);
        }
    }

    /// α3-links face `a` (= 4·tet + local face) with face `b` dart by dart, matching each dart's
    /// (point, other point of its edge), and gives b the face id of a.
    fn sew_tet_faces(&mut self, tets: &[[u32; 4]], a: u32, b: u32) {
        let flag = |tf: u32, k: u32| {
            let local = (tf % 4 * 6 + k) as usize;
            let tet = &tets[tf as usize / 4];
            (tet[TET.vertex[local] as usize], tet[TET.other[local] as usize])
        };
        let id = self.cell_id(2, DartId(a * 6)).0;
        for k in 0..6 {
            let key = flag(a, k);
            let kb = (0..6).find(|&kb| flag(b, kb) == key).expect("faces with equal point sets");
            self.link_raw(3, DartId(a * 6 + k), DartId(b * 6 + kb));
            self.set_cell_raw(2, DartId(b * 6 + kb), id);
        }
    }
}

impl GMap<2> {
    /// The 2-G-map of a triangle mesh with `points` points (see the [module docs](self)).
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
                        slot.1 = d0.0;
                        let a0 = DartId(slot.0);
                        let a1 = self.alpha_dyn(0, a0);
                        let id = self.cell_id(1, a0).0;
                        let same = |a: DartId, b: DartId| triangles[a.index() / 6][FLAG_VERTEX[a.index() % 6]] == tri[FLAG_VERTEX[b.index() % 6]];
                        let (b0, b1) = if same(a0, d0) { (d0, d1) } else { (d1, d0) };
                        self.link_raw(2, a0, b0);
                        self.link_raw(2, a1, b1);
                        self.set_cell_raw(1, d0, id);
                        self.set_cell_raw(1, d1, id);
                    }
                    Some(slot) => {
                        let elements = [slot.0 as usize / 6, slot.1 as usize / 6, t];
                        return Err(BuildError::NonManifold { what: "edge", points: key.to_vec(), elements });
                    }
                }
            }
        }
        Ok(edges)
    }
}

impl<const N: usize> GMap<N> {
    /// Gives every dim-cell a sequential id by flood fill (ids must be unset, `NONE`).
    pub(crate) fn label_by_flood(&mut self, dim: usize) {
        let mask = AlphaMask::cell(N, dim);
        let mut next = 0u32;
        let mut stack = Vec::new();
        for d in 0..self.capacity() as u32 {
            if self.cell_id(dim, DartId(d)).0 == u32::MAX {
                self.flood_label(dim, DartId(d), mask, next, &mut stack);
                next += 1;
            }
        }
        self.set_id_alloc_raw(dim, next, Vec::new());
    }

    /// Labels the unlabelled orbit of d with `id`.
    fn flood_label(&mut self, dim: usize, d: DartId, mask: AlphaMask, id: u32, stack: &mut Vec<DartId>) {
        self.set_cell_raw(dim, d, id);
        stack.push(d);
        while let Some(x) = stack.pop() {
            for j in mask.indices().filter(|&j| j <= N) {
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
        let mut orbits_of = vec![0usize; points];
        let mut next = points as u32;
        let mut stack = Vec::new();
        for d in 0..self.capacity() as u32 {
            let d = DartId(d);
            if self.cell_id(0, d).0 != u32::MAX {
                continue;
            }
            let p = corner(d);
            let id = if orbits_of[p as usize] == 0 { p } else { (next, next += 1).0 };
            orbits_of[p as usize] += 1;
            self.flood_label(0, d, mask, id, &mut stack);
        }
        let unreferenced: Vec<u32> = (0..points as u32).filter(|&p| orbits_of[p as usize] == 0).collect();
        self.set_id_alloc_raw(0, next, unreferenced.clone());
        BuildReport {
            pinched_vertices: (0..points).filter(|&p| orbits_of[p] > 1).map(|p| (p as u32, orbits_of[p])).collect(),
            split_edges: Vec::new(),
            unreferenced_points: unreferenced,
        }
    }

    /// Point pairs carried by more than one edge orbit. O(edges log edges).
    fn split_edges(&self, corner: impl Fn(DartId) -> u32) -> Vec<([u32; 2], usize)> {
        let mut keys: Vec<(u64, u32)> = self
            .one_dart_per_cell(1)
            .into_iter()
            .map(|d| {
                let [a, b] = sorted([corner(d), corner(self.alpha_dyn(0, d))]);
                (((a as u64) << 32) | b as u64, 0)
            })
            .collect();
        keys.sort_unstable();
        let mut out: Vec<([u32; 2], usize)> = Vec::new();
        for w in keys.windows(2) {
            if w[0].0 == w[1].0 {
                let pair = [(w[0].0 >> 32) as u32, w[0].0 as u32];
                match out.last_mut() {
                    Some(last) if last.0 == pair => last.1 += 1,
                    _ => out.push((pair, 2)),
                }
            }
        }
        out
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

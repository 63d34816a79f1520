//! Tetrahedron 1→8 subdivision in 3-G-maps (seed 004, §4.3.3, §5.2).
//!
//! ```text
//!   corners a, b, c, d (labels 0..3); edge midpoints m_xy (labels 4..9)
//!   4 corner tets   {x, m_xy, m_xz, m_xw}, cut off by the triangles (m_xy, m_xz, m_xw)
//!   octahedron      the 6 midpoints, split into 4 tets around its shortest diagonal (D1, D2):
//!                   {D1, D2, X_k, X_k+1} for the equator cycle X_1..X_4 of the other midpoints
//! ```
//! The four faces are first split 1→4 ([`LeveledMap::subdivide_triangle`], reusing the splits a
//! neighbour already made), then 8 faces are inserted (4 corner cuts + 4 faces around the
//! diagonal), two sides each (α3-linked). Around every edge between two midpoints, each child tet
//! has exactly two of its faces; their darts are α2-linked, which replaces the α2 links the
//! boundary darts had across the inner edges of the split faces (recorded at the new level, so
//! the coarser levels keep them).

use super::tri::Side;
use super::{LeveledMap, Mu, SubdivideError};
use crate::gmap::{with_stamps, AlphaMask, DartId};
use rustc_hash::FxHashMap;

/// The six midpoint labels, as the pairs of corners of their edge (label = 4 + index).
const PAIRS: [(u8, u8); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// One side of a triangle face inside the tetrahedron: the child tet it bounds, its three
/// vertex labels and, per label, the dart of the side at that vertex on each of the two edges
/// of the triangle that meet there (`darts[k] = (dart on edge towards k+1, dart on edge from k−1)`).
#[derive(Clone, Debug)]
struct FaceSide {
    tet: usize,
    labels: [u8; 3],
    /// Vertex id at each of the three corners.
    vids: [u32; 3],
    /// `ends[k]`: the dart at vertex `labels[k]` on the edge from `labels[k]` to `labels[k+1]`,
    /// and the dart at vertex `labels[k+1]` on the same edge. `None` for a side of the boundary
    /// that is not a single edge (only possible on the outer half-edges, which are never relinked).
    ends: [Option<(DartId, DartId)>; 3],
}

/// The label of the midpoint of the edge between corners x and y.
pub(super) fn mid_label(x: u8, y: u8) -> u8 {
    let (x, y) = (x.min(y), x.max(y));
    4 + PAIRS.iter().position(|&p| p == (x, y)).expect("x ≠ y are corners 0..3") as u8
}

/// The label of the midpoint of the opposite edge.
fn opposite(m: u8) -> u8 {
    let (x, y) = PAIRS[(m - 4) as usize];
    let rest: Vec<u8> = (0..4).filter(|&z| z != x && z != y).collect();
    mid_label(rest[0], rest[1])
}

/// The eight child tets as label sets, for the chosen diagonal (a midpoint label and its
/// opposite): four corner tets, then four tets around the diagonal.
pub(super) fn child_tets(diag: u8) -> Vec<[u8; 4]> {
    let mut tets: Vec<[u8; 4]> = (0..4u8)
        .map(|x| {
            let others: Vec<u8> = (0..4).filter(|&y| y != x).map(|y| mid_label(x, y)).collect();
            [x, others[0], others[1], others[2]]
        })
        .collect();
    let (d1, d2) = (diag, opposite(diag));
    let q = (4..10).find(|&m| m != d1 && m != d2).expect("six midpoints");
    let r = (4..10).find(|&m| m != d1 && m != d2 && m != q && m != opposite(q)).expect("six midpoints");
    let cycle = [q, r, opposite(q), opposite(r)];
    for k in 0..4 {
        tets.push([d1, d2, cycle[k], cycle[(k + 1) % 4]]);
    }
    tets
}

/// Relative tolerance of the diagonal choice: a diagonal whose squared length is within this
/// fraction of its own of the shortest one ties with it.
pub(super) const DIAGONAL_TIE: f64 = 1e-12;

/// The midpoint label (4, 5 or 6) of the shortest of the three diagonals of the octahedron, from
/// the positions and vertex ids of the six midpoints (index = label − 4). The candidates are the
/// diagonals whose squared length ℓ is within [`DIAGONAL_TIE`] of the shortest one, m:
/// ℓ − m ≤ 1e-12 · ℓ (each compared with the minimum, never with each other, so the relation does
/// not depend on which diagonal is looked at first: finding 211); among them the one whose
/// endpoint positions are lexicographically smaller (smaller end first, then larger end) wins,
/// then the smaller pair of vertex ids. The squared lengths are functions of the two endpoints
/// alone (|p − q|² with a fixed coordinate order; p − q is −(q − p) exactly), so the choice is a
/// function of the six midpoints as a set of opposite pairs: every refinement path (op by op or
/// bulk, whatever order it numbers the corners and midpoints in) makes the same choice; ids only
/// decide between coincident midpoints. Lengths are plain `f64` when every squared length is
/// finite and ≥ 2⁻⁹⁰⁰, else wide floats (no over- or underflow at any scale). O(1).
pub(super) fn choose_diagonal(pos: &[[f64; 3]; 6], vid: &[u32; 6]) -> u8 {
    let ends = |l: u8| ((l - 4) as usize, (opposite(l) - 4) as usize);
    let plain = [4u8, 5, 6].map(|l| {
        let (i, j) = ends(l);
        let d = [0, 1, 2].map(|k| pos[i][k] - pos[j][k]);
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    });
    // Relative sizes: the plain squared lengths, or (out of their safe range) the wide ones
    // divided by the shortest; a zero shortest length ties only with zeros.
    let rel = if plain.iter().all(|&x| x.is_finite() && x >= SMALLEST_PLAIN_LEN2) {
        plain
    } else {
        wide_relative_lengths(pos, ends)
    };
    let shortest = rel.iter().copied().filter(|x| !x.is_nan()).fold(f64::INFINITY, f64::min);
    if shortest.is_infinite() && !rel.contains(&shortest) {
        return 4; // every length NaN
    }
    let candidate = |x: f64| x == shortest || (x.is_finite() && x - shortest <= DIAGONAL_TIE * x);
    let key = |l: u8| {
        let (i, j) = ends(l);
        let (p, q) = (pos[i], pos[j]);
        let (lo, hi) = if lex_less(q, p) { (q, p) } else { (p, q) };
        (lo, hi, vid[i].min(vid[j]), vid[i].max(vid[j]))
    };
    let less = |a: &([f64; 3], [f64; 3], u32, u32), b: &([f64; 3], [f64; 3], u32, u32)| {
        if a.0 != b.0 {
            return lex_less(a.0, b.0);
        }
        if a.1 != b.1 {
            return lex_less(a.1, b.1);
        }
        (a.2, a.3) < (b.2, b.3)
    };
    let mut best: Option<u8> = None;
    for l in [4u8, 5, 6] {
        if !candidate(rel[(l - 4) as usize]) {
            continue;
        }
        best = match best {
            Some(b) if !less(&key(l), &key(b)) => Some(b),
            _ => Some(l),
        };
    }
    best.unwrap_or(4)
}

/// 2⁻⁹⁰⁰: a plain squared length at least this large lost nothing that matters to underflow
/// (an underflowed square is below 2⁻¹²² of it).
const SMALLEST_PLAIN_LEN2: f64 = 1.1830521861667747e-271;

/// The squared lengths of the three diagonals in wide floats, divided by the shortest (so the
/// shortest is 1): for midpoints whose plain squared lengths over- or underflow. A zero shortest
/// length gives 0 for the zero ones and ∞ for the others; NaN stays NaN. O(1).
fn wide_relative_lengths(pos: &[[f64; 3]; 6], ends: impl Fn(u8) -> (usize, usize)) -> [f64; 3] {
    use crate::wide::{difference, dot};
    let len2 = [4u8, 5, 6].map(|l| {
        let (i, j) = ends(l);
        let d = difference(pos[i], pos[j]);
        dot(d, d)
    });
    let mut shortest = None;
    for &x in &len2 {
        if x.to_f64().is_nan() {
            continue;
        }
        shortest = match shortest {
            Some(s) if !x.less_than(s) => Some(s),
            _ => Some(x),
        };
    }
    let Some(shortest) = shortest else { return [f64::NAN; 3] };
    if shortest.is_zero() {
        return len2.map(|x| {
            if x.is_zero() {
                0.0
            } else if x.to_f64().is_nan() {
                f64::NAN
            } else {
                f64::INFINITY
            }
        });
    }
    len2.map(|x| x.div(shortest).to_f64())
}

/// Lexicographic order of two points (NaN coordinates compare as equal).
fn lex_less(a: [f64; 3], b: [f64; 3]) -> bool {
    for k in 0..3 {
        match a[k].partial_cmp(&b[k]) {
            Some(std::cmp::Ordering::Less) => return true,
            Some(std::cmp::Ordering::Greater) => return false,
            _ => {}
        }
    }
    false
}

impl LeveledMap<3> {
    /// Subdivides the tetrahedron of `d` into eight at level `level` (the paper's tetrahedron
    /// subdivision, §4.3.3): its four faces are split 1→4 (faces a neighbour already split are
    /// reused), then four corner tets are cut off by the triangles joining the three edge
    /// midpoints at each corner, and the inner octahedron is split into four tets around its
    /// shortest diagonal (ties broken by the midpoint positions, then by vertex ids). The 8 children take μt = level;
    /// their faces and edges take μf, μa ≥ level (the corollary μt ≤ μf ≤ μa). Returns one dart of
    /// each child: the corner tets (in the order of the corners found), then the four around the
    /// diagonal. Cost O(volume + touched cells).
    ///
    /// Errors: [`SubdivideError::NoSuchDart`], the level-order errors,
    /// [`SubdivideError::AlreadyAtLevel`] (μt(d) ≥ level), [`SubdivideError::OpenEdge`] (a dart
    /// of the volume is α0-, α1- or α2-free), [`SubdivideError::NotATetrahedron`] (the volume at
    /// its own level μt is not a tetrahedron), [`SubdivideError::FaceRefinedTooFar`] (a face of the
    /// volume was refined beyond one 1→4 step or an inner edge of a split face carries a vertex;
    /// not supported yet), [`SubdivideError::NonFinitePosition`] (an end of an edge to
    /// split at a NaN or infinite position), [`SubdivideError::BelowPrecision`] (an edge to split whose midpoint
    /// f64 cannot hold strictly between its ends). The map is unchanged on error.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// let children = m.subdivide_tet(d, 1).unwrap();
    /// assert_eq!(m.map().count_cells().0[3], 8);
    /// assert!(children.iter().all(|&c| m.mu(c).tet == 1));
    /// assert!(m.subdivide_tet(children[0], 1).is_err()); // already at level 1
    /// ```
    pub fn subdivide_tet(&mut self, d: DartId, level: u8) -> Result<[DartId; 8], SubdivideError> {
        self.check_op_level(level)?;
        if !self.map.contains(d) {
            return Err(SubdivideError::NoSuchDart(d));
        }
        let cell_level = self.mu[d.index()].tet;
        if cell_level >= level {
            return Err(SubdivideError::AlreadyAtLevel { dart: d, dim: 3, cell_level, level });
        }
        let corners = self.tet_corners(d, cell_level)?;
        let unsplit = self.check_tet_faces(d, &corners)?;
        // The face splits below must all succeed: an unsplit face already at the level is refused
        // here, before any change (found by the spring-coupling proptest: the map was left with
        // some faces split).
        if let Some(&f) = unsplit.iter().find(|f| self.mu[f.index()].face >= level) {
            let cell_level = self.mu[f.index()].face;
            return Err(SubdivideError::AlreadyAtLevel { dart: f, dim: 2, cell_level, level });
        }
        self.check_split_midpoints(&unsplit, level)?;
        self.check_children(d, level, &corners)?;
        let version = self.version;
        for f in unsplit {
            self.subdivide_triangle(f, level)?;
        }
        self.begin_growth(level);
        let children = self.insert_inner_faces(d, &corners);
        for &c in &children {
            self.set_tet_levels(c, level);
        }
        self.finish();
        // One operation, one version (finding 294): the face splits above counted themselves.
        self.version = version + 1;
        Ok(children)
    }

    /// [`SubdivideError::BelowPrecision`] for the first edge the 1→8 split would split — a side
    /// without inserted vertex of one of its `unsplit` faces (checked triangles) — whose midpoint
    /// f64 cannot hold strictly between its ends. O(faces).
    pub(super) fn check_split_midpoints(&self, unsplit: &[DartId], level: u8) -> Result<(), SubdivideError> {
        for &f in unsplit {
            self.check_side_midpoints(&self.triangle_sides(f)?, level)?;
        }
        Ok(())
    }

    /// The vertex ids of the four corners of the volume of `d` at its own level `lt`: the
    /// vertices with three faces around them inside the volume of G_lt (flat vertices have two).
    pub(super) fn tet_corners(&self, d: DartId, lt: u8) -> Result<[u32; 4], SubdivideError> {
        let volume = self.map.orbit(d, AlphaMask::of(&[0, 1, 2]));
        if let Some(&x) = volume.iter().find(|&&x| (0..3).any(|j| self.map.is_free(j, x))) {
            return Err(SubdivideError::OpenEdge(x));
        }
        let start = volume.iter().copied().find(|x| self.dart_level[x.index()] <= lt);
        let start = start.ok_or(SubdivideError::NotATetrahedron { dart: d, corners: 0 })?;
        let coarse = self.orbit_at(lt, 3, start);
        let mut corners: Vec<u32> = Vec::new();
        for &x in &coarse {
            let mut y = x;
            let mut len = 0;
            // The ⟨α1, α2⟩ orbit of a closed surface is a cycle of 2 × (faces around).
            loop {
                y = self.alpha_at(lt, 1, y);
                y = self.alpha_at(lt, 2, y);
                len += 2;
                if y == x || len > coarse.len() {
                    break;
                }
            }
            let v = self.map.vertex_id(x).0;
            if len == 6 && !corners.contains(&v) {
                corners.push(v);
            }
        }
        match <[u32; 4]>::try_from(corners.as_slice()) {
            Ok(c) => Ok(c),
            Err(_) => Err(SubdivideError::NotATetrahedron { dart: d, corners: corners.len() }),
        }
    }

    /// Checks that every face of the volume of `d` is a triangle that is either unsplit (three
    /// tet corners) or a child of one 1→4 split whose inner sides are single edges, and returns
    /// one dart of each unsplit face.
    fn check_tet_faces(&self, d: DartId, corners: &[u32; 4]) -> Result<Vec<DartId>, SubdivideError> {
        self.check_tet_faces_visiting(d, corners, |_, _| {})
    }

    /// [`Self::check_tet_faces`], calling `visit(sides, is_corner)` with the sides of each face
    /// that passed its own checks and whether each side starts at a corner (the zone pre-check
    /// of `refine_around` reads the midpoints there). O(volume).
    pub(super) fn check_tet_faces_visiting(
        &self,
        d: DartId,
        corners: &[u32; 4],
        mut visit: impl FnMut(&[Side], &[bool]),
    ) -> Result<Vec<DartId>, SubdivideError> {
        let mut unsplit = Vec::new();
        let (mut corner_children, mut centers) = (0usize, 0usize);
        for f in self.volume_faces(d) {
            let sides = self.triangle_sides(f).map_err(|_| SubdivideError::FaceRefinedTooFar { dart: f })?;
            self.check_not_self_glued(f)?;
            let is_corner: Vec<bool> = sides.iter().map(|s| corners.contains(&self.map.vertex_id(s.start).0)).collect();
            match is_corner.iter().filter(|&&c| c).count() {
                3 => unsplit.push(f),
                1 => corner_children += 1,
                0 => centers += 1,
                _ => return Err(SubdivideError::FaceRefinedTooFar { dart: f }),
            }
            for k in 0..3 {
                let inner = !is_corner[k] && !is_corner[(k + 1) % 3];
                if inner && !sides[k].flats.is_empty() {
                    return Err(SubdivideError::FaceRefinedTooFar { dart: f });
                }
            }
            visit(&sides, &is_corner);
        }
        let split = 4 - unsplit.len().min(4);
        if unsplit.len() > 4 || corner_children != 3 * split || centers != split {
            return Err(SubdivideError::FaceRefinedTooFar { dart: d });
        }
        Ok(unsplit)
    }

    /// One dart of each face side (⟨α0, α1⟩ orbit) of the volume of `d`: the first of the side
    /// in the breadth-first order of the volume. O(volume); the face sides are walked as α0/α1
    /// cycles and marked in the thread's epoch stamps (no hashing).
    fn volume_faces(&self, d: DartId) -> Vec<DartId> {
        // Walked before taking the stamps: a large orbit walk takes them too.
        let volume = self.map.orbit(d, AlphaMask::of(&[0, 1, 2]));
        with_stamps(|stamps| {
            let tag = stamps.fresh(self.map.capacity(), 1);
            let mut faces = Vec::new();
            for x in volume {
                if stamps.has(x.0, tag) {
                    continue;
                }
                self.map.for_each_dihedral(x, 0, 1, |y| stamps.mark(y.0, tag));
                faces.push(x);
            }
            faces
        })
    }

    /// Builds the 8 children once the four faces are split: labels the vertices, creates the 8
    /// inner faces and α2-links, around every edge between two midpoints, the two faces of each
    /// child tet. Returns one dart per child.
    fn insert_inner_faces(&mut self, d: DartId, corners: &[u32; 4]) -> [DartId; 8] {
        let mut sides = self.boundary_face_sides(d, corners);
        let label_vid = Self::midpoint_vertices(&mut sides, corners);
        let tets = child_tets(self.shortest_diagonal(&label_vid));
        for side in &mut sides {
            side.tet = tets.iter().position(|t| side.labels.iter().all(|l| t.contains(l))).expect("a child");
        }
        let level = self.op_level();
        let mu = Mu { edge: level, face: level, tet: level };
        let inner: Vec<[u8; 3]> = (0..4u8)
            .map(|x| {
                let m: Vec<u8> = (0..4).filter(|&y| y != x).map(|y| mid_label(x, y)).collect();
                [m[0], m[1], m[2]]
            })
            .chain((4..8).map(|k| [tets[k][0], tets[k][1], tets[k][2]]))
            .collect();
        for labels in inner {
            let owners: Vec<usize> = (0..8).filter(|&t| labels.iter().all(|l| tets[t].contains(l))).collect();
            debug_assert_eq!(owners.len(), 2, "an inner face bounds two children");
            let darts = self.new_triangle(mu);
            for (s, &t) in owners.iter().enumerate() {
                let ends = [0, 1, 2].map(|k| Some((darts[s][2 * k], darts[s][2 * k + 1])));
                sides.push(FaceSide { tet: t, labels, vids: [u32::MAX; 3], ends });
            }
        }
        self.link_children(&sides, &tets);
        let mut out = [d; 8];
        for (t, slot) in out.iter_mut().enumerate() {
            let s = sides.iter().find(|s| s.tet == t).expect("every child has faces");
            *slot = s.ends.iter().flatten().next().expect("a face side has a single edge").0;
        }
        out
    }

    /// The face sides of the volume of `d` (all triangles after the 1→4 step), with labels:
    /// corners 0..3, midpoints 4 + pair index (filled in by [`Self::midpoint_vertices`]).
    fn boundary_face_sides(&self, d: DartId, corners: &[u32; 4]) -> Vec<FaceSide> {
        let mut out = Vec::new();
        for f in self.volume_faces(d) {
            let sides = self.triangle_sides(f).expect("checked: every face is a triangle");
            // Labels: the corner index, or u8::MAX for a midpoint (resolved later).
            let labels = [0, 1, 2].map(|k| {
                let v = self.map.vertex_id(sides[k].start).0;
                corners.iter().position(|&c| c == v).map_or(u8::MAX, |c| c as u8)
            });
            let ends = [0, 1, 2].map(|k| {
                let s = &sides[k];
                s.flats.is_empty().then(|| (s.start, self.map.alpha_dyn(0, s.start)))
            });
            let vids = [0, 1, 2].map(|k| self.map.vertex_id(sides[k].start).0);
            out.push(FaceSide { tet: usize::MAX, labels, vids, ends });
        }
        out
    }

    /// Labels every midpoint vertex by the pair of corners of the corner children it belongs to,
    /// rewrites the face labels, and returns the vertex id of each midpoint label (index = label − 4).
    fn midpoint_vertices(sides: &mut [FaceSide], corners: &[u32; 4]) -> [u32; 6] {
        let mut pair_of: FxHashMap<u32, u8> = FxHashMap::default();
        for s in sides.iter() {
            if let Some(k) = s.labels.iter().position(|&l| l != u8::MAX) {
                if s.labels.iter().filter(|&&l| l != u8::MAX).count() != 1 {
                    continue;
                }
                for m in 0..3 {
                    if m != k {
                        let v = s.vids[m];
                        *pair_of.entry(v).or_insert(0) |= 1 << s.labels[k];
                    }
                }
            }
        }
        let mut vid = [u32::MAX; 6];
        for (&v, &mask) in &pair_of {
            let (x, y) = (mask.trailing_zeros() as u8, 7 - mask.leading_zeros() as u8);
            assert!(mask.count_ones() == 2, "subdivide bug: midpoint {v} in corner children {mask:#b}");
            vid[(mid_label(x, y) - 4) as usize] = v;
        }
        assert!(vid.iter().all(|&v| v != u32::MAX), "subdivide bug: missing midpoint of {corners:?}");
        for s in sides.iter_mut() {
            for m in 0..3 {
                if s.labels[m] == u8::MAX {
                    let v = s.vids[m];
                    s.labels[m] = 4 + vid.iter().position(|&w| w == v).expect("labelled") as u8;
                }
            }
        }
        vid
    }

    /// The midpoint label of the shortest diagonal of the octahedron ([`choose_diagonal`]).
    fn shortest_diagonal(&self, vid: &[u32; 6]) -> u8 {
        let pos = vid.map(|v| self.points.get(v as usize).copied().unwrap_or([0.0; 3]));
        choose_diagonal(&pos, vid)
    }

    /// Creates a triangle face with two sides (12 darts, α0, α1 and α3 linked). Returns the darts
    /// of each side in edge order: `[e0 start, e0 end, e1 start, e1 end, e2 start, e2 end]`.
    fn new_triangle(&mut self, mu: Mu) -> [[DartId; 6]; 2] {
        let darts = [(); 2].map(|_| [(); 6].map(|_| self.new_dart(mu, false)));
        for side in &darts {
            for k in 0..3 {
                self.link(0, side[2 * k], side[2 * k + 1]);
                self.link(1, side[2 * k + 1], side[(2 * k + 2) % 6]);
            }
        }
        for (&x, &y) in darts[0].iter().zip(&darts[1]) {
            self.link(3, x, y);
        }
        darts
    }

    /// α2-links, for every child and every edge of it between two midpoints, the darts of the two
    /// faces of the child along that edge.
    fn link_children(&mut self, sides: &[FaceSide], tets: &[[u8; 4]]) {
        for (t, labels) in tets.iter().enumerate() {
            let mids: Vec<u8> = labels.iter().copied().filter(|&l| l >= 4).collect();
            for a in 0..mids.len() {
                for b in a + 1..mids.len() {
                    let (p, q) = (mids[a], mids[b]);
                    let at: Vec<(DartId, DartId)> =
                        sides.iter().filter(|s| s.tet == t).filter_map(|s| Self::edge_darts(s, p, q)).collect();
                    assert_eq!(at.len(), 2, "subdivide bug: child {t} has {} faces on edge ({p}, {q})", at.len());
                    self.link(2, at[0].0, at[1].0);
                    self.link(2, at[0].1, at[1].1);
                }
            }
        }
    }

    /// The darts of a face side on its edge between labels p and q: (dart at p, dart at q).
    fn edge_darts(s: &FaceSide, p: u8, q: u8) -> Option<(DartId, DartId)> {
        (0..3).find_map(|k| {
            let (u, v) = (s.labels[k], s.labels[(k + 1) % 3]);
            let (x, y) = s.ends[k]?;
            if (u, v) == (p, q) {
                Some((x, y))
            } else if (u, v) == (q, p) {
                Some((y, x))
            } else {
                None
            }
        })
    }

    /// μt = level on the child volume of `c`; μf and μa raised to at least `level` on its faces
    /// and edges (both sides), so μt ≤ μf ≤ μa holds. O(volume · face).
    /// The raises are idempotent (max), so each face and edge orbit is walked once, with the
    /// scratch epoch sets as visited sets (no hashing, no allocation per orbit).
    fn set_tet_levels(&mut self, c: DartId, level: u8) {
        let mut s = std::mem::take(self.scratch());
        let (mut faces, mut edges) = (std::mem::take(&mut s.buf), std::mem::take(&mut s.buf2));
        s.seen.clear();
        s.seen2.clear();
        for x in self.map.orbit(c, AlphaMask::of(&[0, 1, 2])) {
            self.mu[x.index()].tet = level;
            if s.seen.contains(x.0) {
                continue;
            }
            self.walk_orbit(x, AlphaMask::cell(3, 2), &mut s.seen, &mut faces);
            for &y in &faces {
                self.mu[y.index()].face = self.mu[y.index()].face.max(level);
                if s.seen2.contains(y.0) || self.mu[y.index()].edge >= level {
                    continue; // μa is one value per edge: nothing to raise (finding 248)
                }
                self.walk_orbit(y, AlphaMask::cell(3, 1), &mut s.seen2, &mut edges);
                for &z in &edges {
                    self.mu[z.index()].edge = self.mu[z.index()].edge.max(level);
                }
            }
        }
        (s.buf, s.buf2) = (faces, edges);
        *self.scratch() = s;
    }
}

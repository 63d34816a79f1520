//! Edge subdivision (any dimension) and triangle 1→4 subdivision in 2-G-maps (seed 004, §4.3.1,
//! §4.3.2, §5.1).
//!
//! ```text
//!            c2                         c2
//!           /  \                       /  \
//!          /    \                   m20 -- m12
//!         /      \      1→4         / \    / \
//!        /        \    ─────►      /   \  /   \
//!      c0 -------- c1            c0 -- m01 --- c1
//! ```
//! A side that a neighbour already split keeps its midpoint (the inserted vertex of lowest dart
//! level on that side); the others are split now, which also splits the neighbour's edge (its
//! face then has an inserted *flat* vertex and keeps its face level).

use super::{LeveledMap, Mu, SubdivideError};
use crate::gmap::{AlphaMask, DartId};

/// Whether the rounded midpoint m of `a` and `b` (`mesh::midpoint`, as stored for a new vertex)
/// lies strictly between them along some axis k: min(a_k, b_k) < m_k < max(a_k, b_k), so m ≠ a
/// and m ≠ b (in the other coordinates m is within [min, max] by rounding, and may equal an end:
/// a long edge whose ends differ by one ulp across is fine). False for a = b, and for an edge
/// one ulp long along every axis where its ends differ: halving an edge of length ℓ at
/// coordinates of size |x| works about 52 − log2(|x| / ℓ) times (the mantissa has 52 bits);
/// past that, midpoints land on an end and tets collapse. Any axis, not only the one where the
/// ends differ most: that one was chosen by axis order on ties, so an edge and its mirror
/// image could be decided differently (round 26). O(1).
pub(super) fn midpoint_between(a: [f64; 3], b: [f64; 3]) -> bool {
    let m = crate::mesh::midpoint(a, b);
    (0..3).any(|k| a[k].min(b[k]) < m[k] && m[k] < a[k].max(b[k]))
}

/// One side of a triangle face: the corner dart it starts from and its inserted (flat) vertices
/// in order, each as (dart on the incoming half, dart on the outgoing half).
#[derive(Clone, Debug)]
pub(super) struct Side {
    pub(super) start: DartId,
    pub(super) flats: Vec<(DartId, DartId)>,
}

impl<const N: usize> LeveledMap<N> {
    /// Inserts a vertex in the middle of the edge of `d` at level `level` (the paper's
    /// `subdividedge`). Every dart x of the edge gets a new dart x' with α0^level(x) = x'; the
    /// new darts are α1-linked pairwise at the new vertex and αj-linked (j ≥ 2) like their
    /// partners. All darts of the two halves take μa = level. Returns α0(d) afterwards.
    /// O(edge · (n + log edge)): each dart's new partner is found in the orbit sorted once; the
    /// relabelling at the end walks the edge's cells, not its end vertices (finding 248).
    ///
    /// Errors: [`SubdivideError::NoSuchDart`], [`SubdivideError::OpenEdge`],
    /// [`SubdivideError::AlreadyAtLevel`] (μa(d) ≥ level), [`SubdivideError::NonFinitePosition`] (an end of an edge to
    /// split at a NaN or infinite position), [`SubdivideError::BelowPrecision`]
    /// (the rounded midpoint of the edge's end positions is not strictly between them),
    /// the level-order errors. The map is unchanged on error.
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
    /// let old = m.map().alpha_dyn(0, d);
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.map().alpha_dyn(0, d), mid);
    /// assert!(m.split_edge(d, 1).is_err()); // that half already has μa = 1
    /// assert_eq!(m.alpha_at(0, 0, d), old);
    /// ```
    pub fn split_edge(&mut self, d: DartId, level: u8) -> Result<DartId, SubdivideError> {
        self.check_op_level(level)?;
        self.check_edge(d, level)?;
        self.check_midpoint(d, level)?;
        self.begin_growth(level);
        let m = self.split_edge_raw(d);
        self.finish();
        Ok(m)
    }

    fn check_edge(&self, d: DartId, level: u8) -> Result<(), SubdivideError> {
        if !self.map.contains(d) {
            return Err(SubdivideError::NoSuchDart(d));
        }
        if let Some(x) = self.map.orbit(d, AlphaMask::cell(N, 1)).into_iter().find(|&x| self.map.is_free(0, x)) {
            return Err(SubdivideError::OpenEdge(x));
        }
        let cell_level = self.mu[d.index()].edge;
        if cell_level >= level {
            return Err(SubdivideError::AlreadyAtLevel { dart: d, dim: 1, cell_level, level });
        }
        Ok(())
    }

    /// [`SubdivideError::NonFinitePosition`] when an end of the edge of `d` (closed) has a NaN
    /// or infinite position (its midpoint would be one too: round 27, the single operations made
    /// such vertices), [`SubdivideError::BelowPrecision`] when the rounded midpoint of the two
    /// is not strictly between them ([`midpoint_between`]). Nothing is checked without both
    /// positions (a map without points). O(1).
    pub(super) fn check_midpoint(&self, d: DartId, level: u8) -> Result<(), SubdivideError> {
        let vertices = [d, self.map.alpha_dyn(0, d)].map(|x| self.map.vertex_id(x).0);
        let [Some(&a), Some(&b)] = vertices.map(|v| self.points.get(v as usize)) else { return Ok(()) };
        for (vertex, position) in vertices.into_iter().zip([a, b]) {
            if !position.iter().all(|c| c.is_finite()) {
                return Err(SubdivideError::NonFinitePosition { vertex, position });
            }
        }
        if midpoint_between(a, b) {
            return Ok(());
        }
        Err(SubdivideError::BelowPrecision { level, dart: d, vertices, positions: [a, b] })
    }

    /// [`Self::check_midpoint`] on every side of a triangle that its 1→4 split splits (the sides
    /// without an inserted vertex). O(sides).
    pub(super) fn check_side_midpoints(&self, sides: &[Side], level: u8) -> Result<(), SubdivideError> {
        for s in sides.iter().filter(|s| s.flats.is_empty()) {
            self.check_midpoint(s.start, level)?;
        }
        Ok(())
    }

    /// [`SubdivideError::FlatTriangleChild`] for the 1→4 split of the triangle of `d` with sides
    /// `sides`: corners at the sides' starts, a side's midpoint at its oldest inserted vertex
    /// (the one the split keeps) or, without one, the rounded midpoint it will insert. O(sides).
    fn check_split_triangle(&self, d: DartId, level: u8, sides: &[Side]) -> Result<(), SubdivideError> {
        let corners: [u32; 3] = std::array::from_fn(|k| self.map.vertex_id(sides[k].start).0);
        let mids = std::array::from_fn(|k| {
            let kept = self.kept_midpoint(&sides[k]);
            kept.and_then(|(a, _)| self.points.get(self.map.vertex_id(a).0 as usize).copied())
        });
        self.check_triangle_children(d, level, corners, mids)
    }

    /// The topology of [`Self::split_edge`] inside a running operation. The edge must be closed.
    pub(super) fn split_edge_raw(&mut self, d: DartId) -> DartId {
        let level = self.op_level();
        let edge = self.map.orbit(d, AlphaMask::cell(N, 1));
        let ends: Vec<DartId> = edge.iter().map(|&x| self.map.alpha_dyn(0, x)).collect();
        let fresh: Vec<DartId> = edge
            .iter()
            .map(|&x| {
                let mu = self.mu[x.index()];
                self.new_dart(Mu { edge: level, ..mu }, true)
            })
            .collect();
        // x ↦ x': the orbit indexed once, sorted by dart (a linear search per dart made a split
        // O(edge² · n): 44 s for one tet beside an edge of valence 50 000, round 25 B).
        let mut index: Vec<(DartId, usize)> = edge.iter().copied().zip(0..).collect();
        index.sort_unstable();
        let prime = |x: DartId| {
            let k = index.binary_search_by_key(&x, |&(e, _)| e).expect("edge orbit is closed");
            fresh[index[k].1]
        };
        for k in 0..edge.len() {
            self.link(0, edge[k], fresh[k]);
        }
        for k in 0..edge.len() {
            self.link(1, fresh[k], prime(ends[k]));
            for j in 2..=N {
                let other = self.map.alpha_dyn(j, edge[k]);
                self.link(j, fresh[k], prime(other));
            }
        }
        for &x in &edge {
            self.mu[x.index()].edge = level;
        }
        let m = prime(d);
        self.note_midpoint(m, d, ends[0]);
        m
    }
}

impl<const N: usize> LeveledMap<N> {
    /// Subdivides the triangle face of `d` into four at level `level` (the paper's triangle
    /// subdivision; in a 3-G-map the face is split on both of its sides, so the α3-adjacent
    /// volume sees the same four faces): its three sides are split at their midpoints (existing inserted vertices
    /// are reused) and three edges are inserted between the midpoints. Every dart of the four
    /// children takes μf = level; their edges and the α2-adjacent halves take μa = level.
    /// Returns one dart of each child: the corner triangles at the three corners, then the
    /// central one. O(face + touched cells).
    ///
    /// Errors: [`SubdivideError::WrongDimension`] (n ∉ {2, 3}), [`SubdivideError::NoSuchDart`],
    /// [`SubdivideError::AlreadyAtLevel`] (μf(d) ≥ level), [`SubdivideError::NotATriangle`],
    /// [`SubdivideError::OpenEdge`], [`SubdivideError::NonFinitePosition`] (an end of an edge to
    /// split at a NaN or infinite position), [`SubdivideError::BelowPrecision`] (a side to split whose
    /// midpoint f64 cannot hold strictly between its ends), in a 2-G-map
    /// [`SubdivideError::FlatTriangleChild`] (a triangle so nearly collinear at its scale that,
    /// its midpoints placed, a child would be collinear or inverted; `orient.rs`), the
    /// level-order errors. The map is unchanged on error.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let children = m.subdivide_triangle(d, 1).unwrap();
    /// assert_eq!(children.len(), 4);
    /// assert_eq!(m.map().count_cells().0, vec![6, 9, 4]);
    /// assert!(m.check_all().is_ok());
    /// ```
    pub fn subdivide_triangle(&mut self, d: DartId, level: u8) -> Result<[DartId; 4], SubdivideError> {
        if !(2..=3).contains(&N) {
            return Err(SubdivideError::WrongDimension(N));
        }
        self.check_op_level(level)?;
        if !self.map.contains(d) {
            return Err(SubdivideError::NoSuchDart(d));
        }
        let cell_level = self.mu[d.index()].face;
        if cell_level >= level {
            return Err(SubdivideError::AlreadyAtLevel { dart: d, dim: 2, cell_level, level });
        }
        let sides = self.triangle_sides(d)?;
        if let Some(s) = sides.iter().find(|s| self.map.is_free(0, s.start)) {
            return Err(SubdivideError::OpenEdge(s.start));
        }
        self.check_not_self_glued(d)?;
        self.check_side_midpoints(&sides, level)?;
        if N == 2 {
            self.check_split_triangle(d, level, &sides)?;
        }
        self.begin_growth(level);
        let mids: Vec<(DartId, DartId)> = sides.iter().map(|s| self.side_midpoint(s)).collect();
        let (m_in, m_out): (Vec<DartId>, Vec<DartId>) = mids.into_iter().unzip();
        self.insert_edge_2d(m_in[0], m_out[2]);
        self.insert_edge_2d(m_out[0], m_in[1]);
        let (e, f) = self.insert_edge_2d(m_out[1], m_in[2]);
        let center = if self.map.same_orbit(f, sides[2].start, AlphaMask::of(&[0, 1])) { e } else { f };
        // The midpoints are corners of the children on both sides of the face (in 3D the
        // α3-mirror darts at the midpoints were created flat too).
        for &x in m_in.iter().chain(&m_out) {
            self.flat[x.index()] = false;
            if N >= 3 {
                let y = self.map.alpha_dyn(3, x);
                self.flat[y.index()] = false;
            }
        }
        let children = [sides[0].start, sides[1].start, sides[2].start, center];
        for c in children {
            self.set_child_levels(c, level);
        }
        self.finish();
        Ok(children)
    }

    /// Refuses a face sewn onto itself ([`SubdivideError::SelfGluedFace`]): a dart x of the
    /// face of `d` whose αj (j ≥ 2) is in the same face — two of its sides glued (a cone), or
    /// the face folded onto itself by α3. The split walks each side once and would split a
    /// glued side twice (then the flat law broke) or never end (finding 270). O(face²), the face
    /// having a handful of darts.
    pub(super) fn check_not_self_glued(&self, d: DartId) -> Result<(), SubdivideError> {
        let face = self.map.orbit(d, AlphaMask::of(&[0, 1]));
        for &x in &face {
            for j in 2..=N {
                if !self.map.is_free(j, x) && face.contains(&self.map.alpha_dyn(j, x)) {
                    return Err(SubdivideError::SelfGluedFace { dart: x, alpha: j });
                }
            }
        }
        Ok(())
    }

    /// The three sides of the triangle face of `d`, from a corner. O(face).
    pub(super) fn triangle_sides(&self, d: DartId) -> Result<Vec<Side>, SubdivideError> {
        let face = self.map.orbit(d, AlphaMask::of(&[0, 1]));
        let corner = face.iter().copied().find(|&x| !self.flat[x.index()]);
        let corner = corner.ok_or(SubdivideError::NotATriangle { dart: d, corners: 0 })?;
        let mut sides = Vec::new();
        let mut x = corner;
        let mut current = Side { start: x, flats: Vec::new() };
        // Each step crosses one edge; the face has face.len() / 2 edges at most.
        for _ in 0..face.len() {
            let y = self.map.alpha_dyn(0, x);
            let z = self.map.alpha_dyn(1, y);
            if self.flat[y.index()] {
                current.flats.push((y, z));
            } else {
                sides.push(std::mem::replace(&mut current, Side { start: z, flats: Vec::new() }));
            }
            x = z;
            if x == corner {
                break;
            }
        }
        if sides.len() != 3 {
            return Err(SubdivideError::NotATriangle { dart: d, corners: sides.len() });
        }
        Ok(sides)
    }

    /// The inserted vertex of a side that a 1→4 split keeps as its midpoint: the oldest (lowest
    /// dart level), as its two darts (incoming half, outgoing half); `None` on an unsplit side.
    /// O(side).
    fn kept_midpoint(&self, side: &Side) -> Option<(DartId, DartId)> {
        side.flats.iter().min_by_key(|(a, _)| self.dart_level[a.index()]).copied()
    }

    /// The two darts of the face at the midpoint of a side (incoming half, outgoing half),
    /// splitting the side now if nobody split it before.
    fn side_midpoint(&mut self, side: &Side) -> (DartId, DartId) {
        match self.kept_midpoint(side) {
            Some(pair) => pair,
            None => {
                let m = self.split_edge_raw(side.start);
                (m, self.map.alpha_dyn(1, m))
            }
        }
    }

    /// Inserts an edge in the face of `a` and `b` between their vertices (α1(a) and α1(b) are
    /// separated), splitting the face in two. Returns the two new darts at the vertex of `a`, one
    /// in each of the two faces. O(face).
    fn insert_edge_2d(&mut self, a: DartId, b: DartId) -> (DartId, DartId) {
        let (a1, b1) = (self.map.alpha_dyn(1, a), self.map.alpha_dyn(1, b));
        let mut x = a1;
        let end = loop {
            x = self.map.alpha_dyn(0, x);
            if x == b || x == b1 {
                break x;
            }
            x = self.map.alpha_dyn(1, x);
        };
        let other = if end == b { b1 } else { b };
        let level = self.op_level();
        let mu = Mu { edge: level, face: level, tet: self.mu[a.index()].tet };
        let [e1, e2, f1, f2] = [(); 4].map(|_| self.new_dart(mu, false));
        self.link(0, e1, e2);
        self.link(0, f1, f2);
        self.link(2, e1, f1);
        self.link(2, e2, f2);
        self.link(1, a1, e1);
        self.link(1, end, e2);
        self.link(1, a, f1);
        self.link(1, other, f2);
        if N >= 3 && !self.map.is_free(3, a) {
            let tet = self.mu[self.map.alpha_dyn(3, a).index()].tet;
            let mirror = [(); 4].map(|_| self.new_dart(Mu { tet, ..mu }, false));
            for (k, x) in [e1, e2, f1, f2].into_iter().enumerate() {
                self.link(3, x, mirror[k]);
            }
            let [e1m, e2m, f1m, f2m] = mirror;
            self.link(0, e1m, e2m);
            self.link(0, f1m, f2m);
            self.link(2, e1m, f1m);
            self.link(2, e2m, f2m);
            let side = [a1, end, a, other].map(|x| self.map.alpha_dyn(3, x));
            self.link(1, side[0], e1m);
            self.link(1, side[1], e2m);
            self.link(1, side[2], f1m);
            self.link(1, side[3], f2m);
        }
        (e1, f1)
    }

    /// μf = level on the face of `c`, μa = level on its edges (both sides). O(face).
    fn set_child_levels(&mut self, c: DartId, level: u8) {
        // The assignments are idempotent, so each edge orbit is walked once (scratch epoch sets
        // as visited sets: no hashing, no allocation per orbit).
        let mut s = std::mem::take(self.scratch());
        let (mut face, mut edge) = (std::mem::take(&mut s.buf), std::mem::take(&mut s.buf2));
        s.seen.clear();
        s.seen2.clear();
        self.walk_orbit(c, AlphaMask::cell(N, 2), &mut s.seen, &mut face);
        for &x in &face {
            self.mu[x.index()].face = level;
            if s.seen2.contains(x.0) || self.mu[x.index()].edge == level {
                continue; // μa is one value per edge and at most the level: already set (finding 248)
            }
            self.walk_orbit(x, AlphaMask::cell(N, 1), &mut s.seen2, &mut edge);
            for &y in &edge {
                self.mu[y.index()].edge = level;
            }
        }
        (s.buf, s.buf2) = (face, edge);
        *self.scratch() = s;
    }
}

//! The machinery every subdivision operation runs on: recorded raw links (so each level can be
//! rebuilt), dart creation with levels, and the exact local relabelling of cell ids at the end.

use super::{LeveledMap, LinkChange, Mu, SubdivideError, MAX_LEVEL};
use crate::gmap::{AlphaMask, DartId};

/// A set of u32 slots (dart slots or cell ids) as epoch stamps: slot i is in the set iff
/// `marks[i] == tag`. [`EpochSet::clear`] takes a new tag, so emptying is O(1) and a test or an
/// insert is one load or store, with no hashing. The array grows to the largest slot inserted.
/// A set must be cleared once before its first use (tag 0 would match every unwritten slot).
#[derive(Clone, Debug, Default)]
pub(super) struct EpochSet {
    marks: Vec<u32>,
    tag: u32,
}

impl EpochSet {
    /// Empties the set. O(1) amortised (O(len) when the 32-bit tags wrap).
    pub(super) fn clear(&mut self) {
        if self.tag == u32::MAX {
            self.marks.fill(0);
            self.tag = 0;
        }
        self.tag += 1;
    }

    /// Adds slot i; returns whether it was absent. O(1) amortised.
    #[inline]
    pub(super) fn insert(&mut self, i: u32) -> bool {
        debug_assert!(self.tag != 0, "EpochSet used before its first clear");
        let i = i as usize;
        if i >= self.marks.len() {
            self.marks.resize((i + 1).max(2 * self.marks.len()), 0);
        }
        let absent = self.marks[i] != self.tag;
        self.marks[i] = self.tag;
        absent
    }

    /// Whether slot i is in the set. O(1).
    #[inline]
    pub(super) fn contains(&self, i: u32) -> bool {
        self.marks.get(i as usize).is_some_and(|&m| m == self.tag)
    }
}

/// Reusable scratch of the operations: per-slot sets and buffers kept across operations so that
/// no operation hashes or allocates per orbit. Holds nothing meaningful between uses.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    /// Darts touched by the running operation (see `OpLog::touched`).
    touched: EpochSet,
    /// Index in `OpLog::touched` of each touched dart slot (valid where `touched` holds it).
    touched_at: Vec<u32>,
    /// Darts created by the running operation.
    created: EpochSet,
    /// General dart sets for walks (visited orbits).
    pub(super) seen: EpochSet,
    pub(super) seen2: EpochSet,
    /// Cell ids kept by an orbit during one relabelling.
    claimed: EpochSet,
    /// Breadth-first queue of the orbit being relabelled.
    orbit: Vec<DartId>,
    /// General orbit buffers.
    pub(super) buf: Vec<DartId>,
    pub(super) buf2: Vec<DartId>,
    /// Old ids of the touched darts (one dimension), sorted.
    pool: Vec<u32>,
}

/// What the running operation touched. Empty between operations (except the scratch).
#[derive(Clone, Debug, Default)]
pub(super) struct OpLog {
    level: u8,
    /// Whether the running operation only adds darts to vertices and creates vertices, never
    /// separating or joining the darts of existing ones ([`LeveledMap::begin_growth`]).
    grows_vertices: bool,
    /// Pre-existing darts whose links changed, in first-touch order.
    touched: Vec<DartId>,
    /// (N + 1) cell ids per touched dart, as they were before the operation.
    old_ids: Vec<u32>,
    /// Per touched dart, the bit set of the generators αj whose link it changed (bit j, as in
    /// [`AlphaMask`]).
    changed: Vec<u8>,
    /// Darts created by the operation.
    created: Vec<DartId>,
    /// Inserted vertices: (a dart at the new vertex, darts at the two end vertices).
    midpoints: Vec<(DartId, DartId, DartId)>,
    /// Darts a cut may move to a new vertex: (dart, its vertex id and position before the
    /// operation). A dart whose id changed records a copy of the old vertex (its origin).
    pub(super) cut_darts: Vec<(DartId, u32, [f64; 3])>,
    /// Reusable sets and buffers.
    pub(super) scratch: Scratch,
}

impl<const N: usize> LeveledMap<N> {
    /// Checks a new operation before it changes anything: its level is at most [`MAX_LEVEL`]
    /// and at least the maximum level, and the map's points cover its vertices
    /// ([`Self::check_points_cover`]).
    pub(super) fn check_op_level(&self, level: u8) -> Result<(), SubdivideError> {
        if level > MAX_LEVEL {
            return Err(SubdivideError::LevelTooHigh(level));
        }
        if level < self.max_level {
            return Err(SubdivideError::LevelBelowMax { level, max_level: self.max_level });
        }
        self.check_points_cover()
    }

    /// Refuses to operate on a partial geometry: points given, but none for some live vertex (the
    /// operation would take the origin for it, store a made-up midpoint and fill the gap with the
    /// origin). A map without points (no geometry) is accepted.
    /// O(1) when the points reach every vertex id; O(darts) otherwise.
    pub(super) fn check_points_cover(&self) -> Result<(), SubdivideError> {
        if self.points.is_empty() {
            return Ok(());
        }
        self.check_positions_given()
    }

    /// [`SubdivideError::NoPosition`] for the smallest live vertex id past the end of the points.
    /// O(1) when the points reach every vertex id; O(darts) otherwise.
    pub(super) fn check_positions_given(&self) -> Result<(), SubdivideError> {
        let points = self.points.len();
        if points >= self.map.cell_id_bound(0) {
            return Ok(());
        }
        let uncovered = self.map.darts().map(|d| self.map.vertex_id(d).0).filter(|&v| v as usize >= points).min();
        uncovered.map_or(Ok(()), |vertex| Err(SubdivideError::NoPosition { vertex, points }))
    }

    /// Opens the log of an operation of level `level` (already checked).
    pub(super) fn begin(&mut self, level: u8) {
        debug_assert!(self.check_op_level(level).is_ok());
        debug_assert!(self.op.touched.is_empty() && self.op.created.is_empty());
        self.op.level = level;
        self.op.grows_vertices = false;
        self.op.scratch.touched.clear();
        self.op.scratch.created.clear();
    }

    /// [`Self::begin`] for a split (of an edge, a triangle or a tet's inner faces): such an
    /// operation inserts darts into vertices and creates new vertices, but never separates the
    /// darts of a vertex nor joins two vertices (the split keeps every old vertex a point of the
    /// mesh with the same neighbourhood, refined). So [`Self::finish`] gives the vertex ids of
    /// the created darts only ([`Self::label_grown_vertices`]), and an operation at a vertex of
    /// valence V no longer walks it (finding 248). The law is checked after every operation in
    /// debug builds on the darts touched, and by the full `validate()` under `expensive-checks`.
    pub(super) fn begin_growth(&mut self, level: u8) {
        self.begin(level);
        self.op.grows_vertices = true;
    }

    /// Records that `d` is about to change (its old cell ids and, once per level and αj, the old
    /// link value).
    fn touch(&mut self, j: usize, d: DartId) {
        let level = self.op.level;
        if self.dart_level[d.index()] == level && self.op.scratch.created.contains(d.0) {
            return; // a dart of this operation: nothing to restore below its level
        }
        if self.op.scratch.touched.insert(d.0) {
            let at = &mut self.op.scratch.touched_at;
            if at.len() <= d.index() {
                at.resize((d.index() + 1).max(2 * at.len()), 0);
            }
            at[d.index()] = self.op.touched.len() as u32;
            self.op.touched.push(d);
            self.op.changed.push(0);
            for dim in 0..=N {
                self.op.old_ids.push(self.map.cell_id(dim, d).0);
            }
        }
        let at = self.op.scratch.touched_at[d.index()] as usize;
        self.op.changed[at] |= 1 << j;
        if !self.history.of(d.index()).any(|c| c.level == level && c.j as usize == j) {
            let old = self.map.alpha_dyn(j, d).0;
            self.history.push(d.index(), LinkChange { level, j: j as u8, old });
        }
    }

    /// αj(a) = b and αj(b) = a, recording every change; former partners become j-free.
    pub(super) fn link(&mut self, j: usize, a: DartId, b: DartId) {
        let (pa, pb) = (self.map.alpha_dyn(j, a), self.map.alpha_dyn(j, b));
        if pa == b {
            return;
        }
        for x in [a, b, pa, pb] {
            self.touch(j, x);
        }
        if pa != a {
            self.map.unlink_raw(j, a);
        }
        if self.map.alpha_dyn(j, b) != b {
            self.map.unlink_raw(j, b);
        }
        self.map.link_raw(j, a, b);
    }

    /// Makes `a` and its αj partner j-free, recording both changes.
    pub(super) fn unlink(&mut self, j: usize, a: DartId) {
        let pa = self.map.alpha_dyn(j, a);
        if pa == a {
            return;
        }
        self.touch(j, a);
        self.touch(j, pa);
        self.map.unlink_raw(j, a);
    }

    /// Creates a free dart of the current level with levels `mu` and the given flat flag.
    pub(super) fn new_dart(&mut self, mu: Mu, flat: bool) -> DartId {
        let d = DartId(self.map.alloc_darts_raw(1));
        let cap = self.map.capacity();
        self.dart_level.resize(cap, 0);
        self.mu.resize(cap, Mu::default());
        self.flat.resize(cap, false);
        self.dart_level[d.index()] = self.op.level;
        self.mu[d.index()] = mu;
        self.flat[d.index()] = flat;
        self.op.created.push(d);
        self.op.scratch.created.insert(d.0);
        d
    }

    /// Notes that the vertex of `m` is new and lies halfway between the vertices of `a` and `b`.
    pub(super) fn note_midpoint(&mut self, m: DartId, a: DartId, b: DartId) {
        self.op.midpoints.push((m, a, b));
    }

    /// After a cut's relabelling: if the vertex of `x` is no longer `old`, it is a copy of `old`
    /// ([`Self::vertex_origin`]) placed at `p`, the position `old` had. O(1) amortized.
    fn note_copy(&mut self, x: DartId, old: u32, p: [f64; 3]) {
        let v = self.map.vertex_id(x).0;
        if v != old {
            self.set_vertex_origin(v, old);
        }
        if !self.points.is_empty() {
            let v = v as usize;
            if self.points.len() <= v {
                self.points.resize(v + 1, [0.0; 3]);
            }
            self.points[v] = p;
        }
    }

    /// The level of the running operation.
    pub(super) fn op_level(&self) -> u8 {
        self.op.level
    }

    /// Closes the operation: exact cell ids for every touched cell, positions of new vertices, the
    /// new maximum level. The finest map is valid afterwards (checked in debug builds).
    pub(super) fn finish(&mut self) {
        let midpoints = std::mem::take(&mut self.op.midpoints);
        // Before the relabelling, a pre-existing dart still carries the id its edge had.
        let old_edges: Vec<u32> = midpoints.iter().map(|&(_, a, _)| self.map.cell_id(1, a).0).collect();
        for dim in 0..=N {
            if dim == 0 && self.op.grows_vertices {
                self.label_grown_vertices();
            } else {
                self.relabel_dim(dim);
            }
        }
        for ((m, a, b), edge) in midpoints.into_iter().zip(old_edges) {
            let (pa, pb) = (self.position(a), self.position(b));
            let v = self.map.vertex_id(m).index();
            let ends = [self.map.vertex_id(a).0, self.map.vertex_id(b).0];
            self.splits.push([v as u32, ends[0], ends[1]]);
            let halves = [self.map.cell_id(1, a).0, self.map.cell_id(1, b).0];
            self.edge_splits.push(super::EdgeSplit { vertex: v as u32, ends, edge, halves });
            if !self.points.is_empty() {
                if self.points.len() <= v {
                    self.points.resize(v + 1, [0.0; 3]);
                }
                self.points[v] = crate::mesh::midpoint(pa, pb);
            }
        }
        for (x, old, p) in std::mem::take(&mut self.op.cut_darts) {
            self.note_copy(x, old, p);
        }
        self.max_level = self.max_level.max(self.op.level);
        self.bump_version();
        if cfg!(debug_assertions) {
            let touched: Vec<DartId> = self.op.touched.iter().chain(&self.op.created).copied().collect();
            debug_assert!(
                self.map.validate_local(&touched).is_ok(),
                "subdivide bug: {:?}",
                self.map.validate_local(&touched)
            );
        }
        self.op.touched.clear();
        self.op.old_ids.clear();
        self.op.changed.clear();
        self.op.created.clear();
        // The leveled map's laws (`check_after_op`: the finest map, the μ order, the flat law and
        // every level's map, or the touched ones past a few levels), not the finest map alone
        // (finding 327).
        #[cfg(feature = "expensive-checks")]
        if let Err(e) = self.check_after_op(self.op.level) {
            panic!("topomech bug: subdivision broke the leveled map: {e}");
        }
    }

    /// Re-derives the dim-cell ids of every cell that may have changed: the cells of the created
    /// darts and of the touched darts that changed a link of the cell's own generators. An
    /// orbit keeps an id one of its darts had before the operation when it can (untouched darts
    /// first, in breadth-first orbit order, then the old ids of touched darts in the same order),
    /// otherwise gets a fresh one; old ids no orbit kept are released in increasing order.
    ///
    /// A touched dart whose changed links are all outside the cell's generators starts no walk
    /// (finding 248): if no dart of its orbit changed such a link or was created, the orbit's
    /// links are the old ones, so it is the old cell, whole, and keeps its id (the relabelling
    /// would give it that id too: its untouched darts carry it, or all its old ids are it, and no
    /// other orbit had it). So the corners of an operation at a vertex of valence V, whose
    /// α1, α2, α3 links no split changes, cost nothing here instead of O(V).
    /// O(changed cells); the visited and claimed sets are epoch stamps ([`EpochSet`]).
    fn relabel_dim(&mut self, dim: usize) {
        let mut s = std::mem::take(&mut self.op.scratch);
        s.seen.clear();
        s.claimed.clear();
        let nt = self.op.touched.len();
        let mask = AlphaMask::cell(N, dim);
        for k in 0..nt + self.op.created.len() {
            let start = if k < nt { self.op.touched[k] } else { self.op.created[k - nt] };
            if s.seen.contains(start.0) || (k < nt && self.op.changed[k] & mask.0 == 0) {
                continue;
            }
            self.walk_orbit(start, mask, &mut s.seen, &mut s.orbit);
            let id = self.kept_id(dim, &s).unwrap_or_else(|| self.map.alloc_cell_id(dim));
            s.claimed.insert(id);
            for &x in &s.orbit {
                self.map.set_cell_raw(dim, x, id);
            }
        }
        for &d in &self.op.touched {
            if !s.seen.contains(d.0) {
                let id = self.map.cell_id(dim, d).0;
                debug_assert_eq!(id, self.op.old_ids[s.touched_at[d.index()] as usize * (N + 1) + dim]);
                s.claimed.insert(id); // an unchanged cell, not walked: its id stays
            }
        }
        s.pool.clear();
        s.pool.extend((0..nt).map(|k| self.op.old_ids[k * (N + 1) + dim]));
        s.pool.sort_unstable();
        s.pool.dedup();
        for &id in &s.pool {
            if !s.claimed.contains(id) {
                self.map.release_cell_id(dim, id);
            }
        }
        self.op.scratch = s;
    }

    /// The vertex ids after an operation opened by [`Self::begin_growth`]: each vertex of
    /// created darts takes the id of the pre-existing darts it holds (one id: the operation
    /// joins no vertices), or a fresh one if it holds none (a new vertex), in the order of the
    /// created darts — the ids [`Self::relabel_dim`] gives, without walking the pre-existing
    /// darts. O(created darts · n).
    fn label_grown_vertices(&mut self) {
        let mut s = std::mem::take(&mut self.op.scratch);
        s.seen.clear();
        for k in 0..self.op.created.len() {
            let start = self.op.created[k];
            if !s.seen.insert(start.0) {
                continue;
            }
            s.orbit.clear();
            s.orbit.push(start);
            let (mut head, mut id) = (0, None);
            while head < s.orbit.len() {
                let row = self.map.alpha_row(s.orbit[head].0);
                head += 1;
                for &y in &row[1..=N] {
                    if !s.created.contains(y) {
                        let old = self.map.cell_id(0, DartId(y)).0;
                        debug_assert!(id.is_none_or(|i| i == old), "subdivide bug: a split joined two vertices");
                        id = Some(old);
                    } else if s.seen.insert(y) {
                        s.orbit.push(DartId(y));
                    }
                }
            }
            let id = id.unwrap_or_else(|| self.map.alloc_cell_id(0));
            #[cfg(test)]
            tests::WALKED.set(tests::WALKED.get() + s.orbit.len());
            for &x in &s.orbit {
                self.map.set_cell_raw(0, x, id);
            }
        }
        self.op.scratch = s;
    }

    /// The reusable scratch sets and buffers (empty of meaning between uses).
    pub(super) fn scratch(&mut self) -> &mut Scratch {
        &mut self.op.scratch
    }

    /// The orbit ⟨mask⟩(start) into `out`, in the breadth-first order of [`crate::GMap::orbit`]
    /// (generators in increasing index order), skipping and marking darts in `seen`: when `seen`
    /// holds only darts of other orbits, `out` is the whole orbit. O(orbit · n).
    pub(super) fn walk_orbit(&self, start: DartId, mask: AlphaMask, seen: &mut EpochSet, out: &mut Vec<DartId>) {
        let mut gens = [0usize; 8];
        let mut len = 0;
        for j in (0..=N.min(7)).filter(|&j| mask.contains(j)) {
            gens[len] = j;
            len += 1;
        }
        out.clear();
        out.push(start);
        seen.insert(start.0);
        let mut head = 0;
        while head < out.len() {
            #[cfg(test)]
            tests::WALKED.set(tests::WALKED.get() + 1);
            let x = out[head];
            head += 1;
            let row = self.map.alpha_row(x.0);
            for &j in &gens[..len] {
                if seen.insert(row[j]) {
                    out.push(DartId(row[j]));
                }
            }
        }
    }

    /// The id the orbit in `s.orbit` keeps: the first unclaimed current id of an untouched,
    /// pre-existing dart, else the first unclaimed old id of a touched dart (orbit order). O(orbit).
    fn kept_id(&self, dim: usize, s: &Scratch) -> Option<u32> {
        let untouched = s.orbit.iter().filter(|x| !s.touched.contains(x.0) && !s.created.contains(x.0));
        let fresh = untouched.map(|&x| self.map.cell_id(dim, x).0).find(|&id| !s.claimed.contains(id));
        fresh.or_else(|| {
            let old = s.orbit.iter().filter(|x| s.touched.contains(x.0));
            old.map(|x| self.op.old_ids[s.touched_at[x.index()] as usize * (N + 1) + dim])
                .find(|&id| !s.claimed.contains(id))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::EpochSet;
    use crate::subdivide::LeveledMap;
    use crate::GMap;

    thread_local! {
        /// Darts walked by this thread's operations through [`super::LeveledMap::walk_orbit`]
        /// (the relabellings, the level raises) and the labelling of grown vertices.
        pub(super) static WALKED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    /// The cone from the centre of the cube [-1, 1]³ over its surface (each side an n × n grid,
    /// two triangles per square): 12 n² tets at the centre vertex 0, whose edges have valence
    /// at most 6.
    fn star(n: u32) -> LeveledMap<3> {
        let mut points = vec![[0.0; 3]];
        let mut ids = std::collections::HashMap::new();
        let mut tets = Vec::new();
        for (axis, side) in (0..3).flat_map(|a| [(a, -1.0), (a, 1.0)]) {
            let mut id = |a: u32, b: u32| {
                let mut p = [side; 3];
                p[(axis + 1) % 3] = -1.0 + 2.0 * f64::from(a) / f64::from(n);
                p[(axis + 2) % 3] = -1.0 + 2.0 * f64::from(b) / f64::from(n);
                *ids.entry(p.map(f64::to_bits)).or_insert_with(|| {
                    points.push(p);
                    points.len() as u32 - 1
                })
            };
            for (i, j) in (0..n).flat_map(|i| (0..n).map(move |j| (i, j))) {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                tets.extend([[0, q[0], q[1], q[2]], [0, q[0], q[2], q[3]]]);
            }
        }
        let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        LeveledMap::new(map, points)
    }

    /// Finding 248: splitting an edge at a vertex of valence V relabelled that vertex's whole
    /// orbit (6 darts per tet around it), and refining the tets around it was O(V²). Now the
    /// darts the operation walks do not grow with V: the same spoke split at the centre of
    /// 192 and of 3 072 tets walks the same number of darts (the edge ring, its faces and
    /// volumes, the new vertex), and the ids are exact (`validate` after each).
    #[test]
    fn a_split_at_a_high_valence_vertex_walks_no_more_for_more_tets() {
        let mut walked = Vec::new();
        for n in [4, 16] {
            let mut m = star(n);
            let d = m.map().darts().find(|&d| m.map().vertex_id(d).0 == 0).unwrap();
            let before = WALKED.get();
            m.split_edge(d, 1).unwrap();
            walked.push(WALKED.get() - before);
            m.map().validate().unwrap();
            assert_eq!(m.map().count_cells(), m.map().count_cells_by_traversal());
            assert_eq!(m.map().count_cells().0[3], 12 * n as usize * n as usize);
        }
        assert!(walked[0] < 6 * 192, "{walked:?}");
        assert_eq!(walked[0], walked[1], "the relabelling grows with the valence: {walked:?}");
    }

    #[test]
    fn epoch_set_clear_empties_and_insert_reports_absence() {
        let mut s = EpochSet::default();
        s.clear();
        assert!(!s.contains(7) && !s.contains(1_000));
        assert!(s.insert(7));
        assert!(!s.insert(7), "a second insert finds the slot present");
        assert!(s.contains(7) && !s.contains(6) && !s.contains(8));
        assert!(s.insert(100), "the array grows past its length");
        s.clear();
        assert!(!s.contains(7) && !s.contains(100), "a new tag empties the set");
        assert!(s.insert(7));
    }

    #[test]
    fn epoch_set_survives_tag_wrap() {
        let mut s = EpochSet::default();
        s.clear();
        s.insert(3);
        s.tag = u32::MAX; // next clear wraps
        s.insert(4);
        s.clear();
        assert_eq!(s.tag, 1);
        assert!(!s.contains(3) && !s.contains(4), "marks from before the wrap are stale");
        assert!(s.insert(3) && s.contains(3));
    }

    /// Finding 248, its edge part: each tet split beside an edge of valence k walked the edge's
    /// orbit (4 darts per tet of its ring) to raise μa, and each face split beside it too, so
    /// refining the k tets around the edge was O(k²). μa is one value per edge, so an edge
    /// already at the level is not walked again: one level around the axis of a closed fan
    /// walks about as many darts per tet for k = 16 as for k = 128 (within 25 %), with every
    /// law of `check_all` after it.
    #[test]
    fn refining_around_a_high_valence_edge_walks_linearly() {
        let mut per_tet = Vec::new();
        for k in [16u32, 128] {
            let tets: Vec<[u32; 4]> = (0..k).map(|i| [0, 1, 2 + i, 2 + (i + 1) % k]).collect();
            let mut points = vec![[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]];
            points.extend((0..k).map(|i| {
                let a = std::f64::consts::TAU * f64::from(i) / f64::from(k);
                [a.cos(), a.sin(), 0.0]
            }));
            let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
            let mut m = LeveledMap::new(map, points);
            let mut masses = crate::subdivide::TetMasses::from_density(&m, 1.0).unwrap();
            let before = WALKED.get();
            let r = m.refine_around_per_op([0.0; 3], 0.0, 1, &mut masses).unwrap();
            assert_eq!(r.subdivided_per_level, vec![0, k as usize]);
            per_tet.push((WALKED.get() - before) as f64 / f64::from(k));
            m.check_all().unwrap();
        }
        assert!(per_tet[1] <= 1.25 * per_tet[0], "darts walked per tet: {per_tet:?}");
    }
}

//! The machinery every subdivision operation runs on: recorded raw links (so each level can be
//! rebuilt), dart creation with levels, and the exact local relabelling of cell ids at the end.

use super::{LeveledMap, LinkChange, Mu, SubdivideError, MAX_LEVEL};
use crate::gmap::{AlphaMask, DartId};
use rustc_hash::{FxHashMap, FxHashSet};

/// What the running operation touched. Empty between operations.
#[derive(Clone, Debug, Default)]
pub(super) struct OpLog {
    level: u8,
    /// Pre-existing darts whose links changed, in first-touch order.
    touched: Vec<DartId>,
    /// Index of each touched dart in `touched`.
    touched_at: FxHashMap<u32, usize>,
    /// (N + 1) cell ids per touched dart, as they were before the operation.
    old_ids: Vec<u32>,
    /// Darts created by the operation.
    created: Vec<DartId>,
    /// Inserted vertices: (a dart at the new vertex, darts at the two end vertices).
    midpoints: Vec<(DartId, DartId, DartId)>,
}

impl<const N: usize> LeveledMap<N> {
    /// Checks the level of a new operation: at most [`MAX_LEVEL`], at least the maximum level.
    pub(super) fn check_op_level(&self, level: u8) -> Result<(), SubdivideError> {
        if level > MAX_LEVEL {
            return Err(SubdivideError::LevelTooHigh(level));
        }
        if level < self.max_level {
            return Err(SubdivideError::LevelBelowMax { level, max_level: self.max_level });
        }
        Ok(())
    }

    /// Opens the log of an operation of level `level` (already checked).
    pub(super) fn begin(&mut self, level: u8) {
        debug_assert!(self.check_op_level(level).is_ok());
        debug_assert!(self.op.touched.is_empty() && self.op.created.is_empty());
        self.op.level = level;
    }

    /// Records that `d` is about to change (its old cell ids and, once per level and αj, the old
    /// link value).
    fn touch(&mut self, j: usize, d: DartId) {
        let level = self.op.level;
        if self.dart_level[d.index()] == level && self.op.created.contains(&d) {
            return; // a dart of this operation: nothing to restore below its level
        }
        if !self.op.touched_at.contains_key(&d.0) {
            self.op.touched_at.insert(d.0, self.op.touched.len());
            self.op.touched.push(d);
            for dim in 0..=N {
                self.op.old_ids.push(self.map.cell_id(dim, d).0);
            }
        }
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
        self.history.resize(cap);
        self.dart_level[d.index()] = self.op.level;
        self.mu[d.index()] = mu;
        self.flat[d.index()] = flat;
        self.op.created.push(d);
        d
    }

    /// Notes that the vertex of `m` is new and lies halfway between the vertices of `a` and `b`.
    pub(super) fn note_midpoint(&mut self, m: DartId, a: DartId, b: DartId) {
        self.op.midpoints.push((m, a, b));
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
            self.relabel_dim(dim);
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
                self.points[v] = [0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k]));
            }
        }
        self.max_level = self.max_level.max(self.op.level);
        let touched: Vec<DartId> = self.op.touched.iter().chain(&self.op.created).copied().collect();
        self.op = OpLog::default();
        debug_assert!(
            self.map.validate_local(&touched).is_ok(),
            "subdivide bug: {:?}",
            self.map.validate_local(&touched)
        );
        #[cfg(feature = "expensive-checks")]
        if let Err(e) = self.map.validate() {
            panic!("topomech bug: subdivision broke the map: {e}");
        }
    }

    /// Re-derives the dim-cell ids of every cell that contains a touched or created dart. An
    /// orbit keeps an id one of its darts had before the operation when it can (untouched darts
    /// first), otherwise gets a fresh one; old ids no orbit kept are released. O(touched cells).
    fn relabel_dim(&mut self, dim: usize) {
        let mask = AlphaMask::cell(N, dim);
        let starts: Vec<DartId> = self.op.touched.iter().chain(&self.op.created).copied().collect();
        let mut seen: FxHashSet<u32> = FxHashSet::default();
        let mut claimed: FxHashSet<u32> = FxHashSet::default();
        let created: FxHashSet<u32> = self.op.created.iter().map(|d| d.0).collect();
        for s in starts {
            if seen.contains(&s.0) {
                continue;
            }
            let orbit = self.map.orbit(s, mask);
            let mut untouched = Vec::new();
            let mut old = Vec::new();
            for &x in &orbit {
                seen.insert(x.0);
                match self.op.touched_at.get(&x.0) {
                    Some(&k) => old.push(self.op.old_ids[k * (N + 1) + dim]),
                    None if !created.contains(&x.0) => untouched.push(self.map.cell_id(dim, x).0),
                    None => {}
                }
            }
            let id = match untouched.into_iter().chain(old).find(|id| !claimed.contains(id)) {
                Some(id) => id,
                None => self.map.alloc_cell_id(dim),
            };
            claimed.insert(id);
            for x in orbit {
                self.map.set_cell_raw(dim, x, id);
            }
        }
        let mut pool: Vec<u32> = (0..self.op.touched.len()).map(|k| self.op.old_ids[k * (N + 1) + dim]).collect();
        pool.sort_unstable();
        pool.dedup();
        for id in pool {
            if !claimed.contains(&id) {
                self.map.release_cell_id(dim, id);
            }
        }
    }
}

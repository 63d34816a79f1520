//! Orbits ⟨Π⟩(d): every dart reachable from d by any composition of the involutions in Π.
//!
//! The i-cell of d is the orbit ⟨⟩N−{i}(d) = ⟨α0, …, αi−1, αi+1, …, αn⟩(d) (seed 000, §2.1).
//! Walks are breadth-first, visit generators in increasing index order (so the order is
//! deterministic), and are bounded by the number of live darts.

use rustc_hash::FxHashSet;

use super::{AlphaMask, CellId, DartId, DartSet, GMap};

/// A visited set tuned for orbits: linear scan while small, hashing beyond.
pub(crate) struct SmallDartSet {
    small: Vec<u32>,
    large: Option<FxHashSet<u32>>,
}

impl SmallDartSet {
    const LINEAR_LIMIT: usize = 48;

    pub(crate) fn new() -> Self {
        SmallDartSet { small: Vec::new(), large: None }
    }

    /// Inserts d; returns whether it was absent.
    #[inline]
    pub(crate) fn insert(&mut self, d: DartId) -> bool {
        if let Some(set) = &mut self.large {
            return set.insert(d.0);
        }
        if self.small.contains(&d.0) {
            return false;
        }
        self.small.push(d.0);
        if self.small.len() > Self::LINEAR_LIMIT {
            self.large = Some(self.small.drain(..).collect());
        }
        true
    }

    #[inline]
    pub(crate) fn contains(&self, d: DartId) -> bool {
        match &self.large {
            Some(set) => set.contains(&d.0),
            None => self.small.contains(&d.0),
        }
    }
}

impl<const N: usize> GMap<N> {
    /// The darts of ⟨mask⟩(d) in breadth-first order, d first. O(orbit · n).
    pub fn orbit(&self, d: DartId, mask: AlphaMask) -> Vec<DartId> {
        let mut seen = SmallDartSet::new();
        let mut out = vec![d];
        seen.insert(d);
        let mut head = 0;
        while head < out.len() {
            let x = out[head];
            head += 1;
            for i in mask.indices().filter(|&i| i <= N) {
                let y = self.alpha_dyn(i, x);
                if seen.insert(y) {
                    out.push(y);
                }
            }
        }
        out
    }

    /// The darts of the i-cell of d, ⟨⟩N−{i}(d). O(cell · n).
    pub fn cell_darts(&self, i: usize, d: DartId) -> Vec<DartId> {
        self.orbit(d, AlphaMask::cell(N, i))
    }

    /// Whether b lies in ⟨mask⟩(a). Walks from a and b at once and stops as soon as the walks
    /// meet or one of them is exhausted, so the cost is O(min(|orbit(a)|, |orbit(b)|) · n) when
    /// the orbits differ.
    pub fn same_orbit(&self, a: DartId, b: DartId, mask: AlphaMask) -> bool {
        self.split_side(a, b, mask).is_none()
    }

    /// Walks ⟨mask⟩(a) and ⟨mask⟩(b) in lockstep. `None` if they are one orbit; otherwise the
    /// darts of the orbit that was exhausted first (the smaller one, up to one step) and whether
    /// it is b's.
    pub(crate) fn split_side(&self, a: DartId, b: DartId, mask: AlphaMask) -> Option<(Vec<DartId>, bool)> {
        if a == b {
            return None;
        }
        let mut seen = [SmallDartSet::new(), SmallDartSet::new()];
        let mut queue = [vec![a], vec![b]];
        let mut head = [0usize, 0usize];
        seen[0].insert(a);
        seen[1].insert(b);
        loop {
            for side in 0..2 {
                if head[side] == queue[side].len() {
                    return Some((std::mem::take(&mut queue[side]), side == 1));
                }
                let x = queue[side][head[side]];
                head[side] += 1;
                for i in mask.indices().filter(|&i| i <= N) {
                    let y = self.alpha_dyn(i, x);
                    if seen[1 - side].contains(y) {
                        return None;
                    }
                    if seen[side].insert(y) {
                        queue[side].push(y);
                    }
                }
            }
        }
    }

    /// One dart per i-cell: for each live i-cell id, the smallest dart carrying it. O(capacity).
    pub fn one_dart_per_cell(&self, i: usize) -> Vec<DartId> {
        let mut first = vec![u32::MAX; self.cell_id_bound(i)];
        for d in self.darts() {
            let id = self.cell_id(i, d).index();
            if first[id] == u32::MAX {
                first[id] = d.0;
            }
        }
        first.into_iter().filter(|&d| d != u32::MAX).map(DartId).collect()
    }

    /// One dart per i-cell, found by walking orbits with a mark and ignoring cell ids: the
    /// independent oracle for [`GMap::one_dart_per_cell`]. O(darts · n).
    pub fn one_dart_per_cell_by_traversal(&self, i: usize) -> Vec<DartId> {
        let mask = AlphaMask::cell(N, i);
        let mut seen = DartSet::with_capacity(self.capacity());
        let mut stack = Vec::new();
        let mut out = Vec::new();
        for d in self.darts() {
            if seen.insert(d) {
                out.push(d);
                self.flood(d, mask, &mut seen, &mut stack);
            }
        }
        out
    }

    /// Marks in `seen` every dart of ⟨mask⟩(d) (d itself already marked). Returns the number of
    /// darts newly marked, d included. O(orbit · n), iterative.
    pub(crate) fn flood(&self, d: DartId, mask: AlphaMask, seen: &mut DartSet, stack: &mut Vec<DartId>) -> usize {
        stack.clear();
        stack.push(d);
        let mut count = 1;
        while let Some(x) = stack.pop() {
            for i in mask.indices().filter(|&i| i <= N) {
                let y = self.alpha_dyn(i, x);
                if seen.insert(y) {
                    count += 1;
                    stack.push(y);
                }
            }
        }
        count
    }

    /// Sets the i-cell id of every dart reachable from d through `mask` whose id is `from` to
    /// `to`. Because relabelled darts no longer carry `from`, no visited set is needed. Returns
    /// the number of darts relabelled. O(relabelled · n).
    pub(crate) fn relabel(&mut self, i: usize, d: DartId, mask: AlphaMask, from: u32, to: u32) -> usize {
        debug_assert_ne!(from, to);
        if self.cell_id(i, d).0 != from {
            return 0;
        }
        self.set_cell_raw(i, d, to);
        let mut stack = vec![d];
        let mut count = 1;
        while let Some(x) = stack.pop() {
            for j in mask.indices().filter(|&j| j <= N) {
                let y = self.alpha_dyn(j, x);
                if self.cell_id(i, y).0 == from {
                    self.set_cell_raw(i, y, to);
                    count += 1;
                    stack.push(y);
                }
            }
        }
        count
    }

    /// The ids of the i-cells incident to d's j-cell, each once. O(j-cell · n).
    pub fn incident_cells(&self, d: DartId, j: usize, i: usize) -> Vec<CellId> {
        let mut ids: Vec<CellId> = self.cell_darts(j, d).into_iter().map(|e| self.cell_id(i, e)).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

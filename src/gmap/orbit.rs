//! Orbits ⟨Π⟩(d): every dart reachable from d by any composition of the involutions in Π.
//!
//! The i-cell of d is the orbit ⟨⟩N−{i}(d) = ⟨α0, …, αi−1, αi+1, …, αn⟩(d) (seed 000, §2.1).
//! Walks are breadth-first, visit generators in increasing index order (so the order is
//! deterministic), and are bounded by the number of live darts.

use super::{AlphaMask, CellId, DartId, GMap};

/// A visited set tuned for single orbits: linear scan while small, then an open-addressing hash
/// table of dart ids (Fibonacci hashing, linear probing, grown at half load).
pub(crate) struct SmallDartSet {
    small: Vec<u32>,
    table: Vec<u32>,
    len: usize,
}

impl SmallDartSet {
    const LINEAR_LIMIT: usize = 24;
    const EMPTY: u32 = u32::MAX;

    pub(crate) fn new() -> Self {
        SmallDartSet { small: Vec::new(), table: Vec::new(), len: 0 }
    }

    #[inline(always)]
    fn slot(table_len: usize, d: u32) -> usize {
        let shift = 64 - table_len.trailing_zeros();
        (u64::from(d).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize
    }

    /// Inserts into the table (which has room); returns whether d was absent.
    #[inline]
    fn table_insert(table: &mut [u32], d: u32) -> bool {
        let mask = table.len() - 1;
        let mut k = Self::slot(table.len(), d);
        loop {
            match table[k] {
                Self::EMPTY => {
                    table[k] = d;
                    return true;
                }
                x if x == d => return false,
                _ => k = (k + 1) & mask,
            }
        }
    }

    fn grow(&mut self) {
        let old = std::mem::replace(&mut self.table, vec![Self::EMPTY; (self.len * 4).next_power_of_two().max(128)]);
        for &d in old.iter().chain(self.small.iter()).filter(|&&d| d != Self::EMPTY) {
            Self::table_insert(&mut self.table, d);
        }
        self.small.clear();
    }

    /// Inserts d; returns whether it was absent.
    #[inline]
    pub(crate) fn insert(&mut self, d: DartId) -> bool {
        if self.table.is_empty() {
            if self.small.contains(&d.0) {
                return false;
            }
            self.small.push(d.0);
            self.len += 1;
            if self.small.len() > Self::LINEAR_LIMIT {
                self.grow();
            }
            return true;
        }
        if !Self::table_insert(&mut self.table, d.0) {
            return false;
        }
        self.len += 1;
        if self.len * 2 > self.table.len() {
            self.grow();
        }
        true
    }

    #[inline]
    pub(crate) fn contains(&self, d: DartId) -> bool {
        if self.table.is_empty() {
            return self.small.contains(&d.0);
        }
        let mask = self.table.len() - 1;
        let mut k = Self::slot(self.table.len(), d.0);
        loop {
            match self.table[k] {
                Self::EMPTY => return false,
                x if x == d.0 => return true,
                _ => k = (k + 1) & mask,
            }
        }
    }
}

/// A fixed-size bit set over dart slots (or ids): the visited set of whole-map traversals. No
/// growth and no count, so the hot test-and-set is one load, one store and one bounds check.
pub(crate) struct VisitBits {
    words: Vec<u64>,
}

impl VisitBits {
    /// An empty set of slots 0..len.
    pub(crate) fn new(len: usize) -> Self {
        VisitBits { words: vec![0; len.div_ceil(64)] }
    }

    /// Adds slot i (< len); returns whether it was absent.
    #[inline(always)]
    pub(crate) fn insert(&mut self, i: u32) -> bool {
        let w = &mut self.words[i as usize >> 6];
        let bit = 1u64 << (i & 63);
        let absent = *w & bit == 0;
        *w |= bit;
        absent
    }

    /// Whether slot i is in the set (false past the end).
    #[inline(always)]
    pub(crate) fn contains(&self, i: u32) -> bool {
        self.words.get(i as usize >> 6).is_some_and(|w| w & (1u64 << (i & 63)) != 0)
    }
}

/// The generators of `mask` that exist in an n-map, in increasing order, as an array and a
/// length: hot loops iterate `&gens[..len]` instead of testing eight bits per dart.
#[inline]
pub(crate) fn generators(n: usize, mask: AlphaMask) -> ([usize; 8], usize) {
    let mut gens = [0usize; 8];
    let mut len = 0;
    for i in (0..=n.min(7)).filter(|&i| mask.contains(i)) {
        gens[len] = i;
        len += 1;
    }
    (gens, len)
}

impl<const N: usize> GMap<N> {
    /// The darts of ⟨mask⟩(d) in breadth-first order, d first. O(orbit · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let face = map.orbit(d, AlphaMask::of(&[0, 1]));
    /// assert_eq!(face.len(), 6); // a triangle: 3 corners × 2 edges
    /// assert_eq!(face[0], d);
    /// assert_eq!(map.orbit(d, AlphaMask::all(3)).len(), 24);
    /// assert_eq!(map.orbit(d, AlphaMask::EMPTY), vec![d]);
    /// ```
    pub fn orbit(&self, d: DartId, mask: AlphaMask) -> Vec<DartId> {
        let mut seen = SmallDartSet::new();
        let mut out = vec![d];
        seen.insert(d);
        let (gens, len) = generators(N, mask);
        let mut head = 0;
        while head < out.len() {
            let x = out[head];
            head += 1;
            let row = self.alpha_row(x.0);
            for &i in &gens[..len] {
                let y = DartId(row[i]);
                if y != x && seen.insert(y) {
                    out.push(y);
                }
            }
        }
        out
    }

    /// The darts of the i-cell of d, ⟨⟩N−{i}(d). O(cell · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let sizes: Vec<usize> = (0..=3).map(|i| map.cell_darts(i, d).len()).collect();
    /// assert_eq!(sizes, vec![6, 4, 6, 24]); // corner, edge, face, volume of one tet
    /// assert!(map.cell_darts(0, d).iter().all(|&e| map.vertex_id(e) == map.vertex_id(d)));
    /// ```
    pub fn cell_darts(&self, i: usize, d: DartId) -> Vec<DartId> {
        self.orbit(d, AlphaMask::cell(N, i))
    }

    /// Whether b lies in ⟨mask⟩(a). Walks from a and b at once and stops as soon as the walks
    /// meet or one of them is exhausted, so the cost is O(min(|orbit(a)|, |orbit(b)|) · n) when
    /// the orbits differ.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let e = map.alpha::<0>(d);
    /// assert!(map.same_orbit(d, e, AlphaMask::cell(3, 1))); // same edge
    /// assert!(!map.same_orbit(d, e, AlphaMask::cell(3, 0))); // different vertices
    /// ```
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
        let (gens, len) = generators(N, mask);
        loop {
            for side in 0..2 {
                if head[side] == queue[side].len() {
                    return Some((std::mem::take(&mut queue[side]), side == 1));
                }
                let x = queue[side][head[side]];
                head[side] += 1;
                let row = self.alpha_row(x.0);
                for &i in &gens[..len] {
                    let y = DartId(row[i]);
                    if y == x {
                        continue;
                    }
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
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// for i in 0..=3 {
    ///     let darts = map.one_dart_per_cell(i);
    ///     assert_eq!(darts.len(), map.count_cells().0[i]);
    ///     assert_eq!(darts.len(), map.one_dart_per_cell_by_traversal(i).len());
    /// }
    /// ```
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
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, triangles) = generate::grid_triangles(2);
    /// let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    /// let mut ids: Vec<_> = map.one_dart_per_cell_by_traversal(1).iter().map(|&d| map.cell_id(1, d)).collect();
    /// ids.sort_unstable();
    /// ids.dedup();
    /// assert_eq!(ids.len(), 16); // E = 3n² + 2n distinct edge ids
    /// ```
    pub fn one_dart_per_cell_by_traversal(&self, i: usize) -> Vec<DartId> {
        let mut out = Vec::new();
        self.for_each_orbit(AlphaMask::cell(N, i), |d| out.push(d));
        out
    }

    /// Calls `first(d)` once per orbit ⟨mask⟩, with d the smallest dart of the orbit, in increasing
    /// order of d. Returns the number of orbits. O(darts · |mask| · α(darts)), one u32 per dart
    /// of memory.
    ///
    /// A sequential sweep joins each live dart d with every αj(d) < d (j in mask) in a
    /// union-find forest whose roots are the smallest darts of their trees (each link is met
    /// once, from its larger end, since the αs are involutions); the roots are then the smallest
    /// dart of each orbit. Rows are read in memory order, unlike the random reads of a flood.
    pub(crate) fn for_each_orbit(&self, mask: AlphaMask, mut first: impl FnMut(DartId)) -> usize {
        let (gens, len) = generators(N, mask);
        let mut forest: Vec<u32> = (0..self.capacity() as u32).collect();
        self.for_each_live(|d| {
            join_with_smaller(&mut forest, d, self.alpha_row(d), &gens[..len]);
        });
        let mut count = 0;
        self.for_each_live(|d| {
            if forest[d as usize] == d {
                count += 1;
                first(DartId(d));
            }
        });
        count
    }

    /// Calls f on every live dart index in increasing order, a 64-dart word at a time. O(capacity).
    #[inline]
    pub(crate) fn for_each_live(&self, mut f: impl FnMut(u32)) {
        for (w, &word) in self.alive.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                f((w * 64) as u32 + bits.trailing_zeros());
                bits &= bits - 1;
            }
        }
    }

    /// The n + 1 links of dart slot d, α0(d) … αn(d).
    #[inline(always)]
    pub(crate) fn alpha_row(&self, d: u32) -> &[u32] {
        let base = d as usize * (N + 1);
        &self.alpha[base..base + N + 1]
    }

    /// The n + 1 cell ids of dart slot d.
    #[inline(always)]
    pub(crate) fn cell_row(&self, d: u32) -> &[u32] {
        let base = d as usize * (N + 1);
        &self.cell[base..base + N + 1]
    }

    /// Marks in `seen` every dart of the orbit of d under the generators `gens` (d itself already
    /// marked). Returns the number of darts newly marked, d included. O(orbit · |gens|),
    /// iterative (depth-first with an explicit stack).
    #[inline]
    pub(crate) fn flood(&self, d: u32, gens: &[usize], seen: &mut VisitBits, stack: &mut Vec<u32>) -> usize {
        stack.clear();
        stack.push(d);
        let mut count = 1;
        while let Some(x) = stack.pop() {
            let row = self.alpha_row(x);
            for &i in gens {
                let y = row[i];
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
        let (gens, len) = generators(N, mask);
        let mut stack = vec![d];
        let mut count = 1;
        while let Some(x) = stack.pop() {
            for &j in &gens[..len] {
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
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap(); // on the shared face
    /// assert_eq!(map.incident_cells(d, 2, 0).len(), 3); // its corners
    /// assert_eq!(map.incident_cells(d, 2, 3).len(), 2); // the two tets around it
    /// assert_eq!(map.incident_cells(d, 0, 3).len(), 2);
    /// ```
    pub fn incident_cells(&self, d: DartId, j: usize, i: usize) -> Vec<CellId> {
        let mut ids: Vec<CellId> = self.cell_darts(j, d).into_iter().map(|e| self.cell_id(i, e)).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

/// The root of x in a union-find forest (`forest[r] == r` at roots), halving the path on the way.
#[inline(always)]
pub(crate) fn find_root(forest: &mut [u32], mut x: u32) -> u32 {
    loop {
        let parent = forest[x as usize];
        if parent == x {
            return x;
        }
        let grandparent = forest[parent as usize];
        forest[x as usize] = grandparent;
        x = grandparent;
    }
}

/// Joins dart d with the trees of its neighbours αj(d) < d (j in `gens`, `row` = d's α row) in
/// a union-find forest whose roots are the smallest elements of their trees; returns the number
/// of successful joins. O(|gens| · α(len)).
///
/// Precondition: no element points to d yet. It holds when darts are swept in increasing order
/// and every join is made by this function: a join links the larger of two roots under the
/// smaller, and both are below the dart being swept. So d is its own root on entry and the only
/// root to track is the current one: one `find_root` per neighbour instead of two per join.
#[inline(always)]
pub(crate) fn join_with_smaller(forest: &mut [u32], d: u32, row: &[u32], gens: &[usize]) -> usize {
    let mut root = d;
    let mut joins = 0;
    for &j in gens {
        let y = row[j];
        if y < d {
            let other = find_root(forest, y);
            if other != root {
                let (lo, hi) = if other < root { (other, root) } else { (root, other) };
                forest[hi as usize] = lo;
                root = lo;
                joins += 1;
            }
        }
    }
    joins
}

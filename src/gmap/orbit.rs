//! Orbits ⟨Π⟩(d): every dart reachable from d by any composition of the involutions in Π.
//!
//! The i-cell of d is the orbit ⟨⟩N−{i}(d) = ⟨α0, …, αi−1, αi+1, …, αn⟩(d) (seed 000, §2.1).
//! Walks are breadth-first, visit generators in increasing index order (so the order is
//! deterministic), and are bounded by the number of live darts. Their visited set is the list of
//! darts found while it is short (`LINEAR_LIMIT`), then a per-thread array of epoch stamps
//! (`Stamps`: one u32 per dart slot, a fresh tag per walk, never cleared): no hashing. Orbits of
//! two generators need no visited set at all (`GMap::for_each_dihedral`).

use super::{AlphaMask, CellId, DartId, GMap};

/// Epoch-stamped visited marks, one u32 per dart slot, shared by the walks of one thread.
///
/// A walk takes fresh tags ([`Stamps::fresh`]) and marks a dart by writing its tag; a dart is
/// visited iff its mark equals the tag. Nothing is cleared between walks (a new tag makes every
/// old mark stale), so a test or a mark is one load or store with no hashing. The array grows to
/// the largest map capacity the thread walks (4 bytes per dart slot), and is wiped only when
/// the 32-bit tags wrap. It shrinks back after [`SHRINK_AFTER`] walks in a row on maps below a
/// quarter of its size (a thread that walked a 30 M-dart map and went on with small ones kept
/// 120 MB: round 25), and [`release_thread_caches`] frees it at once.
#[derive(Default)]
pub(crate) struct Stamps {
    marks: Vec<u32>,
    last: u32,
    /// Walks in a row that addressed less than a quarter of `marks`.
    small_walks: u32,
}

/// Walks in a row on maps below a quarter of the stamp array before it shrinks: a thread that
/// alternates between a large map and small ones regrows it at most once per this many walks.
const SHRINK_AFTER: u32 = 4096;

/// Stamp arrays up to this many slots (256 KiB) are never shrunk.
const KEEP_SLOTS: usize = 1 << 16;

impl Stamps {
    /// `tags` consecutive tags never written since the last wipe, the first returned; `len`
    /// slots are addressable afterwards. O(1) amortised (O(len) on growth or wrap).
    pub(crate) fn fresh(&mut self, len: usize, tags: u32) -> u32 {
        if self.marks.len() < len {
            self.marks.resize(len, 0);
        }
        self.small_walks = if len < self.marks.len() / 4 { self.small_walks + 1 } else { 0 };
        if self.small_walks >= SHRINK_AFTER && self.marks.len() > KEEP_SLOTS {
            // the tags of the slots kept stay valid: nothing to wipe
            self.marks.truncate(len.max(KEEP_SLOTS));
            self.marks.shrink_to_fit();
            self.small_walks = 0;
        }
        if self.last > u32::MAX - tags {
            self.marks.fill(0);
            self.last = 0;
        }
        let first = self.last + 1;
        self.last += tags;
        first
    }

    /// Marks slot d with `tag`.
    #[inline(always)]
    pub(crate) fn mark(&mut self, d: u32, tag: u32) {
        self.marks[d as usize] = tag;
    }

    /// Whether slot d carries `tag`.
    #[inline(always)]
    pub(crate) fn has(&self, d: u32, tag: u32) -> bool {
        self.marks[d as usize] == tag
    }
}

thread_local! {
    static STAMPS: std::cell::RefCell<Stamps> = std::cell::RefCell::new(Stamps::default());
}

/// Frees this thread's walk scratch: the orbit walks' visited marks (4 bytes per dart slot of
/// the largest map the thread walked since; they shrink by themselves only after many walks on
/// smaller maps). Call it on a long-lived thread that is done with a large map; the next walk
/// allocates again. Results are unchanged either way. O(1) (a deallocation).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::{AlphaMask, GMap};
///
/// let (points, tets) = kuhn_cube(3);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let d = map.darts().next().unwrap();
/// let before = map.orbit(d, AlphaMask::all(3)).len();
/// topomech::gmap::release_thread_caches();
/// assert_eq!(map.orbit(d, AlphaMask::all(3)).len(), before);
/// ```
pub fn release_thread_caches() {
    STAMPS.with(|cell| {
        if let Ok(mut stamps) = cell.try_borrow_mut() {
            *stamps = Stamps::default();
        }
    });
}

/// Runs `f` with this thread's [`Stamps`] (a private, fresh set if they are in use already, so a
/// nested walk is correct, only slower). `f` must not keep tags across calls.
pub(crate) fn with_stamps<R>(f: impl FnOnce(&mut Stamps) -> R) -> R {
    STAMPS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut stamps) => f(&mut stamps),
        Err(_) => f(&mut Stamps::default()),
    })
}

/// Orbits up to this many darts are walked with a linear scan of the darts found so far (no
/// stamps: cheaper for the small orbits of faces, edges and tets, and no cache miss in the
/// stamp array); larger ones switch to [`Stamps`].
const LINEAR_LIMIT: usize = 32;

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
    /// The darts of ⟨mask⟩(d) in breadth-first order, d first; empty when d is not a live dart.
    /// O(orbit · n).
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
    /// assert!(map.orbit(topomech::DartId(999), AlphaMask::all(3)).is_empty()); // no such dart
    /// ```
    pub fn orbit(&self, d: DartId, mask: AlphaMask) -> Vec<DartId> {
        if !self.contains(d) {
            return Vec::new();
        }
        let (gens, len) = generators(N, mask);
        let gens = &gens[..len];
        let mut out = vec![d];
        let mut head = 0;
        while head < out.len() {
            if out.len() > LINEAR_LIMIT {
                self.orbit_stamped(&mut out, head, gens);
                break;
            }
            let x = out[head];
            head += 1;
            let row = self.alpha_row(x.0);
            for &i in gens {
                let y = DartId(row[i]);
                if y != x && !out.contains(&y) {
                    out.push(y);
                }
            }
        }
        out
    }

    /// Continues the breadth-first walk of [`GMap::orbit`] from `head` with stamps: same order.
    fn orbit_stamped(&self, out: &mut Vec<DartId>, mut head: usize, gens: &[usize]) {
        out.reserve(4 * out.len());
        with_stamps(|stamps| {
            let tag = stamps.fresh(self.capacity(), 1);
            for &x in out.iter() {
                stamps.mark(x.0, tag);
            }
            while head < out.len() {
                let x = out[head];
                head += 1;
                let row = self.alpha_row(x.0);
                for &i in gens {
                    let y = row[i];
                    if !stamps.has(y, tag) {
                        stamps.mark(y, tag);
                        out.push(DartId(y));
                    }
                }
            }
        })
    }

    /// The darts of the i-cell of d, ⟨⟩N−{i}(d); empty for i > n or a dart that is not live.
    /// O(cell · n).
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
    /// assert!(map.cell_darts(5, d).is_empty()); // no 5-cells in a 3-map
    /// ```
    pub fn cell_darts(&self, i: usize, d: DartId) -> Vec<DartId> {
        if i > N {
            return Vec::new();
        }
        self.orbit(d, AlphaMask::cell(N, i))
    }

    /// Whether b lies in ⟨mask⟩(a) (false when either is not a live dart). Walks from a and b
    /// at once and stops as soon as the walks meet or one of them is exhausted, so the cost is
    /// O(min(|orbit(a)|, |orbit(b)|) · n) when the orbits differ.
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
    /// assert!(!map.same_orbit(d, topomech::DartId(999), AlphaMask::all(3))); // no such dart
    /// ```
    pub fn same_orbit(&self, a: DartId, b: DartId, mask: AlphaMask) -> bool {
        self.contains(a) && self.contains(b) && self.split_side(a, b, mask).is_none()
    }

    /// Walks ⟨mask⟩(a) and ⟨mask⟩(b) in lockstep. `None` if they are one orbit; otherwise the
    /// darts of the orbit that was exhausted first (the smaller one, up to one step) and whether
    /// it is b's.
    pub(crate) fn split_side(&self, a: DartId, b: DartId, mask: AlphaMask) -> Option<(Vec<DartId>, bool)> {
        if a == b {
            return None;
        }
        let (gens, len) = generators(N, mask);
        let gens = &gens[..len];
        let mut walk = Lockstep { queue: [Vec::with_capacity(16), Vec::with_capacity(16)], head: [0, 0] };
        walk.queue[0].push(a);
        walk.queue[1].push(b);
        loop {
            if walk.queue[0].len() + walk.queue[1].len() > LINEAR_LIMIT {
                return with_stamps(|stamps| walk.finish_stamped(self, gens, stamps));
            }
            for side in 0..2 {
                let Some(x) = walk.next(side) else { return Some(walk.take(side)) };
                let row = self.alpha_row(x.0);
                for &i in gens {
                    let y = DartId(row[i]);
                    if y == x {
                        continue;
                    }
                    if walk.queue[1 - side].contains(&y) {
                        return None;
                    }
                    if !walk.queue[side].contains(&y) {
                        walk.queue[side].push(y);
                    }
                }
            }
        }
    }

    /// One dart per i-cell: for each live i-cell id, the smallest dart carrying it (none for
    /// i > n). O(capacity).
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
        if i > N {
            return Vec::new();
        }
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
    /// independent oracle for [`GMap::one_dart_per_cell`] (none for i > n). O(darts · n).
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
        if i > N {
            return out; // no i-cells, as in `one_dart_per_cell`
        }
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

    /// Sets every live dart's i-cell ids, for every i, from the links alone: the i-cells
    /// numbered 0, 1, … in increasing order of their smallest darts (the order of
    /// [`GMap::one_dart_per_cell_by_traversal`]), and each id allocator set to exactly those ids.
    /// One union-find sweep per dimension ([`GMap::for_each_orbit`]'s), then one labelling pass
    /// in dart order: a root is the smallest dart of its tree, so it is labelled before its
    /// tree's other darts. For bulk builders whose links are set but ids are not.
    /// O(darts · n² · α(darts)), two u32 per dart slot of scratch.
    pub(crate) fn label_cells_raw(&mut self) {
        let cap = self.capacity();
        let mut forest: Vec<u32> = Vec::with_capacity(cap);
        let mut label = vec![u32::MAX; cap];
        for dim in 0..=N {
            let (gens, len) = generators(N, AlphaMask::cell(N, dim));
            forest.clear();
            forest.extend(0..cap as u32);
            self.for_each_live(|d| {
                join_with_smaller(&mut forest, d, self.alpha_row(d), &gens[..len]);
            });
            let mut next = 0u32;
            self.for_each_live(|d| {
                let root = find_root(&mut forest, d);
                label[d as usize] = if root == d {
                    next += 1;
                    next - 1
                } else {
                    label[root as usize]
                };
            });
            for (row, &id) in self.cell.chunks_exact_mut(N + 1).zip(&label) {
                if id != u32::MAX {
                    row[dim] = id;
                }
            }
            self.set_id_alloc_raw(dim, next, Vec::new());
        }
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

    /// The ids of the i-cells incident to d's j-cell, each once; empty for i or j > n or a dart
    /// that is not live. O(j-cell · n).
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
    /// assert!(map.incident_cells(d, 9, 0).is_empty() && map.incident_cells(d, 0, 9).is_empty());
    /// ```
    pub fn incident_cells(&self, d: DartId, j: usize, i: usize) -> Vec<CellId> {
        if i > N {
            return Vec::new();
        }
        let mut ids: Vec<CellId> = self.cell_darts(j, d).into_iter().map(|e| self.cell_id(i, e)).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}

impl<const N: usize> GMap<N> {
    /// Calls `f` once on every dart of the two-generator orbit ⟨αj, αk⟩(d), d first, with no
    /// visited set: such an orbit is a cycle or a path of alternating αj, αk links, walked from d
    /// one way (αj first) until it closes or ends, then the other way. Returns whether it closed:
    /// then the darts came in cycle order, the t-th and the next one (the last and d) linked by
    /// αj for even t, by αk for odd t. O(orbit).
    pub(crate) fn for_each_dihedral(&self, d: DartId, j: usize, k: usize, mut f: impl FnMut(DartId)) -> bool {
        f(d);
        for gens in [[j, k], [k, j]] {
            let mut x = d;
            for step in 0..=self.capacity() {
                let y = self.alpha_local(gens[step % 2], x);
                if y == x {
                    break; // an end of the path: walk the other way from d
                }
                if y == d {
                    return true; // the cycle closed: every dart was visited
                }
                f(y);
                x = y;
            }
        }
        false
    }
}

impl<const N: usize> GMap<N> {
    /// Whether every live dart is known to lie in a closed tetrahedron as [`GMap::from_tets`]
    /// built it: true from that builder until the first write that may change an αi link with
    /// i < 3 or add a dart (α3 sews and unsews keep it). When true, every volume is a closed
    /// tetrahedron whose darts 24t … 24t + 23 are linked by α0, α1, α2 in the builder's fixed
    /// pattern, so those links need not be read nor checked. False proves nothing; always false for
    /// n ≠ 3. A law of [`GMap::validate`] (`Law::TetLayout`). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// assert!(map.tets_as_built());
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// map.unsew::<3>(d).unwrap(); // a face dissociation keeps every tet closed
    /// assert!(map.tets_as_built());
    /// map.unsew::<2>(d).unwrap(); // opens a tet
    /// assert!(!map.tets_as_built());
    /// ```
    #[inline]
    pub fn tets_as_built(&self) -> bool {
        self.tets_as_built
    }
}

impl GMap<3> {
    /// The distinct volume ids around the vertex of d, sorted: the vertex orbit ⟨α1, α2, α3⟩(d)
    /// walked as its corners ⟨α1, α2⟩ (each inside one volume, walked by [`GMap::for_each_dihedral`])
    /// joined by α3, one id per corner, no list of darts. O(vertex orbit).
    pub(crate) fn vertex_volumes(&self, d: DartId) -> Vec<CellId> {
        let mut volumes = Vec::with_capacity(32);
        self.for_each_corner(d, |c, x| {
            if x == c {
                volumes.push(self.cell_id(3, c)); // once per corner: the corner's first dart
            }
        });
        volumes.sort_unstable();
        volumes.dedup();
        volumes
    }

    /// Calls `visit(c, x)` once on every dart x of the vertex orbit ⟨α1, α2, α3⟩(d), corner by
    /// corner: the darts of one corner ⟨α1, α2⟩ (inside one volume) come together, c being the
    /// dart the corner was entered by (d for the first), visited first. Corners are joined by α3
    /// and marked with this thread's stamps; no list of darts is built. A corner that is a closed
    /// hexagon (every corner of a tetrahedron) is read by [`GMap::hexagon`] — two chains of three
    /// dependent loads instead of a cycle of six, its darts kept until visited — others by
    /// [`GMap::for_each_dihedral`]. `visit` must not walk orbits itself (a nested walk would get
    /// private stamps: correct, but it allocates). O(vertex orbit).
    pub(crate) fn for_each_corner(&self, d: DartId, mut visit: impl FnMut(DartId, DartId)) {
        // A corner waiting to be visited: its six darts, or (entry dart, `None`) for another shape.
        type Pending = (DartId, Option<[DartId; 6]>);
        let mut stack: [Pending; 32] = [(d, None); 32];
        let mut spill: Vec<Pending> = Vec::new();
        let mut len = 0;
        with_stamps(|stamps| {
            let tag = stamps.fresh(self.capacity(), 1);
            let enter = |c: DartId, stamps: &mut Stamps| -> Pending {
                let six = self.hexagon(c);
                match six {
                    Some(darts) => darts.iter().for_each(|x| stamps.mark(x.0, tag)),
                    None => _ = self.for_each_dihedral(c, 1, 2, |x| stamps.mark(x.0, tag)),
                }
                (c, six)
            };
            let first = enter(d, stamps);
            let mut next = Some(first);
            while let Some((c, six)) = next {
                let mut step = |x: DartId| {
                    visit(c, x);
                    let y = self.alpha::<3>(x);
                    if y != x && !stamps.has(y.0, tag) {
                        let pending = enter(y, stamps);
                        if len < stack.len() {
                            stack[len] = pending;
                            len += 1;
                        } else {
                            spill.push(pending);
                        }
                    }
                };
                match six {
                    Some(darts) => darts.into_iter().for_each(&mut step),
                    None => _ = self.for_each_dihedral(c, 1, 2, step),
                }
                next = spill.pop().or_else(|| {
                    len = len.checked_sub(1)?;
                    Some(stack[len])
                });
            }
        });
    }

    /// The corner ⟨α1, α2⟩(c) as six distinct darts (c, α1 c, α2 c, α2 α1 c, α1 α2 c,
    /// α1 α2 α1 c) if it is a closed hexagon, i.e. α1 α2 α1 c = α2 α1 α2 c (every corner of a
    /// tetrahedron); `None` otherwise. Two independent chains of three loads. O(1).
    #[inline]
    pub(crate) fn hexagon(&self, c: DartId) -> Option<[DartId; 6]> {
        let (a1, a2) = (self.alpha_local(1, c), self.alpha_local(2, c));
        let (a21, a12) = (self.alpha_local(2, a1), self.alpha_local(1, a2));
        let (a121, a212) = (self.alpha_local(1, a21), self.alpha_local(2, a12));
        let darts = [c, a1, a2, a21, a12, a121];
        if self.tets_as_built {
            // Every corner of a tet as built is a closed hexagon of six distinct darts (the
            // layout law, checked at every dart by `mark_tets_as_built` in debug builds).
            return Some(darts);
        }
        let distinct = (0..6).all(|i| (i + 1..6).all(|j| darts[i] != darts[j]));
        (a121 == a212 && distinct).then_some(darts)
    }

    /// Sets the flag of [`GMap::tets_as_built`]: for the builder, whose tets are closed by
    /// construction (checked at every dart in debug builds). O(1) (O(darts) in debug builds).
    pub(crate) fn mark_tets_as_built(&mut self) {
        debug_assert!(self.darts().all(|d| self.closed_tet_darts(d).is_some()), "a built tet is not closed");
        self.tets_as_built = true;
    }

    /// The darts w(d) for the 24 words w of [`TetWords`] if they are closed under α0, α1, α2 —
    /// then they are exactly the volume orbit ⟨α0, α1, α2⟩(d) (possibly with repeats, for a
    /// folded volume); `None` otherwise (a volume that is not a closed tetrahedron, such as one
    /// being taken apart). 23 + 2 · 13 lookups, no visited set. O(1).
    pub(crate) fn closed_tet_darts(&self, d: DartId) -> Option<[DartId; 24]> {
        let words = TetWords::get();
        let mut darts = [d; 24];
        for (k, &(parent, g)) in words.tree.iter().enumerate().skip(1) {
            darts[k] = self.alpha_dyn(g as usize, darts[parent as usize]);
        }
        let closed =
            words.extra.iter().all(|&(a, g, b)| self.alpha_dyn(g as usize, darts[a as usize]) == darts[b as usize]);
        closed.then_some(darts)
    }
}

/// The 24 flags of a tetrahedron as words in α0, α1, α2 from one of them: a breadth-first
/// spanning tree of the flag graph of a tet as [`GMap::from_tets`] lays it out (`tree[k]` =
/// (parent, generator), `tree[0]` the root) and its 13 other links (`extra`: (a, g, b) with
/// αg(flag a) = flag b). A set of darts w(d) closed under these links is closed under α0, α1,
/// α2: every (flag, generator) is a tree link or an extra link, both ways.
///
/// Built from the builder's link pattern itself ([`crate::build::built_tet_link`]), not from a
/// built map: building a map checks its tets with these words in debug builds, so building one
/// here would re-enter the initialisation of the words (a deadlock of the `OnceLock`, which hung
/// every debug build's first `from_tets`; test `tet_words_build_in_debug_builds`).
struct TetWords {
    tree: [(u8, u8); 24],
    extra: Vec<(u8, u8, u8)>,
}

impl TetWords {
    fn get() -> &'static TetWords {
        static WORDS: std::sync::OnceLock<TetWords> = std::sync::OnceLock::new();
        WORDS.get_or_init(TetWords::build)
    }

    fn build() -> TetWords {
        let link = |g: usize, x: DartId| DartId(crate::build::built_tet_link(g, x.0));
        let mut index = [u8::MAX; 24];
        let mut order = vec![DartId(0)];
        let mut tree = [(0u8, 0u8); 24];
        index[0] = 0;
        let mut extra = Vec::new();
        let mut head = 0;
        while head < order.len() {
            let x = order[head];
            for g in 0..3 {
                let y = link(g, x);
                if index[y.index()] == u8::MAX {
                    index[y.index()] = order.len() as u8;
                    tree[order.len()] = (head as u8, g as u8);
                    order.push(y);
                } else if index[y.index()] as usize > head && tree[index[y.index()] as usize] != (head as u8, g as u8) {
                    extra.push((head as u8, g as u8, index[y.index()]));
                }
            }
            head += 1;
        }
        assert_eq!((order.len(), extra.len()), (24, 13), "a tetrahedron has 24 flags and 36 links");
        TetWords { tree, extra }
    }
}

/// The state of [`GMap::split_side`]: two breadth-first walks, each queue holding every dart its
/// side has found (so the queues are also the visited sets while they are small).
struct Lockstep {
    queue: [Vec<DartId>; 2],
    head: [usize; 2],
}

impl Lockstep {
    /// The next dart of `side` to expand, or `None` if that side is exhausted.
    #[inline]
    fn next(&mut self, side: usize) -> Option<DartId> {
        let x = self.queue[side].get(self.head[side]).copied()?;
        self.head[side] += 1;
        Some(x)
    }

    /// The exhausted side's darts and whether it is b's (side 1).
    fn take(&mut self, side: usize) -> (Vec<DartId>, bool) {
        (std::mem::take(&mut self.queue[side]), side == 1)
    }

    /// Continues the lockstep walk with stamps (tag t for side 0, t + 1 for side 1): the same
    /// visiting order and the same answer as the linear phase would give.
    fn finish_stamped<const N: usize>(
        &mut self,
        map: &GMap<N>,
        gens: &[usize],
        stamps: &mut Stamps,
    ) -> Option<(Vec<DartId>, bool)> {
        let tag = stamps.fresh(map.capacity(), 2);
        for side in 0..2 {
            for &x in &self.queue[side] {
                stamps.mark(x.0, tag + side as u32);
            }
        }
        loop {
            for side in 0..2 {
                let Some(x) = self.next(side) else { return Some(self.take(side)) };
                let (own, other) = (tag + side as u32, tag + 1 - side as u32);
                let row = map.alpha_row(x.0);
                for &i in gens {
                    let y = row[i];
                    if y == x.0 {
                        continue;
                    }
                    if stamps.has(y, other) {
                        return None;
                    }
                    if !stamps.has(y, own) {
                        stamps.mark(y, own);
                        self.queue[side].push(DartId(y));
                    }
                }
            }
        }
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

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    /// The shrink rule's boundary: walks addressing exactly a quarter of the stamp array are not
    /// small (the array is kept however many there are); one slot less, and after
    /// `SHRINK_AFTER` of them in a row it shrinks to what they address (at least `KEEP_SLOTS`).
    /// Fresh tags stay fresh across the shrink.
    #[test]
    fn stamps_shrink_only_after_walks_below_a_quarter() {
        use super::{Stamps, KEEP_SLOTS, SHRINK_AFTER};
        let big = 8 * KEEP_SLOTS;
        let mut s = Stamps::default();
        let mut last = s.fresh(big, 1);
        for _ in 0..2 * SHRINK_AFTER {
            let t = s.fresh(big / 4, 1);
            assert!(t > last);
            last = t;
        }
        assert_eq!(s.marks.len(), big, "a quarter is not below a quarter");
        for _ in 0..SHRINK_AFTER - 1 {
            s.fresh(big / 4 - 1, 1);
        }
        assert_eq!(s.marks.len(), big, "not yet: one walk short");
        let t = s.fresh(big / 4 - 1, 1);
        assert_eq!(s.marks.len(), big / 4 - 1);
        assert!(t > last);
    }

    /// The tet words, built from the layout pattern with no map, are those of a breadth-first
    /// walk over a built lone tet's α0, α1, α2; and building them builds no map (that re-entered
    /// their own initialisation from `from_tets`' debug check: every debug build hung). Run with
    /// debug assertions (`cargo test --lib`, as `.ci/run` does) the first `from_tets` below is
    /// the one that used to hang; it runs in a thread, so a regression fails instead of hanging.
    #[test]
    fn tet_words_build_in_debug_builds() {
        let (sent, got) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let built = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).map(|(tet, _)| tet);
            let _ = sent.send(built);
        });
        let tet = got
            .recv_timeout(std::time::Duration::from_secs(120))
            .expect("from_tets did not return in 120 s (the tet words' initialisation re-entered?)")
            .unwrap();
        let words = super::TetWords::build();
        let mut darts = [DartId(0); 24];
        for (k, &(parent, g)) in words.tree.iter().enumerate().skip(1) {
            darts[k] = tet.alpha_dyn(usize::from(g), darts[usize::from(parent)]);
        }
        let distinct: HashSet<DartId> = darts.iter().copied().collect();
        assert_eq!(distinct.len(), 24, "the tree reaches every flag of the tet once");
        for &(a, g, b) in &words.extra {
            assert_eq!(tet.alpha_dyn(usize::from(g), darts[usize::from(a)]), darts[usize::from(b)]);
        }
        assert_eq!(words.extra.len(), 13);
    }

    use super::*;
    use crate::generate::kuhn_cube;

    /// Breadth-first orbit with a hash set: the reference for [`GMap::orbit`]'s order.
    fn orbit_reference<const N: usize>(map: &GMap<N>, d: DartId, mask: AlphaMask) -> Vec<DartId> {
        let (mut out, mut seen, mut head) = (vec![d], HashSet::from([d]), 0);
        while head < out.len() {
            let x = out[head];
            head += 1;
            for i in mask.indices().filter(|&i| i <= N) {
                let y = map.alpha_dyn(i, x);
                if seen.insert(y) {
                    out.push(y);
                }
            }
        }
        out
    }

    fn cut_cube() -> GMap<3> {
        let (points, tets) = kuhn_cube(3);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let inner: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
        for d in inner.into_iter().step_by(3) {
            map.unsew::<3>(d).unwrap();
        }
        map
    }

    /// `label_cells_raw` numbers the cells of every dimension 0, 1, … in the order of their
    /// smallest darts, consistently with the orbits (same id iff same reference orbit), and
    /// leaves a map that validates; on a cube cut into pieces with deleted darts in between
    /// (holes in the dart slots), scrambled ids first.
    #[test]
    fn label_cells_raw_numbers_the_orbits_by_their_smallest_dart() {
        let mut map = cut_cube();
        // Isolate one tet and delete its darts: dead slots among the live ones.
        let tet = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
        let darts = map.cell_darts(3, tet);
        for &d in &darts {
            for i in 0..=3 {
                if !map.is_free(i, d) {
                    map.unsew_dyn(i, d).unwrap();
                }
            }
        }
        for &d in &darts {
            map.delete_dart(d).unwrap();
        }
        let live: Vec<DartId> = map.darts().collect();
        for (k, &d) in live.iter().enumerate() {
            for dim in 0..=3 {
                map.set_cell_raw(dim, d, (k * 7 + dim) as u32 % 5); // wrong on purpose
            }
        }
        map.label_cells_raw();
        map.validate().unwrap();
        for dim in 0..=3 {
            let mask = AlphaMask::cell(3, dim);
            let mut smallest: Vec<DartId> = Vec::new();
            for &d in &live {
                let orbit = orbit_reference(&map, d, mask);
                let min = *orbit.iter().min().unwrap();
                if min == d {
                    smallest.push(d);
                }
                assert!(orbit.iter().all(|&x| map.cell_id(dim, x) == map.cell_id(dim, d)), "dim {dim}, {d}");
            }
            for (k, &d) in smallest.iter().enumerate() {
                assert_eq!(map.cell_id(dim, d).0 as usize, k, "dim {dim}: the k-th smallest root gets id k");
            }
            assert_eq!(map.cell_id_bound(dim), smallest.len());
        }
    }

    /// Orbits small (linear phase) and large (stamped phase, interior vertices have 144 darts)
    /// come out in the reference order; split_side agrees with the reference orbits.
    #[test]
    fn orbits_match_the_hash_set_walk() {
        let map = cut_cube();
        let mut large = 0;
        for dim in 0..=3 {
            let mask = AlphaMask::cell(3, dim);
            for d in map.darts().step_by(5) {
                let orbit = map.orbit(d, mask);
                assert_eq!(orbit, orbit_reference(&map, d, mask));
                large += usize::from(orbit.len() > LINEAR_LIMIT);
                let e = DartId((d.0 * 7919) % map.capacity() as u32);
                let joined = orbit.contains(&e);
                assert_eq!(map.same_orbit(d, e, mask), joined);
                if let Some((side, is_e)) = map.split_side(d, e, mask) {
                    let whole = orbit_reference(&map, if is_e { e } else { d }, mask);
                    assert_eq!(side.iter().collect::<HashSet<_>>(), whole.iter().collect::<HashSet<_>>());
                }
            }
        }
        assert!(large > 0, "no orbit exercised the stamped phase");
    }

    /// The lockstep walk with plain scans only (no filter, no stamps): the reference for
    /// [`GMap::split_side`]'s answer, side list order included.
    fn split_side_reference<const N: usize>(
        map: &GMap<N>,
        a: DartId,
        b: DartId,
        mask: AlphaMask,
    ) -> Option<(Vec<DartId>, bool)> {
        if a == b {
            return None;
        }
        let (mut queue, mut head) = ([vec![a], vec![b]], [0, 0]);
        loop {
            for side in 0..2 {
                let Some(&x) = queue[side].get(head[side]) else { return Some((queue[side].clone(), side == 1)) };
                head[side] += 1;
                for i in mask.indices().filter(|&i| i <= N) {
                    let y = map.alpha_dyn(i, x);
                    if y == x {
                        continue;
                    }
                    if queue[1 - side].contains(&y) {
                        return None;
                    }
                    if !queue[side].contains(&y) {
                        queue[side].push(y);
                    }
                }
            }
        }
    }

    /// The linear phase and the stamped phase of [`GMap::split_side`] give the plain scan's
    /// answer: the same side, its darts in the same order, on split and joined pairs of
    /// every cell dimension (vertex orbits exceed [`LINEAR_LIMIT`]).
    #[test]
    fn split_side_is_the_plain_lockstep() {
        let map = cut_cube();
        let (mut splits, mut joined) = (0, 0);
        for dim in 0..=3 {
            let mask = AlphaMask::cell(3, dim);
            for d in map.darts().step_by(7) {
                for e in [map.alpha::<0>(d), map.alpha::<3>(d), DartId((d.0 * 7919) % map.capacity() as u32)] {
                    let got = map.split_side(d, e, mask);
                    assert_eq!(got, split_side_reference(&map, d, e, mask), "dim {dim}, {d:?} {e:?}");
                    splits += usize::from(got.is_some());
                    joined += usize::from(got.is_none());
                }
            }
        }
        assert!(splits > 0 && joined > 0);
    }

    /// The two-generator walk visits each dart of ⟨αj, αk⟩ once, on cycles (inner edges) and
    /// on paths (boundary edges).
    #[test]
    fn dihedral_walks_visit_each_dart_once() {
        let map = cut_cube();
        for (j, k) in [(0, 1), (1, 2), (2, 3), (0, 2), (0, 3), (1, 3)] {
            for d in map.darts().step_by(3) {
                let mut seen = Vec::new();
                map.for_each_dihedral(d, j, k, |x| seen.push(x));
                let mut want = map.orbit(d, AlphaMask::of(&[j, k]));
                assert_eq!(seen[0], d);
                seen.sort_unstable();
                want.sort_unstable();
                assert_eq!(seen, want, "<a{j}, a{k}>({d})");
            }
        }
    }

    /// The corner walk finds the volumes of the whole vertex orbit.
    #[test]
    fn vertex_volumes_are_those_of_the_vertex_orbit() {
        let map = cut_cube();
        for d in map.darts().step_by(4) {
            let mut want: Vec<CellId> = map.cell_darts(0, d).iter().map(|&x| map.cell_id(3, x)).collect();
            want.sort_unstable();
            want.dedup();
            assert_eq!(map.vertex_volumes(d), want);
        }
    }

    /// The corner walk visits every dart of the vertex orbit once, corner by corner, each
    /// corner's entry dart first — on hexagonal corners and, after some α2 unsews, on open ones
    /// (the general path); `hexagon` answers only for closed hexagons.
    #[test]
    fn corner_walk_visits_the_vertex_orbit_once() {
        let mut map = cut_cube();
        let some: Vec<DartId> = map.darts().filter(|d| d.0 % 53 == 0).collect();
        for d in some {
            if !map.is_free(2, d) {
                map.unsew::<2>(d).unwrap();
            }
        }
        let (mut open, mut closed) = (0, 0);
        for d in map.darts().step_by(3) {
            let mut seen: Vec<(DartId, DartId)> = Vec::new();
            map.for_each_corner(d, |c, x| seen.push((c, x)));
            assert_eq!(seen[0], (d, d));
            let mut got: Vec<DartId> = seen.iter().map(|&(_, x)| x).collect();
            let mut want = map.cell_darts(0, d);
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want, "vertex orbit of {d}");
            let mut groups: Vec<DartId> = Vec::new();
            for (k, &(c, x)) in seen.iter().enumerate() {
                let corner = map.orbit(c, AlphaMask::of(&[1, 2]));
                assert!(corner.contains(&x));
                if k == 0 || seen[k - 1].0 != c {
                    assert_eq!(x, c, "a corner starts with its entry dart");
                    assert!(!groups.contains(&c), "corner of {c} visited twice");
                    groups.push(c);
                }
                match map.hexagon(c) {
                    Some(six) => {
                        let mut six = six.to_vec();
                        let mut corner = corner.clone();
                        six.sort_unstable();
                        corner.sort_unstable();
                        assert_eq!(six, corner);
                        closed += 1;
                    }
                    None => {
                        let path = corner.iter().any(|&y| map.is_free(1, y) || map.is_free(2, y));
                        assert!(path || corner.len() != 6, "a closed hexagon at {c} was missed");
                        open += 1;
                    }
                }
            }
        }
        assert!(open > 0 && closed > 0, "open {open}, closed {closed}");
    }

    /// Closed tets give their 24 darts; a tet opened inside (α2 unsewn) gives `None`.
    #[test]
    fn closed_tet_darts_are_the_volume_orbit() {
        let mut map = cut_cube();
        for d in map.darts().step_by(7) {
            let mut got = map.closed_tet_darts(d).unwrap().to_vec();
            let mut want = map.cell_darts(3, d);
            got.sort_unstable();
            want.sort_unstable();
            assert_eq!(got, want);
        }
        let d = DartId(0);
        map.unsew::<2>(d).unwrap();
        assert_eq!(map.closed_tet_darts(d), None);
        assert!(map.closed_tet_darts(DartId(24)).is_some()); // the next tet is intact
    }

    /// `tets_as_built` is up exactly while only α3 links changed since `from_tets`, and whenever
    /// it is up every dart's tet is closed: through α3 unsews and sews, then down after an α1
    /// unsew (and it stays down after sewing back: the flag is conservative), down after a new
    /// dart.
    #[test]
    fn tets_as_built_flag_follows_the_writes() {
        let all_closed = |map: &GMap<3>| map.darts().all(|d| map.closed_tet_darts(d).is_some());
        let mut map = cut_cube();
        assert!(map.tets_as_built() && all_closed(&map));
        let inner: Vec<DartId> = map.darts().filter(|&d| !map.is_free(3, d)).step_by(5).collect();
        for &d in &inner {
            if !map.is_free(3, d) {
                let e = map.alpha::<3>(d);
                map.unsew::<3>(d).unwrap();
                assert!(map.tets_as_built() && all_closed(&map));
                map.sew::<3>(d, e).unwrap();
                assert!(map.tets_as_built());
            }
        }
        let d = DartId(5);
        let e = map.alpha::<1>(d);
        map.unsew::<1>(d).unwrap();
        assert!(!map.tets_as_built() && !all_closed(&map));
        map.sew::<1>(d, e).unwrap();
        assert!(!map.tets_as_built() && all_closed(&map));
        let (mut fresh, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        assert!(fresh.tets_as_built());
        fresh.create_dart().unwrap();
        assert!(!fresh.tets_as_built());
    }

    /// The computed inner links of tets as built are the stored ones at every dart and index,
    /// after α3 unsews too; once the flag is down (an α2 unsew) `alpha_local` reads the rows.
    #[test]
    fn alpha_local_is_the_stored_link() {
        let same = |map: &GMap<3>| map.darts().all(|d| (0..=3).all(|i| map.alpha_local(i, d) == map.alpha_dyn(i, d)));
        let (points, tets) = crate::cut::ops::jittered_cube(2, 3);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        assert!(map.tets_as_built() && same(&map));
        let mut map2 = cut_cube();
        assert!(map2.tets_as_built() && same(&map2));
        map2.unsew::<2>(DartId(0)).unwrap();
        assert!(!map2.tets_as_built() && same(&map2));
        // Not vacuous: the pattern really is the builder's, and differs between tets only by offset.
        let d = map.darts().nth(30).unwrap();
        assert_eq!(map.alpha_local(2, d).0 / 24, d.0 / 24);
        let inner = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
        map.unsew::<3>(inner).unwrap();
        assert!(same(&map));
    }
}

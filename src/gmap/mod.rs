//! The n-dimensional generalized map (seed 000, §2.1).
//!
//! An n-G-map is G = (B, α0, …, αn) where B is a finite set of darts, every αi is an involution on
//! B, and αi∘αj is an involution whenever 0 ≤ i < i + 2 ≤ j ≤ n (the quasi-manifold law). A dart
//! with αi(d) = d is *i-free*; the αn-free darts form the boundary.
//!
//! # Layout
//! One generic implementation for every dimension `N` (1, 2 and 3 are tested). State lives in flat
//! arrays keyed by [`DartId`]: `alpha[d·(N+1) + i]` and `cell[d·(N+1) + i]`, the id of the i-cell
//! of d. For N = 3 that is 32 bytes per dart (topology and all four cell ids), plus one bit of
//! liveness. Freed dart slots are reused.
//!
//! # Layers of mutators
//! 1. crate-private raw links (`GMap::link_raw`) that may break validity;
//! 2. topological [`GMap::sew`] / [`GMap::unsew`] that sew whole orbits so the quasi-manifold law
//!    holds and keep cell ids exact, returning the [`CellChanges`] they made;
//! 3. (in `embedding`) the version that also splits and merges attributes.
//!
//! Every public mutator leaves the map valid. In debug builds a cheap local check runs on the
//! darts it touched; with the `expensive-checks` feature the full [`GMap::validate`] runs.

mod cells;
mod cells_tets;
mod cmap;
mod dart;
mod handle;
mod iso;
mod mark;
mod mask;
mod orbit;
mod sew;
mod validate;
mod validate_tets;

pub use cells::{CellCounts, MapSummary};
pub use cmap::CombinatorialMap;
pub use dart::{CellId, DartId};
pub use handle::{CellHandle, StaleCell};
pub use mark::{DartSet, Mark};
pub use mask::AlphaMask;
pub use orbit::release_thread_caches;
pub use sew::{CellChange, CellChanges, SewError, SplitSides};
pub use validate::{InvariantViolation, Law};

pub(crate) use orbit::{join_with_smaller, with_stamps};

/// A number no earlier call returned in this process (1, 2, 3, …): the identities of maps, bodies
/// and leveled-map states and the release stamps of cell ids all come from this one counter.
/// O(1).
pub(crate) fn next_unique() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

use dart::NONE;

/// Allocator of the ids of one cell dimension: dense ids, a free list, and a count of live ids;
/// with, per id, the stamp of its last release (its generation, for [`CellHandle`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct IdAlloc {
    pub(crate) next: u32,
    pub(crate) free: Vec<u32>,
    /// `released[id]`: the [`next_unique`] number drawn when `id` was last released, 0 if never;
    /// ids past the end: 0. Grown by a release only, so a map that never released an id holds
    /// none of it. No two releases share a stamp, in any map of the process (finding 332).
    pub(crate) released: Vec<u64>,
}

impl IdAlloc {
    fn alloc(&mut self) -> u32 {
        match self.free.pop() {
            Some(id) => id,
            None => {
                self.next += 1;
                self.next - 1
            }
        }
    }

    fn release(&mut self, id: u32) {
        debug_assert!(id < self.next, "releasing an id never allocated");
        self.free.push(id);
        let k = id as usize;
        if k >= self.released.len() {
            self.released.resize(k + 1, 0);
        }
        self.released[k] = next_unique();
    }

    /// The stamp of the last release of `id`, 0 if it was never released. O(1).
    pub(crate) fn generation(&self, id: u32) -> u64 {
        self.released.get(id as usize).copied().unwrap_or(0)
    }

    /// Number of live ids. O(1).
    pub(crate) fn live(&self) -> usize {
        self.next as usize - self.free.len()
    }
}

/// Errors of dart creation and deletion.
///
/// # Examples
///
/// ```
/// use topomech::gmap::DartError;
/// use topomech::{DartId, GMap};
///
/// let mut map = GMap::<2>::new();
/// let d = map.create_dart().unwrap();
/// assert!(matches!(map.delete_dart(DartId(7)), Err(DartError::NoSuchDart(DartId(7)))));
/// map.delete_dart(d).unwrap();
/// assert!(matches!(map.delete_dart(d), Err(DartError::NoSuchDart(x)) if x == d));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DartError {
    /// The id is past the end of the map or names a deleted dart.
    #[error("{0} does not exist in this map")]
    NoSuchDart(DartId),
    /// Only isolated darts (free for every αi) may be deleted.
    #[error("{dart} is not isolated: it is {i}-sewn to {other}; unsew it first")]
    NotIsolated {
        /// The dart to delete.
        dart: DartId,
        /// An involution for which it is not free.
        i: usize,
        /// Its αi image.
        other: DartId,
    },
    /// The map has 2^32 − 1 darts already.
    #[error("the map is full: {0} darts")]
    Full(usize),
    /// An involution index past the dimension: α{i} of an n-map with n = {n}.
    #[error("alpha index {i} out of range for a {n}-map")]
    BadIndex {
        /// The index given.
        i: usize,
        /// The map's dimension.
        n: usize,
    },
}

/// An n-dimensional generalized map with exact cell ids. See the [module docs](self).
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// assert_eq!(map.dimension(), 3);
/// assert_eq!(map.dart_count(), 24); // 4 faces × 3 edges × 2 ends
/// assert_eq!(map.count_cells().0, vec![4, 6, 4, 1]);
/// assert!(map.darts().all(|d| map.is_free(3, d))); // a lone tet: all on the boundary
/// assert_eq!(map.validate(), Ok(()));
/// ```
#[derive(Clone, Debug)]
pub struct GMap<const N: usize> {
    alpha: Vec<u32>,
    cell: Vec<u32>,
    alive: Vec<u64>,
    free_darts: Vec<u32>,
    n_alive: usize,
    ids: Vec<IdAlloc>,
    mark_pool: Vec<DartSet>,
    /// Every live dart lies in a closed tetrahedron as [`GMap::from_tets`] built it (its 24
    /// darts closed under α0, α1, α2): set by that builder only, cleared by every write that may
    /// change an αi link with i < n or add a dart. A conservative flag (false proves nothing); it
    /// lets the mechanics skip the per-face closure check. See [`GMap::tets_as_built`].
    tets_as_built: bool,
    /// The map's identity for [`CellHandle`]s: a [`next_unique`] number drawn when the map was
    /// made (empty, built or loaded), kept by its clones (finding 332).
    origin: u64,
}

impl<const N: usize> Default for GMap<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> GMap<N> {
    /// Number of involutions, n + 1.
    pub const ALPHAS: usize = N + 1;

    /// An empty map. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let map = GMap::<2>::new();
    /// assert_eq!(map.dart_count(), 0);
    /// assert_eq!(map.dimension(), 2);
    /// assert_eq!(map.count_cells().0, vec![0, 0, 0]);
    /// assert!(map.validate().is_ok());
    /// ```
    pub fn new() -> Self {
        const { assert!(N >= 1 && N <= 7, "dimension must be in 1..=7") };
        GMap {
            alpha: Vec::new(),
            cell: Vec::new(),
            alive: Vec::new(),
            free_darts: Vec::new(),
            n_alive: 0,
            ids: vec![IdAlloc::default(); N + 1],
            mark_pool: Vec::new(),
            tets_as_built: false,
            origin: next_unique(),
        }
    }

    /// The dimension n.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// assert_eq!(GMap::<3>::new().dimension(), 3);
    /// assert_eq!(GMap::<2>::ALPHAS, 3); // α0, α1, α2
    /// ```
    pub const fn dimension(&self) -> usize {
        N
    }

    /// Number of live darts. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(map.dart_count(), 24); // one dart per (vertex, edge, face) flag of the tet
    /// assert_eq!(map.darts().count(), map.dart_count());
    /// ```
    pub fn dart_count(&self) -> usize {
        self.n_alive
    }

    /// One past the largest dart index ever used: the length flat per-dart arrays need. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<1>::new();
    /// let a = map.create_dart().unwrap();
    /// let _b = map.create_dart().unwrap();
    /// map.delete_dart(a).unwrap();
    /// assert_eq!(map.dart_count(), 1);
    /// assert_eq!(map.capacity(), 2); // the freed slot still counts until it is reused
    /// ```
    pub fn capacity(&self) -> usize {
        self.alpha.len() / (N + 1)
    }

    /// Whether `d` names a live dart of this map. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{DartId, GMap};
    ///
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// assert!(map.contains(DartId(5)));
    /// assert!(!map.contains(DartId(6))); // a triangle has 6 darts
    /// ```
    #[inline]
    pub fn contains(&self, d: DartId) -> bool {
        let i = d.index();
        i < self.capacity() && self.alive[i / 64] & (1u64 << (i % 64)) != 0
    }

    /// The live darts in increasing order. O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<2>::new();
    /// let ids: Vec<_> = (0..3).map(|_| map.create_dart().unwrap()).collect();
    /// map.delete_dart(ids[1]).unwrap();
    /// assert_eq!(map.darts().collect::<Vec<_>>(), vec![ids[0], ids[2]]);
    /// ```
    pub fn darts(&self) -> impl Iterator<Item = DartId> + '_ {
        (0..self.capacity() as u32).map(DartId).filter(|&d| self.contains(d))
    }

    /// αi(d) with i checked at compile time. O(1). `d` must be live (debug-asserted).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let e = map.alpha::<0>(d);
    /// assert_ne!(e, d);
    /// assert_eq!(map.alpha::<0>(e), d); // α0 is an involution
    /// assert_ne!(map.vertex_id(e), map.vertex_id(d)); // ... that moves to the other end of the edge
    /// assert_eq!(map.alpha::<3>(d), d); // a lone tet: every dart is 3-free
    /// ```
    #[inline(always)]
    pub fn alpha<const I: usize>(&self, d: DartId) -> DartId {
        const { assert!(I <= N, "alpha index out of range for this dimension") };
        self.alpha_dyn(I, d)
    }

    /// αi(d) with i given at run time. O(1).
    ///
    /// # Panics
    /// If `i > n` or `d` is not below [`GMap::capacity`] (the hot-path accessor: a release build
    /// panics with the slice index, a debug build names the dart; [`GMap::try_alpha`] returns
    /// an error instead). A dead dart below the capacity: a debug build panics naming it, a
    /// release build reads its row (a dart is deleted isolated, so: itself).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// for d in map.darts() {
    ///     for i in 0..=3 {
    ///         assert_eq!(map.alpha_dyn(i, map.alpha_dyn(i, d)), d);
    ///     }
    ///     // the quasi-manifold law: α0∘α2 is an involution
    ///     let once = map.alpha_dyn(0, map.alpha_dyn(2, d));
    ///     assert_eq!(map.alpha_dyn(0, map.alpha_dyn(2, once)), d);
    /// }
    /// ```
    #[inline(always)]
    pub fn alpha_dyn(&self, i: usize, d: DartId) -> DartId {
        assert!(i <= N, "alpha index {i} out of range for a {N}-map");
        debug_assert!(self.contains(d), "{d:?} is not a live dart");
        DartId(self.alpha[d.index() * (N + 1) + i])
    }

    /// αi(d) as [`GMap::alpha_dyn`], but computed without reading d's row when it is an inner
    /// link of a tet as built (n = 3, i < 3 and [`GMap::tets_as_built`]): dart 24t + k is
    /// linked to 24t + `TET_LINKS[k][i]` then, the builder's fixed pattern. For walks that
    /// alternate α3 with inner links (rings around an edge, corners of a vertex): only the α3
    /// steps load a row, which halves their chain of dependent cache misses. O(1).
    #[inline(always)]
    pub(crate) fn alpha_local(&self, i: usize, d: DartId) -> DartId {
        if N == 3 && i < 3 && self.tets_as_built {
            DartId(crate::build::built_tet_link(i, d.0))
        } else {
            self.alpha_dyn(i, d)
        }
    }

    /// αi(d), or an error if `d` is not a live dart or i > n. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartError;
    /// use topomech::{DartId, GMap};
    ///
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// assert_eq!(map.try_alpha(2, DartId(0)), Ok(DartId(0))); // a lone triangle is 2-free
    /// assert_eq!(map.try_alpha(3, DartId(0)), Err(DartError::BadIndex { i: 3, n: 2 }));
    /// assert_eq!(map.try_alpha(1, DartId(6)), Err(DartError::NoSuchDart(DartId(6))));
    /// ```
    pub fn try_alpha(&self, i: usize, d: DartId) -> Result<DartId, DartError> {
        if i > N {
            return Err(DartError::BadIndex { i, n: N });
        }
        if !self.contains(d) {
            return Err(DartError::NoSuchDart(d));
        }
        Ok(self.alpha_dyn(i, d))
    }

    /// Whether d is i-free (αi(d) = d). O(1).
    ///
    /// # Panics
    /// As [`GMap::alpha_dyn`]: if `i > n` or `d` is not below [`GMap::capacity`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// // Two triangles sharing the diagonal of a unit square.
    /// let (points, triangles) = generate::grid_triangles(1);
    /// let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    /// assert_eq!(map.darts().filter(|&d| !map.is_free(2, d)).count(), 4);
    /// assert!(map.darts().all(|d| !map.is_free(0, d) && !map.is_free(1, d)));
    /// ```
    #[inline]
    pub fn is_free(&self, i: usize, d: DartId) -> bool {
        self.alpha_dyn(i, d) == d
    }

    /// Whether d is free for every αi. O(n).
    ///
    /// # Panics
    /// As [`GMap::alpha_dyn`]: if `d` is not below [`GMap::capacity`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<2>::new();
    /// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
    /// assert!(map.is_isolated(a));
    /// map.sew::<1>(a, b).unwrap();
    /// assert!(!map.is_isolated(a) && !map.is_isolated(b));
    /// ```
    pub fn is_isolated(&self, d: DartId) -> bool {
        (0..=N).all(|i| self.is_free(i, d))
    }

    /// The i-sewn pairs {d, αi(d)} with d < αi(d), each once (none for i > n). O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, triangles) = generate::grid_triangles(1);
    /// let (map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    /// let pairs: Vec<_> = map.sewn_pairs(2).collect();
    /// assert_eq!(pairs.len(), 2); // the shared diagonal: two darts on each side
    /// assert!(pairs.iter().all(|&(d, e)| d < e && map.alpha::<2>(d) == e));
    /// ```
    pub fn sewn_pairs(&self, i: usize) -> impl Iterator<Item = (DartId, DartId)> + '_ {
        self.darts().take_while(move |_| i <= N).filter_map(move |d| {
            let e = self.alpha_dyn(i, d);
            (d < e).then_some((d, e))
        })
    }

    /// The id of the i-cell that contains d. O(1).
    ///
    /// # Panics
    /// If `i > n` or `d` is not below [`GMap::capacity`] (the hot-path accessor: a release build
    /// panics with the slice index, a debug build with the dimension or the index). A dead dart
    /// below the capacity returns `CellId(u32::MAX)`: no cell (deleting a dart clears its ids).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{CellId, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// for d in map.darts() {
    ///     // α1, α2, α3 stay in d's vertex and keep its id; α0 leaves it.
    ///     assert_eq!(map.cell_id(0, map.alpha::<1>(d)), map.cell_id(0, d));
    ///     assert_ne!(map.cell_id(0, map.alpha::<0>(d)), map.cell_id(0, d));
    ///     assert_eq!(map.cell_id(3, d), CellId(0)); // the volume id is the tet index
    /// }
    /// ```
    #[inline(always)]
    pub fn cell_id(&self, i: usize, d: DartId) -> CellId {
        assert!(i <= N, "cell dimension {i} out of range for a {N}-map");
        CellId(self.cell[d.index() * (N + 1) + i])
    }

    /// The vertex (0-cell) id of d. O(1).
    ///
    /// # Panics
    /// If `d` is not below [`GMap::capacity`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// // Vertex ids are the input point indices.
    /// let (map, _) = GMap::<3>::from_tets(6, &[[5, 1, 2, 3]]).unwrap();
    /// let mut ids: Vec<u32> = map.darts().map(|d| map.vertex_id(d).0).collect();
    /// ids.sort_unstable();
    /// ids.dedup();
    /// assert_eq!(ids, vec![1, 2, 3, 5]);
    /// ```
    #[inline(always)]
    pub fn vertex_id(&self, d: DartId) -> CellId {
        self.cell_id(0, d)
    }

    /// One past the largest live i-cell id: the length an array keyed by i-cell id needs (0 for
    /// i > n: there are no such cells). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// // Points 0 and 4 are unused: their vertex ids stay free, below the bound.
    /// let (map, report) = GMap::<3>::from_tets(6, &[[5, 1, 2, 3]]).unwrap();
    /// assert_eq!(report.unreferenced_points, vec![0, 4]);
    /// assert_eq!(map.cell_id_bound(0), 6);
    /// assert_eq!(map.count_cells().0[0], 4);
    /// ```
    pub fn cell_id_bound(&self, i: usize) -> usize {
        self.ids.get(i).map_or(0, |ids| ids.next as usize)
    }

    /// Whether `id` is a live i-cell id (false for i > n). O(free ids of dimension i).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{CellId, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(6, &[[5, 1, 2, 3]]).unwrap();
    /// assert!(map.is_live_cell(0, CellId(5)));
    /// assert!(!map.is_live_cell(0, CellId(4))); // point 4 is used by no tet
    /// assert!(!map.is_live_cell(3, CellId(1))); // only one volume
    /// ```
    pub fn is_live_cell(&self, i: usize, id: CellId) -> bool {
        self.ids.get(i).is_some_and(|ids| id.0 < ids.next && !ids.free.contains(&id.0))
    }

    /// Creates an isolated dart (free for every αi), reusing a freed slot if any. It is its own
    /// i-cell for every i and gets a fresh id in each dimension. Amortized O(n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<2>::new();
    /// let d = map.create_dart().unwrap();
    /// assert!(map.is_isolated(d));
    /// assert_eq!(map.count_cells().0, vec![1, 1, 1]); // its own vertex, edge and face
    /// map.validate().unwrap();
    /// ```
    pub fn create_dart(&mut self) -> Result<DartId, DartError> {
        let d = match self.free_darts.pop() {
            Some(d) => d,
            None => {
                let d = self.capacity();
                if d >= NONE as usize - 1 {
                    return Err(DartError::Full(d));
                }
                self.alpha.extend(std::iter::repeat_n(d as u32, N + 1));
                self.cell.extend(std::iter::repeat_n(NONE, N + 1));
                if d / 64 >= self.alive.len() {
                    self.alive.push(0);
                }
                d as u32
            }
        };
        let base = d as usize * (N + 1);
        for i in 0..=N {
            self.alpha[base + i] = d;
            self.cell[base + i] = self.ids[i].alloc();
        }
        self.alive[d as usize / 64] |= 1u64 << (d % 64);
        self.n_alive += 1;
        self.tets_as_built = false;
        self.after_mutation(&[DartId(d)]);
        Ok(DartId(d))
    }

    /// Deletes an isolated dart and frees its slot and cell ids. O(n).
    ///
    /// Errors: [`DartError::NoSuchDart`], [`DartError::NotIsolated`]; the map is unchanged then.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartError;
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<2>::new();
    /// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
    /// map.sew::<0>(a, b).unwrap();
    /// assert_eq!(map.delete_dart(a), Err(DartError::NotIsolated { dart: a, i: 0, other: b }));
    /// map.unsew::<0>(a).unwrap();
    /// map.delete_dart(a).unwrap();
    /// assert_eq!((map.dart_count(), map.contains(a)), (1, false));
    /// assert_eq!(map.delete_dart(a), Err(DartError::NoSuchDart(a)));
    /// ```
    pub fn delete_dart(&mut self, d: DartId) -> Result<(), DartError> {
        if !self.contains(d) {
            return Err(DartError::NoSuchDart(d));
        }
        if let Some(i) = (0..=N).find(|&i| !self.is_free(i, d)) {
            let other = self.alpha_dyn(i, d);
            return Err(DartError::NotIsolated { dart: d, i, other });
        }
        let base = d.index() * (N + 1);
        for i in 0..=N {
            let id = self.cell[base + i];
            self.ids[i].release(id);
            self.cell[base + i] = NONE;
        }
        self.alive[d.index() / 64] &= !(1u64 << (d.0 % 64));
        self.n_alive -= 1;
        self.free_darts.push(d.0);
        self.tets_as_built = false;
        self.after_mutation(&[]);
        Ok(())
    }

    /// Raw link αi(a) = b and αi(b) = a, with no check and no cell-id update. May break every
    /// law: only the crate's sew and builders use it, and they restore validity before returning.
    #[inline(always)]
    pub(crate) fn link_raw(&mut self, i: usize, a: DartId, b: DartId) {
        self.tets_as_built &= i == N;
        self.alpha[a.index() * (N + 1) + i] = b.0;
        self.alpha[b.index() * (N + 1) + i] = a.0;
    }

    /// Raw unlink: d and αi(d) become i-free. No check, no cell-id update.
    #[inline(always)]
    pub(crate) fn unlink_raw(&mut self, i: usize, d: DartId) {
        self.tets_as_built &= i == N;
        let e = self.alpha_dyn(i, d);
        self.alpha[d.index() * (N + 1) + i] = d.0;
        self.alpha[e.index() * (N + 1) + i] = e.0;
    }

    /// Raw write of the i-cell id of d.
    #[inline(always)]
    pub(crate) fn set_cell_raw(&mut self, i: usize, d: DartId, id: u32) {
        self.cell[d.index() * (N + 1) + i] = id;
    }

    /// Allocates `count` darts at once with every link free and every cell id unset: the start of
    /// a bulk build, or one dart of an operation. Returns the first index. The caller must link
    /// and label them all. An empty map gets exactly the room asked for (a build knows its size);
    /// a map that grows gets amortized room (at least doubling), so darts added one at a time
    /// cost O(1) each, not a reallocation of the whole map each (finding 224). O(count) amortized.
    pub(crate) fn alloc_darts_raw(&mut self, count: usize) -> u32 {
        self.tets_as_built = false;
        let first = self.capacity();
        let total = first + count;
        if first == 0 {
            self.alpha.reserve_exact(count * (N + 1));
            self.cell.reserve_exact(count * (N + 1));
        } else {
            self.alpha.reserve(count * (N + 1));
            self.cell.reserve(count * (N + 1));
        }
        for d in first..total {
            self.alpha.extend(std::iter::repeat_n(d as u32, N + 1));
        }
        self.cell.resize(total * (N + 1), NONE);
        self.alive.resize(total.div_ceil(64), 0);
        for d in first..total {
            self.alive[d / 64] |= 1u64 << (d % 64);
        }
        self.n_alive += count;
        first as u32
    }

    /// Reserves room for `count` more darts (rows), so that [`Self::push_rows_raw`] does not
    /// reallocate. The liveness words need ⌈(c + count)/64⌉ − ⌈c/64⌉ ≤ ⌈count/64⌉ more for c
    /// slots (equal when c is a multiple of 64). O(1) amortized.
    pub(crate) fn reserve_darts_raw(&mut self, count: usize) {
        self.alpha.reserve_exact(count * (N + 1));
        self.cell.reserve_exact(count * (N + 1));
        self.alive.reserve_exact(count.div_ceil(64));
    }

    /// Appends live darts whose rows are given (`alpha` and `cell`, n + 1 entries per dart, the
    /// layout of [`Self::rows_mut_raw`]): the write pass of a bulk refinement, one sequential
    /// write per row. Returns the first new index. The caller must leave every law true.
    /// O(rows).
    pub(crate) fn push_rows_raw(&mut self, alpha: &[u32], cell: &[u32]) -> u32 {
        self.tets_as_built = false;
        debug_assert_eq!(alpha.len(), cell.len());
        let first = self.capacity();
        let count = alpha.len() / (N + 1);
        let total = first + count;
        self.alpha.extend_from_slice(alpha);
        self.cell.extend_from_slice(cell);
        self.alive.resize(total.div_ceil(64), 0);
        // Whole words at once: bits lo..hi of word w.
        let mut d = first;
        while d < total {
            let (w, lo) = (d / 64, d % 64);
            let hi = (total - w * 64).min(64);
            self.alive[w] |= (u64::MAX >> (64 - (hi - lo))) << lo;
            d = w * 64 + hi;
        }
        self.n_alive += count;
        first as u32
    }

    /// A map whose darts are the rows of `alpha` and `cell` (n + 1 entries per dart), all live:
    /// the end of a bulk build, which sets the id allocators next and must leave every law true.
    pub(crate) fn from_rows_raw(alpha: Vec<u32>, cell: Vec<u32>) -> Self {
        debug_assert_eq!(alpha.len(), cell.len());
        let darts = alpha.len() / (N + 1);
        // Exactly one bit per dart: a `vec!` of the full words and then a `push` of the last one
        // doubled the capacity (finding 304: 32.25 bytes per dart instead of 32.125).
        let mut alive = Vec::with_capacity(darts.div_ceil(64));
        alive.resize(darts / 64, u64::MAX);
        if darts % 64 != 0 {
            alive.push((1u64 << (darts % 64)) - 1);
        }
        GMap { alpha, cell, alive, n_alive: darts, ..Self::new() }
    }

    /// The raw rows (αi and i-cell id of dart d at `d * (n + 1) + i`) for a bulk rewrite in place
    /// (`subdivide`'s uniform refinement). The caller must leave every law true.
    pub(crate) fn rows_mut_raw(&mut self) -> (&mut [u32], &mut [u32]) {
        self.tets_as_built = false;
        (&mut self.alpha, &mut self.cell)
    }

    /// Sets the id allocator of dimension i to "ids 0..next are used but those in `free`".
    /// The release stamps ([`CellHandle`] generations) stay: the bulk refinement appends ids.
    pub(crate) fn set_id_alloc_raw(&mut self, i: usize, next: u32, free: Vec<u32>) {
        let released = std::mem::take(&mut self.ids[i].released);
        self.ids[i] = IdAlloc { next, free, released };
    }

    /// The id allocator of dimension i as (next, free list): for the file format (`crate::store`).
    pub(crate) fn id_alloc_raw(&self, i: usize) -> (u32, &[u32]) {
        (self.ids[i].next, &self.ids[i].free)
    }

    /// The free dart slots in reuse order (the last is reused first): for `crate::store`.
    pub(crate) fn free_dart_slots_raw(&self) -> &[u32] {
        &self.free_darts
    }

    /// Raw one-sided write αi(d) = target (the partner row is not touched). For `crate::store`.
    pub(crate) fn set_alpha_raw(&mut self, i: usize, d: DartId, target: DartId) {
        self.tets_as_built = false;
        self.alpha[d.index() * (N + 1) + i] = target.0;
    }

    /// Raw: kills dart d (its row becomes free links and unset ids) and pushes its slot on the
    /// free-slot list, with no check and no cell-id release. For `crate::store`'s loader.
    pub(crate) fn kill_dart_raw(&mut self, d: DartId) {
        self.tets_as_built = false;
        let base = d.index() * (N + 1);
        for i in 0..=N {
            self.alpha[base + i] = d.0;
            self.cell[base + i] = NONE;
        }
        self.alive[d.index() / 64] &= !(1u64 << (d.0 % 64));
        self.n_alive -= 1;
        self.free_darts.push(d.0);
    }

    pub(crate) fn alloc_cell_id(&mut self, i: usize) -> u32 {
        self.ids[i].alloc()
    }

    pub(crate) fn release_cell_id(&mut self, i: usize, id: u32) {
        self.ids[i].release(id)
    }

    /// Checks run after every public mutation: local ones in debug builds, the full `validate()`
    /// under the `expensive-checks` feature. A failure is a bug in this library and panics.
    #[inline]
    pub(crate) fn after_mutation(&self, touched: &[DartId]) {
        #[cfg(debug_assertions)]
        if let Err(e) = self.validate_local(touched) {
            panic!("topomech bug: local invariant broken after a mutation: {e}");
        }
        let _ = touched;
        #[cfg(feature = "expensive-checks")]
        if let Err(e) = self.validate() {
            panic!("topomech bug: invariant broken after a mutation: {e}");
        }
    }

    /// Bytes used per live dart by topology and cell ids (not counting the mark pool). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let bytes = map.bytes_per_dart();
    /// assert!(bytes >= 32.0 && bytes < 64.0, "{bytes}"); // 4 links + 4 cell ids of 4 bytes each
    /// ```
    pub fn bytes_per_dart(&self) -> f64 {
        let bytes = (self.alpha.capacity() + self.cell.capacity()) * 4 + self.alive.capacity() * 8;
        bytes as f64 / self.n_alive.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Darts `lo..hi` are live, each with the given rows.
    fn check_rows(map: &GMap<2>, lo: u32, hi: u32, row: impl Fn(u32) -> ([u32; 3], [u32; 3])) {
        for d in lo..hi {
            assert!(map.contains(DartId(d)), "dart {d} should be live");
            let (alpha, cell) = row(d);
            assert_eq!(map.alpha_row(d), alpha, "links of {d}");
            assert_eq!(map.cell_row(d), cell, "cell ids of {d}");
        }
    }

    /// The bulk-build layer under `subdivide` and level extraction: darts allocated
    /// (`alloc_darts_raw`, free and unlabelled) and rows pushed (`push_rows_raw`) after a
    /// prefix whose length is no multiple of 64 (so the liveness words are filled from the
    /// middle, across several words) are all live, and only they, with their rows; writes
    /// through `rows_mut_raw` reach the map; `from_rows_raw` makes every row a live dart.
    /// `reserve_darts_raw(k)` leaves room for k more rows in each array (so that the pushes of a
    /// bulk refinement never reallocate), from slot counts on and off a word boundary.
    #[test]
    fn reserve_leaves_room_for_the_rows_pushed_after_it() {
        for (start, count) in [(128, 130), (128, 64), (180, 70), (0, 1), (64, 65), (63, 2)] {
            let mut map = GMap::<3>::new();
            if start > 0 {
                map.alloc_darts_raw(start);
            }
            assert_eq!(map.alive.len(), start.div_ceil(64));
            map.reserve_darts_raw(count);
            let total = start + count;
            let room = (map.alpha.capacity(), map.cell.capacity(), map.alive.capacity());
            assert!(room.0 >= 4 * total && room.1 >= 4 * total, "{start} + {count}: rows {room:?}");
            assert!(room.2 >= total.div_ceil(64), "{start} + {count}: liveness words {room:?}");
        }
    }

    #[test]
    fn bulk_rows_allocate_push_and_write_through() {
        let mut map = GMap::<2>::new();
        for _ in 0..70 {
            map.create_dart().unwrap();
        }
        let free = |d: u32| ([d; 3], [NONE; 3]);
        assert_eq!(map.alloc_darts_raw(10), 70); // fewer than the prefix
        assert_eq!(map.alloc_darts_raw(100), 80); // more than the prefix
        assert_eq!((map.capacity(), map.dart_count()), (180, 180));
        check_rows(&map, 70, 180, free);
        assert!(!map.contains(DartId(180)));
        map.reserve_darts_raw(130);
        let pushed = |d: u32| ([d, d, d], [7, d % 5, 9]);
        let (alpha, cell): (Vec<u32>, Vec<u32>) = (180..310)
            .flat_map(|d| {
                let (a, c) = pushed(d);
                a.into_iter().zip(c)
            })
            .unzip();
        assert_eq!(map.push_rows_raw(&alpha, &cell), 180);
        assert_eq!((map.capacity(), map.dart_count()), (310, 310));
        check_rows(&map, 180, 310, pushed);
        check_rows(&map, 70, 180, free); // the earlier darts are untouched
        assert!(!map.contains(DartId(310)) && map.darts().count() == 310);
        // The liveness words end with the slots: no bit past the last one (a later slot appended
        // by a raw writer must not find itself live already).
        assert_eq!(map.alive.len(), 310usize.div_ceil(64));
        assert_eq!(map.alive[4] >> (310 % 64), 0, "liveness bits past the last slot");
        let (alpha, _) = map.rows_mut_raw();
        alpha[3 * 75] = 76;
        alpha[3 * 76] = 75;
        assert_eq!(map.alpha_dyn(0, DartId(75)), DartId(76));
        let rows = (0..65u32).flat_map(|d| [d, d, d]).collect::<Vec<_>>();
        let map = GMap::<2>::from_rows_raw(rows.clone(), rows);
        assert_eq!(map.dart_count(), 65);
        check_rows(&map, 0, 65, |d| ([d; 3], [d; 3]));
        assert!(!map.contains(DartId(65)) && map.darts().count() == 65);
    }

    /// The net under every public mutation: a broken law next to the darts an operation touches
    /// is caught by `after_mutation` (local checks in debug builds, the full `validate()` under
    /// `expensive-checks`), and the operation panics naming the law, instead of returning as if
    /// the map were valid. The law is broken with a raw write (no public operation can break it),
    /// then two triangles are 2-sewn next to it. Builds with neither check do nothing there.
    #[test]
    #[cfg(any(debug_assertions, feature = "expensive-checks"))]
    #[should_panic(expected = "invariant broken after a mutation")]
    fn a_mutation_next_to_a_broken_law_panics() {
        let (mut map, _) = GMap::<2>::from_triangles(6, &[[0, 1, 2], [3, 4, 5]]).unwrap();
        let x = DartId(0);
        let y = map.darts().find(|&d| map.cell_id(2, d) != map.cell_id(2, x)).unwrap();
        assert!(map.is_sewable::<2>(x, y));
        // α1(x) is in x's face orbit ⟨α0, α1⟩ but now names another face; the 2-sew of x leaves
        // faces alone, so only the check can notice.
        let neighbour = map.alpha::<1>(x);
        let other = map.cell_id(2, y).0;
        map.set_cell_raw(2, neighbour, other);
        let _ = map.sew::<2>(x, y);
    }
}

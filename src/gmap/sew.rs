//! Topological i-sew and i-unsew (layer 2 of the mutators).
//!
//! To i-sew d1 and d2 is to set αi(x) = f(x) for every x of the orbit O1 = ⟨αj : |i − j| ≥ 2⟩(d1),
//! where f: O1 → O2 = ⟨αj : |i − j| ≥ 2⟩(d2) is the isomorphism with f(d1) = d2 and
//! f(αj(x)) = αj(f(x)). Sewing the whole orbit is exactly what keeps αi∘αj an involution for
//! every j ≥ i + 2 (and j ≤ i − 2). The sew is possible iff f exists, is a fixed-point-free
//! involution on O1 ∪ O2, and every dart of O1 ∪ O2 is i-free: [`GMap::is_sewable`].
//!
//! An i-sew merges, for every j ≠ i, the j-cells on both sides (the cell of d1's side keeps its
//! id); an i-unsew may split them (the side found smaller gets a fresh id). Both report what they
//! did as [`CellChanges`], which the embedding layer turns into attribute merges and splits.
//!
//! Cost: O(|O1| · n) for the links plus the size of the relabelled cells; an unsew also walks,
//! for each cell it might split, both sides in lockstep until they meet or the smaller one ends —
//! unless a cheap proof settles it first (`QuickLinks`: direct αk links between the unsewn darts,
//! and the rings ⟨αi±1, αi⟩ walked from both darts of each pair). For the α3-unsew of an inner
//! triangle that proof covers all three vertices and edges (three rings of tets around its edges)
//! and the face itself, so nothing is walked beyond the rings. What the proof leaves (a cell that
//! really split, as on every face of a tear's fan) is walked by a `Shortcut` where the cell's
//! orbit allows it — the edge as two paths of tets, the vertex corner by corner — with the
//! lockstep walk's answer.

use rustc_hash::FxHashMap;

use super::orbit::{generators, with_stamps, Stamps};
use super::{AlphaMask, CellId, DartId, GMap};

/// Why a sew or unsew was refused. The map is unchanged when one is returned.
///
/// # Examples
///
/// ```
/// use topomech::gmap::SewError;
/// use topomech::GMap;
///
/// let mut map = GMap::<2>::new();
/// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
/// assert!(matches!(map.unsew::<0>(a), Err(SewError::AlreadyFree { i: 0, .. })));
/// map.sew::<0>(a, b).unwrap();
/// assert!(matches!(map.sew::<0>(a, b), Err(SewError::NotFree { dart, i: 0, partner }) if (dart, partner) == (a, b)));
/// assert!(matches!(map.sew_dyn(5, a, b), Err(SewError::BadIndex { i: 5, n: 2 })));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SewError {
    /// A dart id that is not live in this map.
    #[error("{0} does not exist in this map")]
    NoSuchDart(DartId),
    /// αi with i > n.
    #[error("alpha index {i} is out of range for a {n}-map")]
    BadIndex {
        /// The index asked for.
        i: usize,
        /// The map's dimension.
        n: usize,
    },
    /// A dart of the orbit to sew is already i-sewn.
    #[error("{dart} is already {i}-sewn to {partner}")]
    NotFree {
        /// The dart.
        dart: DartId,
        /// The involution.
        i: usize,
        /// Its current αi image.
        partner: DartId,
    },
    /// The sew would make a dart its own αi image, or the two orbits overlap inconsistently.
    #[error("{i}-sewing {d1} with {d2} would link {dart} inconsistently (to itself or to two darts)")]
    NotInvolution {
        /// First dart given.
        d1: DartId,
        /// Second dart given.
        d2: DartId,
        /// Index of the sew.
        i: usize,
        /// Where the correspondence breaks.
        dart: DartId,
    },
    /// The orbits of the two darts are not isomorphic: following αj breaks the correspondence.
    #[error("{i}-sew of {d1} and {d2}: orbits differ at {at} along alpha{j} (the quasi-manifold law would break)")]
    OrbitsDiffer {
        /// First dart given.
        d1: DartId,
        /// Second dart given.
        d2: DartId,
        /// Index of the sew.
        i: usize,
        /// The dart of d1's orbit where the walks disagree.
        at: DartId,
        /// The involution followed.
        j: usize,
    },
    /// Unsewing a dart that is i-free.
    #[error("{dart} is {i}-free: nothing to unsew")]
    AlreadyFree {
        /// The dart.
        dart: DartId,
        /// The involution.
        i: usize,
    },
}

/// One change of cell identity made by a sew or an unsew.
///
/// # Examples
///
/// ```
/// use topomech::gmap::CellChange;
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let changes = map.unsew::<3>(d).unwrap();
/// // the shared triangle becomes two faces, one per tet
/// let face_split = changes.changes.iter().any(|c| matches!(c, CellChange::Split { dim: 2, .. }));
/// assert!(face_split);
/// assert_eq!(map.count_cells().0[2], 8);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellChange {
    /// Two `dim`-cells became one: `absorbed` no longer exists, its darts now carry `kept`.
    Merged {
        /// Dimension of the cells.
        dim: usize,
        /// The surviving id.
        kept: CellId,
        /// The id released.
        absorbed: CellId,
    },
    /// One `dim`-cell became two: the darts of one side (`dart_new` among them) now carry the
    /// fresh id `new`; the other side (`dart_kept` among them) keeps `kept`. A cell cut into
    /// three or more pieces by one operation is reported as one split per extra piece, each
    /// with its own `new`, `kept` staying with one piece; in every entry `dart_kept` and
    /// `dart_new` carry `kept` and `new` in the map as the operation leaves it (finding 276).
    Split {
        /// Dimension of the cells.
        dim: usize,
        /// The id that stays with one side.
        kept: CellId,
        /// The fresh id of the other side.
        new: CellId,
        /// A dart of the side that kept the id.
        dart_kept: DartId,
        /// A dart of the side with the new id.
        dart_new: DartId,
    },
}

/// Everything a sew or unsew changed in cell identities, in the order it happened.
///
/// Dropping a report hands its emptied lists to the next unsew on the same thread (the
/// crate-private `spare` module), so a loop of cuts and sews allocates nothing for its reports
/// once warm. Because of that `Drop`, move a list out with `std::mem::take`, not by
/// destructuring.
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let changes = map.unsew::<3>(d).unwrap();
/// assert_eq!(changes.pairs.len(), 6); // the 6 darts of one side of the shared triangle
/// assert!(changes.pairs.iter().all(|&(a, b)| map.is_free(3, a) && map.is_free(3, b)));
/// assert_eq!(changes.merges(2).count(), 0); // an unsew only splits
/// ```
#[derive(Debug, Clone, Default)]
pub struct CellChanges {
    /// The changes.
    pub changes: Vec<CellChange>,
    /// The pairs of darts linked or unlinked by αi.
    pub pairs: Vec<(DartId, DartId)>,
    /// For the splits an unsew found by walking, every dart of the new side (the cell that got
    /// the fresh id): [`CellChanges::new_side`]. Empty for a sew. Not compared by `==`.
    pub new_sides: SplitSides,
    /// Which operation returned the report, set by the embedding layer
    /// ([`crate::embedding::Embedded::sew`] / [`crate::embedding::Embedded::unsew`]): the
    /// embedded map's identity, its version after the operation and a fingerprint of the lists
    /// above (so an edited report no longer matches). `None` for the kernel's own reports and
    /// for `Default`. Not compared by `==`.
    pub(crate) stamp: Option<(u64, u64, u64)>,
}

/// The darts of the new side of the splits an unsew found by walking (the lockstep walk of
/// `GMap::split_side` lists the new side, the smaller one, before relabelling it): handed on
/// so that the rules and the projection records need not walk that cell again. Splits settled
/// without a walk (cheap proofs, small cells) have no entry. A by-product of how the kernel
/// found the splits, not part of the outcome: [`CellChanges`]' equality ignores it.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::GMap;
///
/// // Cut the cube k = 2 along the plane x = 1: the last face unsewn splits the centre vertex.
/// let (points, tets) = kuhn_cube(2);
/// let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let x = |d| points[map.vertex_id(d).index()][0];
/// let on_plane: Vec<_> = map.one_dart_per_cell(2).into_iter().filter(|&d| {
///     !map.is_free(3, d) && map.cell_darts(2, d).iter().all(|&e| x(e) == 1.0)
/// }).collect();
/// let mut walked = 0;
/// for d in on_plane {
///     let changes = map.unsew::<3>(d).unwrap();
///     for (k, (_, new, _, dart_new)) in changes.splits_with_index(0) {
///         let side = changes.new_side(k);
///         assert!(side.iter().all(|&e| map.vertex_id(e) == new));
///         assert!(side.is_empty() || side.len() == map.cell_darts(0, dart_new).len());
///         walked += usize::from(!side.is_empty());
///     }
/// }
/// assert!(walked > 0);
/// ```
#[derive(Debug, Clone, Default)]
pub struct SplitSides {
    /// Per recorded side: (index of the split in `changes`, end of its darts in `darts`); a
    /// side starts where the previous one ends.
    ends: Vec<(u32, u32)>,
    /// The darts of every recorded side, one side after the other (one buffer for all sides:
    /// an unsew allocates two lists for its sides, not one per side).
    darts: Vec<DartId>,
}

impl SplitSides {
    /// Where the darts of the next side go: a side is appended to this buffer, then
    /// [`SplitSides::close`]d (darts appended and not closed belong to no side: truncate them).
    fn open(&mut self) -> &mut Vec<DartId> {
        if self.darts.capacity() == 0 {
            // Room for both sides of the cells of a face (a walked split reads both sides):
            // the buffer is allocated once per unsew, not grown dart by dart.
            self.darts.reserve(Self::FIRST_CAPACITY);
        }
        &mut self.darts
    }

    /// Darts reserved at the first side.
    const FIRST_CAPACITY: usize = 128;

    /// The darts of the side being appended (those past the last closed side).
    fn pending(&self) -> &[DartId] {
        &self.darts[self.ends.last().map_or(0, |e| e.1 as usize)..]
    }

    /// Closes the appended darts as the new side of change k.
    fn close(&mut self, k: usize) {
        self.ends.push((k as u32, self.darts.len() as u32));
    }

    /// The darts of change k's new side; empty if none was recorded. O(recorded sides).
    fn get(&self, k: usize) -> &[DartId] {
        let Some(e) = self.ends.iter().position(|e| e.0 as usize == k) else { return &[] };
        let start = if e == 0 { 0 } else { self.ends[e - 1].1 as usize };
        &self.darts[start..self.ends[e].1 as usize]
    }
}

/// Two reports are equal when they list the same changes and the same pairs; `new_sides` is not
/// compared (which splits carry their side depends on the proofs the kernel found, not on the
/// outcome).
impl PartialEq for CellChanges {
    fn eq(&self, other: &Self) -> bool {
        self.changes == other.changes && self.pairs == other.pairs
    }
}

impl Eq for CellChanges {}

/// The buffers of a [`CellChanges`]: its changes and pairs, then its [`SplitSides`]' two lists.
type ChangeLists = ((Vec<CellChange>, Vec<(DartId, DartId)>), (Vec<(u32, u32)>, Vec<DartId>));

thread_local! {
    /// The lists of the [`CellChanges`] last dropped on this thread, for the next unsew
    /// (the crate-private `spare` module).
    static SPARE_LISTS: std::cell::Cell<Option<ChangeLists>> = const { std::cell::Cell::new(None) };
}

impl CellChanges {
    /// An empty report on this thread's spare lists. O(1).
    fn on_spare_lists() -> Self {
        let ((changes, pairs), (ends, darts)) = crate::spare::take(&SPARE_LISTS);
        CellChanges { changes, pairs, new_sides: SplitSides { ends, darts }, stamp: None }
    }
}

/// Gives the lists back to this thread's spare slot (the crate-private `spare` module); a
/// sew's report (no side lists) does not displace an unsew's. O(1).
impl Drop for CellChanges {
    fn drop(&mut self) {
        let SplitSides { ends, darts } = &mut self.new_sides;
        let lists = (
            (std::mem::take(&mut self.changes), std::mem::take(&mut self.pairs)),
            (std::mem::take(ends), std::mem::take(darts)),
        );
        crate::spare::give_back(&SPARE_LISTS, lists);
    }
}

impl CellChanges {
    /// Every dart of the new side of `changes[k]` (the whole cell that got the fresh id, in no
    /// particular order) when the unsew found that split by walking it ([`SplitSides`]); empty
    /// otherwise (a split settled without a walk, a merge, an index past the end). O(walked
    /// splits).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::CellChange;
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// let e = map.alpha::<3>(d);
    /// let changes = map.unsew::<3>(d).unwrap();
    /// for (k, change) in changes.changes.iter().enumerate() {
    ///     let CellChange::Split { dim, dart_new, .. } = *change else { unreachable!() };
    ///     let side = changes.new_side(k); // each empty, or the whole new cell
    ///     assert!(side.is_empty() || side.len() == map.cell_darts(dim, dart_new).len());
    /// }
    /// let merged = map.sew::<3>(d, e).unwrap();
    /// assert!(merged.new_side(0).is_empty());
    /// ```
    pub fn new_side(&self, k: usize) -> &[DartId] {
        self.new_sides.get(k)
    }

    /// [`CellChanges::splits`] with the index of each split in `changes` (for
    /// [`CellChanges::new_side`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// let changes = map.unsew::<3>(d).unwrap();
    /// let edges: Vec<_> = changes.splits_with_index(1).map(|(_, split)| split).collect();
    /// assert_eq!(edges, changes.splits(1).collect::<Vec<_>>());
    /// ```
    pub fn splits_with_index(
        &self,
        dim: usize,
    ) -> impl Iterator<Item = (usize, (CellId, CellId, DartId, DartId))> + '_ {
        self.changes.iter().enumerate().filter_map(move |(k, c)| match *c {
            CellChange::Split { dim: d, kept, new, dart_kept, dart_new } if d == dim => {
                Some((k, (kept, new, dart_kept, dart_new)))
            }
            _ => None,
        })
    }

    /// The splits of `dim`-cells, as (kept, new, dart_kept, dart_new).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// let changes = map.unsew::<3>(d).unwrap();
    /// for (kept, new, dart_kept, dart_new) in changes.splits(0) {
    ///     assert_eq!((map.vertex_id(dart_kept), map.vertex_id(dart_new)), (kept, new));
    /// }
    /// assert_eq!((changes.splits(0).count(), changes.splits(1).count()), (3, 3));
    /// ```
    pub fn splits(&self, dim: usize) -> impl Iterator<Item = (CellId, CellId, DartId, DartId)> + '_ {
        self.changes.iter().filter_map(move |c| match *c {
            CellChange::Split { dim: k, kept, new, dart_kept, dart_new } if k == dim => {
                Some((kept, new, dart_kept, dart_new))
            }
            _ => None,
        })
    }

    /// The merges of `dim`-cells, as (kept, absorbed).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// let e = map.alpha::<3>(d);
    /// map.unsew::<3>(d).unwrap();
    /// let changes = map.sew::<3>(d, e).unwrap();
    /// assert_eq!(changes.merges(0).count(), 3); // the three split vertices meet again
    /// assert!(changes.merges(0).all(|(kept, gone)| map.is_live_cell(0, kept) && !map.is_live_cell(0, gone)));
    /// ```
    pub fn merges(&self, dim: usize) -> impl Iterator<Item = (CellId, CellId)> + '_ {
        self.changes.iter().filter_map(move |c| match *c {
            CellChange::Merged { dim: k, kept, absorbed } if k == dim => Some((kept, absorbed)),
            _ => None,
        })
    }
}

/// A partial involution being built: dart → partner.
struct Pairing {
    small: Vec<(u32, u32)>,
    large: Option<FxHashMap<u32, u32>>,
}

impl Pairing {
    fn new() -> Self {
        Pairing { small: Vec::new(), large: None }
    }

    fn get(&self, x: DartId) -> Option<DartId> {
        match &self.large {
            Some(m) => m.get(&x.0).map(|&y| DartId(y)),
            None => self.small.iter().find(|p| p.0 == x.0).map(|p| DartId(p.1)),
        }
    }

    fn put(&mut self, x: DartId, y: DartId) {
        match &mut self.large {
            Some(m) => {
                m.insert(x.0, y.0);
            }
            None => {
                self.small.push((x.0, y.0));
                if self.small.len() > 32 {
                    self.large = Some(self.small.drain(..).collect());
                }
            }
        }
    }
}

impl<const N: usize> GMap<N> {
    fn check_index(i: usize) -> Result<(), SewError> {
        if i > N {
            return Err(SewError::BadIndex { i, n: N });
        }
        Ok(())
    }

    fn check_dart(&self, d: DartId) -> Result<(), SewError> {
        if !self.contains(d) {
            return Err(SewError::NoSuchDart(d));
        }
        Ok(())
    }

    /// The pairs an i-sew of d1 and d2 would link, or why it may not. O(|O1| · n).
    pub(crate) fn sew_pairs(&self, i: usize, d1: DartId, d2: DartId) -> Result<Vec<(DartId, DartId)>, SewError> {
        Self::check_index(i)?;
        self.check_dart(d1)?;
        self.check_dart(d2)?;
        let mask = AlphaMask::commuting_with(N, i);
        let mut pairing = Pairing::new();
        let mut pairs = Vec::new();
        self.pair_up(i, (d1, d2), (d1, d2), &mut pairing, &mut pairs)?;
        let mut head = 0;
        while head < pairs.len() {
            let (x, y) = pairs[head];
            head += 1;
            for j in mask.indices().filter(|&j| j <= N) {
                let (xj, yj) = (self.alpha_dyn(j, x), self.alpha_dyn(j, y));
                self.pair_up(i, (d1, d2), (xj, yj), &mut pairing, &mut pairs).map_err(|_| SewError::OrbitsDiffer {
                    d1,
                    d2,
                    i,
                    at: x,
                    j,
                })?;
            }
        }
        Ok(pairs)
    }

    /// Adds the pair (x, y) to the pairing if new, checking that both are i-free and that the
    /// pairing stays a fixed-point-free involution.
    fn pair_up(
        &self,
        i: usize,
        (d1, d2): (DartId, DartId),
        (x, y): (DartId, DartId),
        pairing: &mut Pairing,
        pairs: &mut Vec<(DartId, DartId)>,
    ) -> Result<(), SewError> {
        match (pairing.get(x), pairing.get(y)) {
            (Some(px), _) if px == y => return Ok(()),
            (Some(_), _) | (_, Some(_)) => return Err(SewError::NotInvolution { d1, d2, i, dart: x }),
            (None, None) => {}
        }
        if x == y {
            return Err(SewError::NotInvolution { d1, d2, i, dart: x });
        }
        for z in [x, y] {
            let partner = self.alpha_dyn(i, z);
            if partner != z {
                return Err(SewError::NotFree { dart: z, i, partner });
            }
        }
        pairing.put(x, y);
        pairing.put(y, x);
        pairs.push((x, y));
        Ok(())
    }

    /// Whether `sew::<I>(d1, d2)` would succeed. O(|O1| · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<2>::new();
    /// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
    /// assert!(map.is_sewable::<2>(a, b));
    /// assert!(!map.is_sewable::<2>(a, a)); // αi(a) = a would not be a link
    /// map.sew::<2>(a, b).unwrap();
    /// assert!(!map.is_sewable::<2>(a, b)); // both are 2-sewn now
    /// assert!(!map.is_sewable_dyn(3, a, b)); // no α3 in a 2-map
    /// ```
    pub fn is_sewable<const I: usize>(&self, d1: DartId, d2: DartId) -> bool {
        const { assert!(I <= N) };
        self.sew_pairs(I, d1, d2).is_ok()
    }

    /// Run-time-index version of [`GMap::is_sewable`]; false for i > n.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<2>::from_triangles(6, &[[0, 1, 2], [3, 4, 5]]).unwrap();
    /// let (a, b) = (map.darts().next().unwrap(), map.darts().nth(6).unwrap()); // one dart of each triangle
    /// assert!(map.is_sewable_dyn(2, a, b));
    /// assert!(!map.is_sewable_dyn(1, a, b)); // a is 1-sewn already
    /// assert!(!map.is_sewable_dyn(5, a, b)); // no α5
    /// ```
    pub fn is_sewable_dyn(&self, i: usize, d1: DartId, d2: DartId) -> bool {
        self.sew_pairs(i, d1, d2).is_ok()
    }

    /// I-sews d1 with d2, and with them the whole orbits ⟨αj : |i − j| ≥ 2⟩ of both, dart by dart, so the
    /// quasi-manifold law holds; cells that meet are merged and reported in the [`CellChanges`].
    /// Errors ([`SewError`]) leave the map unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// // Two separate triangles; glue edge {0, 1} of the first onto edge {3, 4} of the second.
    /// let (mut map, _) = GMap::<2>::from_triangles(6, &[[0, 1, 2], [3, 4, 5]]).unwrap();
    /// let on = |a, b| map.darts().find(|&d| map.vertex_id(d).0 == a && map.vertex_id(map.alpha::<0>(d)).0 == b);
    /// let (x, y) = (on(0, 1).unwrap(), on(3, 4).unwrap());
    /// let changes = map.sew::<2>(x, y).unwrap();
    /// assert_eq!(changes.merges(0).count(), 2); // 0 meets 3, 1 meets 4
    /// assert_eq!(changes.merges(1).count(), 1);
    /// assert_eq!(map.count_cells().0, vec![4, 5, 2]);
    /// assert_eq!(map.components().len(), 1);
    /// ```
    pub fn sew<const I: usize>(&mut self, d1: DartId, d2: DartId) -> Result<CellChanges, SewError> {
        const { assert!(I <= N) };
        self.sew_dyn(I, d1, d2)
    }

    /// Run-time-index version of [`GMap::sew`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::SewError;
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<1>::new();
    /// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
    /// assert_eq!(map.sew_dyn(2, a, b), Err(SewError::BadIndex { i: 2, n: 1 }));
    /// map.sew_dyn(0, a, b).unwrap(); // a segment: two darts, two vertices, one edge
    /// assert_eq!(map.count_cells().0, vec![2, 1]);
    /// ```
    pub fn sew_dyn(&mut self, i: usize, d1: DartId, d2: DartId) -> Result<CellChanges, SewError> {
        let pairs = self.sew_pairs(i, d1, d2)?;
        Ok(self.link_sew_pairs(i, d1, pairs))
    }

    /// Links `pairs`, the result of [`Self::sew_pairs`] for (i, d1, ·) on the map as it is, and
    /// merges the cells that meet. O(|pairs| · n + merged cells).
    pub(crate) fn link_sew_pairs(&mut self, i: usize, d1: DartId, pairs: Vec<(DartId, DartId)>) -> CellChanges {
        for &(x, y) in &pairs {
            self.link_raw(i, x, y);
        }
        let keep: Vec<u32> = (0..=N).map(|dim| self.cell_id(dim, d1).0).collect();
        let mut report = CellChanges { changes: Vec::new(), pairs, new_sides: SplitSides::default(), stamp: None };
        for k in 0..report.pairs.len() {
            let (x, y) = report.pairs[k];
            for dim in (0..=N).filter(|&dim| dim != i) {
                self.merge_cells(dim, x, y, keep[dim], &mut report.changes);
            }
        }
        self.after_mutation(&touched(&report.pairs));
        report
    }

    /// After a link, makes the dim-cells of x and y carry one id: x's, unless y's is `keep` (the
    /// id d1 had before the sew, which always survives when two cells merge).
    fn merge_cells(&mut self, dim: usize, x: DartId, y: DartId, keep: u32, changes: &mut Vec<CellChange>) {
        let (kx, ky) = (self.cell_id(dim, x).0, self.cell_id(dim, y).0);
        if kx == ky {
            return;
        }
        let (from_dart, kept, absorbed) = if ky == keep { (x, ky, kx) } else { (y, kx, ky) };
        self.relabel(dim, from_dart, AlphaMask::cell(N, dim), absorbed, kept);
        self.release_cell_id(dim, absorbed);
        changes.push(CellChange::Merged { dim, kept: CellId(kept), absorbed: CellId(absorbed) });
    }

    /// I-unsews d from αi(d), with the whole orbit ⟨αj : |i − j| ≥ 2⟩(d). Errors leave the map
    /// unchanged: [`SewError::AlreadyFree`] if d is i-free.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// // Cut the unit square along its diagonal.
    /// let (points, triangles) = generate::grid_triangles(1);
    /// let (mut map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(2, d)).unwrap();
    /// let changes = map.unsew::<2>(d).unwrap();
    /// assert_eq!(changes.splits(0).count(), 2); // both ends of the diagonal split
    /// assert_eq!(changes.splits(1).count(), 1);
    /// assert_eq!(map.count_cells().0, vec![6, 6, 2]);
    /// assert!(map.unsew::<2>(d).is_err()); // already free
    /// ```
    pub fn unsew<const I: usize>(&mut self, d: DartId) -> Result<CellChanges, SewError> {
        const { assert!(I <= N) };
        self.unsew_dyn(I, d)
    }

    /// Run-time-index version of [`GMap::unsew`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::SewError;
    /// use topomech::GMap;
    ///
    /// let mut map = GMap::<1>::new();
    /// let (a, b) = (map.create_dart().unwrap(), map.create_dart().unwrap());
    /// map.sew_dyn(0, a, b).unwrap();
    /// map.unsew_dyn(0, b).unwrap();
    /// assert!(map.is_isolated(a) && map.is_isolated(b));
    /// assert_eq!(map.unsew_dyn(0, a), Err(SewError::AlreadyFree { dart: a, i: 0 }));
    /// ```
    pub fn unsew_dyn(&mut self, i: usize, d: DartId) -> Result<CellChanges, SewError> {
        self.unsew_with(i, d, true)
    }

    /// [`GMap::unsew_dyn`], with the cheap proofs of [`QuickLinks`] (`quick`) or without them
    /// (every candidate split is walked): the same outcome either way.
    fn unsew_with(&mut self, i: usize, d: DartId, quick: bool) -> Result<CellChanges, SewError> {
        Self::check_index(i)?;
        self.check_dart(d)?;
        if self.is_free(i, d) {
            return Err(SewError::AlreadyFree { dart: d, i });
        }
        let mut report = CellChanges::on_spare_lists();
        let cycle = self.unsewn_pairs(i, d, &mut report.pairs);
        for &(x, y) in &report.pairs {
            // Bring the endpoints' cell rows in now (`split_cells` reads and writes them after
            // the ring walks): their cache misses overlap with each other and with the walks
            // instead of being paid one by one later. Reads only, no effect on the outcome.
            std::hint::black_box((self.cell_row(x.0)[0], self.cell_row(y.0)[0]));
            self.unlink_raw(i, x);
        }
        let mut links = QuickLinks::none();
        if quick {
            links.find(self, i, &report.pairs, cycle.endpoints(report.pairs.len()).as_ref());
        }
        // The per-dimension lists of `split_cells`, kept per thread between unsews (no
        // allocation in the steady state; they are cleared before use).
        let mut scratch = SPLIT_SCRATCH.take();
        for dim in (0..=N).filter(|&dim| dim != i) {
            let CellChanges { changes, pairs, new_sides, .. } = &mut report;
            self.split_cells((i, dim, quick), pairs, &links, &mut scratch, (changes, new_sides));
        }
        SPLIT_SCRATCH.set(scratch);
        #[cfg(debug_assertions)]
        self.after_mutation(&touched(&report.pairs));
        #[cfg(not(debug_assertions))]
        self.after_mutation(&[]);
        Ok(report)
    }

    /// The pairs {x, αi(x)} that an αi-unsew of d unlinks, each once, sorted: x over the orbit
    /// of d under the generators commuting with αi. The orbit usually holds only one side of a
    /// pair (αi(x) is in it only for twisted orbits), so the pair is normalised rather than
    /// filtered on x < y. A two-generator orbit (the face ⟨α0, α1⟩ of an α3-unsew) is walked
    /// with no visited set and no list of its own, and also returned as a [`Cycle`] (closed or
    /// not). O(orbit · log orbit).
    fn unsewn_pairs(&self, i: usize, d: DartId, pairs: &mut Vec<(DartId, DartId)>) -> Cycle {
        let mask = AlphaMask::commuting_with(N, i);
        let (gens, len) = generators(N, mask);
        pairs.clear();
        let mut cycle = Cycle::new([gens[0], gens[1]]);
        let pair_of = |x: DartId| {
            let y = self.alpha_dyn(i, x);
            pairs.push((x.min(y), x.max(y)));
            cycle.push(x, x.min(y));
        };
        let closed = if len == 2 {
            self.for_each_dihedral(d, gens[0], gens[1], pair_of)
        } else {
            self.orbit(d, mask).into_iter().for_each(pair_of);
            false
        };
        cycle.closed = closed;
        pairs.sort_unstable();
        pairs.dedup();
        cycle
    }

    /// After unlinking, makes the dim-cell ids exact again. Every piece of a cell that fell apart
    /// holds an endpoint of an unlinked pair, so it suffices to check each endpoint against an
    /// *anchor* endpoint of its current id: if they are no longer in one orbit, the piece found
    /// smaller by the lockstep walk (a complete orbit; on `quick` unsews, where the cell's orbit
    /// allows it, a [`Shortcut`] finds the same piece by paths or by corners) gets a fresh id. A
    /// piece that got a fresh id is complete, so its other endpoints are skipped. Endpoints that
    /// `links` proves still joined skip the walk (it would find them joined too: the outcome is
    /// the same). An endpoint proven joined to an *earlier* endpoint is skipped before its id is even read:
    /// it is in the same cell as that one through every relabelling (each relabels a whole cell),
    /// so it would be skipped as complete, or be joined to the anchor of that cell, or lead to a
    /// check that finds it joined — never to a change or a new anchor. Only the first endpoint of
    /// each class is looked at (3 of the 12 per dimension for an inner face).
    /// `scratch` holds the (id, anchor endpoint index) list and the ids that got a fresh id (the
    /// complete pieces), reused across dimensions.
    fn split_cells(
        &mut self,
        (i, dim, quick): (usize, usize, bool),
        pairs: &[(DartId, DartId)],
        links: &QuickLinks,
        (anchors, complete): &mut SplitScratch,
        (changes, sides): (&mut Vec<CellChange>, &mut SplitSides),
    ) {
        let mask = AlphaMask::cell(N, dim);
        let classes = links.classes(dim);
        anchors.clear();
        complete.clear();
        let count = if quick { Self::split_endpoints(i, dim, pairs.len()) } else { 2 * pairs.len() };
        let mut index = IdIndex::for_endpoints(count);
        for (k, z) in pairs.iter().flat_map(|&(x, y)| [x, y]).take(count).enumerate() {
            if classes.has_earlier_member(k) {
                continue;
            }
            let id = self.cell_id(dim, z).0;
            if index.is_complete(complete, id) {
                continue;
            }
            let Some(slot) = index.anchor_slot(anchors, id) else {
                index.push_anchor(anchors, (id, k));
                continue;
            };
            let a = anchors[slot].1;
            if classes.joined(a, k) {
                continue;
            }
            let anchor = endpoint(pairs, a);
            let new = match links.split_of_whole_classes(&classes, dim, a, k) {
                Some((side, is_z_side)) => {
                    let new = self.alloc_cell_id(dim);
                    for w in bits(classes.members(side)) {
                        self.set_cell_raw(dim, endpoint(pairs, w), new);
                    }
                    (new, is_z_side)
                }
                None => {
                    #[cfg(test)]
                    tests::CELL_WALKS.set(tests::CELL_WALKS.get() + 1);
                    let out = sides.open();
                    let walked = match Shortcut::of(N, i, dim).filter(|_| quick) {
                        Some(Shortcut::Ring(ring)) => ring.split_side(self, anchor, z, out),
                        Some(Shortcut::Corners(corners)) => corners.split_side(self, anchor, z, out),
                        None => self.split_side(anchor, z, mask).map(|(side, is_z_side)| {
                            out.extend(side);
                            is_z_side
                        }),
                    };
                    let Some(is_z_side) = walked else { continue };
                    let new = self.alloc_cell_id(dim);
                    for &w in sides.pending() {
                        self.set_cell_raw(dim, w, new);
                    }
                    sides.close(changes.len());
                    (new, is_z_side)
                }
            };
            let (new, is_z_side) = new;
            index.push_complete(complete, new);
            let (dart_kept, dart_new) = if is_z_side { (anchor, z) } else { (z, anchor) };
            anchors[slot].1 = if is_z_side { a } else { k };
            changes.push(CellChange::Split { dim, kept: CellId(id), new: CellId(new), dart_kept, dart_new });
        }
        // One fresh id per split: the last `complete.len()` changes are this call's splits.
        if complete.len() >= 2 {
            let first = changes.len() - complete.len();
            self.keep_darts_in_kept(dim, pairs, anchors, &index, &mut changes[first..]);
        }
    }

    /// A cell cut into three or more pieces by one unsew is split once per extra piece, and a
    /// later split can carry an earlier one's `dart_kept` away to its new piece (finding 276).
    /// Points each `dart_kept` of `made` (one dimension's splits of one call of
    /// [`Self::split_cells`]) that no longer carries its `kept` at the endpoint its anchor slot
    /// ends with, which keeps the id. The new pieces are complete and never split again in
    /// that call, so every `dart_new` stays in its `new`. Apart, not inlined: the splits of a
    /// face dissociation rarely come two to a dimension, and the loop of `split_cells` keeps
    /// its code. O(splits).
    #[inline(never)]
    fn keep_darts_in_kept(
        &self,
        dim: usize,
        pairs: &[(DartId, DartId)],
        anchors: &[(u32, usize)],
        index: &IdIndex,
        made: &mut [CellChange],
    ) {
        for change in made {
            if let CellChange::Split { kept, dart_kept, .. } = change {
                if self.cell_id(dim, *dart_kept) != *kept {
                    let slot = index.anchor_slot(anchors, kept.0).expect("a split id has an anchor");
                    *dart_kept = endpoint(pairs, anchors[slot].1);
                }
            }
        }
    }
}

impl<const N: usize> GMap<N> {
    /// How many endpoints of the `pairs` unlinked by an αi-unsew [`GMap::split_cells`] has to
    /// look at for the dim-cells: the first pair's two when |dim − i| = 1, else all.
    ///
    /// The law: the pairs are (x, αi x) for x over the orbit ⟨C⟩(d) of the generators C that
    /// commute with αi (|j − i| ≥ 2). When |dim − i| = 1, C holds no α_dim, so C ⊆ the dim-cell's
    /// generators minus αi: after the unsew every x is still in one dim-cell with x0 (a word w
    /// of C, x = w x0), and every αi x = w αi x0 (the αs of C commute with αi) with αi x0. So
    /// the cell of the pairs falls into at most the two pieces of the first pair's ends, and
    /// every later endpoint would be skipped as complete or found joined to its anchor: no
    /// change. This keeps the α0-unsew of an edge of valence k in a 3-map (2k pairs, each edge
    /// piece the whole fan of one end) at O(k) instead of one O(k) fan walk per endpoint
    /// (finding 271). Used on `quick` unsews only, so that the exact path still looks at every
    /// endpoint (unit tests `quick_proofs_change_no_outcome`, `fan_unsews_change_no_outcome`).
    /// O(1).
    fn split_endpoints(i: usize, dim: usize, pairs: usize) -> usize {
        if dim.abs_diff(i) == 1 {
            2.min(2 * pairs)
        } else {
            2 * pairs
        }
    }
}

type SplitScratch = (Vec<(u32, usize)>, Vec<u32>);

/// The lookups of [`GMap::split_cells`] in its (id, anchor) and complete-id lists: scans of the
/// short lists for the usual handful of endpoints (12 per dimension for an inner face), hash
/// indexes past [`IdIndex::SCAN`] endpoints. An α0-unsew around an edge of valence k in a 3-map
/// has 4k endpoints for faces and for volumes, with k face ids and k volume ids, so scans would
/// make it O(k²) (finding 271, with the fan walks of [`GMap::split_endpoints`]). O(1) per lookup
/// either way (expected, for the hash indexes).
struct IdIndex {
    hashed: Option<(std::collections::HashMap<u32, usize>, std::collections::HashSet<u32>)>,
}

impl IdIndex {
    /// Endpoint counts up to this are scanned.
    const SCAN: usize = 64;

    fn for_endpoints(endpoints: usize) -> Self {
        IdIndex { hashed: (endpoints > Self::SCAN).then(Default::default) }
    }

    fn is_complete(&self, complete: &[u32], id: u32) -> bool {
        match &self.hashed {
            Some((_, done)) => done.contains(&id),
            None => complete.contains(&id),
        }
    }

    fn anchor_slot(&self, anchors: &[(u32, usize)], id: u32) -> Option<usize> {
        match &self.hashed {
            Some((slots, _)) => slots.get(&id).copied(),
            None => anchors.iter().position(|a| a.0 == id),
        }
    }

    fn push_anchor(&mut self, anchors: &mut Vec<(u32, usize)>, anchor: (u32, usize)) {
        if let Some((slots, _)) = &mut self.hashed {
            slots.insert(anchor.0, anchors.len());
        }
        anchors.push(anchor);
    }

    fn push_complete(&mut self, complete: &mut Vec<u32>, id: u32) {
        if let Some((_, done)) = &mut self.hashed {
            done.insert(id);
        }
        complete.push(id);
    }
}

thread_local! {
    /// The (id, anchor) and complete-id lists of [`GMap::split_cells`], reused across unsews.
    static SPLIT_SCRATCH: std::cell::Cell<SplitScratch> = const { std::cell::Cell::new((Vec::new(), Vec::new())) };
    /// The two sides' dart lists of [`CornerCell::split_side`], reused across walks.
    static CORNER_SCRATCH: std::cell::Cell<[Vec<DartId>; 2]> = const { std::cell::Cell::new([Vec::new(), Vec::new()]) };
}

/// A faster way than [`GMap::split_side`]'s dart-by-dart walk to the same answer, for one cell
/// dimension after an αi-unsew: by paths ([`RingCell`]) or by corners ([`CornerCell`]).
#[derive(Clone, Copy, Debug)]
enum Shortcut {
    Ring(RingCell),
    Corners(CornerCell),
}

impl Shortcut {
    /// The shortcut for the dim-cells of an n-map after an αi-unsew, if there is one: paths where
    /// the cell has a ring form, else corners in a 3-map. O(n).
    fn of(n: usize, i: usize, dim: usize) -> Option<Shortcut> {
        RingCell::of(n, i, dim).map(Shortcut::Ring).or_else(|| CornerCell::of(n, i, dim).map(Shortcut::Corners))
    }
}

/// A cell of a 3-map after an αi-unsew walked corner by corner: its orbit ⟨αi, αh, αl⟩ is the
/// union of the two-generator orbits ⟨αh, αl⟩ (the corners: for a vertex after an α3-unsew, the
/// six darts of the vertex in one tet) joined by αi links. [`CornerCell::split_side`] runs the
/// lockstep walk of [`GMap::split_side`] over corners instead of darts — a corner is read with no
/// visited set, and only its darts' αi images are looked up — and gives the same answer: `None`
/// iff the two darts are one cell (a side that ends without meeting the other is its whole
/// cell, which then does not hold the other dart), else the side the dart walk would exhaust
/// first, that is the anchor's iff it has no more darts than the other (the anchor moves first
/// in each round). The corner walk keeps counting the other side until that comparison is
/// decided. The darts come in another order (not part of the answer). O(darts walked).
/// Unit test `corner_split_is_split_side`.
#[derive(Clone, Copy, Debug)]
struct CornerCell {
    i: usize,
    h: usize,
    l: usize,
}

impl CornerCell {
    /// The corner form of the dim-cells of an n-map after an αi-unsew: for n = 3, every dim ≠ i.
    fn of(n: usize, i: usize, dim: usize) -> Option<CornerCell> {
        if n != 3 || dim == i || dim > 3 || i > 3 {
            return None;
        }
        let mut hl = (0..=3).filter(|&g| g != dim && g != i);
        Some(CornerCell { i, h: hl.next()?, l: hl.next()? })
    }

    /// See the type's documentation: the side is appended to `out`, and whether it is z's
    /// returned (`out` unchanged when `None`).
    fn split_side<const N: usize>(&self, map: &GMap<N>, a: DartId, z: DartId, out: &mut Vec<DartId>) -> Option<bool> {
        if a == z {
            return None;
        }
        // Per side: its darts (corner after corner, so also the queue of corners to expand:
        // `next` is the first dart not yet looked across αi) and whether it is complete. The
        // two lists are kept per thread between walks (cleared first: no allocation in the
        // steady state).
        let mut darts = CORNER_SCRATCH.take();
        darts.iter_mut().for_each(Vec::clear);
        let answer = with_stamps(|stamps| self.walk(map, (a, z), stamps, &mut darts));
        if let Some(z_side) = answer {
            out.extend_from_slice(&darts[usize::from(z_side)]);
        }
        CORNER_SCRATCH.set(darts);
        answer
    }

    /// The lockstep corner walk of [`CornerCell::split_side`] from `a` and `z`, filling `darts`
    /// (empty on entry) with the darts found on each side; returns whether z's side is the answer.
    fn walk<const N: usize>(
        &self,
        map: &GMap<N>,
        (a, z): (DartId, DartId),
        stamps: &mut Stamps,
        darts: &mut [Vec<DartId>; 2],
    ) -> Option<bool> {
        let tag = stamps.fresh(map.capacity(), 2);
        let mut next = [0usize; 2];
        self.enter(map, a, stamps, tag, &mut darts[0]);
        if stamps.has(z.0, tag) {
            return None; // one corner
        }
        self.enter(map, z, stamps, tag + 1, &mut darts[1]);
        let mut done = [false; 2];
        loop {
            for side in 0..2 {
                if done[side] {
                    continue;
                }
                let (own, other) = (tag + side as u32, tag + 1 - side as u32);
                match self.expand(map, stamps, (own, other), &mut darts[side], &mut next[side]) {
                    Expand::Met => return None,
                    Expand::Grew => {}
                    Expand::Complete => done[side] = true,
                }
            }
            let (sa, sz) = (darts[0].len(), darts[1].len());
            // A complete side is a whole cell; the other side has at least its darts so far.
            let decided = match done {
                [true, true] => Some(sa > sz),
                [true, false] if sz >= sa => Some(false),
                [false, true] if sa > sz => Some(true),
                _ => None,
            };
            if decided.is_some() {
                return decided;
            }
        }
    }

    /// Appends the corner ⟨αh, αl⟩ of `c` to `darts`, stamping each with `own`.
    fn enter<const N: usize>(&self, map: &GMap<N>, c: DartId, stamps: &mut Stamps, own: u32, darts: &mut Vec<DartId>) {
        map.for_each_dihedral(c, self.h, self.l, |x| {
            #[cfg(test)]
            tests::CORNER_DARTS.set(tests::CORNER_DARTS.get() + 1);
            stamps.mark(x.0, own);
            darts.push(x);
        });
    }

    /// Looks across αi from the side's darts `next..` until a corner not yet found is entered
    /// (or the other side's is met). O(corner).
    fn expand<const N: usize>(
        &self,
        map: &GMap<N>,
        stamps: &mut Stamps,
        (own, other): (u32, u32),
        darts: &mut Vec<DartId>,
        next: &mut usize,
    ) -> Expand {
        while *next < darts.len() {
            let x = darts[*next];
            *next += 1;
            let y = map.alpha_dyn(self.i, x);
            if y == x || stamps.has(y.0, own) {
                continue;
            }
            if stamps.has(y.0, other) {
                return Expand::Met;
            }
            self.enter(map, y, stamps, own, darts);
            return Expand::Grew;
        }
        Expand::Complete
    }
}

/// What one step of a [`CornerCell`] walk did.
enum Expand {
    /// It reached a dart of the other side: one cell.
    Met,
    /// It entered a new corner.
    Grew,
    /// The side has no dart left to look across: it is a whole cell.
    Complete,
}

/// A cell dimension whose orbit, after an αi-unsew, is read off one two-generator path: the
/// cell's generators are αi, αj and at most one αk that commutes with both (|k − i| ≥ 2 and
/// |k − j| ≥ 2). Then ⟨αi, αj, αk⟩ = ⟨αj, αi⟩ ∪ αk ⟨αj, αi⟩, so the cell of an unlinked endpoint x
/// (i-free) is the path ⟨αj, αi⟩(x) plus its αk image, which is that path itself or disjoint from
/// it. In a 3-map unsewn by α3 this is the edge (α0, α2, α3): the chain of tets around it on one
/// side of the cut, both ends; in a 2-map unsewn by α2, the vertex (α1, α2).
///
/// [`RingCell::split_side`] gives [`GMap::split_side`]'s answer without its visited sets: the
/// same side (the lockstep walk exhausts the anchor's side first iff it is not larger, as the
/// anchor moves first in each round), with its darts in another order (the order is not part of
/// the answer: [`CellChanges::new_side`]). Requires a map whose α links commute as validity says
/// (true after every public operation). Unit test `ring_split_is_split_side`.
#[derive(Clone, Copy, Debug)]
struct RingCell {
    i: usize,
    j: usize,
    k: Option<usize>,
}

impl RingCell {
    /// The ring form of the dim-cells of an n-map after an αi-unsew, if they have one. O(n).
    fn of(n: usize, i: usize, dim: usize) -> Option<RingCell> {
        let (mut others, mut len) = ([0; 2], 0);
        for g in (0..=n).filter(|&g| g != dim && g != i) {
            if len == 2 {
                return None; // four generators or more: not a ring
            }
            others[len] = g;
            len += 1;
        }
        let commutes = |a: usize, b: usize| a.abs_diff(b) >= 2;
        match others[..len] {
            [j] => Some(RingCell { i, j, k: None }),
            [a, b] if commutes(b, i) && commutes(b, a) => Some(RingCell { i, j: a, k: Some(b) }),
            [a, b] if commutes(a, i) && commutes(a, b) => Some(RingCell { i, j: b, k: Some(a) }),
            _ => None,
        }
    }

    /// [`GMap::split_side`] of the i-free darts `a` (the anchor) and `z`: `None` if they are one
    /// cell (`out` unchanged), else the smaller side (a's on a tie) appended to `out` and whether
    /// it is z's.
    ///
    /// The law: the cell of an i-free x is path(x) ∪ αk(path(x)) (one path ⟨αj, αi⟩ walked from
    /// x, αj first; αk(path(x)) is path(x) itself iff αk(x) is on it), so a whole side has
    /// len × 1 or × 2 darts, and z is in a's cell iff z or αk(z) (i-free: an end) is on path(a).
    /// The two paths are walked in lockstep, a first in each round, their darts pushed to `out`
    /// interleaved (the invariant: while both run, a's darts at even offsets from the start, z's
    /// at odd ones, each in path order). In one cell both paths have one length, so a's walk
    /// meets z or αk(z) before z's can end; once a path ends without that, they are two cells
    /// and its side's size is known, and the other walk goes on only until it ends or its path
    /// alone is at least as large (strictly larger against z's side: a's side wins ties). The
    /// chosen side is then compacted in place and its αk image appended if that is another path.
    /// No list of its own. O(smaller side) when split (at most 2 steps per dart of it), O(cell)
    /// when joined.
    fn split_side<const N: usize>(&self, map: &GMap<N>, a: DartId, z: DartId, out: &mut Vec<DartId>) -> Option<bool> {
        let (mut wa, mut wz) = (PathWalk::new(map, self, a), PathWalk::new(map, self, z));
        if z == a || z == wa.twin {
            return None;
        }
        let start = out.len();
        out.extend([a, z]);
        let joined = loop {
            match wa.step(map, self) {
                Some(y) if y == z || y == wz.twin => break true,
                Some(y) => out.push(y),
                None => break false,
            }
            match wz.step(map, self) {
                Some(y) => out.push(y), // one cell: a's walk, a step ahead, meets it first
                None => break false,
            }
        };
        if joined {
            out.truncate(start);
            return None;
        }
        // Two cells: one path ended after `pairs` darts; the other's later darts follow the
        // interleaved prefix of 2 × `pairs` darts.
        let a_ended = wa.ended;
        let pairs = if a_ended { wa.len } else { wz.len };
        let z_side = if a_ended {
            let size_a = wa.size();
            while !wz.ended && wz.len < size_a {
                out.extend(wz.step(map, self));
            }
            wz.ended && wz.size() < size_a
        } else {
            let size_z = wz.size();
            while !wa.ended && wa.len <= size_z {
                out.extend(wa.step(map, self));
            }
            !wa.ended || wa.size() > size_z
        };
        let side = if z_side { &wz } else { &wa };
        for t in 0..pairs {
            out[start + t] = out[start + 2 * t + usize::from(z_side)];
        }
        if z_side == a_ended {
            out.copy_within(start + 2 * pairs.., start + pairs); // the walk that went on
        }
        out.truncate(start + side.len);
        if let (Some(k), false) = (self.k, side.single) {
            for p in start..start + side.len {
                out.push(map.alpha_local(k, out[p]));
            }
        }
        Some(z_side)
    }
}

/// One side of a [`RingCell::split_side`] walk: the path ⟨αj, αi⟩ from an i-free anchor,
/// walked one way (αj first) one dart at a time.
struct PathWalk {
    /// The anchor's αk image (the anchor itself without αk).
    twin: DartId,
    /// The last dart reached.
    at: DartId,
    /// Darts reached, the anchor included.
    len: usize,
    /// Whether `twin` was reached: then the cell is the path alone, else also its αk image.
    single: bool,
    /// Whether the path ended at `at` (its next link is free).
    ended: bool,
}

impl PathWalk {
    fn new<const N: usize>(map: &GMap<N>, ring: &RingCell, anchor: DartId) -> Self {
        let twin = ring.k.map_or(anchor, |k| map.alpha_local(k, anchor));
        PathWalk { twin, at: anchor, len: 1, single: twin == anchor, ended: false }
    }

    /// The path's next dart, or `None` at its end (then `ended`). O(1).
    fn step<const N: usize>(&mut self, map: &GMap<N>, ring: &RingCell) -> Option<DartId> {
        #[cfg(test)]
        tests::RING_STEPS.with(|n| n.set(n.get() + 1));
        let y = map.alpha_local(if self.len % 2 == 1 { ring.j } else { ring.i }, self.at);
        if y == self.at {
            self.ended = true;
            return None;
        }
        (self.at, self.len, self.single) = (y, self.len + 1, self.single || y == self.twin);
        Some(y)
    }

    /// The darts of the side's cell, once the path `ended`.
    fn size(&self) -> usize {
        if self.single {
            self.len
        } else {
            2 * self.len
        }
    }
}

/// Endpoint k of the unlinked pairs: pair k / 2, first or second dart.
#[inline]
fn endpoint(pairs: &[(DartId, DartId)], k: usize) -> DartId {
    let (x, y) = pairs[k / 2];
    if k % 2 == 0 {
        x
    } else {
        y
    }
}

/// The orbit of an unsew's dart under its two commuting generators ⟨αj, αk⟩ when that orbit is a
/// closed cycle, as [`GMap::for_each_dihedral`] walked it (for an α3-unsew in a 3-map: the six
/// darts of a closed triangle on one side of the face, alternately α0- and α1-linked). The links
/// between its darts are then known from the walk, so [`QuickLinks::find`] takes its direct
/// links from here instead of looking up αj and αk of every endpoint in a dart → endpoint table.
struct Cycle {
    gens: [usize; 2],
    /// Per dart in walk order: the dart, and the smaller dart of its unsewn pair.
    darts: [(DartId, DartId); QuickLinks::MAX_PAIRS],
    /// Darts walked (may exceed the array: then no hint).
    len: usize,
    closed: bool,
}

impl Cycle {
    fn new(gens: [usize; 2]) -> Self {
        Cycle { gens, darts: [(DartId(0), DartId(0)); QuickLinks::MAX_PAIRS], len: 0, closed: false }
    }

    fn push(&mut self, x: DartId, pair_min: DartId) {
        if let Some(slot) = self.darts.get_mut(self.len) {
            *slot = (x, pair_min);
        }
        self.len += 1;
    }

    /// The endpoint index of each walked dart, in walk order, if the walk closed and each of its
    /// darts is in its own unlinked pair (`pairs` distinct pairs, as many as darts: no pair has
    /// both darts in the cycle). The pairs are sorted by their smaller dart, all distinct, so
    /// the pair of a dart is the rank of its pair's smaller dart: endpoint 2 · rank, plus one
    /// when the dart is the larger of its pair. O(len²), len ≤ [`QuickLinks::MAX_PAIRS`].
    fn endpoints(&self, pairs: usize) -> Option<CycleEnds> {
        if !self.closed || self.len != pairs || self.len > QuickLinks::MAX_PAIRS {
            return None;
        }
        let walked = &self.darts[..self.len];
        let mut ends = [0u8; QuickLinks::MAX_PAIRS];
        for (e, &(x, low)) in ends.iter_mut().zip(walked) {
            let rank = walked.iter().filter(|w| w.1 < low).count();
            *e = (2 * rank + usize::from(x != low)) as u8;
        }
        Some(CycleEnds { gens: self.gens, ends, len: self.len })
    }
}

/// A closed [`Cycle`] by endpoint index: the t-th and the next walked dart (the last and the
/// first) are linked by `gens[t % 2]`.
struct CycleEnds {
    gens: [usize; 2],
    ends: [u8; QuickLinks::MAX_PAIRS],
    len: usize,
}

/// Connections between the endpoints of an unsew that are cheap to prove, so that the exact
/// lockstep walk runs only where a cell may really have split.
///
/// Two kinds of proof, both valid after the unlinking:
/// - a direct link: endpoint q = αk(p), with αk commuting with αi (so it maps the unsewn orbit
///   into itself), joins p and q in every cell whose orbit uses αk;
/// - a ring: for j = i ± 1, the orbit ⟨αj, αi⟩ of an endpoint is a path starting there (it is
///   i-free now); when the paths of the two darts x, y of an unlinked pair are one path (found
///   by [`RingWalks`], no visited set, at most [`QuickLinks::RING_STEPS`] rounds), x and y are
///   joined in every cell whose orbit uses both αj and αi — the dimensions other than i and j.
///   In a 3-map unsewn by α3 the ring is the chain of tets around an edge of the face: when it
///   still links both sides of the face, neither that edge nor its two vertices split, the
///   common case of an inner face. A generator αk commuting with αi and αj maps the path of
///   (x, y) onto that of (αk(x), αk(y)), so that one is not walked (α0 in the example: the
///   other end of the edge).
///
/// Built only for up to [`QuickLinks::MAX_PAIRS`] pairs and maps of dimension below
/// [`QuickLinks::MAX_GENS`] (else no proof: every check walks).
struct QuickLinks {
    /// Per generator k and endpoint p, the bit set of the endpoints q joined to p through αk
    /// (direct) or through the ring ⟨αk, αi⟩; either way the proof holds in the cells of every
    /// dimension other than k (and i). Kept per generator so that the classes of a dimension
    /// are the closure of a few bit-set unions ([`QuickLinks::classes`]).
    adjacent: [[u32; 2 * QuickLinks::MAX_PAIRS]; QuickLinks::MAX_GENS],
    /// Per endpoint, the bit set of the generators k with a direct link αk(p) = q or αk(p) = p.
    direct: [u8; 2 * QuickLinks::MAX_PAIRS],
    /// The bit set of the map's generators α0 … αn.
    gens: u8,
    /// Number of endpoints covered (0: no proof was built).
    ends: usize,
}

/// Endpoint k of the unlinked pairs by dart: a small open-addressing table (64 slots, at most
/// 2 · [`QuickLinks::MAX_PAIRS`] = 32 keys, so at most half full), built in O(pairs), each
/// lookup O(1) expected — the linear scan it replaces was a quarter of [`QuickLinks::find`].
/// Same answers as the scan `(0..2 · pairs).find(|&k| endpoint(pairs, k) == d)` (unit test
/// `endpoint_index_is_the_linear_scan`): a dart that is the endpoint of two pairs (impossible
/// for a real unsew) keeps its first index, as the scan would.
struct EndpointIndex {
    /// Dart + 1 per slot (0: empty; live darts are below `u32::MAX - 1`, `create_dart`'s limit,
    /// so dart + 1 is never 0).
    keys: [u32; EndpointIndex::SLOTS],
    values: [u8; EndpointIndex::SLOTS],
}

impl EndpointIndex {
    const SLOTS: usize = 64;

    fn slot(d: DartId) -> usize {
        (d.0.wrapping_mul(0x9E37_79B9) >> 26) as usize
    }

    /// Requires `pairs.len() <= QuickLinks::MAX_PAIRS`.
    fn new(pairs: &[(DartId, DartId)]) -> Self {
        debug_assert!(pairs.len() <= QuickLinks::MAX_PAIRS);
        let mut t = EndpointIndex { keys: [0; Self::SLOTS], values: [0; Self::SLOTS] };
        for k in 0..2 * pairs.len() {
            let d = endpoint(pairs, k);
            let mut s = Self::slot(d);
            loop {
                if t.keys[s] == d.0.wrapping_add(1) {
                    break; // already there with a smaller index
                }
                if t.keys[s] == 0 {
                    t.keys[s] = d.0.wrapping_add(1);
                    t.values[s] = k as u8;
                    break;
                }
                s = (s + 1) % Self::SLOTS;
            }
        }
        t
    }

    /// The first endpoint index of `d`, if it is an endpoint.
    fn get(&self, d: DartId) -> Option<usize> {
        let mut s = Self::slot(d);
        loop {
            match self.keys[s] {
                0 => return None,
                k if k == d.0.wrapping_add(1) => return Some(self.values[s] as usize),
                _ => s = (s + 1) % Self::SLOTS,
            }
        }
    }
}

/// A partition of the endpoints into classes known to be joined in one cell dimension: per
/// endpoint p, the bit set of its class (bit q set iff q is proven joined to p; p's own bit
/// included). All sets are empty when no proof was built. Endpoint indices are below
/// 2 · [`QuickLinks::MAX_PAIRS`] = 32, so a class is one `u32`: `joined` is one shift, a class's
/// size one popcount, and its members the set bits.
struct Classes {
    class: [u32; 2 * QuickLinks::MAX_PAIRS],
    /// The endpoints joined to a lower-numbered one (every class member but its lowest).
    followers: u32,
}

impl Classes {
    /// The classes of the graph on `ends` endpoints where `adjacent(p)` is the bit set of p's
    /// neighbours: the connected components, each found by a breadth-first closure over bit
    /// sets. O(ends) calls of `adjacent`.
    fn closure(ends: usize, adjacent: impl Fn(usize) -> u32) -> Self {
        let mut class = [0u32; 2 * QuickLinks::MAX_PAIRS];
        // The endpoints not yet in a class; each round closes the class of the lowest one.
        let mut rest = u32::MAX.checked_shr(u32::BITS - ends as u32).unwrap_or(0);
        let mut followers = rest;
        while rest != 0 {
            let first = 1u32 << rest.trailing_zeros();
            followers &= !first;
            let (mut members, mut todo) = (first, first);
            while todo != 0 {
                let q = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let fresh = adjacent(q) & !members;
                members |= fresh;
                todo |= fresh;
            }
            for q in bits(members) {
                class[q] = members;
            }
            rest &= !members;
        }
        Classes { class, followers }
    }

    /// The members of p's class as a bit set (empty when no proof was built or p is past the
    /// covered endpoints).
    fn members(&self, p: usize) -> u32 {
        self.class.get(p).copied().unwrap_or(0)
    }

    /// Whether endpoint p is proven joined to an endpoint q < p. O(1).
    fn has_earlier_member(&self, p: usize) -> bool {
        self.followers.checked_shr(p as u32).is_some_and(|f| f & 1 != 0)
    }

    /// Whether endpoints p and q are proven joined (false when no proof was built).
    fn joined(&self, p: usize, q: usize) -> bool {
        q < u32::BITS as usize && self.members(p) >> q & 1 != 0
    }
}

/// The indices of the set bits of `set`, lowest first.
fn bits(mut set: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        let q = set.trailing_zeros() as usize;
        set &= set.checked_sub(1)?;
        Some(q)
    })
}

impl QuickLinks {
    const MAX_PAIRS: usize = 16;
    /// Generators α0 … α3: proofs are built for maps of dimension ≤ 3.
    const MAX_GENS: usize = 4;
    const RING_STEPS: usize = 64;

    /// Records that endpoints p and q are joined through αk (or the ring ⟨αk, αi⟩).
    fn push(&mut self, p: usize, q: usize, k: usize) {
        if p != q {
            self.adjacent[k][p] |= 1 << q;
            self.adjacent[k][q] |= 1 << p;
        }
    }

    /// The endpoint that αk (k commuting with αi, its direct links found) maps endpoint p to:
    /// p itself when p is k-free, `None` when the image is no endpoint. O(1).
    fn image(&self, k: usize, p: usize) -> Option<usize> {
        (self.direct[p] >> k & 1 != 0).then(|| match self.adjacent[k][p] {
            0 => p,
            q => q.trailing_zeros() as usize,
        })
    }

    /// No proof at all.
    fn none() -> Self {
        QuickLinks {
            adjacent: [[0; 2 * Self::MAX_PAIRS]; Self::MAX_GENS],
            direct: [0; 2 * Self::MAX_PAIRS],
            gens: 0,
            ends: 0,
        }
    }

    /// Fills `self` (no proof yet, [`QuickLinks::none`]; filled in place, as the struct is
    /// half a kilobyte) with the proofs for the endpoints of `pairs`, just unlinked by αi.
    /// `cycle`, when the unsewn orbit was a closed cycle, gives the direct links without a
    /// lookup (the same links: unit test `cycle_links_are_the_looked_up_links`).
    fn find<const N: usize>(&mut self, map: &GMap<N>, i: usize, pairs: &[(DartId, DartId)], cycle: Option<&CycleEnds>) {
        let out = self;
        if pairs.len() > Self::MAX_PAIRS || N >= Self::MAX_GENS {
            return;
        }
        out.ends = 2 * pairs.len();
        out.gens = ((1u16 << (N + 1)) - 1) as u8;
        let mut ends = [DartId(0); 2 * Self::MAX_PAIRS];
        for (e, &(x, y)) in ends.chunks_exact_mut(2).zip(pairs) {
            e.copy_from_slice(&[x, y]);
        }
        let ends = &ends[..out.ends];
        // The generators commuting with αk: those at index distance ≥ 2 from k.
        let gens = u32::from(out.gens);
        let commuting_with = |k: usize| gens & !(0b111 << k >> 1);
        match cycle {
            Some(cycle) => out.cycle_links(i, cycle),
            None => out.looked_up_links(map, i, ends, pairs, commuting_with(i)),
        }
        for j in [i.checked_sub(1), Some(i + 1).filter(|&j| j <= N)].into_iter().flatten() {
            let mirrors = commuting_with(i) & commuting_with(j);
            // One walk per pair, none for a pair that is the αk image of a walked one.
            let mut covered = 0u32;
            let mut walks = RingWalks::new(i, j);
            for (m, &pair) in pairs.iter().enumerate() {
                if covered >> (2 * m) & 1 != 0 {
                    continue;
                }
                walks.start(pair, m);
                for p in [2 * m, 2 * m + 1] {
                    covered |= 1 << p;
                    for q in bits(mirrors).filter_map(|k| out.image(k, p)) {
                        covered |= 1 << q;
                    }
                }
            }
            walks.run(map, Self::RING_STEPS);
            for m in walks.joined() {
                out.push(2 * m, 2 * m + 1, j);
                for k in bits(mirrors) {
                    if let (Some(p), Some(q)) = (out.image(k, 2 * m), out.image(k, 2 * m + 1)) {
                        out.push(p, q, j);
                    }
                }
            }
        }
    }

    /// The direct links, looked up for the first dart x of each pair only: αk (each k of
    /// `commuting`, the generators commuting with αi) maps the pair (x, αi x) onto the pair
    /// (αk x, αi αk x), endpoint q onto its partner q ^ 1 (the pairs are disjoint, each its two
    /// darts). O(pairs · generators).
    fn looked_up_links<const N: usize>(
        &mut self,
        map: &GMap<N>,
        i: usize,
        ends: &[DartId],
        pairs: &[(DartId, DartId)],
        commuting: u32,
    ) {
        let table = EndpointIndex::new(pairs);
        for (p, &x) in ends.iter().enumerate().step_by(2) {
            self.direct[p] |= 1 << i; // every endpoint is i-free now
            self.direct[p + 1] |= 1 << i;
            for k in bits(commuting) {
                let y = map.alpha_local(k, x);
                let Some(q) = (if y == x { Some(p) } else { table.get(y) }) else { continue };
                self.direct_link(p, q, k);
            }
        }
    }

    /// The same links as [`QuickLinks::looked_up_links`] when the unsewn orbit is the closed
    /// `cycle`: each of its links joins two of its darts' endpoints, and their partners. O(pairs).
    fn cycle_links(&mut self, i: usize, cycle: &CycleEnds) {
        let ends = &cycle.ends[..cycle.len];
        for (t, &p) in ends.iter().enumerate() {
            let p = usize::from(p);
            self.direct[p] |= 1 << i; // every endpoint is i-free now
            self.direct[p ^ 1] |= 1 << i;
            let q = usize::from(if t + 1 < ends.len() { ends[t + 1] } else { ends[0] });
            self.direct_link(p, q, cycle.gens[t % 2]);
        }
    }

    /// Records the direct link αk(p) = q (q = p when p is k-free) and its image by αi, the link
    /// between the partners p ^ 1 and q ^ 1.
    #[inline]
    fn direct_link(&mut self, p: usize, q: usize, k: usize) {
        for (p, q) in [(p, q), (p ^ 1, q ^ 1)] {
            self.direct[p] |= 1 << k;
            self.direct[q] |= 1 << k;
            self.push(p, q, k);
        }
    }

    /// When the classes of endpoints a and z (not joined) are each a whole dim-cell — every
    /// member's αk image, for every αk of the cell's orbit, is itself or a member reached by a
    /// direct link — the split [`GMap::split_side`] would find, without walking: the class of a
    /// if it is not larger (the lockstep walk exhausts a's side first then, a's side moving
    /// first in each round), else z's. Returns a member of that class and whether it is z's.
    fn split_of_whole_classes(&self, classes: &Classes, dim: usize, a: usize, z: usize) -> Option<(usize, bool)> {
        if self.ends == 0 {
            return None;
        }
        let cell = self.gens & !(1 << dim);
        let (side_a, side_z) = (classes.members(a), classes.members(z));
        if bits(side_a | side_z).any(|p| self.direct[p] & cell != cell) {
            return None;
        }
        Some(if side_a.count_ones() <= side_z.count_ones() { (a, false) } else { (z, true) })
    }

    /// The classes of endpoints proven joined in the cells of dimension `dim`. O(ends).
    fn classes(&self, dim: usize) -> Classes {
        // αk is in the dim-cell orbit iff k ≠ dim; a ring also needs αi, and dim ≠ i here.
        let adjacent = |p: usize| (0..Self::MAX_GENS).filter(|&k| k != dim).fold(0, |a, k| a | self.adjacent[k][p]);
        Classes::closure(self.ends, adjacent)
    }
}

/// Walks of the paths ⟨αj, αi⟩ between the two darts of unlinked pairs, all interleaved (the
/// loads of different walks are independent, so their cache misses overlap). Each walk goes from
/// both ends at once (both darts are i-free, so each is an end of its path, which alternates αj,
/// αi from there): the two fronts meet iff the pair is still joined through the ring, after
/// about half the ring each; a front that reaches the other end of its path first proves
/// nothing.
struct RingWalks {
    gens: [usize; 2],
    /// (front from x, front from y, parity of the steps taken by each, pair index, state).
    walks: [([DartId; 2], [u8; 2], u8, Walk); QuickLinks::MAX_PAIRS],
    len: usize,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Walk {
    Running,
    Met,
    Open,
}

impl RingWalks {
    fn new(i: usize, j: usize) -> Self {
        RingWalks { gens: [j, i], walks: [([DartId(0); 2], [0; 2], 0, Walk::Open); QuickLinks::MAX_PAIRS], len: 0 }
    }

    fn start(&mut self, (x, y): (DartId, DartId), pair: usize) {
        self.walks[self.len] = ([x, y], [0, 0], pair as u8, Walk::Running);
        self.len += 1;
    }

    /// Advances every running walk, one step of each front per round, for at most `rounds`.
    fn run<const N: usize>(&mut self, map: &GMap<N>, rounds: usize) {
        for _ in 0..rounds {
            let mut running = false;
            for (fronts, steps, _, state) in self.walks[..self.len].iter_mut().filter(|w| w.3 == Walk::Running) {
                for f in 0..2 {
                    let here = fronts[f];
                    let next = map.alpha_local(self.gens[steps[f] as usize], here);
                    if next == here {
                        *state = Walk::Open;
                        break;
                    }
                    fronts[f] = next;
                    steps[f] ^= 1;
                    if fronts[0] == fronts[1] {
                        *state = Walk::Met;
                        break;
                    }
                }
                running |= *state == Walk::Running;
            }
            if !running {
                return;
            }
        }
    }

    /// The pairs whose fronts met.
    fn joined(&self) -> impl Iterator<Item = usize> + '_ {
        self.walks[..self.len].iter().filter(|w| w.3 == Walk::Met).map(|w| w.2 as usize)
    }
}

/// The darts of the pairs, for the local checks.
fn touched(pairs: &[(DartId, DartId)]) -> Vec<DartId> {
    pairs.iter().flat_map(|&(x, y)| [x, y]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{kuhn_cube, SplitMix64};

    fn same_state<const N: usize>(a: &GMap<N>, b: &GMap<N>) -> bool {
        a.capacity() == b.capacity()
            && a.darts()
                .all(|d| (0..=N).all(|k| a.alpha_dyn(k, d) == b.alpha_dyn(k, d) && a.cell_id(k, d) == b.cell_id(k, d)))
    }

    thread_local! {
        /// Cells whose split the unsews of this thread decided by a walk (the lockstep walk
        /// or a shortcut), not by the quick proofs.
        pub(super) static CELL_WALKS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
        /// Darts [`RingCell::split_side`] looked up (one per step of either path walk).
        pub(super) static RING_STEPS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
        /// Darts [`CornerCell::split_side`] entered (corner by corner, both sides).
        pub(super) static CORNER_DARTS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    /// The darts of a fan of k tets around the edge (0, 1) (closed around it, or open: the
    /// edge on the boundary), and a dart of vertex 0 on that edge.
    fn fan(k: u32, closed: bool) -> (GMap<3>, DartId) {
        let tets: Vec<[u32; 4]> = (0..k).map(|t| [0, 1, 2 + t, 2 + (t + 1) % (k + u32::from(!closed))]).collect();
        let (map, _) = GMap::<3>::from_tets(k as usize + 3, &tets).unwrap();
        let d = map.darts().find(|&d| map.vertex_id(d).0 == 0 && map.vertex_id(map.alpha::<0>(d)).0 == 1).unwrap();
        (map, d)
    }

    /// Finding 271: the α0-unsew of an edge of valence k walked the whole fan (2k darts) once
    /// per endpoint of its 2k pairs for the edge pieces, and scanned lists of k face and volume
    /// ids per endpoint: O(k²). The darts its walks enter (corners and ring steps, all
    /// dimensions) now grow linearly with k: at most 80 per tet of the fan (70 now), and doubling k at
    /// most doubles them (+5 %). Before, the edge walks alone were 8k² darts.
    #[test]
    fn a_high_valence_edge_unsews_in_linear_walks() {
        let mut per_k = Vec::new();
        for k in [100u32, 200, 400, 800] {
            for closed in [true, false] {
                let (mut map, d) = fan(k, closed);
                let (corners, steps) = (CORNER_DARTS.get(), RING_STEPS.get());
                let changes = map.unsew_dyn(0, d).unwrap();
                let walked = CORNER_DARTS.get() - corners + RING_STEPS.get() - steps;
                assert_eq!(changes.splits(1).count(), 1, "k = {k}: the edge splits in two");
                assert!(walked <= 80 * k as usize, "k = {k}, closed {closed}: {walked} darts walked");
                per_k.push(walked);
            }
        }
        for w in per_k.windows(4).step_by(2) {
            assert!(w[2] * 100 <= w[0] * 210 && w[3] * 100 <= w[1] * 210, "not linear: {per_k:?}");
        }
    }

    /// The shortcut of [`GMap::split_endpoints`] (only the first pair's endpoints for the
    /// dimensions next to i) gives the exact path's outcome where the quick proofs do not
    /// reach: fans of more than 16 pairs, open and closed, every unsew of a random order.
    #[test]
    fn fan_unsews_change_no_outcome() {
        for (k, closed) in [(9, true), (12, false), (20, true), (3, true)] {
            let (start, _) = fan(k, closed);
            for i in 0..=3 {
                let (mut fast, mut slow) = (start.clone(), start.clone());
                let mut darts: Vec<DartId> = start.darts().collect();
                let mut rng = SplitMix64(u64::from(k) * 7 + i as u64);
                for t in (1..darts.len()).rev() {
                    darts.swap(t, rng.below(t + 1));
                }
                for d in darts {
                    let j = if rng.below(2) == 0 { 0 } else { i };
                    if fast.is_free(j, d) {
                        continue;
                    }
                    let (a, b) = (fast.unsew_with(j, d, true).unwrap(), slow.unsew_with(j, d, false).unwrap());
                    assert_eq!(a, b, "k = {k}: alpha{j} unsew of {d}");
                }
                assert!(same_state(&fast, &slow), "k = {k}, alpha{i}: the maps differ");
                assert_eq!(fast.count_cells(), fast.count_cells_by_traversal());
            }
        }
    }

    /// The quick proofs do their job: an α3-unsew of an inner face that splits nothing (every
    /// ring around its edges closed, its corners joined around) is settled with no walk at
    /// all, and over all inner faces the proofs spare most of the walks that the exact path
    /// makes. (Outcomes are checked by `quick_proofs_change_no_outcome`; this checks the
    /// speed-only part, which a proof that never fires would pass.)
    #[test]
    fn quick_proofs_settle_unsplit_faces_without_walks() {
        let (points, tets) = kuhn_cube(3);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let inner: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
        let (mut walks, mut unsplit) = ([0usize; 2], 0);
        for &d in &inner {
            let e = map.alpha::<3>(d);
            for (slot, quick) in [(0, true), (1, false)] {
                let before = CELL_WALKS.get();
                let changes = map.unsew_with(3, d, quick).unwrap();
                let n = CELL_WALKS.get() - before;
                walks[slot] += n;
                if quick && changes.splits(0).count() + changes.splits(1).count() == 0 {
                    unsplit += 1;
                    assert_eq!(n, 0, "face of {d}: split nothing but took {n} walks");
                }
                map.sew::<3>(d, e).unwrap();
            }
        }
        assert!(unsplit > inner.len() / 4, "{unsplit} of {} inner faces split nothing", inner.len());
        assert!(walks[0] * 4 < walks[1], "walks with the proofs {}, without {}", walks[0], walks[1]);
    }

    /// The same on a 2-map: an α2-unsew of an inner edge that splits neither end vertex (both
    /// inner, their rings ⟨α1, α2⟩ closed) is settled with no walk. No generator of a 2-map
    /// commutes with both α1 and α2, so the ring of each of the edge's two pairs must be walked:
    /// a walk skipped by a wrong "already covered" bit leaves a vertex to the lockstep walk.
    #[test]
    fn quick_proofs_settle_unsplit_edges_without_walks_in_2d() {
        let (points, triangles) = crate::generate::grid_triangles(4);
        let (mut map, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
        let inner: Vec<DartId> = map.one_dart_per_cell(1).into_iter().filter(|&d| !map.is_free(2, d)).collect();
        let mut unsplit = 0;
        for &d in &inner {
            let e = map.alpha::<2>(d);
            let before = CELL_WALKS.get();
            let changes = map.unsew_with(2, d, true).unwrap();
            let n = CELL_WALKS.get() - before;
            if changes.splits(0).count() == 0 {
                unsplit += 1;
                assert_eq!(n, 0, "edge of {d}: split no vertex but took {n} walks");
            }
            map.sew::<2>(d, e).unwrap();
        }
        // 4 × 4 squares: the 3 × 3 inner vertices are joined by 12 axis edges and 4 diagonals.
        assert_eq!(unsplit, 16, "{unsplit} of {} inner edges split no vertex", inner.len());
    }

    /// A dropped report lends its lists to the next unsew on the thread, emptied: the next
    /// report reuses the same buffers and lists only its own pairs and changes.
    #[test]
    fn a_dropped_report_lends_its_emptied_lists_to_the_next_unsew() {
        let (points, tets) = kuhn_cube(2);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let inner: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
        let mut first = map.unsew::<3>(inner[0]).unwrap();
        // A capacity no fresh list of an unsew would have marks the buffers.
        first.pairs.reserve(1000);
        first.changes.reserve(1000);
        let pairs_len = first.pairs.len();
        drop(first);
        let second = map.unsew::<3>(inner[1]).unwrap();
        assert!(second.pairs.capacity() >= 1000 && second.changes.capacity() >= 1000, "the lists were not reused");
        assert_eq!(second.pairs.len(), pairs_len); // a triangle's six pairs, none left over
        let face = map.cell_darts(2, inner[1]);
        assert!(second
            .pairs
            .iter()
            .all(|&(a, b)| map.is_free(3, a) && map.is_free(3, b) && (face.contains(&a) || face.contains(&b))));
        // While a report is alive its lists are its own: a second live report gets other buffers.
        let third = map.unsew::<3>(inner[2]).unwrap();
        assert!(third.pairs.capacity() < 1000 && third.pairs.len() == pairs_len);
        // Over the limit, lists are freed rather than kept.
        let mut big = third;
        big.pairs.reserve(crate::spare::CAPACITY_LIMIT + 1);
        drop(second);
        let fourth = map.unsew::<3>(inner[3]).unwrap(); // takes second's lists: the slot is empty
        drop(big);
        assert!(map.unsew::<3>(inner[4]).unwrap().pairs.capacity() <= crate::spare::CAPACITY_LIMIT);
        assert!(fourth.pairs.capacity() >= 1000);
    }

    /// Unsews every sewn dart of a Kuhn cube by αi (i = 0..=3, each on a fresh cube, in a
    /// scrambled order), with and without the quick proofs: the reports and the maps must be
    /// identical at every step, and real splits must have happened in every dimension.
    #[test]
    fn quick_proofs_change_no_outcome() {
        let (points, tets) = kuhn_cube(2);
        let (cube, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut splits = [0usize; 4];
        let mut sides = 0;
        for i in 0..=3 {
            let (mut fast, mut slow) = (cube.clone(), cube.clone());
            let mut darts: Vec<DartId> = cube.darts().collect();
            let mut rng = SplitMix64(11 + i as u64);
            for k in (1..darts.len()).rev() {
                darts.swap(k, rng.below(k + 1));
            }
            for d in darts {
                if fast.is_free(i, d) {
                    continue;
                }
                let (a, b) = (fast.unsew_with(i, d, true).unwrap(), slow.unsew_with(i, d, false).unwrap());
                assert_eq!(a, b, "alpha{i} unsew of {d}");
                // Each reported new side is exactly the new cell (as a set), on both paths; the
                // slow path walks every split, so it reports every side.
                for (map, changes, all) in [(&fast, &a, false), (&slow, &b, true)] {
                    for dim in 0..=3 {
                        for (k, (_, new, _, dart_new)) in changes.splits_with_index(dim) {
                            let mut side = changes.new_side(k).to_vec();
                            if side.is_empty() && !all {
                                continue;
                            }
                            let mut cell = map.cell_darts(dim, dart_new);
                            side.sort_unstable();
                            cell.sort_unstable();
                            assert_eq!(side, cell, "alpha{i} unsew of {d}: new side of {dim}-cell {new}");
                            sides += 1;
                        }
                    }
                }
                for (dim, n) in splits.iter_mut().enumerate() {
                    *n += a.splits(dim).count();
                }
            }
            assert!(same_state(&fast, &slow), "alpha{i}: the maps differ");
            assert_eq!(fast.validate(), Ok(()));
            assert_eq!(fast.count_cells(), fast.count_cells_by_traversal());
        }
        assert!(splits.iter().all(|&n| n > 0), "splits per dimension {splits:?}");
        assert!(sides > splits.iter().sum::<usize>(), "sides checked {sides}");
    }

    /// The bit-set classes are the connected components of the link graph: on random graphs
    /// (1 to 32 endpoints, sparse to dense, links of several generators, one generator left
    /// out as a cell dimension would be), `joined`, `members` and `has_earlier_member` agree with
    /// a plain union-find over the same links; past the covered endpoints nothing is joined.
    #[test]
    fn classes_are_the_connected_components() {
        let mut rng = SplitMix64(23);
        for round in 0..500 {
            let ends = 1 + rng.below(2 * QuickLinks::MAX_PAIRS);
            let mut links = QuickLinks::none();
            links.ends = ends;
            let mut edges = Vec::new();
            for _ in 0..rng.below(1 + ends * (1 + round % 3)) {
                let (p, q, k) = (rng.below(ends), rng.below(ends), rng.below(QuickLinks::MAX_GENS));
                links.push(p, q, k);
                edges.push((p, q, k));
            }
            let dim = rng.below(QuickLinks::MAX_GENS);
            let classes = links.classes(dim);
            let mut parent: Vec<usize> = (0..ends).collect();
            fn root(parent: &mut [usize], mut p: usize) -> usize {
                while parent[p] != p {
                    p = parent[p];
                }
                p
            }
            for &(p, q, _) in edges.iter().filter(|e| e.2 != dim) {
                let (rp, rq) = (root(&mut parent, p), root(&mut parent, q));
                parent[rp] = rq;
            }
            for p in 0..ends {
                let class: Vec<usize> = (0..ends).filter(|&q| root(&mut parent, q) == root(&mut parent, p)).collect();
                assert_eq!(bits(classes.members(p)).collect::<Vec<_>>(), class, "round {round}, endpoint {p}");
                for q in 0..ends {
                    assert_eq!(classes.joined(p, q), class.contains(&q), "round {round}, {p} ~ {q}");
                }
                assert_eq!(classes.has_earlier_member(p), class[0] < p, "round {round}, endpoint {p}");
            }
            for p in ends..40 {
                assert!(!classes.has_earlier_member(p) && !classes.joined(p, 0) && !classes.joined(0, p));
            }
        }
        assert!(!QuickLinks::none().classes(0).joined(0, 0), "no proof, nothing joined");
    }

    /// The direct links read off a closed unsewn cycle are those looked up dart by dart: the same
    /// bit sets, for α3-unsews (closed triangles) and α0-unsews (closed edge rings) of a 3-map,
    /// with the tets as built (links computed) and after α2-cuts (links read), at every dart.
    #[test]
    fn cycle_links_are_the_looked_up_links() {
        let (points, tets) = kuhn_cube(2);
        let (cube, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut cycles = [0usize; 4];
        let maps = [cube.clone(), cut_at_random(&cube, 3, 5, 4), cut_at_random(&cube, 2, 7, 9)];
        for (m, map) in maps.iter().enumerate() {
            assert_eq!(map.tets_as_built(), m < 2);
            for (i, cycles) in cycles.iter_mut().enumerate() {
                for d in map.darts().filter(|&d| !map.is_free(i, d)) {
                    let mut pairs = Vec::new();
                    let cycle = map.unsewn_pairs(i, d, &mut pairs);
                    let Some(ends) = cycle.endpoints(pairs.len()) else { continue };
                    let mut unlinked = map.clone();
                    for &(x, _) in &pairs {
                        unlinked.unlink_raw(i, x);
                    }
                    let (mut looked_up, mut read) = (QuickLinks::none(), QuickLinks::none());
                    looked_up.find(&unlinked, i, &pairs, None);
                    read.find(&unlinked, i, &pairs, Some(&ends));
                    assert!(looked_up.ends > 0, "alpha{i} unsew of {d}: no proof built");
                    assert_eq!(looked_up.adjacent, read.adjacent, "alpha{i} unsew of {d}");
                    assert_eq!(looked_up.direct, read.direct, "alpha{i} unsew of {d}");
                    *cycles += 1;
                }
            }
        }
        assert!(cycles[0] > 0 && cycles[3] > 0 && cycles[1] == 0 && cycles[2] == 0, "cycles per i {cycles:?}");
    }

    /// A face α3-sewn to itself (six darts, three pairs: the orbit holds both darts of each
    /// pair) gives no cycle hint, and its unsew comes out the same with and without the quick
    /// proofs.
    #[test]
    fn self_glued_faces_give_no_cycle_hint() {
        let (tet, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut glued = 0;
        for (d, e) in tet.darts().flat_map(|d| tet.darts().map(move |e| (d, e))) {
            if !tet.is_sewable::<3>(d, e) {
                continue;
            }
            let mut fast = tet.clone();
            fast.sew::<3>(d, e).unwrap();
            let mut pairs = Vec::new();
            let cycle = fast.unsewn_pairs(3, d, &mut pairs);
            if pairs.len() == 6 {
                continue; // glued to another face
            }
            assert!(cycle.closed && cycle.len == 6 && pairs.len() == 3, "{d} ~ {e}");
            assert!(cycle.endpoints(pairs.len()).is_none(), "{d} ~ {e}: a hint for a self-glued face");
            let mut slow = fast.clone();
            assert_eq!(fast.unsew_with(3, d, true).unwrap(), slow.unsew_with(3, d, false).unwrap(), "{d} ~ {e}");
            assert!(same_state(&fast, &slow) && fast.validate().is_ok(), "{d} ~ {e}");
            glued += 1;
        }
        assert!(glued > 0, "no face could be glued to itself");
    }

    /// The hashed endpoint index answers as the linear scan it replaces, for endpoints and for
    /// other darts, on real unsew pair lists and on random ones (colliding slots included).
    #[test]
    fn endpoint_index_is_the_linear_scan() {
        let mut rng = SplitMix64(5);
        for round in 0..400 {
            let n = 1 + rng.below(QuickLinks::MAX_PAIRS);
            // Small dart ranges in some rounds force collisions and repeated darts.
            let range = if round % 2 == 0 { 40 } else { 1 << 30 };
            let pairs: Vec<(DartId, DartId)> =
                (0..n).map(|_| (DartId(rng.below(range) as u32), DartId(rng.below(range) as u32))).collect();
            let table = EndpointIndex::new(&pairs);
            let scan = |d: DartId| (0..2 * pairs.len()).find(|&k| endpoint(&pairs, k) == d);
            for k in 0..2 * n {
                let d = endpoint(&pairs, k);
                assert_eq!(table.get(d), scan(d), "pairs {pairs:?}, dart {d}");
            }
            for _ in 0..50 {
                let d = DartId(rng.below(range) as u32);
                assert_eq!(table.get(d), scan(d), "pairs {pairs:?}, dart {d}");
            }
        }
    }

    /// A copy of `map` with about one in `one_in` of its i-sewn darts unsewn (seeded).
    fn cut_at_random<const N: usize>(map: &GMap<N>, i: usize, seed: u64, one_in: usize) -> GMap<N> {
        let mut cut = map.clone();
        let mut rng = SplitMix64(seed);
        for d in map.darts() {
            if rng.below(one_in) == 0 && !cut.is_free(i, d) {
                cut.unsew_with(i, d, false).unwrap();
            }
        }
        cut
    }

    /// A split walk's answer with the side sorted (the order is not part of the answer).
    fn as_set(answer: Option<(Vec<DartId>, bool)>) -> Option<(Vec<DartId>, bool)> {
        answer.map(|(mut side, flag)| {
            side.sort_unstable();
            (side, flag)
        })
    }

    /// The answer of a shortcut's `split_side` that appends to a list, run on a list that
    /// already holds other darts: they must be left as they were, and nothing appended on
    /// `None`. Returns the appended side (sorted) and the flag.
    fn appended(split_side: impl FnOnce(&mut Vec<DartId>) -> Option<bool>) -> Option<(Vec<DartId>, bool)> {
        let before = [DartId(7), DartId(3), DartId(7)];
        let mut out = before.to_vec();
        let flag = split_side(&mut out);
        assert_eq!(out[..before.len()], before, "the darts already in the list changed");
        let side = out.split_off(before.len());
        assert!(flag.is_some() || side.is_empty(), "darts appended without a split: {side:?}");
        as_set(flag.map(|flag| (side, flag)))
    }

    /// [`CornerCell::split_side`] is [`GMap::split_side`] (the same side as a set, the same
    /// flag) on pairs of i-free darts of a cut 3-map, for every i and every cell dimension ≠ i,
    /// pairs of one corner included.
    #[test]
    fn corner_split_is_split_side() {
        let (points, tets) = kuhn_cube(2);
        let (cube, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mut seen = [0; 3]; // joined, split on a's side, split on z's side
        for i in 0..=3 {
            let map = cut_at_random(&cube, i, 17 + i as u64, 3);
            for dim in (0..=3).filter(|&dim| dim != i) {
                let corners = CornerCell::of(3, i, dim).unwrap();
                let free: Vec<DartId> = map.darts().filter(|&d| map.is_free(i, d)).collect();
                for (n, &a) in free.iter().enumerate().step_by(2) {
                    let near = [map.alpha_local(corners.h, a), map.alpha_local(corners.l, a)];
                    for z in free.iter().copied().skip(n % 7).step_by(7).chain(near) {
                        let want = as_set(map.split_side(a, z, AlphaMask::cell(3, dim)));
                        assert_eq!(
                            appended(|out| corners.split_side(&map, a, z, out)),
                            want,
                            "alpha{i} dim {dim}: {a:?} {z:?}"
                        );
                        seen[want.map_or(0, |w| 1 + usize::from(w.1))] += 1;
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 20), "joined / a's side / z's side: {seen:?}");
        assert!(CornerCell::of(2, 2, 0).is_none() && CornerCell::of(3, 3, 3).is_none());
    }

    /// A fan of `n` triangles around point 0 (a closed disk) and a needle of `n` tets around the
    /// edge of points 0 and 1 (a closed ring), with the dart of element t that is sewn to element
    /// t + 1 across the spoke (the edge 0–(t+1)) or the face (0, 1, t + 2) of both.
    fn fan_and_needle(n: u32) -> ((GMap<2>, Vec<DartId>), (GMap<3>, Vec<DartId>)) {
        let (points, triangles) = crate::generate::disk_fan(n);
        let (fan, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
        let tets: Vec<[u32; 4]> = (0..n).map(|t| [0, 1, 2 + t, 2 + (t + 1) % n]).collect();
        let (needle, _) = GMap::<3>::from_tets(n as usize + 2, &tets).unwrap();
        let next = |size: usize, t: usize, d: DartId, alpha: DartId| {
            d.index() / size == t && alpha.index() / size == (t + 1) % n as usize
        };
        let spokes = (0..n as usize)
            .map(|t| fan.darts().find(|&d| fan.cell_id(0, d) == CellId(0) && next(6, t, d, fan.alpha::<2>(d))).unwrap())
            .collect();
        let on_axis = |d: DartId| needle.cell_id(0, d).0 < 2 && needle.cell_id(0, needle.alpha::<0>(d)).0 < 2;
        let faces = (0..n as usize)
            .map(|t| needle.darts().find(|&d| on_axis(d) && next(24, t, d, needle.alpha::<3>(d))).unwrap())
            .collect();
        ((fan, spokes), (needle, faces))
    }

    /// [`RingCell::split_side`] is [`GMap::split_side`] (the same side as a set, the same flag)
    /// on every pair of i-free darts of a map with boundaries and cuts, in every cell dimension
    /// that has a ring form, for 3-maps unsewn by α3 (edges), α2, α1 or α0 and 2-maps unsewn by
    /// α2 (vertices and edges) or α1. The pairs include joined ones, split ones of equal sizes
    /// (ties) and of very different sizes (a fan and a needle cut in a few places), and darts of
    /// one cell; the sides include paths that are their cell alone because αk fixes the anchor
    /// (a boundary) or because αk maps the path onto itself (a face α3-sewn to itself).
    #[test]
    fn ring_split_is_split_side() {
        /// Joined, split on a's side, on z's side, ties, sizes ≥ 4 × apart, folded paths.
        type Seen = [usize; 6];
        fn check<const N: usize>(map: &GMap<N>, i: usize, every: usize) -> Seen {
            let mut seen = [0; 6];
            for dim in (0..=N).filter(|&dim| dim != i) {
                let Some(ring) = RingCell::of(N, i, dim) else { continue };
                let free: Vec<DartId> = map.darts().filter(|&d| map.is_free(i, d)).collect();
                for (n, &a) in free.iter().enumerate() {
                    let mut walk = PathWalk::new(map, &ring, a);
                    while walk.step(map, &ring).is_some() {}
                    seen[5] += usize::from(walk.single && walk.twin != a);
                    for &z in free.iter().skip(n % every).step_by(every) {
                        let want = as_set(map.split_side(a, z, AlphaMask::cell(N, dim)));
                        assert_eq!(
                            appended(|out| ring.split_side(map, a, z, out)),
                            want,
                            "alpha{i} dim {dim}: {a:?} {z:?}"
                        );
                        seen[want.as_ref().map_or(0, |w| 1 + usize::from(w.1))] += 1;
                        if let Some((side, is_z)) = want {
                            let other = map.cell_darts(dim, if is_z { a } else { z }).len();
                            seen[3] += usize::from(other == side.len());
                            seen[4] += usize::from(other >= 4 * side.len());
                        }
                    }
                }
            }
            seen
        }
        let mut totals = [0; 6];
        let mut add = |seen: Seen| totals.iter_mut().zip(seen).for_each(|(t, s)| *t += s);
        let (points, tets) = kuhn_cube(2);
        let (cube, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        for i in 0..=3 {
            add(check(&cut_at_random(&cube, i, 3 + i as u64, 4), i, 5));
        }
        let (points, triangles) = crate::generate::grid_triangles(4);
        let (grid, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
        for i in 1..=2 {
            add(check(&cut_at_random(&grid, i, 5 + i as u64, 3), i, 5));
        }
        let ((mut fan, spokes), (mut needle, faces)) = fan_and_needle(40);
        for t in [0, 1, 2, 9, 17, 33] {
            fan.unsew::<2>(spokes[t]).unwrap();
            needle.unsew::<3>(faces[t]).unwrap();
        }
        add(check(&fan, 2, 3));
        add(check(&needle, 3, 7));
        // A tet with one face α3-sewn to itself, cut in its α0 or α1 links: the face's path
        // ⟨α0, α1⟩ or ⟨α1, α0⟩ is then its own α3 image.
        let (tet, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        for (d, e) in tet.darts().flat_map(|d| tet.darts().map(move |e| (d, e))) {
            if tet.is_sewable::<3>(d, e) {
                let mut glued = tet.clone();
                glued.sew::<3>(d, e).unwrap();
                for i in 0..=1 {
                    add(check(&cut_at_random(&glued, i, u64::from(d.0 + e.0), 2), i, 1));
                }
            }
        }
        assert!(totals.iter().all(|&n| n > 20), "joined / a's / z's side / ties / lopsided / folded: {totals:?}");
    }

    /// [`RingCell::split_side`] costs the smaller side, not the larger: cutting 2-dart pieces
    /// off the centre of a fan of 10 000 triangles (α2), and one tet off a needle of 10 000 tets
    /// around one edge (α3, the edge's ring), the walk steps at most twice per dart of the
    /// piece, with either endpoint as the anchor. (Reading both cells whole, it stepped through
    /// the 20 000 or 40 000 darts of the rest.)
    #[test]
    fn ring_split_costs_the_smaller_side() {
        fn cut<const N: usize>(map: &mut GMap<N>, i: usize, dim: usize, d: DartId, piece: usize) {
            let z = map.alpha_dyn(i, d);
            map.unsew_with(i, d, false).unwrap();
            let ring = RingCell::of(N, i, dim).unwrap();
            for (a, z, is_z) in [(d, z, false), (z, d, true)] {
                RING_STEPS.set(0);
                let mut out = Vec::new();
                assert_eq!(ring.split_side(map, a, z, &mut out), Some(is_z), "alpha{i} unsew of {d}");
                assert_eq!(out.len(), piece, "alpha{i} unsew of {d}");
                assert!(RING_STEPS.get() <= 2 * piece, "{} steps for a side of {piece} darts", RING_STEPS.get());
            }
        }
        let ((mut fan, spokes), (mut needle, faces)) = fan_and_needle(10_000);
        fan.unsew::<2>(spokes[0]).unwrap(); // opens the disk: no piece yet
        needle.unsew::<3>(faces[0]).unwrap();
        for &spoke in &spokes[1..20] {
            cut(&mut fan, 2, 0, spoke, 2); // the two darts at the centre of the spoke's triangle
        }
        cut(&mut needle, 3, 1, faces[1], 4); // tet 1's four darts on the axis
    }

    /// The same on a 2-map (rings ⟨α1, α2⟩ and ⟨α0, α1⟩, ⟨α2, α1⟩), cut edge by edge.
    #[test]
    fn quick_proofs_change_no_outcome_in_2d() {
        let (points, triangles) = crate::generate::grid_triangles(4);
        let (grid, _) = GMap::<2>::from_triangles(points.len(), &triangles).unwrap();
        for i in 0..=2 {
            let (mut fast, mut slow) = (grid.clone(), grid.clone());
            for d in grid.darts().collect::<Vec<_>>().into_iter().rev() {
                if !fast.is_free(i, d) {
                    assert_eq!(fast.unsew_with(i, d, true).unwrap(), slow.unsew_with(i, d, false).unwrap());
                }
            }
            assert!(same_state(&fast, &slow));
            assert_eq!(fast.count_cells(), fast.count_cells_by_traversal());
        }
    }
}

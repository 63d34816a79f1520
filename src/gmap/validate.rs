//! The laws of an n-G-map with cell ids, and `validate()`, which checks all of them.
//!
//! | law | statement | checked by |
//! |---|---|---|
//! | [`Law::Involution`] | αi(αi(d)) = d for every live d and i ≤ n, and αi(d) is live | [`GMap::validate`], local checks |
//! | [`Law::QuasiManifold`] | αi(αj(d)) = αj(αi(d)) for 0 ≤ i, i + 2 ≤ j ≤ n | same |
//! | [`Law::CellIdConstant`] | the i-cell id is constant on every orbit ⟨⟩N−{i} and is a live id | same |
//! | [`Law::CellIdUnique`] | two different i-cells never share an id, and every live id has a cell | `validate` |
//!
//! `validate()` costs O(darts · n² · α(darts)): one sequential pass for the first three laws and
//! one union-find sweep (all dimensions at once) for the last. The local check costs
//! O(touched · n²).
//!
//! Two paths, one verdict: a fast path decides whether every law holds (one pass reading each
//! dart's row and its n + 1 neighbours' rows, then per dimension #orbits = #distinct ids =
//! #live ids, which given constant live ids is equivalent to uniqueness with no orphan; the
//! distinct ids are read only at the local minima of each dimension, which include one dart of
//! every orbit, and a dimension whose local minima all carry distinct ids needs no orbit count);
//! only when it finds a violation does the detailed path run, which checks the laws in the
//! table's order and names the first violation.
//!
//! A map flagged [`GMap::tets_as_built`] whose layout law holds takes a third path instead of
//! the generic fast one (`validate_tets`): the layout fixes α0, α1, α2 inside every tet, so the
//! laws about them hold by the pattern, and what is left is checked per tet (α3 and the ids
//! across it) and counted per piece of a tet (corner, edge, face) rather than per dart. Same
//! verdict (tested against the generic path and the proofs' oracle), ~1.7× faster on the Kuhn
//! cube.

use super::orbit::{generators, VisitBits};
use super::{AlphaMask, CellId, DartId, DartSet, GMap};

/// The law a violation breaks.
///
/// # Examples
///
/// ```
/// use topomech::gmap::Law;
/// use topomech::{CellId, DartId, InvariantViolation};
///
/// let v = InvariantViolation::CellIdOrphan { dim: 0, id: CellId(9) };
/// assert_eq!(v.law(), Law::CellIdUnique);
/// let w = InvariantViolation::DanglingLink { dart: DartId(0), i: 2, target: DartId(99) };
/// assert_eq!(w.law(), Law::Involution);
/// assert_ne!(Law::CellIdConstant, Law::CellIdUnique);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Law {
    /// Each αi is an involution on the live darts.
    Involution,
    /// αi∘αj is an involution for j ≥ i + 2.
    QuasiManifold,
    /// Cell ids are constant on cells and live.
    CellIdConstant,
    /// Distinct cells have distinct ids; every live id names a cell.
    CellIdUnique,
    /// While [`GMap::tets_as_built`] is set, every tet keeps the builder's inner links (α0, α1, α2
    /// of dart 24t + k are 24t + the builder's pattern), so that computing them instead of
    /// reading them ([`GMap::tets_as_built`]'s use in cutting) is exact.
    TetLayout,
}

/// A broken law, naming the dart(s), the indices and the law.
///
/// # Examples
///
/// ```
/// use topomech::{generate, GMap, InvariantViolation};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let verdict: Result<(), InvariantViolation> = map.validate();
/// assert_eq!(verdict, Ok(())); // maps built through the public API keep every law
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InvariantViolation {
    /// αi(d) is not a live dart.
    #[error("involution law: alpha{i}({dart}) = {target:?}, which is not a live dart")]
    DanglingLink {
        /// The dart.
        dart: DartId,
        /// The involution.
        i: usize,
        /// Where it points.
        target: DartId,
    },
    /// αi(αi(d)) ≠ d.
    #[error("involution law: alpha{i}({dart}) = {image:?} but alpha{i}({image:?}) = {back:?}")]
    NotInvolution {
        /// The dart.
        dart: DartId,
        /// The involution.
        i: usize,
        /// αi(d).
        image: DartId,
        /// αi(αi(d)).
        back: DartId,
    },
    /// αi(αj(d)) ≠ αj(αi(d)) with j ≥ i + 2.
    #[error("quasi-manifold law: alpha{i}·alpha{j} is not an involution at {dart}: alpha{i}(alpha{j}) = {ij:?}, alpha{j}(alpha{i}) = {ji:?}")]
    QuasiManifold {
        /// The dart.
        dart: DartId,
        /// Lower index.
        i: usize,
        /// Higher index (≥ i + 2).
        j: usize,
        /// αi(αj(d)).
        ij: DartId,
        /// αj(αi(d)).
        ji: DartId,
    },
    /// The dim-cell id differs between d and αj(d) (j ≠ dim): one cell, two ids.
    #[error("cell-id law: {dart} has {dim}-cell {id:?} but alpha{j}({dart}) = {other:?} has {other_id:?}")]
    CellIdDiffers {
        /// The dart.
        dart: DartId,
        /// The cell dimension.
        dim: usize,
        /// The involution followed.
        j: usize,
        /// The dart's id.
        id: CellId,
        /// The neighbour.
        other: DartId,
        /// The neighbour's id.
        other_id: CellId,
    },
    /// A dart carries an id that is not live.
    #[error("cell-id law: {dart} carries {dim}-cell id {id:?}, which is not live")]
    CellIdNotLive {
        /// The dart.
        dart: DartId,
        /// The cell dimension.
        dim: usize,
        /// The id.
        id: CellId,
    },
    /// Two different orbits carry one id.
    #[error("cell-id law: {dim}-cells of {first} and {second} are different orbits but share id {id:?}")]
    CellIdShared {
        /// The cell dimension.
        dim: usize,
        /// The shared id.
        id: CellId,
        /// A dart of the first orbit.
        first: DartId,
        /// A dart of the second orbit.
        second: DartId,
    },
    /// A live id is carried by no dart.
    #[error("cell-id law: {dim}-cell id {id:?} is live but no dart carries it")]
    CellIdOrphan {
        /// The cell dimension.
        dim: usize,
        /// The id.
        id: CellId,
    },
    /// The map claims [`GMap::tets_as_built`] but αi(dart) is not the builder's link (`built`),
    /// or a dart slot is dead (`stored` is then the dart itself).
    #[error("tet-layout law: the map is flagged as built tets but alpha{i}({dart}) = {stored:?}, the builder's link is {built:?}")]
    TetLayout {
        /// The dart.
        dart: DartId,
        /// The involution (< 3).
        i: usize,
        /// The stored αi(dart).
        stored: DartId,
        /// The builder's αi(dart).
        built: DartId,
    },
}

impl InvariantViolation {
    /// The law broken.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::Law;
    /// use topomech::{DartId, InvariantViolation};
    ///
    /// let v = InvariantViolation::NotInvolution { dart: DartId(3), i: 1, image: DartId(4), back: DartId(5) };
    /// assert_eq!(v.law(), Law::Involution);
    /// assert!(v.to_string().contains("alpha1(dart 3)"));
    /// ```
    pub fn law(&self) -> Law {
        use InvariantViolation::*;
        match self {
            DanglingLink { .. } | NotInvolution { .. } => Law::Involution,
            QuasiManifold { .. } => Law::QuasiManifold,
            CellIdDiffers { .. } | CellIdNotLive { .. } => Law::CellIdConstant,
            CellIdShared { .. } | CellIdOrphan { .. } => Law::CellIdUnique,
            TetLayout { .. } => Law::TetLayout,
        }
    }
}

/// Per cell dimension: the number of local minima (darts none of whose neighbours under the
/// dimension's generators is smaller) and of distinct ids among them, `used` marking the ids
/// seen. Filled by the fast path's local pass.
struct IdCensus<'a> {
    minima: Vec<usize>,
    distinct: Vec<usize>,
    used: &'a mut [VisitBits],
}

impl IdCensus<'_> {
    /// Records dart d (α row `links`, cell row `cells`, ids known to be live): for each
    /// dimension where d is a local minimum, counts it and its id if new. O(n).
    #[inline(always)]
    fn record(&mut self, links: &[u32], cells: &[u32], d: u32) {
        let below = links.iter().enumerate().fold(0u32, |m, (j, &e)| m | (u32::from(e < d) << j));
        for (dim, &id) in cells.iter().enumerate() {
            if below & !(1 << dim) == 0 {
                self.minima[dim] += 1;
                self.distinct[dim] += self.used[dim].insert(id) as usize;
            }
        }
    }
}

impl<const N: usize> GMap<N> {
    /// Checks every law of [`Law`]: involutions, quasi-manifold, constant and unique cell ids.
    /// O(darts · n²).
    ///
    /// Errors: the first violation in the order of the table (involution and quasi-manifold laws
    /// of every dart first, then cell ids of every dart, then uniqueness per dimension).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(2);
    /// let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// assert_eq!(map.validate(), Ok(()));
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// map.unsew::<3>(d).unwrap();
    /// assert_eq!(map.validate(), Ok(())); // public mutators keep every law
    /// ```
    pub fn validate(&self) -> Result<(), InvariantViolation> {
        if self.laws_hold() {
            return Ok(());
        }
        self.validate_detailed()
    }

    /// The fast path: whether every law holds. Maps flagged [`GMap::tets_as_built`] whose layout
    /// law holds take the tet path (`validate_tets`), the others the generic one. O(darts · n²).
    fn laws_hold(&self) -> bool {
        let (dead, live) = self.id_liveness();
        if self.tets_as_built {
            return self.built_tet_laws_hold(&dead, &live);
        }
        self.all_laws_hold(&dead, &live)
    }

    /// Per cell dimension: the freed ids below the allocator's bound (`None` when there is none)
    /// and the number of live ids. O(ids).
    pub(super) fn id_liveness(&self) -> (Vec<Option<VisitBits>>, Vec<usize>) {
        let mut dead = Vec::with_capacity(N + 1);
        let mut live = Vec::with_capacity(N + 1);
        for alloc in &self.ids {
            let mut set = VisitBits::new(alloc.next as usize);
            let freed = alloc.free.iter().filter(|&&id| id < alloc.next && set.insert(id)).count();
            dead.push((freed > 0).then_some(set));
            live.push(alloc.next as usize - freed);
        }
        (dead, live)
    }

    /// The [`Law::TetLayout`] law: when [`GMap::tets_as_built`] is set, every dart slot is live
    /// and α0, α1, α2 of dart 24t + k are 24t + the builder's pattern for k. O(darts) when the
    /// flag is set (one sequential pass over the α rows), O(1) otherwise.
    pub(super) fn check_tet_layout(&self) -> Result<(), InvariantViolation> {
        if !self.tets_as_built {
            return Ok(());
        }
        let row = N + 1;
        let violation = |d: usize, i: usize| InvariantViolation::TetLayout {
            dart: DartId(d as u32),
            i,
            stored: DartId(self.alpha.get(d * row + i).copied().unwrap_or(d as u32)),
            built: DartId(crate::build::built_tet_link(i, d as u32)),
        };
        if N != 3 || self.capacity() % 24 != 0 {
            return Err(violation(self.capacity(), 0));
        }
        if let Some(d) = (0..self.capacity()).find(|&d| !self.contains(DartId(d as u32))) {
            return Err(violation(d, 0));
        }
        for (d, links) in self.alpha.chunks_exact(row).enumerate() {
            let built = crate::build::built_tet_links(d as u32);
            if let Some(i) = (0..3).find(|&i| links[i] != built[i]) {
                return Err(violation(d, i));
            }
        }
        Ok(())
    }

    /// The detailed path: names the first violation. O(darts · n²).
    fn validate_detailed(&self) -> Result<(), InvariantViolation> {
        let dead = self.dead_id_sets();
        // Involutions everywhere first, so that a broken link is named as such and not as a
        // quasi-manifold violation seen from a neighbour.
        for d in self.darts() {
            self.check_dart_involutions(d)?;
        }
        for d in self.darts() {
            self.check_dart_quasi_manifold(d)?;
        }
        for d in self.darts() {
            self.check_dart_cells(d, Some(&dead))?;
        }
        for (dim, dead) in dead.iter().enumerate() {
            self.check_ids_unique(dim, dead)?;
        }
        self.check_tet_layout()
    }

    /// The generic fast path: whether the laws other than [`Law::TetLayout`] hold. Same verdict
    /// as [`Self::validate_detailed`] on them. `dead`, `live`: [`Self::id_liveness`].
    pub(super) fn all_laws_hold(&self, dead: &[Option<VisitBits>], live: &[usize]) -> bool {
        let mut used: Vec<VisitBits> = self.ids.iter().map(|a| VisitBits::new(a.next as usize)).collect();
        let mut census = IdCensus { minima: vec![0; N + 1], distinct: vec![0; N + 1], used: &mut used };
        if !self.local_laws_hold(dead, &mut census) {
            return false;
        }
        // Ids are now known to be constant on cells and live, so each orbit carries one id and
        // every carried id is live: ids are unique iff #orbits = #distinct ids, and no live id is
        // an orphan iff #distinct ids = #live ids. Every orbit contains a local minimum (its
        // smallest dart), which carries the orbit's id, so the local minima carry every id and
        // #distinct ≤ #orbits ≤ #local minima: where the last two counts of a dimension are
        // equal, its ids are unique with no orbit walk. Only the other dimensions are counted by
        // a union-find sweep.
        let IdCensus { minima, distinct, .. } = census;
        if distinct != live {
            return false;
        }
        let unsettled: Vec<usize> = (0..=N).filter(|&dim| minima[dim] != distinct[dim]).collect();
        if unsettled.is_empty() {
            return true;
        }
        let masks: Vec<AlphaMask> = unsettled.iter().map(|&dim| AlphaMask::cell(N, dim)).collect();
        let orbits = self.count_orbits_in_one_sweep(&masks);
        unsettled.iter().zip(orbits).all(|(&dim, count)| count == distinct[dim])
    }

    /// The involution, quasi-manifold and constant-live-id laws at every live dart (same verdict
    /// as `check_dart_links` + `check_dart_cells` on every dart), and the census of local minima
    /// and distinct ids of the darts that pass. `dead[dim]` is `None` when dimension dim has no
    /// freed id. O(darts · n²).
    ///
    /// Darts are checked 64 at a time (one word of the liveness bits). Before a word's darts are
    /// checked, a tight loop loads the first α and cell entries of the αn neighbour of each of
    /// its slots: these loads are independent, so the cache misses on distant neighbours (αn
    /// crosses from volume to volume, anywhere in the arrays) overlap instead of stalling the
    /// checks one dart at a time. The loaded values are discarded.
    fn local_laws_hold(&self, dead: &[Option<VisitBits>], census: &mut IdCensus<'_>) -> bool {
        let (w, capacity) = (N + 1, self.capacity());
        let mut touched = 0u32;
        for (word_index, &word) in self.alive.iter().enumerate() {
            let first = word_index * 64;
            for d in first..(first + 64).min(capacity) {
                let e = self.alpha[d * w + N] as usize;
                if e < capacity {
                    touched ^= self.alpha[e * w] ^ self.cell[e * w];
                }
            }
            let mut bits = word;
            while bits != 0 {
                let d = first as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if !self.dart_laws_hold(d, dead) {
                    return false;
                }
                census.record(self.alpha_row(d), self.cell_row(d), d);
            }
        }
        std::hint::black_box(touched);
        true
    }

    /// The local laws at live dart slot d, reading its row and its neighbours' rows once.
    /// Violations are accumulated in one flag rather than returned early, so the common (valid)
    /// path has no data-dependent branch besides the range test that guards indexing.
    #[inline(always)]
    fn dart_laws_hold(&self, d: u32, dead: &[Option<VisitBits>]) -> bool {
        let (w, capacity) = (N + 1, self.capacity());
        let (links, cells) = (self.alpha_row(d), self.cell_row(d));
        let mut bad = false;
        for (i, &e) in links.iter().enumerate() {
            if e as usize >= capacity {
                return false;
            }
            let alive = self.alive[e as usize >> 6] >> (e & 63) & 1 == 1;
            let other = e as usize * w;
            bad |= !alive | (self.alpha[other + i] != d);
            let other_cells = &self.cell[other..other + w];
            for dim in 0..w {
                bad |= (dim != i) & (other_cells[dim] != cells[dim]);
            }
        }
        // αi(αj(d)) is entry i of αj(d)'s row, αj(αi(d)) entry j of αi(d)'s row.
        for i in 0..w {
            for j in i + 2..w {
                bad |= self.alpha[links[j] as usize * w + i] != self.alpha[links[i] as usize * w + j];
            }
        }
        for (dim, &id) in cells.iter().enumerate() {
            bad |= id >= self.ids[dim].next;
            if let Some(dead) = &dead[dim] {
                bad |= dead.contains(id);
            }
        }
        !bad
    }

    /// Checks the local laws (involution, quasi-manifold, constant cell ids) at the given darts
    /// and their αi neighbours. O(touched · n³).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let touched: Vec<_> = map.darts().filter(|&d| !map.is_free(3, d)).collect();
    /// assert_eq!(touched.len(), 12);
    /// assert!(map.validate_local(&touched).is_ok());
    /// ```
    pub fn validate_local(&self, touched: &[DartId]) -> Result<(), InvariantViolation> {
        for &d in touched {
            if !self.contains(d) {
                continue;
            }
            self.check_dart_links(d)?;
            for i in 0..=N {
                let e = self.alpha_dyn(i, d);
                self.check_dart_links(e)?;
                self.check_dart_cells(e, None)?;
            }
        }
        Ok(())
    }

    /// Involution and quasi-manifold laws at one dart. O(n²).
    fn check_dart_links(&self, d: DartId) -> Result<(), InvariantViolation> {
        self.check_dart_involutions(d)?;
        self.check_dart_quasi_manifold(d)
    }

    /// The involution law at one dart: every αi(d) is live and αi(αi(d)) = d. O(n).
    fn check_dart_involutions(&self, d: DartId) -> Result<(), InvariantViolation> {
        for i in 0..=N {
            let image = DartId(self.alpha[d.index() * (N + 1) + i]);
            if !self.contains(image) {
                return Err(InvariantViolation::DanglingLink { dart: d, i, target: image });
            }
            let back = self.alpha_dyn(i, image);
            if back != d {
                return Err(InvariantViolation::NotInvolution { dart: d, i, image, back });
            }
        }
        Ok(())
    }

    /// The quasi-manifold law at one dart. A dead dart met on the way is reported as a dangling
    /// link of the dart that points to it. O(n²).
    fn check_dart_quasi_manifold(&self, d: DartId) -> Result<(), InvariantViolation> {
        for i in 0..=N {
            for j in i + 2..=N {
                let ij = self.live_alpha(i, self.live_alpha(j, d)?)?;
                let ji = self.live_alpha(j, self.live_alpha(i, d)?)?;
                if ij != ji {
                    return Err(InvariantViolation::QuasiManifold { dart: d, i, j, ij, ji });
                }
            }
        }
        Ok(())
    }

    /// αi(d) if it is a live dart (d must be live), else the dangling link. O(1).
    fn live_alpha(&self, i: usize, d: DartId) -> Result<DartId, InvariantViolation> {
        let image = DartId(self.alpha[d.index() * (N + 1) + i]);
        if !self.contains(image) {
            return Err(InvariantViolation::DanglingLink { dart: d, i, target: image });
        }
        Ok(image)
    }

    /// Cell ids at one dart: constant across each generator of the cell, and live. O(n²).
    fn check_dart_cells(&self, d: DartId, dead: Option<&[DartSet]>) -> Result<(), InvariantViolation> {
        for dim in 0..=N {
            let id = self.cell_id(dim, d);
            let live = match dead {
                Some(dead) => id.0 < self.ids[dim].next && !dead[dim].contains(DartId(id.0)),
                None => id.0 < self.ids[dim].next,
            };
            if !live {
                return Err(InvariantViolation::CellIdNotLive { dart: d, dim, id });
            }
            for j in (0..=N).filter(|&j| j != dim) {
                let other = self.alpha_dyn(j, d);
                let other_id = self.cell_id(dim, other);
                if other_id != id {
                    return Err(InvariantViolation::CellIdDiffers { dart: d, dim, j, id, other, other_id });
                }
            }
        }
        Ok(())
    }

    /// The freed ids of each dimension as bit sets (ids reuse the dart bit set type).
    fn dead_id_sets(&self) -> Vec<DartSet> {
        self.ids
            .iter()
            .map(|alloc| {
                let mut set = DartSet::with_capacity(alloc.next as usize);
                alloc.free.iter().for_each(|&id| {
                    set.insert(DartId(id));
                });
                set
            })
            .collect()
    }

    /// Distinct dim-cells carry distinct ids and every live id is used. One flood per orbit.
    fn check_ids_unique(&self, dim: usize, dead: &DartSet) -> Result<(), InvariantViolation> {
        let (gens, len) = generators(N, AlphaMask::cell(N, dim));
        let mut owner = vec![u32::MAX; self.ids[dim].next as usize];
        let mut seen = VisitBits::new(self.capacity());
        let mut stack = Vec::new();
        for d in self.darts() {
            if !seen.insert(d.0) {
                continue;
            }
            let id = self.cell_id(dim, d);
            if owner[id.index()] != u32::MAX {
                let first = DartId(owner[id.index()]);
                return Err(InvariantViolation::CellIdShared { dim, id, first, second: d });
            }
            owner[id.index()] = d.0;
            self.flood(d.0, &gens[..len], &mut seen, &mut stack);
        }
        match (0..owner.len()).find(|&k| owner[k] == u32::MAX && !dead.contains(DartId(k as u32))) {
            Some(k) => Err(InvariantViolation::CellIdOrphan { dim, id: CellId(k as u32) }),
            None => Ok(()),
        }
    }
}

/// A lone tet as built whose α1 is rewired inside (darts 0 and 6 swap partners: still an
/// involution, every piece of the pattern keeps one id, nothing sewn by α3), with the
/// tets-as-built flag forced on. Its actual vertex orbits are no longer the pattern's corners
/// (the generic laws see vertex ids that are not constant), but every check of the tet paths that
/// reads the pattern passes: only their layout check can tell. For the tests of the tet paths.
#[cfg(test)]
pub(super) fn tet_rewired_inside() -> GMap<3> {
    let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let (a, b) = (DartId(0), DartId(6));
    let (a1, b1) = (map.alpha_dyn(1, a), map.alpha_dyn(1, b));
    map.link_raw(1, a, b);
    map.link_raw(1, a1, b1);
    map.tets_as_built = true;
    map
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `validate`'s fast path says "valid" exactly when the detailed walk finds nothing, on
    /// both of its branches (tets as built, generic): a fast path stuck at "invalid" would
    /// only cost time, so only this test sees it.
    #[test]
    fn the_fast_path_agrees_with_the_detailed_walk() {
        let (valid, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
        for (built, ok) in [(valid, true), (tet_rewired_inside(), false)] {
            assert!(built.tets_as_built);
            let mut generic = built.clone();
            generic.tets_as_built = false;
            for map in [&built, &generic] {
                assert_eq!((map.laws_hold(), map.validate_detailed().is_ok()), (ok, ok));
            }
        }
    }

    /// A local minimum is a dart none of whose neighbours is smaller: a free link (αj(d) = d)
    /// is not a smaller neighbour, a link to a smaller dart is, and only the dimensions whose
    /// generators include that link lose the minimum.
    #[test]
    fn free_links_do_not_hide_a_local_minimum() {
        let mut used: Vec<VisitBits> = (0..3).map(|_| VisitBits::new(8)).collect();
        let mut census = IdCensus { minima: vec![0; 3], distinct: vec![0; 3], used: &mut used };
        // Dart 5 of a 2-map: α0 free, α1 → 7, α2 free: a minimum in every dimension.
        census.record(&[5, 7, 5], &[1, 2, 3], 5);
        assert_eq!(census.minima, vec![1, 1, 1]);
        assert_eq!(census.distinct, vec![1, 1, 1]);
        // Dart 6: α1 → 2 (smaller): a minimum only for the 1-cell (generators α0, α2).
        census.record(&[6, 2, 6], &[4, 5, 3], 6);
        assert_eq!(census.minima, vec![1, 2, 1]);
        assert_eq!(census.distinct, vec![1, 2, 1], "id 5 is new for dimension 1");
    }

    /// Exchanges the labels of darts a and b (rows and every link to them): an isomorphic map,
    /// so every other law still holds.
    fn swap_labels(map: &mut GMap<3>, a: usize, b: usize) {
        for k in 0..4 {
            map.alpha.swap(a * 4 + k, b * 4 + k);
            map.cell.swap(a * 4 + k, b * 4 + k);
        }
        for link in map.alpha.iter_mut() {
            if *link == a as u32 {
                *link = b as u32;
            } else if *link == b as u32 {
                *link = a as u32;
            }
        }
    }

    /// The tet-layout law binds exactly while the flag is set: two darts of one tet relabelled
    /// (a valid, isomorphic map) break it and validate() names the first dart whose link is
    /// not the builder's; with the flag cleared the same map is valid.
    #[test]
    fn tet_layout_law_is_checked_while_the_flag_is_set() {
        let (points, tets) = crate::generate::kuhn_cube(1);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        assert!(map.tets_as_built());
        assert_eq!(map.validate(), Ok(()));
        swap_labels(&mut map, 24 + 3, 24 + 17);
        assert!(map.tets_as_built(), "the raw relabelling must not clear the flag");
        let err = map.validate().unwrap_err();
        assert_eq!(err.law(), Law::TetLayout);
        let InvariantViolation::TetLayout { dart, i, stored, built } = err else { unreachable!() };
        assert!((24..48).contains(&dart.index()), "{dart:?}");
        assert_ne!(stored, built);
        assert_eq!(map.alpha_dyn(i, dart), stored);
        map.tets_as_built = false;
        assert_eq!(map.validate(), Ok(()));
    }

    /// [`tet_rewired_inside`]: validate's tet path must refuse it through its layout check, and
    /// the detailed pass names the first law broken in table order.
    #[test]
    fn a_tet_rewired_inside_is_refused_by_the_tet_path() {
        let mut map = tet_rewired_inside();
        assert!(!map.laws_hold(), "the fast path missed the rewiring");
        assert_eq!(map.validate().map_err(|e| e.law()), Err(Law::CellIdConstant)); // first in table order
        map.tets_as_built = false;
        assert_eq!(map.validate().map_err(|e| e.law()), Err(Law::CellIdConstant));
    }
}

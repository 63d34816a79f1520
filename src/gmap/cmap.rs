//! Export of an orientable n-G-map to an n-dimensional combinatorial map.
//!
//! Keep the darts of one colour of an orientation (every αi link joins two colours). On them,
//! β1 = α0∘α1 (first α1, then α0) is a permutation and βi = α0∘αi (i ≥ 2) is an involution or
//! undefined (the dart is i-free in the G-map). Each kept dart stands for itself and α0 of it.
//!
//! The G-map's law that αi∘αj is an involution for |i − j| ≥ 2 carries over as the law of an
//! n-map that βi∘βj (first βj, then βi) is a partial involution for 1 ≤ i, i + 2 ≤ j ≤ n:
//! β1∘βj = α0α1α0αj and, for i ≥ 2, βi∘βj = α0αiα0αj = αiαj, both involutions because αj
//! commutes with α0, α1 and αi (and α0 with αi). "Partial": where βi(βj(d)) is defined, so is
//! βi(βj) of it, and it is d; so a face (a β1 orbit) is j-sewn whole or not at all. In 3D this is
//! β1∘β3: the two volumes on either side of a face pair its darts in opposite turning order.

use super::{DartId, GMap};

/// An n-map: darts 0..len, β1 a permutation, βi for i ≥ 2 partial involutions without fixed
/// points, and βi∘βj (first βj, then βi) a partial involution for 1 ≤ i, i + 2 ≤ j ≤ n (β1∘β3 in
/// 3D; see the module docs): wherever βi(βj(d)) is defined, βi(βj(βi(βj(d)))) is defined and is d.
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// let (tet, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let cmap = tet.to_combinatorial_map().unwrap();
/// assert!(cmap.is_valid());
/// assert_eq!(cmap.origin.len(), tet.dart_count() / 2); // one colour of the orientation
/// assert_eq!(cmap.beta.len(), 2); // β2 and β3
/// assert!(cmap.origin.iter().all(|&d| tet.contains(d)));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CombinatorialMap {
    /// For each combinatorial dart, the G-map dart it came from.
    pub origin: Vec<DartId>,
    /// β1 as indices into `origin`.
    pub beta1: Vec<u32>,
    /// `beta[i - 2][d]` = βi(d) for i in 2..=n, `None` where d is i-free.
    pub beta: Vec<Vec<Option<u32>>>,
}

impl CombinatorialMap {
    /// Checks that β1 is a permutation, every βi (i ≥ 2) an involution without fixed points
    /// where defined, and every βi∘βj with 1 ≤ i, i + 2 ≤ j ≤ n (β1∘β3 in 3D) a partial
    /// involution: wherever βi(βj(d)) is defined, βi(βj) of it is defined and is d (finding 199:
    /// a β3 re-paired inside a face stayed an involution and passed). Every map
    /// [`GMap::to_combinatorial_map`] returns passes. `false` (never a panic) when `beta1` or a
    /// row of `beta` does not have exactly `origin.len()` entries, so no β may name a dart that
    /// does not exist. O(darts · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// // The surface of a tetrahedron as a 2-map: 12 of the 24 darts, β1 turns around each triangle.
    /// let surface = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
    /// let (map, _) = GMap::<2>::from_triangles(4, &surface).unwrap();
    /// let cmap = map.to_combinatorial_map().unwrap();
    /// assert!(cmap.is_valid());
    /// assert_eq!(cmap.origin.len(), 12);
    /// let b1 = |d: u32| cmap.beta1[d as usize];
    /// assert!((0..12).all(|d| b1(b1(b1(d))) == d && b1(d) != d));
    /// assert!(cmap.beta[0].iter().all(|b| b.is_some())); // closed surface: β2 everywhere
    /// ```
    pub fn is_valid(&self) -> bool {
        let n = self.origin.len();
        if self.beta1.len() != n || self.beta.iter().any(|bi| bi.len() != n) {
            return false;
        }
        let mut hit = vec![false; n];
        for &b in &self.beta1 {
            if b as usize >= n || std::mem::replace(&mut hit[b as usize], true) {
                return false;
            }
        }
        let involutions = self.beta.iter().all(|bi| {
            (0..n).all(|d| match bi[d] {
                None => true,
                Some(e) => e as usize != d && bi.get(e as usize) == Some(&Some(d as u32)),
            })
        });
        involutions && self.compositions_are_involutions()
    }

    /// βi(d) for i ≥ 1 (`None` where d is i-free, or i or d out of range). O(1).
    fn beta_of(&self, i: usize, d: u32) -> Option<u32> {
        match i {
            1 => self.beta1.get(d as usize).copied(),
            _ => self.beta.get(i.checked_sub(2)?)?.get(d as usize).copied().flatten(),
        }
    }

    /// Whether βi∘βj is a partial involution for every 1 ≤ i, i + 2 ≤ j ≤ n. O(darts · n²).
    fn compositions_are_involutions(&self) -> bool {
        let n = self.beta.len() + 1;
        let step = |i: usize, j: usize, d: u32| self.beta_of(j, d).and_then(|e| self.beta_of(i, e));
        (1..=n).all(|i| {
            (i + 2..=n)
                .all(|j| (0..self.origin.len() as u32).all(|d| step(i, j, d).is_none_or(|y| step(i, j, y) == Some(d))))
        })
    }
}

impl<const N: usize> GMap<N> {
    /// The combinatorial map of an orientable G-map, or `None` if it is not orientable, some
    /// dart is 0-free or 1-free (β1 would not be a permutation), or some dart d has
    /// αi(d) = α0(d) for an i ≥ 2 (a cell sewn onto itself across that edge: βi = α0αi would fix
    /// d, and a βi with a fixed point is no involution of a combinatorial map). O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let strip: Vec<[u32; 3]> = (0..5).map(|i| [i, (i + 1) % 5, (i + 2) % 5]).collect();
    /// let (mobius, _) = GMap::<2>::from_triangles(5, &strip).unwrap();
    /// assert!(mobius.to_combinatorial_map().is_none()); // not orientable
    /// let (tet, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let cmap = tet.to_combinatorial_map().unwrap();
    /// assert_eq!(cmap.origin.len(), 12);
    /// assert!(cmap.beta[1].iter().all(|b| b.is_none())); // a lone tet: β3 undefined
    /// ```
    pub fn to_combinatorial_map(&self) -> Option<CombinatorialMap> {
        let colour = self.orientation()?;
        if self.darts().any(|d| self.is_free(0, d) || self.is_free(1, d)) {
            return None;
        }
        // (An i-free d has αi(d) = d ≠ α0(d), d being 0-sewn here: only a fold matches.)
        let folded = |d: DartId| (2..=N).any(|i| self.alpha_dyn(i, d) == self.alpha_dyn(0, d));
        if self.darts().any(folded) {
            return None;
        }
        let origin: Vec<DartId> = self.darts().filter(|d| colour[d.index()] == 0).collect();
        let mut index = vec![u32::MAX; self.capacity()];
        origin.iter().enumerate().for_each(|(k, d)| index[d.index()] = k as u32);
        let beta1 = origin.iter().map(|&d| index[self.alpha_dyn(0, self.alpha_dyn(1, d)).index()]).collect();
        let beta = (2..=N)
            .map(|i| {
                origin
                    .iter()
                    .map(|&d| (!self.is_free(i, d)).then(|| index[self.alpha_dyn(0, self.alpha_dyn(i, d)).index()]))
                    .collect()
            })
            .collect();
        Some(CombinatorialMap { origin, beta1, beta })
    }
}

//! Export of an orientable n-G-map to an n-dimensional combinatorial map.
//!
//! Keep the darts of one colour of an orientation (every αi link joins two colours). On them,
//! β1 = α0∘α1 (first α1, then α0) is a permutation and βi = α0∘αi (i ≥ 2) is an involution or
//! undefined (the dart is i-free in the G-map). Each kept dart stands for itself and α0 of it.

use super::{DartId, GMap};

/// An n-map: darts 0..len, β1 a permutation, βi for i ≥ 2 partial involutions.
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
    /// Checks that β1 is a permutation and every βi (i ≥ 2) an involution without fixed points
    /// where defined. O(darts · n).
    pub fn is_valid(&self) -> bool {
        let n = self.origin.len();
        let mut hit = vec![false; n];
        for &b in &self.beta1 {
            if b as usize >= n || std::mem::replace(&mut hit[b as usize], true) {
                return false;
            }
        }
        self.beta.iter().all(|bi| {
            (0..n).all(|d| match bi[d] {
                None => true,
                Some(e) => e as usize != d && bi.get(e as usize) == Some(&Some(d as u32)),
            })
        })
    }
}

impl<const N: usize> GMap<N> {
    /// The combinatorial map of an orientable G-map, or `None` if it is not orientable or some
    /// dart is 0-free or 1-free (β1 would not be a permutation). O(darts · n).
    pub fn to_combinatorial_map(&self) -> Option<CombinatorialMap> {
        let colour = self.orientation()?;
        if self.darts().any(|d| self.is_free(0, d) || self.is_free(1, d)) {
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

//! Map isomorphism: a bijection f between the darts of two n-G-maps with f(αi(d)) = αi(f(d))
//! for every i and d. Cell ids are ignored (they are derived data).

use super::{AlphaMask, DartId, GMap};

impl<const N: usize> GMap<N> {
    /// The isomorphism between the component of `a` in `self` and the component of `b` in
    /// `other` that sends a to b, if there is one, as (dart, image) pairs. A component is
    /// connected, so f is determined by f(a): the walk is O(component · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (a, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let (b, _) = GMap::<3>::from_tets(4, &[[3, 2, 1, 0]]).unwrap();
    /// let d = a.darts().next().unwrap();
    /// let f = a.isomorphism_from(d, &b, b.darts().next().unwrap()).unwrap();
    /// assert_eq!(f.len(), 24);
    /// // f commutes with every αi
    /// assert!(f.iter().all(|&(x, y)| f.iter().any(|&(u, v)| u == a.alpha::<1>(x) && v == b.alpha::<1>(y))));
    /// ```
    pub fn isomorphism_from(&self, a: DartId, other: &GMap<N>, b: DartId) -> Option<Vec<(DartId, DartId)>> {
        if !self.contains(a) || !other.contains(b) {
            return None;
        }
        let mut fwd = vec![u32::MAX; self.capacity()];
        let mut bwd = vec![u32::MAX; other.capacity()];
        let mut pairs = vec![(a, b)];
        fwd[a.index()] = b.0;
        bwd[b.index()] = a.0;
        let mut head = 0;
        while head < pairs.len() {
            let (x, y) = pairs[head];
            head += 1;
            for i in 0..=N {
                let (xi, yi) = (self.alpha_dyn(i, x), other.alpha_dyn(i, y));
                match (fwd[xi.index()], bwd[yi.index()]) {
                    (u32::MAX, u32::MAX) => {
                        fwd[xi.index()] = yi.0;
                        bwd[yi.index()] = xi.0;
                        pairs.push((xi, yi));
                    }
                    (fx, _) if fx == yi.0 => {}
                    _ => return None,
                }
            }
        }
        Some(pairs)
    }

    /// Whether the two maps are isomorphic. Each component of `self` is matched with an unused
    /// component of `other` by trying the darts of `other` as images of its root: O(darts²)
    /// in the worst case, O(darts · n) when the first try succeeds (e.g. copies, round trips).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (a, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    /// let (b, _) = GMap::<3>::from_tets(5, &[[4, 3, 2, 1], [4, 3, 2, 0]]).unwrap();
    /// let (c, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    /// assert!(a.is_isomorphic(&b)); // same shape, other numbering
    /// assert!(!a.is_isomorphic(&c)); // same darts and cells per tet, but not glued
    /// ```
    pub fn is_isomorphic(&self, other: &GMap<N>) -> bool {
        if self.dart_count() != other.dart_count() || self.count_cells() != other.count_cells() {
            return false;
        }
        let mut used = vec![false; other.capacity()];
        for root in self.components() {
            let size = self.orbit(root, AlphaMask::all(N)).len();
            let found = other
                .darts()
                .filter(|c| !used[c.index()])
                .find_map(|c| self.isomorphism_from(root, other, c).filter(|pairs| pairs.len() == size));
            match found {
                Some(pairs) => pairs.iter().for_each(|&(_, y)| used[y.index()] = true),
                None => return false,
            }
        }
        true
    }
}

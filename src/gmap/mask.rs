//! Sets of involutions {αi}, used to name orbits.

/// A subset of {α0, …, α7} as a bit set; bit i stands for αi.
///
/// Indices above [`AlphaMask::MAX_INDEX`] cannot be stored (a map has dimension ≤ 7). The
/// constructors that would have to store one ([`AlphaMask::of`], and [`AlphaMask::all`] /
/// [`AlphaMask::commuting_with`] for n > 7) panic in every build, naming the index; the queries
/// answer for them: [`AlphaMask::contains`] is false and [`AlphaMask::cell`] removes nothing.
///
/// The i-cell orbit of an n-G-map is `⟨⟩N−{i}`: [`AlphaMask::cell`]. The involutions that commute
/// with αi by the quasi-manifold law (|i − j| ≥ 2) form [`AlphaMask::commuting_with`]; an i-sew
/// links exactly the darts of that orbit.
///
/// # Examples
///
/// ```
/// use topomech::AlphaMask;
///
/// assert_eq!(AlphaMask::all(3), AlphaMask::of(&[0, 1, 2, 3]));
/// assert_eq!(AlphaMask::cell(3, 1), AlphaMask::of(&[0, 2, 3])); // edges of a 3-map
/// assert_eq!(AlphaMask::commuting_with(3, 0), AlphaMask::of(&[2, 3]));
/// assert!(AlphaMask::of(&[1, 3]).contains(3));
/// assert_eq!(AlphaMask::of(&[3, 1]).indices().collect::<Vec<_>>(), vec![1, 3]);
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug, Default)]
pub struct AlphaMask(pub u8);

impl AlphaMask {
    /// The empty set.
    pub const EMPTY: AlphaMask = AlphaMask(0);

    /// The largest index a mask can hold: 7 (one bit per involution of a map of dimension ≤ 7).
    pub const MAX_INDEX: usize = 7;

    /// All involutions α0..=αn of an n-map. O(1).
    ///
    /// # Panics
    /// If n > [`AlphaMask::MAX_INDEX`] (α8 cannot be stored), in every build.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::AlphaMask;
    ///
    /// assert_eq!(AlphaMask::all(2), AlphaMask::of(&[0, 1, 2]));
    /// assert_eq!(AlphaMask::all(3).0, 0b1111);
    /// ```
    pub const fn all(n: usize) -> AlphaMask {
        assert!(n <= Self::MAX_INDEX, "AlphaMask::all: a mask holds α0..=α7 only");
        AlphaMask(((1u16 << (n + 1)) - 1) as u8)
    }

    /// The set {αj : j in `indices`}. O(|indices|).
    ///
    /// # Panics
    /// If an index is above [`AlphaMask::MAX_INDEX`], in every build (before, release builds
    /// wrapped α9 onto α1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::AlphaMask;
    ///
    /// let mask = AlphaMask::of(&[2, 0]);
    /// assert!(mask.contains(0) && mask.contains(2) && !mask.contains(1));
    /// assert_eq!(mask.indices().collect::<Vec<_>>(), vec![0, 2]);
    /// ```
    pub const fn of(indices: &[usize]) -> AlphaMask {
        let mut bits = 0u8;
        let mut k = 0;
        while k < indices.len() {
            assert!(indices[k] <= Self::MAX_INDEX, "AlphaMask::of: an index above 7 (a mask holds α0..=α7 only)");
            bits |= 1 << indices[k];
            k += 1;
        }
        AlphaMask(bits)
    }

    /// The generators of the i-cell orbit of an n-map: every αj but αi (all of them for i > n).
    /// O(1).
    ///
    /// # Panics
    /// As [`AlphaMask::all`], if n > [`AlphaMask::MAX_INDEX`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// assert_eq!(map.orbit(d, AlphaMask::cell(3, 0)).len(), 6); // a corner of a tet: 3 edges × 2 faces
    /// assert_eq!(map.orbit(d, AlphaMask::cell(3, 1)).len(), 4); // an edge: 2 ends × 2 faces
    /// ```
    pub const fn cell(n: usize, i: usize) -> AlphaMask {
        if i > Self::MAX_INDEX {
            return Self::all(n);
        }
        AlphaMask(Self::all(n).0 & !(1 << i))
    }

    /// The involutions that must commute with αi in an n-map: αj with j ≤ n and |i − j| ≥ 2.
    /// O(n).
    ///
    /// # Panics
    /// As [`AlphaMask::all`], if n > [`AlphaMask::MAX_INDEX`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::AlphaMask;
    ///
    /// assert_eq!(AlphaMask::commuting_with(3, 3), AlphaMask::of(&[0, 1]));
    /// assert_eq!(AlphaMask::commuting_with(3, 1), AlphaMask::of(&[3]));
    /// assert_eq!(AlphaMask::commuting_with(2, 1), AlphaMask::EMPTY);
    /// ```
    pub const fn commuting_with(n: usize, i: usize) -> AlphaMask {
        assert!(n <= Self::MAX_INDEX, "AlphaMask::commuting_with: a mask holds α0..=α7 only");
        let mut bits = 0u8;
        let mut j = 0;
        while j <= n {
            if j + 2 <= i || i + 2 <= j {
                bits |= 1 << j;
            }
            j += 1;
        }
        AlphaMask(bits)
    }

    /// Whether αi is in the set (false for every i above [`AlphaMask::MAX_INDEX`]). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::AlphaMask;
    ///
    /// let m = AlphaMask::of(&[0, 2]);
    /// assert!(m.contains(0) && m.contains(2));
    /// assert!(!m.contains(1) && !m.contains(3));
    /// ```
    #[inline(always)]
    pub const fn contains(self, i: usize) -> bool {
        i <= Self::MAX_INDEX && self.0 & (1 << i) != 0
    }

    /// The indices in the set, in increasing order.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::AlphaMask;
    ///
    /// assert_eq!(AlphaMask::of(&[3, 0, 1]).indices().collect::<Vec<_>>(), vec![0, 1, 3]);
    /// assert_eq!(AlphaMask::all(2).indices().count(), 3);
    /// assert_eq!(AlphaMask::EMPTY.indices().next(), None);
    /// ```
    pub fn indices(self) -> impl Iterator<Item = usize> {
        (0..8).filter(move |&i| self.contains(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_and_commuting_masks() {
        assert_eq!(AlphaMask::cell(3, 0), AlphaMask::of(&[1, 2, 3]));
        assert_eq!(AlphaMask::cell(2, 1), AlphaMask::of(&[0, 2]));
        assert_eq!(AlphaMask::commuting_with(3, 3), AlphaMask::of(&[0, 1]));
        assert_eq!(AlphaMask::commuting_with(3, 1), AlphaMask::of(&[3]));
        assert_eq!(AlphaMask::commuting_with(3, 0), AlphaMask::of(&[2, 3]));
        assert_eq!(AlphaMask::commuting_with(1, 0), AlphaMask::EMPTY);
        assert_eq!(AlphaMask::all(3).indices().collect::<Vec<_>>(), vec![0, 1, 2, 3]);
    }
}

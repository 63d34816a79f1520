//! Marks: one bit per dart, reusable, that must be cleaned before release.

use super::{DartId, GMap};

/// A set of darts as a bit set with a count. Grows on demand. Insert, remove and test are O(1).
///
/// # Examples
///
/// ```
/// use topomech::gmap::DartSet;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let first = map.darts().next().unwrap();
/// let mut set = DartSet::with_capacity(map.dart_count());
/// for d in map.darts().filter(|&d| map.vertex_id(d) == map.vertex_id(first)) {
///     assert!(set.insert(d));
/// }
/// assert_eq!(set.len(), 2); // a triangle corner holds two darts
/// assert!(set.contains(first));
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DartSet {
    bits: Vec<u64>,
    count: usize,
}

impl DartSet {
    /// An empty set able to hold darts below `capacity` without growing.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(100);
    /// assert!(set.is_empty());
    /// assert!(set.insert(DartId(99)));
    /// assert_eq!(set.len(), 1);
    /// ```
    pub fn with_capacity(capacity: usize) -> Self {
        DartSet { bits: vec![0; capacity.div_ceil(64)], count: 0 }
    }

    /// Whether d is in the set. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::default();
    /// assert!(!set.contains(DartId(1_000_000))); // past the end: simply absent
    /// set.insert(DartId(64));
    /// assert!(set.contains(DartId(64)) && !set.contains(DartId(63)));
    /// ```
    #[inline(always)]
    pub fn contains(&self, d: DartId) -> bool {
        let i = d.index();
        self.bits.get(i / 64).is_some_and(|w| w & (1u64 << (i % 64)) != 0)
    }

    /// Adds d; returns whether it was absent. O(1) amortized.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(10);
    /// assert!(set.insert(DartId(3)));
    /// assert!(!set.insert(DartId(3))); // already there
    /// assert!(set.insert(DartId(500))); // grows on demand
    /// assert_eq!(set.len(), 2);
    /// assert!(set.remove(DartId(3)) && !set.contains(DartId(3)));
    /// set.clear();
    /// assert!(set.is_empty());
    /// ```
    #[inline(always)]
    pub fn insert(&mut self, d: DartId) -> bool {
        let i = d.index();
        if i / 64 >= self.bits.len() {
            self.bits.resize(i / 64 + 1, 0);
        }
        let w = &mut self.bits[i / 64];
        let bit = 1u64 << (i % 64);
        let absent = *w & bit == 0;
        *w |= bit;
        self.count += absent as usize;
        absent
    }

    /// Removes d; returns whether it was present. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(8);
    /// set.insert(DartId(2));
    /// assert!(set.remove(DartId(2)));
    /// assert!(!set.remove(DartId(2))); // already gone
    /// assert!(!set.remove(DartId(500))); // never there
    /// assert!(set.is_empty());
    /// ```
    #[inline(always)]
    pub fn remove(&mut self, d: DartId) -> bool {
        let i = d.index();
        let Some(w) = self.bits.get_mut(i / 64) else { return false };
        let bit = 1u64 << (i % 64);
        let present = *w & bit != 0;
        *w &= !bit;
        self.count -= present as usize;
        present
    }

    /// Number of darts in the set. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(8);
    /// set.insert(DartId(1));
    /// set.insert(DartId(1)); // already there
    /// set.insert(DartId(5));
    /// assert_eq!(set.len(), 2);
    /// ```
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the set is empty. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(8);
    /// assert!(set.is_empty());
    /// set.insert(DartId(3));
    /// assert!(!set.is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Empties the set. O(capacity / 64).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::DartSet;
    /// use topomech::DartId;
    ///
    /// let mut set = DartSet::with_capacity(200);
    /// (0..200).for_each(|k| drop(set.insert(DartId(k))));
    /// set.clear();
    /// assert!(set.is_empty() && !set.contains(DartId(150)));
    /// ```
    pub fn clear(&mut self) {
        self.bits.iter_mut().for_each(|w| *w = 0);
        self.count = 0;
    }
}

/// A reserved mark of a map (CGAL's "reserve_mark"): a [`DartSet`] taken from the map's pool.
///
/// Give it back with [`GMap::free_mark`] once every dart is unmarked again; a mark released or
/// dropped while darts are still marked is a bug in the caller's algorithm and asserts.
///
/// # Examples
///
/// ```
/// use topomech::{AlphaMask, GMap};
///
/// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let d = map.darts().next().unwrap();
/// let mut mark = map.reserve_mark();
/// map.mark_orbit(&mut mark, d, AlphaMask::of(&[0, 1]));
/// assert_eq!(mark.count(), 6); // the whole triangle
/// map.unmark_orbit(&mut mark, d, AlphaMask::of(&[0, 1]));
/// map.free_mark(mark); // clean again: can go back to the pool
/// ```
#[derive(Debug)]
pub struct Mark {
    set: DartSet,
}

impl Mark {
    /// Marks d; returns whether it was unmarked. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// assert!(mark.mark(d)); // newly marked
    /// assert!(!mark.mark(d)); // already marked
    /// assert!(mark.is_marked(d) && mark.count() == 1);
    /// mark.unmark(d);
    /// map.free_mark(mark);
    /// ```
    pub fn mark(&mut self, d: DartId) -> bool {
        self.set.insert(d)
    }

    /// Unmarks d; returns whether it was marked. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// assert!(!mark.unmark(d)); // was not marked
    /// mark.mark(d);
    /// assert!(mark.unmark(d) && !mark.is_marked(d));
    /// map.free_mark(mark);
    /// ```
    pub fn unmark(&mut self, d: DartId) -> bool {
        self.set.remove(d)
    }

    /// Whether d is marked. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// map.mark_orbit(&mut mark, d, AlphaMask::cell(2, 2)); // d's triangle
    /// assert_eq!(map.darts().filter(|&e| mark.is_marked(e)).count(), 6);
    /// assert!(map.darts().all(|e| mark.is_marked(e) == (map.cell_id(2, e) == map.cell_id(2, d))));
    /// map.unmark_orbit(&mut mark, d, AlphaMask::cell(2, 2));
    /// map.free_mark(mark);
    /// ```
    pub fn is_marked(&self, d: DartId) -> bool {
        self.set.contains(d)
    }

    /// Number of marked darts. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// map.mark_orbit(&mut mark, d, AlphaMask::cell(3, 0)); // d's vertex: 6 darts
    /// map.mark_orbit(&mut mark, d, AlphaMask::cell(3, 1)); // d's edge: 4 darts, 2 of them marked already
    /// assert_eq!(mark.count(), 8);
    /// map.unmark_orbit(&mut mark, d, AlphaMask::all(3));
    /// map.free_mark(mark);
    /// ```
    pub fn count(&self) -> usize {
        self.set.len()
    }
}

impl Drop for Mark {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            assert!(self.set.is_empty(), "a mark was dropped with {} darts still marked", self.set.len());
        }
    }
}

impl<const N: usize> GMap<N> {
    /// Reserves a mark with no dart marked, reusing a released one if any. O(1) amortized.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut mark = map.reserve_mark();
    /// let d = map.darts().next().unwrap();
    /// assert!(mark.mark(d));
    /// assert_eq!(mark.count(), 1);
    /// assert!(mark.unmark(d));
    /// map.free_mark(mark);
    /// ```
    pub fn reserve_mark(&mut self) -> Mark {
        let set = self.mark_pool.pop().unwrap_or_else(|| DartSet::with_capacity(self.capacity()));
        debug_assert!(set.is_empty());
        Mark { set }
    }

    /// Returns a mark to the pool. Panics if some dart is still marked (a bug in the caller).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// mark.mark(d);
    /// mark.unmark(d); // a mark goes back clean
    /// map.free_mark(mark);
    /// let again = map.reserve_mark(); // reused from the pool, still clean
    /// assert_eq!(again.count(), 0);
    /// map.free_mark(again);
    /// ```
    pub fn free_mark(&mut self, mut mark: Mark) {
        assert!(mark.set.is_empty(), "free_mark: {} darts are still marked", mark.set.len());
        self.mark_pool.push(std::mem::take(&mut mark.set));
    }

    /// Marks every dart of the orbit ⟨mask⟩(d). O(orbit).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// map.mark_orbit(&mut mark, d, AlphaMask::cell(3, 2));
    /// assert_eq!(mark.count(), 6); // the darts of d's face
    /// assert!(mark.is_marked(d) && !mark.is_marked(map.alpha::<2>(d)));
    /// map.unmark_orbit(&mut mark, d, AlphaMask::cell(3, 2));
    /// map.free_mark(mark); // every dart is unmarked again
    /// ```
    pub fn mark_orbit(&self, mark: &mut Mark, d: DartId, mask: super::AlphaMask) {
        for e in self.orbit(d, mask) {
            mark.mark(e);
        }
    }

    /// Unmarks every dart of the orbit ⟨mask⟩(d). O(orbit).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{AlphaMask, GMap};
    ///
    /// let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// let mut mark = map.reserve_mark();
    /// map.mark_orbit(&mut mark, d, AlphaMask::all(2));
    /// assert_eq!(mark.count(), 6);
    /// map.unmark_orbit(&mut mark, d, AlphaMask::of(&[0]));
    /// assert_eq!(mark.count(), 4); // d and α0(d) unmarked
    /// map.unmark_orbit(&mut mark, d, AlphaMask::all(2));
    /// map.free_mark(mark);
    /// ```
    pub fn unmark_orbit(&self, mark: &mut Mark, d: DartId, mask: super::AlphaMask) {
        for e in self.orbit(d, mask) {
            mark.unmark(e);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::GMap;

    /// The law of marks: a mark is released clean. Dropping one with a dart still marked is a
    /// bug of its user and asserts, naming how many darts were left.
    #[test]
    #[should_panic(expected = "a mark was dropped with 1 darts still marked")]
    fn a_mark_dropped_with_darts_marked_asserts() {
        let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let d = map.darts().next().unwrap();
        let mut mark = map.reserve_mark();
        mark.mark(d);
        drop(mark);
    }

    /// Handing a dirty mark back to the pool asserts too (the next user would see its darts).
    #[test]
    #[should_panic(expected = "free_mark: 2 darts are still marked")]
    fn a_mark_freed_with_darts_marked_asserts() {
        let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let mut mark = map.reserve_mark();
        for d in map.darts().take(2) {
            mark.mark(d);
        }
        map.free_mark(mark);
    }

    /// A clean mark dropped or freed does not assert, and a pooled mark made when the map was
    /// small still marks darts created after it (the set grows with the map).
    #[test]
    fn clean_marks_are_released_and_a_pooled_mark_covers_darts_created_later() {
        let (mut map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        let first = map.darts().next().unwrap();
        let mut mark = map.reserve_mark();
        assert!(mark.mark(first) && mark.unmark(first));
        drop(mark);
        let pooled = map.reserve_mark();
        map.free_mark(pooled);
        let late: Vec<_> = (0..200).map(|_| map.create_dart().unwrap()).collect();
        let mut mark = map.reserve_mark();
        assert_eq!(mark.count(), 0);
        for &d in &late {
            assert!(mark.mark(d));
        }
        assert!(late.iter().all(|&d| mark.is_marked(d)) && !mark.is_marked(first));
        assert_eq!(mark.count(), late.len());
        for &d in &late {
            assert!(mark.unmark(d));
        }
        map.free_mark(mark);
    }
}

//! Dart and cell identifiers: small `u32` newtypes.
//!
//! A dart is the single abstract element of an n-G-map (seed 000, §2.1): in 3D, roughly "a vertex
//! on an edge of a face of a volume". Darts are indices into the map's flat arrays, so a `DartId`
//! is only meaningful together with the map that issued it.

use std::fmt;

/// Index of a dart in a [`GMap`](crate::gmap::GMap). Four bytes; `u32::MAX` is never a valid dart.
///
/// # Examples
///
/// ```
/// use topomech::{DartId, GMap};
///
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let d = DartId(4);
/// assert!(map.contains(d));
/// assert_eq!(d.index(), 4);
/// assert_eq!(d.to_string(), "dart 4");
/// assert_eq!(format!("{d:?}"), "d4");
/// ```
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct DartId(pub u32);

impl DartId {
    /// The index as `usize`, for indexing flat arrays.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::DartId;
    ///
    /// let mut seen = vec![false; 4];
    /// seen[DartId(3).index()] = true;
    /// assert_eq!(DartId(3).index(), 3);
    /// assert_eq!(seen, [false, false, false, true]);
    /// ```
    #[inline(always)]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Debug for DartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "d{}", self.0)
    }
}

impl fmt::Display for DartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "dart {}", self.0)
    }
}

/// Identifier of an i-cell (the dimension is carried separately). Ids of one dimension are dense
/// in `0..capacity` and reused after a cell disappears; embeddings are stored in arrays keyed by it.
///
/// # Examples
///
/// ```
/// use topomech::{CellId, GMap};
///
/// // One f64 per vertex, indexed by vertex id.
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut degree = vec![0usize; map.cell_id_bound(0)];
/// for d in map.darts() {
///     degree[map.vertex_id(d).index()] += 1;
/// }
/// assert_eq!(degree, vec![2, 2, 2]); // two darts per corner of a triangle
/// assert_eq!(CellId(7).to_string(), "cell 7");
/// ```
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct CellId(pub u32);

impl CellId {
    /// The index as `usize`, for indexing embedding arrays.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let mut darts_per_vertex = vec![0; map.cell_id_bound(0)];
    /// map.darts().for_each(|d| darts_per_vertex[map.vertex_id(d).index()] += 1);
    /// assert_eq!(darts_per_vertex, vec![6; 4]); // 6 darts around each corner of a tet
    /// ```
    #[inline(always)]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Debug for CellId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "c{}", self.0)
    }
}

impl fmt::Display for CellId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cell {}", self.0)
    }
}

/// Sentinel for "no id" inside flat arrays (dead darts, unassigned cells during a build).
pub(crate) const NONE: u32 = u32::MAX;

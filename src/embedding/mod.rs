//! Embeddings: attributes attached to i-cells, and the embedding-aware sew/unsew (the third layer
//! of the mutators, seed 000 §2.2 and §4.3).
//!
//! An attribute of the i-cells lives in a flat array indexed by the cell id that the kernel keeps
//! on every dart ([`GMap::cell_id`]): one value per cell, never one per dart, and no pointer. When a
//! topological sew or unsew changes cell identities, the kernel reports it as [`CellChanges`]
//! (`Merged { dim, kept, absorbed }`, `Split { dim, kept, new, dart_kept, dart_new }`); the
//! [`Embedded`] layer hands every change to the attribute owner's [`CellRules`], **after** the whole
//! topological operation is done, so a rule sees the final map and can recompute a value from the
//! geometry around each resulting cell (the mass of a vertex from the tetrahedra now around it)
//! rather than only copying or halving it.
//!
//! ```text
//!   layer 3  Embedded::sew / unsew      topology + attributes (this module)
//!   layer 2  GMap::sew_dyn / unsew_dyn  topology, exact cell ids, returns CellChanges
//!   layer 1  link_raw (crate-private)   may break validity
//! ```
//!
//! With the `expensive-checks` feature every mutating operation of this layer ends with
//! [`CellRules::check`] (for the mechanical model: the conservation laws).

use crate::gmap::{CellChange, CellChanges, SewError};
use crate::{CellId, DartId, GMap};

/// A flat array of attributes keyed by the ids of one cell dimension.
///
/// Index `id.index()` holds the attribute of cell `id`; slots of dead ids hold stale values that
/// nothing reads. [`CellArray::grow`] extends it when the kernel hands out larger ids.
///
/// # Examples
///
/// ```
/// use topomech::embedding::CellArray;
/// use topomech::CellId;
///
/// let mut mass = CellArray::filled(2, 0.5);
/// mass.grow(4, 0.0); // the kernel handed out ids 2 and 3
/// assert_eq!(mass.as_slice(), &[0.5, 0.5, 0.0, 0.0]);
/// assert_eq!((mass[CellId(1)], mass.get(CellId(9))), (0.5, None));
/// mass.grow(1, 9.9); // never shrinks
/// assert_eq!(mass.len(), 4);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CellArray<T> {
    values: Vec<T>,
}

impl<T: Clone> CellArray<T> {
    /// An array of `len` copies of `fill`. O(len).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    ///
    /// let a = CellArray::filled(3, 7u8);
    /// assert_eq!(a.as_slice(), &[7, 7, 7]);
    /// assert!(CellArray::filled(0, 7u8).is_empty());
    /// ```
    pub fn filled(len: usize, fill: T) -> Self {
        CellArray { values: vec![fill; len] }
    }

    /// Extends the array with `fill` up to `len` slots (never shrinks). Amortized O(growth).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    ///
    /// let mut a = CellArray::from_vec(vec![1, 2]);
    /// a.grow(4, 0);
    /// assert_eq!(a.as_slice(), &[1, 2, 0, 0]);
    /// a.grow(2, 9); // never shrinks nor overwrites
    /// assert_eq!(a.as_slice(), &[1, 2, 0, 0]);
    /// ```
    pub fn grow(&mut self, len: usize, fill: T) {
        if self.values.len() < len {
            self.values.resize(len, fill);
        }
    }
}

impl<T> CellArray<T> {
    /// An array taking ownership of `values` (slot i = cell id i). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    /// use topomech::CellId;
    ///
    /// let a = CellArray::from_vec(vec!['a', 'b', 'c']);
    /// assert_eq!((a.len(), a[CellId(2)]), (3, 'c'));
    /// ```
    pub fn from_vec(values: Vec<T>) -> Self {
        CellArray { values }
    }

    /// Number of slots. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    ///
    /// assert_eq!(CellArray::filled(5, 0.0).len(), 5);
    /// assert_eq!(CellArray::<f64>::default().len(), 0);
    /// ```
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether there is no slot. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    ///
    /// assert!(CellArray::<u32>::default().is_empty());
    /// assert!(!CellArray::from_vec(vec![1u32]).is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The attribute of `id`, or `None` past the end. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    /// use topomech::CellId;
    ///
    /// let a = CellArray::from_vec(vec![10, 20]);
    /// assert_eq!(a.get(CellId(1)), Some(&20));
    /// assert_eq!(a.get(CellId(2)), None); // past the end: no panic
    /// ```
    pub fn get(&self, id: CellId) -> Option<&T> {
        self.values.get(id.index())
    }

    /// All slots as a slice (slot i = cell id i). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    ///
    /// let a = CellArray::from_vec(vec![1.0, 2.0]);
    /// assert_eq!(a.as_slice().iter().sum::<f64>(), 3.0);
    /// ```
    pub fn as_slice(&self) -> &[T] {
        &self.values
    }

    /// All slots as a mutable slice. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::CellArray;
    /// use topomech::CellId;
    ///
    /// let mut a = CellArray::filled(3, 1);
    /// a.as_mut_slice().iter_mut().for_each(|x| *x *= 2);
    /// assert_eq!(a[CellId(2)], 2);
    /// ```
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.values
    }
}

impl<T> std::ops::Index<CellId> for CellArray<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, id: CellId) -> &T {
        &self.values[id.index()]
    }
}

impl<T> std::ops::IndexMut<CellId> for CellArray<T> {
    #[inline(always)]
    fn index_mut(&mut self, id: CellId) -> &mut T {
        &mut self.values[id.index()]
    }
}

/// A mutable view of the values of a [`CellArray`]: every slot can be read and written, none
/// added or removed. Handed out where the values are free to change but the length is bound to
/// the map (a body's positions, velocities, pins), so that no caller can shorten an array that
/// later operations index by cell id.
///
/// # Examples
///
/// ```
/// use topomech::embedding::{CellArray, CellSliceMut};
/// use topomech::CellId;
///
/// let mut speed = CellArray::filled(3, 1.0);
/// let mut view = CellSliceMut::new(&mut speed);
/// view[CellId(2)] = 4.0;
/// view.as_mut_slice()[0] *= 2.0;
/// assert_eq!((view.len(), view.get(CellId(3))), (3, None)); // past the end: no panic
/// assert_eq!(speed.as_slice(), &[2.0, 1.0, 4.0]); // the length did not change
/// ```
#[derive(Debug)]
pub struct CellSliceMut<'a, T> {
    values: &'a mut [T],
}

impl<'a, T> CellSliceMut<'a, T> {
    /// The view of every slot of `array`. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    ///
    /// let mut a = CellArray::from_vec(vec![1, 2]);
    /// CellSliceMut::new(&mut a).as_mut_slice().swap(0, 1);
    /// assert_eq!(a.as_slice(), &[2, 1]);
    /// ```
    pub fn new(array: &'a mut CellArray<T>) -> Self {
        CellSliceMut { values: &mut array.values }
    }

    /// Number of slots. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    ///
    /// let mut a = CellArray::filled(4, 0u8);
    /// assert_eq!(CellSliceMut::new(&mut a).len(), 4);
    /// ```
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether there is no slot. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    ///
    /// let mut a = CellArray::<u8>::default();
    /// assert!(CellSliceMut::new(&mut a).is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The value of `id`, or `None` past the end. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    /// use topomech::CellId;
    ///
    /// let mut a = CellArray::from_vec(vec![5, 6]);
    /// let view = CellSliceMut::new(&mut a);
    /// assert_eq!((view.get(CellId(1)), view.get(CellId(2))), (Some(&6), None));
    /// ```
    pub fn get(&self, id: CellId) -> Option<&T> {
        self.values.get(id.index())
    }

    /// The value of `id` for writing, or `None` past the end. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    /// use topomech::CellId;
    ///
    /// let mut a = CellArray::from_vec(vec![5, 6]);
    /// let mut view = CellSliceMut::new(&mut a);
    /// *view.get_mut(CellId(0)).unwrap() = 7;
    /// assert!(view.get_mut(CellId(2)).is_none());
    /// assert_eq!(a.as_slice(), &[7, 6]);
    /// ```
    pub fn get_mut(&mut self, id: CellId) -> Option<&mut T> {
        self.values.get_mut(id.index())
    }

    /// Every slot, read-only (slot i = cell id i). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    ///
    /// let mut a = CellArray::from_vec(vec![1.0, 2.0]);
    /// assert_eq!(CellSliceMut::new(&mut a).as_slice().iter().sum::<f64>(), 3.0);
    /// ```
    pub fn as_slice(&self) -> &[T] {
        self.values
    }

    /// Every slot, writable; a slice cannot change its length. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::embedding::{CellArray, CellSliceMut};
    ///
    /// let mut a = CellArray::filled(3, 1);
    /// CellSliceMut::new(&mut a).as_mut_slice().fill(9);
    /// assert_eq!(a.as_slice(), &[9, 9, 9]);
    /// ```
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        self.values
    }
}

impl<T> std::ops::Index<CellId> for CellSliceMut<'_, T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, id: CellId) -> &T {
        &self.values[id.index()]
    }
}

impl<T> std::ops::IndexMut<CellId> for CellSliceMut<'_, T> {
    #[inline(always)]
    fn index_mut(&mut self, id: CellId) -> &mut T {
        &mut self.values[id.index()]
    }
}

/// Split and merge rules of a set of cell attributes: what the embedding layer does with the
/// attributes when a sew merges cells or an unsew splits them.
///
/// Every method receives the map *after* the topological operation, so both resulting cells can
/// be walked.
///
/// The methods are called by the embedding layer ([`Embedded::sew`], [`Embedded::unsew`]), in
/// that order, once per operation. An [`Embedded`]'s own attributes cannot be reached mutably
/// from outside the crate (a body opens its free state only, [`crate::mechanics::AttrsMut`];
/// round 27), so they cannot be called on them by hand; called on attributes taken out
/// ([`Embedded::into_parts`]) they rewrite them from whatever map they are given, and
/// [`Embedded::new`] names the law that breaks when the parts are put back together (for
/// [`crate::mechanics::Mechanics`]: a face flag, a sum).
///
/// # Panics
///
/// A rule that panics unwinds out of [`Embedded::sew`] or [`Embedded::unsew`] *after* the
/// topological change: the map is the new one and the attributes are updated only up to the
/// rule that panicked. The layer does not roll back; an [`Embedded`] caught across such an
/// unwind (`catch_unwind`) is inconsistent and must be dropped ([`Embedded::check`] then reports
/// the broken law when the rules' laws can see it). The rules of this crate do not panic on a
/// map that the `check_*` methods accepted.
///
/// # Examples
///
/// ```
/// use std::convert::Infallible;
/// use topomech::embedding::{CellRules, Embedded, Split};
/// use topomech::{CellId, GMap};
///
/// struct SplitCount(usize); // counts cell splits, keeps no attribute
/// impl CellRules<3> for SplitCount {
///     type Error = Infallible;
///     fn grow_to(&mut self, _: &GMap<3>) {}
///     fn on_split(&mut self, _: &GMap<3>, _: &Split<'_>) { self.0 += 1 }
///     fn on_merge(&mut self, _: &GMap<3>, _: usize, _: CellId, _: CellId) {}
/// }
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let mut e = Embedded::new(map, SplitCount(0)).unwrap();
/// let changes = e.unsew(3, d).unwrap();
/// assert_eq!(e.attrs().0, changes.changes.len());
/// ```
pub trait CellRules<const N: usize> {
    /// What [`CellRules::check`] reports.
    type Error: std::error::Error + 'static;

    /// Makes room for every cell id the map can now hand out (`map.cell_id_bound(i)` for all i).
    /// Called before the rules of an operation run.
    fn grow_to(&mut self, map: &GMap<N>);

    /// The `split.dim`-cell `split.kept` (containing `split.dart_kept`) was split: the darts of
    /// the other side, `split.dart_new` among them, now form the cell `split.new`; when the
    /// kernel reported them, `split.new_side` lists every one of them (no need to walk it).
    /// The rules run after the whole operation, on the map as it leaves it: a cell cut into
    /// three pieces comes as two splits of the same `kept`, and in each `dart_kept` lies in
    /// `kept` and `dart_new` in `new` in that final map.
    fn on_split(&mut self, map: &GMap<N>, split: &Split<'_>);

    /// The `dim`-cell `absorbed` was merged into `kept`, which now holds the darts of both.
    fn on_merge(&mut self, map: &GMap<N>, dim: usize, kept: CellId, absorbed: CellId);

    /// Called once after all splits or merges of one operation, with the darts it (un)linked:
    /// the place for rules that depend on several dimensions at once (e.g. boundary flags).
    fn after_operation(&mut self, map: &GMap<N>, changes: &CellChanges) {
        let _ = (map, changes);
    }

    /// Whether the rules can keep their laws through an i-sew that would link `pairs` (each
    /// (x, y) becomes αi-linked and their cells merge), asked before the map changes. The
    /// default accepts every sew. O(pairs) typically.
    ///
    /// # Errors
    /// `Self::Error` naming what the merge could not keep; the sew is then refused.
    fn check_sew(&self, map: &GMap<N>, i: usize, pairs: &[(DartId, DartId)]) -> Result<(), Self::Error> {
        let _ = (map, i, pairs);
        Ok(())
    }

    /// Whether the rules can keep their laws through an i-unsew of `d` (the cells it splits get
    /// the split rules), asked before the map changes. The default accepts every unsew. O(1)
    /// typically.
    ///
    /// # Errors
    /// `Self::Error` naming what the split could not keep; the unsew is then refused.
    fn check_unsew(&self, map: &GMap<N>, i: usize, d: DartId) -> Result<(), Self::Error> {
        let _ = (map, i, d);
        Ok(())
    }

    /// Checks the attributes against the map (laws such as conservation). O(model) typically.
    ///
    /// # Errors
    /// `Self::Error` naming the cell at fault.
    fn check(&self, map: &GMap<N>) -> Result<(), Self::Error> {
        let _ = map;
        Ok(())
    }
}

/// One cell split, as handed to [`CellRules::on_split`]: a [`CellChange::Split`] with the darts
/// of its new side.
///
/// # Examples
///
/// ```
/// use std::convert::Infallible;
/// use topomech::embedding::{CellRules, Embedded, Split};
/// use topomech::{CellId, GMap};
///
/// // Checks that each reported new side is empty (not walked) or the whole new cell.
/// struct SideCheck(usize);
/// impl CellRules<3> for SideCheck {
///     type Error = Infallible;
///     fn grow_to(&mut self, _: &GMap<3>) {}
///     fn on_split(&mut self, map: &GMap<3>, s: &Split<'_>) {
///         assert_eq!(map.cell_id(s.dim, s.dart_new), s.new);
///         assert!(s.new_side.iter().all(|&x| map.cell_id(s.dim, x) == s.new));
///         assert!(s.new_side.is_empty() || s.new_side.len() == map.cell_darts(s.dim, s.dart_new).len());
///         self.0 += 1;
///     }
///     fn on_merge(&mut self, _: &GMap<3>, _: usize, _: CellId, _: CellId) {}
/// }
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let mut e = Embedded::new(map, SideCheck(0)).unwrap();
/// e.unsew(3, d).unwrap();
/// assert_eq!(e.attrs().0, 7); // 3 vertices, 3 edges and the face
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split<'a> {
    /// Dimension of the cell.
    pub dim: usize,
    /// The id that stays with one side.
    pub kept: CellId,
    /// The fresh id of the other side.
    pub new: CellId,
    /// A dart of the side that kept the id.
    pub dart_kept: DartId,
    /// A dart of the side with the new id.
    pub dart_new: DartId,
    /// Every dart of the new side, in no particular order ([`CellChanges::new_side`]); empty when
    /// the kernel did not report them (rules must then walk the cell of `dart_new`).
    pub new_side: &'a [DartId],
}

/// Errors of the embedding-aware mutators.
///
/// # Examples
///
/// ```
/// use topomech::embedding::EmbedError;
/// use topomech::gmap::SewError;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap(); // a boundary dart
/// let err = body.unsew(3, d).unwrap_err();
/// assert!(matches!(err, EmbedError::Sew(SewError::AlreadyFree { i: 3, .. })));
/// assert_eq!(body.version(), 0); // refused: nothing changed
/// ```
#[derive(Debug, thiserror::Error)]
pub enum EmbedError<E: std::error::Error + 'static> {
    /// The topological operation was refused; map and attributes are unchanged.
    #[error(transparent)]
    Sew(#[from] SewError),
    /// The rules cannot keep their laws through the operation ([`CellRules::check_sew`],
    /// [`CellRules::check_unsew`]); map and attributes are unchanged.
    #[error("{op} of {dart} refused: {source}")]
    Refused {
        /// "sew", "unsew", or the higher operation that checked (e.g. "remove_volume").
        op: &'static str,
        /// The dart the operation was called with.
        dart: DartId,
        /// What the rules could not keep.
        source: E,
    },
    /// The rules left the attributes inconsistent (only with `expensive-checks`).
    #[error("attributes broken after {op} of {dart}: {source}")]
    Check {
        /// "sew" or "unsew".
        op: &'static str,
        /// The dart the operation was called with.
        dart: DartId,
        /// What the check found.
        source: E,
    },
}

/// A map together with cell attributes kept consistent by [`CellRules`].
///
/// The map is only reachable read-only from outside, so every topological change goes through
/// [`Embedded::sew`] / [`Embedded::unsew`] and the rules cannot be bypassed. [`Embedded::version`]
/// counts topological changes; projections built from the map remember it to detect staleness.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// body.unsew(3, d).unwrap(); // topology and attributes change together
/// assert_eq!(body.version(), 1);
/// assert!(body.map().is_free(3, d));
/// assert!(body.check().is_ok());
/// ```
#[derive(Debug)]
pub struct Embedded<const N: usize, E> {
    map: GMap<N>,
    attrs: E,
    version: u64,
    identity: u64,
    /// For a clone: the identity and version of the body it was cloned from (its lineage, which
    /// a version alone — an operation count — cannot tell).
    source: Option<(u64, u64)>,
}

/// A 64-bit digest of a report's lists (changes, pairs and the recorded new sides), for
/// [`Embedded::returned_last`]: lists edited after the stamp almost surely change it. Not
/// cryptographic; it guards against mistakes, not adversaries. O(changes · walked splits +
/// pairs + side darts) (a few dozen words for a face).
fn fingerprint(changes: &CellChanges) -> u64 {
    let mut h = 0x243f_6a88_85a3_08d3_u64;
    let mut mix = |x: u64| h = (h.rotate_left(5) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let pair = |a: u32, b: u32| (u64::from(a) << 32) | u64::from(b);
    mix(pair(changes.changes.len() as u32, changes.pairs.len() as u32));
    for (k, change) in changes.changes.iter().enumerate() {
        let words = match *change {
            CellChange::Split { dim, kept, new, dart_kept, dart_new } => {
                [1 + dim as u64, pair(kept.0, new.0), pair(dart_kept.0, dart_new.0)]
            }
            CellChange::Merged { dim, kept, absorbed } => [16 + dim as u64, pair(kept.0, absorbed.0), 0],
        };
        words.into_iter().for_each(&mut mix);
        let side = changes.new_side(k);
        mix(side.len() as u64);
        side.iter().for_each(|d| mix(d.0.into()));
    }
    changes.pairs.iter().for_each(|&(a, b)| mix(pair(a.0, b.0)));
    h
}

/// A clone is another body: same map, attributes and version, its own [`Embedded::identity`]
/// (so what was built for the original does not run on the copy unnoticed).
impl<const N: usize, E: Clone> Clone for Embedded<N, E> {
    fn clone(&self) -> Self {
        Embedded {
            map: self.map.clone(),
            attrs: self.attrs.clone(),
            version: self.version,
            identity: crate::gmap::next_unique(),
            source: Some((self.identity, self.version)),
        }
    }
}

/// Parts that [`Embedded::new`] refused: the reason ([`CellRules::check`]'s error) and the map
/// and attributes given back unchanged (after [`CellRules::grow_to`]), so nothing is lost.
pub struct RefusedParts<const N: usize, E: CellRules<N>> {
    /// What the check found.
    pub error: E::Error,
    /// The map given.
    pub map: GMap<N>,
    /// The attributes given.
    pub attrs: E,
}

impl<const N: usize, E: CellRules<N>> std::fmt::Debug for RefusedParts<N, E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RefusedParts").field("error", &self.error).field("darts", &self.map.dart_count()).finish()
    }
}

impl<const N: usize, E: CellRules<N>> std::fmt::Display for RefusedParts<N, E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the attributes do not agree with the map: {}", self.error)
    }
}

impl<const N: usize, E: CellRules<N>> std::error::Error for RefusedParts<N, E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

impl<const N: usize, E: CellRules<N>> Embedded<N, E> {
    /// Wraps a map and attributes, which must agree: [`CellRules::check`] runs first (for the
    /// mechanical model, every conservation law), since parts from outside are the one way in
    /// that no rule has vetted. O(check) (plus [`CellRules::grow_to`]).
    ///
    /// # Errors
    /// [`RefusedParts`] (boxed: it holds the whole map): the check's error, with both parts given
    /// back.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, mech) = body.into_parts();
    /// let rebuilt = Body::new(map.clone(), mech.clone()).unwrap();
    /// assert_eq!(rebuilt.version(), 0);
    /// assert!(rebuilt.map().is_isomorphic(&map));
    /// // The attributes of another body do not agree with this map: refused, parts given back.
    /// let (points, tets) = kuhn_cube(2);
    /// let (other, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let refused = Body::new(other.into_parts().0, mech).unwrap_err();
    /// assert!(refused.to_string().starts_with("the attributes do not agree with the map"));
    /// assert_eq!(refused.map.dart_count(), 1152);
    /// ```
    pub fn new(map: GMap<N>, mut attrs: E) -> Result<Self, Box<RefusedParts<N, E>>> {
        attrs.grow_to(&map);
        if let Err(error) = attrs.check(&map) {
            return Err(Box::new(RefusedParts { error, map, attrs }));
        }
        Ok(Embedded { map, attrs, version: 0, identity: crate::gmap::next_unique(), source: None })
    }

    /// [`Embedded::new`] without the check, for parts this crate has just built or checked
    /// itself (the model builder, the store after its own conservation check). O(1) (plus
    /// [`CellRules::grow_to`]).
    pub(crate) fn from_checked_parts(map: GMap<N>, mut attrs: E) -> Self {
        attrs.grow_to(&map);
        Embedded { map, attrs, version: 0, identity: crate::gmap::next_unique(), source: None }
    }

    /// The map (read-only). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.map().count_cells().0, vec![8, 19, 18, 6]);
    /// assert_eq!(body.map().dart_count(), 6 * 24);
    /// ```
    pub fn map(&self) -> &GMap<N> {
        &self.map
    }

    /// The attributes. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let total = body.total_vertex_mass();
    /// assert!((total - Material::default().density).abs() < 1e-12); // the unit cube
    /// ```
    pub fn attrs(&self) -> &E {
        &self.attrs
    }

    /// The attributes, mutable as a whole, inside the crate only: a caller outside gets a body's
    /// free state through [`crate::mechanics::AttrsMut`] (`Body::attrs_mut`), which cannot
    /// replace or swap the attributes whole (rounds 26–27: attributes put back from another
    /// state broke the cover and the laws behind every check's back). O(1).
    pub(crate) fn attrs_raw_mut(&mut self) -> &mut E {
        &mut self.attrs
    }

    /// A number that names this body among all bodies of the process: set by
    /// [`Embedded::new`], different for a clone. Projections and simulations remember it and
    /// refuse another body. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let copy = body.clone();
    /// assert_ne!(copy.identity(), body.identity());
    /// assert_eq!((copy.version(), copy.map().dart_count()), (body.version(), body.map().dart_count()));
    /// ```
    pub fn identity(&self) -> u64 {
        self.identity
    }

    /// Whether this body is a clone of `original` taken at `original`'s present version, with
    /// no operation on either since. O(1).
    pub(crate) fn is_unchanged_clone_of(&self, original: &Self) -> bool {
        self.source == Some((original.identity, original.version)) && self.version == original.version
    }

    /// Number of topological operations applied so far. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.version(), 0);
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// body.unsew3(d).unwrap();
    /// assert_eq!(body.version(), 1);
    /// assert!(body.unsew3(d).is_err()); // refused: nothing changed
    /// assert_eq!(body.version(), 1);
    /// ```
    pub fn version(&self) -> u64 {
        self.version
    }

    /// i-sews `d1` and `d2` ([`GMap::sew_dyn`]) and applies the merge rules to every merged cell.
    /// The report is stamped as this map's operation (identity, version after it, a fingerprint
    /// of its lists), which [`crate::mechanics::TouchedCells::record_change`] checks.
    /// Cost: the kernel's sew plus the rules (for the mechanical model, O(size of merged cells)).
    ///
    /// # Errors
    /// [`EmbedError::Sew`] when the kernel refuses, [`EmbedError::Refused`] when the rules do
    /// ([`CellRules::check_sew`]; nothing changed either way); [`EmbedError::Check`] under
    /// `expensive-checks` when the attributes fail their check afterwards.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let e = body.map().alpha::<3>(d);
    /// body.unsew(3, d).unwrap();
    /// assert!(body.sew(3, d, d).is_err()); // refused by the kernel
    /// let changes = body.sew(3, d, e).unwrap();
    /// assert!(changes.merges(0).count() > 0 && body.check().is_ok());
    /// ```
    pub fn sew(&mut self, i: usize, d1: DartId, d2: DartId) -> Result<CellChanges, EmbedError<E::Error>> {
        let pairs = self.map.sew_pairs(i, d1, d2)?;
        self.attrs.check_sew(&self.map, i, &pairs).map_err(|source| EmbedError::Refused {
            op: "sew",
            dart: d1,
            source,
        })?;
        let mut changes = self.map.link_sew_pairs(i, d1, pairs);
        self.apply(&changes);
        self.after("sew", d1)?;
        self.stamp(&mut changes);
        Ok(changes)
    }

    /// i-unsews `d` ([`GMap::unsew_dyn`]) and applies the split rules to every split cell; the
    /// report is stamped as for [`Embedded::sew`].
    /// Cost: the kernel's unsew plus the rules (O(size of the split cells) for mechanics).
    ///
    /// # Errors
    /// As [`Embedded::sew`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let e = body.map().alpha::<3>(d);
    /// let changes = body.unsew(3, d).unwrap();
    /// assert_eq!(changes.pairs.len(), 6); // the six darts of a triangle, each with its partner
    /// body.sew(3, d, e).unwrap();
    /// assert!(body.check().is_ok());
    /// ```
    pub fn unsew(&mut self, i: usize, d: DartId) -> Result<CellChanges, EmbedError<E::Error>> {
        self.attrs.check_unsew(&self.map, i, d).map_err(|source| EmbedError::Refused {
            op: "unsew",
            dart: d,
            source,
        })?;
        let mut changes = self.map.unsew_dyn(i, d)?;
        self.apply(&changes);
        self.after("unsew", d)?;
        self.stamp(&mut changes);
        Ok(changes)
    }

    /// Marks `changes` as the report of this map's last operation: (identity, version,
    /// [`fingerprint`]), which [`Embedded::returned_last`] compares. O(the report's lists).
    fn stamp(&self, changes: &mut CellChanges) {
        changes.stamp = Some((self.identity, self.version, fingerprint(changes)));
    }

    /// Whether `changes` is, unedited, the report that this map's last [`Embedded::sew`] or
    /// [`Embedded::unsew`] returned: its stamp names this identity and the present version, and
    /// its lists still have the fingerprint they were stamped with. A kernel report, a default
    /// one, an earlier one, another map's or an edited one is not. O(the report's lists).
    pub(crate) fn returned_last(&self, changes: &CellChanges) -> bool {
        changes.stamp == Some((self.identity, self.version, fingerprint(changes)))
    }

    /// The map (read-only) and the attributes (mutable) at once, for updates of the attributes
    /// that read the topology (the map stays untouchable, so this is not a topological change:
    /// the version stays). O(1).
    pub(crate) fn map_and_attrs_mut(&mut self) -> (&GMap<N>, &mut E) {
        (&self.map, &mut self.attrs)
    }

    /// Runs the rules of `changes` (already applied to the map).
    fn apply(&mut self, changes: &CellChanges) {
        self.version += 1;
        self.attrs.grow_to(&self.map);
        for (k, change) in changes.changes.iter().enumerate() {
            match *change {
                CellChange::Split { dim, kept, new, dart_kept, dart_new } => {
                    let new_side = changes.new_side(k);
                    self.attrs.on_split(&self.map, &Split { dim, kept, new, dart_kept, dart_new, new_side })
                }
                CellChange::Merged { dim, kept, absorbed } => self.attrs.on_merge(&self.map, dim, kept, absorbed),
            }
        }
        self.attrs.after_operation(&self.map, changes);
    }

    #[cfg(feature = "expensive-checks")]
    fn after(&self, op: &'static str, dart: DartId) -> Result<(), EmbedError<E::Error>> {
        self.attrs.check(&self.map).map_err(|source| EmbedError::Check { op, dart, source })
    }

    #[cfg(not(feature = "expensive-checks"))]
    #[inline(always)]
    fn after(&self, _op: &'static str, _dart: DartId) -> Result<(), EmbedError<E::Error>> {
        Ok(())
    }

    /// Runs [`CellRules::check`] now, whatever the features.
    ///
    /// # Errors
    /// The check's error.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!(body.check().is_ok());
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// body.unsew3(d).unwrap();
    /// assert!(body.check().is_ok()); // the split rules kept the laws
    /// ```
    pub fn check(&self) -> Result<(), E::Error> {
        self.attrs.check(&self.map)
    }

    /// Map and attributes, both mutable, bypassing the rules: only for crate operations that keep
    /// the attributes lawful themselves (volume removal deletes an isolated volume's darts,
    /// `crate::cut`). Counts as a topological change: bumps [`Embedded::version`]. O(1).
    pub(crate) fn parts_mut_bypassing_rules(&mut self) -> (&mut GMap<N>, &mut E) {
        self.version += 1;
        (&mut self.map, &mut self.attrs)
    }

    /// Splits into map and attributes. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, mech) = body.into_parts();
    /// let again = Body::new(map, mech).unwrap(); // back together, attributes unchanged
    /// assert!(again.check().is_ok());
    /// assert_eq!(again.map().dart_count(), 144);
    /// ```
    pub fn into_parts(self) -> (GMap<N>, E) {
        (self.map, self.attrs)
    }
}

//! Cell handles: a cell id held across operations, checked for reuse ([`CellHandle`]).

use super::{CellId, GMap};

/// A cell id with the generation it had when the handle was taken, and the map it was taken on.
///
/// Cell ids are dense and a released id is reused by a later operation (module docs of
/// [`crate::gmap`], docs/ARCHITECTURE.md §3), so a bare [`CellId`] kept across a cut, a removal
/// or a sew silently names another cell once its id comes back. A [`CellHandle`] is the tuple
/// (i, id, g, o) where g is the id's *generation* when the handle was taken — the stamp of its
/// last release in dimension i, 0 if none — and o the identity of the map. Stamps and identities
/// come from one process-wide counter: no two releases share a stamp, in any map, and every map
/// made (empty, built from a mesh, loaded from a file, extracted as a level) gets a new identity
/// that its clones keep. The law:
///
/// > `resolve(h)` on a map of identity o is `Ok(id)` exactly when `id` is a live i-cell now
/// > and its last release is still the one it had when `h` was taken (none, or the same event).
///
/// A cell that keeps its id through an operation keeps its handles: the side of a split that
/// keeps the id ([`CellChange::Split`](super::CellChange::Split)'s `kept`), the surviving cell
/// of a merge (`kept`). The absorbed cell of a merge, and every cell whose darts were deleted,
/// had their ids released: their handles are stale for good, even after the id is given to a new
/// cell. On a clone, a handle taken before the clone resolves in both until the id is released in
/// one of them; one taken after a release that the other map did not make is stale there, since
/// that map's id names another cell (finding 332). The stamps are the map's history, not its
/// state: the file formats (`crate::store`) do not keep them, and a loaded map is another map
/// (handles taken before the save are refused with [`StaleCell::OtherMap`]).
///
/// # Examples
///
/// ```
/// use topomech::gmap::StaleCell;
/// use topomech::GMap;
///
/// // Two tets glued along a face: unsewing it splits its three vertices, sewing it back merges them.
/// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let e = map.alpha::<3>(d);
/// let apex = map.cell_handle(0, topomech::CellId(3)).unwrap(); // no operation touches it
///
/// let (kept, new, _, _) = map.unsew::<3>(d).unwrap().splits(0).next().unwrap();
/// let (one, other) = (map.cell_handle(0, kept).unwrap(), map.cell_handle(0, new).unwrap());
/// map.sew::<3>(d, e).unwrap(); // the two pieces merge again: one id stays, one is released
/// let (a, b) = (map.resolve(one), map.resolve(other));
/// assert!(a.is_ok() != b.is_ok());
///
/// map.unsew::<3>(d).unwrap(); // the released id is given to a new vertex
/// let stale = if a.is_ok() { other } else { one };
/// assert!(matches!(map.resolve(stale), Err(StaleCell::Reused { .. })));
/// assert_eq!(map.resolve(apex), Ok(topomech::CellId(3)));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellHandle {
    dim: u8,
    id: CellId,
    generation: u64,
    origin: u64,
}

impl CellHandle {
    /// The cell's dimension i.
    pub fn dim(&self) -> usize {
        self.dim as usize
    }

    /// The cell id the handle was taken for.
    pub fn id(&self) -> CellId {
        self.id
    }

    /// The id's generation when the handle was taken: the stamp of its last release, 0 if it had
    /// never been released. Only equality is meaningful (stamps grow with time in the process).
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

/// Why a [`CellHandle`] no longer names its cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StaleCell {
    /// The id is free: the cell was merged into another or its darts were deleted.
    #[error("{dim}-cell {id} no longer exists (its id was released and is free)")]
    Released {
        /// The dimension.
        dim: usize,
        /// The id.
        id: CellId,
    },
    /// The id is live but its last release is not the one it had when the handle was taken
    /// (released since, or on a clone, released by another history): it names another cell.
    #[error(
        "{dim}-cell {id} no longer exists: its id now names another cell (generation {now}, {then} when the handle was taken)"
    )]
    Reused {
        /// The dimension.
        dim: usize,
        /// The id.
        id: CellId,
        /// The id's generation when the handle was taken ([`CellHandle::generation`]).
        then: u64,
        /// Its generation now.
        now: u64,
    },
    /// The handle was taken on another map (not this one or a clone of it): a map built apart,
    /// loaded from a file, or extracted as a level.
    #[error("the handle on {dim}-cell {id} was taken on another map")]
    OtherMap {
        /// The dimension.
        dim: usize,
        /// The id.
        id: CellId,
    },
    /// No such dimension, or an id that was never allocated.
    #[error("no {dim}-cell {id} in this map")]
    NoSuchCell {
        /// The dimension.
        dim: usize,
        /// The id.
        id: CellId,
    },
}

impl<const N: usize> GMap<N> {
    /// A handle on the live i-cell `id`, to be [`resolve`](GMap::resolve)d after later
    /// operations ([`CellHandle`]). O(free ids of dimension i).
    ///
    /// # Errors
    /// [`StaleCell::NoSuchCell`] when i > n or `id` was never allocated,
    /// [`StaleCell::Released`] when `id` is free.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::StaleCell;
    /// use topomech::{CellId, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(6, &[[5, 1, 2, 3]]).unwrap();
    /// assert!(map.cell_handle(0, CellId(5)).is_ok());
    /// assert!(matches!(map.cell_handle(0, CellId(4)), Err(StaleCell::Released { .. }))); // unused point
    /// assert!(matches!(map.cell_handle(4, CellId(0)), Err(StaleCell::NoSuchCell { .. })));
    /// ```
    pub fn cell_handle(&self, i: usize, id: CellId) -> Result<CellHandle, StaleCell> {
        match self.ids.get(i) {
            Some(ids) if id.0 < ids.next => {
                if ids.free.contains(&id.0) {
                    return Err(StaleCell::Released { dim: i, id });
                }
                Ok(CellHandle { dim: i as u8, id, generation: ids.generation(id.0), origin: self.origin })
            }
            _ => Err(StaleCell::NoSuchCell { dim: i, id }),
        }
    }

    /// The id of the cell `h` was taken for, if that cell still holds it: `Ok(id)` exactly when
    /// `h` was taken on this map or a clone of it, the id is live and its generation is the
    /// handle's ([`CellHandle`]). O(free ids of the handle's dimension).
    ///
    /// # Errors
    /// [`StaleCell::OtherMap`] for a handle taken on another map, [`StaleCell::Released`] when
    /// the id is free, [`StaleCell::Reused`] when it is live but was released since (it names
    /// another cell now).
    pub fn resolve(&self, h: CellHandle) -> Result<CellId, StaleCell> {
        let (dim, id) = (h.dim(), h.id);
        if h.origin != self.origin {
            return Err(StaleCell::OtherMap { dim, id });
        }
        let Some(ids) = self.ids.get(dim).filter(|ids| id.0 < ids.next) else {
            return Err(StaleCell::NoSuchCell { dim, id });
        };
        if ids.free.contains(&id.0) {
            return Err(StaleCell::Released { dim, id });
        }
        let now = ids.generation(id.0);
        if now != h.generation {
            return Err(StaleCell::Reused { dim, id, then: h.generation, now });
        }
        Ok(id)
    }
}

//! Export and rebuild a [`LeveledMap`] from plain data ([`LevelParts`]): what `store` saves.
//!
//! [`LeveledMap::to_parts`] copies every per-dart record; [`LeveledMap::from_parts`] checks the
//! records against the map (lengths, level bounds, well-formed histories) and then every level
//! law ([`LeveledMap::check_all`]), so a file can never smuggle in a map whose levels are broken.

use super::{LevelError, LeveledMap, LinkChange, Mu, MAX_LEVEL};
use crate::gmap::{DartId, GMap, InvariantViolation};

/// One recorded link change: before level `level`, αj(d) was `old` (see the module docs of
/// [`crate::subdivide`]).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::LeveledMap;
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![]);
/// let d = m.map().darts().next().unwrap();
/// let old = m.map().alpha_dyn(0, d);
/// m.split_edge(d, 1).unwrap();
/// let h = &m.to_parts().darts[d.index()].history;
/// assert!(h.iter().any(|e| e.level == 1 && e.j == 0 && e.old == old.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistoryEntry {
    /// The level of the operation that changed the link (1..=max level in practice).
    pub level: u8,
    /// The involution αj, 0 ≤ j ≤ n.
    pub j: u8,
    /// The dart αj(d) was linked to before that level.
    pub old: u32,
}

/// The level records of one dart slot.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::LeveledMap;
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![]);
/// let d = m.map().darts().next().unwrap();
/// let mid = m.split_edge(d, 1).unwrap();
/// let parts = m.to_parts();
/// let r = &parts.darts[mid.index()];
/// assert_eq!((r.level, r.mu), (m.dart_level(mid), m.mu(mid)));
/// assert!(r.flat); // the midpoint is an inserted vertex of the triangle's side
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DartLevels {
    /// The level at which the dart was created.
    pub level: u8,
    /// Its resolution levels μa, μf, μt.
    pub mu: Mu,
    /// Whether its vertex is an inserted (flat) vertex of a side of its face.
    pub flat: bool,
    /// Its link changes, in the order they were made (non-decreasing level).
    pub history: Vec<HistoryEntry>,
}

/// Everything a [`LeveledMap`] holds besides its finest map, as plain data.
///
/// Invariant checked by [`LeveledMap::from_parts`]: `darts` has one record per dart slot of the
/// map (dead slots: ignored, rebuilt as defaults).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::LeveledMap;
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// let parts = m.to_parts();
/// assert_eq!((parts.max_level, parts.darts.len()), (1, m.map().capacity()));
/// assert_eq!(parts.points.len(), 6);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LevelParts {
    /// The largest level any operation used (k ≤ [`MAX_LEVEL`]).
    pub max_level: u8,
    /// One record per dart slot, indexed by dart id.
    pub darts: Vec<DartLevels>,
    /// Vertex positions keyed by vertex id (may be empty).
    pub points: Vec<[f64; 3]>,
    /// The vertices a cut made, as (copy, [origin](LeveledMap::vertex_origin)) with copy ≠
    /// origin, copies strictly increasing (empty when no cut split a vertex).
    pub origins: Vec<[u32; 2]>,
}

/// Why [`LeveledMap::from_parts`] refused its input.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::{LevelPartsError, LeveledMap};
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let m = LeveledMap::new(map, vec![]);
/// let mut parts = m.to_parts();
/// parts.max_level = 251;
/// let e = LeveledMap::from_parts(m.map().clone(), parts).unwrap_err();
/// assert!(matches!(e, LevelPartsError::MaxLevelTooHigh(251)));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LevelPartsError {
    /// The number of dart records is not the map's dart capacity.
    #[error("{found} dart level records for a map of {capacity} dart slots")]
    WrongLength {
        /// Records given.
        found: usize,
        /// Dart slots of the map.
        capacity: usize,
    },
    /// The maximum level is above [`MAX_LEVEL`].
    #[error("max level {0} is above the maximum {MAX_LEVEL}")]
    MaxLevelTooHigh(u8),
    /// A dart's creation level is above the maximum level.
    #[error("{dart}: dart level {level} is above the max level {max_level}")]
    DartLevelAboveMax {
        /// The dart.
        dart: DartId,
        /// Its level.
        level: u8,
        /// The map's maximum level.
        max_level: u8,
    },
    /// A dart's μa is above the maximum level (μf and μt above it break the μ order, a law
    /// checked after the records).
    #[error("{dart}: μa = {} is above the max level {max_level}", .mu.edge)]
    MuAboveMax {
        /// The dart.
        dart: DartId,
        /// Its levels.
        mu: Mu,
        /// The map's maximum level.
        max_level: u8,
    },
    /// A history entry is malformed: j > n, level above the max level, `old` not a dart slot,
    /// levels out of order, or a second change of one αj at one level.
    #[error("{dart}: history entry {index} (level {}, α{}, old {}) {reason}", .entry.level, .entry.j, .entry.old)]
    BadHistory {
        /// The dart.
        dart: DartId,
        /// Index of the entry in the dart's history.
        index: usize,
        /// The entry.
        entry: HistoryEntry,
        /// What is wrong.
        reason: &'static str,
    },
    /// An origin pair is malformed: a vertex id at or past the map's vertex id bound, a copy
    /// named as its own origin, or copies not strictly increasing.
    #[error("origin pair {index} (vertex {}, origin {}) {reason}", .pair[0], .pair[1])]
    BadOrigin {
        /// Index of the pair in [`LevelParts::origins`].
        index: usize,
        /// The pair (copy, origin).
        pair: [u32; 2],
        /// What is wrong.
        reason: &'static str,
    },
    /// The records are well formed but a level law is broken.
    #[error("level law: {0}")]
    Law(#[from] LevelError),
}

/// Every malformed record of `parts` for `map` (empty when all are well formed), at most `limit`.
/// Laws are not checked here. O(capacity + history entries).
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// # use topomech::subdivide::record_errors;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// let mut parts = m.to_parts();
/// assert!(record_errors(m.map(), &parts, 10).is_empty());
/// parts.max_level = 0; // every new dart now has a level above the max
/// assert_eq!(record_errors(m.map(), &parts, 3).len(), 3);
/// ```
pub fn record_errors<const N: usize>(map: &GMap<N>, parts: &LevelParts, limit: usize) -> Vec<LevelPartsError> {
    let cap = map.capacity();
    let mut out = Vec::new();
    if parts.darts.len() != cap {
        out.push(LevelPartsError::WrongLength { found: parts.darts.len(), capacity: cap });
        return out;
    }
    if parts.max_level > MAX_LEVEL {
        out.push(LevelPartsError::MaxLevelTooHigh(parts.max_level));
    }
    for d in map.darts() {
        let rec = &parts.darts[d.index()];
        if rec.level > parts.max_level {
            out.push(LevelPartsError::DartLevelAboveMax { dart: d, level: rec.level, max_level: parts.max_level });
        }
        if rec.mu.edge > parts.max_level {
            out.push(LevelPartsError::MuAboveMax { dart: d, mu: rec.mu, max_level: parts.max_level });
        }
        for (index, &entry) in rec.history.iter().enumerate() {
            if let Some(reason) = history_problem::<N>(&rec.history[..index], entry, parts.max_level, cap) {
                out.push(LevelPartsError::BadHistory { dart: d, index, entry, reason });
            }
        }
    }
    for (index, &pair) in parts.origins.iter().enumerate() {
        let before = index.checked_sub(1).map(|k| parts.origins[k][0]);
        if let Some(reason) = origin_problem(pair, before, map.cell_id_bound(0)) {
            out.push(LevelPartsError::BadOrigin { index, pair, reason });
        }
    }
    out.truncate(limit);
    out
}

/// What is wrong with the origin pair `[copy, origin]` after a pair of copy `before`, with
/// `vertices` the map's vertex id bound, if anything. O(1).
fn origin_problem([copy, origin]: [u32; 2], before: Option<u32>, vertices: usize) -> Option<&'static str> {
    if copy as usize >= vertices || origin as usize >= vertices {
        Some("names a vertex id past the map's vertex ids")
    } else if copy == origin {
        Some("names a vertex as its own origin")
    } else if before.is_some_and(|b| b >= copy) {
        Some("does not come after the previous copy")
    } else {
        None
    }
}

/// What is wrong with `entry` after the entries `before` of the same dart, if anything.
fn history_problem<const N: usize>(
    before: &[HistoryEntry],
    entry: HistoryEntry,
    max_level: u8,
    capacity: usize,
) -> Option<&'static str> {
    if entry.j as usize > N {
        Some("names an involution above the dimension")
    } else if entry.level > max_level {
        Some("has a level above the max level")
    } else if entry.old as usize >= capacity {
        Some("points outside the dart slots")
    } else if before.last().is_some_and(|p| p.level > entry.level) {
        Some("comes after a change of a higher level")
    } else if before.iter().any(|p| p.level == entry.level && p.j == entry.j) {
        Some("repeats a change of the same link at the same level")
    } else {
        None
    }
}

impl<const N: usize> LeveledMap<N> {
    /// Copies the dart levels, μ, flat flags, histories, max level, points and the origins of
    /// the vertices a cut made ([`LeveledMap::vertex_origin`]). The split log is not copied: the
    /// histories hold it ([`LeveledMap::rebuild_split_log`]). O(capacity + history entries +
    /// points + vertices).
    ///
    /// ```
    /// use topomech::subdivide::LeveledMap;
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// let back = LeveledMap::from_parts(m.map().clone(), m.to_parts()).unwrap();
    /// assert_eq!(back.to_parts(), m.to_parts());
    /// ```
    pub fn to_parts(&self) -> LevelParts {
        let darts = (0..self.map.capacity())
            .map(|k| DartLevels {
                level: self.dart_level[k],
                mu: self.mu[k],
                flat: self.flat[k],
                history: self.history.of(k).map(|c| HistoryEntry { level: c.level, j: c.j, old: c.old }).collect(),
            })
            .collect();
        LevelParts { max_level: self.max_level, darts, points: self.points.clone(), origins: self.origin_pairs() }
    }

    /// Rebuilds a leveled map from its finest map and its records. Records of dead dart slots are
    /// ignored (rebuilt as defaults). O(k · capacity · n²) (it runs [`Self::check_all`]).
    ///
    /// # Errors
    /// The first of [`record_errors`] ([`LevelPartsError::WrongLength`], `MaxLevelTooHigh`,
    /// `DartLevelAboveMax`, `MuAboveMax`, `BadHistory`, `BadOrigin`), then [`LevelPartsError::Law`] with the first level law
    /// broken: a level not closed or not an involution at some dart, then (from
    /// [`Self::check_all`]) the finest map invalid, μ order or constancy, a level not a valid
    /// G-map, a flat flag other than the one the levels and history determine
    /// ([`LevelError::FlatFlag`]), an origin law broken or a history that is no split log
    /// ([`LevelError::SplitLog`]). [`LevelPartsError::BadOrigin`] comes with the record errors.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// # use topomech::subdivide::LevelPartsError;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.split_edge(d, 1).unwrap();
    /// let back = LeveledMap::from_parts(m.map().clone(), m.to_parts()).unwrap();
    /// assert_eq!(back.alpha_at(0, 0, d), m.alpha_at(0, 0, d));
    /// let mut parts = m.to_parts();
    /// parts.darts.pop();
    /// let e = LeveledMap::from_parts(m.map().clone(), parts).unwrap_err();
    /// assert!(matches!(e, LevelPartsError::WrongLength { .. }));
    /// ```
    pub fn from_parts(map: GMap<N>, parts: LevelParts) -> Result<Self, LevelPartsError> {
        if let Some(e) = record_errors(&map, &parts, 1).into_iter().next() {
            return Err(e);
        }
        let m = Self::from_parts_unchecked(map, parts);
        if let Some(e) = m.level_link_errors(1).into_iter().next() {
            return Err(e.into());
        }
        m.check_all()?;
        Ok(m)
    }

    /// The involution law of every level on the leveled map's own darts, up to `limit` violations:
    /// for d ∈ B_i, αj^i(d) must be in B_i ([`LevelError::NotClosed`]) and αj^i(αj^i(d)) = d
    /// ([`LevelError::InvalidLevel`] with `NotInvolution`). [`Self::level`] links darts in pairs,
    /// so a one-sided history would be hidden in the extracted map: this check sees it.
    /// O(k · capacity · n · history length).
    pub(crate) fn level_link_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        for level in 0..=self.max_level {
            for d in self.map.darts().filter(|d| self.dart_level[d.index()] <= level) {
                for j in 0..=N {
                    let e = self.alpha_at(level, j, d);
                    if !self.map.contains(e) || self.dart_level[e.index()] > level {
                        out.push(LevelError::NotClosed { level, dart: d, j, image: e });
                    } else if self.alpha_at(level, j, e) != d {
                        let back = self.alpha_at(level, j, e);
                        let source = InvariantViolation::NotInvolution { dart: d, i: j, image: e, back };
                        out.push(LevelError::InvalidLevel { level, source });
                    }
                    if out.len() >= limit {
                        return out;
                    }
                }
            }
        }
        out
    }

    /// Rebuilds without checking any law. The records must satisfy [`record_errors`] (empty), so
    /// that [`Self::level`] and [`Self::alpha_at`] stay in range. O(capacity + entries).
    pub(crate) fn from_parts_unchecked(map: GMap<N>, parts: LevelParts) -> Self {
        let mut m = LeveledMap::new(map, parts.points);
        m.max_level = parts.max_level;
        for (k, rec) in parts.darts.into_iter().enumerate() {
            if !m.map.contains(DartId(k as u32)) {
                continue;
            }
            m.dart_level[k] = rec.level;
            m.mu[k] = rec.mu;
            m.flat[k] = rec.flat;
            for e in &rec.history {
                m.history.push(k, LinkChange { level: e.level, j: e.j, old: e.old });
            }
        }
        // As given (not followed to a root as a cut records them): the laws judge them.
        if let Some(&[last, _]) = parts.origins.iter().max_by_key(|p| p[0]) {
            m.origins = (0..=last).collect();
        }
        for [copy, origin] in parts.origins {
            m.origins[copy as usize] = origin;
        }
        m.splits = m.rebuild_split_log();
        m
    }
}

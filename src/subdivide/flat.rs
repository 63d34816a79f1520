//! The law of the per-dart *flat* flag (whether the vertex of a dart inside its face is an
//! inserted vertex of a side of the face rather than one of its corners).
//!
//! The flag is not free data: it follows from the dart levels and the link history. Only an
//! edge split ([`LeveledMap::split_edge`], and the side splits of
//! [`LeveledMap::subdivide_triangle`]) makes flat darts: every dart x of the edge, α0-linked to
//! y, gets a new dart x' of the operation's level L with α0(x) = x' (recorded in x's history as
//! the change (L, α0, y), since x is older than the operation), and the new darts are α1-linked
//! in pairs, so at the new vertex each face has a pair (d, e = α1(d)), both of level L, whose
//! half-edges end at x = α0^L(d) and y = α0^L(e), α0-linked before level L. The pair stops being
//! flat only when a face split makes the vertex a corner of the children, and that split re-links
//! α1 of both darts (recorded in their history when it is a later operation; when the split is
//! the operation that made the vertex, the new α1 partner is a dart of a new inner edge, whose α0
//! has no such change). Every other dart (level 0, inner edges and faces, the darts of a bulk
//! refinement) is a corner. Hence the law, for every live dart d of level L = `dart_level(d)`:
//!
//! > flat(d) ⇔ L ≥ 1, e = α1(d) ≠ d has level L, neither d nor e has an α1 history entry, and
//! > x = α0^L(d), y = α0^L(e) have the history entries (L, α0, y) and (L, α0, x) (the two
//! > half-edges were one edge before level L).
//!
//! The entries are read rather than α0^{L−1}, because x and y need not be in B_{L−1}: an edge
//! made at level L (an inner edge of a tetrahedron) can be split by a later operation of the
//! same level L when it is also a side of a coarser face.
//!
//! Without this law a stored map could carry a wrong flag, which the face and tetrahedron
//! subdivisions trust (they walk the sides of a face by it).

use super::{LevelError, LeveledMap};
use crate::gmap::DartId;

impl<const N: usize> LeveledMap<N> {
    /// Whether the law of the module docs makes the live dart `d` flat. Images that are not
    /// live darts are taken as "not flat" rather than read, so this never panics, whatever the
    /// records (only history values below the capacity, as [`super::record_errors`] requires).
    /// O(changes of d, α1(d), α0^L(d) and α0^L(α1(d))).
    pub(super) fn derived_flat(&self, d: DartId) -> bool {
        let level = self.dart_level[d.index()];
        if level == 0 {
            return false;
        }
        let e = self.map.alpha_dyn(1, d);
        if e == d || !self.map.contains(e) || self.dart_level[e.index()] != level {
            return false;
        }
        let alpha1_changed = |x: DartId| self.history.of(x.index()).any(|c| c.j == 1);
        if alpha1_changed(d) || alpha1_changed(e) {
            return false;
        }
        let (x, y) = (self.alpha_at(level, 0, d), self.alpha_at(level, 0, e));
        // The value α0 had before the level-L operations, if one of them changed it.
        let before = |z: DartId| self.history.of(z.index()).find(|c| c.j == 0 && c.level == level).map(|c| c.old);
        before(x) == Some(y.0) && before(y) == Some(x.0)
    }

    /// Every live dart whose flat flag breaks the law of the module docs
    /// ([`LevelError::FlatFlag`]), in dart order, at most `limit`. Meaningful once the links of
    /// every level are closed ([`Self::level_link_errors`] empty), as [`Self::check_all`] and
    /// the store's check run it. O(capacity · changes per dart), within
    /// the O(k · capacity · n²) of [`Self::check_all`] (at most one change per level and αj).
    pub(crate) fn flat_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        for d in self.map.darts() {
            if out.len() >= limit {
                break;
            }
            let flat = self.flat[d.index()];
            if flat != self.derived_flat(d) {
                out.push(LevelError::FlatFlag { dart: d, flat });
            }
        }
        out
    }
}

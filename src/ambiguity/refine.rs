//! The naive indexed model refined the usual way: a tet is split 1→8 over its corners and six
//! edge midpoints, the midpoint of an edge being looked up in a hash keyed by its two point
//! indices, so a neighbour that refines later reuses it.
//!
//! ```text
//!   tet [a, b, c, d] → 4 corner tets [x, m_xy, m_xz, m_xw]
//!                    + 4 tets [D1, D2, X_k, X_k+1] around an octahedron diagonal (D1, D2)
//! ```
//! What the tet list cannot say: a neighbour that shares a face or an edge with a refined tet but
//! is not refined itself keeps its coarse triangle, so the midpoints on its edges are *hanging*
//! (T-junctions): adjacency through shared point triples no longer glues it to the children.
//! After cuts, the hash is keyed by the duplicated point indices, so an edge the cut rule left
//! shared between two sides shares one midpoint — the model cannot tell which copy was meant.

use rustc_hash::FxHashMap;

use crate::ambiguity::indexed::{IndexedError, IndexedModel};

/// The six edges of a tet as pairs of corner indices (midpoint label = 4 + index).
const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// An [`IndexedModel`] with point positions and the edge → midpoint hash.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::refine::RefinedModel;
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
/// let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
/// r.subdivide(0, None).unwrap();
/// r.subdivide(1, None).unwrap(); // then its neighbour (tet indices never change)
/// assert_eq!(r.hanging_edges(), 0);
/// assert_eq!(r.model.points, 5 + 9); // the shared face's three midpoints are reused
/// ```
#[derive(Debug, Clone)]
pub struct RefinedModel {
    /// The tet list (cuts go through [`IndexedModel::cut`]).
    pub model: IndexedModel,
    /// Positions of the points that are no copy (input points and midpoints), by point index;
    /// a copy has the position of its `origin`.
    positions: Vec<[f64; 3]>,
    /// Midpoint of each refined edge, keyed by its sorted point pair.
    midpoint: FxHashMap<(u32, u32), u32>,
}

impl RefinedModel {
    /// The model of `tets` over `points` (one position per point). O(points + tets).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::refine::RefinedModel;
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let r = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!((r.model.points, r.model.tets.len()), (4, 1));
    /// assert_eq!(r.hanging_edges(), 0);
    /// ```
    pub fn new(points: &[[f64; 3]], tets: &[[u32; 4]]) -> Result<Self, IndexedError> {
        Ok(RefinedModel {
            model: IndexedModel::new(points.len(), tets)?,
            positions: points.to_vec(),
            midpoint: FxHashMap::default(),
        })
    }

    /// The position of point p (the origin if unknown). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::refine::RefinedModel;
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(r.position(3), [0.0, 0.0, 1.0]);
    /// r.subdivide(0, None).unwrap();
    /// assert_eq!(r.position(4), [0.5, 0.0, 0.0]); // the first midpoint: edge (0, 1)
    /// ```
    pub fn position(&self, p: u32) -> [f64; 3] {
        let o = self.model.origin.get(p as usize).copied().unwrap_or(p);
        self.positions.get(o as usize).copied().unwrap_or([0.0; 3])
    }

    /// The midpoint of the edge (p, q): the hashed one, or a new point halfway. O(1).
    fn midpoint_of(&mut self, p: u32, q: u32) -> u32 {
        let key = (p.min(q), p.max(q));
        if let Some(&m) = self.midpoint.get(&key) {
            return m;
        }
        let (a, b) = (self.position(p), self.position(q));
        let m = self.model.add_point();
        if self.positions.len() <= m as usize {
            self.positions.resize(m as usize + 1, [0.0; 3]);
        }
        self.positions[m as usize] = crate::mesh::midpoint(a, b);
        self.midpoint.insert(key, m);
        m
    }

    /// Splits tet t into eight (see the [module docs](self)); the octahedron is split along the
    /// diagonal whose end positions are nearest `diagonal` (the g-map's choice, so both models
    /// take the same one), or along the shortest one when `diagonal` is `None`. Returns the
    /// children: t itself (now the corner tet at its first corner), then seven new indices.
    /// O(1) amortised plus the point lists of the corners.
    ///
    /// # Errors
    /// [`IndexedError::NoSuchTet`] when t does not exist (nothing changes).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::refine::RefinedModel;
    /// use topomech::GMap;
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
    /// assert!(r.subdivide(1, None).is_err()); // no tet 1
    /// let kids = r.subdivide(0, None).unwrap();
    /// assert_eq!((kids[0], r.model.tets.len(), r.model.points), (0, 8, 10));
    /// let (map, _) = GMap::<3>::from_tets(r.model.points, &r.model.tets).unwrap();
    /// assert_eq!(map.count_cells().0, vec![10, 25, 24, 8]);
    /// ```
    pub fn subdivide(&mut self, t: u32, diagonal: Option<[[f64; 3]; 2]>) -> Result<[u32; 8], IndexedError> {
        let tets = self.model.tets.len();
        let c = *self.model.tets.get(t as usize).ok_or(IndexedError::NoSuchTet { tet: t, tets })?;
        let m: Vec<u32> = PAIRS.iter().map(|&(x, y)| self.midpoint_of(c[x], c[y])).collect();
        let mid = |x: usize, y: usize| m[PAIRS.iter().position(|&p| p == (x.min(y), x.max(y))).expect("x ≠ y")];
        let mut children: Vec<[u32; 4]> = (0..4)
            .map(|x| {
                let o: Vec<usize> = (0..4).filter(|&y| y != x).collect();
                [c[x], mid(x, o[0]), mid(x, o[1]), mid(x, o[2])]
            })
            .collect();
        // Diagonals: (m01, m23), (m02, m13), (m03, m12); the equator of (m_i, m_5−i) is the rest.
        let score = |k: usize| {
            let (p, q) = (self.position(m[k]), self.position(m[5 - k]));
            match diagonal {
                Some([u, v]) => (dist2(p, u) + dist2(q, v)).min(dist2(p, v) + dist2(q, u)),
                None => dist2(p, q),
            }
        };
        let k = (0..3).min_by(|&a, &b| score(a).total_cmp(&score(b))).expect("three diagonals");
        let rest: Vec<usize> = (0..3).filter(|&j| j != k).collect();
        let cycle = [m[rest[0]], m[rest[1]], m[5 - rest[0]], m[5 - rest[1]]];
        for i in 0..4 {
            children.push([m[k], m[5 - k], cycle[i], cycle[(i + 1) % 4]]);
        }
        let mut out = [t; 8];
        self.model.set_tet(t, children[0])?;
        for (i, &child) in children.iter().enumerate().skip(1) {
            out[i] = self.model.push_tet(child)?;
        }
        Ok(out)
    }

    /// Edges of some tet whose midpoint exists and is used by another tet: T-junctions the
    /// tet list cannot glue. O(tets).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::refine::RefinedModel;
    ///
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    /// let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// r.subdivide(0, None).unwrap();
    /// assert_eq!(r.hanging_edges(), 3); // the edges of the face shared with the unrefined tet
    /// ```
    pub fn hanging_edges(&self) -> usize {
        let mut seen: Vec<(u32, u32)> = Vec::new();
        for tet in &self.model.tets {
            for &(x, y) in &PAIRS {
                let key = (tet[x].min(tet[y]), tet[x].max(tet[y]));
                if self.midpoint.get(&key).is_some_and(|&m| self.model.is_used(m)) {
                    seen.push(key);
                }
            }
        }
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }
}

fn dist2(p: [f64; 3], q: [f64; 3]) -> f64 {
    (0..3).map(|k| (p[k] - q[k]) * (p[k] - q[k])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmap::GMap;

    #[test]
    fn one_subdivided_tet_is_eight_tets_glued_like_the_g_map() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
        let kids = r.subdivide(0, None).unwrap();
        assert_eq!(r.model.tets.len(), 8);
        assert_eq!(r.model.points, 10);
        assert_eq!(kids[0], 0);
        let (map, report) = GMap::<3>::from_tets(r.model.points, &r.model.tets).expect("builds");
        assert!(report.pinched_vertices.is_empty() && report.split_edges.is_empty());
        assert_eq!(map.count_cells().0, [10, 25, 24, 8]);
        assert_eq!(r.hanging_edges(), 0);
    }

    /// The diagonal hint is an unordered pair of positions: its ends in either order split the
    /// octahedron the same way, whatever the hint (here every ordered pair of the ten points).
    #[test]
    fn the_diagonal_hint_does_not_depend_on_the_order_of_its_ends() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let fresh = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
        let mut probe = fresh.clone();
        probe.subdivide(0, None).unwrap();
        let ten: Vec<[f64; 3]> = (0..10).map(|p| probe.position(p)).collect();
        let split = |hint| {
            let mut r = fresh.clone();
            r.subdivide(0, Some(hint)).unwrap();
            r.model.tets
        };
        for &u in &ten {
            for &v in &ten {
                assert_eq!(split([u, v]), split([v, u]), "hint {u:?} {v:?}");
            }
        }
    }

    #[test]
    fn a_refined_neighbour_leaves_hanging_edges_until_the_other_refines() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let mut r = RefinedModel::new(&points, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
        r.subdivide(0, None).unwrap();
        assert_eq!(r.hanging_edges(), 3, "the three edges of the shared face");
        assert_eq!(r.model.points, 11);
        let other = r.model.tets.iter().position(|t| t.contains(&4)).expect("tet 1 unrefined") as u32;
        r.subdivide(other, None).unwrap();
        assert_eq!(r.hanging_edges(), 0);
        assert_eq!(r.model.points, 5 + 9, "the shared face's midpoints are reused");
        let (map, _) = GMap::<3>::from_tets(r.model.points, &r.model.tets).expect("builds");
        assert_eq!(map.components().len(), 1);
        assert_eq!(map.count_cells().0[3], 16);
    }
}

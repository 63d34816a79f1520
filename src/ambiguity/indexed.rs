//! The naive indexed model: a tet list over a point list, where adjacency is *derived* from shared
//! point indices (two tets are glued iff they share three points). A cut duplicates the points of
//! the cut face on one side — the usual approach — and nothing else is stored.
//!
//! # The cut rule
//! To cut the face between tets t1 and t2, for each point v of that face: walk the tets around v
//! from t2 through triangles containing v (shared point triples), never crossing the cut face
//! itself. If the walk does not reach t1, the tets reached form t2's side of v and get a fresh
//! copy of v. If it reaches t1, the tets around v are still connected around the cut and v stays
//! shared (the g-map keeps one vertex there too). When no point of the face was duplicated, t1 and
//! t2 still share the triple: the adjacency graph cannot express the cut, and the model re-glues
//! the face it was told to cut. When some but not all were, the edges of the face between two
//! kept points may be left with several fans of tets around them: a non-manifold edge, whose
//! duplication the point-based graph cannot express either.
//!
//! After the cuts, [`IndexedModel::audit`] compares the model with the g-map cut the same way:
//! the g-map rebuilt from the tet list (`GMap::from_tets`) is what the indexed model *means*; its
//! build report lists pinched points (tets around a point forming several fans: volumes joined by
//! a vertex only) and non-manifold point pairs (volumes joined by an edge only).
//!
//! Cost: a cut is O(tets around the face's points²); an audit is one `from_tets` (O(tets)) plus an
//! O(darts) comparison of α3.

use crate::gmap::{DartId, GMap};
use crate::BuildError;

/// A tet list over `points` points, with the naive cut rule of the [module docs](self).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::indexed::IndexedModel;
///
/// // Three tets around the edge (0, 1): cutting one face separates point 3 only.
/// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]]).unwrap();
/// let out = model.cut(0, 1).unwrap();
/// assert_eq!(out.kept, vec![0, 1]);
/// assert_eq!(out.duplicated, vec![(3, 5)]);
/// assert_eq!(model.origin[5], 3);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IndexedModel {
    /// Number of points (grows when points are duplicated).
    pub points: usize,
    /// The tetrahedra; tet indices never change.
    pub tets: Vec<[u32; 4]>,
    /// For every point, the tets using it.
    around: Vec<Vec<u32>>,
    /// For every point, the point of the input it copies.
    pub origin: Vec<u32>,
}

/// What one cut did to the indexed model.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::indexed::IndexedModel;
/// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
/// let out = model.cut(0, 1).unwrap();
/// assert_eq!(out.duplicated.len(), 3); // the three points of the shared face
/// assert!(out.kept.is_empty() && !out.face_still_shared);
/// assert_eq!(model.points, 8);
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct CutOutcome {
    /// Points duplicated: (old point, new point).
    pub duplicated: Vec<(u32, u32)>,
    /// Points of the face left shared because t1 is reachable around them.
    pub kept: Vec<u32>,
    /// Whether t1 and t2 still share three points: the model re-glued the cut face.
    pub face_still_shared: bool,
}

/// Why the indexed model could not perform a cut.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::indexed::{IndexedError, IndexedModel};
/// let mut model = IndexedModel::new(6, &[[0, 1, 2, 3], [2, 3, 4, 5]]).unwrap();
/// assert_eq!(model.cut(0, 7), Err(IndexedError::NoSuchTet { tet: 7, tets: 2 }));
/// assert!(matches!(model.cut(0, 1), Err(IndexedError::NoSharedFace(0, 1))));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IndexedError {
    /// A tet index past the end.
    #[error("tet {tet} does not exist (the model has {tets} tets)")]
    NoSuchTet {
        /// The index.
        tet: u32,
        /// Number of tets.
        tets: usize,
    },
    /// The two tets do not share exactly three points (or are one tet).
    #[error("tets {0} and {1} share no face (three points) in the indexed model")]
    NoSharedFace(u32, u32),
    /// Two tets of the input have the same four points (a duplicated element): the model names a
    /// face by its three points, so "the face between them" would be any of four. Refused by
    /// [`IndexedModel::new`].
    #[error(
        "tets {first} and {second} have the same four points {points:?} (a duplicated tet): the indexed model names a face by its three points and cannot tell their four common faces apart"
    )]
    CoincidentTets {
        /// The first of them, by index in the input.
        first: usize,
        /// The second (the first later tet with the same points).
        second: usize,
        /// The points of `second`, as listed.
        points: [u32; 4],
    },
    /// A tet names a point past the end.
    #[error("tet {tet} names point {point}, but the model has {points} points")]
    NoSuchPoint {
        /// The tet: its index in the input list, or the index it would take.
        tet: usize,
        /// The point.
        point: u32,
        /// Number of points.
        points: usize,
    },
}

/// Why [`IndexedModel::audit`] could not compare the models.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::CutComplex;
/// use topomech::ambiguity::indexed::{AuditError, IndexedError, IndexedModel};
///
/// let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
/// let model = IndexedModel::new(5, &tets).unwrap();
/// let gmap = CutComplex { points: 5, tets: tets.to_vec(), cuts: vec![] }.build().unwrap();
/// assert_eq!(
///     model.audit(&gmap, &[[0, 9]], &[]).unwrap_err(),
///     AuditError::Cut { cut: 0, source: IndexedError::NoSuchTet { tet: 9, tets: 2 } }
/// );
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AuditError {
    /// A cut names a tet past the end of the model's tet list
    /// ([`IndexedError::NoSuchTet`]).
    #[error("cut {cut}: {source}")]
    Cut {
        /// The cut's index in `cuts`.
        cut: usize,
        /// Why it is refused.
        source: IndexedError,
    },
    /// The model's tet list no longer builds as a g-map.
    #[error(transparent)]
    Build(#[from] BuildError),
}

/// [`IndexedError::NoSuchPoint`] for the first point of `tet` (tet number `t`) past `points`.
fn check_points(t: usize, tet: &[u32; 4], points: usize) -> Result<(), IndexedError> {
    match tet.iter().find(|&&p| p as usize >= points) {
        Some(&point) => Err(IndexedError::NoSuchPoint { tet: t, point, points }),
        None => Ok(()),
    }
}

/// The comparison of an indexed model with the g-map cut the same way.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::campaign::run_cuts;
/// let run = run_cuts(5, &[[0, 1, 2, 3], [1, 2, 3, 4]], &[[0, 1]]).unwrap();
/// let a = run.audit;
/// assert!(a.gmap_valid && a.cuts_without_duplication == 0);
/// assert_eq!((a.gmap_vertices, a.indexed_vertices), (8, 8));
/// assert!(!a.ambiguous() && !a.wrong());
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Audit {
    /// Cuts that duplicated no point (each is also a face still shared unless a later cut
    /// separated it).
    pub cuts_without_duplication: usize,
    /// Cut faces whose tets still share three points at the end.
    pub faces_still_shared: usize,
    /// Points whose tets form several fans (pinched vertices).
    pub pinched_points: usize,
    /// Point pairs whose tets form several fans (non-manifold edges).
    pub non_manifold_edges: usize,
    /// Whether the map rebuilt from the tet list glues faces differently from the g-map.
    pub gluing_differs: bool,
    /// Vertices of the g-map.
    pub gmap_vertices: usize,
    /// Points the tet list uses (the vertices the indexed model believes in).
    pub indexed_vertices: usize,
    /// Whether the g-map passed `validate()`.
    pub gmap_valid: bool,
}

impl Audit {
    /// Whether the indexed model's final state cannot stand for the topology the cuts made: a
    /// cut face it re-glued, a pinched point, a non-manifold edge, or a gluing that differs from
    /// the g-map's.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::Audit;
    ///
    /// assert!(!Audit::default().ambiguous());
    /// let lost = Audit { faces_still_shared: 1, gluing_differs: true, ..Audit::default() };
    /// assert!(lost.ambiguous() && lost.wrong());
    /// let pinched = Audit { pinched_points: 1, ..Audit::default() };
    /// assert!(pinched.ambiguous() && !pinched.wrong());
    /// ```
    pub fn ambiguous(&self) -> bool {
        self.faces_still_shared > 0 || self.pinched_points > 0 || self.non_manifold_edges > 0 || self.gluing_differs
    }

    /// Whether the indexed model's state means a different object from the g-map.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::Audit;
    ///
    /// let same = Audit { gmap_vertices: 8, indexed_vertices: 8, ..Audit::default() };
    /// assert!(!same.wrong());
    /// let fewer = Audit { gmap_vertices: 8, indexed_vertices: 7, ..Audit::default() };
    /// assert!(fewer.wrong() && !fewer.ambiguous());
    /// ```
    pub fn wrong(&self) -> bool {
        self.gluing_differs || self.gmap_vertices != self.indexed_vertices
    }
}

impl IndexedModel {
    /// A model of `tets` over `points` points. O(tets).
    ///
    /// # Errors
    /// [`IndexedError::NoSuchPoint`] for the first tet naming a point past `points`;
    /// [`IndexedError::CoincidentTets`] for the first tet with the same four points as an earlier
    /// one (in any order).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::{IndexedError, IndexedModel};
    ///
    /// let model = IndexedModel::new(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// assert_eq!((model.points, model.tets.len()), (5, 2));
    /// assert_eq!(model.origin, vec![0, 1, 2, 3, 4]);
    /// assert_eq!(model.used_points(), 5);
    /// let e = IndexedModel::new(4, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap_err();
    /// assert_eq!(e, IndexedError::NoSuchPoint { tet: 1, point: 4, points: 4 });
    /// // Tet 1 is tet 0 again (its points in another order): a duplicated element.
    /// let e = IndexedModel::new(4, &[[0, 1, 2, 3], [1, 0, 3, 2]]).unwrap_err();
    /// assert_eq!(e, IndexedError::CoincidentTets { first: 0, second: 1, points: [1, 0, 3, 2] });
    /// ```
    pub fn new(points: usize, tets: &[[u32; 4]]) -> Result<Self, IndexedError> {
        let mut around = vec![Vec::new(); points];
        let mut first_with: rustc_hash::FxHashMap<[u32; 4], usize> = rustc_hash::FxHashMap::default();
        for (t, tet) in tets.iter().enumerate() {
            check_points(t, tet, points)?;
            let mut key = *tet;
            key.sort_unstable();
            if let Some(&first) = first_with.get(&key) {
                return Err(IndexedError::CoincidentTets { first, second: t, points: *tet });
            }
            first_with.insert(key, t);
            for &p in tet {
                around[p as usize].push(t as u32);
            }
        }
        Ok(IndexedModel { points, tets: tets.to_vec(), around, origin: (0..points as u32).collect() })
    }

    fn tet(&self, t: u32) -> Result<[u32; 4], IndexedError> {
        self.tets.get(t as usize).copied().ok_or(IndexedError::NoSuchTet { tet: t, tets: self.tets.len() })
    }

    /// The points shared by two tets.
    fn shared(&self, a: u32, b: u32) -> Vec<u32> {
        let (ta, tb) = (self.tets[a as usize], self.tets[b as usize]);
        ta.iter().copied().filter(|p| tb.contains(p)).collect()
    }

    /// Cuts the face between tets t1 and t2 by the rule of the [module docs](self).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::{IndexedError, IndexedModel};
    ///
    /// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let out = model.cut(0, 1).unwrap();
    /// assert_eq!(out.duplicated.len(), 3);
    /// assert!(out.kept.is_empty() && !out.face_still_shared);
    /// assert_eq!(model.points, 8);
    /// assert_eq!(model.cut(0, 1), Err(IndexedError::NoSharedFace(0, 1))); // nothing shared now
    /// assert_eq!(model.cut(0, 9), Err(IndexedError::NoSuchTet { tet: 9, tets: 2 }));
    /// ```
    pub fn cut(&mut self, t1: u32, t2: u32) -> Result<CutOutcome, IndexedError> {
        self.tet(t1)?;
        self.tet(t2)?;
        let face = self.shared(t1, t2);
        if face.len() != 3 || t1 == t2 {
            return Err(IndexedError::NoSharedFace(t1, t2));
        }
        let mut outcome = CutOutcome::default();
        for &v in &face {
            let side = self.fan_from(v, t2, (t1, t2));
            if side.contains(&t1) {
                outcome.kept.push(v);
                continue;
            }
            let copy = self.duplicate(v, &side);
            outcome.duplicated.push((v, copy));
        }
        outcome.face_still_shared = self.shared(t1, t2).len() == 3;
        Ok(outcome)
    }

    /// The tets around point v reachable from `start` through shared triangles containing v,
    /// not crossing the face between the two tets of `cut`. O(tets around v²).
    fn fan_from(&self, v: u32, start: u32, cut: (u32, u32)) -> Vec<u32> {
        let around = &self.around[v as usize];
        let mut reached = vec![start];
        let mut head = 0;
        while head < reached.len() {
            let t = reached[head];
            head += 1;
            for &u in around {
                let crosses_cut = (t, u) == cut || (u, t) == cut;
                if reached.contains(&u) || crosses_cut || self.shared(t, u).len() != 3 {
                    continue;
                }
                reached.push(u);
            }
        }
        reached
    }

    /// Replaces v by a fresh point in the tets of `side`; returns the new point.
    fn duplicate(&mut self, v: u32, side: &[u32]) -> u32 {
        let copy = self.points as u32;
        self.points += 1;
        self.origin.push(self.origin[v as usize]);
        for &t in side {
            for p in &mut self.tets[t as usize] {
                if *p == v {
                    *p = copy;
                }
            }
        }
        self.around[v as usize].retain(|t| !side.contains(t));
        self.around.push(side.to_vec());
        copy
    }

    /// Adds a point of its own (not a copy of another) and returns it. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::IndexedModel;
    ///
    /// let mut model = IndexedModel::new(4, &[[0, 1, 2, 3]]).unwrap();
    /// let p = model.add_point();
    /// assert_eq!((p, model.points, model.origin[4]), (4, 5, 4));
    /// assert!(!model.is_used(p));
    /// ```
    pub fn add_point(&mut self) -> u32 {
        let p = self.points as u32;
        self.points += 1;
        self.origin.push(p);
        self.around.push(Vec::new());
        p
    }

    /// Replaces tet t by `tet`. O(tets around its points).
    ///
    /// # Errors
    /// [`IndexedError::NoSuchTet`] when t does not exist, [`IndexedError::NoSuchPoint`] when a
    /// point of `tet` does not; the model is then unchanged.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::{IndexedError, IndexedModel};
    ///
    /// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(model.set_tet(7, [1, 2, 3, 4]), Err(IndexedError::NoSuchTet { tet: 7, tets: 1 }));
    /// assert_eq!(model.set_tet(0, [1, 2, 3, 9]), Err(IndexedError::NoSuchPoint { tet: 0, point: 9, points: 5 }));
    /// assert_eq!(model.tets, vec![[0, 1, 2, 3]]);
    /// model.set_tet(0, [1, 2, 3, 4]).unwrap();
    /// assert_eq!(model.tets, vec![[1, 2, 3, 4]]);
    /// assert!(!model.is_used(0) && model.is_used(4));
    /// ```
    pub fn set_tet(&mut self, t: u32, tet: [u32; 4]) -> Result<(), IndexedError> {
        let old = self.tet(t)?;
        check_points(t as usize, &tet, self.points)?;
        for p in old {
            self.around[p as usize].retain(|&u| u != t);
        }
        for p in tet {
            self.around[p as usize].push(t);
        }
        self.tets[t as usize] = tet;
        Ok(())
    }

    /// Appends a tet over existing points and returns its index. O(1).
    ///
    /// # Errors
    /// [`IndexedError::NoSuchPoint`] when a point of `tet` does not exist (nothing is appended).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::{IndexedError, IndexedModel};
    ///
    /// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(model.used_points(), 4);
    /// assert_eq!(model.push_tet([1, 2, 3, 4]), Ok(1));
    /// assert_eq!(model.push_tet([1, 2, 3, 5]), Err(IndexedError::NoSuchPoint { tet: 2, point: 5, points: 5 }));
    /// assert_eq!(model.used_points(), 5);
    /// ```
    pub fn push_tet(&mut self, tet: [u32; 4]) -> Result<u32, IndexedError> {
        let t = self.tets.len() as u32;
        check_points(t as usize, &tet, self.points)?;
        self.tets.push(tet);
        for p in tet {
            self.around[p as usize].push(t);
        }
        Ok(t)
    }

    /// Whether some tet uses point p. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::IndexedModel;
    ///
    /// let model = IndexedModel::new(6, &[[0, 1, 2, 3]]).unwrap();
    /// assert!(model.is_used(3));
    /// assert!(!model.is_used(5) && !model.is_used(99));
    /// ```
    pub fn is_used(&self, p: u32) -> bool {
        self.around.get(p as usize).is_some_and(|a| !a.is_empty())
    }

    /// The number of points some tet uses. O(points).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::indexed::IndexedModel;
    ///
    /// let mut model = IndexedModel::new(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// model.cut(0, 1).unwrap();
    /// assert_eq!(model.used_points(), 8); // the three points of the cut face are duplicated
    /// ```
    pub fn used_points(&self) -> usize {
        self.around.iter().filter(|a| !a.is_empty()).count()
    }

    /// Compares the model with `gmap`, the g-map built from the same input by `GMap::from_tets`
    /// and cut by `unsew::<3>` on the same `cuts` (with `outcomes` the model's results of them).
    /// O(tets + cuts + darts · n).
    ///
    /// # Errors
    /// [`AuditError::Cut`] for the first cut that names a tet past the end of the tet list (as
    /// [`IndexedModel::cut`] refuses it: [`IndexedError::NoSuchTet`]), checked first, never a
    /// panic; [`AuditError::Build`] if the tet list no longer builds (cannot happen with this cut
    /// rule: it never makes a face shared by three tets).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::CutComplex;
    /// use topomech::ambiguity::indexed::IndexedModel;
    ///
    /// let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
    /// let mut model = IndexedModel::new(5, &tets).unwrap();
    /// let out = model.cut(0, 1).unwrap();
    /// let gmap = CutComplex { points: 5, tets: tets.to_vec(), cuts: vec![[0, 1]] }.build().unwrap();
    /// let audit = model.audit(&gmap, &[[0, 1]], &[out]).unwrap();
    /// assert!(!audit.ambiguous() && !audit.wrong() && audit.gmap_valid);
    /// assert_eq!((audit.gmap_vertices, audit.indexed_vertices), (8, 8));
    /// ```
    pub fn audit(&self, gmap: &GMap<3>, cuts: &[[u32; 2]], outcomes: &[CutOutcome]) -> Result<Audit, AuditError> {
        for (cut, &[a, b]) in cuts.iter().enumerate() {
            for t in [a, b] {
                self.tet(t).map_err(|source| AuditError::Cut { cut, source })?;
            }
        }
        let (rebuilt, report) = GMap::<3>::from_tets(self.points, &self.tets)?;
        let gluing_differs = gmap.capacity() != rebuilt.capacity()
            || gmap.darts().any(|d| !rebuilt.contains(d) || rebuilt.alpha::<3>(d) != gmap.alpha::<3>(d));
        let faces_still_shared = cuts.iter().filter(|&&[a, b]| self.shared(a, b).len() == 3).count();
        Ok(Audit {
            cuts_without_duplication: outcomes.iter().filter(|o| o.duplicated.is_empty()).count(),
            faces_still_shared,
            pinched_points: report.pinched_vertices.len(),
            non_manifold_edges: report.split_edges.len(),
            gluing_differs,
            gmap_vertices: gmap.count_cells().0[0],
            indexed_vertices: self.used_points(),
            gmap_valid: gmap.validate().is_ok(),
        })
    }
}

/// Whether `d` (a dart of a map laid out by `from_tets`) lies in tet t. O(1).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::indexed::dart_in_tet;
/// use topomech::gmap::DartId;
///
/// assert!(dart_in_tet(DartId(24), 1) && dart_in_tet(DartId(47), 1));
/// assert!(!dart_in_tet(DartId(23), 1));
/// ```
pub fn dart_in_tet(d: DartId, t: u32) -> bool {
    d.index() / 24 == t as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ambiguity::construct::CutComplex;

    #[test]
    fn cutting_the_only_face_of_two_tets_duplicates_its_three_points() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let mut model = IndexedModel::new(5, &tets).unwrap();
        let out = model.cut(0, 1).expect("shared face");
        assert_eq!(out.duplicated.len(), 3);
        assert!(out.kept.is_empty() && !out.face_still_shared);
        let gmap = CutComplex { points: 5, tets: tets.to_vec(), cuts: vec![[0, 1]] }.build().expect("builds");
        let audit = model.audit(&gmap, &[[0, 1]], &[out]).expect("builds");
        assert!(!audit.ambiguous() && !audit.wrong(), "{audit:?}");
        assert_eq!(audit.gmap_vertices, 8);
    }

    #[test]
    fn cutting_one_face_of_a_ring_of_three_tets_is_represented_exactly() {
        // Three tets around the edge (0, 1), ring 2-3-4: the points 0 and 1 keep their tets
        // connected around the cut, point 3 is separated; the indexed model gets it right.
        let tets = [[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]];
        let mut model = IndexedModel::new(5, &tets).unwrap();
        let out = model.cut(0, 1).expect("shared face");
        assert_eq!(out.kept, vec![0, 1]);
        assert_eq!(out.duplicated.len(), 1);
        let gmap = CutComplex { points: 5, tets: tets.to_vec(), cuts: vec![[0, 1]] }.build().expect("builds");
        let audit = model.audit(&gmap, &[[0, 1]], &[out]).expect("builds");
        assert!(!audit.ambiguous() && !audit.wrong(), "{audit:?}");
        assert_eq!(audit.gmap_vertices, 6);
    }

    #[test]
    fn a_cut_splitting_no_vertex_is_lost_by_the_indexed_model() {
        // Property over every interior face of a Kuhn cube: the indexed model re-glues the face
        // exactly when the g-map's unsew splits no vertex.
        let (points, tets) = crate::generate::kuhn_cube(2);
        let (fresh, _) = GMap::<3>::from_tets(points.len(), &tets).expect("builds");
        let mut lost = 0;
        for [t1, t2] in crate::ambiguity::construct::glued_faces(&fresh) {
            let mut gmap = fresh.clone();
            let d = crate::ambiguity::construct::shared_face_dart(&gmap, t1, t2).expect("glued");
            let changes = gmap.unsew::<3>(d).expect("sewn");
            let mut model = IndexedModel::new(points.len(), &tets).unwrap();
            let out = model.cut(t1, t2).expect("shared face");
            assert_eq!(out.face_still_shared, changes.splits(0).count() == 0, "cut {t1}-{t2}");
            let audit = model.audit(&gmap, &[[t1, t2]], &[out]).expect("builds");
            assert!(audit.gmap_valid);
            if audit.faces_still_shared > 0 {
                assert!(audit.gluing_differs && audit.ambiguous(), "a re-glued face is a different gluing");
            }
            lost += usize::from(audit.faces_still_shared > 0);
        }
        assert!(lost > 0, "some interior face of a Kuhn cube has all its points interior");
    }

    #[test]
    fn bad_cuts_are_errors() {
        let mut model = IndexedModel::new(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
        assert_eq!(model.cut(0, 7), Err(IndexedError::NoSuchTet { tet: 7, tets: 2 }));
        assert_eq!(model.cut(0, 0), Err(IndexedError::NoSharedFace(0, 0)));
    }
}

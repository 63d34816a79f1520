//! JSON test vectors: every catalogued ambiguity as plain data that any engine can replay.
//!
//! A [`PairVector`] holds two maps (their darts with α links, and how they were made) and the
//! graph they share; replaying it rebuilds both maps both ways and checks that they are *not*
//! isomorphic while their graphs *are*. An [`IndexedVector`] holds a tet list and a cut sequence
//! and the audit of the indexed model against the g-map; replaying it reruns both models.

use crate::ambiguity::campaign::{run_cuts, Symptom};
use crate::ambiguity::construct::CutComplex;
use crate::ambiguity::darts::{DartsError, DartsJson};
use crate::ambiguity::finder::{Candidate, Origin, Why};
use crate::ambiguity::indexed::Audit;
use crate::gmap::GMap;
use crate::graph::{graph_of, graphs_isomorphic, GraphJson, GraphJsonError, GraphKind, Multiplicity};

/// A test vector of either kind.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::*};
/// let uncut = CutComplex { points: 4, tets: vec![[0, 1, 2, 3]], cuts: vec![] };
/// let i = IndexedVector::of("one_tet", Symptom::SkeletonUnchanged, &uncut, "").unwrap();
/// let v = Vector::Indexed(Box::new(i));
/// assert!(v.check().is_ok() && v.name() == "one_tet");
/// assert_eq!(v.recompute().unwrap(), v);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Vector {
    /// Two maps sharing a graph.
    Pair(Box<PairVector>),
    /// An indexed model that cannot stand for the g-map after a cut sequence.
    Indexed(Box<IndexedVector>),
}

/// Characteristics of a map, stored for the reader (and checked on replay).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::vector::MapFacts;
/// use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let f = MapFacts::of(&map);
/// assert_eq!((f.darts, f.cells.clone(), f.boundary_darts), (6, vec![3, 3, 1], 6));
/// assert_eq!(f.euler_characteristic, 3 - 3 + 1);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct MapFacts {
    /// Live darts.
    pub darts: usize,
    /// i-cells for each i.
    pub cells: Vec<usize>,
    /// Darts that are αn-free.
    pub boundary_darts: usize,
    /// Σ (−1)^i · #i-cells.
    pub euler_characteristic: i64,
    /// Whether the map is orientable.
    pub orientable: bool,
}

impl MapFacts {
    /// The facts of `map`. O(darts · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::vector::MapFacts;
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let facts = MapFacts::of(&map);
    /// assert_eq!((facts.darts, facts.boundary_darts, facts.euler_characteristic), (24, 24, 1));
    /// assert_eq!(facts.cells, vec![4, 6, 4, 1]);
    /// assert!(facts.orientable);
    /// ```
    pub fn of<const N: usize>(map: &GMap<N>) -> Self {
        MapFacts {
            darts: map.dart_count(),
            cells: map.count_cells().0,
            boundary_darts: map.boundary_darts().count(),
            euler_characteristic: map.euler_characteristic(),
            orientable: map.is_orientable(),
        }
    }
}

/// One map of a pair.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{construct::Gluing, finder::*, vector::PairVector};
/// use topomech::graph::{GraphKind, Multiplicity};
/// let square = |same| Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] };
/// let cand = |same| Candidate { map: square(same).build().unwrap(), origin: Origin::Gluing(square(same)) };
/// let v = PairVector::of("t_k", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(1), "");
/// assert_eq!(v.a.origin, Origin::Gluing(square(0)));
/// assert_eq!((v.a.facts.darts, v.a.darts.alpha.len()), (8, 8));
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MapEntry {
    /// How it was made.
    pub origin: Origin,
    /// Its characteristics.
    pub facts: MapFacts,
    /// Its darts and α links.
    pub darts: DartsJson,
}

/// Two non-isomorphic maps with isomorphic graphs of one kind.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{construct::Gluing, finder::*, vector::PairVector};
/// use topomech::graph::{GraphKind, Multiplicity};
/// let square = |same| Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] };
/// let cand = |same| Candidate { map: square(same).build().unwrap(), origin: Origin::Gluing(square(same)) };
/// let v = PairVector::of("t_k", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(1), "");
/// assert_eq!((v.name.as_str(), v.graph_kind), ("t_k", GraphKind::Incidence));
/// assert_ne!(v.a.facts, v.b.facts);
/// assert!(v.check().is_ok());
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairVector {
    /// File stem and snapshot name.
    pub name: String,
    /// Dimension of both maps.
    pub dim: usize,
    /// The graph they share.
    pub graph_kind: GraphKind,
    /// Whether the shared graph includes multiplicities.
    pub multiplicity: Multiplicity,
    /// Why the maps differ.
    pub why: Why,
    /// One line for the catalogue.
    pub description: String,
    /// The first map.
    pub a: MapEntry,
    /// The second map.
    pub b: MapEntry,
    /// The graph both share (that of `a`).
    pub graph: GraphJson,
}

/// A cut sequence after which the indexed model shows a symptom.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::IndexedVector};
/// let cut = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![[0, 1]] };
/// let v = IndexedVector::of("two_tets", Symptom::PinchedPoint, &cut, "").unwrap();
/// assert_eq!((v.complex.cuts.len(), v.audit.gmap_vertices), (1, 8));
/// assert!(v.check().is_err()); // the cut shows no pinched point
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IndexedVector {
    /// File stem and snapshot name.
    pub name: String,
    /// The symptom this vector shows.
    pub symptom: Symptom,
    /// One line for the catalogue.
    pub description: String,
    /// The tets and the cuts.
    pub complex: CutComplex,
    /// The expected audit.
    pub audit: Audit,
}

/// Why a vector does not replay.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::*};
/// let bad = CutComplex { points: 4, tets: vec![[0, 1, 2, 3]], cuts: vec![[0, 0]] };
/// let e = IndexedVector::of("bad", Symptom::PinchedPoint, &bad, "").unwrap_err();
/// assert!(matches!(e, VectorError::Construction { .. }));
/// assert!(e.to_string().contains("bad"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VectorError {
    /// A dimension other than 2 or 3.
    #[error("vector {name}: dimension {dim} is not supported (2 or 3)")]
    Dimension {
        /// The vector.
        name: String,
        /// Its dimension.
        dim: usize,
    },
    /// The stored darts are not a valid map.
    #[error("vector {name}: {source}")]
    Darts {
        /// The vector.
        name: String,
        /// Why.
        source: DartsError,
    },
    /// The stored graph is malformed.
    #[error("vector {name}: {source}")]
    Graph {
        /// The vector.
        name: String,
        /// Why.
        source: GraphJsonError,
    },
    /// The construction does not build.
    #[error("vector {name}: the construction of map {which} fails: {message}")]
    Construction {
        /// The vector.
        name: String,
        /// "a" or "b".
        which: &'static str,
        /// The error.
        message: String,
    },
    /// A replay check failed.
    #[error("vector {name}: {check}")]
    Check {
        /// The vector.
        name: String,
        /// The failed check.
        check: String,
    },
}

impl PairVector {
    /// The vector of two candidates of one finder group. O(darts · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{construct::Gluing, finder::*, vector::PairVector};
    /// use topomech::graph::{GraphKind, Multiplicity};
    ///
    /// let square = |same| Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] };
    /// let cand = |same| Candidate { map: square(same).build().unwrap(), origin: Origin::Gluing(square(same)) };
    /// let v = PairVector::of("torus_klein", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(1), "");
    /// assert_eq!((v.dim, v.why), (2, Why::Orientation));
    /// assert!(v.a.facts.orientable && !v.b.facts.orientable);
    /// ```
    pub fn of<const N: usize>(
        name: &str,
        kind: GraphKind,
        multiplicity: Multiplicity,
        a: &Candidate<N>,
        b: &Candidate<N>,
        description: &str,
    ) -> Self {
        let entry = |c: &Candidate<N>| MapEntry {
            origin: c.origin.clone(),
            facts: MapFacts::of(&c.map),
            darts: DartsJson::of(&c.map),
        };
        PairVector {
            name: name.to_string(),
            dim: N,
            graph_kind: kind,
            multiplicity,
            why: Why::of(&a.map, &b.map),
            description: description.to_string(),
            a: entry(a),
            b: entry(b),
            graph: GraphJson::of(&graph_of(&a.map, kind), kind),
        }
    }

    /// Replays the vector: see the [module docs](self). O(darts² + VF2).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{construct::Gluing, finder::*, vector::PairVector};
    /// use topomech::graph::{GraphKind, Multiplicity};
    ///
    /// let square = |same| Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] };
    /// let cand = |same| Candidate { map: square(same).build().unwrap(), origin: Origin::Gluing(square(same)) };
    /// let v = PairVector::of("torus_klein", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(1), "");
    /// assert!(v.check().is_ok());
    /// let same = PairVector::of("torus_twice", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(0), "");
    /// assert!(same.check().is_err()); // isomorphic maps are no ambiguity
    /// ```
    pub fn check(&self) -> Result<(), VectorError> {
        match self.dim {
            2 => self.check_dim::<2>(),
            3 => self.check_dim::<3>(),
            dim => Err(VectorError::Dimension { name: self.name.clone(), dim }),
        }
    }

    fn fail(&self, check: impl Into<String>) -> VectorError {
        VectorError::Check { name: self.name.clone(), check: check.into() }
    }

    fn check_dim<const N: usize>(&self) -> Result<(), VectorError> {
        let a: GMap<N> = self.rebuild(&self.a, "a")?;
        let b: GMap<N> = self.rebuild(&self.b, "b")?;
        if a.is_isomorphic(&b) {
            return Err(self.fail("the two maps are isomorphic"));
        }
        if Why::of(&a, &b) != self.why {
            return Err(self.fail(format!("the maps differ by {:?}, not {:?}", Why::of(&a, &b), self.why)));
        }
        let (ga, gb) = (graph_of(&a, self.graph_kind), graph_of(&b, self.graph_kind));
        if !graphs_isomorphic(&ga, &gb, self.multiplicity) {
            return Err(self.fail(format!("the {} graphs are not isomorphic", self.graph_kind)));
        }
        let stored = self.graph.to_graph().map_err(|source| VectorError::Graph { name: self.name.clone(), source })?;
        if !graphs_isomorphic(&ga, &stored, Multiplicity::Match) {
            return Err(self.fail("the stored graph is not the graph of map a"));
        }
        Ok(())
    }

    /// Rebuilds a map from its darts, checks its facts, and checks that its construction gives
    /// an isomorphic map.
    fn rebuild<const N: usize>(&self, entry: &MapEntry, which: &'static str) -> Result<GMap<N>, VectorError> {
        let map: GMap<N> =
            entry.darts.to_map().map_err(|source| VectorError::Darts { name: self.name.clone(), source })?;
        if map.validate().is_err() || MapFacts::of(&map) != entry.facts {
            return Err(self.fail(format!("map {which}: invalid or facts differ from the stored ones")));
        }
        let constructed = construct_dyn::<N>(&entry.origin).map_err(|message| VectorError::Construction {
            name: self.name.clone(),
            which,
            message,
        })?;
        if !constructed.is_isomorphic(&map) {
            return Err(self.fail(format!("map {which}: the construction is not isomorphic to the darts")));
        }
        Ok(map)
    }
}

/// Builds an origin as an N-map (its darts re-read through [`DartsJson`] to change the type).
fn construct_dyn<const N: usize>(origin: &Origin) -> Result<GMap<N>, String> {
    let darts = match origin {
        Origin::Gluing(g) => DartsJson::of(&g.build().map_err(|e| e.to_string())?),
        Origin::Complex(c) => DartsJson::of(&c.build().map_err(|e| e.to_string())?),
        Origin::FaceGluing(g) => DartsJson::of(&g.build().map_err(|e| e.to_string())?),
    };
    darts.to_map().map_err(|e| e.to_string())
}

impl IndexedVector {
    /// The vector of a complex whose cuts show `symptom`. Errors: the complex does not run.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{campaign::*, construct::*, vector::IndexedVector};
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(2);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let one_cut = |f| CutComplex { points: points.len(), tets: tets.clone(), cuts: vec![f] };
    /// let lost = glued_faces(&map).into_iter().map(one_cut).find(|c| shows(c, Symptom::FaceStillShared)).unwrap();
    /// let v = IndexedVector::of("lost_cut", Symptom::FaceStillShared, &lost, "a re-glued face").unwrap();
    /// assert_eq!((v.audit.faces_still_shared, v.audit.cuts_without_duplication), (1, 1));
    /// assert!(v.check().is_ok());
    /// ```
    pub fn of(name: &str, symptom: Symptom, complex: &CutComplex, description: &str) -> Result<Self, VectorError> {
        let run = run_cuts(complex.points, &complex.tets, &complex.cuts).map_err(|e| VectorError::Construction {
            name: name.to_string(),
            which: "a",
            message: e.to_string(),
        })?;
        Ok(IndexedVector {
            name: name.to_string(),
            symptom,
            description: description.to_string(),
            complex: complex.clone(),
            audit: run.audit,
        })
    }

    /// Reruns both models and compares the audit and the symptom.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::IndexedVector};
    ///
    /// let uncut = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![] };
    /// let v = IndexedVector::of("uncut", Symptom::SkeletonUnchanged, &uncut, "").unwrap();
    /// assert!(v.check().is_ok());
    /// let cut = CutComplex { cuts: vec![[0, 1]], ..uncut };
    /// let w = IndexedVector::of("cut", Symptom::SkeletonUnchanged, &cut, "").unwrap();
    /// assert!(w.check().is_err()); // that cut splits vertices: the symptom is not shown
    /// ```
    pub fn check(&self) -> Result<(), VectorError> {
        let c = &self.complex;
        let fail = |check: String| VectorError::Check { name: self.name.clone(), check };
        let run = run_cuts(c.points, &c.tets, &c.cuts).map_err(|e| fail(e.to_string()))?;
        if run.audit != self.audit {
            return Err(fail(format!("audit {:?} differs from the stored {:?}", run.audit, self.audit)));
        }
        if !run.symptoms().contains(&self.symptom) || !run.audit.gmap_valid {
            return Err(fail(format!("symptom {:?} not shown (or the g-map is invalid)", self.symptom)));
        }
        Ok(())
    }
}

impl Vector {
    /// The vector's name.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::*};
    ///
    /// let uncut = CutComplex { points: 4, tets: vec![[0, 1, 2, 3]], cuts: vec![] };
    /// let i = IndexedVector::of("one_tet", Symptom::SkeletonUnchanged, &uncut, "").unwrap();
    /// let v = Vector::Indexed(Box::new(i));
    /// assert_eq!(v.name(), "one_tet");
    /// ```
    pub fn name(&self) -> &str {
        match self {
            Vector::Pair(p) => &p.name,
            Vector::Indexed(i) => &i.name,
        }
    }

    /// Replays the vector.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{campaign::Symptom, construct::CutComplex, vector::*};
    ///
    /// let uncut = CutComplex { points: 4, tets: vec![[0, 1, 2, 3]], cuts: vec![] };
    /// let i = IndexedVector::of("one_tet", Symptom::SkeletonUnchanged, &uncut, "").unwrap();
    /// let v = Vector::Indexed(Box::new(i));
    /// assert!(v.check().is_ok());
    /// let j = IndexedVector::of("one_tet", Symptom::PinchedPoint, &uncut, "").unwrap();
    /// let w = Vector::Indexed(Box::new(j));
    /// assert!(matches!(w.check(), Err(VectorError::Check { .. })));
    /// ```
    pub fn check(&self) -> Result<(), VectorError> {
        match self {
            Vector::Pair(p) => p.check(),
            Vector::Indexed(i) => i.check(),
        }
    }

    /// The vector made afresh from its constructions (same name, graph and description): equal
    /// to `self` as long as the builders and the kernel behave as when it was stored.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{construct::Gluing, finder::*, vector::*};
    /// use topomech::graph::{GraphKind, Multiplicity};
    ///
    /// let square = |same| Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] };
    /// let cand = |same| Candidate { map: square(same).build().unwrap(), origin: Origin::Gluing(square(same)) };
    /// let p = PairVector::of("torus_klein", GraphKind::Incidence, Multiplicity::Match, &cand(0), &cand(1), "");
    /// let v = Vector::Pair(Box::new(p));
    /// assert_eq!(v.recompute().unwrap(), v);
    /// ```
    pub fn recompute(&self) -> Result<Vector, VectorError> {
        match self {
            Vector::Pair(p) => match p.dim {
                2 => p.recompute_dim::<2>().map(|p| Vector::Pair(Box::new(p))),
                3 => p.recompute_dim::<3>().map(|p| Vector::Pair(Box::new(p))),
                dim => Err(VectorError::Dimension { name: p.name.clone(), dim }),
            },
            Vector::Indexed(i) => {
                IndexedVector::of(&i.name, i.symptom, &i.complex, &i.description).map(|i| Vector::Indexed(Box::new(i)))
            }
        }
    }
}

impl PairVector {
    fn recompute_dim<const N: usize>(&self) -> Result<PairVector, VectorError> {
        let candidate = |e: &MapEntry, which: &'static str| {
            construct_dyn::<N>(&e.origin)
                .map(|map| Candidate { map, origin: e.origin.clone() })
                .map_err(|message| VectorError::Construction { name: self.name.clone(), which, message })
        };
        let (a, b) = (candidate(&self.a, "a")?, candidate(&self.b, "b")?);
        Ok(PairVector::of(&self.name, self.graph_kind, self.multiplicity, &a, &b, &self.description))
    }
}

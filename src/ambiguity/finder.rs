//! The exhaustive finder: sorts small maps into isomorphism classes, then groups the classes whose
//! graphs are isomorphic. A group with two classes or more is an ambiguity of that graph: maps that
//! are not isomorphic (not the same object) yet share the graph.
//!
//! Candidates are added smallest first, so the first two classes of a group are a smallest pair
//! of the enumeration: the exhaustive search is its own shrinker.
//!
//! Cost: adding a candidate is O(darts · n²) for its key plus one `is_isomorphic` (O(darts²)) per
//! class with the same key; grouping is one VF2 per class and group with the same graph invariant.

use std::collections::HashMap;

use crate::ambiguity::construct::{CutComplex, FaceGluing, Gluing};
use crate::gmap::GMap;
use crate::graph::{graph_of, graphs_isomorphic, CellGraph, GraphInvariant, GraphKind, Multiplicity};

/// How a candidate map was made.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::Gluing;
/// use topomech::ambiguity::finder::{surfaces, Origin};
/// let finder = surfaces(2, 2);
/// // Every 2D class comes from a polygon gluing that rebuilds its map.
/// for c in finder.classes() {
///     let Origin::Gluing(g) = &c.origin else { panic!("2D classes are gluings") };
///     assert!(g.build().unwrap().is_isomorphic(&c.map));
/// }
/// assert!(matches!(Origin::Gluing(Gluing { sides: vec![3], pairs: vec![] }), Origin::Gluing(_)));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Origin {
    /// Polygons glued along sides (2D).
    Gluing(Gluing),
    /// Tetrahedra with dissociated faces (3D).
    Complex(CutComplex),
    /// Tetrahedra with faces glued to each other (3D).
    FaceGluing(FaceGluing),
}

/// A map and how it was made.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::Gluing;
/// use topomech::ambiguity::finder::{Candidate, Origin};
/// let g = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] };
/// let c = Candidate { map: g.build().unwrap(), origin: Origin::Gluing(g.clone()) };
/// assert_eq!(c.map.dart_count(), 8);
/// assert_eq!(c.origin, Origin::Gluing(g));
/// ```
#[derive(Debug, Clone)]
pub struct Candidate<const N: usize> {
    /// The map.
    pub map: GMap<N>,
    /// Its construction.
    pub origin: Origin,
}

/// An isomorphism invariant of a map, to bucket candidates before `is_isomorphic`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct MapKey {
    darts: usize,
    orbit_sizes: Vec<Vec<usize>>,
    boundary: usize,
    orientable: bool,
}

impl MapKey {
    fn of<const N: usize>(map: &GMap<N>) -> Self {
        let orbit_sizes = (0..=N)
            .map(|i| {
                let mut sizes: Vec<usize> =
                    map.one_dart_per_cell(i).into_iter().map(|d| map.cell_darts(i, d).len()).collect();
                sizes.sort_unstable();
                sizes
            })
            .collect();
        MapKey {
            darts: map.dart_count(),
            orbit_sizes,
            boundary: map.boundary_darts().count(),
            orientable: map.is_orientable(),
        }
    }
}

/// Why two maps of a pair differ, the first reason found in this order.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{construct::Gluing, finder::Why};
/// let disc = Gluing { sides: vec![4], pairs: vec![] }.build().unwrap();
/// let torus = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] }.build().unwrap();
/// assert_eq!(Why::of(&disc, &torus), Why::VertexIdentification);
/// assert_eq!(Why::of(&torus, &disc), Why::VertexIdentification);
/// assert_eq!(Why::of(&torus, &torus), Why::Gluing); // nothing else tells them apart
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Why {
    /// One is orientable, the other not.
    Orientation,
    /// Different numbers of vertices: vertices identified (pinched) in one, separate in the other.
    VertexIdentification,
    /// Same vertices, different numbers of higher cells: cells identified in one.
    CellIdentification,
    /// Different boundaries.
    Boundary,
    /// Same counts, orientability and boundary: only the way cells are glued differs.
    Gluing,
}

impl Why {
    /// Classifies the difference between two non-isomorphic maps. O(darts · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{construct::Gluing, finder::Why};
    ///
    /// let torus = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] }.build().unwrap();
    /// let klein = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 1]] }.build().unwrap();
    /// assert_eq!(Why::of(&torus, &klein), Why::Orientation);
    /// let disc = Gluing { sides: vec![4], pairs: vec![] }.build().unwrap();
    /// assert_eq!(Why::of(&torus, &disc), Why::VertexIdentification);
    /// ```
    pub fn of<const N: usize>(a: &GMap<N>, b: &GMap<N>) -> Self {
        let (ca, cb) = (a.count_cells().0, b.count_cells().0);
        if a.is_orientable() != b.is_orientable() {
            Why::Orientation
        } else if ca[0] != cb[0] {
            Why::VertexIdentification
        } else if ca != cb {
            Why::CellIdentification
        } else if a.boundary_darts().count() != b.boundary_darts().count() {
            Why::Boundary
        } else {
            Why::Gluing
        }
    }
}

/// Isomorphism classes of the candidates added so far.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::finder::surfaces;
/// use topomech::graph::{GraphKind, Multiplicity};
///
/// let finder = surfaces(4, 4);
/// let groups = finder.groups(GraphKind::VertexEdge, Multiplicity::Ignore);
/// assert!(!groups.is_empty());
/// for g in groups {
///     let (a, b) = (&finder.classes()[g.classes[0]].map, &finder.classes()[g.classes[1]].map);
///     assert!(!a.is_isomorphic(b)); // different objects, one vertex–edge graph
/// }
/// ```
#[derive(Debug, Default)]
pub struct Finder<const N: usize> {
    classes: Vec<Candidate<N>>,
    by_key: HashMap<MapKey, Vec<usize>>,
    tried: usize,
}

/// One ambiguity: classes (indices into [`Finder::classes`]) whose graphs of `kind` are
/// isomorphic, smallest first.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::finder::surfaces;
/// use topomech::graph::{GraphKind, Multiplicity};
/// let finder = surfaces(4, 4);
/// let groups = finder.groups(GraphKind::VertexEdge, Multiplicity::Ignore);
/// assert!(groups.iter().all(|g| g.kind == GraphKind::VertexEdge && g.classes.len() >= 2));
/// assert!(groups.iter().all(|g| g.classes.iter().all(|&c| c < finder.classes().len())));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Group {
    /// The graph.
    pub kind: GraphKind,
    /// Whether multiplicities were matched.
    pub multiplicity: Multiplicity,
    /// The classes sharing the graph (at least two).
    pub classes: Vec<usize>,
}

impl<const N: usize> Finder<N> {
    /// An empty finder.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::finder::Finder;
    ///
    /// let finder = Finder::<2>::new();
    /// assert!(finder.classes().is_empty());
    /// assert_eq!(finder.tried(), 0);
    /// ```
    pub fn new() -> Self {
        Finder { classes: Vec::new(), by_key: HashMap::new(), tried: 0 }
    }

    /// Adds a candidate if connected and not isomorphic to a class already known; returns
    /// whether it made a new class.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::Gluing;
    /// use topomech::ambiguity::finder::{Candidate, Finder, Origin};
    ///
    /// let mut finder = Finder::<2>::new();
    /// let mut add = |g: Gluing| finder.add(Candidate { map: g.build().unwrap(), origin: Origin::Gluing(g) });
    /// assert!(add(Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] }));
    /// assert!(!add(Gluing { sides: vec![4], pairs: vec![[1, 3, 0], [0, 2, 0]] })); // isomorphic
    /// assert!(!add(Gluing { sides: vec![3, 3], pairs: vec![] })); // disconnected
    /// ```
    pub fn add(&mut self, candidate: Candidate<N>) -> bool {
        self.tried += 1;
        if candidate.map.dart_count() == 0 || candidate.map.components().len() != 1 {
            return false;
        }
        let key = MapKey::of(&candidate.map);
        let bucket = self.by_key.entry(key).or_default();
        if bucket.iter().any(|&c| self.classes[c].map.is_isomorphic(&candidate.map)) {
            return false;
        }
        bucket.push(self.classes.len());
        self.classes.push(candidate);
        true
    }

    /// The classes found, in order of discovery.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::finder::surfaces;
    ///
    /// let finder = surfaces(2, 2);
    /// let classes = finder.classes();
    /// assert!(!classes.is_empty() && classes.len() < finder.tried());
    /// assert!(classes.iter().all(|c| c.map.components().len() == 1));
    /// ```
    pub fn classes(&self) -> &[Candidate<N>] {
        &self.classes
    }

    /// Candidates offered so far (including duplicates and disconnected ones).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::{construct::gluings, finder::surfaces};
    ///
    /// // Every gluing builds here, so every one is offered.
    /// assert_eq!(surfaces(3, 3).tried(), gluings(3, 3).len());
    /// ```
    pub fn tried(&self) -> usize {
        self.tried
    }

    /// The groups of classes sharing a graph of `kind`, each with ≥ 2 classes, in order of their
    /// first class.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::Gluing;
    /// use topomech::ambiguity::finder::{Candidate, Finder, Origin};
    /// use topomech::graph::{GraphKind, Multiplicity};
    ///
    /// let mut finder = Finder::<2>::new();
    /// for same in [0, 1] {
    ///     let g = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, same]] }; // torus, Klein bottle
    ///     finder.add(Candidate { map: g.build().unwrap(), origin: Origin::Gluing(g) });
    /// }
    /// let groups = finder.groups(GraphKind::Incidence, Multiplicity::Match);
    /// assert_eq!(groups.len(), 1);
    /// assert_eq!(groups[0].classes, vec![0, 1]);
    /// ```
    pub fn groups(&self, kind: GraphKind, multiplicity: Multiplicity) -> Vec<Group> {
        let graphs: Vec<CellGraph> = self.classes.iter().map(|c| graph_of(&c.map, kind)).collect();
        let mut buckets: HashMap<GraphInvariant, Vec<Vec<usize>>> = HashMap::new();
        for (c, g) in graphs.iter().enumerate() {
            let groups = buckets.entry(GraphInvariant::of(g, multiplicity)).or_default();
            match groups.iter_mut().find(|grp| graphs_isomorphic(&graphs[grp[0]], g, multiplicity)) {
                Some(grp) => grp.push(c),
                None => groups.push(vec![c]),
            }
        }
        let mut out: Vec<Group> = buckets
            .into_values()
            .flatten()
            .filter(|grp| grp.len() >= 2)
            .map(|classes| Group { kind, multiplicity, classes })
            .collect();
        out.sort_by_key(|g| g.classes[0]);
        out
    }
}

/// The 2D search: every connected gluing of at most `max_sides` sides (polygons of at most
/// `max_polygon` sides), smallest first.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::finder::surfaces;
/// use topomech::graph::{GraphKind, Multiplicity};
///
/// let finder = surfaces(4, 4);
/// let groups = finder.groups(GraphKind::Incidence, Multiplicity::Match);
/// assert!(!groups.is_empty()); // e.g. the torus and the Klein bottle
/// let (a, b) = (&finder.classes()[groups[0].classes[0]], &finder.classes()[groups[0].classes[1]]);
/// assert!(!a.map.is_isomorphic(&b.map));
/// ```
pub fn surfaces(max_sides: usize, max_polygon: usize) -> Finder<2> {
    let mut gluings = crate::ambiguity::construct::gluings(max_sides, max_polygon);
    gluings.sort_by_key(|g| (g.side_count(), g.sides.len(), g.pairs.len()));
    let mut finder = Finder::new();
    for g in gluings {
        if let Ok(map) = g.build() {
            finder.add(Candidate { map, origin: Origin::Gluing(g) });
        }
    }
    finder
}

/// The 3D search: every connected complex of at most `max_tets` tets on `points` points with
/// every subset of its interior faces dissociated, then every gluing of the faces of at most
/// `glue_tets` tets with at most `glue_pairs` pairs; smallest first within each family.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::finder::complexes;
///
/// // Of the 9 complexes of at most 2 tets on 5 points, the cut pairs are disconnected and the
/// // glued pairs all isomorphic: two classes, one tet and two glued tets.
/// let finder = complexes(5, 2, 0, 0);
/// assert_eq!(finder.tried(), 9);
/// let volumes: Vec<usize> = finder.classes().iter().map(|c| c.map.count_cells().0[3]).collect();
/// assert_eq!(volumes, vec![1, 2]);
/// ```
pub fn complexes(points: usize, max_tets: usize, glue_tets: u8, glue_pairs: usize) -> Finder<3> {
    let mut all = crate::ambiguity::construct::cut_complexes(points, max_tets);
    all.sort_by_key(|c| (c.tets.len(), c.points, c.cuts.len()));
    let mut finder = Finder::new();
    for c in all {
        if let Ok(map) = c.build() {
            finder.add(Candidate { map, origin: Origin::Complex(c) });
        }
    }
    let mut glued = crate::ambiguity::construct::face_gluings(glue_tets, glue_pairs);
    glued.sort_by_key(|g| (g.tets, g.pairs.len()));
    for g in glued {
        if let Ok(map) = g.build() {
            finder.add(Candidate { map, origin: Origin::FaceGluing(g) });
        }
    }
    finder
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_square_gluings_contain_torus_and_klein_bottle_with_one_incidence_graph() {
        let finder = surfaces(4, 4);
        let groups = finder.groups(GraphKind::Incidence, Multiplicity::Match);
        let torus_klein = groups.iter().any(|g| {
            let maps: Vec<&GMap<2>> = g.classes.iter().map(|&c| &finder.classes()[c].map).collect();
            let closed_chi0 = |m: &GMap<2>| m.boundary_darts().count() == 0 && m.euler_characteristic() == 0;
            maps.iter().any(|m| closed_chi0(m) && m.is_orientable())
                && maps.iter().any(|m| closed_chi0(m) && !m.is_orientable())
        });
        assert!(torus_klein, "torus and Klein bottle share an incidence graph");
        for g in &groups {
            let (a, b) = (&finder.classes()[g.classes[0]].map, &finder.classes()[g.classes[1]].map);
            assert!(!a.is_isomorphic(b));
        }
    }
}

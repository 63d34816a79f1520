//! The catalogue: runs the exhaustive finder in 2D and 3D and picks, for every graph studied and
//! every reason two maps can differ ([`Why`]), the first (hence smallest) pair found, as a
//! [`PairVector`]. Also turns campaign findings into shrunk vectors.

use crate::ambiguity::campaign::{shrink, Run, Symptom};
use crate::ambiguity::construct::CutComplex;
use crate::ambiguity::finder::{complexes, surfaces, Candidate, Finder, Origin, Why};
use crate::ambiguity::vector::{IndexedVector, PairVector, VectorError};
use crate::graph::{GraphKind, Multiplicity};

/// The graphs studied, with the multiplicity rule: the three adjacency graphs as an indexed mesh
/// stores them, and the incidence graph with multiplicities.
pub const STUDIED: [(GraphKind, Multiplicity); 4] = [
    (GraphKind::VertexEdge, Multiplicity::Ignore),
    (GraphKind::Dual, Multiplicity::Ignore),
    (GraphKind::Incidence, Multiplicity::Ignore),
    (GraphKind::Incidence, Multiplicity::Match),
];

/// Bounds of the exhaustive search.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::catalogue::Bounds;
/// let (s, c) = (Bounds::SMALL, Bounds::CATALOGUE);
/// assert!(s.max_sides <= c.max_sides && s.points <= c.points && s.max_tets <= c.max_tets);
/// assert!(s.glue_tets <= c.glue_tets);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Bounds {
    /// 2D: most sides in total.
    pub max_sides: usize,
    /// 2D: most sides of one polygon.
    pub max_polygon: usize,
    /// 3D: points available.
    pub points: usize,
    /// 3D: most tets.
    pub max_tets: usize,
    /// 3D face gluings: most tets.
    pub glue_tets: u8,
    /// 3D face gluings: most glued pairs.
    pub glue_pairs: usize,
}

impl Bounds {
    /// Small bounds for the test suite (well under a second in release).
    pub const SMALL: Bounds =
        Bounds { max_sides: 4, max_polygon: 4, points: 5, max_tets: 3, glue_tets: 1, glue_pairs: 2 };
    /// The bounds the catalogue of `docs/ambiguity.md` was made with.
    pub const CATALOGUE: Bounds =
        Bounds { max_sides: 6, max_polygon: 4, points: 6, max_tets: 4, glue_tets: 2, glue_pairs: 2 };
}

/// How many ambiguities one graph has in one dimension.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::catalogue::{catalogue, Bounds};
/// let cat = catalogue(Bounds::SMALL);
/// assert!(cat.counts.iter().all(|c| c.dim == 2 || c.dim == 3));
/// assert!(cat.counts.iter().all(|c| c.ambiguous_classes <= c.classes));
/// assert!(cat.counts.iter().any(|c| c.groups > 0));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct GroupCount {
    /// 2 or 3.
    pub dim: usize,
    /// The graph.
    pub graph_kind: GraphKind,
    /// The multiplicity rule.
    pub multiplicity: Multiplicity,
    /// Map classes searched.
    pub classes: usize,
    /// Groups of ≥ 2 non-isomorphic classes sharing one graph.
    pub groups: usize,
    /// Classes that share their graph with another class.
    pub ambiguous_classes: usize,
}

/// The result of the exhaustive search.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::catalogue::{catalogue, Bounds};
/// let cat = catalogue(Bounds::SMALL);
/// assert_eq!(cat.bounds, Bounds::SMALL);
/// assert!(cat.tried.iter().all(|&n| n > 0));
/// assert!(cat.pairs.iter().all(|p| p.check().is_ok()));
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Catalogue {
    /// The bounds used.
    pub bounds: Bounds,
    /// Candidates tried in 2D and 3D.
    pub tried: [usize; 2],
    /// Counts per dimension and graph.
    pub counts: Vec<GroupCount>,
    /// The first pair for every (dimension, graph, reason).
    pub pairs: Vec<PairVector>,
}

/// Runs the exhaustive search within `bounds`. O(enumeration · (darts² + VF2)).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::catalogue::{catalogue, Bounds};
///
/// let cat = catalogue(Bounds::SMALL);
/// assert!(cat.tried[0] > 0 && cat.tried[1] > 0);
/// assert!(!cat.pairs.is_empty());
/// assert!(cat.pairs.iter().all(|p| p.check().is_ok()));
/// assert!(cat.counts.iter().all(|c| c.ambiguous_classes >= 2 * c.groups));
/// ```
pub fn catalogue(bounds: Bounds) -> Catalogue {
    let f2 = surfaces(bounds.max_sides, bounds.max_polygon);
    let f3 = complexes(bounds.points, bounds.max_tets, bounds.glue_tets, bounds.glue_pairs);
    let mut counts = Vec::new();
    let mut pairs = Vec::new();
    collect(&f2, &mut counts, &mut pairs);
    collect(&f3, &mut counts, &mut pairs);
    Catalogue { bounds, tried: [f2.tried(), f3.tried()], counts, pairs }
}

fn collect<const N: usize>(finder: &Finder<N>, counts: &mut Vec<GroupCount>, pairs: &mut Vec<PairVector>) {
    let classes = finder.classes();
    for (kind, multiplicity) in STUDIED {
        let groups = finder.groups(kind, multiplicity);
        counts.push(GroupCount {
            dim: N,
            graph_kind: kind,
            multiplicity,
            classes: classes.len(),
            groups: groups.len(),
            ambiguous_classes: groups.iter().map(|g| g.classes.len()).sum(),
        });
        let mut seen: Vec<Why> = Vec::new();
        for g in &groups {
            for (i, &ci) in g.classes.iter().enumerate() {
                for &cj in &g.classes[i + 1..] {
                    let (a, b) = (&classes[ci], &classes[cj]);
                    let why = Why::of(&a.map, &b.map);
                    if seen.contains(&why) {
                        continue;
                    }
                    seen.push(why);
                    let name = format!("ambiguity_{N}d_{}_{}_{}", kind.name(), mult_name(multiplicity), why_name(why));
                    pairs.push(PairVector::of(&name, kind, multiplicity, a, b, &describe(a, b)));
                }
            }
        }
    }
}

fn mult_name(m: Multiplicity) -> &'static str {
    match m {
        Multiplicity::Ignore => "simple",
        Multiplicity::Match => "multi",
    }
}

/// The snake-case name of a reason.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{catalogue::why_name, finder::Why};
///
/// assert_eq!(why_name(Why::VertexIdentification), "vertex_identification");
/// assert_eq!(why_name(Why::Gluing), "gluing");
/// ```
pub fn why_name(w: Why) -> &'static str {
    match w {
        Why::Orientation => "orientation",
        Why::VertexIdentification => "vertex_identification",
        Why::CellIdentification => "cell_identification",
        Why::Boundary => "boundary",
        Why::Gluing => "gluing",
    }
}

/// One line naming both constructions.
fn describe<const N: usize>(a: &Candidate<N>, b: &Candidate<N>) -> String {
    format!("{} vs {}", origin_text(&a.origin), origin_text(&b.origin))
}

/// A construction in one line: a gluing word ([`crate::ambiguity::construct::Gluing::word`]:
/// `?` for a gluing that names a side past the last one, never a panic), or tets and cuts.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::catalogue::origin_text;
/// use topomech::ambiguity::construct::{CutComplex, Gluing};
/// use topomech::ambiguity::finder::Origin;
///
/// let torus = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] };
/// assert_eq!(origin_text(&Origin::Gluing(torus)), "(a b a' b')");
/// let bad = Gluing { sides: vec![2], pairs: vec![[0, 5, 0]] }; // `build` refuses side 5 of 2
/// assert_eq!(origin_text(&Origin::Gluing(bad)), "?");
/// let tet = CutComplex { points: 4, tets: vec![[0, 1, 2, 3]], cuts: vec![] };
/// assert_eq!(origin_text(&Origin::Complex(tet)), "tets [[0, 1, 2, 3]] cut []");
/// ```
pub fn origin_text(o: &Origin) -> String {
    match o {
        Origin::Gluing(g) => g.word(),
        Origin::Complex(c) => format!("tets {:?} cut {:?}", c.tets, c.cuts),
        Origin::FaceGluing(g) => format!("{} tet(s), faces glued {:?}", g.tets, g.pairs),
    }
}

/// The vectors of a campaign's first runs: for each symptom shown, the run shrunk to a 1-minimal
/// complex; for the skeleton symptom also the pair (uncut map, cut map) sharing their vertex–edge
/// graph. `budget` bounds the tests of each ddmin.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::campaign_k, catalogue::campaign_vectors};
/// use topomech::generate::{self, SplitMix64};
///
/// let (points, tets) = generate::kuhn_cube(2);
/// let (_, firsts) = campaign_k(points.len(), &tets, 3, 20, &mut SplitMix64(7)).unwrap();
/// let (indexed, pairs) = campaign_vectors(points.len(), &tets, &firsts, 200).unwrap();
/// assert!(!indexed.is_empty());
/// assert!(indexed.iter().all(|v| v.check().is_ok() && v.complex.tets.len() < tets.len()));
/// assert!(pairs.iter().all(|p| p.check().is_ok()));
/// ```
pub fn campaign_vectors(
    points: usize,
    tets: &[[u32; 4]],
    firsts: &[Run],
    budget: usize,
) -> Result<(Vec<IndexedVector>, Vec<PairVector>), VectorError> {
    let mut indexed = Vec::new();
    let mut pairs = Vec::new();
    for symptom in Symptom::ALL {
        let Some(run) = firsts.iter().find(|r| r.symptoms().contains(&symptom)) else { continue };
        let big = CutComplex { points, tets: tets.to_vec(), cuts: run.cuts.clone() };
        let small = shrink(&big, symptom, budget);
        let name = format!("ambiguity_campaign_{}", symptom_name(symptom));
        let text = format!(
            "shrunk from {} cuts on {} tets: tets {:?} cut {:?}",
            run.cuts.len(),
            tets.len(),
            small.tets,
            small.cuts
        );
        if symptom == Symptom::SkeletonUnchanged {
            let uncut = CutComplex { cuts: Vec::new(), ..small.clone() };
            let (a, b) = (candidate(&uncut, &name)?, candidate(&small, &name)?);
            pairs.push(PairVector::of(&name, GraphKind::VertexEdge, Multiplicity::Ignore, &a, &b, &text));
        } else {
            indexed.push(IndexedVector::of(&name, symptom, &small, &text)?);
        }
    }
    Ok((indexed, pairs))
}

fn candidate(c: &CutComplex, name: &str) -> Result<Candidate<3>, VectorError> {
    let map = c.build().map_err(|e| VectorError::Construction {
        name: name.to_string(),
        which: "a",
        message: e.to_string(),
    })?;
    Ok(Candidate { map, origin: Origin::Complex(c.clone()) })
}

/// The snake-case name of a symptom.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{campaign::Symptom, catalogue::symptom_name};
///
/// assert_eq!(symptom_name(Symptom::FaceStillShared), "face_still_shared");
/// assert!(Symptom::ALL.iter().all(|&s| !symptom_name(s).contains(' ')));
/// ```
pub fn symptom_name(s: Symptom) -> &'static str {
    match s {
        Symptom::FaceStillShared => "face_still_shared",
        Symptom::PinchedPoint => "pinched_point",
        Symptom::NonManifoldEdge => "non_manifold_edge",
        Symptom::GluingDiffers => "gluing_differs",
        Symptom::SkeletonUnchanged => "skeleton_unchanged",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_small_catalogue_replays() {
        let cat = catalogue(Bounds::SMALL);
        assert!(!cat.pairs.is_empty());
        for p in &cat.pairs {
            p.check().unwrap_or_else(|e| panic!("{e}"));
        }
        assert!(cat.counts.iter().all(|c| c.ambiguous_classes >= 2 * c.groups));
    }

    /// Every pair's description names both constructions, that of `a` then that of `b`.
    #[test]
    fn every_catalogue_description_names_both_constructions() {
        let pairs = catalogue(Bounds::SMALL).pairs;
        assert!(!pairs.is_empty());
        for p in pairs {
            let (a, b) = (origin_text(&p.a.origin), origin_text(&p.b.origin));
            assert_eq!(p.description, format!("{a} vs {b}"), "{}", p.name);
        }
    }
}

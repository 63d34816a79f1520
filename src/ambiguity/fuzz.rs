//! The comparison driven by arbitrary bytes: the body of the cargo-fuzz target
//! `fuzz/fuzz_targets/ambiguity.rs` and of the corpus replay test.
//!
//! Decoding: byte 0 picks the mesh (Kuhn cube k = 1 or 2, or the ring of three tets around an
//! edge); every following byte picks one still-glued interior face (index modulo their number) and
//! cuts it on both models. At most [`MAX_CUTS`] cuts; empty input does nothing.
//!
//! Invariants checked (each failure is a bug in topomech, reported as a [`FuzzFailure`]):
//! 1. the g-map passes `validate()` after every cut and its cell counts from ids equal those from
//!    traversal;
//! 2. the g-map and its dart round trip are isomorphic, and so are their incidence graphs (with
//!    multiplicities): isomorphic maps have isomorphic graphs;
//! 3. when the indexed model's tet list glues the faces the g-map glues, the map it means is
//!    isomorphic to the g-map, and then their incidence graphs are isomorphic too;
//! 4. when no cut split a vertex or an edge, the cut and uncut g-maps have isomorphic vertex–edge
//!    graphs, and (after at least one cut) are not isomorphic. The converse of 2 may fail: that
//!    is the ambiguity this module studies, not a bug.

use crate::ambiguity::campaign::run_cuts;
use crate::ambiguity::construct::glued_faces;
use crate::ambiguity::darts::DartsJson;
use crate::gmap::GMap;
use crate::graph::{graph_of, graphs_isomorphic, GraphKind, Multiplicity};

/// Most cuts decoded from one input.
pub const MAX_CUTS: usize = 64;

/// An invariant of the [module docs](self) that failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FuzzFailure {
    /// Invariant 1.
    #[error("after cut {cut}: the g-map is invalid or its cell counts disagree: {detail}")]
    Invalid {
        /// Index of the cut.
        cut: usize,
        /// What failed.
        detail: String,
    },
    /// Invariant 2.
    #[error("after cut {cut}: isomorphic maps with non-isomorphic {kind} graphs")]
    IsoWithoutGraphIso {
        /// Index of the cut.
        cut: usize,
        /// The graph.
        kind: GraphKind,
    },
    /// Invariant 3.
    #[error("the indexed model glues like the g-map but means a non-isomorphic map")]
    SameGluingNotIsomorphic,
    /// Invariant 4.
    #[error("no vertex or edge split, yet the vertex-edge graphs differ or the maps are isomorphic")]
    Skeleton,
    /// A step that cannot fail on these meshes failed.
    #[error("unexpected error: {0}")]
    Unexpected(String),
}

/// What one input did.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct FuzzReport {
    /// Cuts made.
    pub cuts: usize,
    /// Whether the indexed model ended ambiguous.
    pub ambiguous: bool,
    /// Whether the cut and uncut maps share their vertex–edge graph.
    pub skeleton_unchanged: bool,
}

/// The mesh byte 0 selects: (points, tets).
fn mesh(selector: u8) -> (usize, Vec<[u32; 4]>) {
    match selector % 3 {
        0 => {
            let (p, t) = crate::generate::kuhn_cube(1);
            (p.len(), t)
        }
        1 => {
            let (p, t) = crate::generate::kuhn_cube(2);
            (p.len(), t)
        }
        _ => (5, vec![[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]]),
    }
}

/// Decodes `bytes` and checks the invariants. O(cuts · darts · n²) plus one VF2 per check.
pub fn check_bytes(bytes: &[u8]) -> Result<FuzzReport, FuzzFailure> {
    let Some((&selector, rest)) = bytes.split_first() else { return Ok(FuzzReport::default()) };
    let (points, tets) = mesh(selector);
    let unexpected = |e: &dyn std::fmt::Display| FuzzFailure::Unexpected(e.to_string());
    let (fresh, _) = GMap::<3>::from_tets(points, &tets).map_err(|e| unexpected(&e))?;
    let mut gmap = fresh.clone();
    let mut cuts = Vec::new();
    for (k, &b) in rest.iter().take(MAX_CUTS).enumerate() {
        let faces = glued_faces(&gmap);
        let Some(&[t1, t2]) = faces.get(b as usize % faces.len().max(1)) else { break };
        let d = crate::ambiguity::construct::shared_face_dart(&gmap, t1, t2)
            .ok_or_else(|| FuzzFailure::Unexpected(format!("face {t1}-{t2} listed but not found")))?;
        gmap.unsew::<3>(d).map_err(|e| unexpected(&e))?;
        cuts.push([t1, t2]);
        check_valid(&gmap, k)?;
    }
    check_round_trip(&gmap, cuts.len())?;
    let run = run_cuts(points, &tets, &cuts).map_err(|e| unexpected(&e))?;
    if !run.audit.gluing_differs {
        let (n, cut_tets) = indexed_tets(points, &tets, &cuts)?;
        let (rebuilt, _) = GMap::<3>::from_tets(n, &cut_tets).map_err(|e| unexpected(&e))?;
        if !rebuilt.is_isomorphic(&gmap) {
            return Err(FuzzFailure::SameGluingNotIsomorphic);
        }
        same_graphs(&rebuilt, &gmap, cuts.len(), GraphKind::Incidence)?;
    }
    if run.skeleton_unchanged {
        let same_skeleton = graphs_isomorphic(
            &graph_of(&fresh, GraphKind::VertexEdge),
            &graph_of(&gmap, GraphKind::VertexEdge),
            Multiplicity::Ignore,
        );
        if !same_skeleton || (!cuts.is_empty() && fresh.is_isomorphic(&gmap)) {
            return Err(FuzzFailure::Skeleton);
        }
    }
    Ok(FuzzReport { cuts: cuts.len(), ambiguous: run.audit.ambiguous(), skeleton_unchanged: run.skeleton_unchanged })
}

/// The indexed model's points and tets after the cuts.
fn indexed_tets(points: usize, tets: &[[u32; 4]], cuts: &[[u32; 2]]) -> Result<(usize, Vec<[u32; 4]>), FuzzFailure> {
    let mut model = crate::ambiguity::indexed::IndexedModel::new(points, tets);
    for &[a, b] in cuts {
        model.cut(a, b).map_err(|e| FuzzFailure::Unexpected(e.to_string()))?;
    }
    Ok((model.points, model.tets))
}

fn check_valid(gmap: &GMap<3>, cut: usize) -> Result<(), FuzzFailure> {
    if let Err(e) = gmap.validate() {
        return Err(FuzzFailure::Invalid { cut, detail: e.to_string() });
    }
    if gmap.count_cells() != gmap.count_cells_by_traversal() {
        return Err(FuzzFailure::Invalid { cut, detail: "cell counts by id and by traversal differ".into() });
    }
    Ok(())
}

fn check_round_trip(gmap: &GMap<3>, cut: usize) -> Result<(), FuzzFailure> {
    let copy: GMap<3> = DartsJson::of(gmap).to_map().map_err(|e| FuzzFailure::Unexpected(e.to_string()))?;
    if !copy.is_isomorphic(gmap) {
        return Err(FuzzFailure::Invalid { cut, detail: "the dart round trip is not isomorphic".into() });
    }
    same_graphs(&copy, gmap, cut, GraphKind::Incidence)
}

fn same_graphs(a: &GMap<3>, b: &GMap<3>, cut: usize, kind: GraphKind) -> Result<(), FuzzFailure> {
    if graphs_isomorphic(&graph_of(a, kind), &graph_of(b, kind), Multiplicity::Match) {
        Ok(())
    } else {
        Err(FuzzFailure::IsoWithoutGraphIso { cut, kind })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_and_short_inputs_pass() {
        assert_eq!(check_bytes(&[]), Ok(FuzzReport::default()));
        let r = check_bytes(&[2, 0]).expect("invariants hold");
        assert_eq!(r.cuts, 1);
        let r = check_bytes(&[1, 5, 9, 200, 3]).expect("invariants hold");
        assert_eq!(r.cuts, 4);
    }
}

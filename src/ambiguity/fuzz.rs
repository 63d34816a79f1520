//! The comparison driven by arbitrary bytes: the body of the cargo-fuzz target
//! `fuzz/fuzz_targets/ambiguity.rs` and of the corpus replay test.
//!
//! Decoding: byte 0 picks the mesh (`byte0 % 3`: Kuhn cube k = 1 or 2, or the ring of three tets
//! around an edge) and the mode. Empty input does nothing.
//! - *Cut mode* (byte 0 < [`MIXED`]; the corpus files of before the mixed mode all are): every
//!   following byte picks one still-glued interior face (index modulo their number) and cuts it on
//!   both models. At most [`MAX_CUTS`] cuts.
//! - *Mixed mode* (byte 0 ≥ [`MIXED`]): every following byte is an [`Op`] ([`decode_ops`]):
//!   b < 192 cuts glued face b, b ≥ 192 subdivides tet b − 192 (indices modulo the current
//!   count), run by [`run_ops`] on the leveled g-map and the refined indexed model. At most
//!   [`MAX_CUTS`] ops, of which at most [`MAX_SUBDIVISIONS`] subdivisions (later ones are dropped).
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
//!
//! In mixed mode: 1'. the leveled map passes `check_all` (finest map and every level valid,
//! μt ≤ μf ≤ μa); 4'. invariant 4 for every cut that splits no vertex or edge (the maps before
//! and after it); 5. the level law of [`crate::ambiguity::mixed`] holds (G_i is the finest map as
//! it was when level i ended); 6. when the tet list shows none of the symptoms (no hanging edge,
//! no inexpressible or lost cut, no pinched point or non-manifold edge, as many points as g-map
//! vertices), the map it means is the g-map, through the tet ↔ volume pairing; 7. the vertex
//! masses lumped from density 1 keep the input's first moment Σ_v m_v x_v = ∫ x dV (finding
//! 335: a cut through a hanging midpoint lumped its copy as a corner).

use crate::ambiguity::campaign::run_cuts;
use crate::ambiguity::construct::glued_faces;
use crate::ambiguity::darts::DartsJson;
use crate::ambiguity::mixed::{run_ops, Op};
use crate::gmap::GMap;
use crate::graph::{graph_of, graphs_isomorphic, GraphKind, Multiplicity};

/// Most cuts (or ops, in mixed mode) decoded from one input.
pub const MAX_CUTS: usize = 64;

/// Byte 0 at or above this selects the mixed mode.
pub const MIXED: u8 = 128;

/// Most subdivisions decoded from one input in mixed mode.
pub const MAX_SUBDIVISIONS: usize = 12;

/// The ops of the mixed mode (bytes after byte 0): b < 192 is `Op::Cut(b)`, b ≥ 192 is
/// `Op::Subdivide(b − 192)`. At most [`MAX_CUTS`] ops; subdivisions past [`MAX_SUBDIVISIONS`]
/// are dropped. O(bytes).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{fuzz::decode_ops, mixed::Op};
///
/// assert_eq!(decode_ops(&[5, 191, 192, 255]), vec![Op::Cut(5), Op::Cut(191), Op::Subdivide(0), Op::Subdivide(63)]);
/// assert_eq!(decode_ops(&[200; 20]).len(), 12); // at most MAX_SUBDIVISIONS subdivisions
/// ```
pub fn decode_ops(bytes: &[u8]) -> Vec<Op> {
    let mut subdivisions = 0;
    let mut ops = Vec::new();
    for &b in bytes.iter().take(MAX_CUTS) {
        if b < 192 {
            ops.push(Op::Cut(u32::from(b)));
        } else if subdivisions < MAX_SUBDIVISIONS {
            subdivisions += 1;
            ops.push(Op::Subdivide(u32::from(b - 192)));
        }
    }
    ops
}

/// The byte encoding of `ops` for the mixed mode on mesh `mesh` (0, 1 or 2), inverse of
/// [`decode_ops`] for ops with small indices (cut indices are reduced modulo 192, subdivision
/// indices modulo 64). O(ops).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::fuzz::{decode_ops, encode_ops, MIXED};
/// use topomech::ambiguity::mixed::Op;
///
/// let ops = [Op::Cut(7), Op::Subdivide(2)];
/// let bytes = encode_ops(2, &ops);
/// assert_eq!(bytes, vec![MIXED + 2, 7, 194]);
/// assert_eq!(decode_ops(&bytes[1..]), ops);
/// ```
pub fn encode_ops(mesh: u8, ops: &[Op]) -> Vec<u8> {
    let body = ops.iter().map(|op| match *op {
        Op::Cut(i) => (i % 192) as u8,
        Op::Subdivide(i) => 192 + (i % 64) as u8,
    });
    std::iter::once(MIXED + mesh % 3).chain(body).collect()
}
/// An invariant of the [module docs](self) that failed.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::fuzz::{check_bytes, FuzzFailure};
/// // The invariants hold on every input tried here: no failure.
/// assert!((0..4u8).all(|b| check_bytes(&[b, 1, 2]).is_ok()));
/// let f = FuzzFailure::Invalid { cut: 2, detail: "α3 not an involution".into() };
/// assert!(f.to_string().contains("after cut 2"));
/// ```
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
    /// Invariant 5 (mixed mode).
    #[error("a level of the leveled map is not the finest map as it was when that level ended")]
    LevelLaw,
    /// Invariant 6 (mixed mode).
    #[error("the tet list shows no symptom yet means another map than the g-map")]
    CleanButDifferent,
    /// Invariant 7 (mixed mode).
    #[error("the lumped vertex masses moved the first moment of the input")]
    FirstMoment,
    /// A step that cannot fail on these meshes failed.
    #[error("unexpected error: {0}")]
    Unexpected(String),
}

/// What one input did.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::fuzz::check_bytes;
/// let r = check_bytes(&[0, 0, 0, 0]).unwrap(); // three cuts on the Kuhn cube
/// assert_eq!((r.cuts, r.subdivisions), (3, 0));
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct FuzzReport {
    /// Cuts made.
    pub cuts: usize,
    /// Subdivisions made (mixed mode).
    pub subdivisions: usize,
    /// Whether the indexed model ended ambiguous.
    pub ambiguous: bool,
    /// Whether the cut and uncut maps share their vertex–edge graph.
    pub skeleton_unchanged: bool,
}

/// The mesh byte 0 selects: (point positions, tets).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::fuzz::mesh;
///
/// assert_eq!(mesh(0).1.len(), 6); // Kuhn cube, k = 1
/// assert_eq!(mesh(1).1.len(), 48); // Kuhn cube, k = 2
/// let (points, tets) = mesh(2); // three tets around the edge (0, 1)
/// assert_eq!((points.len(), tets.len()), (5, 3));
/// assert_eq!(mesh(3), mesh(0));
/// ```
pub fn mesh(selector: u8) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    match selector % 3 {
        0 => crate::generate::kuhn_cube(1),
        1 => crate::generate::kuhn_cube(2),
        _ => {
            let ring = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.5], [-0.5, 0.87, 0.5], [-0.5, -0.87, 0.5]];
            (ring.to_vec(), vec![[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]])
        }
    }
}

/// Decodes `bytes` and checks the invariants. O(cuts · darts · n²) plus one VF2 per check.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::fuzz::{check_bytes, encode_ops, FuzzReport};
/// use topomech::ambiguity::mixed::Op;
///
/// assert_eq!(check_bytes(&[]), Ok(FuzzReport::default()));
/// assert_eq!(check_bytes(&[0, 3, 1]).unwrap().cuts, 2); // two cuts on the Kuhn cube
/// let mixed = check_bytes(&encode_ops(0, &[Op::Subdivide(0), Op::Cut(4)])).unwrap();
/// assert_eq!((mixed.subdivisions, mixed.cuts), (1, 1));
/// assert!(mixed.ambiguous); // a refined tet next to unrefined ones: hanging edges
/// ```
pub fn check_bytes(bytes: &[u8]) -> Result<FuzzReport, FuzzFailure> {
    let Some((&selector, rest)) = bytes.split_first() else { return Ok(FuzzReport::default()) };
    if selector >= MIXED {
        return check_mixed(selector, rest);
    }
    let (positions, tets) = mesh(selector);
    let points = positions.len();
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
    Ok(FuzzReport {
        cuts: cuts.len(),
        subdivisions: 0,
        ambiguous: run.audit.ambiguous(),
        skeleton_unchanged: run.skeleton_unchanged,
    })
}

/// The mixed mode: invariants 1', 4', 5, 6 and 7 of the [module docs](self).
fn check_mixed(selector: u8, rest: &[u8]) -> Result<FuzzReport, FuzzFailure> {
    let (points, tets) = mesh(selector);
    let ops = decode_ops(rest);
    let run = run_ops(&points, &tets, &ops).map_err(|e| FuzzFailure::Unexpected(e.to_string()))?;
    if !run.gmap_valid {
        return Err(FuzzFailure::Invalid { cut: ops.len(), detail: "the leveled map fails check_all".into() });
    }
    if !run.level_law {
        return Err(FuzzFailure::LevelLaw);
    }
    if !run.first_moment_kept {
        return Err(FuzzFailure::FirstMoment);
    }
    if run.skeleton_violations > 0 {
        return Err(FuzzFailure::Skeleton);
    }
    let clean = |c: &crate::ambiguity::mixed::Compare| {
        c.hanging_edges + c.pinched_points + c.non_manifold_edges == 0 && c.gmap_vertices == c.indexed_vertices
    };
    let cuts_fine = run.cuts_inexpressible + run.cuts_lost == 0;
    if cuts_fine && clean(&run.finest) && run.finest.map_differs {
        return Err(FuzzFailure::CleanButDifferent);
    }
    Ok(FuzzReport {
        cuts: run.cuts,
        subdivisions: run.subdivisions,
        ambiguous: run.ambiguous(),
        skeleton_unchanged: run.skeleton_cuts > 0,
    })
}

/// The indexed model's points and tets after the cuts.
fn indexed_tets(points: usize, tets: &[[u32; 4]], cuts: &[[u32; 2]]) -> Result<(usize, Vec<[u32; 4]>), FuzzFailure> {
    let mut model = crate::ambiguity::indexed::IndexedModel::new(points, tets)
        .map_err(|e| FuzzFailure::Unexpected(e.to_string()))?;
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

    /// Invariant 1 rejects a map that breaks a law: here α3 is no longer an involution.
    #[test]
    fn check_valid_rejects_a_broken_involution() {
        let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).expect("builds");
        assert_eq!(check_valid(&map, 0), Ok(()));
        let glued = map.darts().find(|&d| !map.is_free(3, d)).expect("a glued face");
        map.set_alpha_raw(3, glued, glued); // its partner still points to it
        assert!(matches!(check_valid(&map, 7), Err(FuzzFailure::Invalid { cut: 7, .. })));
    }

    #[test]
    fn mixed_inputs_decode_to_ops_and_back() {
        let ops = [Op::Cut(5), Op::Subdivide(3), Op::Cut(191), Op::Subdivide(63)];
        let bytes = encode_ops(1, &ops);
        assert_eq!(bytes[0], MIXED + 1);
        assert_eq!(decode_ops(&bytes[1..]), ops);
        let r = check_bytes(&bytes).expect("invariants hold");
        assert_eq!(r.cuts + r.subdivisions, 4);
        let many = decode_ops(&[255; 40]);
        assert_eq!(many.len(), MAX_SUBDIVISIONS);
    }
}

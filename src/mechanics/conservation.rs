//! `check_conservation`: the laws of [`model`](super::model) recomputed from the map's orbits.
//!
//! The check does not trust any stored mass or stiffness. It first requires a lawful material
//! (ρ > 0, E, β, ν ≥ 0, finite), and of each tet a positive finite rest volume and E_t = E (a
//! body is homogeneous). It covers the volumes of the map (a
//! traversal with a dart set, seed §4.2, independent of the kernel's cell ids for finding the
//! volumes) and, from each tetrahedron, scatters m_t/4 to its four vertices and E_t·V_t/L_e² to
//! its six edges, where L_e is measured again on the rest positions of the edge's two vertices.
//! This volume-centred scatter is a different computation from the vertex- and edge-centred
//! gathers the split rules use, so a wrong rule cannot hide behind itself. It then compares every
//! stored value with the recomputed one to a relative [`TOLERANCE`], and Σ_v m_v with Σ_t m_t.
//!
//! Cost: O(darts · log) time, O(cell ids) memory.

use crate::gmap::DartSet;
use crate::{AlphaMask, CellId, DartId, GMap};

use super::geom::{close, compensated_sum, CompensatedSum};
use super::model::{distinct, stiffness_contribution, Mechanics};

/// Relative tolerance of every conservation comparison.
pub const TOLERANCE: f64 = 1e-12;

/// A conservation law that does not hold, naming the cell.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{check_conservation, Body, ConservationError, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// // The same cube with its points numbered from 1 on (the last is 0): lawful on its own map,
/// // but its vertex i is another corner, so its masses do not fit the vertices of `body`'s map.
/// let n = points.len();
/// let shifted: Vec<_> = (0..n).map(|i| points[(i + n - 1) % n]).collect();
/// let tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(|v| (v + 1) % n as u32)).collect();
/// let (other, _) = Body::from_tets(&shifted, &tets, Material::default()).unwrap();
/// let err = check_conservation(body.map(), other.attrs()).unwrap_err();
/// assert!(matches!(err, ConservationError::VertexMass { .. }), "{err}");
/// assert!(check_conservation(other.map(), other.attrs()).is_ok());
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConservationError {
    /// m_v ≠ Σ_{t ∋ v} m_t / 4.
    #[error("vertex {} (e.g. {dart}): stored mass {stored} but its tets give {expected}", .vertex.0)]
    VertexMass {
        /// The vertex id.
        vertex: CellId,
        /// A dart of the vertex.
        dart: DartId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// γ_v ≠ ν · m_v.
    #[error("vertex {}: stored viscosity {stored} but ν·m gives {expected}", .vertex.0)]
    VertexViscosity {
        /// The vertex id.
        vertex: CellId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// L_e differs from the distance between the rest positions of its vertices.
    #[error("edge {} (e.g. {dart}): stored rest length {stored} but its vertices are {expected} apart", .edge.0)]
    RestLength {
        /// The edge id.
        edge: CellId,
        /// A dart of the edge.
        dart: DartId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// k_e ≠ Σ_{t ∋ e} E_t V_t / L_e².
    #[error("edge {} (e.g. {dart}): stored stiffness {stored} but its tets give {expected}", .edge.0)]
    EdgeStiffness {
        /// The edge id.
        edge: CellId,
        /// A dart of the edge.
        dart: DartId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// c_e ≠ β · k_e.
    #[error("edge {}: stored damping {stored} but β·k gives {expected}", .edge.0)]
    EdgeDamping {
        /// The edge id.
        edge: CellId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// m_t ≠ ρ · V_t.
    #[error("volume {}: stored mass {stored} but ρ·V gives {expected}", .tet.0)]
    TetMass {
        /// The volume id.
        tet: CellId,
        /// The stored value.
        stored: f64,
        /// The recomputed value.
        expected: f64,
    },
    /// A tet's rest volume V_t is not positive and finite (a tet is built from four points
    /// spanning a volume; its mass ρ·V_t and its springs' stiffnesses E·V_t/L² are its shares).
    #[error("volume {} (e.g. {dart}): rest volume {volume} is not positive and finite", .tet.0)]
    RestVolume {
        /// The volume id.
        tet: CellId,
        /// A dart of the volume.
        dart: DartId,
        /// The stored value.
        volume: f64,
    },
    /// A tet's Young's modulus E_t is not the material's E (a body is homogeneous: every tet's
    /// springs are computed from E_t = E; compared bit for bit).
    #[error("volume {}: Young's modulus {stored} but the material's E is {material}", .tet.0)]
    TetYoung {
        /// The volume id.
        tet: CellId,
        /// The stored value.
        stored: f64,
        /// The material's E.
        material: f64,
    },
    /// The material constants break their law ([`crate::mechanics::Material`]: ρ > 0, E, β,
    /// ν ≥ 0, all finite).
    #[error("material: {0}")]
    Material(crate::mechanics::ModelError),
    /// A dart given to a recomputation from the map is not live in that map.
    #[error("{0} is not a live dart of the map")]
    NoSuchDart(DartId),
    /// The attribute arrays of a dimension are shorter than the map's cell ids (the map changed
    /// without the embedding layer).
    #[error("{dim}-cell attributes cover {len} ids but the map uses {bound}")]
    MissingAttributes {
        /// Cell dimension.
        dim: usize,
        /// Slots in the attribute arrays.
        len: usize,
        /// The map's `cell_id_bound(dim)`.
        bound: usize,
    },
    /// Σ_v m_v ≠ Σ_t m_t.
    #[error("total vertex mass {vertices} differs from total tet mass {tets}")]
    TotalMass {
        /// Σ_v m_v.
        vertices: f64,
        /// Σ_t m_t.
        tets: f64,
    },
    /// A sew would merge two vertices that are apart at rest: the merged vertex has one rest
    /// position, so the rest lengths of the edges of one side would be wrong (the rest-length
    /// law). Raised before the sew ([`crate::embedding::CellRules::check_sew`]), which is then refused.
    #[error("sewing {dart} to {other} would merge vertex {} with vertex {}, {distance} apart at rest (only faces that coincide at rest can be sewn)", .vertex.0, .other_vertex.0)]
    SewApart {
        /// A dart of the sew.
        dart: DartId,
        /// The dart it would be linked with.
        other: DartId,
        /// The vertex of `dart`.
        vertex: CellId,
        /// The vertex of `other`.
        other_vertex: CellId,
        /// The distance between their rest positions.
        distance: f64,
    },
    /// A 0-unsew would leave an edge (a spring) with one vertex for both ends: a spring cannot
    /// lose an end, so no rest length or stiffness could follow it. Raised before the unsew
    /// ([`crate::embedding::CellRules::check_unsew`]), which is then refused; bodies are cut by
    /// dissociating faces (3-unsews), which split springs into parallel ones instead.
    #[error("0-unsewing {dart} would cut the spring of its edge {} into ends with no length (a body's edges cannot lose a vertex; cut by 3-unsews)", .edge.0)]
    UnsewEdge {
        /// The dart the unsew was called with.
        dart: DartId,
        /// Its edge.
        edge: CellId,
    },
    /// A 1- or 2-unsew would open a tetrahedron: it unlinks two darts of one volume, so it splits
    /// a vertex or an edge *inside* that volume (a tet with five vertices, each given m_t/4, breaks
    /// law 1; an edge split inside one tet gives both halves the tet's whole term of law 2, so the
    /// unsew creates stiffness). The model has laws for closed tetrahedra only. Raised before the
    /// unsew ([`crate::embedding::CellRules::check_unsew`]), which is then refused; bodies are cut
    /// by dissociating faces (3-unsews).
    #[error("{i}-unsewing {dart} would open the tetrahedron of volume {} (the mass/spring laws hold for closed tetrahedra only; cut by 3-unsews)", .volume.0)]
    UnsewOpensTet {
        /// The dart the unsew was called with.
        dart: DartId,
        /// The dimension of the unsew (1 or 2).
        i: usize,
        /// Its volume.
        volume: CellId,
    },
    /// An i-sew with i ≤ 2 would link darts by α0, α1 or α2, which stay inside one volume: it
    /// would join two volumes into one (a 1-sew of two tets makes a 7-vertex volume whose vertex
    /// masses no law covers) or change a tet's own cells. A body's volumes are closed tetrahedra,
    /// glued face to face by 3-sews only. Raised before the sew
    /// ([`crate::embedding::CellRules::check_sew`]), which is then refused.
    #[error("{i}-sewing {dart} to {other} would α{i}-link volume {} to volume {}: a body's tetrahedra are closed (their α0, α1, α2 links are fixed) and glued face to face by 3-sews only", .volume.0, .other_volume.0)]
    SewInsideVolume {
        /// A dart of the sew.
        dart: DartId,
        /// The dart it would be linked with.
        other: DartId,
        /// The dimension of the sew (0, 1 or 2).
        i: usize,
        /// The volume of `dart`.
        volume: CellId,
        /// The volume of `other`.
        other_volume: CellId,
    },
    /// A face's boundary flag is not whether the face is α3-free in the map
    /// ([`Mechanics::check_faces`]).
    #[error("face {} (e.g. {dart}) is flagged {} but is {} face of the map", .face.0,
        if *.flagged_boundary { "boundary" } else { "inner" }, if *.flagged_boundary { "an inner" } else { "a boundary" })]
    FaceFlag {
        /// The face id.
        face: CellId,
        /// A dart of the face.
        dart: DartId,
        /// The stored flag (the map says the opposite).
        flagged_boundary: bool,
    },
    /// An inner (α3-sewn) face has a nonzero normal ([`Mechanics::check_faces`]).
    #[error("inner face {} (e.g. {dart}) has the normal {normal:?}, not zero", .face.0)]
    InnerFaceNormal {
        /// The face id.
        face: CellId,
        /// A dart of the face.
        dart: DartId,
        /// The stored normal.
        normal: [f64; 3],
    },
}

/// What the volume-centred scatter recomputes.
struct Expected {
    vertex_mass: Vec<f64>,
    vertex_dart: Vec<Option<DartId>>,
    edge_stiffness: Vec<f64>,
    edge_dart: Vec<Option<DartId>>,
    edge_length: Vec<f64>,
    /// Σ of the masses of the tets met, compensated (finding 228).
    tet_mass_total: CompensatedSum,
}

/// Verifies laws 1–5 of [`model`](super::model) on every live cell of `map` (see the module
/// docs). O(darts · log).
///
/// # Errors
/// The first [`ConservationError`] found, vertices first, then edges, then the totals.
///
/// # Examples
///
/// ```
/// use topomech::cut::{incise_plane, Plane};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{check_conservation, Body, Material};
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// assert_eq!(check_conservation(body.map(), body.attrs()), Ok(()));
/// let plane = Plane { point: [1.0, 1.0, 1.0], normal: [0.0, 1.0, 0.0] };
/// incise_plane(&mut body, &plane).unwrap();
/// assert_eq!(body.map().components().len(), 2);
/// assert_eq!(check_conservation(body.map(), body.attrs()), Ok(())); // the laws hold after the cut too
/// ```
pub fn check_conservation(map: &GMap<3>, mech: &Mechanics) -> Result<(), ConservationError> {
    match conservation_violations(map, mech, 1).into_iter().next() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Every violation [`check_conservation`] would find, in the same order (tets while covering the
/// volumes, then vertices, then edges, then the totals), at most `limit` of them: what
/// `topomech check` lists. Its first element is exactly the error of [`check_conservation`].
/// O(darts · log) time, O(cell ids) memory.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{conservation_violations, Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// assert!(conservation_violations(body.map(), body.attrs(), usize::MAX).is_empty());
/// // The attributes of the same cube with its points numbered from 1 on break many laws here.
/// let n = points.len();
/// let shifted: Vec<_> = (0..n).map(|i| points[(i + n - 1) % n]).collect();
/// let tets: Vec<[u32; 4]> = tets.iter().map(|t| t.map(|v| (v + 1) % n as u32)).collect();
/// let (other, _) = Body::from_tets(&shifted, &tets, Material::default()).unwrap();
/// let all = conservation_violations(body.map(), other.attrs(), usize::MAX);
/// assert!(all.len() > 3, "{all:?}");
/// assert_eq!(conservation_violations(body.map(), other.attrs(), 3), all[..3].to_vec());
/// ```
pub fn conservation_violations(map: &GMap<3>, mech: &Mechanics, limit: usize) -> Vec<ConservationError> {
    let mut sink = Sink { out: Vec::new(), limit };
    if let Err(e) = mech.check_covers(map) {
        sink.push(e);
        return sink.out;
    }
    if let Err(e) = super::model::check_material(mech.material()) {
        sink.push(ConservationError::Material(e));
        return sink.out;
    }
    let exp = scatter_from_volumes(map, mech, &mut sink);
    check_vertices(mech, &exp, &mut sink);
    check_edges(mech, &exp, &mut sink);
    // Both totals compensated: plain sums of 10⁵ terms drift apart by more than 1e-12 on their
    // own (finding 228).
    let vertices = compensated_sum(
        exp.vertex_dart
            .iter()
            .enumerate()
            .filter(|(_, d)| d.is_some())
            .map(|(v, _)| mech.vertex_mass(CellId(v as u32))),
    );
    let tets = exp.tet_mass_total.value();
    if !close(vertices, tets, TOLERANCE) {
        sink.push(ConservationError::TotalMass { vertices, tets });
    }
    sink.out
}

/// The violations found so far, up to a limit.
struct Sink {
    out: Vec<ConservationError>,
    limit: usize,
}

impl Sink {
    fn push(&mut self, e: ConservationError) {
        if self.out.len() < self.limit {
            self.out.push(e);
        }
    }

    fn full(&self) -> bool {
        self.out.len() >= self.limit
    }
}

fn scatter_from_volumes(map: &GMap<3>, mech: &Mechanics, sink: &mut Sink) -> Expected {
    let mut exp = Expected {
        vertex_mass: vec![0.0; map.cell_id_bound(0)],
        vertex_dart: vec![None; map.cell_id_bound(0)],
        edge_stiffness: vec![0.0; map.cell_id_bound(1)],
        edge_dart: vec![None; map.cell_id_bound(1)],
        edge_length: vec![0.0; map.cell_id_bound(1)],
        tet_mass_total: CompensatedSum::default(),
    };
    let mut seen = DartSet::with_capacity(map.capacity());
    for d in map.darts() {
        if seen.contains(d) {
            continue;
        }
        let volume = map.orbit(d, AlphaMask::cell(3, 3));
        for &x in &volume {
            seen.insert(x);
        }
        scatter_one(map, mech, &volume, &mut exp, sink);
    }
    exp
}

/// Adds the contributions of the tet made of `darts` (one volume orbit).
fn scatter_one(map: &GMap<3>, mech: &Mechanics, darts: &[DartId], exp: &mut Expected, sink: &mut Sink) {
    let t = map.cell_id(3, darts[0]);
    let (mass, volume, young) = (mech.tet_mass(t), mech.tet_rest_volume(t), mech.tet_young(t));
    if !(volume.is_finite() && volume > 0.0) {
        sink.push(ConservationError::RestVolume { tet: t, dart: darts[0], volume });
    }
    if young.to_bits() != mech.material().young.to_bits() {
        sink.push(ConservationError::TetYoung { tet: t, stored: young, material: mech.material().young });
    }
    let expected = mech.material().density * volume;
    if !close(mass, expected, TOLERANCE) {
        sink.push(ConservationError::TetMass { tet: t, stored: mass, expected });
    }
    exp.tet_mass_total.add(mass);
    for v in distinct(darts.iter().map(|&x| map.vertex_id(x))) {
        exp.vertex_mass[v.index()] += mass / 4.0;
        let dart = darts.iter().copied().find(|&x| map.vertex_id(x) == v);
        exp.vertex_dart[v.index()] = dart;
    }
    for e in distinct(darts.iter().map(|&x| map.cell_id(1, x))) {
        let x = darts.iter().copied().find(|&x| map.cell_id(1, x) == e).expect("edge of this volume");
        let (a, b) = (mech.rest_position[map.vertex_id(x)], mech.rest_position[map.vertex_id(map.alpha::<0>(x))]);
        let length = super::geom::rest_length(a, b);
        // Law 2 reads the edge's stored rest length, as every rule that recomputes a stiffness
        // does; the stored length is checked against the rest positions on its own (finding 287:
        // a length stored within the tolerance of the distance, read from a file, made the next
        // recomputed stiffness fail a law measured on the distance).
        exp.edge_stiffness[e.index()] += stiffness_contribution(young, volume, mech.edge_rest_length(e));
        exp.edge_dart[e.index()] = Some(x);
        exp.edge_length[e.index()] = length;
    }
}

fn check_vertices(mech: &Mechanics, exp: &Expected, sink: &mut Sink) {
    let nu = mech.material().viscosity;
    for (v, dart) in exp.vertex_dart.iter().enumerate() {
        let Some(dart) = *dart else { continue };
        if sink.full() {
            return;
        }
        let vertex = CellId(v as u32);
        let (stored, expected) = (mech.vertex_mass(vertex), exp.vertex_mass[v]);
        if !close(stored, expected, TOLERANCE) {
            sink.push(ConservationError::VertexMass { vertex, dart, stored, expected });
        }
        let (stored, expected) = (mech.vertex_viscosity(vertex), nu * mech.vertex_mass(vertex));
        if !close(stored, expected, TOLERANCE) {
            sink.push(ConservationError::VertexViscosity { vertex, stored, expected });
        }
    }
}

fn check_edges(mech: &Mechanics, exp: &Expected, sink: &mut Sink) {
    let beta = mech.material().damping;
    for (e, dart) in exp.edge_dart.iter().enumerate() {
        let Some(dart) = *dart else { continue };
        if sink.full() {
            return;
        }
        let edge = CellId(e as u32);
        let (stored, expected) = (mech.edge_rest_length(edge), exp.edge_length[e]);
        if !close(stored, expected, TOLERANCE) {
            sink.push(ConservationError::RestLength { edge, dart, stored, expected });
        }
        let (stored, expected) = (mech.edge_stiffness(edge), exp.edge_stiffness[e]);
        if !close(stored, expected, TOLERANCE) {
            sink.push(ConservationError::EdgeStiffness { edge, dart, stored, expected });
        }
        let (stored, expected) = (mech.edge_damping(edge), beta * mech.edge_stiffness(edge));
        if !close(stored, expected, TOLERANCE) {
            sink.push(ConservationError::EdgeDamping { edge, stored, expected });
        }
    }
}

//! Face dissociation (volume separation, seed §3.2 and Appendix A).

use crate::gmap::CellChanges;
use crate::mechanics::{Body, TouchedCells};
use crate::{CellId, DartId};

use super::CutError;

/// One cell that a dissociation split in two: `kept` stays with the side of `dart_kept`, the
/// darts on the side of `dart_new` now carry the fresh id `new`.
///
/// # Examples
///
/// ```
/// use topomech::cut::dissociate_face;
/// use topomech::mechanics::{Body, Material};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// let (mut body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [0, 1, 2, 4]], Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// for s in dissociate_face(&mut body, d).unwrap().vertices {
///     assert_ne!(s.kept, s.new);
///     assert_eq!((body.map().vertex_id(s.dart_kept), body.map().vertex_id(s.dart_new)), (s.kept, s.new));
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SplitCell {
    /// Id of the side that kept it.
    pub kept: CellId,
    /// Fresh id of the other side.
    pub new: CellId,
    /// A dart of the kept side.
    pub dart_kept: DartId,
    /// A dart of the new side.
    pub dart_new: DartId,
}

/// What one face dissociation did.
///
/// # Examples
///
/// ```
/// use topomech::cut::dissociate_face;
/// use topomech::mechanics::{Body, Material};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// let (mut body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [0, 1, 2, 4]], Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// let cut = dissociate_face(&mut body, d).unwrap();
/// assert_eq!(cut.dart, d);
/// assert!(body.map().is_free(3, cut.dart) && body.map().is_free(3, cut.opposite));
/// assert_ne!(cut.faces.0, cut.faces.1);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Dissociation {
    /// The dart the face was named by.
    pub dart: DartId,
    /// Its former α3 image (now on the other, separate face).
    pub opposite: DartId,
    /// The face ids after the operation: (side of `dart`, side of `opposite`).
    pub faces: (CellId, CellId),
    /// Vertices of the face that dissociated (their two sides no longer share a vertex orbit).
    pub vertices: Vec<SplitCell>,
    /// Edges of the face that dissociated.
    pub edges: Vec<SplitCell>,
    /// Vertex and edge ids whose projected values changed (for `Projection::update`).
    pub touched: TouchedCells,
}

/// Dissociates the face of `d` from the face it is α3-sewn to: α3-unsews the six (for a
/// triangle) darts of the face with the six of the other side ([`Body::unsew3`]); every vertex and
/// edge of the face whose two sides no longer share an orbit is dissociated, the new side gets a
/// fresh id with a copy of position and velocity, and both sides get masses and stiffnesses
/// recomputed from the tets now around them (m = m1 + m2, k = k1 + k2).
///
/// Cost: O(face + split cells' orbits) — the kernel's unsew walks both sides of each cell it might
/// split in lockstep, and the rules recompute each split cell from its orbit. For an inner face
/// whose vertices and edges do not split, that is the three rings of tets around its edges (the
/// kernel's proof that nothing split) and two O(1) face normals.
///
/// # Errors
/// [`CutError::NoSuchDart`], [`CutError::BoundaryFace`] (body unchanged); [`CutError::Body`] if the
/// embedding layer's check fails (a bug, `expensive-checks` only).
///
/// # Examples
///
/// ```
/// use topomech::cut::{components, dissociate_face, CutError};
/// use topomech::mechanics::{check_conservation, Body, Material};
///
/// // Two tets glued along the face {0, 1, 2}.
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// let (mut body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [0, 1, 2, 4]], Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// let cut = dissociate_face(&mut body, d).unwrap();
/// assert_eq!((cut.vertices.len(), cut.edges.len()), (3, 3)); // nothing else holds the tets together
/// assert_eq!(components(&body).len(), 2);
/// check_conservation(body.map(), body.attrs()).unwrap();
/// assert!(matches!(dissociate_face(&mut body, d), Err(CutError::BoundaryFace { .. })));
/// ```
pub fn dissociate_face(body: &mut Body, d: DartId) -> Result<Dissociation, CutError> {
    let map = body.map();
    if !map.contains(d) {
        return Err(CutError::NoSuchDart(d));
    }
    if map.is_free(3, d) {
        return Err(CutError::BoundaryFace { face: map.cell_id(2, d), dart: d });
    }
    let (opposite, from) = (map.alpha::<3>(d), body.version());
    let changes = body.unsew3(d)?;
    let mut dis = report(body, d, opposite, &changes);
    dis.touched.cover(body, from);
    Ok(dis)
}

/// [`dissociate_face`] of the face with id `f`. O(darts) to find a dart of it ([`face_dart`]),
/// then as [`dissociate_face`].
///
/// # Errors
/// [`CutError::NoSuchFace`], then as [`dissociate_face`].
///
/// # Examples
///
/// ```
/// use topomech::cut::{dissociate_face_id, face_dart, CutError};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let inner = (0..18).map(CellId).find(|&f| !body.map().is_free(3, face_dart(&body, f).unwrap())).unwrap();
/// let cut = dissociate_face_id(&mut body, inner).unwrap();
/// assert_eq!(body.map().boundary_cell_count(), 12 + 2); // both sides are boundary now
/// assert_ne!(cut.faces.0, cut.faces.1);
/// assert!(matches!(dissociate_face_id(&mut body, CellId(99)), Err(CutError::NoSuchFace(_))));
/// ```
pub fn dissociate_face_id(body: &mut Body, f: CellId) -> Result<Dissociation, CutError> {
    let d = face_dart(body, f).ok_or(CutError::NoSuchFace(f))?;
    dissociate_face(body, d)
}

/// A dart of face `f`, or `None` if no live dart carries that id. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::cut::face_dart;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = face_dart(&body, CellId(5)).unwrap();
/// assert_eq!(body.map().cell_id(2, d), CellId(5));
/// assert_eq!(face_dart(&body, CellId(18)), None); // 18 faces: ids 0..18
/// ```
pub fn face_dart(body: &Body, f: CellId) -> Option<DartId> {
    let map = body.map();
    map.darts().find(|&d| map.cell_id(2, d) == f)
}

fn report(body: &Body, d: DartId, opposite: DartId, changes: &CellChanges) -> Dissociation {
    let map = body.map();
    let split = |dim| {
        changes
            .splits(dim)
            .map(|(kept, new, dart_kept, dart_new)| SplitCell { kept, new, dart_kept, dart_new })
            .collect::<Vec<_>>()
    };
    let mut touched = TouchedCells::default();
    touched.record(map, changes);
    Dissociation {
        dart: d,
        opposite,
        faces: (map.cell_id(2, d), map.cell_id(2, opposite)),
        vertices: split(0),
        edges: split(1),
        touched,
    }
}

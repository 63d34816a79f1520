//! Cutting a mechanical body (seed 000 §3.2, §4.3, §5.1, Appendix A): face dissociation, volume
//! removal, incision along a plane, tearing, and connectivity — each keeping the map valid and
//! the conservation laws of [`crate::mechanics::model`] exact.
//!
//! ```text
//!   dissociate_face   α3-unsew of one face; vertices/edges whose two sides no longer share an
//!                     orbit are dissociated: masses split m = m1 + m2, stiffnesses k = k1 + k2
//!   remove_volume     dissociate the tet's inner faces, then delete its 24 darts; report the
//!                     mass and stiffness that left with it
//!   incise_plane      dissociate every inner face whose two tets' centroids lie on opposite sides
//!   incise_sweep      the same along a polyline swept by a depth vector (a bounded, bent cut):
//!                     every inner face whose tets' centroid segment crosses the swept surface
//!   tear_vertex       the closed fan of faces around a vertex (walk α2 α3 α2 α1), dissociated
//!   components        connected parts and their masses
//!   ops               one generator of cut sequences (decoder, oracle, law checks) for the
//!                     proptest suite, the fuzz target and the replay test
//! ```
//!
//! Every operation returns what it changed, including the [`TouchedCells`] that
//! [`Projection::update`](crate::mechanics::Projection::update) needs to follow incrementally.
//! A bad id or an operation that does not apply returns a [`CutError`] and changes nothing.

mod connectivity;
mod dissociate;
mod incise;
pub mod ops;
mod remove;
mod sweep;
mod tear;

pub use connectivity::{components, Component};
pub use dissociate::{dissociate_face, dissociate_face_id, face_dart, Dissociation, SplitCell};
pub use incise::{incise_plane, tet_sides, Incision, Plane};
pub use remove::{remove_volume, volume_dart, Removal};
pub use sweep::{incise_sweep, sweep_faces, PolylineSweep};
pub use tear::{check_threshold, fan_darts, principal_stress, tear_step, tear_vertex, Stress, Tear, TearStep};

use crate::gmap::{DartError, SewError};
use crate::mechanics::{BodyError, SimError, Vec3};
use crate::{CellId, DartId};

pub use crate::mechanics::TouchedCells;

/// Why a cutting operation was refused or failed. When it is refused (every variant but
/// [`CutError::Body`], [`CutError::Kernel`], [`CutError::Dart`] and [`CutError::Sim`]) the body is
/// unchanged.
///
/// # Examples
///
/// ```
/// use topomech::cut::{incise_plane, remove_volume, tear_vertex, CutError, Plane};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// assert!(matches!(remove_volume(&mut body, CellId(6)), Err(CutError::NoSuchVolume(CellId(6)))));
/// assert!(matches!(tear_vertex(&mut body, CellId(99), [1.0, 0.0, 0.0], None), Err(CutError::NoSuchVertex(_))));
/// let flat = Plane { point: [0.0; 3], normal: [0.0; 3] };
/// assert!(matches!(incise_plane(&mut body, &flat), Err(CutError::BadPlane { .. })));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum CutError {
    /// A dart id that is not live in the body's map.
    #[error("{0} does not exist in this body")]
    NoSuchDart(DartId),
    /// A face id that no live dart carries.
    #[error("face {} does not exist in this body", .0.0)]
    NoSuchFace(CellId),
    /// A dissociation given back (to [`crate::subdivide::measure_cut`]) whose dart is live but not
    /// α3-free on the face it reported: the incision was made on another body.
    #[error("{dart} is not an α3-free dart of face {} in this body: the incision was not made on it", .face.0)]
    NotDissociated {
        /// A dart of the dissociation.
        dart: DartId,
        /// The face id the dissociation reported for it.
        face: CellId,
    },
    /// The face is α3-free: it is on the boundary already, there is nothing to dissociate.
    #[error("face {} ({dart}) is a boundary face: nothing to dissociate", .face.0)]
    BoundaryFace {
        /// The face id.
        face: CellId,
        /// The dart given or found.
        dart: DartId,
    },
    /// A volume id that no live dart carries (never created, or already removed).
    #[error("volume {} does not exist (never created or already removed)", .0.0)]
    NoSuchVolume(CellId),
    /// The volume is not a tetrahedron (24 darts).
    #[error("volume {} ({dart}) has {darts} darts, not the 24 of a tetrahedron", .volume.0)]
    NotATet {
        /// The volume id.
        volume: CellId,
        /// A dart of it.
        dart: DartId,
        /// Its dart count.
        darts: usize,
    },
    /// A vertex id that no live dart carries.
    #[error("vertex {} does not exist in this body", .0.0)]
    NoSuchVertex(CellId),
    /// A live vertex whose current position is NaN or infinite, where the operation needs it
    /// (the sides of an incision, the face normals of a tear): nothing is cut.
    #[error("vertex {} has the non-finite position {position:?}: its tets have no side to be cut on", .vertex.0)]
    NonFinitePosition {
        /// The smallest such vertex id (for a tear: of the star of the torn vertex, itself and
        /// the other end of every edge at it).
        vertex: CellId,
        /// Its position.
        position: [f64; 3],
    },
    /// The plane's point or normal is not finite, or the normal is zero.
    #[error("cut plane point {point:?} / normal {normal:?} is not finite or the normal is zero")]
    BadPlane {
        /// Point on the plane.
        point: [f64; 3],
        /// Normal.
        normal: [f64; 3],
    },
    /// A measuring zone (ball) whose centre is not finite or whose radius is not a finite
    /// number ≥ 0 (with NaN every face would compare inside it).
    #[error("measuring zone centre {center:?} / radius {radius} is not finite (or the radius is negative)")]
    BadZone {
        /// The centre given.
        center: [f64; 3],
        /// The radius given.
        radius: f64,
    },
    /// A tearing threshold that is NaN, infinite or negative (with NaN no vertex would ever
    /// compare above it: tearing would silently never happen).
    #[error("tear threshold {0} must be a finite number ≥ 0")]
    BadThreshold(f64),
    /// A tear direction that is not finite or is zero (no face normal can be closest to it).
    #[error("tear direction {0:?} must be finite and non-zero")]
    BadDirection(Vec3),
    /// A polyline sweep that is not a well-formed cut surface (too few points, non-finite,
    /// two consecutive equal points, zero sweep, a segment along the sweep).
    #[error("bad polyline sweep: {reason}")]
    BadSweep {
        /// What is wrong, naming the point or segment.
        reason: String,
    },
    /// The embedding layer refused or its check failed (a bug if the check failed).
    #[error(transparent)]
    Body(#[from] BodyError),
    /// A kernel unsew inside an isolated tet failed (a bug).
    #[error("unsewing inside an isolated volume: {0}")]
    Kernel(#[from] SewError),
    /// A kernel dart deletion failed (a bug).
    #[error("deleting the darts of an isolated volume: {0}")]
    Dart(#[from] DartError),
    /// The simulation could not follow the change.
    #[error(transparent)]
    Sim(#[from] SimError),
}

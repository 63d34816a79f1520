//! The mechanical embeddings of a tetrahedral body and the laws that define them (seed 000 §3.1,
//! §4.1, §4.3).
//!
//! | cell | attributes (keyed by the cell's id) |
//! |---|---|
//! | volume t | rest volume V_t, mass m_t = ρ·V_t, Young's modulus E_t |
//! | edge e | rest length L_e, stiffness k_e, damping c_e |
//! | face f | boundary flag, outward unit normal (boundary faces, for rendering) |
//! | vertex v | rest position, position, velocity, force, mass m_v, ambient viscosity γ_v, pinned |
//!
//! # Laws
//! 1. **Vertex mass** (seed eq. 1): m_v = Σ_{t ∋ v} m_t / 4, the sum over the tetrahedra around v
//!    in the map (the volumes met by the vertex orbit ⟨α1, α2, α3⟩).
//! 2. **Spring stiffness**: each tet contributes k_{t,e} = E_t · V_t / L_e² to each of its six
//!    edges, and k_e = Σ_{t ∋ e} k_{t,e} over the tets around e (the edge orbit ⟨α0, α2, α3⟩).
//!    Why this formula: a spring of stiffness k stretched by a strain ε stores ½ k L² ε²; a tet of
//!    an isotropic solid under a uniform dilatation ε stores ½ · 9K · ε² · V with bulk modulus K.
//!    With k_{t,e} L_e² = E V_t the six springs store 3 E V ε², which equals 9/2 K V ε² exactly
//!    when K = 2E/3, i.e. for Poisson's ratio ν = 1/4 — the ratio that central-force spring
//!    networks are known to produce (Cauchy relation). It scales correctly (k ∝ E · length),
//!    favours no edge direction, and is linear in the tets, so an edge dissociated into two keeps
//!    k = k1 + k2 (springs in parallel).
//! 3. **Damping** c_e = β · k_e (stiffness-proportional, β in seconds), so c = c1 + c2 too.
//! 4. **Ambient viscosity** γ_v = ν · m_v (ν in 1/s).
//! 5. **Mass conservation**: Σ_v m_v = Σ_t m_t, after any dissociation.
//!
//! [`check_conservation`] verifies all five from the map's orbits.
//!
//! # Split and merge rules ([`CellRules`] for [`Mechanics`])
//! - vertex split: both sides copy rest position, position, velocity and the pinned flag; each
//!   side's mass and viscosity are recomputed from the tets now around it (m = m1 + m2).
//! - edge split: both sides copy the rest length; stiffness and damping are recomputed from the
//!   tets now around each side (k = k1 + k2).
//! - face split / merge: boundary flags and normals of the faces touched are recomputed.
//! - vertex merge: position and velocity become the mass-weighted means (momentum is kept), or
//!   the pinned side's when exactly one side is pinned (a pin holds its vertex); the mass is
//!   recomputed (= m1 + m2); edge merge: stiffness recomputed (= k1 + k2).
//! - only 3-unsews and 3-sews (face dissociation and gluing) reach these rules: every i-unsew
//!   and i-sew with i ≤ 2 would open a tet or join volumes, for which the model has no law, and
//!   is refused before the map changes ([`CellRules::check_unsew`], [`CellRules::check_sew`]).

use crate::embedding::{CellArray, CellRules, CellSliceMut, Embedded, Split};
use crate::gmap::CellChanges;
use crate::{AlphaMask, BuildError, BuildReport, CellId, DartId, GMap};

use super::conservation::{check_conservation, ConservationError};
use super::geom::{cross, dot, norm, scale, sub, tet_volume, Scaled, Vec3};

/// Material constants of a homogeneous body.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material, ModelError};
///
/// let (points, tets) = kuhn_cube(1); // the unit cube
/// let dense = Material { density: 2.5, ..Material::default() };
/// let (body, _) = Body::from_tets(&points, &tets, dense).unwrap();
/// assert!((body.total_tet_mass() - 2.5).abs() < 1e-12); // ρ · volume
/// let bad = Material { young: -1.0, ..Material::default() };
/// assert!(matches!(Body::from_tets(&points, &tets, bad), Err(ModelError::BadMaterial { name: "young", .. })));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Mass density ρ (mass per unit volume); m_t = ρ·V_t.
    pub density: f64,
    /// Young's modulus E (force per unit area); k_{t,e} = E·V_t/L_e².
    pub young: f64,
    /// Stiffness-proportional spring damping β (seconds); c_e = β·k_e.
    pub damping: f64,
    /// Ambient viscosity per unit mass ν (1/s); γ_v = ν·m_v.
    pub viscosity: f64,
}

impl Default for Material {
    /// ρ = 1, E = 1000, β = 0.001 s, ν = 1 /s: soft tissue in consistent arbitrary units.
    fn default() -> Self {
        Material { density: 1.0, young: 1000.0, damping: 0.001, viscosity: 1.0 }
    }
}

/// Why a body could not be built.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::{Body, Material, ModelError};
///
/// let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
/// let err = Body::from_tets(&flat, &[[0, 1, 2, 3]], Material::default()).unwrap_err();
/// assert!(matches!(err, ModelError::DegenerateTet { tet: 0 }));
/// let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let err = Body::from_tets(&nan, &[[0, 1, 2, 3]], Material::default()).unwrap_err();
/// assert!(matches!(err, ModelError::NonFinitePoint { point: 0, .. }));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// The map could not be built from the tetrahedra.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A material constant is negative, zero where it must not be, or not finite.
    #[error("material constant {name} = {value} is invalid (must be finite and {rule})")]
    BadMaterial {
        /// Which constant.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {point} has a non-finite coordinate {coords:?}")]
    NonFinitePoint {
        /// Point index.
        point: usize,
        /// Its coordinates.
        coords: Vec3,
    },
    /// A flat tetrahedron, which would make a massless, infinitely stiff element: its determinant
    /// det[b − a, c − a, d − a], computed with the plain formula's roundings and an unbounded
    /// exponent (wide floats), is 0. That is the rounded determinant, not the exact volume: an
    /// exactly coplanar tet whose products do not cancel in rounding builds, and a tet of tiny
    /// nonzero volume whose products do is refused (the mesh check's relative test
    /// |6V| ≤ 10⁻¹² l³ flags both). A tet whose volume merely underflows f64 (tiny, or a needle)
    /// is not one ([`ModelError::VolumeUnderflow`]).
    #[error("tetrahedron {tet} has zero volume")]
    DegenerateTet {
        /// Tet index (= volume id).
        tet: usize,
    },
    /// A tetrahedron that is not flat (its determinant in wide floats is not 0:
    /// [`ModelError::DegenerateTet`]) but whose volume, as an f64, is below the normal range (about 2.2e-308: a regular
    /// tet of edge 1e-103 or less). A model stores rest volumes and measures masses and stiffnesses
    /// on them, so such a volume would be 0 or lose its precision: refused, not called flat.
    #[error("tetrahedron {tet} has volume {volume:e}, below the normal range of f64 (coordinates too small for a stored rest volume; it is not flat)")]
    VolumeUnderflow {
        /// Tet index (= volume id).
        tet: usize,
        /// Its volume as computed in f64 (0 or subnormal).
        volume: f64,
    },
    /// A sum of the model overflows f64 from this tet on: its volume, the total mass or the total
    /// stiffness (coordinates, density or Young's modulus too large). Every vertex mass and spring
    /// stiffness is a part of those non-negative totals, so finite totals make them all finite.
    #[error("tetrahedron {tet}: {quantity} = {value:e} overflows (coordinates, density or Young's modulus too large for f64)")]
    Overflow {
        /// Tet index (= volume id): the first at which a total stops being finite.
        tet: usize,
        /// What overflowed: "volume", "total mass", "total stiffness" or "total damping".
        quantity: &'static str,
        /// Its value there (infinite or NaN).
        value: f64,
    },
    /// A tet whose mass ρ·V is so small that a quarter of it (the least a vertex of that tet can
    /// weigh) has an inverse that overflows f64, or rounds to 0 (density or volume too small):
    /// the step divides by vertex masses.
    #[error("tetrahedron {tet}: its mass {mass:e} is too small for f64 (a vertex's inverse mass would overflow; density or volume too small)")]
    MassTooSmall {
        /// Tet index (= volume id).
        tet: usize,
        /// Its mass ρ·V.
        mass: f64,
    },
    /// A gravity vector with a NaN or infinite component (the flat model's constructor).
    #[error("gravity {0:?} must be finite")]
    BadGravity(Vec3),
    /// A pin list that is neither empty nor one flag per point (the flat model's constructor).
    #[error("{len} pin flags for {points} points (give one per point, or none)")]
    PinCount {
        /// Flags given.
        len: usize,
        /// Points.
        points: usize,
    },
}

/// The mechanical attributes of a tetrahedral 3-G-map, all in arrays keyed by cell id.
///
/// State variables (positions, velocities, pins) are writable value by value through views that
/// cannot change an array's length ([`Mechanics::position_mut`], [`Mechanics::velocity_mut`],
/// [`Mechanics::pinned_mut`]): the simulation writes them every step, and every operation may
/// index them by any vertex id of the map. Parameters bound by the laws (masses, stiffnesses, rest
/// lengths and the rest positions they are measured on) are read-only and change only through
/// the split/merge rules, so the laws cannot be broken from outside.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let m = body.attrs();
/// assert_eq!(m.position().as_slice(), m.rest_position().as_slice()); // built at rest
/// assert!(m.velocity().as_slice().iter().all(|v| *v == [0.0; 3]));
/// assert!(!m.pinned().as_slice().iter().any(|&p| p));
/// assert!((m.total_tet_mass(body.map()).unwrap() - 1.0).abs() < 1e-12); // density 1, unit cube
/// ```
///
/// A state array cannot be replaced by one of another length (finding 33 in
/// docs/VERIFICATION.md: a shorter one made later operations panic on an index):
///
/// ```compile_fail
/// use topomech::embedding::CellArray;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// body.attrs_mut().position = CellArray::from_vec(vec![[0.0; 3]; 2]); // private field
/// ```
///
/// nor a rest position moved from outside (it would break the rest-length law):
///
/// ```compile_fail
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// body.attrs_raw_mut().rest_position()[CellId(0)][0] += 0.25; // read-only
/// ```
#[derive(Clone, Debug)]
pub struct Mechanics {
    pub(crate) material: Material,
    // volumes
    pub(crate) tet_rest_volume: CellArray<f64>,
    pub(crate) tet_mass: CellArray<f64>,
    pub(crate) tet_young: CellArray<f64>,
    // edges
    pub(crate) edge_rest_length: CellArray<f64>,
    pub(crate) edge_stiffness: CellArray<f64>,
    pub(crate) edge_damping: CellArray<f64>,
    // faces
    pub(crate) face_boundary: CellArray<bool>,
    pub(crate) face_normal: CellArray<Vec3>,
    // vertices
    pub(crate) vertex_mass: CellArray<f64>,
    pub(crate) vertex_viscosity: CellArray<f64>,
    // vertex state: private so that no caller can change an array's length (values change
    // through the `*_mut` views); rest positions are bound by the laws and read-only
    pub(crate) rest_position: CellArray<Vec3>,
    pub(crate) position: CellArray<Vec3>,
    pub(crate) velocity: CellArray<Vec3>,
    pub(crate) force: CellArray<Vec3>,
    pub(crate) pinned: CellArray<bool>,
    /// A fresh process-wide stamp each time the pins are handed out for writing
    /// ([`Mechanics::pinned_mut`], [`Mechanics::pin_where`]; 0 before): a projection built
    /// before sees that its fixed slots may be stale, and two bodies with the same stamp have
    /// the same pins (a clone's, untouched since). Not part of the body's state (never stored).
    pub(crate) pins_epoch: u64,
    /// A fresh stamp each time the velocities are handed out for writing
    /// ([`Mechanics::velocity_mut`]): the simulation then re-zeroes the pinned velocities.
    pub(crate) velocity_epoch: u64,
    /// A fresh stamp each time the positions are handed out for writing
    /// ([`Mechanics::position_mut`]): the simulation then takes the state as the new start of
    /// its runaway test (energy put in by hand is not a blow-up).
    pub(crate) position_epoch: u64,
    /// Which value this is: fresh when made and on every clone, so a projection records which
    /// attributes it read (round 26, when they could still be replaced whole; since round 27
    /// [`AttrsMut`] opens the free state only, and the stamp is a second defence).
    pub(crate) instance: Instance,
}

/// The identity of one [`Mechanics`] value: process-wide unique, fresh on every clone (a clone
/// is another value, which may be put in place of the first), with the identity of the value it
/// was cloned from (0 for none). Not part of the body's state (never stored, not compared).
/// O(1).
#[derive(Debug)]
pub(crate) struct Instance {
    /// This value's identity.
    pub(crate) id: u64,
    /// The identity of the value this one was cloned from, or 0.
    pub(crate) from: u64,
}

impl Instance {
    /// A number no other instance has. O(1).
    pub(crate) fn fresh() -> Self {
        Instance { id: crate::gmap::next_unique(), from: 0 }
    }
}

impl Clone for Instance {
    fn clone(&self) -> Self {
        Instance { id: crate::gmap::next_unique(), from: self.id }
    }
}

/// A mechanical body: a 3-G-map whose sew/unsew keep the [`Mechanics`] attributes lawful. Its
/// volumes are closed tetrahedra: it takes 3-unsews and 3-sews (face dissociation and gluing)
/// and refuses every i-unsew and i-sew with i ≤ 2, unchanged.
///
/// # Examples
///
/// ```
/// use topomech::embedding::EmbedError;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, ConservationError, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _): (Body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
/// body.unsew3(d).unwrap();
/// assert_eq!(body.version(), 1);
/// assert!(body.check().is_ok()); // the mechanical laws still hold
/// let err = body.unsew(2, d).unwrap_err(); // would open a tet: refused
/// assert!(matches!(err, EmbedError::Refused { source: ConservationError::UnsewOpensTet { i: 2, .. }, .. }));
/// assert_eq!(body.version(), 1);
/// ```
pub type Body = Embedded<3, Mechanics>;

/// A body's attributes opened for writing what is free state — positions, velocities and pins
/// — and readable whole (it dereferences to [`Mechanics`]). Everything else (masses,
/// stiffnesses, rest shape, face flags) is derived from the topology and changes only through
/// the body's operations, which keep the laws; and the attributes cannot be replaced or swapped
/// as a whole, so that the arrays always cover the map and follow its state (rounds 26–27:
/// attributes put back from another state made a dozen entries panic or use stale values).
/// Each writer records that it was handed out, so that projections and simulations take the
/// writes up. O(1) to make.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let mut attrs = body.attrs_mut();
/// attrs.position_mut()[CellId(0)] = [0.0, 0.0, -1.0];
/// attrs.velocity_mut()[CellId(0)] = [0.0, 0.0, -2.0];
/// attrs.pinned_mut()[CellId(1)] = true;
/// assert_eq!(attrs.position()[CellId(0)], [0.0, 0.0, -1.0]); // reads go through
/// assert_eq!(body.version(), 0); // attributes are not topology
/// ```
///
/// The attributes of another state cannot be put in:
///
/// ```compile_fail
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let older = body.attrs().clone();
/// *body.attrs_mut() = older; // no `DerefMut`: does not compile
/// ```
///
/// ```compile_fail
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut a, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let (mut b, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// std::mem::swap(&mut *a.attrs_mut(), &mut *b.attrs_mut()); // does not compile either
/// ```
#[derive(Debug)]
pub struct AttrsMut<'a> {
    mech: &'a mut Mechanics,
}

impl std::ops::Deref for AttrsMut<'_> {
    type Target = Mechanics;

    fn deref(&self) -> &Mechanics {
        self.mech
    }
}

impl AttrsMut<'_> {
    /// [`Mechanics::position_mut`]. O(1).
    pub fn position_mut(&mut self) -> CellSliceMut<'_, Vec3> {
        self.mech.position_mut()
    }

    /// [`Mechanics::velocity_mut`]. O(1).
    pub fn velocity_mut(&mut self) -> CellSliceMut<'_, Vec3> {
        self.mech.velocity_mut()
    }

    /// [`Mechanics::pinned_mut`]. O(1).
    pub fn pinned_mut(&mut self) -> CellSliceMut<'_, bool> {
        self.mech.pinned_mut()
    }

    /// [`Mechanics::pin_where`]. O(vertex ids).
    pub fn pin_where(&mut self, pin: impl FnMut(CellId, Vec3) -> bool) {
        self.mech.pin_where(pin)
    }
}

impl Embedded<3, Mechanics> {
    /// The body's free state, writable: positions, velocities and pins ([`AttrsMut`]; the rest
    /// changes only through the operations). The map stays untouchable. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().position_mut()[CellId(0)] = [0.0, 0.0, -1.0];
    /// assert_eq!(body.attrs().position()[CellId(0)], [0.0, 0.0, -1.0]);
    /// ```
    pub fn attrs_mut(&mut self) -> AttrsMut<'_> {
        AttrsMut { mech: self.attrs_raw_mut() }
    }
}

/// Errors of the body's topological operations.
///
/// # Examples
///
/// ```
/// use topomech::embedding::EmbedError;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, BodyError, Material};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let d = body.map().darts().find(|&d| body.map().is_free(3, d)).unwrap();
/// let err: BodyError = body.unsew3(d).unwrap_err(); // nothing to unsew on the boundary
/// assert!(matches!(err, EmbedError::Sew(_)));
/// ```
pub type BodyError = crate::embedding::EmbedError<ConservationError>;

impl Mechanics {
    /// The material constants. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let stiff = Material { young: 5e4, ..Material::default() };
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, stiff).unwrap();
    /// assert_eq!(body.attrs().material(), &stiff);
    /// ```
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// Rest volume V_t of volume `t`. O(1).
    ///
    /// # Panics
    /// If `t` is not below [`Mechanics::attribute_len`]`(3)` (no volume id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let points = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 1.0]];
    /// let (body, _) = Body::from_tets(&points, &[[0, 2, 1, 3]], Material::default()).unwrap(); // inverted order
    /// assert!((body.attrs().tet_rest_volume(CellId(0)) - 1.0).abs() < 1e-15); // |det| / 6 = 6 / 6
    /// assert_eq!(body.attrs().tet_young(CellId(0)), Material::default().young);
    /// ```
    pub fn tet_rest_volume(&self, t: CellId) -> f64 {
        self.tet_rest_volume[t]
    }

    /// Mass m_t = ρ·V_t of volume `t`. O(1).
    ///
    /// # Panics
    /// If `t` is not below [`Mechanics::attribute_len`]`(3)` (no volume id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::{CellId, DartId};
    ///
    /// let unit = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let (body, _) = Body::from_tets(&unit, &[[0, 1, 2, 3]], Material::default()).unwrap();
    /// let m = body.attrs();
    /// assert!((m.tet_mass(CellId(0)) - 1.0 / 6.0).abs() < 1e-15); // ρ · V
    /// assert!((0..4).all(|v| (m.vertex_mass(CellId(v)) - 1.0 / 24.0).abs() < 1e-15)); // m_t / 4
    /// let f = body.map().cell_id(2, DartId(0));
    /// assert!(m.face_is_boundary(f));
    /// let n = m.face_normal(f);
    /// assert!((n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12);
    /// ```
    pub fn tet_mass(&self, t: CellId) -> f64 {
        self.tet_mass[t]
    }

    /// Young's modulus of volume `t`. O(1).
    ///
    /// # Panics
    /// If `t` is not below [`Mechanics::attribute_len`]`(3)` (no volume id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let material = Material { young: 1234.0, ..Material::default() };
    /// let (body, _) = Body::from_tets(&points, &tets, material).unwrap();
    /// let vols = body.map().one_dart_per_cell(3);
    /// assert!(vols.iter().all(|&d| body.attrs().tet_young(body.map().cell_id(3, d)) == 1234.0));
    /// ```
    pub fn tet_young(&self, t: CellId) -> f64 {
        self.tet_young[t]
    }

    /// Rest length L_e of edge `e`. O(1).
    ///
    /// # Panics
    /// If `e` is not below [`Mechanics::attribute_len`]`(1)` (no edge id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// // The Kuhn cube's edges: 12 sides, 6 face diagonals, 1 space diagonal.
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// let edges = map.one_dart_per_cell(1);
    /// let lengths: Vec<f64> = edges.iter().map(|&d| m.edge_rest_length(map.cell_id(1, d))).collect();
    /// let count = |l: f64| lengths.iter().filter(|&&x| (x - l).abs() < 1e-12).count();
    /// assert_eq!((count(1.0), count(2f64.sqrt()), count(3f64.sqrt())), (12, 6, 1));
    /// ```
    pub fn edge_rest_length(&self, e: CellId) -> f64 {
        self.edge_rest_length[e]
    }

    /// Stiffness k_e of edge `e`. O(1).
    ///
    /// # Panics
    /// If `e` is not below [`Mechanics::attribute_len`]`(1)` (no edge id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Body, Material};
    ///
    /// // One tet: each edge gets k = E·V/L² from its only tet.
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let (body, _) = Body::from_tets(&points, &[[0, 1, 2, 3]], Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// for d in map.one_dart_per_cell(1) {
    ///     let (e, young) = (map.cell_id(1, d), m.material().young);
    ///     let l = m.edge_rest_length(e);
    ///     assert!((m.edge_stiffness(e) - young * (1.0 / 6.0) / (l * l)).abs() < 1e-9);
    /// }
    /// ```
    pub fn edge_stiffness(&self, e: CellId) -> f64 {
        self.edge_stiffness[e]
    }

    /// Damping c_e of edge `e`. O(1).
    ///
    /// # Panics
    /// If `e` is not below [`Mechanics::attribute_len`]`(1)` (no edge id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// for d in map.one_dart_per_cell(1) {
    ///     let e = map.cell_id(1, d);
    ///     assert_eq!(m.edge_damping(e), m.material().damping * m.edge_stiffness(e)); // c = β k
    /// }
    /// ```
    pub fn edge_damping(&self, e: CellId) -> f64 {
        self.edge_damping[e]
    }

    /// Mass m_v of vertex `v`. O(1).
    ///
    /// # Panics
    /// If `v` is not below [`Mechanics::attribute_len`]`(0)` (no vertex id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// // Corner (0, 0, 0) of the Kuhn cube touches all 6 tets; corner (1, 0, 0) only 2.
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let m = body.attrs();
    /// assert!((m.vertex_mass(CellId(0)) - 6.0 * (1.0 / 6.0) / 4.0).abs() < 1e-15);
    /// assert!((m.vertex_mass(CellId(1)) - 2.0 * (1.0 / 6.0) / 4.0).abs() < 1e-15);
    /// ```
    pub fn vertex_mass(&self, v: CellId) -> f64 {
        self.vertex_mass[v]
    }

    /// Ambient viscosity γ_v = ν·m_v of vertex `v`. O(1).
    ///
    /// # Panics
    /// If `v` is not below [`Mechanics::attribute_len`]`(0)` (no vertex id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let m = body.attrs();
    /// assert!((0..8).map(CellId).all(|v| m.vertex_viscosity(v) == m.material().viscosity * m.vertex_mass(v)));
    /// ```
    pub fn vertex_viscosity(&self, v: CellId) -> f64 {
        self.vertex_viscosity[v]
    }

    /// Whether face `f` is on the boundary (its darts are α3-free). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// let boundary = map.one_dart_per_cell(2).into_iter().filter(|&d| m.face_is_boundary(map.cell_id(2, d))).count();
    /// assert_eq!(boundary, 12);
    /// ```
    pub fn face_is_boundary(&self, f: CellId) -> bool {
        self.face_boundary.get(f).copied().unwrap_or(false)
    }

    /// Outward unit normal of boundary face `f` from the positions at the body's last
    /// topological change or [`Body::update_normals`] (zero for inner faces). O(1).
    ///
    /// # Panics
    /// If `f` is not below [`Mechanics::attribute_len`]`(2)` (no face id of this body's map is).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// for d in map.one_dart_per_cell(2) {
    ///     let (f, n) = (map.cell_id(2, d), m.face_normal(map.cell_id(2, d)));
    ///     let axis_aligned = n.iter().filter(|c| c.abs() == 1.0).count() == 1; // outward ±x, ±y or ±z
    ///     assert_eq!(axis_aligned, m.face_is_boundary(f)); // inner faces: zero normal
    /// }
    /// ```
    pub fn face_normal(&self, f: CellId) -> Vec3 {
        self.face_normal[f]
    }

    /// Rest (initial) position of each vertex, read-only: rest lengths and volumes are measured
    /// on it, so it is bound by the laws and changes only through the operations. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.attrs().rest_position().as_slice(), &points[..]); // vertex id i = point i
    /// assert_eq!(body.attrs().rest_position()[CellId(7)], [1.0, 1.0, 1.0]);
    /// ```
    pub fn rest_position(&self) -> &CellArray<Vec3> {
        &self.rest_position
    }

    /// Current position of each vertex. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.attrs().position(), body.attrs().rest_position()); // built at rest
    /// ```
    pub fn position(&self) -> &CellArray<Vec3> {
        &self.position
    }

    /// Current positions, writable value by value; the array keeps its length (one slot per
    /// vertex id of the map), so no later operation can index past it. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().position_mut()[CellId(0)] = [0.0, 0.0, -1.0];
    /// assert_eq!(body.attrs().position()[CellId(0)], [0.0, 0.0, -1.0]);
    /// assert_eq!(body.attrs().position().len(), 8);
    /// ```
    pub fn position_mut(&mut self) -> CellSliceMut<'_, Vec3> {
        self.position_epoch = crate::gmap::next_unique();
        CellSliceMut::new(&mut self.position)
    }

    /// Current velocity of each vertex. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!(body.attrs().velocity().as_slice().iter().all(|v| *v == [0.0; 3])); // at rest
    /// ```
    pub fn velocity(&self) -> &CellArray<Vec3> {
        &self.velocity
    }

    /// Current velocities, writable value by value; the length stays bound to the map. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().velocity_mut().as_mut_slice().fill([1.0, 0.0, 0.0]);
    /// assert!((body.kinetic_energy() - 0.5).abs() < 1e-12); // ½ · 1 kg · (1 m/s)²
    /// ```
    pub fn velocity_mut(&mut self) -> CellSliceMut<'_, Vec3> {
        self.velocity_epoch = crate::gmap::next_unique();
        CellSliceMut::new(&mut self.velocity)
    }

    /// Sum of the forces on each vertex at the last evaluation (seed §4.1 "for optimization"),
    /// read-only: [`crate::mechanics::Simulation::write_forces`] writes it (the step loop keeps
    /// its sums in its own buffers); zero until then, and reset to zero on both sides of a vertex
    /// that splits. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.attrs().force().len(), 8);
    /// ```
    pub fn force(&self) -> &CellArray<Vec3> {
        &self.force
    }

    /// Which vertices are fixed (their velocity stays zero: a simulation zeroes it when it is
    /// built and at each step after the pins or velocities were written). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!(!body.attrs().pinned().as_slice().contains(&true)); // nothing fixed at first
    /// ```
    pub fn pinned(&self) -> &CellArray<bool> {
        &self.pinned
    }

    /// The pins, writable value by value ([`Mechanics::pin_where`] sets them by a predicate);
    /// the length stays bound to the map. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().pinned_mut()[CellId(3)] = true;
    /// assert_eq!(body.attrs().pinned().as_slice().iter().filter(|&&p| p).count(), 1);
    /// ```
    pub fn pinned_mut(&mut self) -> CellSliceMut<'_, bool> {
        self.pins_epoch = crate::gmap::next_unique();
        CellSliceMut::new(&mut self.pinned)
    }

    /// Number of attribute slots of `dim`-cells (≥ the map's `cell_id_bound(dim)` when in sync).
    /// O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::dissociate_face;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// dissociate_face(&mut body, d).unwrap(); // new vertex, edge and face ids appear
    /// assert!((0..=3).all(|i| body.attrs().attribute_len(i) >= body.map().cell_id_bound(i)));
    /// ```
    pub fn attribute_len(&self, dim: usize) -> usize {
        match dim {
            0 => self.vertex_mass.len().min(self.position.len()),
            1 => self.edge_stiffness.len(),
            2 => self.face_normal.len(),
            _ => self.tet_mass.len(),
        }
    }

    /// Whether the attribute arrays hold an entry for every cell id of `map`, in every
    /// dimension: what every function taking the map beside the attributes needs, so that none
    /// indexes past an array. A bound check, not an identity check: a map with more ids than
    /// the arrays (e.g. a larger body's) is refused, but another body's map of the same size or
    /// smaller, or a copy of this body's map taken before a cut, passes (a map alone does not
    /// say whose it is); the [`Body`] methods use the body's own map. O(1).
    ///
    /// # Errors
    /// [`ConservationError::MissingAttributes`] for the first dimension whose arrays are short.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, ConservationError, Material};
    ///
    /// let body = |k| Body::from_tets(&kuhn_cube(k).0, &kuhn_cube(k).1, Material::default()).unwrap().0;
    /// let (small, big) = (body(1), body(2));
    /// assert!(small.attrs().check_covers(small.map()).is_ok());
    /// let e = small.attrs().check_covers(big.map()).unwrap_err();
    /// assert_eq!(e, ConservationError::MissingAttributes { dim: 0, len: 8, bound: 27 });
    /// assert!(small.attrs().total_vertex_mass(big.map()).is_err());
    /// ```
    pub fn check_covers(&self, map: &GMap<3>) -> Result<(), ConservationError> {
        for dim in 0..=3 {
            let (len, bound) = (self.attribute_len(dim), map.cell_id_bound(dim));
            if len < bound {
                return Err(ConservationError::MissingAttributes { dim, len, bound });
            }
        }
        Ok(())
    }

    /// Sets every live face's boundary flag to whether it is α3-free in `map` and its normal to
    /// the outward unit normal (boundary) or zero (inner), for a map the attributes cover: the
    /// body's own ([`Body::update_normals`]). Crate-private: from outside, a stale or foreign
    /// map of the same size would rewrite the flags from the wrong topology. O(darts).
    pub(crate) fn update_normals_raw(&mut self, map: &GMap<3>) {
        for d in map.one_dart_per_cell(2) {
            let f = map.cell_id(2, d);
            self.face_boundary[f] = map.is_free(3, d);
            self.face_normal[f] = if self.face_boundary[f] { self.outward_normal(map, d) } else { [0.0; 3] };
        }
    }

    /// Unit normal of the face of `d` pointing away from the 4th vertex of d's tet: the face's
    /// three vertex ids a < b < c, the apex the smallest vertex id of the volume not on the face;
    /// zero if the face has not exactly three vertices, the volume no other vertex, or the face
    /// no area. O(1) for a closed tet: five loads when the map's tets are as built
    /// ([`GMap::tets_as_built`]), else after [`GMap::closed_tet_darts`]' 36; O(volume) by orbits
    /// otherwise ([`Mechanics::outward_normal_by_orbits`], the same definition).
    fn outward_normal(&self, map: &GMap<3>, d: DartId) -> Vec3 {
        if !map.tets_as_built() && map.closed_tet_darts(d).is_none() {
            return self.outward_normal_by_orbits(map, d);
        }
        let Some(face) = closed_triangle_vertices(map, d) else { return [0.0; 3] };
        // In a closed tet the 24 darts' vertex ids are those of its four corners, each corner
        // ⟨α1, α2⟩ carrying one id; α0 α1 α2(d) is on the corner opposite d's face (α2: the other
        // face on d's edge, α1: its edge towards the fourth vertex, α0: that vertex). So the
        // vertices off the face are that corner's id or none: the reference's minimum, in three
        // loads instead of 24.
        let apex = map.vertex_id(map.alpha_local(0, map.alpha_local(1, map.alpha_local(2, d))));
        self.normal_away_from(face, (!face.contains(&apex)).then_some(apex))
    }

    /// [`Mechanics::outward_normal`] from the whole face and volume orbits: the reference.
    fn outward_normal_by_orbits(&self, map: &GMap<3>, d: DartId) -> Vec3 {
        let face = distinct(map.orbit(d, AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)));
        let tet = distinct(map.cell_darts(3, d).into_iter().map(|x| map.vertex_id(x)));
        let apex = tet.iter().copied().find(|v| !face.contains(v));
        match face.as_slice() {
            &[a, b, c] => self.normal_away_from([a, b, c], apex),
            _ => [0.0; 3],
        }
    }

    /// Unit normal of the triangle `[a, b, c]` (sorted ids), oriented away from `apex`. The
    /// edges, their cross product and the apex direction are scaled by powers of two to a
    /// largest component in [1, 2) (exact), so nothing over- or underflows at any coordinate
    /// scale (round 26: at 1e-80 the normal was 1 + 6e-6 long, from 1e78 zero, from 1e155 NaN);
    /// for ordinary coordinates the result is the unscaled formula's bit for bit. O(1).
    fn normal_away_from(&self, [a, b, c]: [CellId; 3], apex: Option<CellId>) -> Vec3 {
        let Some(apex) = apex else { return [0.0; 3] };
        let p = |v: CellId| self.position[v];
        let (e1, e2) = (Scaled::diff(p(b), p(a), 0).dir, Scaled::diff(p(c), p(a), 0).dir);
        let n = Scaled::new(cross(e1, e2), 0).dir;
        let len = norm(n);
        if len == 0.0 || !len.is_finite() {
            return [0.0; 3];
        }
        let sign = if dot(n, Scaled::diff(p(apex), p(a), 0).dir) > 0.0 { -1.0 } else { 1.0 };
        scale(n, sign / len)
    }

    /// Total mass Σ_v m_v over the live vertices of `map`. O(darts). [`Body::total_vertex_mass`]
    /// is the same for a body's own pair.
    ///
    /// # Errors
    /// [`ConservationError::MissingAttributes`] for a map the attributes do not cover
    /// ([`Mechanics::check_covers`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// // Law 1 summed over the body: each tet gives a quarter of its mass to each corner.
    /// assert!((m.total_vertex_mass(map).unwrap() - m.total_tet_mass(map).unwrap()).abs() < 1e-12);
    /// assert!((m.total_tet_mass(map).unwrap() - 8.0).abs() < 1e-12); // density 1, volume 2³
    /// ```
    pub fn total_vertex_mass(&self, map: &GMap<3>) -> Result<f64, ConservationError> {
        self.check_covers(map)?;
        Ok(self.total_vertex_mass_raw(map))
    }

    /// [`Mechanics::total_vertex_mass`] for a map the attributes cover. O(darts).
    pub(crate) fn total_vertex_mass_raw(&self, map: &GMap<3>) -> f64 {
        map.one_dart_per_cell(0).into_iter().map(|d| self.vertex_mass[map.vertex_id(d)]).fold(0.0, |s, m| s + m)
        // +0 when empty
    }

    /// Total mass Σ_t m_t over the live volumes of `map`. O(darts). [`Body::total_tet_mass`] is
    /// the same for a body's own pair.
    ///
    /// # Errors
    /// As [`Mechanics::total_vertex_mass`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::remove_volume;
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    /// use topomech::CellId;
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let gone = remove_volume(&mut body, CellId(2)).unwrap().removed_mass;
    /// let m = body.attrs();
    /// assert!((body.total_tet_mass() - (1.0 - gone)).abs() < 1e-12);
    /// assert!((m.total_vertex_mass(body.map()).unwrap() - m.total_tet_mass(body.map()).unwrap()).abs() < 1e-12);
    /// ```
    pub fn total_tet_mass(&self, map: &GMap<3>) -> Result<f64, ConservationError> {
        self.check_covers(map)?;
        Ok(self.total_tet_mass_raw(map))
    }

    /// [`Mechanics::total_tet_mass`] for a map the attributes cover. O(darts).
    pub(crate) fn total_tet_mass_raw(&self, map: &GMap<3>) -> f64 {
        map.one_dart_per_cell(3).into_iter().map(|d| self.tet_mass[map.cell_id(3, d)]).fold(0.0, |s, m| s + m)
        // +0 when empty
    }

    /// Law 1 at the vertex of `d`: Σ m_t/4 over the distinct volumes of its orbit. O(vertex).
    ///
    /// # Errors
    /// [`ConservationError::NoSuchDart`] unless `d` is a live dart of `map`, and
    /// [`ConservationError::MissingAttributes`] for a map the attributes do not cover.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// for d in map.darts() {
    ///     assert!((m.vertex_mass_from_map(map, d).unwrap() - m.vertex_mass(map.vertex_id(d))).abs() < 1e-15);
    /// }
    /// ```
    pub fn vertex_mass_from_map(&self, map: &GMap<3>, d: DartId) -> Result<f64, ConservationError> {
        self.check_dart_of(map, d)?;
        Ok(self.vertex_mass_from_map_raw(map, d))
    }

    /// [`ConservationError::NoSuchDart`] unless `d` is live in `map`, then
    /// [`Mechanics::check_covers`]. O(1).
    fn check_dart_of(&self, map: &GMap<3>, d: DartId) -> Result<(), ConservationError> {
        if !map.contains(d) {
            return Err(ConservationError::NoSuchDart(d));
        }
        self.check_covers(map)
    }

    /// [`Mechanics::vertex_mass_from_map`] for a live dart of a covered map. O(vertex).
    pub(crate) fn vertex_mass_from_map_raw(&self, map: &GMap<3>, d: DartId) -> f64 {
        let tets = map.vertex_volumes(d);
        tets.iter().map(|&t| self.tet_mass[t] / 4.0).sum()
    }

    /// Law 2 at the edge of `d`: Σ E_t·V_t/L_e² over the distinct volumes of its orbit, with L_e
    /// the edge's stored rest length. O(edge).
    ///
    /// # Errors
    /// As [`Mechanics::vertex_mass_from_map`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let (map, m) = (body.map(), body.attrs());
    /// for d in map.one_dart_per_cell(1) {
    ///     let stored = m.edge_stiffness(map.cell_id(1, d));
    ///     assert!(stored > 0.0 && (m.edge_stiffness_from_map(map, d).unwrap() - stored).abs() <= 1e-12 * stored);
    /// }
    /// ```
    pub fn edge_stiffness_from_map(&self, map: &GMap<3>, d: DartId) -> Result<f64, ConservationError> {
        self.check_dart_of(map, d)?;
        Ok(self.edge_stiffness_from_map_raw(map, d))
    }

    /// [`Mechanics::edge_stiffness_from_map`] for a live dart of a covered map. O(edge).
    pub(crate) fn edge_stiffness_from_map_raw(&self, map: &GMap<3>, d: DartId) -> f64 {
        let l = self.edge_rest_length[map.cell_id(1, d)];
        let k = |t: &CellId| stiffness_contribution(self.tet_young[*t], self.tet_rest_volume[*t], l);
        // α0 keeps the volume, so the volumes of the edge orbit ⟨α0, α2, α3⟩ are those of the ring
        // ⟨α2, α3⟩(d), walked without a visited set; summed in increasing id order either way.
        let mut ring = [CellId(0); 64];
        let mut len = 0;
        map.for_each_dihedral(d, 2, 3, |x| {
            let t = map.cell_id(3, x);
            if len <= ring.len() && !ring[..len.min(ring.len())].contains(&t) {
                if len < ring.len() {
                    ring[len] = t;
                }
                len += 1;
            }
        });
        if len > ring.len() {
            let tets = distinct(map.cell_darts(1, d).into_iter().map(|x| map.cell_id(3, x)));
            return tets.iter().map(k).sum();
        }
        ring[..len].sort_unstable();
        ring[..len].iter().map(k).sum()
    }

    /// Sets the mass and viscosity of the vertex of `d` from law 1 and law 4.
    fn recompute_vertex(&mut self, map: &GMap<3>, d: DartId) {
        let mass = self.vertex_mass_from_map_raw(map, d);
        self.set_vertex_mass(map.vertex_id(d), mass);
    }

    /// Sets the mass of vertex `v` and its viscosity from law 4.
    fn set_vertex_mass(&mut self, v: CellId, mass: f64) {
        self.vertex_mass[v] = mass;
        self.vertex_viscosity[v] = self.material.viscosity * mass;
    }

    /// Law 1 for the vertex whose orbit is exactly `darts` (in any order): Σ m_t/4 over their
    /// distinct volumes, summed in increasing id order as [`Mechanics::vertex_mass_from_map`]
    /// does, so the two agree bit for bit. O(|darts| log |darts|), no walk.
    fn vertex_mass_of_darts(&self, map: &GMap<3>, darts: &[DartId]) -> f64 {
        // Distinct volumes in a small array (a corner's darts share one, and the kernel's walk
        // meets them close together); past its size, the general path.
        let mut volumes = [CellId(u32::MAX); 64];
        let mut len = 0;
        for &x in darts {
            let t = map.cell_id(3, x);
            if volumes[..len].contains(&t) {
                continue;
            }
            if len == volumes.len() {
                return distinct(darts.iter().map(|&x| map.cell_id(3, x)))
                    .iter()
                    .map(|&t| self.tet_mass[t] / 4.0)
                    .sum();
            }
            volumes[len] = t;
            len += 1;
        }
        volumes[..len].sort_unstable();
        volumes[..len].iter().map(|&t| self.tet_mass[t] / 4.0).sum()
    }

    /// Sets the stiffness and damping of the edge of `d` from laws 2 and 3.
    fn recompute_edge(&mut self, map: &GMap<3>, d: DartId) {
        let e = map.cell_id(1, d);
        self.edge_stiffness[e] = self.edge_stiffness_from_map_raw(map, d);
        self.edge_damping[e] = self.material.damping * self.edge_stiffness[e];
    }

    /// Re-applies the pin set from a predicate on rest positions: `pin(v, rest)`. O(vertex ids).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// body.attrs_mut().pin_where(|_, rest| rest[2] == 0.0); // the bottom face
    /// assert_eq!(body.attrs().pinned().as_slice().iter().filter(|&&p| p).count(), 4);
    /// ```
    pub fn pin_where(&mut self, mut pin: impl FnMut(CellId, Vec3) -> bool) {
        self.pins_epoch = crate::gmap::next_unique();
        for (i, (p, r)) in self.pinned.as_mut_slice().iter_mut().zip(self.rest_position.as_slice()).enumerate() {
            *p = pin(CellId(i as u32), *r);
        }
    }

    fn copy_vertex(&mut self, from: CellId, to: CellId) {
        self.rest_position[to] = self.rest_position[from];
        self.position[to] = self.position[from];
        self.velocity[to] = self.velocity[from];
        self.pinned[to] = self.pinned[from];
        self.force[to] = [0.0; 3];
    }

    fn merge_vertex_state(&mut self, kept: CellId, absorbed: CellId) {
        let (m1, m2) = (self.vertex_mass[kept], self.vertex_mass[absorbed]);
        let total = m1 + m2;
        let (w1, w2) = if total > 0.0 { (m1 / total, m2 / total) } else { (0.5, 0.5) };
        // Component by component; equal components are kept as they are (w1 + w2 may differ
        // from 1 by a rounding, and w1·p + w2·p moved a pinned vertex sewn back onto itself by
        // one ulp: round 26).
        let mix = |a: Vec3, b: Vec3| std::array::from_fn(|k| if a[k] == b[k] { a[k] } else { w1 * a[k] + w2 * b[k] });
        // A pin holds its vertex: when exactly one side is pinned, the merged vertex is where
        // that side is, with its velocity (round 27: a sew moved a pin by the other side's
        // offset, weighted by mass). Both pinned at two places: the weighted mean, as unpinned.
        match (self.pinned[kept], self.pinned[absorbed]) {
            (true, false) => {}
            (false, true) => {
                self.position[kept] = self.position[absorbed];
                self.velocity[kept] = self.velocity[absorbed];
            }
            _ => {
                self.position[kept] = mix(self.position[kept], self.position[absorbed]);
                self.velocity[kept] = mix(self.velocity[kept], self.velocity[absorbed]);
            }
        }
        self.pinned[kept] = self.pinned[kept] || self.pinned[absorbed];
        self.vertex_mass[absorbed] = 0.0;
        self.vertex_viscosity[absorbed] = 0.0;
    }
}

/// Law 2's per-tet term: k_{t,e} = E·|V|/L², zero for a zero-length edge (or E = 0, V = 0). O(1).
///
/// Computed as (E·|V|)/(L·L) when both products are normal numbers (every ordinary input: the
/// same bits as ever); otherwise, for finite inputs, in wide floats (`crate::wide`: an `f64`
/// mantissa with an unbounded exponent, the same rounding), so that E·|V| overflowing or L² under- or overflowing does not
/// make a finite k infinite or zero: k is ∞ or 0 only when it is itself past `f64::MAX` or below
/// the smallest subnormal.
///
/// # Examples
///
/// ```
/// use topomech::mechanics::model::stiffness_contribution;
///
/// assert_eq!(stiffness_contribution(1000.0, 0.5, 2.0), 125.0); // E·V/L²
/// assert_eq!(stiffness_contribution(1000.0, -0.5, 2.0), 125.0); // |V|
/// assert_eq!(stiffness_contribution(1000.0, 0.5, 0.0), 0.0); // a zero-length edge carries nothing
/// let k = stiffness_contribution(1e300, 1e15, 1e5); // E·V alone is past f64::MAX
/// assert!((k / 1e305 - 1.0).abs() < 1e-15);
/// ```
pub fn stiffness_contribution(young: f64, volume: f64, rest_length: f64) -> f64 {
    if rest_length.is_nan() || rest_length <= 0.0 || young == 0.0 || volume == 0.0 {
        return 0.0;
    }
    let (ev, ll) = (young * volume.abs(), rest_length * rest_length);
    let finite = young.is_finite() && volume.is_finite() && rest_length.is_finite();
    if !finite || (ev.is_normal() && ll.is_normal()) {
        return ev / ll;
    }
    use crate::wide::Wide;
    let l = Wide::new(rest_length);
    Wide::new(young).mul(Wide::new(volume.abs())).div(l.mul(l)).to_f64()
}

/// The corner pairs of a tet, in the order of [`tet_stiffnesses`].
pub(crate) const TET_PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Law 2's six terms of the tet with corners `c` (no volume stored): k_{t,e} = E·|V|/L_e² for the
/// corner pairs of [`TET_PAIRS`], with L_e = [`super::geom::rest_length`]. For ordinary corners
/// ([`super::geom::plain_corners`]) V is the plain determinant and each term is
/// [`stiffness_contribution`] (the same bits as ever); otherwise E·|V|/L² is taken in wide floats
/// (`crate::wide`: an f64 mantissa, an unbounded exponent), so a tet whose volume under- or
/// overflows f64 (edge 1e-110; a needle 1e-170 thin beside a unit edge; a sliver 1e200 wide and
/// 1e-200 thick) gets its finite terms. O(1).
pub(crate) fn tet_stiffnesses(young: f64, c: [Vec3; 4]) -> [f64; 6] {
    if super::geom::plain_corners(c) {
        let volume = dot(cross(sub(c[1], c[0]), sub(c[2], c[0])), sub(c[3], c[0])) / 6.0;
        return TET_PAIRS.map(|(i, j)| stiffness_contribution(young, volume, super::geom::rest_length(c[i], c[j])));
    }
    use crate::wide::{difference, norm, six_volume, Wide};
    let ev = Wide::new(young).mul(six_volume(c[0], c[1], c[2], c[3]).abs()).div(Wide::new(6.0));
    TET_PAIRS.map(|(i, j)| {
        let length = norm(difference(c[j], c[i]));
        if !length.is_positive() || young == 0.0 || ev.is_zero() {
            return 0.0;
        }
        ev.div(length.mul(length)).to_f64()
    })
}

/// The distinct values of `ids`, sorted.
pub(crate) fn distinct(ids: impl Iterator<Item = CellId>) -> Vec<CellId> {
    let mut v: Vec<CellId> = ids.collect();
    v.sort_unstable();
    v.dedup();
    v
}

impl CellRules<3> for Mechanics {
    type Error = ConservationError;

    fn grow_to(&mut self, map: &GMap<3>) {
        let (nv, ne, nf, nt) = (map.cell_id_bound(0), map.cell_id_bound(1), map.cell_id_bound(2), map.cell_id_bound(3));
        self.tet_rest_volume.grow(nt, 0.0);
        self.tet_mass.grow(nt, 0.0);
        self.tet_young.grow(nt, 0.0);
        self.edge_rest_length.grow(ne, 0.0);
        self.edge_stiffness.grow(ne, 0.0);
        self.edge_damping.grow(ne, 0.0);
        self.face_boundary.grow(nf, false);
        self.face_normal.grow(nf, [0.0; 3]);
        self.vertex_mass.grow(nv, 0.0);
        self.vertex_viscosity.grow(nv, 0.0);
        self.rest_position.grow(nv, [0.0; 3]);
        self.position.grow(nv, [0.0; 3]);
        self.velocity.grow(nv, [0.0; 3]);
        self.force.grow(nv, [0.0; 3]);
        self.pinned.grow(nv, false);
    }

    fn on_split(&mut self, map: &GMap<3>, split: &Split<'_>) {
        let Split { dim, kept, new, dart_kept, dart_new, new_side } = *split;
        match dim {
            0 => {
                self.copy_vertex(kept, new);
                self.recompute_vertex(map, dart_kept);
                // The new side's darts are known: its volumes without walking it again.
                let mass = if new_side.is_empty() {
                    self.vertex_mass_from_map_raw(map, dart_new)
                } else {
                    self.vertex_mass_of_darts(map, new_side)
                };
                self.set_vertex_mass(new, mass);
            }
            1 => {
                self.edge_rest_length[new] = self.edge_rest_length[kept];
                self.recompute_edge(map, dart_kept);
                self.recompute_edge(map, dart_new);
            }
            3 => {
                self.tet_rest_volume[new] = 0.0;
                self.tet_mass[new] = 0.0;
                self.tet_young[new] = self.tet_young[kept];
            }
            _ => {} // faces: after_operation
        }
    }

    /// Only a 3-sew glues tetrahedra (face to face): an i-sew with i ≤ 2 links darts inside what
    /// must stay one closed tet, joining two volumes into one that no law covers (a 1-sew of two
    /// tets makes a 7-vertex volume) or changing a tet's own cells: refused with
    /// [`ConservationError::SewInsideVolume`]. A 3-sew merges the vertices of each linked pair;
    /// they must have the same rest position, exactly (as the two sides of a dissociated face do:
    /// a split copies it), or the rest lengths of one side's edges would no longer be the
    /// distances of their ends ([`ConservationError::SewApart`]). O(pairs).
    fn check_sew(&self, map: &GMap<3>, i: usize, pairs: &[(DartId, DartId)]) -> Result<(), ConservationError> {
        // A defence: short attributes (replaced whole before round 27).
        self.check_covers(map)?;
        if let (true, Some(&(x, y))) = (i <= 2, pairs.first()) {
            let (volume, other_volume) = (map.cell_id(3, x), map.cell_id(3, y));
            return Err(ConservationError::SewInsideVolume { dart: x, other: y, i, volume, other_volume });
        }
        for &(x, y) in pairs {
            let (vx, vy) = (map.vertex_id(x), map.vertex_id(y));
            let (p, q) = (self.rest_position[vx], self.rest_position[vy]);
            if vx != vy && p != q {
                let distance = norm(sub(p, q));
                return Err(ConservationError::SewApart { dart: x, other: y, vertex: vx, other_vertex: vy, distance });
            }
        }
        Ok(())
    }

    /// Only a 3-unsew (a face dissociation) cuts a body: it splits vertices, edges and faces
    /// *between* tets with the rules above. A 0-unsew would give an edge's two ends one vertex
    /// (law 3 has no rest length for it): refused with [`ConservationError::UnsewEdge`]. A 1- or
    /// 2-unsew would open a tet, splitting a vertex or an edge *inside* it (a tet with five
    /// vertices breaks law 1; both halves of an edge split inside one tet would get its whole
    /// term of law 2, creating stiffness): refused with [`ConservationError::UnsewOpensTet`].
    /// A dart that is not live or already i-free is left to the kernel's own error. O(1).
    fn check_unsew(&self, map: &GMap<3>, i: usize, d: DartId) -> Result<(), ConservationError> {
        self.check_covers(map)?;
        if i > 2 || !map.contains(d) || map.is_free(i, d) {
            return Ok(());
        }
        Err(match i {
            0 => ConservationError::UnsewEdge { dart: d, edge: map.cell_id(1, d) },
            _ => ConservationError::UnsewOpensTet { dart: d, i, volume: map.cell_id(3, d) },
        })
    }

    fn on_merge(&mut self, _map: &GMap<3>, dim: usize, kept: CellId, absorbed: CellId) {
        match dim {
            // Masses and stiffnesses of merged cells are recomputed in `after_operation`, which
            // knows the (un)linked darts and so finds a dart of `kept` in O(1).
            0 => self.merge_vertex_state(kept, absorbed),
            1 => {
                self.edge_stiffness[absorbed] = 0.0;
                self.edge_damping[absorbed] = 0.0;
            }
            3 => {
                self.tet_rest_volume[kept] += self.tet_rest_volume[absorbed];
                self.tet_mass[kept] += self.tet_mass[absorbed];
                self.tet_rest_volume[absorbed] = 0.0;
                self.tet_mass[absorbed] = 0.0;
            }
            _ => {}
        }
    }

    fn after_operation(&mut self, map: &GMap<3>, changes: &CellChanges) {
        for (dim, recompute) in
            [(0, Self::recompute_vertex as fn(&mut Self, &GMap<3>, DartId)), (1, Self::recompute_edge)]
        {
            for (kept, _) in changes.merges(dim) {
                if let Some(d) = dart_of(map, dim, kept, changes) {
                    recompute(self, map, d);
                }
            }
        }
        // Once per face: every dart of a face gives the same flag and normal (a face is α3-free
        // on all of its ⟨α0, α1⟩ orbit or on none of it).
        let (mut recent, mut done) = ([CellId(u32::MAX); 4], Vec::new());
        for d in changes.pairs.iter().flat_map(|&(a, b)| [a, b]) {
            let f = map.cell_id(2, d);
            if recent.contains(&f) || done.contains(&f) {
                continue;
            }
            // The first faces met are kept on the stack (an α3 unsew meets two).
            match recent.iter_mut().find(|r| r.0 == u32::MAX) {
                Some(r) => *r = f,
                None => done.push(f),
            }
            self.face_boundary[f] = map.is_free(3, d);
            self.face_normal[f] = if self.face_boundary[f] { self.outward_normal(map, d) } else { [0.0; 3] };
        }
    }

    /// The conservation laws ([`check_conservation`]), then the face law
    /// ([`Mechanics::check_faces`]).
    fn check(&self, map: &GMap<3>) -> Result<(), ConservationError> {
        check_conservation(map, self)?;
        self.check_faces(map)
    }
}

impl Mechanics {
    /// The face law: every live face f of `map` is flagged boundary iff it is α3-free (the flag
    /// is derived from the topology; the surface and the boundary forces read it), and an inner
    /// face's normal is zero. (A boundary face's normal is computed from the positions at the
    /// last change, which may be anything, so its value is not checked here; the store checks
    /// that it is a unit vector or zero before saving.) O(darts).
    ///
    /// # Errors
    /// [`ConservationError::MissingAttributes`] for a map the arrays do not cover,
    /// [`ConservationError::FaceFlag`] or [`ConservationError::InnerFaceNormal`] naming the
    /// first face that breaks the law.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// body.unsew3(d).unwrap(); // both sides become boundary faces
    /// assert!(body.attrs().check_faces(body.map()).is_ok());
    /// ```
    pub fn check_faces(&self, map: &GMap<3>) -> Result<(), ConservationError> {
        self.check_covers(map)?;
        for dart in map.one_dart_per_cell(2) {
            let (face, free) = (map.cell_id(2, dart), map.is_free(3, dart));
            if self.face_boundary[face] != free {
                return Err(ConservationError::FaceFlag { face, dart, flagged_boundary: !free });
            }
            let normal = self.face_normal[face];
            if !free && normal != [0.0; 3] {
                return Err(ConservationError::InnerFaceNormal { face, dart, normal });
            }
        }
        Ok(())
    }
}

/// The vertex ids of the face ⟨α0, α1⟩(d), sorted, if there are exactly three. O(face), no
/// allocation.
pub(crate) fn triangle_vertices(map: &GMap<3>, d: DartId) -> Option<[CellId; 3]> {
    let mut ids = [CellId(u32::MAX); 4];
    let mut count = 0;
    map.for_each_dihedral(d, 0, 1, |x| {
        let v = map.vertex_id(x);
        if count < 4 && !ids[..count].contains(&v) {
            ids[count] = v;
            count += 1;
        }
    });
    if count != 3 {
        return None;
    }
    let mut face = [ids[0], ids[1], ids[2]];
    face.sort_unstable();
    Some(face)
}

/// [`triangle_vertices`] for a dart `d` whose face is known to close as a hexagon (as in a closed
/// tet, [`GMap::closed_tet_darts`], or after the tear's six-dart check): its face
/// ⟨α0, α1⟩(d) is then the closed hexagon d, α1 d, α0 d, α1 α0 d, α0 α1 d, α1 α0 α1 d, whose
/// ⟨α1⟩ pairs share a vertex (α1 is in the vertex orbit), so its distinct vertex ids are those of
/// d, α0 d and α0 α1 d: three loads of ids, the links computed for tets as built
/// ([`GMap::alpha_local`]), else two loads; no walk. O(1).
pub(crate) fn closed_triangle_vertices(map: &GMap<3>, d: DartId) -> Option<[CellId; 3]> {
    let mut face = [
        map.vertex_id(d),
        map.vertex_id(map.alpha_local(0, d)),
        map.vertex_id(map.alpha_local(0, map.alpha_local(1, d))),
    ];
    face.sort_unstable();
    (face[0] != face[1] && face[1] != face[2]).then_some(face)
}

/// A dart carrying the `dim`-cell `id` among the darts an operation (un)linked. O(pairs).
fn dart_of(map: &GMap<3>, dim: usize, id: CellId, changes: &CellChanges) -> Option<DartId> {
    changes.pairs.iter().flat_map(|&(a, b)| [a, b]).find(|&d| map.cell_id(dim, d) == id)
}

/// For each live vertex id, the input point it stands for (pinched points have several ids).
///
/// Uses the builder's documented dart numbering: dart 24t + 6f + k lies on face f of tet t, the
/// face opposite local corner f, so corner j's vertex id is the one of tet t missing from face j.
fn vertex_points(map: &GMap<3>, tets: &[[u32; 4]]) -> Vec<u32> {
    let mut point_of = vec![u32::MAX; map.cell_id_bound(0)];
    for (t, tet) in tets.iter().enumerate() {
        let ids: Vec<CellId> = (0..24).map(|k| map.vertex_id(DartId((24 * t + k) as u32))).collect();
        let all = distinct(ids.iter().copied());
        for (j, &point) in tet.iter().enumerate() {
            let face = &ids[6 * j..6 * j + 6];
            if let Some(&v) = all.iter().find(|v| !face.contains(v)) {
                point_of[v.index()] = point;
            }
        }
    }
    point_of
}

/// The totals a model's build accumulates tet by tet (mass, stiffness and damping over all
/// springs), to refuse the first tet from which one stops being finite: all terms are
/// non-negative, so every partial sum (a vertex mass, a spring's stiffness) is bounded by its total.
#[derive(Default)]
pub(crate) struct ModelTotals {
    mass: f64,
    stiffness: f64,
}

impl ModelTotals {
    /// Adds tet `t` (its corners and volume) to the totals.
    ///
    /// # Errors
    /// [`ModelError::DegenerateTet`] for a zero volume (its determinant decided in wide floats,
    /// `geom::is_flat`), [`ModelError::VolumeUnderflow`] for a tet that is not
    /// flat but whose volume is below the normal range of f64 (the model stores rest volumes),
    /// [`ModelError::MassTooSmall`] when a quarter of the tet's mass has no finite inverse (every
    /// vertex mass is at least the quarter of one of its tets' masses, so this keeps every 1/m_v
    /// finite), [`ModelError::Overflow`] when the volume or a total is no longer finite. O(1).
    pub(crate) fn add(&mut self, t: usize, c: [Vec3; 4], volume: f64, m: &Material) -> Result<(), ModelError> {
        if volume == 0.0 && super::geom::is_flat(c) {
            return Err(ModelError::DegenerateTet { tet: t });
        }
        if volume.is_finite() && !volume.is_normal() {
            return Err(ModelError::VolumeUnderflow { tet: t, volume });
        }
        let mass = m.density * volume;
        if !(4.0 / mass.abs()).is_finite() {
            return Err(ModelError::MassTooSmall { tet: t, mass });
        }
        self.mass += m.density * volume;
        for (i, j) in TET_PAIRS {
            self.stiffness += stiffness_contribution(m.young, volume, super::geom::rest_length(c[i], c[j]));
        }
        let totals = [("volume", volume), ("total mass", self.mass), ("total stiffness", self.stiffness)];
        let damping = ("total damping", m.damping * self.stiffness);
        match totals.into_iter().chain([damping]).find(|(_, v)| !v.is_finite()) {
            Some((quantity, value)) => Err(ModelError::Overflow { tet: t, quantity, value }),
            None => Ok(()),
        }
    }
}

pub(crate) fn check_material(m: &Material) -> Result<(), ModelError> {
    let bad = |name, value: f64, rule| ModelError::BadMaterial { name, value, rule };
    if !(m.density.is_finite() && m.density > 0.0) {
        return Err(bad("density", m.density, "> 0"));
    }
    if !(m.young.is_finite() && m.young >= 0.0) {
        return Err(bad("young", m.young, ">= 0"));
    }
    if !(m.damping.is_finite() && m.damping >= 0.0) {
        return Err(bad("damping", m.damping, ">= 0"));
    }
    if !(m.viscosity.is_finite() && m.viscosity >= 0.0) {
        return Err(bad("viscosity", m.viscosity, ">= 0"));
    }
    Ok(())
}

impl Embedded<3, Mechanics> {
    /// Builds the map of `tets` over `points` ([`GMap::from_tets`]) and every mechanical
    /// attribute from the laws, at rest (positions = points, velocities zero, nothing pinned).
    /// O(T log T).
    ///
    /// # Errors
    /// [`ModelError`]: bad material, non-finite point, zero-volume tet, a tet whose volume is below
    /// the normal range of f64 ([`ModelError::VolumeUnderflow`]), a volume or total (mass,
    /// stiffness, damping) that overflows f64, or a build error.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{check_conservation, Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, report) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.map().count_cells().0, vec![8, 19, 18, 6]);
    /// assert!(report.pinched_vertices.is_empty());
    /// let m = body.attrs();
    /// assert_eq!(m.rest_position().as_slice(), &points[..]); // vertex id = point index
    /// assert_eq!(m.position().as_slice(), m.rest_position().as_slice()); // at rest
    /// check_conservation(body.map(), m).unwrap();
    /// ```
    pub fn from_tets(
        points: &[Vec3],
        tets: &[[u32; 4]],
        material: Material,
    ) -> Result<(Body, BuildReport), ModelError> {
        check_material(&material)?;
        if let Some((point, &coords)) = points.iter().enumerate().find(|(_, p)| p.iter().any(|c| !c.is_finite())) {
            return Err(ModelError::NonFinitePoint { point, coords });
        }
        let (map, report) = GMap::<3>::from_tets(points.len(), tets)?;
        let mut mech = Mechanics::empty(material);
        mech.grow_to(&map);
        let mut totals = ModelTotals::default();
        for (t, tet) in tets.iter().enumerate() {
            let [a, b, c, d] = tet.map(|v| points[v as usize]);
            let volume = tet_volume(a, b, c, d);
            totals.add(t, [a, b, c, d], volume, &material)?;
            mech.tet_rest_volume[CellId(t as u32)] = volume;
            mech.tet_mass[CellId(t as u32)] = material.density * volume;
            mech.tet_young[CellId(t as u32)] = material.young;
        }
        for (v, &p) in vertex_points(&map, tets).iter().enumerate() {
            if p != u32::MAX {
                mech.rest_position.as_mut_slice()[v] = points[p as usize];
            }
        }
        mech.position = mech.rest_position.clone();
        mech.init_from_map(&map);
        Ok((Embedded::from_checked_parts(map, mech), report))
    }

    /// Dissociates the face of `d` from its neighbour: 3-unsews it and applies the split rules
    /// (vertex split → masses recomputed, m = m1 + m2; edge split → stiffnesses recomputed,
    /// k = k1 + k2; both faces become boundary faces with their own normals). The operation the
    /// cutting of the next issue is made of. Cost: the kernel's unsew + O(split cells).
    ///
    /// # Errors
    /// [`BodyError::Sew`] if `d` is 3-free or not a dart; [`BodyError::Check`] under
    /// `expensive-checks` if a conservation law broke (a bug).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{check_conservation, Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let mass = body.total_vertex_mass();
    /// body.unsew3(d).unwrap();
    /// assert!(body.map().is_free(3, d));
    /// assert!((body.total_vertex_mass() - mass).abs() < 1e-12); // m = m1 + m2
    /// check_conservation(body.map(), body.attrs()).unwrap();
    /// ```
    pub fn unsew3(&mut self, d: DartId) -> Result<CellChanges, BodyError> {
        self.unsew(3, d)
    }

    /// Sews two boundary faces back together (the inverse of [`Body::unsew3`]): merged vertices
    /// take mass-weighted positions and velocities (the pinned side's when only one side is
    /// pinned), masses and stiffnesses are recomputed.
    ///
    /// # Errors
    /// As [`Body::unsew3`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{check_conservation, Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let cells = body.map().count_cells();
    /// let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
    /// let e = body.map().alpha::<3>(d);
    /// body.unsew3(d).unwrap();
    /// body.sew3(d, e).unwrap();
    /// assert_eq!(body.map().count_cells(), cells);
    /// check_conservation(body.map(), body.attrs()).unwrap();
    /// ```
    pub fn sew3(&mut self, d1: DartId, d2: DartId) -> Result<CellChanges, BodyError> {
        self.sew(3, d1, d2)
    }

    /// Recomputes the face attributes from the body's own map and the current positions: each
    /// live face's boundary flag is whether it is α3-free, its normal the outward unit normal
    /// (a boundary face; zero if degenerate) or zero (an inner face). Not a topological change:
    /// the version stays. O(darts).
    ///
    /// # Errors
    /// [`ConservationError::MissingAttributes`] when the attributes do not cover the map (a
    /// defence: no public way leads there since round 27); nothing changes then.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let map = body.map();
    /// let faces: Vec<_> = map.one_dart_per_cell(2).into_iter().map(|d| map.cell_id(2, d)).collect();
    /// let top = *faces.iter().find(|&&f| body.attrs().face_normal(f) == [0.0, 0.0, 1.0]).unwrap();
    /// body.attrs_mut().position_mut().as_mut_slice().iter_mut().for_each(|p| p[2] = -p[2]); // mirror in z
    /// body.update_normals().unwrap();
    /// assert_eq!(body.attrs().face_normal(top), [0.0, 0.0, -1.0]); // the top face now faces down
    /// assert_eq!(body.version(), 0);
    /// ```
    ///
    /// The attributes alone take no map for this any more (a copy of the map taken before a cut,
    /// or another body's map of the same size, passed the size check and rewrote the flags from
    /// the wrong topology), so this does not compile:
    ///
    /// ```compile_fail
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let stale = body.map().clone();
    /// body.attrs_mut().update_normals(&stale).unwrap();
    /// ```
    pub fn update_normals(&mut self) -> Result<(), ConservationError> {
        let (map, mech) = self.map_and_attrs_mut();
        mech.check_covers(map)?;
        mech.update_normals_raw(map);
        Ok(())
    }

    /// Total kinetic energy ½ Σ m_v |v_v|² over live vertices. O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert_eq!(body.kinetic_energy(), 0.0); // at rest
    /// body.attrs_mut().velocity_mut().as_mut_slice().fill([2.0, 0.0, 0.0]);
    /// let mass = body.total_vertex_mass();
    /// assert!((body.kinetic_energy() - 0.5 * mass * 4.0).abs() < 1e-12); // ½ m v²
    /// ```
    pub fn kinetic_energy(&self) -> f64 {
        self.kinetic_energy_of_attrs()
    }

    /// Total vertex mass Σ_v m_v of the body ([`Mechanics::total_vertex_mass`] on its own map and
    /// attributes, which always cover each other). O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(1);
    /// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// assert!((body.total_vertex_mass() - 1.0).abs() < 1e-12 && (body.total_tet_mass() - 1.0).abs() < 1e-12);
    /// ```
    pub fn total_vertex_mass(&self) -> f64 {
        self.attrs().total_vertex_mass_raw(self.map())
    }

    /// Total tet mass Σ_t m_t of the body. O(darts).
    pub fn total_tet_mass(&self) -> f64 {
        self.attrs().total_tet_mass_raw(self.map())
    }

    /// ½ Σ m_v |v_v|² over the live vertices. O(darts).
    fn kinetic_energy_of_attrs(&self) -> f64 {
        let m = self.attrs();
        let live = self.map().one_dart_per_cell(0);
        live.into_iter()
            .map(|d| {
                let v = self.map().vertex_id(d);
                0.5 * m.vertex_mass[v] * dot(m.velocity[v], m.velocity[v])
            })
            .fold(0.0, |sum, e| sum + e) // +0 for a body without vertices (`sum` starts at −0)
    }
}

impl Mechanics {
    fn empty(material: Material) -> Self {
        let z = CellArray::from_vec(Vec::new());
        Mechanics {
            material,
            tet_rest_volume: z.clone(),
            tet_mass: z.clone(),
            tet_young: z.clone(),
            edge_rest_length: z.clone(),
            edge_stiffness: z.clone(),
            edge_damping: z.clone(),
            face_boundary: CellArray::from_vec(Vec::new()),
            face_normal: CellArray::from_vec(Vec::new()),
            vertex_mass: z.clone(),
            vertex_viscosity: z,
            rest_position: CellArray::from_vec(Vec::new()),
            position: CellArray::from_vec(Vec::new()),
            velocity: CellArray::from_vec(Vec::new()),
            force: CellArray::from_vec(Vec::new()),
            pinned: CellArray::from_vec(Vec::new()),
            pins_epoch: 0,
            velocity_epoch: 0,
            position_epoch: 0,
            instance: Instance::fresh(),
        }
    }

    /// Rest lengths, stiffnesses, masses and normals of every live cell, from the laws. O(darts).
    fn init_from_map(&mut self, map: &GMap<3>) {
        for d in map.one_dart_per_cell(1) {
            let rest = sub(self.rest_position[map.vertex_id(map.alpha::<0>(d))], self.rest_position[map.vertex_id(d)]);
            self.edge_rest_length[map.cell_id(1, d)] = super::geom::rest_length([0.0; 3], rest);
            self.recompute_edge(map, d);
        }
        for d in map.one_dart_per_cell(0) {
            self.recompute_vertex(map, d);
        }
        self.update_normals_raw(map);
    }

    /// Marks the live vertex ids of `map`: `live[v]` is true iff vertex id v has darts. O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Body, Material, Mechanics};
    ///
    /// // Point 4 is used by no tet: its vertex id is free.
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [7.0; 3]];
    /// let (body, _) = Body::from_tets(&points, &[[0, 1, 2, 3]], Material::default()).unwrap();
    /// assert_eq!(Mechanics::live_vertices(body.map()), vec![true, true, true, true, false]);
    /// ```
    pub fn live_vertices(map: &GMap<3>) -> Vec<bool> {
        let mut live = vec![false; map.cell_id_bound(0)];
        for d in map.darts() {
            live[map.vertex_id(d).index()] = true;
        }
        live
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Law 2's term has no intermediate over- or underflow: ∞ or 0 only when k itself is.
    #[test]
    fn stiffness_contribution_has_no_intermediate_overflow() {
        assert!((stiffness_contribution(1e300, 1e100, 1e100) / 1e200 - 1.0).abs() < 1e-15); // E·V = ∞ alone
        assert_eq!(stiffness_contribution(1e-300, 1e-300, 1e-300), 1.0); // E·V and L² underflow alone
        assert_eq!(stiffness_contribution(3.0, 4.0, 2.0), 3.0);
        assert_eq!(stiffness_contribution(f64::MAX, 4.0, 1.0), f64::INFINITY);
        assert_eq!(stiffness_contribution(1e-300, 1e-300, 1e300), 0.0); // k below the smallest subnormal
    }

    /// `Body::check` reports a broken law: one moved rest position (possible only inside the
    /// crate since finding 33) no longer matches the rest lengths. Found missing by the
    /// twenty-fourth mutation sample (docs/VERIFICATION.md).
    #[test]
    fn check_reports_a_moved_rest_position() {
        let (points, tets) = crate::generate::kuhn_cube(1);
        let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        assert!(body.check().is_ok());
        body.attrs_raw_mut().rest_position[CellId(0)][0] += 0.25;
        assert!(matches!(body.check(), Err(ConservationError::RestLength { .. })));
    }

    /// The face law of `Body::check`: a nonzero normal on an inner face (possible only inside
    /// the crate) is named, as a flipped flag is.
    #[test]
    fn check_names_an_inner_face_normal_and_a_flipped_flag() {
        let (points, tets) = crate::generate::kuhn_cube(1);
        let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        let d = body.map().darts().find(|&d| !body.map().is_free(3, d)).unwrap();
        let f = body.map().cell_id(2, d);
        body.attrs_raw_mut().face_normal[f] = [1.0, 0.0, 0.0];
        let e = body.check().unwrap_err();
        assert!(matches!(e, ConservationError::InnerFaceNormal { face, .. } if face == f), "{e:?}");
        body.attrs_raw_mut().face_normal[f] = [0.0; 3];
        assert!(body.check().is_ok());
        body.attrs_raw_mut().face_boundary[f] = true;
        let e = body.check().unwrap_err();
        assert!(matches!(e, ConservationError::FaceFlag { face, flagged_boundary: true, .. } if face == f), "{e:?}");
    }

    /// The O(1) outward normal equals the orbit-based one, bit for bit, at every dart of a body
    /// with dissociated faces (tets as built: the five-load path), then on its map with a tet
    /// opened inside (where the flag is down and the closure check must step aside).
    #[test]
    fn fast_outward_normal_is_the_orbit_one() {
        let (points, tets) = crate::cut::ops::jittered_cube(2, 7);
        let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        let map = body.map();
        let inner: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
        for d in inner.into_iter().step_by(2) {
            body.unsew3(d).unwrap();
        }
        let same_everywhere = |map: &GMap<3>, mech: &Mechanics| {
            let mut nonzero = 0;
            for d in map.darts() {
                let fast = mech.outward_normal(map, d);
                assert_eq!(fast, mech.outward_normal_by_orbits(map, d), "dart {d}");
                nonzero += usize::from(fast != [0.0; 3]);
            }
            assert!(nonzero > 0);
        };
        assert!(body.map().tets_as_built());
        same_everywhere(body.map(), body.attrs());
        // A body refuses to open a tet (finding 150); its plain map can, and both normals read
        // the positions by vertex id only (a 2-unsew splits an edge, no vertex).
        let (mut map, mut mech) = body.into_parts();
        map.unsew_dyn(2, DartId(0)).unwrap();
        mech.grow_to(&map);
        assert!(!map.tets_as_built());
        assert!(map.closed_tet_darts(DartId(0)).is_none());
        same_everywhere(&map, &mech);
    }

    /// A vertex split's new-side mass read off the kernel's side list equals law 1 from the map,
    /// bit for bit, and both sides' stored masses are the map's: on a jittered cube cut face by
    /// face in a scrambled order.
    #[test]
    fn new_side_mass_is_the_map_mass() {
        let (points, tets) = crate::cut::ops::jittered_cube(3, 5);
        let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        let map = body.map();
        let mut faces: Vec<DartId> = map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect();
        let mut rng = crate::generate::SplitMix64(23);
        for k in (1..faces.len()).rev() {
            faces.swap(k, rng.below(k + 1));
        }
        let (mut with_side, mut without) = (0, 0);
        for d in faces {
            let changes = body.unsew3(d).unwrap();
            let (map, mech) = (body.map(), body.attrs());
            for (k, (kept, new, dart_kept, dart_new)) in changes.splits_with_index(0) {
                let side = changes.new_side(k);
                if side.is_empty() {
                    without += 1;
                } else {
                    with_side += 1;
                    assert_eq!(mech.vertex_mass_of_darts(map, side), mech.vertex_mass_from_map_raw(map, dart_new));
                }
                assert_eq!(mech.vertex_mass(new), mech.vertex_mass_from_map_raw(map, dart_new), "new side {new}");
                assert_eq!(mech.vertex_mass(kept), mech.vertex_mass_from_map_raw(map, dart_kept), "kept side {kept}");
            }
        }
        assert!(with_side > 10, "with a side {with_side}, without {without}");
    }
}

//! The mass/spring state of a [`LeveledMap<3>`] carried through every subdivision operation
//! (issue 5, "mechanics coupling"; beyond seed 004, which stops at the topology).
//!
//! [`LeveledMechanics`] keys everything by cell ids of the finest map: one [`Spring`] per edge
//! cell, keyed by an [`EdgeKey`] (the edge's cell id and the sorted pair of its vertex ids; vertex
//! ids never change under subdivision, an edge keeps its id until it is split), one mass per volume
//! id ([`TetMasses`]), position and velocity per vertex id. Two distinct edges joining the same two
//! vertices (a cut edge whose ends stayed joined, e.g. after a tear) are two edge cells, so two
//! springs. Its operations call the map's, follow its [`LeveledMap::edge_split_log`] (which edge
//! cell each inserted vertex split, which cells the halves are) and then apply the rules below;
//! [`LeveledMechanics::check`] states them as laws.
//!
//! # Rules
//! - **Edge split** (any operation that inserts a midpoint m on an edge (a, b) with spring
//!   (L, k, c)): two springs (a, m), (m, b) with L/2, 2k, 2c. Two springs in series have
//!   compliance 1/k₁ + 1/k₂ = 1/(2k) + 1/(2k) = 1/k: the chain is exactly as stiff (and as damped,
//!   dampers in series add the same way) as the spring it replaces. The first time a spring that
//!   is not itself a half is split, it is kept as the *root* of its chain.
//! - **New vertex**: rest position = midpoint of the rest positions (the map's `points()`);
//!   position and velocity = the mean of the ends' position and velocity (linear interpolation).
//! - **New edge** (the inner edges of a face split 1→4, the octahedron diagonal): a spring with
//!   L = the distance of the rest positions, k = 0, c = 0; then every child tet t of a 1→8 adds
//!   k_{t,e} = E · V_t / L_e² (law 2 of docs/MECHANICS.md) and β · k_{t,e} to each of its six edges
//!   that is **not a half** of a split edge (halves follow the series rule only). A face split on
//!   its own (outside a 1→8) leaves its inner springs at k = 0 until a tet on either side is split.
//! - **Masses**: a tet of mass m split 1→8 gives child k the mass m · V_k / ΣV
//!   ([`LeveledMap::subdivide_tet_with_mass`]); vertex masses are derived, never stored:
//!   each volume t lumps its mass m_t on the vertices of its finest boundary
//!   ([`LeveledMechanics::vertex_masses`]): m_t/4 on each of its four corners (the seed's law 1)
//!   when no neighbour inserted a vertex on its sides; with n_t vertices of which h_t were
//!   inserted on its sides (*hanging*), each hanging vertex gets w_t = m_t / (4 n_t), drawn from
//!   the corners in proportion to its barycentric coordinates (a midpoint of (a, b) takes w/2 from
//!   each end, recursively). So Σ_v m_v = Σ_t m_t, every share is ≥ m_t / n_t > 0 (no vertex is
//!   massless), and per volume Σ_v share_v y_v = m_t · (mean of its corners' y) for any y affine
//!   on the volume (its hanging vertices at the interpolation of their parents).
//! - **Momentum** (finding F2 of round 25): an operation moves mass between vertices, Δ_v =
//!   m_v after − m_v before (a new vertex: its whole mass), which alone changes Σ_v m_v u_v by
//!   E = Σ_v Δ_v u_v. Every operation ([`LeveledMechanics::split_edge`],
//!   [`LeveledMechanics::subdivide_triangle`], [`LeveledMechanics::subdivide_tet`],
//!   [`LeveledMechanics::refine_around`]) then sets u_v ← u_v − E / M_A on
//!   A = {v : Δ_v ≠ 0}, M_A = Σ_{v ∈ A} m_v after: the least change of Σ_v m_v |δu_v|² that
//!   removes E, so **Σ_v m_v u_v is kept in every state** (up to rounding: E is a compensated
//!   sum; Δ_v is taken as computed, so a vertex whose recomputed mass differs by a rounding
//!   joins A). E = 0 exactly when the velocities of A are all equal (a rigid translation: the
//!   correction is skipped, velocities bit-identical), and E = 0 up to rounding when u is affine
//!   in the rest positions P on the volumes concerned (Σ Δ_v = 0 and Σ Δ_v P_v = 0 by the lumping
//!   law above, e.g. an affine field at rest with the inserted vertices interpolated: finding
//!   218's behaviour is unchanged).
//! - **Centre of mass and angular momentum** cannot be kept by a velocity change. On the rest
//!   positions (and on any placement x affine on the volumes concerned, e.g. a state whose
//!   inserted vertices sit where the interpolation put them) Σ_v m_v x_v = Σ_t m_t · centroid_t
//!   is kept (finding 218); otherwise an operation moves Σ_v m_v x_v by Σ_v Δ_v x_v (x the current
//!   positions, which no operation changes). The lumped angular momentum Σ_v m_v x_v × u_v is
//!   kept when it is a function of these two sums (u uniform on A, or at rest), not in general:
//!   the lumped second moment Σ m x xᵀ changes with every split (a midpoint of (a, b) taking w
//!   from a and b changes it by −w (x_a − x_b)(x_a − x_b)ᵀ / 4), so a spinning body changes its
//!   L = Σ m x × u, and the correction changes L by −(Σ_{v ∈ A} m_v x_v) × E / M_A.
//!
//! - **Cut** ([`LeveledMechanics::unsew_face`], round 42): a vertex the cut splits gives its
//!   copy its position and velocity; an edge it splits shares its spring between its two parts
//!   in parallel (k = k₁ + k₂, c = c₁ + c₂, L kept), in proportion to law 2's terms of the tets
//!   around each part (so an edge that is no half gives each part what its own tets give it);
//!   a part of a half stands beside the other part in the side of its split edge
//!   ([`SplitNode`]). Masses and Σ m u are unchanged (the volumes are).
//!
//! Consequences: a chain in tension, its midpoints at equilibrium (equal links), stores exactly its
//! root's energy, so edge splits alone keep the static response; the inner springs of a 1→8 add
//! stiffness (the refined zone is stiffer by the children's contributions). A midpoint has no
//! stiffness across its chain until inner springs hold it, so a chain of free midpoints under
//! compression can buckle sideways: a zone refined by edge splits alone is softer in compression.

use std::collections::{BTreeMap, BTreeSet};

use super::balance::LevelSplit;
use super::{EdgeSplit, LeveledMap, Refinement, SubdivideError, TetMasses};
use crate::gmap::{AlphaMask, DartId, GMap};
use crate::mechanics::geom::{compensated_sum, is_flat, rest_length, CompensatedSum, Vec3};
use crate::mechanics::model::tet_stiffnesses;
use crate::mechanics::{Material, SpringSystem};

/// The six corner pairs of a tet, in the order of [`EdgeKey`] arrays of a tet.
pub(super) const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// One edge cell of the finest map: its end vertex ids a ≤ b and its edge cell id. Ordered by
/// (a, b, id): springs come in vertex-pair order, and the edges joining the same two vertices are
/// neighbours. An edge keeps its key until it is split (vertex ids never change; an unsplit edge
/// keeps its cell id); after a split one half reuses the id with a new end, so a key never names
/// two edges.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::EdgeKey;
/// use topomech::GMap;
/// let k = EdgeKey::new(7, 5, 2);
/// assert_eq!((k.a, k.b, k.id, k.ends()), (2, 5, 7, (2, 5)));
/// assert!(EdgeKey::new(9, 0, 1) < k && k < EdgeKey::new(8, 2, 5)); // pair first, then id
/// assert_eq!(k.to_string(), "edge 7 (2, 5)");
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let d = map.darts().next().unwrap();
/// assert_eq!(EdgeKey::of(&map, d).id, map.cell_id(1, d).0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EdgeKey {
    /// The smaller end vertex id.
    pub a: u32,
    /// The larger end vertex id.
    pub b: u32,
    /// The edge cell id in the finest map.
    pub id: u32,
}

impl EdgeKey {
    /// The key of edge cell `id` joining vertices u and v (either order). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::EdgeKey;
    /// assert_eq!(EdgeKey::new(3, 4, 1), EdgeKey::new(3, 1, 4));
    /// ```
    pub fn new(id: u32, u: u32, v: u32) -> Self {
        EdgeKey { a: u.min(v), b: u.max(v), id }
    }

    /// The key of the edge of dart `d` in `map`: its cell id and the vertex ids of d and α0(d).
    /// O(1).
    ///
    /// # Panics
    /// If `d` is not below the map's capacity (as [`GMap::cell_id`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::EdgeKey;
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let d = map.darts().next().unwrap();
    /// assert_eq!(EdgeKey::of(&map, d), EdgeKey::of(&map, map.alpha_dyn(0, d)));
    /// ```
    pub fn of(map: &GMap<3>, d: DartId) -> Self {
        EdgeKey::new(map.cell_id(1, d).0, map.vertex_id(d).0, map.vertex_id(map.alpha_dyn(0, d)).0)
    }

    /// The end vertex ids (a, b), a ≤ b. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::EdgeKey;
    /// assert_eq!(EdgeKey::new(0, 9, 4).ends(), (4, 9));
    /// ```
    pub fn ends(self) -> (u32, u32) {
        (self.a, self.b)
    }
}

impl std::fmt::Display for EdgeKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "edge {} ({}, {})", self.id, self.a, self.b)
    }
}

/// One spring: rest length L, stiffness k, damping c.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::Spring;
/// let s = Spring { rest: 2.0, stiffness: 10.0, damping: 0.5 };
/// let half = s.half();
/// assert_eq!((half.rest, half.stiffness, half.damping), (1.0, 20.0, 1.0));
/// assert_eq!(1.0 / half.stiffness + 1.0 / half.stiffness, 1.0 / s.stiffness); // in series
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spring {
    /// Rest length L.
    pub rest: f64,
    /// Stiffness k.
    pub stiffness: f64,
    /// Damping c.
    pub damping: f64,
}

impl Spring {
    /// One of the two halves of this spring split at its midpoint: L/2, 2k, 2c (module docs). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::Spring;
    /// let s = Spring { rest: 1.0, stiffness: 3.0, damping: 0.0 }.half().half();
    /// assert_eq!((s.rest, s.stiffness), (0.25, 12.0));
    /// ```
    pub fn half(self) -> Spring {
        Spring { rest: self.rest / 2.0, stiffness: 2.0 * self.stiffness, damping: 2.0 * self.damping }
    }
}

/// An edge cell that was split at its midpoint, as the coupling keeps it: the midpoint's vertex
/// id and, for each side (`sides[0]` at the split edge's end `a`, `sides[1]` at `b`), the edges
/// that stand for that half now: the half itself, or the parallel parts a cut made of it
/// ([`LeveledMechanics::unsew_face`]), each of which may have been split in turn. Gluing the cut
/// back (identifying every vertex with its origin), a side is its members in parallel and the
/// edge is its two sides in series (law 4 of [`LeveledMechanics::check`]).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct SplitNode {
    /// The midpoint's vertex id when the edge was split.
    pub(super) mid: u32,
    /// The members of each side.
    pub(super) sides: [Vec<Member>; 2],
}

/// A member of a [`SplitNode`] side: an edge key and whether its end `a` is the one toward the
/// split edge's end of that side (the outer end; the other lies at the midpoint or a copy of it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Member {
    /// The member's key as it is now.
    pub(super) key: EdgeKey,
    /// Whether `key.a` is its outer end.
    pub(super) outer_at_a: bool,
}

/// Errors of the coupled operations.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics};
/// use topomech::mechanics::Material;
/// use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mut m = LeveledMap::new(map, pts);
/// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
/// let d = m.map().darts().next().unwrap();
/// m.split_edge(d, 1).unwrap(); // behind the coupling's back
/// let e = mech.split_edge(&mut m, d, 2).unwrap_err();
/// assert!(matches!(e, CouplingError::OutOfSync { applied: 0, logged: 1 }));
/// assert!(LeveledMechanics::new(&m, Material::default()).is_err()); // not at level 0
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CouplingError {
    /// The map refused the operation (map and mechanics unchanged).
    #[error(transparent)]
    Subdivide(#[from] SubdivideError),
    /// The coupling starts from a map with no operation done (level 0).
    #[error("the map is at level {0}: a coupling starts from a level-0 map")]
    NotLevelZero(u8),
    /// A vertex has no rest position (the map was built without geometry).
    #[error("vertex {0} has no rest position: the leveled map needs its points")]
    NoGeometry(u32),
    /// A live volume has no mass, or a negative or non-finite one ([`LeveledMechanics::with_masses`]).
    #[error("volume {volume} has no valid mass (given: {given:?})")]
    BadMass {
        /// The volume cell id.
        volume: u32,
        /// The mass given for it, if any.
        given: Option<f64>,
    },
    /// The map inserted vertices the coupling did not see (an operation called on the map alone).
    #[error("the coupling applied {applied} vertex insertions but the map logged {logged}")]
    OutOfSync {
        /// Insertions the coupling followed.
        applied: usize,
        /// Insertions in [`LeveledMap::split_log`].
        logged: usize,
    },
    /// The map split an edge cell that has no spring (a bug, or a tampered coupling).
    #[error("{0} was split but has no spring")]
    NoSpring(EdgeKey),
    /// The coupling holds a state (position, velocity) for another number of vertex ids than the
    /// map has: it was built for another map, the map changed behind its back (a cut), or its
    /// state vectors were resized. Refused before the map changes.
    #[error(
        "the coupling holds {states} vertex states but the map has {vertices} vertex ids: not this map's coupling"
    )]
    StateCount {
        /// Entries of [`LeveledMechanics::position`] / [`LeveledMechanics::velocity`] (the fewer).
        states: usize,
        /// The map's vertex id bound.
        vertices: usize,
    },
    /// The map changed by an operation the coupling did not follow: called on the map alone, and
    /// neither inserting a vertex ([`CouplingError::OutOfSync`]) nor adding a vertex id
    /// ([`CouplingError::StateCount`]) — a [`LeveledMap::unsew_face`] that splits an edge but no
    /// vertex (the coupled cut is [`LeveledMechanics::unsew_face`]), or a subdivision whose edges
    /// were all split before. Its new edge cells have no spring. Refused before the map changes.
    #[error("the map is at version {version} but the coupling followed it up to version {followed}: an operation was called on the map alone")]
    Unfollowed {
        /// The map's [`LeveledMap::version`] after the last operation the coupling followed.
        followed: u64,
        /// The map's version now.
        version: u64,
    },
    /// The map is not the one the coupling follows: built apart (even from the same mesh, with
    /// the same size and version) or a clone that changed on its own since the coupling last
    /// followed it ([`LeveledMap`] carries a stamp of its state; round 25: a coupling refined
    /// another map of the same size with `Ok` and rest lengths of the first). Refused before the
    /// map changes.
    #[error("the map is not the one this coupling follows (another map, or a copy changed on its own)")]
    OtherMap,
    /// A material constant is refused ([`crate::mechanics::ModelError::BadMaterial`], as for a
    /// [`crate::mechanics::Body`]): by the constructors, and by every operation before the map
    /// changes, since [`LeveledMechanics::material`] is a public field.
    #[error(transparent)]
    Material(crate::mechanics::ModelError),
    /// A level-0 tet has zero volume: it would get no mass and no stiffness (a
    /// [`crate::mechanics::Body`] refuses it too). Decided on its determinant taken in wide
    /// floats, so a tet whose volume underflows f64 (tiny, or a needle) is not one.
    #[error("volume {volume} ({dart}) has zero volume")]
    DegenerateTet {
        /// The volume cell id.
        volume: u32,
        /// A dart of it.
        dart: DartId,
    },
    /// A spring of a level-0 tet would hold a value past `f64::MAX`: its rest length (coordinates
    /// too far apart), or its stiffness or damping once this tet's term of law 2 is added (Young's
    /// modulus or the damping factor too large for the geometry). As [`crate::mechanics::Body`]
    /// refuses the same input ([`crate::mechanics::ModelError::Overflow`]); refused before the
    /// coupling exists.
    #[error("volume {volume}: the {quantity} of the spring of {edge} is {value:e}, past the range of f64 (coordinates, Young's modulus or damping too large)")]
    Overflow {
        /// The volume cell id of the tet whose term made it overflow.
        volume: u32,
        /// The edge of the spring.
        edge: EdgeKey,
        /// "rest length", "stiffness" or "damping".
        quantity: &'static str,
        /// Its value (infinite or NaN).
        value: f64,
    },
    /// A split could make a spring's stiffness or damping pass `f64::MAX`: the halves of a split
    /// spring take 2k and 2c, and the children of a 1→8 add law 2's terms to their new edges.
    /// `bound` bounds every value the operation (or, for [`LeveledMechanics::refine_around`], the
    /// whole level) would store ([`LeveledMechanics::subdivide_tet`] states it); refused when it
    /// comes within a factor 1 + 2⁻⁴⁰ of `f64::MAX`, before the map changes. `bound` is NaN
    /// when a spring on the edges concerned holds a NaN value (written through
    /// [`LeveledMechanics::spring_mut`]).
    #[error("splitting at {dart} could make a spring stiffness or damping of {bound:e}, past the range of f64")]
    SplitOverflow {
        /// A dart of the tet (or edge, or face) whose split makes the bound largest.
        dart: DartId,
        /// The bound on the values the split would store.
        bound: f64,
    },
    /// The flat system would hold a value the step loop cannot use: a non-finite gravity, or a
    /// spring value set out of range through [`LeveledMechanics::spring_mut`]
    /// ([`LeveledMechanics::spring_system`]).
    #[error("cannot project the coupling: {0}")]
    System(crate::mechanics::SystemError),
}

/// A tet of the map: its corner vertex ids (increasing) and the keys of its six edges in
/// [`PAIRS`] order (`None` for a corner pair that is no edge of its volume).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Tet0 {
    pub(super) corners: [u32; 4],
    pub(super) edges: [Option<EdgeKey>; 6],
}

/// The corners of the tet of `d` (increasing) and the keys of the edges of its volume joining each
/// corner pair of [`PAIRS`] (`None` where that pair is split or no edge). O(volume).
pub(super) fn tet_edges(m: &LeveledMap<3>, d: DartId) -> Result<Tet0, SubdivideError> {
    let corners = m.tet_vertices(d)?;
    let edges: Vec<EdgeKey> =
        m.map().orbit(d, AlphaMask::of(&[0, 1, 2])).iter().map(|&x| EdgeKey::of(m.map(), x)).collect();
    let find = |u: u32, v: u32| edges.iter().copied().find(|e| e.ends() == (u.min(v), u.max(v)));
    Ok(Tet0 { corners, edges: PAIRS.map(|(i, j)| find(corners[i], corners[j])) })
}

/// Springs, masses and vertex state of a [`LeveledMap<3>`] following its subdivision (module docs).
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::Material;
/// use topomech::subdivide::{LeveledMap, LeveledMechanics};
/// use topomech::GMap;
/// let (points, tets) = kuhn_cube(1);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let mut m = LeveledMap::new(map, points);
/// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
/// assert_eq!(mech.springs().count(), 19);
/// mech.refine_around(&mut m, [0.2, 0.2, 0.2], 0.1, 1).unwrap();
/// mech.check(&m).unwrap();
/// assert_eq!(mech.springs().count(), m.map().count_cells().0[1]); // one spring per edge cell
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LeveledMechanics {
    /// The material (ρ, E, β, ν) of every tet.
    pub material: Material,
    /// One mass per volume id.
    pub masses: TetMasses,
    /// Position per vertex id.
    pub position: Vec<Vec3>,
    /// Velocity per vertex id.
    pub velocity: Vec<Vec3>,
    /// One spring per edge cell of the finest map.
    pub(super) springs: BTreeMap<EdgeKey, Spring>,
    /// Springs that were split and were not halves themselves: their value before the split.
    pub(super) roots: BTreeMap<EdgeKey, Spring>,
    /// Every edge ever split → its midpoint and what replaced its two halves ([`SplitNode`]).
    pub(super) split_at: BTreeMap<EdgeKey, SplitNode>,
    /// The split edge each member of a [`SplitNode`] side belongs to (its key as it is now).
    pub(super) member_of: BTreeMap<EdgeKey, EdgeKey>,
    /// Halves produced by splits, and the parts a cut made of them.
    pub(super) halves: BTreeSet<EdgeKey>,
    /// Entries of the map's split log already followed.
    pub(super) applied: usize,
    /// The [`LeveledMap::version`] of the map after the last operation followed.
    pub(super) followed: u64,
    /// The map's state stamp after the last operation followed (`LeveledMap::stamp`).
    pub(super) followed_stamp: u64,
    /// Σ m_t when the coupling was built.
    pub(super) total_mass: f64,
    /// [`split_parents`] of the map, kept up to date split by split (as [`Self::applied`]), so
    /// that an operation lumps the masses of the volumes it touches without an O(vertices) pass.
    pub(super) parents: Vec<Option<(usize, [u32; 2])>>,
}

impl LeveledMechanics {
    /// The coupling of a level-0 map: masses ρ·V_t, springs from law 2 (k_e = Σ_{t ∋ e} E V_t / L_e²
    /// over the tets whose volume holds the edge cell e, c_e = β k_e, L_e the rest distance), at rest
    /// with zero velocity. Two edge cells joining the same vertices get a spring each, from their own
    /// tets. L_e and E V_t / L_e² are measured scale-safely (in wide floats, an f64 mantissa with
    /// an unbounded exponent, unless every edge-vector component is 0 or within 2^±250, where the
    /// plain formulas give the same bits), so a spring is ∞ only when its value is. O(darts + E log E).
    ///
    /// Errors: [`CouplingError::NotLevelZero`], [`CouplingError::NoGeometry`],
    /// [`CouplingError::Material`] (a material a [`crate::mechanics::Body`] refuses too),
    /// [`CouplingError::DegenerateTet`] (decided exactly on fitted corners: a regular tet of edge
    /// 1e-110 is none), [`CouplingError::Overflow`] for a rest length, stiffness or damping past
    /// `f64::MAX`, [`SubdivideError::MassOverflow`] for masses summing past it,
    /// [`SubdivideError::NonFinitePosition`], and the errors of [`LeveledMap::tet_vertices`] for a
    /// volume that is not a tet.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let mech = LeveledMechanics::new(&m, Material { young: 6.0, ..Material::default() }).unwrap();
    /// let s = mech.spring(0, 1).unwrap();
    /// assert!((s.stiffness - 1.0).abs() < 1e-12); // E V / L² = 6 · (1/6) / 1
    /// ```
    pub fn new(m: &LeveledMap<3>, material: Material) -> Result<Self, CouplingError> {
        check_start(m)?;
        let masses = TetMasses::from_density(m, material.density)?;
        Self::build(m, material, masses)
    }

    /// As [`Self::new`] with the given tet masses (indexed by volume id) instead of ρ·V_t: e.g. the
    /// masses of a [`crate::mechanics::Body`] whose map and positions the leveled map copies.
    /// O(darts + E log E).
    ///
    /// Errors: those of [`Self::new`], and [`CouplingError::BadMass`] for a live volume with no mass
    /// or a negative or non-finite one.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, TetMasses};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let mech = LeveledMechanics::with_masses(&m, Material::default(), TetMasses { mass: vec![2.0] }).unwrap();
    /// assert!((mech.vertex_masses(&m).unwrap()[3] - 0.5).abs() < 1e-15);
    /// let e = LeveledMechanics::with_masses(&m, Material::default(), TetMasses { mass: vec![] }).unwrap_err();
    /// assert_eq!(e, CouplingError::BadMass { volume: 0, given: None });
    /// ```
    pub fn with_masses(m: &LeveledMap<3>, material: Material, masses: TetMasses) -> Result<Self, CouplingError> {
        check_start(m)?;
        for d in m.map().one_dart_per_cell(3) {
            let volume = m.map().cell_id(3, d);
            let given = masses.mass.get(volume.index()).copied();
            if !given.is_some_and(|x| x.is_finite() && x >= 0.0) {
                return Err(CouplingError::BadMass { volume: volume.0, given });
            }
        }
        Self::build(m, material, masses)
    }

    /// The coupling of a checked level-0 map with these masses.
    fn build(m: &LeveledMap<3>, material: Material, masses: TetMasses) -> Result<Self, CouplingError> {
        crate::mechanics::model::check_material(&material).map_err(CouplingError::Material)?;
        let nv = m.map().cell_id_bound(0);
        let level0_tet = |d: DartId| {
            // Finite positions (NoPosition was settled by check_start) and a non-zero volume,
            // decided on fitted corners (a regular tet of edge 1e-110 has a volume below f64).
            m.tet_volume(d)?;
            let t = tet_edges(m, d)?;
            if is_flat(t.corners.map(|v| m.points()[v as usize])) {
                return Err(CouplingError::DegenerateTet { volume: m.map().cell_id(3, d).0, dart: d });
            }
            Ok((m.map().cell_id(3, d).0, t))
        };
        let tets0 = m.map().one_dart_per_cell(3).into_iter().map(level0_tet).collect::<Result<Vec<_>, _>>()?;
        let total_mass = masses.total(m);
        if !total_mass.is_finite() {
            return Err(SubdivideError::MassOverflow { total: total_mass }.into());
        }
        let mut mech = LeveledMechanics {
            material,
            total_mass,
            masses,
            position: m.points()[..nv].to_vec(),
            velocity: vec![[0.0; 3]; nv],
            springs: BTreeMap::new(),
            roots: BTreeMap::new(),
            split_at: BTreeMap::new(),
            member_of: BTreeMap::new(),
            halves: BTreeSet::new(),
            applied: m.edge_split_log().len(),
            followed: m.version(),
            followed_stamp: m.stamp(),
            parents: split_parents(m),
        };
        for (volume, t) in &tets0 {
            mech.add_tet(m, t, *volume)?;
        }
        Ok(mech)
    }

    /// The spring of the edge between vertices a and b (either order) when exactly one edge cell
    /// joins them; `None` when none or several do (see [`Self::springs_between`]). O(log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mech = LeveledMechanics::new(&LeveledMap::new(map, pts), Material::default()).unwrap();
    /// assert_eq!(mech.spring(1, 0).unwrap().rest, 2.0);
    /// assert!(mech.spring(0, 0).is_none());
    /// ```
    pub fn spring(&self, a: u32, b: u32) -> Option<Spring> {
        match self.springs_between(a, b).as_slice() {
            [(_, s)] => Some(*s),
            _ => None,
        }
    }

    /// The key of the edge between vertices a and b when exactly one edge cell joins them. O(log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// assert_eq!(mech.edge(2, 1).unwrap().ends(), (1, 2));
    /// ```
    pub fn edge(&self, a: u32, b: u32) -> Option<EdgeKey> {
        match self.springs_between(a, b).as_slice() {
            [(e, _)] => Some(*e),
            _ => None,
        }
    }

    /// Every spring of an edge cell joining vertices a and b (either order), by edge id: one per
    /// edge, so two for a cut edge whose ends stayed joined. O(log E + found).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mech = LeveledMechanics::new(&LeveledMap::new(map, pts), Material::default()).unwrap();
    /// assert_eq!(mech.springs_between(3, 0).len(), 1);
    /// assert!(mech.springs_between(0, 7).is_empty());
    /// ```
    pub fn springs_between(&self, a: u32, b: u32) -> Vec<(EdgeKey, Spring)> {
        let (a, b) = (a.min(b), a.max(b));
        let range = EdgeKey { a, b, id: 0 }..=EdgeKey { a, b, id: u32::MAX };
        self.springs.range(range).map(|(&e, &s)| (e, s)).collect()
    }

    /// The spring of the edge cell `e` of the finest level, if it has one. O(log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{EdgeKey, LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let d = m.map().darts().next().unwrap();
    /// assert!(mech.spring_at(EdgeKey::of(m.map(), d)).is_some());
    /// ```
    pub fn spring_at(&self, e: EdgeKey) -> Option<Spring> {
        self.springs.get(&e).copied()
    }

    /// Mutable access to the spring of edge cell `e` (for tests and tools; [`Self::check`] says
    /// whether the laws still hold). O(log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics, SpringLawError};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let e = mech.edge(2, 3).unwrap();
    /// mech.spring_mut(e).unwrap().stiffness *= 1.5;
    /// assert!(matches!(mech.check(&m), Err(SpringLawError::Stiffness { a: 2, b: 3, .. })));
    /// ```
    pub fn spring_mut(&mut self, e: EdgeKey) -> Option<&mut Spring> {
        self.springs.get_mut(&e)
    }

    /// Every spring of the finest level as (edge key, spring), one per edge cell, in key order
    /// (vertex pair, then edge id). O(1) per item.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mech = LeveledMechanics::new(&LeveledMap::new(map, pts), Material::default()).unwrap();
    /// let pairs: Vec<(u32, u32)> = mech.springs().map(|(e, _)| e.ends()).collect();
    /// assert_eq!(pairs, vec![(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]);
    /// ```
    pub fn springs(&self) -> impl Iterator<Item = (EdgeKey, Spring)> + '_ {
        self.springs.iter().map(|(&e, &s)| (e, s))
    }

    /// Every root: an edge cell split when it was not itself a half, with its spring at that
    /// moment, in key order. O(1) per item.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let d = m.map().darts().next().unwrap();
    /// mech.subdivide_tet(&mut m, d, 1).unwrap();
    /// assert_eq!(mech.roots().count(), 6);
    /// ```
    pub fn roots(&self) -> impl Iterator<Item = (EdgeKey, Spring)> + '_ {
        self.roots.iter().map(|(&e, &s)| (e, s))
    }

    /// The finest springs along the edge cell `e` of some level, in order from its end `e.a` to
    /// `e.b`: `e` itself if it was never split, else the chains of its two halves; where a cut
    /// made parallel parts of a half ([`Self::unsew_face`]), their chains come one after the
    /// other, each walked in the same direction. O(chain · log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let e = mech.edge(0, 1).unwrap();
    /// let d = m.map().darts().find(|&d| m.map().cell_id(1, d).0 == e.id).unwrap();
    /// mech.split_edge(&mut m, d, 1).unwrap();
    /// let chain = mech.chain(e);
    /// assert_eq!(chain.iter().map(|h| h.ends()).collect::<Vec<_>>(), vec![(0, 4), (1, 4)]);
    /// let compliance: f64 = chain.iter().map(|&h| 1.0 / mech.spring_at(h).unwrap().stiffness).sum();
    /// assert!((compliance * mech.root(e).unwrap().stiffness - 1.0).abs() < 1e-12);
    /// ```
    pub fn chain(&self, e: EdgeKey) -> Vec<EdgeKey> {
        let mut out = Vec::new();
        self.chain_from(e, true, &mut out);
        out
    }

    /// Appends the chain of `e` walked from its end `a` (`from_a`) or `b`: the side at that end
    /// first, each member from its end on the walk's way in.
    fn chain_from(&self, e: EdgeKey, from_a: bool, out: &mut Vec<EdgeKey>) {
        match self.split_at.get(&e) {
            Some(node) => {
                let sides = if from_a { [&node.sides[0], &node.sides[1]] } else { [&node.sides[1], &node.sides[0]] };
                for (k, side) in sides.into_iter().enumerate() {
                    // The first side is entered at its outer end, the second at the midpoint.
                    for member in side {
                        self.chain_from(member.key, member.outer_at_a == (k == 0), out);
                    }
                }
            }
            None => out.push(e),
        }
    }

    /// The spring the edge cell `e` had when it was first split, if it was a root (a spring that was
    /// not itself a half). O(log E).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let e = mech.edge(0, 1).unwrap();
    /// let before = mech.spring_at(e);
    /// let d = m.map().darts().next().unwrap();
    /// mech.subdivide_tet(&mut m, d, 1).unwrap();
    /// assert_eq!(mech.root(e), before);
    /// assert!(mech.spring_at(e).is_none() && mech.spring(0, 1).is_none()); // no longer an edge
    /// ```
    pub fn root(&self, e: EdgeKey) -> Option<Spring> {
        self.roots.get(&e).copied()
    }

    /// Adds law 2's contribution of the tet `t` (volume id `volume`) to its edges that are not
    /// halves, measured scale-safely ([`tet_stiffnesses`], [`rest_length`]). O(log E).
    ///
    /// Errors: [`CouplingError::Overflow`] for a spring value past `f64::MAX` (the springs before
    /// it changed: [`Self::build`] drops the coupling; for the children of a split the checks
    /// before the split make it unreachable, [`Self::check_split_headroom`]).
    fn add_tet(&mut self, m: &LeveledMap<3>, t: &Tet0, volume: u32) -> Result<(), CouplingError> {
        let p = t.corners.map(|v| m.points()[v as usize]);
        let terms = tet_stiffnesses(self.material.young, p);
        for ((&(i, j), e), k) in PAIRS.iter().zip(t.edges).zip(terms) {
            let Some(e) = e.filter(|e| !self.halves.contains(e)) else { continue };
            let rest = rest_length(p[i], p[j]);
            let s = self.springs.entry(e).or_insert(Spring { rest, stiffness: 0.0, damping: 0.0 });
            s.stiffness += k;
            s.damping += self.material.damping * k;
            let values = [("rest length", s.rest), ("stiffness", s.stiffness), ("damping", s.damping)];
            if let Some((quantity, value)) = values.into_iter().find(|(_, v)| !v.is_finite()) {
                return Err(CouplingError::Overflow { volume, edge: e, quantity, value });
            }
        }
        Ok(())
    }

    /// The largest |stiffness| or |damping| of the springs on the edges of the live `darts`; NaN
    /// if one of them is NaN (written through [`Self::spring_mut`]), so that the headroom
    /// checks refuse it rather than drop it (finding 205). O(darts · log E).
    fn largest_spring(&self, m: &LeveledMap<3>, darts: &[DartId]) -> f64 {
        let map = m.map();
        let springs =
            darts.iter().filter(|&&x| map.contains(x)).filter_map(|&x| self.springs.get(&EdgeKey::of(map, x)));
        // Magnitudes: a half of −f64::MAX overflows as surely as one of f64::MAX (finding 223).
        springs.fold(0.0, |a, s| max_keeping_nan(max_keeping_nan(a, s.stiffness.abs()), s.damping.abs()))
    }

    /// A bound of the stiffness and damping terms that the children of a 1→8 split of the tet of
    /// `d` add ([`children_term_bound`] times max(1, β)); 0 for a tet the map refuses to split
    /// for its geometry (no such dart, no finite corner positions). O(volume).
    fn children_bound(&self, m: &LeveledMap<3>, d: DartId) -> f64 {
        if m.tet_volume(d).is_err() {
            return 0.0;
        }
        let Ok(corners) = m.tet_vertices(d) else { return 0.0 };
        let p = corners.map(|v| m.points()[v as usize]);
        children_term_bound(self.material.young, p) * self.material.damping.max(1.0)
    }

    /// Refuses splitting 1→8, at one level and in any order, the tets of `zone` (one dart each)
    /// when a spring value could pass `f64::MAX`, before the map changes. With A the largest
    /// stiffness or damping on the edges of the zone's tets and B the largest bound of a child's
    /// term ([`Self::children_bound`]), every value the level stores is at most 2A + 8B: a half
    /// takes 2k or 2c of a spring that existed before the level (≤ 2A); a new edge of a child is
    /// an inner edge of a face, which takes at most three terms from the children on each side
    /// (the corner child and two tets around the diagonal) over its value before the level
    /// (≤ A, or 0 for an edge made at this level), or the diagonal, which takes four. The rest
    /// lengths stay finite: a child's edges are no longer than its parent's, and the level-0
    /// ones were checked by [`Self::build`]; masses are shares of finite masses. Refused with
    /// [`CouplingError::SplitOverflow`] when 2A + 8B, with a margin of 2⁻⁴⁰ for the rounding of
    /// the children's terms, is not finite. O(Σ zone volumes · log E).
    fn check_split_headroom(&self, m: &LeveledMap<3>, zone: &[DartId]) -> Result<(), CouplingError> {
        let (mut a, mut b, mut worst) = (0.0f64, 0.0f64, None);
        for &d in zone.iter().filter(|&&d| m.map().contains(d)) {
            let at = self.largest_spring(m, &m.map().orbit(d, AlphaMask::of(&[0, 1, 2])));
            let bt = self.children_bound(m, d);
            let own = 2.0 * at + 8.0 * bt;
            if worst.is_none_or(|(w, _)| own > w || own.is_nan()) {
                worst = Some((own, d));
            }
            (a, b) = (max_keeping_nan(a, at), max_keeping_nan(b, bt));
        }
        refuse_past_max(worst.map(|(_, d)| d), 2.0 * a + 8.0 * b)
    }

    /// Refuses splitting the edges of the live `darts` (an edge split or a face split 1→4: the
    /// halves take 2k and 2c, new inner edges k = 0) when a half's value would pass `f64::MAX`.
    /// O(darts · log E).
    fn check_halves_headroom(&self, m: &LeveledMap<3>, darts: &[DartId]) -> Result<(), CouplingError> {
        refuse_past_max(darts.first().copied(), 2.0 * self.largest_spring(m, darts))
    }

    /// Errors unless every vertex insertion of the map was followed and the coupling holds one
    /// state per vertex id of the map. O(1).
    pub(super) fn in_sync(&self, m: &LeveledMap<3>) -> Result<(), CouplingError> {
        // The material is a public field: checked again here, before any operation, as
        // `new` checks it (a NaN Young's modulus or damping would pass the headroom bounds and
        // fail half way through the split: finding 205). O(1).
        crate::mechanics::model::check_material(&self.material).map_err(CouplingError::Material)?;
        let logged = m.edge_split_log().len();
        if logged != self.applied {
            return Err(CouplingError::OutOfSync { applied: self.applied, logged });
        }
        let (vertices, states) = (m.map().cell_id_bound(0), self.position.len().min(self.velocity.len()));
        if states != vertices || self.position.len() != self.velocity.len() {
            return Err(CouplingError::StateCount { states, vertices });
        }
        if m.version() != self.followed {
            return Err(CouplingError::Unfollowed { followed: self.followed, version: m.version() });
        }
        if m.stamp() != self.followed_stamp {
            return Err(CouplingError::OtherMap);
        }
        Ok(())
    }
}

/// max(a, b), NaN when either is (`f64::max` drops a NaN). O(1).
fn max_keeping_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// [`CouplingError::SplitOverflow`] at `dart` unless `bound` · (1 + 2⁻⁴⁰) is finite. O(1).
fn refuse_past_max(dart: Option<DartId>, bound: f64) -> Result<(), CouplingError> {
    match dart {
        Some(dart) if !(bound * (1.0 + 2f64.powi(-40))).is_finite() => {
            Err(CouplingError::SplitOverflow { dart, bound })
        }
        _ => Ok(()),
    }
}

/// A bound of law 2's terms E·|V_c|/L_c² that the eight children of a 1→8 split of the tet with
/// corners `p` add to their edges that are not halves. Every child has the volume V/8 (midpoint
/// subdivision); those edges are inner edges of the faces, each half as long as a parent edge,
/// and the diagonal, one of the three segments joining the midpoints of opposite edges: none is
/// shorter than the shortest of these. The children's volumes are computed from other corners,
/// so they may exceed V/8 by rounding, by a few ulps of ℓ³ (ℓ the longest parent edge): 2⁻⁴⁵ ℓ³
/// is added. Taken in wide floats (`crate::wide`: an f64 mantissa, an unbounded exponent), so
/// it neither overflows nor underflows before the result does, needles and slivers included.
/// ∞ for a segment of length 0 or a NaN corner. O(1).
fn children_term_bound(young: f64, p: [Vec3; 4]) -> f64 {
    use crate::wide::{difference, norm, six_volume, Wide};
    if young == 0.0 {
        return 0.0;
    }
    let length = |a: Vec3, b: Vec3| norm(difference(b, a));
    let edges = PAIRS.map(|(i, j)| length(p[i], p[j]));
    let mid = |(i, j): (usize, usize)| crate::mesh::midpoint(p[i], p[j]);
    let segments = [(0, 5), (1, 4), (2, 3)].map(|(x, y)| length(mid(PAIRS[x]), mid(PAIRS[y])));
    let halves = edges.map(|e| e.mul(Wide::new(0.5)));
    let all = halves.iter().chain(&segments);
    if !all.clone().all(|l| l.is_positive()) {
        return f64::INFINITY; // a zero length, or NaN
    }
    let shortest = all.fold(segments[0], |a, &l| if l.less_than(a) { l } else { a });
    let longest = edges.iter().fold(edges[0], |a, &e| if a.less_than(e) { e } else { a });
    let cube = longest.mul(longest).mul(longest).mul(Wide::new(2f64.powi(-45)));
    let volume = six_volume(p[0], p[1], p[2], p[3]).abs().div(Wide::new(48.0));
    Wide::new(young).mul(volume.add(cube)).div(shortest.mul(shortest)).to_f64()
}

/// Errors unless `m` is at level 0 and has a rest position for every vertex id. O(1).
fn check_start(m: &LeveledMap<3>) -> Result<(), CouplingError> {
    if m.max_level() != 0 {
        return Err(CouplingError::NotLevelZero(m.max_level()));
    }
    if m.points().len() < m.map().cell_id_bound(0) {
        return Err(CouplingError::NoGeometry(m.points().len() as u32));
    }
    Ok(())
}

impl LeveledMechanics {
    /// [`LeveledMap::split_edge`] with the series rule on the edge's spring, the new vertex
    /// interpolated and Σ m u kept (module docs). Returns the map's result.
    /// O(edge · n + ring + log E), ring the darts of the volumes around the vertices of the
    /// edge's volumes (M_A of the momentum correction, gathered only when E ≠ 0).
    ///
    /// Errors: [`CouplingError::OutOfSync`], [`CouplingError::StateCount`] (another map's
    /// coupling), [`CouplingError::Unfollowed`] (the map was changed alone),
    /// [`CouplingError::SplitOverflow`] when a half's 2k or 2c would pass `f64::MAX`, the map's
    /// refusals (all five: both unchanged), or [`CouplingError::NoSpring`] (the map changed; a
    /// tampered coupling).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// mech.velocity[0] = [2.0, 0.0, 0.0];
    /// let d = m.map().darts().find(|&d| m.map().vertex_id(d).0 == 0 && m.map().vertex_id(m.map().alpha_dyn(0, d)).0 == 1).unwrap();
    /// let k = mech.spring(0, 1).unwrap().stiffness;
    /// let mid = mech.split_edge(&mut m, d, 1).unwrap();
    /// let v = m.map().vertex_id(mid).0;
    /// assert_eq!(mech.spring(0, v).unwrap().stiffness, 2.0 * k);
    /// assert_eq!((mech.position[v as usize], mech.velocity[v as usize]), ([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]));
    /// mech.check(&m).unwrap();
    /// ```
    pub fn split_edge(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<DartId, CouplingError> {
        self.in_sync(m)?;
        self.check_halves_headroom(m, &[d])?;
        let patch = self.patch_before(m, &[d]);
        let mid = m.split_edge(d, level)?;
        self.follow(m, &[], &[])?;
        self.conserve_momentum(m, patch, &[]);
        self.expensive_check(m);
        Ok(mid)
    }

    /// [`LeveledMap::subdivide_triangle`] with the series rule on its split sides, zero-stiffness
    /// springs on its three inner edges (no tet is split) and Σ m u kept (module docs).
    /// O(face + touched + ring + log E), touched the volumes around its sides, ring as
    /// [`Self::split_edge`].
    ///
    /// Errors: as [`Self::split_edge`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let d = m.map().darts().next().unwrap();
    /// mech.subdivide_triangle(&mut m, d, 1).unwrap();
    /// assert_eq!(mech.springs().count(), 6 + 3 + 3); // 3 sides split, 3 inner edges
    /// assert_eq!(mech.springs().filter(|(_, s)| s.stiffness == 0.0).count(), 3);
    /// mech.check(&m).unwrap();
    /// ```
    pub fn subdivide_triangle(
        &mut self,
        m: &mut LeveledMap<3>,
        d: DartId,
        level: u8,
    ) -> Result<[DartId; 4], CouplingError> {
        self.in_sync(m)?;
        let mut patch = None;
        if m.map().contains(d) {
            let face = m.map().orbit(d, AlphaMask::of(&[0, 1]));
            self.check_halves_headroom(m, &face)?;
            patch = self.patch_before(m, &face);
        }
        let faces = m.subdivide_triangle(d, level)?;
        self.follow(m, &faces, &[])?;
        self.conserve_momentum(m, patch, &[]);
        self.expensive_check(m);
        Ok(faces)
    }

    /// [`LeveledMap::subdivide_tet_with_mass`] with the series rule on the split edges, new springs
    /// on the new edges, law 2's contributions of the eight children and Σ m u kept (module
    /// docs). O(volume + touched + ring + log E), touched the volumes around its six edges, ring
    /// as [`Self::split_edge`].
    ///
    /// Errors: as [`Self::split_edge`]; [`CouplingError::SplitOverflow`] when a value the split
    /// would store could pass `f64::MAX`: with A the largest stiffness or damping on the tet's
    /// edges and B a bound of its children's terms of law 2 times max(1, β), every stored value
    /// is at most 2A + 8B, refused when that is not finite (with a margin of 2⁻⁴⁰), before the
    /// map changes.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let d = m.map().darts().next().unwrap();
    /// mech.subdivide_tet(&mut m, d, 1).unwrap();
    /// assert_eq!(mech.springs().count(), 25); // 12 halves, 12 face edges, 1 diagonal
    /// assert!(mech.springs().all(|(_, s)| s.stiffness > 0.0));
    /// mech.check(&m).unwrap();
    /// ```
    pub fn subdivide_tet(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<[DartId; 8], CouplingError> {
        let children = self.split_tet(m, d, level)?;
        self.expensive_check(m);
        Ok(children)
    }

    /// [`Self::subdivide_tet`] without the expensive check.
    fn split_tet(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<[DartId; 8], CouplingError> {
        self.in_sync(m)?;
        self.check_split_headroom(m, &[d])?;
        let mut patch = None;
        if m.map().contains(d) {
            patch = self.patch_before(m, &m.map().orbit(d, AlphaMask::cell(3, 3)));
        }
        let children = self.split_followed(m, d, level)?;
        self.conserve_momentum(m, patch, &children);
        Ok(children)
    }

    /// [`Self::split_tet`] without the headroom check ([`Self::refine_around`] made it for the
    /// whole level).
    fn split_followed(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<[DartId; 8], CouplingError> {
        self.in_sync(m)?;
        let children = m.subdivide_tet_with_mass(d, level, &mut self.masses)?;
        self.follow(m, &[], &children)?;
        Ok(children)
    }

    /// [`LeveledMap::refine_around`] through [`Self::subdivide_tet`]: level by level, the tets of
    /// each level's balanced zone (around the ball B(center, radius), widened by face rings so
    /// that no face is refined twice, finding 264) are split 1→8 with their springs and masses
    /// (by the bulk path for a level where the ball holds everything, with the same springs up
    /// to rounding). The levels run from max(1, k), k the map's max level; after `Ok`, every tet
    /// of the finest map that meets the ball has μt ≥ `levels` (a tet that had to wait for a
    /// blocker is split at a later level, if need be past `levels`; on a map above level 0 the call
    /// is all or nothing: map and coupling are copied first and put back on any error, as by
    /// [`LeveledMap::refine_around`]). Σ m u is kept over the whole call, also when a level
    /// refuses after earlier ones were done (module docs; the vertex masses before and after are
    /// recomputed over the whole map). O(darts + Σ_L (darts + zone volumes · touched)).
    ///
    /// Errors: [`SubdivideError::LevelTooHigh`] for `levels` above the maximum,
    /// [`SubdivideError::BadBall`], those of the coupling's sync check, before any change; on a
    /// level-0 map, at a level, those of [`LeveledMap::refine_around`] (the dart limit and the
    /// refusals of [`Self::subdivide_tet`] for any tet of its zone) and
    /// [`CouplingError::SplitOverflow`] (the bound of [`Self::subdivide_tet`] over the whole
    /// zone), all checked on the whole level before its first split: an error leaves the map,
    /// the springs and the masses as the levels before it left them (unchanged when it comes at
    /// the first level, the earlier levels done when it comes later, whatever the refusal; map
    /// and coupling in step either way); on a map above level 0 the same, with map
    /// and coupling put back. With `expensive-checks`, [`Self::check`] runs once at the end (not
    /// after each tet).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let r = mech.refine_around(&mut m, [0.1; 3], 10.0, 2).unwrap();
    /// assert_eq!(r.subdivided_per_level, vec![0, 1, 8]);
    /// mech.check(&m).unwrap();
    /// ```
    pub fn refine_around(
        &mut self,
        m: &mut LeveledMap<3>,
        center: [f64; 3],
        radius: f64,
        levels: u8,
    ) -> Result<Refinement, CouplingError> {
        m.check_op_level(levels)?;
        LeveledMap::check_ball(center, radius)?;
        self.in_sync(m)?;
        let masses = self.vertex_masses_raw(m);
        let result = self.refine_in_step(m, center, radius, levels);
        self.conserve_momentum_whole(m, &masses);
        // As `LeveledMap::refine_around` (finding 331).
        m.expensive_check_all("a coupled refinement around a ball");
        result
    }

    /// [`Self::refine_around`] after its checks of the arguments and of the sync, before the
    /// momentum correction.
    fn refine_in_step(
        &mut self,
        m: &mut LeveledMap<3>,
        center: [f64; 3],
        radius: f64,
        levels: u8,
    ) -> Result<Refinement, CouplingError> {
        let before = self.masses.total(m);
        if m.max_level() == 0 {
            // Levels done before a refusal stay (each level checked before its first split).
            let per_level = m.refine_mixed(center, radius, levels, &mut CoupledSplit { mech: self, center, radius })?;
            self.expensive_check(m);
            let after = self.masses.total(m);
            return Ok(Refinement {
                subdivided_per_level: per_level,
                total_mass_before: before,
                total_mass_after: after,
            });
        }
        let saved = (m.clone(), self.clone());
        let mut splitter = CoupledSplit { mech: self, center, radius };
        let result = m.refine_mixed(center, radius, levels, &mut splitter);
        match result {
            Ok(per_level) => {
                self.expensive_check(m);
                let after = self.masses.total(m);
                Ok(Refinement { subdivided_per_level: per_level, total_mass_before: before, total_mass_after: after })
            }
            Err(e) => {
                (*m, *self) = saved;
                Err(e)
            }
        }
    }

    /// One level of [`Self::refine_around`] by the map's bulk path ([`LeveledMap::refine_uniform`])
    /// when the ball holds every vertex and every tet is at level − 1, then the same rules as per
    /// tet ([`Self::follow`] with every tet a child: series splits from the edge split log, law 2
    /// on the new edges). `None` (nothing changed) where the bulk path does not apply or refuses.
    /// O(darts · log springs).
    fn refine_level_in_bulk(
        &mut self,
        m: &mut LeveledMap<3>,
        center: [f64; 3],
        radius: f64,
        level: u8,
    ) -> Result<Option<usize>, CouplingError> {
        if !m.bulk_applies(center, radius, level) {
            return Ok(None);
        }
        self.in_sync(m)?;
        // The per-op path would make the same check on the same zone (every tet).
        self.check_split_headroom(m, &m.map().one_dart_per_cell(3))?;
        let Ok(r) = m.refine_uniform(level, &mut self.masses) else { return Ok(None) };
        let children = m.map().one_dart_per_cell(3);
        self.follow(m, &[], &children)?;
        Ok(Some(r.subdivided_per_level[level as usize]))
    }

    /// Applies the rules after an operation of the map: series splits from the new entries of its
    /// edge split log, zero springs on the new edge cells of `faces` and `children`, law 2 from
    /// `children`.
    fn follow(&mut self, m: &LeveledMap<3>, faces: &[DartId], children: &[DartId]) -> Result<(), CouplingError> {
        let log = m.edge_split_log();
        for (i, &s) in log.iter().enumerate().skip(self.applied) {
            self.split_spring(m, i, s)?;
        }
        self.applied = log.len();
        self.followed = m.version();
        self.followed_stamp = m.stamp();
        let mut region: Vec<DartId> = Vec::new();
        for &f in faces {
            region.extend(m.map().orbit(f, AlphaMask::of(&[0, 1])));
        }
        for &c in children {
            region.extend(m.map().orbit(c, AlphaMask::of(&[0, 1, 2])));
        }
        for d in region {
            let e = EdgeKey::of(m.map(), d);
            if e.a != e.b {
                let rest = rest_length(m.points()[e.a as usize], m.points()[e.b as usize]);
                self.springs.entry(e).or_insert(Spring { rest, stiffness: 0.0, damping: 0.0 });
            }
        }
        for &c in children {
            let t = tet_edges(m, c)?;
            self.add_tet(m, &t, m.map().cell_id(3, c).0)?;
        }
        Ok(())
    }

    /// With the `expensive-checks` feature, [`Self::check`] after a public operation (a bug of this
    /// module panics, as the map's own checks do). O(1) without the feature.
    pub(super) fn expensive_check(&self, m: &LeveledMap<3>) {
        #[cfg(feature = "expensive-checks")]
        if let Err(e) = self.check(m) {
            panic!("topomech bug: the spring coupling broke a law: {e}");
        }
        let _ = m;
    }

    /// The series rule for one vertex insertion of the map (entry `index` of its split log: the
    /// edge cell it split, the cells of the halves), the new vertex's state and split parents.
    fn split_spring(&mut self, m: &LeveledMap<3>, index: usize, split: EdgeSplit) -> Result<(), CouplingError> {
        let (v, [a, b]) = (split.vertex, split.ends);
        let e = EdgeKey::new(split.edge, a, b);
        let s = self.springs.remove(&e).ok_or(CouplingError::NoSpring(e))?;
        if !self.halves.contains(&e) {
            self.roots.insert(e, s);
        }
        let (at_a, at_b) = (EdgeKey::new(split.halves[0], a, v), EdgeKey::new(split.halves[1], v, b));
        let [(h0, o0), (h1, o1)] = if a == e.a { [(at_a, a), (at_b, b)] } else { [(at_b, b), (at_a, a)] };
        let member = |key: EdgeKey, outer: u32| vec![Member { key, outer_at_a: key.a == outer }];
        self.split_at.insert(e, SplitNode { mid: v, sides: [member(h0, o0), member(h1, o1)] });
        for h in [at_a, at_b] {
            self.springs.insert(h, s.half());
            self.halves.insert(h);
            self.member_of.insert(h, e);
        }
        let n = m.map().cell_id_bound(0).max(v as usize + 1);
        self.position.resize(n, [0.0; 3]);
        self.velocity.resize(n, [0.0; 3]);
        self.parents.resize(n.max(self.parents.len()), None);
        self.parents[v as usize] = Some((index, [m.vertex_origin(a), m.vertex_origin(b)]));
        let mean = |x: &[Vec3]| crate::mesh::midpoint(x[a as usize], x[b as usize]);
        let (x, u) = (mean(&self.position), mean(&self.velocity));
        self.position[v as usize] = x;
        self.velocity[v as usize] = u;
        Ok(())
    }
}

impl LeveledMechanics {
    /// Vertex masses by vertex id, a scatter of every volume's mass shares: m_t/4 on
    /// each corner of a plain tet; a coarse volume with h_t hanging vertices (inserted by its
    /// neighbours on its sides) among its n_t gives each of them m_t / (4 n_t), taken from its
    /// corners along their barycentric coordinates. Σ_v m_v = Σ_t m_t, every share > 0, and
    /// Σ_v m_v P_v = Σ_t m_t · centroid_t on the rest positions P (and on any placement affine on
    /// each volume), so a refinement keeps the rest centre of mass (finding 218). Every
    /// operation keeps Σ_v m_v u_v exactly (up to rounding) in every state by a velocity
    /// correction; in a deformed state it moves Σ_v m_v x_v by Σ_v Δm_v x_v and changes the
    /// angular momentum (module docs, "Momentum"). O(darts).
    ///
    /// # Errors
    /// [`CouplingError::OutOfSync`], [`CouplingError::StateCount`] or
    /// [`CouplingError::Unfollowed`] when `m` is not the map this coupling follows (checked as
    /// every coupling operation does).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::Material;
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material { density: 6.0, ..Material::default() }).unwrap();
    /// let e = mech.edge(0, 1).unwrap();
    /// let d = m.map().darts().find(|&d| m.map().cell_id(1, d).0 == e.id).unwrap();
    /// mech.split_edge(&mut m, d, 1).unwrap(); // a midpoint (vertex 4) on the edge of 0 and 1
    /// let mass = mech.vertex_masses(&m).unwrap();
    /// // the midpoint takes 1/(4·5) = 0.05, half from each end; the other corners keep 1/4
    /// let want = [0.225, 0.225, 0.25, 0.25, 0.05];
    /// assert!(mass.iter().zip(want).all(|(&x, w)| (x - w).abs() < 1e-12));
    /// ```
    pub fn vertex_masses(&self, m: &LeveledMap<3>) -> Result<Vec<f64>, CouplingError> {
        self.in_sync(m)?;
        Ok(self.vertex_masses_raw(m))
    }

    /// [`Self::vertex_masses`] without the check (the law checks, the spring system and
    /// [`Self::refine_around`], which have made it), with the coupling's split parents. O(darts).
    pub(super) fn vertex_masses_raw(&self, m: &LeveledMap<3>) -> Vec<f64> {
        let map = m.map();
        let mut out = vec![0.0; map.cell_id_bound(0)];
        for t in map.one_dart_per_cell(3) {
            for (v, share) in self.volume_shares(m, t) {
                out[v as usize] += share;
            }
        }
        out
    }

    /// The mass shares of the volume of `t` ([`volume_mass_shares`] with its mass and the
    /// coupling's split parents). O(volume + n log n).
    fn volume_shares(&self, m: &LeveledMap<3>, t: DartId) -> Vec<(u32, f64)> {
        let mass = self.masses.mass.get(m.map().cell_id(3, t).index()).copied().unwrap_or(0.0);
        volume_shares_by_id(m, t, mass, &self.parents)
    }

    /// The finest level as a flat [`SpringSystem`] with slots = vertex ids (so [`Self::position`] and
    /// [`Self::velocity`] are its state arrays): one spring per edge cell in key order (two springs
    /// with the same ends for two edges joining the same vertices), masses from
    /// [`Self::vertex_masses`], viscosity ν·m_v, `fixed[v]` pinning vertex v (missing entries:
    /// free). No tet list is rebuilt. O(darts + E).
    ///
    /// # Errors
    /// As [`Self::vertex_masses`]: a coupling given another map (whose spring ends could reach
    /// past its vertex ids) is refused. [`CouplingError::System`] for a non-finite gravity or a
    /// spring value out of range (what [`SpringSystem::new`] refuses).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mechanics::{Integrator, Material, StepConfig, Stepper};
    /// use topomech::subdivide::{LeveledMap, LeveledMechanics};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut mech = LeveledMechanics::new(&m, Material::default()).unwrap();
    /// let d = m.map().darts().next().unwrap();
    /// mech.subdivide_tet(&mut m, d, 1).unwrap();
    /// let sys = mech.spring_system(&m, [0.0, 0.0, -9.81], &[true, true, true]).unwrap();
    /// assert_eq!((sys.slots(), sys.springs()), (10, 25));
    /// let mut stepper = Stepper::new(StepConfig::new(Integrator::Symplectic, 1e-4), &sys, &mech.position, &mech.velocity).unwrap();
    /// let (x, v) = (&mut mech.position, &mut mech.velocity);
    /// stepper.step(&sys, x, v).unwrap();
    /// assert!(mech.position[3][2] < 1.0 && mech.position[0] == [0.0; 3]); // falls, pinned stays
    /// assert!(mech.spring_system(&m, [f64::NAN; 3], &[]).is_err()); // gravity must be finite
    /// ```
    pub fn spring_system(
        &self,
        m: &LeveledMap<3>,
        gravity: Vec3,
        fixed: &[bool],
    ) -> Result<SpringSystem, CouplingError> {
        self.in_sync(m)?;
        let mass = self.vertex_masses_raw(m);
        let n = mass.len();
        let pinned: Vec<bool> = (0..n).map(|v| fixed.get(v).copied().unwrap_or(false)).collect();
        let viscosity = mass.iter().map(|x| self.material.viscosity * x).collect();
        let ends = self.springs.keys().map(|e| [e.a, e.b]).collect();
        let rest = self.springs.values().map(|s| s.rest).collect();
        let stiffness = self.springs.values().map(|s| s.stiffness).collect();
        let damping = self.springs.values().map(|s| s.damping).collect();
        SpringSystem::new(ends, rest, stiffness, damping, mass, &pinned, viscosity, gravity)
            .map_err(CouplingError::System)
    }
}

/// The lumped masses of some volumes before an operation ([`LeveledMechanics::patch_before`]):
/// one dart per volume, and Σ of their shares per vertex id.
struct MassPatch {
    volumes: Vec<DartId>,
    before: BTreeMap<u32, f64>,
}

impl LeveledMechanics {
    /// The patch of an operation that will split the edges of the live `darts` (and, for a 1→8,
    /// the tet of those darts): every volume around one of those edges, the only volumes whose
    /// vertices (and, for the tet, mass) the operation changes. `None` when a dart is not live
    /// (the map refuses the operation). O(Σ edge orbits · volume).
    fn patch_before(&self, m: &LeveledMap<3>, darts: &[DartId]) -> Option<MassPatch> {
        let map = m.map();
        if !darts.iter().all(|&d| map.contains(d)) {
            return None;
        }
        let mut edges = BTreeSet::new();
        let around = darts.iter().filter(|&&d| edges.insert(map.cell_id(1, d))).flat_map(|&d| {
            map.orbit(d, AlphaMask::cell(3, 1)) // ⟨α0, α2, α3⟩: the edge, in every volume around it
        });
        let volumes = distinct_volumes(m, around);
        let before = self.lumped(m, &volumes, |_| true);
        Some(MassPatch { volumes, before })
    }

    /// Σ of the shares of the volumes of `volumes` (one dart each) per vertex id `keep` accepts,
    /// each sum compensated. O(Σ volume · log n).
    fn lumped(&self, m: &LeveledMap<3>, volumes: &[DartId], keep: impl Fn(u32) -> bool) -> BTreeMap<u32, f64> {
        let mut sums: BTreeMap<u32, CompensatedSum> = BTreeMap::new();
        for &t in volumes {
            for (v, share) in self.volume_shares(m, t).into_iter().filter(|&(v, _)| keep(v)) {
                sums.entry(v).or_default().add(share);
            }
        }
        sums.into_iter().map(|(v, s)| (v, s.value())).collect()
    }

    /// Keeps Σ_v m_v u_v over an operation made since `patch` was taken (`children`: the tets it
    /// made): Δ_v = (Σ shares of the patch's volumes and `children` now) − (before), then
    /// [`Self::momentum_excess`] and [`Self::remove_momentum`], with M_A gathered from the volumes
    /// around each vertex of A.
    /// Every other volume kept its vertices and mass, so its shares are unchanged.
    /// O(patch volumes + Σ_{v ∈ A} star(v) · volume).
    fn conserve_momentum(&mut self, m: &LeveledMap<3>, patch: Option<MassPatch>, children: &[DartId]) {
        let Some(patch) = patch else { return };
        let volumes = distinct_volumes(m, patch.volumes.iter().chain(children).copied());
        let mut delta = self.lumped(m, &volumes, |_| true);
        for (v, old) in patch.before {
            *delta.entry(v).or_insert(0.0) -= old;
        }
        let delta: Vec<(u32, f64)> = delta.into_iter().collect();
        if let Some((e, a)) = self.momentum_excess(&delta) {
            let total = self.star_mass(m, &volumes, &a);
            self.remove_momentum(&a, e, total);
        }
    }

    /// Σ_{v ∈ a} m_v (`a` sorted, every vertex of a volume of `volumes`): the shares of every
    /// volume around each vertex of `a`, compensated. O(Σ_{v ∈ a} star(v) · volume).
    fn star_mass(&self, m: &LeveledMap<3>, volumes: &[DartId], a: &[u32]) -> f64 {
        let map = m.map();
        let mut at: BTreeMap<u32, DartId> = BTreeMap::new();
        for &t in volumes {
            for x in map.orbit(t, AlphaMask::cell(3, 3)) {
                let v = map.vertex_id(x).0;
                if a.binary_search(&v).is_ok() {
                    at.entry(v).or_insert(x);
                }
            }
        }
        let stars = at.values().flat_map(|&x| map.orbit(x, AlphaMask::cell(3, 0)));
        let mass = self.lumped(m, &distinct_volumes(m, stars), |v| a.binary_search(&v).is_ok());
        compensated_sum(mass.into_values())
    }

    /// The momentum E an operation created by moving the masses `delta` (Δ_v, sorted by vertex
    /// id) between vertices, and A, the vertices with Δ_v ≠ 0: E = Σ_{v ∈ A} Δ_v (u_v − u_r), u_r
    /// the velocity of the first vertex of A (equal to Σ Δ_v u_v as Σ Δ_v = 0 up to rounding,
    /// and exactly 0 for a uniform velocity). Component by component, as (value, scale) with
    /// E_k = value_k · scale_k: where the differences or their sum overflow, the sum is taken of
    /// halved velocities (scale 2), and a component that is still not finite (a NaN or infinite
    /// velocity in that component) is 0, left uncorrected — the other components are corrected
    /// all the same (round 26: one NaN in x dropped the correction of y and z, and velocities of
    /// ±1.5e308 dropped all of it). `None` when every component is 0. O(A).
    fn momentum_excess(&self, delta: &[(u32, f64)]) -> Option<(Excess, Vec<u32>)> {
        let a: Vec<u32> = delta.iter().filter(|&&(_, d)| d != 0.0).map(|&(v, _)| v).collect();
        let reference = self.velocity[*a.first()? as usize];
        let u = &self.velocity;
        let moved = |k: usize, half: f64| {
            let terms = delta.iter().filter(|&&(_, d)| d != 0.0);
            compensated_sum(terms.map(|&(v, d)| d * (u[v as usize][k] * half - reference[k] * half)))
        };
        let component = |k: usize| match moved(k, 1.0) {
            e if e.is_finite() => (e, 1.0),
            _ => match moved(k, 0.5) {
                e if e.is_finite() => (e, 2.0),
                _ => (0.0, 1.0),
            },
        };
        let e = [0, 1, 2].map(component);
        e.iter().any(|&(x, _)| x != 0.0).then_some((e, a))
    }

    /// The velocity correction of the module docs: u_v −= E / M_A for every v ∈ `a` (M_A =
    /// `total`, Σ_{v ∈ A} m_v after the operation), the least change in Σ_v m_v |δu_v|² that
    /// removes E, component by component ([`Self::momentum_excess`]; a component of E that is
    /// 0 changes nothing). Nothing unless M_A is positive and finite. O(A).
    fn remove_momentum(&mut self, a: &[u32], e: Excess, total: f64) {
        if !(total > 0.0 && total.is_finite()) {
            return;
        }
        let shift = e.map(|(x, scale)| x / total * scale);
        // A component is corrected on all of A or on none: not where the shift is 0 or not
        // finite, nor where a corrected velocity would overflow (round 27: u − shift near
        // ±f64::MAX gave −∞ while the checks passed).
        let apply = [0, 1, 2].map(|k| {
            shift[k] != 0.0
                && shift[k].is_finite()
                && a.iter().all(|&v| {
                    let u = self.velocity[v as usize][k];
                    !u.is_finite() || (u - shift[k]).is_finite()
                })
        });
        for &v in a {
            let u = &mut self.velocity[v as usize];
            *u = [0, 1, 2].map(|k| if apply[k] { u[k] - shift[k] } else { u[k] });
        }
    }

    /// [`Self::momentum_excess`] and [`Self::remove_momentum`] over a whole-map change: `before` the vertex masses before
    /// ([`Self::vertex_masses_raw`]; new vertices 0), the masses now recomputed. Nothing unless
    /// `m` and the coupling are in step. O(darts).
    fn conserve_momentum_whole(&mut self, m: &LeveledMap<3>, before: &[f64]) {
        if self.in_sync(m).is_err() {
            return;
        }
        let after = self.vertex_masses_raw(m);
        let delta: Vec<(u32, f64)> =
            after.iter().enumerate().map(|(v, &x)| (v as u32, x - before.get(v).copied().unwrap_or(0.0))).collect();
        if let Some((e, a)) = self.momentum_excess(&delta) {
            self.remove_momentum(&a, e, compensated_sum(a.iter().map(|&v| after[v as usize])));
        }
    }
}

/// A momentum excess E per component as (value, scale), E_k = value_k · scale_k
/// (`LeveledMechanics::momentum_excess`).
type Excess = [(f64, f64); 3];

/// One dart per distinct volume (by volume id) of `darts`, in order of first meeting. O(darts · log).
fn distinct_volumes(m: &LeveledMap<3>, darts: impl IntoIterator<Item = DartId>) -> Vec<DartId> {
    let mut seen = BTreeSet::new();
    darts.into_iter().filter(|&x| seen.insert(m.map().cell_id(3, x))).collect()
}

/// For every vertex id, the split that inserted it: (its index in [`LeveledMap::split_log`], the
/// [origins](LeveledMap::vertex_origin) of the ends of the split edge); `None` for a vertex of
/// level 0 and for a cut's copy (look its origin up). O(vertices + splits).
pub(super) fn split_parents(m: &LeveledMap<3>) -> Vec<Option<(usize, [u32; 2])>> {
    let mut out = vec![None; m.map().cell_id_bound(0)];
    for (i, &[mid, a, b]) in m.split_log().iter().enumerate() {
        if let Some(slot) = out.get_mut(mid as usize) {
            *slot = Some((i, [m.vertex_origin(a), m.vertex_origin(b)]));
        }
    }
    out
}

/// The hanging vertices among a volume's sorted vertex ids: those inserted on an edge whose two
/// ends are vertices of the same volume (a midpoint lies between its ends, so it is no corner).
/// The rest are the volume's corners. O(log n) (`vertices` sorted).
pub(super) fn is_hanging(vertices: &[u32], parents: &[Option<(usize, [u32; 2])>], v: u32) -> bool {
    match parents.get(v as usize).copied().flatten() {
        Some((_, [a, b])) => vertices.binary_search(&a).is_ok() && vertices.binary_search(&b).is_ok(),
        None => false,
    }
}

/// How a volume of mass `mass` with the sorted vertex ids `vertices` lumps its mass (finding 218):
/// with k corners and n vertices, each hanging vertex h gets w = mass / (k n), and the corners
/// start at mass / k and give up w · λ_c(h) for each h (λ: h's barycentric coordinates, pushed
/// down the split tree: a midpoint passes half of what it owes to each end, children before
/// parents). Hence Σ shares = mass, every share ≥ mass / n, and Σ share · x = mass · (mean of the
/// corners) for any affine placement of the hanging vertices. O(n log n).
pub(super) fn volume_mass_shares(
    vertices: &[u32],
    mass: f64,
    parents: &[Option<(usize, [u32; 2])>],
) -> Vec<(u32, f64)> {
    let mut hanging: Vec<(usize, u32)> = vertices
        .iter()
        .filter(|&&v| is_hanging(vertices, parents, v))
        .map(|&v| (parents[v as usize].map_or(0, |(i, _)| i), v))
        .collect();
    let (n, k) = (vertices.len(), vertices.len() - hanging.len());
    if k == 0 {
        return vertices.iter().map(|&v| (v, mass / n as f64)).collect();
    }
    let (base, w) = (mass / k as f64, mass / (k as f64 * n as f64));
    let at = |v: u32| vertices.binary_search(&v).unwrap_or(0);
    let (mut share, mut owed) = (vec![base; n], vec![0.0; n]);
    hanging.sort_unstable_by(|x, y| y.cmp(x)); // latest split first: children before parents
    for &(_, h) in &hanging {
        // every debt into h has arrived (its children came first); h passes it on, keeps w
        let debt = std::mem::take(&mut owed[at(h)]) + w;
        share[at(h)] = w;
        if let Some((_, [a, b])) = parents[h as usize] {
            owed[at(a)] += debt / 2.0;
            owed[at(b)] += debt / 2.0;
        }
    }
    vertices.iter().zip(share.iter().zip(&owed)).map(|(&v, (&s, &debt))| (v, s - debt)).collect()
}

/// The distinct vertices of the volume of `t` in the finest map, as their
/// [origins](LeveledMap::vertex_origin) (sorted: the keys of [`split_parents`]) and their ids
/// (parallel). Distinct ids have distinct origins in one volume. O(volume).
pub(super) fn volume_vertices(m: &LeveledMap<3>, t: DartId) -> (Vec<u32>, Vec<u32>) {
    let mut vs: Vec<(u32, u32)> = m
        .map()
        .orbit(t, AlphaMask::of(&[0, 1, 2]))
        .iter()
        .map(|&x| m.map().vertex_id(x).0)
        .map(|v| (m.vertex_origin(v), v))
        .collect();
    vs.sort_unstable();
    vs.dedup();
    debug_assert!(vs.windows(2).all(|w| w[0].0 != w[1].0), "topomech bug: two vertices of one volume share an origin");
    vs.into_iter().unzip()
}

/// [`volume_mass_shares`] of the volume of `t` by vertex id (sorted), its vertices looked up in
/// `parents` by their origins. O(volume + n log n).
pub(super) fn volume_shares_by_id(
    m: &LeveledMap<3>,
    t: DartId,
    mass: f64,
    parents: &[Option<(usize, [u32; 2])>],
) -> Vec<(u32, f64)> {
    let (origins, ids) = volume_vertices(m, t);
    let mut out: Vec<(u32, f64)> =
        volume_mass_shares(&origins, mass, parents).into_iter().zip(ids).map(|((_, w), v)| (v, w)).collect();
    out.sort_unstable_by_key(|&(v, _)| v);
    out
}

/// The corners of the volume of `t` (its vertices that do not hang on it, [`is_hanging`] by
/// origin), as vertex ids. O(volume + n log n).
pub(super) fn volume_corners(m: &LeveledMap<3>, t: DartId, parents: &[Option<(usize, [u32; 2])>]) -> Vec<u32> {
    let (origins, ids) = volume_vertices(m, t);
    origins.iter().zip(ids).filter(|&(&o, _)| !is_hanging(&origins, parents, o)).map(|(_, v)| v).collect()
}

/// The splitter of [`LeveledMechanics::refine_around`] on maps with level skips
/// ([`LeveledMap::refine_mixed`]): each split with its springs and masses
/// ([`LeveledMechanics::split_followed`]), the bulk path where it applies.
struct CoupledSplit<'a> {
    mech: &'a mut LeveledMechanics,
    center: [f64; 3],
    radius: f64,
}

impl LevelSplit for CoupledSplit<'_> {
    type Error = CouplingError;

    fn split(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<(), CouplingError> {
        self.mech.split_followed(m, d, level).map(|_| ())
    }

    fn bulk(&mut self, m: &mut LeveledMap<3>, level: u8) -> Result<Option<usize>, CouplingError> {
        self.mech.refine_level_in_bulk(m, self.center, self.radius, level)
    }

    fn check_zone(&mut self, m: &LeveledMap<3>, level: u8, zone: &[DartId]) -> Result<(), CouplingError> {
        m.check_zone(level, zone, &self.mech.masses)?;
        self.mech.check_split_headroom(m, zone)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The refusal keeps a margin of 2⁻⁴⁰ below `f64::MAX` (a bound within it could still
    /// overflow by the rounding of the children's terms), and never refuses without a dart.
    #[test]
    fn refuse_past_max_keeps_its_margin() {
        let d = Some(DartId(3));
        assert!(refuse_past_max(d, 1e300).is_ok());
        assert!(refuse_past_max(d, f64::MAX * (1.0 - 2f64.powi(-30))).is_ok());
        let near = f64::MAX * (1.0 - 2f64.powi(-45));
        assert_eq!(refuse_past_max(d, near), Err(CouplingError::SplitOverflow { dart: DartId(3), bound: near }));
        assert!(refuse_past_max(d, f64::INFINITY).is_err());
        assert!(refuse_past_max(d, f64::NAN).is_err());
        assert!(refuse_past_max(None, f64::INFINITY).is_ok());
    }
}

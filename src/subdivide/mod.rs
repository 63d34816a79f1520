//! Adaptive-resolution subdivision with levels (seed 004, §4.3–§5).
//!
//! A [`LeveledMap`] is the paper's extended G-map G = (B_i, α0^i | i ∈ [0, k], α1, …, αn): one
//! [`GMap`] (the finest level G_k, always valid) plus, per dart,
//! - the *dart level*: the level at which the dart was created, so B_i = {d : level(d) ≤ i} and
//!   B_0 ⊂ B_1 ⊂ … ⊂ B_k by construction;
//! - the resolution levels μa (edge), μf (face) and μt (tetrahedron, 3D only; 0 in 2D);
//! - the history of its links: for every αj that an operation of level L changed, the value the
//!   link had *before* level L. The paper stores only α0^i because it subdivides uniformly;
//!   adaptive refinement also changes α1 (a vertex inserted on an edge by a neighbour becomes a
//!   corner later) and in 3D α2, so the history is kept for every αj.
//!
//! [`LeveledMap::level`] rebuilds G_i = (B_i, α0^i, α1^i, …) as a [`GMap`] of its own.
//!
//! # Level order
//! Operations are applied in non-decreasing level order: an operation of level L requires
//! L ≥ [`LeveledMap::max_level`]. That is the order of the paper's algorithms (refine a zone level
//! by level) and it makes every G_i exact: a level-L change is always the latest one.
//!
//! # Laws checked by [`LeveledMap::check_levels`]
//! μt ≤ μf ≤ μa for every dart (Theorem 1 and its corollary); μa constant on edges, μf on faces,
//! μt on volumes of the finest level; dart levels ≤ max level.
//!
//! # Saving
//! [`LeveledMap::to_parts`] exports every record as plain data ([`LevelParts`]);
//! [`LeveledMap::from_parts`] rebuilds a leveled map from its finest map and those records after
//! checking them (lengths, level bounds, well-formed histories, every level's links closed and
//! involutive, then [`LeveledMap::check_all`]). `store::save_leveled` / `load_leveled` use them.

mod balance;
mod conform;
mod cut;
mod cut_error;
mod flat;
pub mod fuzz;
mod history;
mod ops;
mod orient;
mod origins;
mod own_level;
mod parts;
mod region;
mod springs;
mod springs_check;
mod springs_cut;
mod tet;
mod tri;
mod uniform;

pub use conform::{triangulate_polygon, ConformingMesh};
pub use cut_error::{cut_error, measure_cut, CutSurfaceError};
pub use parts::{record_errors, DartLevels, HistoryEntry, LevelParts, LevelPartsError};
pub use region::{tet_distance, Refinement, TetMasses};
pub use springs::{CouplingError, EdgeKey, LeveledMechanics, Spring};
pub use springs_check::SpringLawError;

use crate::gmap::{DartId, GMap, InvariantViolation};

/// Levels above 0 up to which every operation checks every level's map under
/// `expensive-checks` (`LeveledMap::check_after_op`; deeper maps check the levels the operation
/// touches and the top one).
pub const FULLY_CHECKED_LEVELS: u8 = 4;

/// Darts up to which every operation checks the level maps under `expensive-checks`
/// (`LeveledMap::check_after_op`; larger maps check the finest map and the μ order per
/// operation, and every law at the end of a refinement around a ball or a uniform level).
pub const FULLY_CHECKED_DARTS: usize = 50_000;

/// The largest level an operation may use.
pub const MAX_LEVEL: u8 = 250;

/// The default limit on the darts a refinement may grow a [`LeveledMap`] to
/// ([`LeveledMap::set_max_darts`]): 10⁸ darts, about 9 GB for a refined tet map (measured: 91
/// bytes per dart with levels, history and points, `refine` of liver_547 to level 3). Each
/// 1→8 level multiplies the darts of the refined zone by 8, so without a limit a large ball and a
/// few levels exhaust the memory of any machine; the refinement is refused before it starts.
pub const DEFAULT_MAX_DARTS: usize = 100_000_000;

/// The edge cells of one vertex insertion ([`LeveledMap::edge_split_log`]): the edge with cell id
/// `edge` joining `ends[0]` and `ends[1]` was split at the new vertex `vertex`; afterwards the half
/// `(ends[0], vertex)` has edge id `halves[0]` and the half `(vertex, ends[1])` has `halves[1]`. One of
/// the halves keeps `edge` (the relabelling keeps an old id when it can), the other gets a fresh id.
/// Edge ids, unlike vertex pairs, tell apart two edges joining the same two vertices (a cut edge
/// whose ends stayed joined).
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::{EdgeSplit, LeveledMap};
/// # use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// let edge = m.map().cell_id(1, d).0;
/// let mid = m.split_edge(d, 1).unwrap();
/// let s: EdgeSplit = m.edge_split_log()[0];
/// assert_eq!((s.vertex, s.edge), (m.map().vertex_id(mid).0, edge));
/// assert_eq!(s.halves[0], m.map().cell_id(1, d).0);
/// assert!(s.halves.contains(&edge) && s.halves[0] != s.halves[1]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeSplit {
    /// The inserted vertex id.
    pub vertex: u32,
    /// The end vertex ids of the split edge (as in [`LeveledMap::split_log`]).
    pub ends: [u32; 2],
    /// The edge cell id of the split edge before the operation.
    pub edge: u32,
    /// The edge cell ids of the halves at `ends[0]` and at `ends[1]` after the operation.
    pub halves: [u32; 2],
}

/// A link value that an operation of level `level` overwrote: before `level`, αj(d) was `old`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct LinkChange {
    level: u8,
    j: u8,
    old: u32,
}

/// Per-dart resolution levels (seed 004, §4.3): μa, μf, μt.
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_tet(d, 1).unwrap();
/// let mu = m.mu(d);
/// assert!(mu.tet <= mu.face && mu.face <= mu.edge);
/// assert_eq!(mu.tet, 1);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mu {
    /// Edge resolution level μa.
    pub edge: u8,
    /// Face resolution level μf.
    pub face: u8,
    /// Tetrahedron (volume) resolution level μt; 0 in 2D.
    pub tet: u8,
}

/// Errors of the subdivision operations. The map (and the masses, springs and points that go
/// with it) is unchanged when one is returned, with one documented exception: a multi-level
/// refinement (`refine_around`, and the CLI's levels) that meets [`SubdivideError::DartLimit`] or
/// [`SubdivideError::BelowPrecision`] at a later level keeps the levels it finished.
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::{LeveledMap, SubdivideError};
/// # use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![]);
/// let d = m.map().darts().next().unwrap();
/// assert!(matches!(m.split_edge(d, 251), Err(SubdivideError::LevelTooHigh(251))));
/// m.subdivide_triangle(d, 2).unwrap();
/// let e = m.subdivide_triangle(d, 1).unwrap_err();
/// assert!(matches!(e, SubdivideError::LevelBelowMax { level: 1, max_level: 2 }));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubdivideError {
    /// The dart is not live.
    #[error("{0} does not exist in this map")]
    NoSuchDart(DartId),
    /// Operations must come in non-decreasing level order.
    #[error("level {level} is below the map's maximum level {max_level}: operations must not go back in level")]
    LevelBelowMax {
        /// The requested level.
        level: u8,
        /// The map's current maximum level.
        max_level: u8,
    },
    /// The level is above [`MAX_LEVEL`].
    #[error("level {0} is above the maximum {MAX_LEVEL}")]
    LevelTooHigh(u8),
    /// A cell can only be subdivided at a level above its own resolution level.
    #[error("the {dim}-cell of {dart} already has level {cell_level} ≥ {level}")]
    AlreadyAtLevel {
        /// A dart of the cell.
        dart: DartId,
        /// 1 = edge, 2 = face, 3 = tetrahedron.
        dim: usize,
        /// Its current resolution level.
        cell_level: u8,
        /// The requested level.
        level: u8,
    },
    /// The face is not a triangle (three corners, any number of inserted vertices on its sides).
    #[error("the face of {dart} has {corners} corners, not 3")]
    NotATriangle {
        /// A dart of the face.
        dart: DartId,
        /// Corners found.
        corners: usize,
    },
    /// The operation exists for these dimensions only (faces: n ∈ {2, 3}).
    #[error("this operation is not defined for {0}-G-maps")]
    WrongDimension(usize),
    /// The volume, at its own level μt, is not a tetrahedron (four corners of three faces each).
    #[error("the volume of {dart} has {corners} corners at its own level, not 4")]
    NotATetrahedron {
        /// A dart of the volume.
        dart: DartId,
        /// Corners found.
        corners: usize,
    },
    /// A face of the tetrahedron was refined beyond one 1→4 step, or an inner edge of one of its
    /// split faces carries an inserted vertex (tetrahedron 1→8 does not support this yet).
    #[error("a face of the tetrahedron at {dart} is refined beyond one 1→4 step")]
    FaceRefinedTooFar {
        /// A dart of the offending face (or of the volume when the face count is wrong).
        dart: DartId,
    },
    /// The face to cut has an α3-free dart: it is not glued to another volume there.
    #[error("the face of {0} is not sewn (α3-free)")]
    FaceNotSewn(DartId),
    /// The edge has an α0-free dart: it has no second vertex to split between.
    #[error("the edge of {0} is open (α0-free)")]
    OpenEdge(DartId),
    /// Uniform refinement ([`LeveledMap::refine_uniform`]) needs every dart at one resolution
    /// level m (μa = μf = m, μt = m in 3D and 0 in 2D) and no inserted (flat) vertex.
    #[error("uniform refinement needs every cell at one level {expected} and no inserted vertex: {dart} has μa = {}, μf = {}, μt = {}", .mu.edge, .mu.face, .mu.tet)]
    NotUniform {
        /// The first dart found off the common level (or flat).
        dart: DartId,
        /// Its levels.
        mu: Mu,
        /// The level of the first live dart, which every dart must share.
        expected: u8,
    },
    /// The conforming closure met a face polygon it cannot triangulate (zero area or a reflex
    /// corner) or a cone tet of zero volume, at the face or volume of this dart.
    #[error("the face or volume of {0} is degenerate: no conforming triangulation")]
    DegenerateFace(DartId),
    /// The conforming closure ([`LeveledMap::conforming_tets`]) is a tet list, and a tet list
    /// glues two tets exactly where they share three vertex ids: a triangle of the cut
    /// (α3-free) face of `dart` has the vertex ids `triangle` of a triangle of the face of `other`
    /// (the other side of the same cut when the cut split none of these vertices, or another face
    /// on the same vertices), so [`crate::GMap::from_tets`] would glue the cut again. Refused
    /// rather than output with another topology; nothing is changed.
    #[error(
        "the conforming closure cannot express the cut face of {dart}: its triangle {triangle:?} (vertex ids) \
         is also a triangle of the face of {other}, and a tet list glues two tets sharing three vertices \
         (the cut did not split them: close the map before cutting)"
    )]
    CutNotExpressible {
        /// A dart of the cut (α3-free) face side.
        dart: DartId,
        /// A dart of the other face side with the same triangle.
        other: DartId,
        /// The shared triangle's vertex ids, increasing.
        triangle: [u32; 3],
    },
    /// The ball of a refinement by region has a non-finite centre or a radius that is not a
    /// finite number ≥ 0 (with NaN no tet would compare inside it: nothing would be refined).
    #[error("refinement ball centre {center:?} / radius {radius} is not finite (or the radius is negative)")]
    BadBall {
        /// The centre given.
        center: [f64; 3],
        /// The radius given.
        radius: f64,
    },
    /// A geometric query (a volume, a distance to a ball, a mass from a density) reached a vertex
    /// without a position: the points given to [`LeveledMap::new`] stop before its id. Every
    /// subdivision operation refuses such a partial geometry before it changes anything (it
    /// would take the origin for that vertex); a map given no points at all is accepted.
    #[error("vertex {vertex} has no position (the map was given {points} points)")]
    NoPosition {
        /// The vertex id.
        vertex: u32,
        /// How many positions the map has.
        points: usize,
    },
    /// A geometric query reached a vertex whose position is NaN or infinite (the points given to
    /// [`LeveledMap::new`] are not checked there; a volume, distance or mass from them would be
    /// NaN and compare false everywhere).
    #[error("vertex {vertex} has a non-finite position {position:?}")]
    NonFinitePosition {
        /// The vertex id.
        vertex: u32,
        /// Its stored position.
        position: [f64; 3],
    },
    /// A live volume has no entry in the [`TetMasses`] given (masses made for another, smaller
    /// map, or the volume was made by an operation without masses): sharing its mass would
    /// take it as 0 and lose the parent's. Refused before any change.
    #[error("volume {volume} has no mass (the masses hold {masses} entries): masses of another map, or a volume made without them")]
    NoMass {
        /// The volume id.
        volume: u32,
        /// How many entries the masses hold.
        masses: usize,
    },
    /// A live volume's entry in the [`TetMasses`] given is negative or not finite.
    #[error("volume {volume} has mass {mass} (must be finite and >= 0)")]
    BadMass {
        /// The volume id.
        volume: u32,
        /// Its mass.
        mass: f64,
    },
    /// A live volume's mass is positive but too small for f64: its quarter (the least a vertex
    /// of it can weigh) has no finite inverse, or, for a tet to split, the quarter of the eighth
    /// each child takes (finding 268). Refused before any change.
    #[error("volume {volume} has mass {mass:e}: too small for f64 (a quarter of it, or of a child's eighth when it is split, has no finite inverse)")]
    MassTooSmall {
        /// The volume id.
        volume: u32,
        /// Its mass.
        mass: f64,
    },
    /// The face to split is sewn onto itself: the αj (j ≥ 2) of one of its darts is in the
    /// same face (two sides glued into a cone, or the face folded by α3). A valid g-map, but a
    /// 1→4 split of it is not supported (finding 270). Refused before any change.
    #[error("the face of {dart} is sewn onto itself by α{alpha}: its 1→4 split is not supported")]
    SelfGluedFace {
        /// A dart of the face whose αj is in the face.
        dart: DartId,
        /// The index j.
        alpha: usize,
    },
    /// A density for [`TetMasses::from_density`] that is not a finite number > 0.
    #[error("density {0} must be a finite number > 0")]
    BadDensity(f64),
    /// The masses of the live volumes sum to more than the largest `f64` (a density so large
    /// that masses overflow, or finite entries whose total does): the totals a refinement
    /// reports would be ∞ and NaN. A [`crate::mechanics::Body`] refuses such masses too
    /// (`ModelError::Overflow`).
    #[error("the volume masses sum to {total}: beyond the range of f64")]
    MassOverflow {
        /// The sum (+∞).
        total: f64,
    },
    /// A refinement would grow the map past its dart limit ([`LeveledMap::set_max_darts`]):
    /// refused before anything changed at that level (the levels done before it are kept). The
    /// darts after the level are counted exactly, before it starts (a bulk level: 2ⁿ × the darts;
    /// an op-by-op level or a catch-up: 96 per zone tet, 12 per side of each face it splits 1→4,
    /// and the whole orbit of each edge it splits, 4 darts per tet of the edge's ring), so a level
    /// that fits is never refused and an accepted one never passes the limit. (A catch-up whose
    /// zone mixes levels may add a few darts more than counted; it checks the limit again after
    /// its splits and puts the map back.)
    #[error(
        "refining {tets} cells at level {level} would grow the map from {darts} to about {estimate} darts, \
         over the limit of {limit} darts (raise it with LeveledMap::set_max_darts or --max-darts)"
    )]
    DartLimit {
        /// The level refused.
        level: u8,
        /// Cells (tets, or triangles in 2D) that level would subdivide.
        tets: usize,
        /// Live darts now.
        darts: usize,
        /// Darts after the level: exact, counted before it starts (a catch-up zone mixing
        /// levels, refused after its splits, gives the darts it reached).
        estimate: usize,
        /// The limit.
        limit: usize,
    },
    /// A split past the precision of the `f64` coordinates: the rounded midpoint of the edge's
    /// end positions (the position its new vertex would get) is strictly between them along no
    /// axis: it is an end, or the ends coincide. Accepting it would make tets of zero
    /// or inverted volume that keep a positive mass (m ≠ ρ·V) and lose the point a refinement is
    /// around. Halving an edge of length ℓ at coordinates of size |x| works about
    /// 52 − log2(|x| / ℓ) times: a unit tet at (1, 1, 1) refines to level 52 and level 53 is
    /// refused. Refused before any change (at a level of a refinement, before its first split);
    /// not checked on a map without points.
    #[error(
        "splitting the edge of {dart} (vertices {} and {}) at level {level} is past the precision of f64: \
         the rounded midpoint of {:?} and {:?} is not strictly between them along the edge (edges can be \
         halved about 52 - log2(|coordinates| / edge length) times)",
        .vertices[0], .vertices[1], .positions[0], .positions[1]
    )]
    BelowPrecision {
        /// The level refused.
        level: u8,
        /// A dart of the edge, at `vertices[0]`.
        dart: DartId,
        /// The edge's end vertex ids.
        vertices: [u32; 2],
        /// Their positions.
        positions: [[f64; 3]; 2],
    },
    /// A 1→8 split past the precision of the `f64` coordinates: the tet is valid but so nearly
    /// flat at its scale (corners within a few ulps of a plane) that, with its edge midpoints
    /// rounded, a child would be flat or oriented against it — and keep a share of its mass
    /// (finding 247). Checked for the 8 children of each of the 3 diagonals of the octahedron
    /// (the choice among near ties may fall to vertex ids), by a float filter and else exact
    /// orientation; an exactly flat tet is not refused (it has no orientation to keep).
    /// Refused before any change (at a level of a refinement, before its first split); not
    /// checked on a map without points.
    #[error(
        "splitting the tet of {dart} (corners {corners:?}) 1->8 at level {level} is past the precision of f64: \
         with its midpoints rounded, the child of corner and midpoint labels {child:?} would be flat or \
         inverted (the tet is nearly flat at the scale of its coordinates)"
    )]
    FlatChild {
        /// The level refused.
        level: u8,
        /// A dart of the tet.
        dart: DartId,
        /// Its corner vertex ids (labels 0..3).
        corners: [u32; 4],
        /// The child's labels: corners 0..3, midpoint of corners x < y = 4 + index of (x, y) in
        /// (0,1), (0,2), (0,3), (1,2), (1,3), (2,3).
        child: [u8; 4],
    },
    /// A 1→4 split of a triangle of a 2-G-map past the precision of the `f64` coordinates: the
    /// triangle is valid but so nearly collinear at its scale that, with its side midpoints
    /// placed (rounded, or the inserted vertices already there), a child would be collinear or
    /// oriented against it, in the projection onto the coordinate plane where the parent's
    /// normal is largest (the 2D analogue of [`SubdivideError::FlatChild`]). Checked by a float
    /// filter and else exact orientation; an exactly collinear triangle is not refused. Refused
    /// before any change; not checked on a map without points.
    #[error(
        "splitting the triangle of {dart} (corners {corners:?}) 1->4 at level {level} is past the precision of \
         f64: with its side midpoints placed, the child of corner and midpoint labels {child:?} would be \
         collinear or inverted (the triangle is nearly collinear at the scale of its coordinates)"
    )]
    FlatTriangleChild {
        /// The level refused.
        level: u8,
        /// A dart of the triangle.
        dart: DartId,
        /// Its corner vertex ids (labels 0..2), in the order of its sides.
        corners: [u32; 3],
        /// The child's labels: corners 0..2, midpoint of side k = (k, k + 1 mod 3) = 3 + k.
        child: [u8; 3],
    },
}

/// Violations of the level laws found by [`LeveledMap::check_levels`] and [`LeveledMap::check_all`].
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::{LevelError, LeveledMap, Mu};
/// # use topomech::{DartId, GMap};
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let m = LeveledMap::new(map, vec![]);
/// assert!(m.check_all().is_ok()); // a fresh level-0 map keeps every law
/// let e = LevelError::MuOrder { dart: DartId(0), mu: Mu { edge: 0, face: 1, tet: 0 } };
/// assert!(e.to_string().contains("μt ≤ μf ≤ μa"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LevelError {
    /// μt ≤ μf ≤ μa is broken at a dart.
    #[error("{dart}: μt = {}, μf = {}, μa = {} breaks μt ≤ μf ≤ μa", .mu.tet, .mu.face, .mu.edge)]
    MuOrder {
        /// The dart.
        dart: DartId,
        /// Its levels.
        mu: Mu,
    },
    /// A dart's creation level or its μa (hence μf, μt) is above the map's maximum level k:
    /// no operation makes one (every split at level L ≤ k sets μ ≤ L), and a refinement would
    /// skip such cells at every level up to k.
    #[error("{dart}: dart level {level}, μa = {} above the max level {max_level}", .mu.edge)]
    AboveMaxLevel {
        /// The dart.
        dart: DartId,
        /// Its creation level.
        level: u8,
        /// Its levels.
        mu: Mu,
        /// The map's maximum level.
        max_level: u8,
    },
    /// A resolution level differs between two darts of one cell of the finest level.
    #[error("μ of the {dim}-cell differs between {dart} ({a}) and {other} ({b})")]
    MuNotConstant {
        /// 1 = μa on edges, 2 = μf on faces, 3 = μt on volumes.
        dim: usize,
        /// A dart.
        dart: DartId,
        /// Its level.
        a: u8,
        /// A dart of the same cell.
        other: DartId,
        /// Its level.
        b: u8,
    },
    /// A dart of B_i has an image outside B_i at level i.
    #[error("level {level}: α{j}({dart}) = {image} is not in B_{level}")]
    NotClosed {
        /// The level.
        level: u8,
        /// The dart.
        dart: DartId,
        /// The involution.
        j: usize,
        /// Its image.
        image: DartId,
    },
    /// The G-map extracted at a level breaks a G-map law.
    #[error("level {level} is not a valid G-map: {source}")]
    InvalidLevel {
        /// The level.
        level: u8,
        /// The law broken.
        source: InvariantViolation,
    },
    /// The finest map breaks a G-map law.
    #[error("the finest map is not valid: {0}")]
    InvalidMap(InvariantViolation),
    /// A dart's flat flag (its vertex is an inserted vertex of a side of its face) disagrees
    /// with the flag its level and link history determine: flat exactly when the dart was made,
    /// with its α1 partner, by the split of one edge at its level L ≥ 1 (the two half-edges'
    /// far darts record each other as their α0 before level L) and neither α1 link changed
    /// since (see [`LeveledMap::check_all`]).
    #[error("{dart}: flat flag is {flat}, but its level and link history make it {}", !.flat)]
    FlatFlag {
        /// The dart.
        dart: DartId,
        /// The flag stored for it.
        flat: bool,
    },
    /// The split log disagrees with the link history on an inserted vertex (module `origins`:
    /// the history witnesses each edge split; ids are [origins](LeveledMap::vertex_origin)):
    /// the log has no entry, a second entry, or other ends for it, or two witnesses disagree.
    #[error("split log: vertex {vertex} has the ends {logged:?} in the log but {witnessed:?} in the link history")]
    SplitLog {
        /// The inserted vertex (an origin).
        vertex: u32,
        /// Its ends in the log (increasing), if it has an entry.
        logged: Option<[u32; 2]>,
        /// Its ends as the history witnesses them (increasing), if it does.
        witnessed: Option<[u32; 2]>,
    },
    /// A cut's copy has an origin that is itself a copy.
    #[error("vertex {vertex} has the origin {origin}, which is a copy of {origin_of_origin}")]
    OriginNotRoot {
        /// The copy.
        vertex: u32,
        /// Its origin.
        origin: u32,
        /// The origin's own origin.
        origin_of_origin: u32,
    },
    /// A cut's copy does not lie at the point of its origin.
    #[error("vertex {vertex} does not lie at the point of its origin {origin}")]
    OriginElsewhere {
        /// The copy.
        vertex: u32,
        /// Its origin.
        origin: u32,
    },
    /// A k-cell is not a cell of the level its μ names (module `own_level`): it has no dart of
    /// that level (`escape` = `None`), or its orbit ⟨α0, …, α(k−1)⟩ at that level reaches
    /// `escape`, a dart of another k-cell (the cell is part of a coarser one there).
    #[error("the {dim}-cell of {dart} is no cell of its level {level} ({})", .escape.map_or("it has no dart of that level".to_string(), |y| format!("at that level it reaches {y} of another cell")))]
    NotAtOwnLevel {
        /// The dimension k of the cell (1 edge, 2 face, 3 volume).
        dim: usize,
        /// A dart of the cell.
        dart: DartId,
        /// Its resolution level (μa, μf or μt).
        level: u8,
        /// A dart of another k-cell its orbit at that level reaches, if any.
        escape: Option<DartId>,
    },
    /// A top cell (a volume in 3D, a face in 2D) with resolution level L > 0 was already a cell
    /// at level L − 1: no operation of level L made it (module `own_level`, minimality).
    #[error("the top cell of {dart} has the level {level} but was already a cell at level {}", .level - 1)]
    AboveOwnLevel {
        /// A dart of the cell.
        dart: DartId,
        /// Its resolution level.
        level: u8,
    },
    /// An n-cell (a volume in 3D) has two vertices with one origin: a cut never splits a vertex
    /// inside a cell.
    #[error("the top cell of {dart} has the vertices {} and {} of one origin {origin}", .vertices[0], .vertices[1])]
    OriginTwiceInCell {
        /// A dart of the cell.
        dart: DartId,
        /// The shared origin.
        origin: u32,
        /// The two vertices (increasing).
        vertices: [u32; 2],
    },
}

/// An extracted level G_i together with the ids its darts have in the leveled map.
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// let v = m.level(0).unwrap();
/// assert_eq!(v.darts.len(), v.map.dart_count());
/// assert!(v.darts.iter().all(|&x| m.dart_level(x) == 0));
/// ```
#[derive(Clone, Debug)]
pub struct LevelView<const N: usize> {
    /// G_i as a G-map of its own (dart k of `map` is dart `darts[k]` of the leveled map).
    pub map: GMap<N>,
    /// The leveled-map dart of each dart of `map`.
    pub darts: Vec<DartId>,
}

/// A G-map with adaptive resolution levels. See the [module docs](self).
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_triangle(d, 1).unwrap();
/// assert_eq!(m.map().count_cells().0[2], 4);
/// assert_eq!(m.level(0).unwrap().map.count_cells().0[2], 1);
/// assert!(m.check_all().is_ok());
/// ```
#[derive(Clone, Debug)]
pub struct LeveledMap<const N: usize> {
    map: GMap<N>,
    dart_level: Vec<u8>,
    mu: Vec<Mu>,
    /// Whether the vertex of the dart inside its face is an inserted (flat) vertex of a side of
    /// the face rather than one of its corners.
    flat: Vec<bool>,
    history: history::LinkHistory,
    max_level: u8,
    points: Vec<[f64; 3]>,
    /// Every inserted vertex as [new vertex id, end vertex ids] (see [`LeveledMap::split_log`]).
    splits: Vec<[u32; 3]>,
    /// The edge cells of every inserted vertex, parallel to `splits` (see [`LeveledMap::edge_split_log`]).
    edge_splits: Vec<EdgeSplit>,
    /// `origins[v]`: the vertex a cut ([`LeveledMap::unsew_face`]) split v from, followed to one
    /// that no cut made; v itself past the end or for a vertex no cut made
    /// ([`LeveledMap::vertex_origin`]).
    origins: Vec<u32>,
    op: ops::OpLog,
    /// The dart limit of the refinements ([`LeveledMap::set_max_darts`]).
    max_darts: usize,
    /// Operations that changed the map so far ([`LeveledMap::version`]).
    version: u64,
    /// A process-wide unique stamp of the map's present state ([`LeveledMap::stamp`]).
    stamp: u64,
}

impl<const N: usize> LeveledMap<N> {
    /// Wraps a G-map as level 0: every dart gets level 0 and μ = 0. `points[v]` is the position of
    /// the vertex with id v (may be empty when geometry is not needed; new vertices then get the
    /// origin). The geometric queries (volumes, balls, masses from a density) refuse a vertex
    /// past the end of `points` with [`SubdivideError::NoPosition`] and a NaN or infinite
    /// position with [`SubdivideError::NonFinitePosition`]; the operations refuse points that stop
    /// before a live vertex (but not an empty list). O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map.clone(), pts.clone());
    /// let d = m.map().darts().next().unwrap();
    /// assert_eq!((m.max_level(), m.darts_at_level(0)), (0, 24));
    /// assert_eq!(m.mu(d), topomech::subdivide::Mu::default());
    /// // Points that stop before vertex 3: refused, not filled in with the origin.
    /// let mut partial = LeveledMap::new(map, pts[..3].to_vec());
    /// let e = partial.subdivide_tet(d, 1).unwrap_err();
    /// assert_eq!(e, topomech::subdivide::SubdivideError::NoPosition { vertex: 3, points: 3 });
    /// assert_eq!((partial.map().dart_count(), partial.points().len()), (24, 3));
    /// ```
    pub fn new(map: GMap<N>, points: Vec<[f64; 3]>) -> Self {
        let cap = map.capacity();
        LeveledMap {
            map,
            dart_level: vec![0; cap],
            mu: vec![Mu::default(); cap],
            flat: vec![false; cap],
            history: history::LinkHistory::new(cap),
            max_level: 0,
            points,
            splits: Vec::new(),
            edge_splits: Vec::new(),
            origins: Vec::new(),
            op: ops::OpLog::default(),
            max_darts: DEFAULT_MAX_DARTS,
            version: 0,
            stamp: crate::gmap::next_unique(),
        }
    }

    /// A stamp of the map's present state, unique in the process: a new map and every operation
    /// that changes it (each one that adds to [`LeveledMap::version`]) take a fresh one; a clone
    /// keeps it (it holds the same state). A [`LeveledMechanics`] records the stamp of the map it
    /// followed, so a map built apart — even of the same mesh, size and version — or a clone
    /// that went its own way is refused (round 25: a coupling ran on another map of the same
    /// size). O(1).
    pub(crate) fn stamp(&self) -> u64 {
        self.stamp
    }

    /// Counts one operation that changed the map: [`LeveledMap::version`] + 1 and a fresh
    /// [`LeveledMap::stamp`]. O(1).
    pub(crate) fn bump_version(&mut self) {
        self.version += 1;
        self.stamp = crate::gmap::next_unique();
    }

    /// Number of operations that changed the map since [`LeveledMap::new`] (or
    /// [`LeveledMap::from_parts`]): every accepted split, subdivision, bulk refinement level and
    /// face cut adds one; a refused operation adds nothing. A [`LeveledMechanics`] records the
    /// version it followed, so it can tell an operation called on the map alone. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::LeveledMap;
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![]);
    /// assert_eq!(m.version(), 0);
    /// let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    /// m.unsew_face(glued, 1).unwrap();
    /// assert_eq!(m.version(), 1);
    /// assert!(m.unsew_face(glued, 1).is_err()); // refused: no change
    /// assert_eq!(m.version(), 1);
    /// ```
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Sets the limit on the live darts the level-by-level refinements
    /// ([`LeveledMap::refine_around`], [`LeveledMap::refine_uniform`],
    /// [`LeveledMechanics::refine_around`]) may grow the map to; a level whose result (its darts
    /// counted exactly before it starts, see [`SubdivideError::DartLimit`]) exceeds it is refused
    /// with [`SubdivideError::DartLimit`] before it changes anything.
    /// Default [`DEFAULT_MAX_DARTS`]. Single operations (`subdivide_tet`, …) are not limited.
    /// A limit of the running process, not a record of the map: not saved by
    /// [`Self::to_parts`] or the store, so a loaded map has the default until it is set again
    /// (finding 337).
    /// O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::{LeveledMap, SubdivideError, TetMasses};
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    /// m.set_max_darts(1000); // level 1: 8 tets, 192 darts; level 2: 64 tets, 1536 darts
    /// let e = m.refine_around([0.1; 3], 10.0, 2, &mut masses).unwrap_err();
    /// assert!(matches!(e, SubdivideError::DartLimit { level: 2, darts: 192, limit: 1000, .. }));
    /// assert_eq!((m.max_level(), m.map().dart_count()), (1, 192)); // level 1 is kept
    /// m.check_all().unwrap();
    /// ```
    pub fn set_max_darts(&mut self, limit: usize) {
        self.max_darts = limit;
    }

    /// The dart limit of the refinements ([`LeveledMap::set_max_darts`]). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::subdivide::{LeveledMap, DEFAULT_MAX_DARTS};
    /// use topomech::GMap;
    ///
    /// let m = LeveledMap::new(GMap::<3>::new(), vec![]);
    /// assert_eq!(m.max_darts(), DEFAULT_MAX_DARTS);
    /// ```
    pub fn max_darts(&self) -> usize {
        self.max_darts
    }

    /// Refuses a refinement of `tets` cells at `level` that would leave `estimate` live darts,
    /// when that is over the limit ([`LeveledMap::set_max_darts`]). O(1).
    pub(crate) fn check_dart_limit(&self, level: u8, tets: usize, estimate: usize) -> Result<(), SubdivideError> {
        let darts = self.map.dart_count();
        // A level that adds no dart is never refused, even under a limit lowered below the map
        // (round 26: an empty zone was refused "from 144 to about 144 darts").
        if estimate <= self.max_darts || estimate <= darts {
            return Ok(());
        }
        Err(SubdivideError::DartLimit { level, tets, darts, estimate, limit: self.max_darts })
    }

    /// The finest level G_k. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.map().dart_count(), 28); // the 4 darts of the edge got a partner
    /// assert_eq!(m.map().count_cells().0[0], 5);
    /// ```
    pub fn map(&self) -> &GMap<N> {
        &self.map
    }

    /// The largest level any operation has used (k). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// assert_eq!(m.max_level(), 0);
    /// m.subdivide_triangle(d, 2).unwrap();
    /// assert_eq!(m.max_level(), 2);
    /// ```
    pub fn max_level(&self) -> u8 {
        self.max_level
    }

    /// The level at which dart `d` was created. O(1).
    ///
    /// # Panics
    /// If `d` was never allocated (not below the map's capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!((m.dart_level(d), m.dart_level(mid)), (0, 1));
    /// ```
    pub fn dart_level(&self, d: DartId) -> u8 {
        self.dart_level[d.index()]
    }

    /// μa, μf, μt of dart `d`. O(1).
    ///
    /// # Panics
    /// If `d` was never allocated (not below the map's capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// let mu = m.mu(d);
    /// assert_eq!((mu.edge, mu.face, mu.tet), (1, 1, 0));
    /// ```
    pub fn mu(&self, d: DartId) -> Mu {
        self.mu[d.index()]
    }

    /// Vertex positions keyed by vertex id (new vertices are edge midpoints). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.points().len(), 4);
    /// assert_eq!(m.points()[3], m.position(mid));
    /// ```
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Every vertex inserted on an edge, in insertion order, as `[new vertex id, end vertex id,
    /// end vertex id]` (the ends of the edge it split; a cut may give a vertex copies, which
    /// [`Self::vertex_origin`] maps back). [`LeveledMechanics`] follows the map with it, and the
    /// lumped masses find hanging vertices through it. Not saved by [`LeveledMap::to_parts`]: the
    /// link history holds it, and [`LeveledMap::from_parts`] rebuilds it
    /// ([`Self::rebuild_split_log`]: ids as origins, ends increasing, in (level, vertex) order;
    /// finding 336: a loaded map had an empty log, and lumped every midpoint as a corner). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let (a, b) = (m.map().vertex_id(d).0, m.map().vertex_id(m.map().alpha_dyn(0, d)).0);
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.split_log(), &[[m.map().vertex_id(mid).0, a, b]]);
    /// m.subdivide_triangle(d, 2).unwrap(); // two more sides split
    /// assert_eq!(m.split_log().len(), 3);
    /// ```
    pub fn split_log(&self) -> &[[u32; 3]] {
        &self.splits
    }

    /// The vertex a cut split `v` from: the id of the vertex v was a side of before every
    /// [`Self::unsew_face`] since this map was created or loaded (v itself if no cut made it).
    /// A copy lies where its origin lies and stands for it in [`Self::split_log`]: a volume's
    /// vertices have distinct origins (a cut splits a vertex between volumes, never inside one),
    /// and a cut vertex hangs on a volume exactly when its origin did (round 38: the lumped
    /// masses treated a cut copy of a midpoint as a corner). Saved by [`LeveledMap::to_parts`]
    /// (as [`LevelParts::origins`]; finding 336: it was not, and a loaded map lumped cut
    /// copies as corners). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![]);
    /// let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    /// m.unsew_face(glued, 1).unwrap(); // vertices 1, 2, 3 split: three new ids
    /// let origins: Vec<u32> = (0..8).map(|v| m.vertex_origin(v)).collect();
    /// assert_eq!(origins[..5], [0, 1, 2, 3, 4]);
    /// assert_eq!({ let mut o = origins[5..].to_vec(); o.sort(); o }, [1, 2, 3]);
    /// ```
    pub fn vertex_origin(&self, v: u32) -> u32 {
        self.origins.get(v as usize).copied().unwrap_or(v)
    }

    /// Records that the vertex `copy` was split from `from` by a cut ([`Self::vertex_origin`]).
    /// O(1) amortized.
    pub(crate) fn set_vertex_origin(&mut self, copy: u32, from: u32) {
        let origin = self.vertex_origin(from);
        let k = copy as usize;
        if self.origins.len() <= k {
            let start = self.origins.len() as u32;
            self.origins.extend(start..=copy);
        }
        self.origins[k] = origin;
    }

    /// The edge cells of every entry of [`Self::split_log`] (same order, same length): which edge
    /// cell was split and which edge cells its halves are ([`EdgeSplit`]). Not saved by
    /// [`LeveledMap::to_parts`]: a loaded map starts an empty one (its [`Self::split_log`] is
    /// rebuilt from the link history, but not the edge cells; a coupling, the only reader,
    /// starts from level 0). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_tet(d, 1).unwrap();
    /// let log = m.edge_split_log();
    /// assert_eq!(log.len(), m.split_log().len());
    /// assert!(log.iter().zip(m.split_log()).all(|(e, s)| [e.vertex, e.ends[0], e.ends[1]] == *s));
    /// ```
    pub fn edge_split_log(&self) -> &[EdgeSplit] {
        &self.edge_splits
    }

    /// Position of the vertex of dart `d` (the origin if no geometry was given). O(1).
    ///
    /// # Panics
    /// If `d` is not below the map's capacity (as [`GMap::vertex_id`]).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let (a, b) = (m.position(d), m.position(m.map().alpha_dyn(0, d)));
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.position(mid), [0, 1, 2].map(|k| (a[k] + b[k]) / 2.0));
    /// ```
    pub fn position(&self, d: DartId) -> [f64; 3] {
        self.points.get(self.map.vertex_id(d).index()).copied().unwrap_or([0.0; 3])
    }

    /// Number of darts of B_i (created at a level ≤ i). O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// assert_eq!(m.darts_at_level(0), 6);
    /// assert_eq!(m.darts_at_level(1), 24);
    /// ```
    pub fn darts_at_level(&self, i: u8) -> usize {
        self.map.darts().filter(|d| self.dart_level[d.index()] <= i).count()
    }

    /// αj^i(d): the image of d by αj at level i (the paper's α0^i for j = 0). O(changes of d).
    /// `d` must be a live dart and j ≤ n, as for [`GMap::alpha_dyn`] (panics otherwise; a dart
    /// from outside is checked first with `self.map().contains(d)`).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// let old = m.map().alpha_dyn(0, d);
    /// let mid = m.split_edge(d, 1).unwrap();
    /// assert_eq!(m.alpha_at(0, 0, d), old); // before the split
    /// assert_eq!(m.alpha_at(1, 0, d), mid);
    /// ```
    pub fn alpha_at(&self, i: u8, j: usize, d: DartId) -> DartId {
        // The history of d is in non-decreasing level order; the first change made after level i
        // holds the value the link had at level i.
        self.history
            .of(d.index())
            .find(|c| c.j as usize == j && c.level > i)
            .map_or_else(|| self.map.alpha_dyn(j, d), |c| DartId(c.old))
    }

    /// The orbit ⟨α0^i, …, α(k−1)^i⟩ of `d` in G_i (the k-cell of d at level i for k = n, the
    /// face for k = 2 …), breadth-first from `d`. `d` must be a live dart of B_i and k ≤ n + 1.
    /// O(orbit · history length); the visited set is the thread's epoch stamps (no hashing).
    pub(super) fn orbit_at(&self, i: u8, k: usize, d: DartId) -> Vec<DartId> {
        crate::gmap::with_stamps(|stamps| {
            let tag = stamps.fresh(self.map.capacity(), 1);
            let mut out = vec![d];
            stamps.mark(d.0, tag);
            let mut next = 0;
            while next < out.len() {
                let x = out[next];
                next += 1;
                for j in 0..k {
                    let y = self.alpha_at(i, j, x);
                    if !stamps.has(y.0, tag) {
                        stamps.mark(y.0, tag);
                        out.push(y);
                    }
                }
            }
            out
        })
    }

    /// Extracts G_i = (B_i, α0^i, α1^i, …, αn^i) as a G-map of its own, with fresh dense dart and
    /// cell ids. O(capacity + |B_i| · n).
    ///
    /// Errors: [`LevelError::NotClosed`] if some αj^i leaves B_i (a bug of this module).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_triangle(d, 1).unwrap();
    /// let g0 = m.level(0).unwrap();
    /// assert_eq!((g0.map.dart_count(), g0.map.count_cells().0[2]), (6, 1));
    /// assert!(m.level(1).unwrap().map.is_isomorphic(m.map()));
    /// ```
    pub fn level(&self, i: u8) -> Result<LevelView<N>, LevelError> {
        let darts: Vec<DartId> = self.map.darts().filter(|d| self.dart_level[d.index()] <= i).collect();
        let mut index = vec![u32::MAX; self.map.capacity()];
        for (k, d) in darts.iter().enumerate() {
            index[d.index()] = k as u32;
        }
        let mut out = GMap::<N>::new();
        out.alloc_darts_raw(darts.len());
        for (k, &d) in darts.iter().enumerate() {
            for j in 0..=N {
                let image = self.alpha_at(i, j, d);
                let target = index[image.index()];
                if target == u32::MAX {
                    return Err(LevelError::NotClosed { level: i, dart: d, j, image });
                }
                out.link_raw(j, DartId(k as u32), DartId(target));
            }
        }
        out.label_cells_raw();
        Ok(LevelView { map: out, darts })
    }

    /// Checks the level laws on the finest map: μt ≤ μf ≤ μa at every dart, dart levels and μa
    /// ≤ max level, μa constant on edges, μf on faces, μt on volumes. O(darts · n).
    ///
    /// Errors: the first [`LevelError::MuOrder`], [`LevelError::AboveMaxLevel`] or
    /// [`LevelError::MuNotConstant`] found.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_tet(d, 1).unwrap();
    /// assert!(m.check_levels().is_ok());
    /// ```
    pub fn check_levels(&self) -> Result<(), LevelError> {
        for d in self.map.darts() {
            let mu = self.mu[d.index()];
            if !(mu.tet <= mu.face && mu.face <= mu.edge) {
                return Err(LevelError::MuOrder { dart: d, mu });
            }
            let level = self.dart_level[d.index()];
            if level > self.max_level || mu.edge > self.max_level {
                return Err(LevelError::AboveMaxLevel { dart: d, level, mu, max_level: self.max_level });
            }
            for j in 0..=N {
                let e = self.map.alpha_dyn(j, d);
                let other = self.mu[e.index()];
                let pairs = [(1, mu.edge, other.edge), (2, mu.face, other.face), (3, mu.tet, other.tet)];
                for (dim, a, b) in pairs {
                    // αj keeps the dim-cell for every j ≠ dim (in 2D, μt is 0 everywhere).
                    if j != dim && a != b {
                        return Err(LevelError::MuNotConstant { dim, dart: d, a, other: e, b });
                    }
                }
            }
        }
        Ok(())
    }

    /// The check after every operation under `expensive-checks` (finding 327): the finest map and
    /// [`Self::check_levels`] (μ order, levels constant on their cells) always, O(darts); on maps
    /// of at most [`FULLY_CHECKED_DARTS`] darts also the level maps and the flat law, as
    /// [`Self::check_all`] does — every level while the map has at most
    /// [`FULLY_CHECKED_LEVELS`] levels above 0, past that the operation's level, the one below
    /// and the top one. Bounded so that the quadratic cost of a check after each of the
    /// thousands of operations of a large refinement stays that of `validate()` alone; a
    /// refinement around a ball and a uniform level end with [`Self::check_all`] at any size.
    #[cfg(feature = "expensive-checks")]
    pub(crate) fn check_after_op(&self, level: u8) -> Result<(), LevelError> {
        self.map.validate().map_err(LevelError::InvalidMap)?;
        self.check_levels()?;
        if self.map.dart_count() > FULLY_CHECKED_DARTS {
            return Ok(());
        }
        let levels: Vec<u8> = if self.max_level <= FULLY_CHECKED_LEVELS {
            (0..=self.max_level).collect()
        } else {
            let mut top = vec![level.saturating_sub(1), level.min(self.max_level), self.max_level];
            top.dedup();
            top
        };
        for i in levels {
            let view = self.level(i)?;
            view.map.validate().map_err(|source| LevelError::InvalidLevel { level: i, source })?;
        }
        match self.flat_errors(1).into_iter().chain(self.own_level_errors(1)).chain(self.past_errors(1)).next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Under `expensive-checks`, [`Self::check_all`] at the end of a whole operation (a
    /// refinement around a ball, coupled or not, a uniform level), at any size: its single
    /// operations check only what [`Self::check_after_op`] affords (findings 327, 331). A failure
    /// is a bug of this module and panics naming `op`. Without the feature, nothing.
    pub(crate) fn expensive_check_all(&self, op: &str) {
        #[cfg(feature = "expensive-checks")]
        if let Err(e) = self.check_all() {
            panic!("topomech bug: {op} broke the leveled map: {e}");
        }
        #[cfg(not(feature = "expensive-checks"))]
        let _ = op;
    }

    /// Every law: the finest map valid, [`Self::check_levels`], every level 0..=k extracted
    /// and valid (B_{i−1} ⊂ B_i holds by construction of B_i from dart levels), and the flat
    /// flag of every dart the one its level and history determine: a dart d of level L is flat
    /// iff L ≥ 1, e = α1(d) ≠ d has level L, neither d nor e has an α1 history entry, and
    /// x = α0^L(d), y = α0^L(e) have the history entries (L, α0, y) and (L, α0, x) (its vertex
    /// was inserted on one edge at level L and no face split has made it a corner since;
    /// [`LevelError::FlatFlag`]); every cell a cell of the level its μ names, and a top cell
    /// of no lower level ([`LevelError::NotAtOwnLevel`], [`LevelError::AboveOwnLevel`], module
    /// `own_level`); then the laws of the vertices' past
    /// (module `origins`): origins
    /// are roots lying at their copies' points, no top cell meets one origin twice
    /// ([`LevelError::OriginNotRoot`], [`LevelError::OriginElsewhere`],
    /// [`LevelError::OriginTwiceInCell`]), and the split log is what the link history witnesses
    /// ([`LevelError::SplitLog`]).
    /// O(k · capacity · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_tet(d, 1).unwrap();
    /// m.subdivide_triangle(d, 2).unwrap();
    /// assert!(m.check_all().is_ok());
    /// ```
    pub fn check_all(&self) -> Result<(), LevelError> {
        self.map.validate().map_err(LevelError::InvalidMap)?;
        self.check_levels()?;
        for i in 0..=self.max_level {
            let view = self.level(i)?;
            view.map.validate().map_err(|source| LevelError::InvalidLevel { level: i, source })?;
        }
        // Every level is closed now, so the flat law reads live darts only.
        match self.flat_errors(1).into_iter().chain(self.own_level_errors(1)).chain(self.past_errors(1)).next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// The laws of the vertices' past (module `origins`): the first violation of the origin
    /// laws, then of the split-log law, up to `limit`. O(darts · log + history entries).
    pub(crate) fn past_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = self.origin_errors(limit);
        if out.len() < limit {
            out.extend(self.split_log_errors(limit - out.len()));
        }
        out
    }
}

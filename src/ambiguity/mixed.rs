//! Random interleavings of cuts and tetrahedron subdivisions, on the leveled g-map
//! ([`LeveledMap`]) and on the naive indexed model ([`RefinedModel`]) side by side.
//!
//! # Operations
//! An [`Op`] carries an index taken modulo the current number of candidates:
//! - [`Op::Cut`]: the i-th glued face of the finest g-map (one per face, in dart order) is cut
//!   ([`LeveledMap::unsew_face`] at the current maximum level); on the indexed side the tets of
//!   its two volumes are cut ([`crate::ambiguity::indexed::IndexedModel::cut`]) — or the cut is
//!   *inexpressible* when they share no point triple (a hanging face);
//! - [`Op::Subdivide`]: the i-th tet of the indexed model, and the g-map volume it stands for, is
//!   split 1→8 ([`LeveledMap::subdivide_tet`] at level max + 1; [`RefinedModel::subdivide`]).
//!   When the g-map refuses (a face refined beyond one step), the op is *refused* on both sides.
//!
//! Each indexed tet stands for one g-map volume (a dart of it is kept); the eight children of a
//! subdivision are paired by the positions of their corners.
//!
//! # Comparison
//! After the sequence, and at every level i of the leveled map (G_i against the indexed model as
//! it was when level i ended), the map the tet list means (`GMap::from_tets`) is compared with
//! the g-map through that pairing (an isomorphism sending each tet to its volume). When they
//! differ, their incidence graphs are compared too: isomorphic graphs of non-isomorphic maps are
//! an ambiguous pair. A cut that splits no g-map vertex or edge gives a *skeleton pair*: the maps
//! before and after it share their vertex–edge graph but are not isomorphic (verified by VF2 and
//! map isomorphism on maps of at most [`SKELETON_CHECK_DARTS`] darts). The *level law* is checked as well: G_i is isomorphic (through the dart
//! identity) to the finest map as it was when level i ended.

use rustc_hash::{FxHashMap, FxHashSet};

use crate::ambiguity::indexed::IndexedError;
use crate::ambiguity::refine::RefinedModel;
use crate::generate::SplitMix64;
use crate::gmap::{AlphaMask, DartId, GMap};
use crate::graph::{graph_of, graphs_isomorphic, GraphInvariant, GraphKind, Multiplicity};
use crate::subdivide::{LevelView, LeveledMap, SubdivideError, MAX_LEVEL};
use crate::BuildError;

/// Graphs with more nodes than this are not compared by VF2 (the pair is then *undecided*).
pub const VF2_NODE_CAP: usize = 4000;

/// Skeleton pairs are verified by VF2 (and map isomorphism) only on maps with at most this many
/// darts.
pub const SKELETON_CHECK_DARTS: usize = 6000;

/// One operation; the index is reduced modulo the number of candidates when applied.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{run_ops, Op};
/// use topomech::generate;
/// let (points, tets) = generate::kuhn_cube(1);
/// // Indices wrap around the candidates: Subdivide(6) refines tet 0 of six.
/// let run = run_ops(&points, &tets, &[Op::Subdivide(6), Op::Cut(0)]).unwrap();
/// assert_eq!((run.subdivisions, run.cuts), (1, 1));
/// assert_eq!(run.ops, vec![Op::Subdivide(6), Op::Cut(0)]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Op {
    /// Cut a glued face of the g-map.
    Cut(u32),
    /// Subdivide a tet of the indexed model (and its g-map volume).
    Subdivide(u32),
}

/// Why a mixed sequence could not run: `Build`, `Pinched`, `Degenerate` and `Indexed` with
/// [`IndexedError::CoincidentTets`] are bad input; every other case is a bug of topomech.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{run_ops, MixedError};
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// // Point 4 does not exist: the mesh does not build.
/// let e = run_ops(&points, &[[0, 1, 2, 4]], &[]).unwrap_err();
/// assert!(matches!(e, MixedError::Build(_)));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MixedError {
    /// The input mesh does not build, or the tet list after the ops does not.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The input mesh has a pinched vertex: positions per g-map vertex are not defined.
    #[error("the input mesh has {0} pinched vertices; the mixed campaign needs a manifold mesh")]
    Pinched(usize),
    /// A g-map operation failed where it cannot.
    #[error(transparent)]
    Subdivide(#[from] SubdivideError),
    /// The indexed model refuses the mesh ([`IndexedError::CoincidentTets`]: a duplicated tet), or
    /// an indexed cut failed where it cannot (a bug).
    #[error(transparent)]
    Indexed(#[from] IndexedError),
    /// A child of a subdivision has no g-map counterpart with the same corner positions (or only
    /// one already paired with another child).
    #[error("child tet {0} of a subdivision matches no g-map volume")]
    Unpaired(u32),
    /// A g-map volume stands for no tet of the indexed model.
    #[error("the g-map volume of {0:?} stands for no tet of the indexed model")]
    NoModelTet(DartId),
    /// The input has a tet of zero volume or with a corner that is not finite, and the ops
    /// subdivide: the children of a subdivision are paired with the g-map's by the positions of
    /// their corners, which needs the ten points of every tet (corners and edge midpoints) to be
    /// distinct.
    #[error("tet {tet} has {} and the ops subdivide: the children of a subdivision are paired by corner positions, which needs every tet to have volume", if volume.is_finite() { "zero volume" } else { "a corner that is not finite" })]
    Degenerate {
        /// The tet's index in the input.
        tet: usize,
        /// Its signed volume (zero, or not finite).
        volume: f64,
    },
    /// A level of the leveled map cannot be extracted.
    #[error("level {0} cannot be extracted: {1}")]
    Level(u8, String),
}

/// The comparison of the indexed model with the g-map at one level (or the finest).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{run_ops, Op};
/// use topomech::generate;
/// let (points, tets) = generate::kuhn_cube(1);
/// let run = run_ops(&points, &tets, &[Op::Subdivide(0)]).unwrap();
/// let c = &run.finest;
/// assert!(c.hanging_edges > 0 && c.ambiguous());
/// assert_eq!(run.levels[0].level, 0);
/// assert!(!run.levels[0].ambiguous()); // level 0 is the uncut, unrefined cube
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Compare {
    /// The level (the finest for the final comparison).
    pub level: u8,
    /// Edges of the tet list with a used midpoint (T-junctions).
    pub hanging_edges: usize,
    /// Points whose tets form several fans.
    pub pinched_points: usize,
    /// Point pairs whose tets form several fans.
    pub non_manifold_edges: usize,
    /// G-map vertices.
    pub gmap_vertices: usize,
    /// Points some tet uses.
    pub indexed_vertices: usize,
    /// Whether the map the tet list means is not the g-map (through the tet ↔ volume pairing).
    pub map_differs: bool,
    /// When the maps differ: `Some(true)` if their incidence graphs are isomorphic anyway (an
    /// ambiguous pair), `Some(false)` if not, `None` if too large to decide.
    pub graph_pair: Option<bool>,
}

impl Compare {
    /// Whether the tet list fails to represent the g-map at this level.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::mixed::Compare;
    ///
    /// let same = Compare { gmap_vertices: 8, indexed_vertices: 8, ..Compare::default() };
    /// assert!(!same.ambiguous());
    /// assert!(Compare { hanging_edges: 1, ..same.clone() }.ambiguous());
    /// assert!(Compare { indexed_vertices: 9, ..same }.ambiguous());
    /// ```
    pub fn ambiguous(&self) -> bool {
        self.hanging_edges > 0
            || self.pinched_points > 0
            || self.non_manifold_edges > 0
            || self.gmap_vertices != self.indexed_vertices
            || self.map_differs
    }
}

/// The outcome of one mixed sequence.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{run_ops, Op};
/// use topomech::generate;
/// let (points, tets) = generate::kuhn_cube(1);
/// let run = run_ops(&points, &tets, &[Op::Cut(0), Op::Cut(0)]).unwrap();
/// assert_eq!((run.cuts, run.subdivisions, run.refused), (2, 0, 0));
/// assert!(run.gmap_valid && run.level_law && run.levels.is_empty());
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct MixedRun {
    /// The operations as given.
    pub ops: Vec<Op>,
    /// Cuts done on the g-map.
    pub cuts: usize,
    /// Subdivisions done on both models.
    pub subdivisions: usize,
    /// Subdivisions refused (not done on either side): by the g-map (a face refined beyond one
    /// step) or at the level cap.
    pub refused: usize,
    /// Of those, subdivisions refused because the map was at level [`MAX_LEVEL`] already (every
    /// subdivision opens a level).
    pub refused_level_cap: usize,
    /// Cuts whose two volumes share no point triple in the tet list.
    pub cuts_inexpressible: usize,
    /// Cuts after which the two tets still shared their triple (the cut re-glued).
    pub cuts_lost: usize,
    /// Cuts that split no g-map vertex or edge: the maps before and after share their
    /// vertex–edge graph (skeleton pairs).
    pub skeleton_cuts: usize,
    /// Skeleton pairs whose verification failed: different vertex–edge graphs or isomorphic
    /// maps (expected 0; only maps of at most [`SKELETON_CHECK_DARTS`] darts are verified).
    pub skeleton_violations: usize,
    /// The final comparison.
    pub finest: Compare,
    /// The comparison at every level below the finest.
    pub levels: Vec<Compare>,
    /// Whether every G_i equals the finest map as it was when level i ended (expected).
    pub level_law: bool,
    /// Whether the leveled map passes `check_all` (expected).
    pub gmap_valid: bool,
    /// Whether the vertex masses lumped from density 1 ([`crate::subdivide::TetMasses`]) keep
    /// the input's first moment, Σ_v m_v x_v = ∫ x dV (expected: cuts move nothing and a split's
    /// children fill their parent; finding 335).
    pub first_moment_kept: bool,
}

impl MixedRun {
    /// Whether the indexed model ends unable to represent the g-map.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::mixed::{run_ops, Op};
    /// use topomech::generate;
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// assert!(!run_ops(&points, &tets, &[]).unwrap().ambiguous());
    /// let refined = run_ops(&points, &tets, &[Op::Subdivide(0)]).unwrap();
    /// assert!(refined.ambiguous() && refined.finest.hanging_edges > 0);
    /// ```
    pub fn ambiguous(&self) -> bool {
        self.finest.ambiguous() || self.cuts_inexpressible > 0 || self.cuts_lost > 0
    }
}

/// Both models and the pairing of tets with g-map volumes.
struct Sides {
    lm: LeveledMap<3>,
    model: RefinedModel,
    /// A g-map dart of the volume each indexed tet stands for.
    vol_dart: Vec<DartId>,
}

impl Sides {
    /// Both models of the input mesh, tet t standing for the volume of dart 24 t.
    fn new(map: GMap<3>, points: &[[f64; 3]], tets: &[[u32; 4]]) -> Result<Self, MixedError> {
        Ok(Sides {
            lm: LeveledMap::new(map, points.to_vec()),
            model: RefinedModel::new(points, tets)?,
            vol_dart: (0..tets.len()).map(|t| DartId(24 * t as u32)).collect(),
        })
    }
}

impl MixedRun {
    /// A run of `ops` with nothing counted yet.
    fn empty(ops: &[Op]) -> Self {
        MixedRun {
            ops: ops.to_vec(),
            cuts: 0,
            subdivisions: 0,
            refused: 0,
            refused_level_cap: 0,
            cuts_inexpressible: 0,
            cuts_lost: 0,
            skeleton_cuts: 0,
            skeleton_violations: 0,
            finest: Compare::default(),
            levels: Vec::new(),
            level_law: true,
            gmap_valid: true,
            first_moment_kept: true,
        }
    }
}

/// Runs `ops` on both models built from the mesh. O(ops · (mesh + darts)) plus one comparison
/// per level (each O(tets + darts · n) and a VF2 when maps differ but graph invariants agree).
///
/// Memory: O(mesh + darts + ops), independent of the number of levels. The comparison at level i
/// needs both models as they were when level i ended; they are not kept (a copy per level was
/// O(levels × darts)) but recomputed: after the run, the ops are replayed once on fresh models
/// (the ops are deterministic), and each level is compared when the replay reaches its end, so
/// at most two states (the final one and the replayed one) are alive at a time. The replay
/// doubles the cost of the ops, not of the comparisons.
///
/// A subdivision past level [`MAX_LEVEL`] is refused and counted (`refused` and
/// `refused_level_cap`), like one the g-map refuses for a face refined too far.
///
/// Errors: [`MixedError::Build`] / [`MixedError::Pinched`] for a bad mesh,
/// [`MixedError::Indexed`] ([`IndexedError::CoincidentTets`]) for a duplicated tet, and
/// [`MixedError::Degenerate`] for a tet of zero volume or with a non-finite corner when `ops`
/// subdivide; the other variants are bugs.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{run_ops, Op};
/// use topomech::generate;
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let ops: Vec<Op> = (0..6).map(Op::Subdivide).collect(); // every tet, one after the other
/// let run = run_ops(&points, &tets, &ops).unwrap();
/// assert_eq!((run.subdivisions, run.refused, run.levels.len()), (6, 0, 6));
/// assert!(run.gmap_valid && run.level_law);
/// assert!(!run.ambiguous()); // all refined: nothing hangs, both models agree
/// ```
pub fn run_ops(points: &[[f64; 3]], tets: &[[u32; 4]], ops: &[Op]) -> Result<MixedRun, MixedError> {
    // A duplicated tet is named by the indexed model's own error, as the campaigns name it (the
    // g-map builder refuses it too, as `BuildError::DuplicateElement`).
    if let Some((first, second)) = crate::mesh::duplicate_cells(tets) {
        return Err(MixedError::Indexed(IndexedError::CoincidentTets { first, second, points: tets[second] }));
    }
    let (map, report) = GMap::<3>::from_tets(points.len(), tets)?;
    if !report.pinched_vertices.is_empty() {
        return Err(MixedError::Pinched(report.pinched_vertices.len()));
    }
    if ops.iter().any(|op| matches!(op, Op::Subdivide(_))) {
        check_volumes(points, tets)?;
    }
    let mut s = Sides::new(map, points, tets)?;
    let mut run = MixedRun::empty(ops);
    // The index of the op whose subdivision ended level i, for every level i below the finest.
    let mut level_ends: Vec<usize> = Vec::new();
    for (j, &op) in ops.iter().enumerate() {
        match op {
            Op::Cut(i) => cut(&mut s, i, &mut run, true)?,
            Op::Subdivide(i) => {
                if subdivide(&mut s, i, &mut run)? {
                    level_ends.push(j);
                }
            }
        }
    }
    run.gmap_valid = s.lm.check_all().is_ok();
    run.first_moment_kept = first_moment_kept(&s.lm, points, tets);
    if !level_ends.is_empty() {
        // The input again (built, not kept: no copy is alive during the first pass).
        let (map, _) = GMap::<3>::from_tets(points.len(), tets)?;
        compare_levels(&s, Sides::new(map, points, tets)?, ops, &level_ends, &mut run)?;
    }
    run.finest = compare(s.lm.map(), &s.vol_dart, &s.model)?;
    run.finest.level = s.lm.max_level();
    Ok(run)
}

/// Replays `ops` on `replay` (fresh models of the input) up to the last level end, and compares
/// level i of the final leveled map (`done.lm`) with the replayed models when the replay reaches
/// `level_ends[i]`, before that op's subdivision: the level law and [`compare`]. Memory: the
/// replayed models, one level view and one comparison at a time.
fn compare_levels(
    done: &Sides,
    mut replay: Sides,
    ops: &[Op],
    level_ends: &[usize],
    run: &mut MixedRun,
) -> Result<(), MixedError> {
    let Some(&last) = level_ends.last() else { return Ok(()) };
    // The counters of the replay are thrown away: the first pass counted.
    let mut scratch = MixedRun::empty(&[]);
    let mut ends = level_ends.iter().enumerate().peekable();
    for (j, &op) in ops[..=last].iter().enumerate() {
        let ended = ends.next_if(|&(_, &end)| end == j).map(|(level, _)| level);
        if let Some(level) = ended {
            let level = u8::try_from(level).map_err(|_| MixedError::Level(u8::MAX, "more levels than u8".into()))?;
            let c = compare_level(done, &replay, level, run)?;
            run.levels.push(c);
        }
        let subdivided = match op {
            Op::Cut(i) => {
                cut(&mut replay, i, &mut scratch, false)?;
                false
            }
            Op::Subdivide(i) => subdivide(&mut replay, i, &mut scratch)?,
        };
        if subdivided != ended.is_some() {
            return Err(MixedError::Level(replay.lm.max_level(), format!("the replay of op {j} diverged")));
        }
    }
    Ok(())
}

/// Level `level` of `done.lm` against `snap`, the models as they were when that level ended: the
/// level law (into `run.level_law`) and the comparison of G_i with the tet list.
fn compare_level(done: &Sides, snap: &Sides, level: u8, run: &mut MixedRun) -> Result<Compare, MixedError> {
    let view = done.lm.level(level).map_err(|e| MixedError::Level(level, e.to_string()))?;
    let mut index: FxHashMap<u32, DartId> = FxHashMap::default();
    for (k, d) in view.darts.iter().enumerate() {
        index.insert(d.0, DartId(k as u32));
    }
    run.level_law &= level_matches(&view, snap.lm.map());
    let vol: Option<Vec<DartId>> = snap.vol_dart.iter().map(|d| index.get(&d.0).copied()).collect();
    let vol = vol.ok_or_else(|| MixedError::Level(level, "a paired dart is not in B_i".into()))?;
    let mut c = compare(&view.map, &vol, &snap.model)?;
    c.level = level;
    Ok(c)
}

/// Whether G_i (`view`) is `snap`, the finest map as it was when level i ended: as many darts,
/// and every component of G_i isomorphic to its image through the dart identity (dart k of
/// `view.map` is dart `view.darts[k]` of `snap`). O(darts · n).
fn level_matches(view: &LevelView<3>, snap: &GMap<3>) -> bool {
    view.map.dart_count() == snap.dart_count()
        && view.map.components().iter().all(|&r| {
            let size = view.map.orbit(r, AlphaMask::all(3)).len();
            view.map.isomorphism_from(r, snap, view.darts[r.index()]).is_some_and(|p| p.len() == size)
        })
}

/// The first tet of zero signed volume or with a non-finite corner, as
/// [`MixedError::Degenerate`]. The determinant is taken in wide floats (`crate::wide`), so a
/// regular tet of edge 1e150 (volume past f64) or 1e-150 (below it) is not degenerate. O(tets).
fn check_volumes(points: &[[f64; 3]], tets: &[[u32; 4]]) -> Result<(), MixedError> {
    for (tet, t) in tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| points[v as usize]);
        let six = crate::wide::six_volume(a, b, c, d);
        if six.is_zero() || !six.is_finite() {
            return Err(MixedError::Degenerate { tet, volume: crate::wide::signed_volume(a, b, c, d) });
        }
    }
    Ok(())
}

/// Whether Σ_v m_v x_v of the vertex masses lumped from density 1 equals ∫ x dV = Σ_t V_t c_t
/// over the input's tets (V_t its volume, c_t its centroid), to 1e-9 of Σ_t V_t max|x|: the
/// leveled map's volumes fill the input's and its hanging vertices lump along their corners
/// (docs/SUBDIVISION.md). O(darts + splits).
fn first_moment_kept(lm: &LeveledMap<3>, points: &[[f64; 3]], tets: &[[u32; 4]]) -> bool {
    let lumped = match crate::subdivide::TetMasses::from_density(lm, 1.0).and_then(|m| m.vertex_masses(lm)) {
        Ok(lumped) => lumped,
        Err(_) => return false,
    };
    let (mut got, mut want, mut scale) = ([0.0; 3], [0.0; 3], 0.0);
    for (v, &m) in lumped.iter().enumerate() {
        if lm.map().is_live_cell(0, crate::CellId(v as u32)) {
            (0..3).for_each(|k| got[k] += m * lm.points()[v][k]);
        }
    }
    for t in tets {
        let p = t.map(|v| points[v as usize]);
        let volume = crate::mesh::signed_volume(p[0], p[1], p[2], p[3]).abs();
        (0..3).for_each(|k| want[k] += volume * p.iter().map(|x| x[k]).sum::<f64>() / 4.0);
        scale += volume * p.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    }
    (0..3).all(|k| (got[k] - want[k]).abs() <= 1e-9 * scale.max(f64::MIN_POSITIVE))
}

/// One dart per glued face of the finest map, in dart order. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{construct::glued_faces, mixed::glued_face_darts};
/// use topomech::{generate, GMap};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let darts = glued_face_darts(&map);
/// assert_eq!(darts.len(), glued_faces(&map).len());
/// assert!(darts.iter().all(|&d| !map.is_free(3, d)));
/// ```
pub fn glued_face_darts(map: &GMap<3>) -> Vec<DartId> {
    let mut seen: FxHashSet<u32> = FxHashSet::default();
    map.darts().filter(|&d| !map.is_free(3, d) && seen.insert(map.cell_id(2, d).0)).collect()
}

/// Cuts the i-th glued face (modulo their number) on both sides and counts it in `run`; with
/// `verify`, a skeleton pair is verified on maps of at most [`SKELETON_CHECK_DARTS`] darts.
fn cut(s: &mut Sides, i: u32, run: &mut MixedRun, verify: bool) -> Result<(), MixedError> {
    let faces = glued_face_darts(s.lm.map());
    if faces.is_empty() {
        return Ok(());
    }
    let d = faces[i as usize % faces.len()];
    let map = s.lm.map();
    let tet_of: FxHashMap<u32, u32> =
        s.vol_dart.iter().enumerate().map(|(t, &x)| (map.cell_id(3, x).0, t as u32)).collect();
    let tet = |x: DartId| tet_of.get(&map.cell_id(3, x).0).copied().ok_or(MixedError::NoModelTet(x));
    let (t1, t2) = (tet(d)?, tet(map.alpha::<3>(d))?);
    let before_counts = map.count_cells();
    let before = (verify && map.dart_count() <= SKELETON_CHECK_DARTS).then(|| map.clone());
    s.lm.unsew_face(d, s.lm.max_level())?;
    run.cuts += 1;
    let after = s.lm.map();
    if after.count_cells().0[..2] == before_counts.0[..2] {
        run.skeleton_cuts += 1;
        if let Some(before) = before {
            let same = graphs_isomorphic(
                &graph_of(&before, GraphKind::VertexEdge),
                &graph_of(after, GraphKind::VertexEdge),
                Multiplicity::Ignore,
            );
            run.skeleton_violations += usize::from(!same || before.is_isomorphic(after));
        }
    }
    match s.model.model.cut(t1, t2) {
        Ok(out) => run.cuts_lost += usize::from(out.face_still_shared),
        Err(IndexedError::NoSharedFace(..)) => run.cuts_inexpressible += 1,
        Err(e) => return Err(e.into()),
    }
    Ok(())
}

/// Subdivides the i-th indexed tet (modulo their number) and its g-map volume at level
/// max + 1; `Ok(false)` when refused (a face refined too far, or max = [`MAX_LEVEL`]), counted.
fn subdivide(s: &mut Sides, i: u32, run: &mut MixedRun) -> Result<bool, MixedError> {
    let t = i % s.model.model.tets.len() as u32;
    if s.lm.max_level() >= MAX_LEVEL {
        run.refused += 1;
        run.refused_level_cap += 1;
        return Ok(false);
    }
    let level = s.lm.max_level() + 1;
    let kids = match s.lm.subdivide_tet(s.vol_dart[t as usize], level) {
        Ok(kids) => kids,
        Err(SubdivideError::FaceRefinedTooFar { .. }) => {
            run.refused += 1;
            return Ok(false);
        }
        Err(e) => return Err(e.into()),
    };
    let sets: Vec<Vec<[f64; 3]>> = kids.iter().map(|&k| volume_positions(&s.lm, k)).collect();
    let diagonal: Vec<[f64; 3]> =
        sets[4].iter().copied().filter(|p| sets[5..].iter().all(|set| set.contains(p))).collect();
    let hint = <[[f64; 3]; 2]>::try_from(diagonal.as_slice()).ok();
    let children = s.model.subdivide(t, hint)?;
    s.vol_dart.resize(s.model.model.tets.len(), DartId(0));
    let mut paired = [false; 8];
    for c in children {
        let corners = s.model.model.tets[c as usize].map(|p| s.model.position(p));
        let k = (0..8)
            .find(|&k| !paired[k] && corners.iter().all(|p| sets[k].contains(p)))
            .ok_or(MixedError::Unpaired(c))?;
        paired[k] = true;
        s.vol_dart[c as usize] = kids[k];
    }
    run.subdivisions += 1;
    Ok(true)
}

/// The positions of the vertices of the volume of `d` (corners and inserted vertices).
fn volume_positions(lm: &LeveledMap<3>, d: DartId) -> Vec<[f64; 3]> {
    let mut out: Vec<[f64; 3]> = Vec::new();
    for x in lm.map().orbit(d, AlphaMask::of(&[0, 1, 2])) {
        let p = lm.position(x);
        if !out.contains(&p) {
            out.push(p);
        }
    }
    out
}

/// Compares the map the tet list of `model` means with `map`, tet t standing for the volume of
/// `vol_dart[t]`. O(tets + darts · n), plus a VF2 when the maps differ but the graph invariants
/// agree and the graphs have at most [`VF2_NODE_CAP`] nodes.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{mixed::compare, refine::RefinedModel};
/// use topomech::{DartId, GMap};
///
/// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let model = RefinedModel::new(&points, &[[0, 1, 2, 3]]).unwrap();
/// let c = compare(&map, &[DartId(0)], &model).unwrap();
/// assert!(!c.map_differs && !c.ambiguous());
/// assert_eq!((c.gmap_vertices, c.indexed_vertices, c.graph_pair), (4, 4, None));
/// ```
pub fn compare(map: &GMap<3>, vol_dart: &[DartId], model: &RefinedModel) -> Result<Compare, MixedError> {
    let (rebuilt, report) = GMap::<3>::from_tets(model.model.points, &model.model.tets)?;
    let map_differs = !same_by_pairing(&rebuilt, map, vol_dart);
    let graph_pair = map_differs.then(|| graph_pair(&rebuilt, map)).flatten();
    Ok(Compare {
        level: 0,
        hanging_edges: model.hanging_edges(),
        pinched_points: report.pinched_vertices.len(),
        non_manifold_edges: report.split_edges.len(),
        gmap_vertices: map.count_cells().0[0],
        indexed_vertices: model.model.used_points(),
        map_differs,
        graph_pair,
    })
}

/// Whether `rebuilt` (laid out by `from_tets`) is isomorphic to `map` by an isomorphism sending
/// each tet t into the volume of `vol_dart[t]`: per component, the 24 darts of one tet are tried
/// as preimages of `vol_dart[t]`. O(24 · darts · n).
fn same_by_pairing(rebuilt: &GMap<3>, map: &GMap<3>, vol_dart: &[DartId]) -> bool {
    if rebuilt.dart_count() != map.dart_count() || rebuilt.count_cells() != map.count_cells() {
        return false;
    }
    let mut used = vec![false; map.capacity()];
    for root in rebuilt.components() {
        let t = root.index() / 24;
        let size = rebuilt.orbit(root, AlphaMask::all(3)).len();
        let found = (0..24).find_map(|j| {
            rebuilt
                .isomorphism_from(DartId((24 * t + j) as u32), map, vol_dart[t])
                .filter(|pairs| pairs.len() == size && pairs.iter().all(|&(_, y)| !used[y.index()]))
        });
        match found {
            Some(pairs) => pairs.iter().for_each(|&(_, y)| used[y.index()] = true),
            None => return false,
        }
    }
    true
}

/// Whether the incidence graphs (plain, without multiplicities) are isomorphic; `None` when the
/// invariants agree but the graphs are too large for VF2.
fn graph_pair(a: &GMap<3>, b: &GMap<3>) -> Option<bool> {
    let (ga, gb) = (graph_of(a, GraphKind::Incidence), graph_of(b, GraphKind::Incidence));
    if GraphInvariant::of(&ga, Multiplicity::Ignore) != GraphInvariant::of(&gb, Multiplicity::Ignore) {
        return Some(false);
    }
    (ga.node_count() <= VF2_NODE_CAP).then(|| graphs_isomorphic(&ga, &gb, Multiplicity::Ignore))
}

/// `k` random ops, each a subdivision with probability `p_subdivide`, indices uniform in u32.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::{random_ops, Op};
/// use topomech::generate::SplitMix64;
///
/// let mut rng = SplitMix64(5);
/// assert!(random_ops(8, 0.0, &mut rng).iter().all(|op| matches!(op, Op::Cut(_))));
/// assert!(random_ops(8, 1.0, &mut rng).iter().all(|op| matches!(op, Op::Subdivide(_))));
/// assert_eq!(random_ops(3, 0.5, &mut SplitMix64(9)), random_ops(3, 0.5, &mut SplitMix64(9)));
/// ```
pub fn random_ops(k: usize, p_subdivide: f64, rng: &mut SplitMix64) -> Vec<Op> {
    (0..k)
        .map(|_| {
            let coin = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let i = rng.next_u64() as u32;
            if coin < p_subdivide {
                Op::Subdivide(i)
            } else {
                Op::Cut(i)
            }
        })
        .collect()
}

/// Counts over the mixed sequences of one length k.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::campaign_mixed;
/// use topomech::generate::{self, SplitMix64};
/// let (points, tets) = generate::kuhn_cube(1);
/// let (s, _) = campaign_mixed(&points, &tets, 2, 1.0, 3, &mut SplitMix64(5)).unwrap();
/// assert_eq!((s.k, s.sequences, s.cuts), (2, 3, 0)); // p = 1: subdivisions only
/// assert_eq!(s.subdivisions + s.refused, 6);
/// assert_eq!(s.level_law_broken + s.gmap_invalid, 0);
/// ```
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct MixedStats {
    /// Ops per sequence.
    pub k: usize,
    /// Probability of a subdivision per op.
    pub p_subdivide: f64,
    /// Sequences run.
    pub sequences: usize,
    /// Sequences after which the indexed model cannot represent the g-map ([`MixedRun::ambiguous`]).
    pub ambiguous: usize,
    /// Sequences after which the tet list means another map ([`Compare::map_differs`]).
    pub wrong: usize,
    /// Sequences ending with hanging edges.
    pub hanging: usize,
    /// Sequences with an inexpressible cut.
    pub inexpressible: usize,
    /// Sequences with a cut the indexed model re-glued.
    pub lost: usize,
    /// Sequences ending with pinched points or non-manifold edges in the tet list.
    pub non_manifold: usize,
    /// Sequences ending with different vertex counts.
    pub vertices_differ: usize,
    /// Sequences where the maps differ but the incidence graphs are isomorphic (final or at a level).
    pub graph_pairs: usize,
    /// Sequences with a skeleton pair (a cut splitting no g-map vertex or edge).
    pub skeleton_pairs: usize,
    /// Skeleton pairs whose verification failed, in total (expected 0).
    pub skeleton_violations: usize,
    /// Sequences where such a pair could not be decided (graphs too large).
    pub graph_undecided: usize,
    /// Cuts, subdivisions and refused subdivisions, in total.
    pub cuts: usize,
    /// Subdivisions done.
    pub subdivisions: usize,
    /// Subdivisions refused (by the g-map, or at the level cap).
    pub refused: usize,
    /// Of those, subdivisions refused at the level cap [`MAX_LEVEL`].
    pub refused_level_cap: usize,
    /// Levels compared below the finest, in total.
    pub levels_compared: usize,
    /// Of those, levels where the indexed model could not represent G_i.
    pub levels_ambiguous: usize,
    /// Sequences where the level law failed (expected 0).
    pub level_law_broken: usize,
    /// Sequences where the leveled map failed `check_all` (expected 0).
    pub gmap_invalid: usize,
    /// Sequences whose lumped vertex masses moved the input's first moment (expected 0;
    /// [`MixedRun::first_moment_kept`]).
    pub first_moment_moved: usize,
}

impl MixedStats {
    fn add(&mut self, r: &MixedRun) {
        let all = || std::iter::once(&r.finest).chain(&r.levels);
        self.sequences += 1;
        self.ambiguous += usize::from(r.ambiguous());
        self.wrong += usize::from(r.finest.map_differs);
        self.hanging += usize::from(r.finest.hanging_edges > 0);
        self.inexpressible += usize::from(r.cuts_inexpressible > 0);
        self.lost += usize::from(r.cuts_lost > 0);
        self.non_manifold += usize::from(r.finest.pinched_points + r.finest.non_manifold_edges > 0);
        self.vertices_differ += usize::from(r.finest.gmap_vertices != r.finest.indexed_vertices);
        self.graph_pairs += usize::from(all().any(|c| c.graph_pair == Some(true)));
        self.skeleton_pairs += usize::from(r.skeleton_cuts > 0);
        self.skeleton_violations += r.skeleton_violations;
        self.graph_undecided += usize::from(all().any(|c| c.map_differs && c.graph_pair.is_none()));
        self.cuts += r.cuts;
        self.subdivisions += r.subdivisions;
        self.refused += r.refused;
        self.refused_level_cap += r.refused_level_cap;
        self.levels_compared += r.levels.len();
        self.levels_ambiguous += r.levels.iter().filter(|c| c.ambiguous()).count();
        self.level_law_broken += usize::from(!r.level_law);
        self.gmap_invalid += usize::from(!r.gmap_valid);
        self.first_moment_moved += usize::from(!r.first_moment_kept);
    }
}

/// Runs `sequences` random mixed sequences of `k` ops. Returns the statistics and the first
/// ambiguous run and the first run with a graph pair, if any. Cost: `sequences` × [`run_ops`].
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::mixed::campaign_mixed;
/// use topomech::generate::{self, SplitMix64};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (stats, firsts) = campaign_mixed(&points, &tets, 3, 0.5, 4, &mut SplitMix64(2)).unwrap();
/// assert_eq!(stats.sequences, 4);
/// assert_eq!(stats.level_law_broken + stats.gmap_invalid, 0);
/// assert!(firsts.len() <= 2 && stats.ambiguous <= 4);
/// ```
pub fn campaign_mixed(
    points: &[[f64; 3]],
    tets: &[[u32; 4]],
    k: usize,
    p_subdivide: f64,
    sequences: usize,
    rng: &mut SplitMix64,
) -> Result<(MixedStats, Vec<MixedRun>), MixedError> {
    let mut stats = MixedStats { k, p_subdivide, ..MixedStats::default() };
    let mut firsts: Vec<MixedRun> = Vec::new();
    let (mut had_ambiguous, mut had_pair) = (false, false);
    for _ in 0..sequences {
        let ops = random_ops(k, p_subdivide, rng);
        let run = run_ops(points, tets, &ops)?;
        stats.add(&run);
        let pair = std::iter::once(&run.finest).chain(&run.levels).any(|c| c.graph_pair == Some(true));
        if (run.ambiguous() && !had_ambiguous) || (pair && !had_pair) {
            had_ambiguous |= run.ambiguous();
            had_pair |= pair;
            firsts.push(run);
        }
    }
    Ok((stats, firsts))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
        crate::generate::kuhn_cube(1)
    }

    #[test]
    fn subdividing_every_tet_of_a_cube_leaves_nothing_hanging_and_both_models_agree() {
        let (p, t) = cube();
        let ops: Vec<Op> = (0..6).map(Op::Subdivide).collect();
        let run = run_ops(&p, &t, &ops).expect("runs");
        assert_eq!((run.subdivisions, run.refused), (6, 0), "a face is never refined twice here");
        assert!(run.gmap_valid && run.level_law, "{run:?}");
        assert_eq!(run.levels.len(), run.subdivisions);
        assert!(!run.ambiguous(), "{:?}", run.finest);
        // Every intermediate level has a refined tet next to an unrefined one: hanging edges.
        assert!(run.levels.iter().skip(1).all(|c| c.hanging_edges > 0 && c.ambiguous()));
    }

    #[test]
    fn one_subdivision_next_to_a_neighbour_is_not_representable() {
        let (p, t) = cube();
        let run = run_ops(&p, &t, &[Op::Subdivide(0)]).expect("runs");
        assert_eq!(run.subdivisions, 1);
        assert!(run.finest.hanging_edges > 0 && run.finest.map_differs && run.ambiguous());
        assert!(!run.levels[0].ambiguous(), "level 0 is the input: {:?}", run.levels[0]);
        assert!(run.level_law && run.gmap_valid);
    }

    #[test]
    fn cuts_only_agree_with_the_cut_campaign_on_lost_cuts() {
        let (p, t) = crate::generate::kuhn_cube(2);
        let mut rng = SplitMix64(3);
        let (stats, _) = campaign_mixed(&p, &t, 4, 0.0, 10, &mut rng).expect("runs");
        assert_eq!(stats.subdivisions + stats.refused, 0);
        assert_eq!(stats.level_law_broken + stats.gmap_invalid + stats.first_moment_moved, 0);
        assert_eq!(stats.cuts, 40);
        assert_eq!(stats.skeleton_violations, 0);
        assert!(stats.skeleton_pairs > 0, "a Kuhn cube has faces whose cut splits nothing: {stats:?}");
        assert!(stats.wrong >= stats.lost, "a lost cut is a different gluing: {stats:?}");
    }

    /// Before the check, a flat cube paired every child with the first volume whose corners it
    /// met: an all-subdivide run passed with a made-up pairing, and a cut after a subdivision
    /// panicked on a volume that stood for no tet.
    #[test]
    fn subdividing_a_mesh_without_volume_is_refused_and_cutting_it_is_not() {
        let (p, t) = cube();
        let flat: Vec<[f64; 3]> = p.iter().map(|&[x, y, _]| [x, y, 0.0]).collect();
        let zero = vec![[0.0; 3]; p.len()];
        let mut nan = p.clone();
        nan[7][2] = f64::NAN;
        let ops = [Op::Subdivide(0), Op::Cut(1), Op::Subdivide(3), Op::Cut(2)];
        for points in [&flat, &zero, &nan] {
            match run_ops(points, &t, &ops) {
                Err(MixedError::Degenerate { tet, volume }) => {
                    assert!(tet < t.len() && (volume == 0.0 || volume.is_nan()), "{tet} {volume}");
                    let message = MixedError::Degenerate { tet, volume }.to_string();
                    assert!(message.contains(&format!("tet {tet} has")), "{message}");
                }
                other => panic!("expected Degenerate, got {other:?}"),
            }
            let run = run_ops(points, &t, &[Op::Cut(1), Op::Cut(2)]).expect("cuts need no geometry");
            assert_eq!((run.cuts, run.subdivisions), (2, 0));
        }
        let e = run_ops(&nan, &t, &ops).unwrap_err();
        assert!(e.to_string().contains("a corner that is not finite"), "{e}");
        assert!(run_ops(&p, &t, &ops).is_ok(), "the cube itself runs");
    }

    /// Each of the five symptoms alone makes the tet list fail to represent the g-map.
    #[test]
    fn each_symptom_alone_makes_a_comparison_ambiguous() {
        let same = Compare { gmap_vertices: 8, indexed_vertices: 8, ..Compare::default() };
        assert!(!same.ambiguous());
        let alone = [
            Compare { hanging_edges: 1, ..same.clone() },
            Compare { pinched_points: 1, ..same.clone() },
            Compare { non_manifold_edges: 1, ..same.clone() },
            Compare { indexed_vertices: 9, ..same.clone() },
            Compare { map_differs: true, ..same },
        ];
        for c in alone {
            assert!(c.ambiguous(), "{c:?}");
        }
    }

    /// `hanging` counts the sequences that end with hanging edges, and only those: of no op, one
    /// subdivision next to unrefined neighbours (T-junctions) and one cut (no midpoint at all),
    /// only the subdivision hangs.
    #[test]
    fn the_statistics_count_the_sequences_ending_with_hanging_edges() {
        let (p, t) = cube();
        let mut stats = MixedStats::default();
        for ops in [&[][..], &[Op::Subdivide(0)], &[Op::Cut(0)]] {
            stats.add(&run_ops(&p, &t, ops).expect("runs"));
        }
        assert_eq!((stats.sequences, stats.hanging), (3, 1), "{stats:?}");
    }

    /// The level law holds only for the map the level was: the cube against itself, not against
    /// the cube with one face cut (as many darts, another gluing).
    #[test]
    fn a_level_matches_its_own_map_and_not_a_cut_one() {
        let (p, t) = cube();
        let (map, _) = GMap::<3>::from_tets(p.len(), &t).expect("builds");
        let lm = LeveledMap::new(map.clone(), p);
        let view = lm.level(0).expect("level 0");
        assert!(level_matches(&view, &map));
        let mut cut = map;
        let d = cut.darts().find(|&d| !cut.is_free(3, d)).expect("a glued face");
        cut.unsew::<3>(d).expect("unsews");
        assert_eq!(cut.dart_count(), view.map.dart_count());
        assert!(!level_matches(&view, &cut));
    }

    /// Finding 136: every subdivision opens a level; once the map is at [`MAX_LEVEL`], one more
    /// is refused and counted (both counters), not an error that ends the campaign.
    #[test]
    fn a_subdivision_at_the_level_cap_is_refused_and_counted() {
        let (p, t) = cube();
        let (map, _) = GMap::<3>::from_tets(p.len(), &t).expect("builds");
        let mut s = Sides::new(map, &p, &t).expect("models");
        s.lm.subdivide_tet(s.vol_dart[0], MAX_LEVEL).expect("an op may start at any level");
        let mut run = MixedRun::empty(&[]);
        assert!(!subdivide(&mut s, 3, &mut run).expect("refused, not an error"));
        assert_eq!((run.subdivisions, run.refused, run.refused_level_cap), (0, 1, 1));
        assert_eq!(s.model.model.tets.len(), t.len(), "nothing done on the indexed side");
    }

    #[test]
    fn a_mixed_campaign_keeps_the_laws() {
        let (p, t) = crate::generate::kuhn_cube(2);
        let mut rng = SplitMix64(11);
        let (stats, firsts) = campaign_mixed(&p, &t, 6, 0.5, 6, &mut rng).expect("runs");
        assert_eq!(stats.sequences, 6);
        assert_eq!(stats.level_law_broken, 0, "{stats:?}");
        assert_eq!(stats.gmap_invalid, 0, "{stats:?}");
        assert_eq!(stats.first_moment_moved, 0, "{stats:?}");
        assert!(stats.subdivisions > 0 && stats.ambiguous > 0, "{stats:?}");
        assert!(!firsts.is_empty());
    }
}

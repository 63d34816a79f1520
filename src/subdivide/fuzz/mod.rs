//! Random subdivision sequences decoded from bytes: the body of the cargo-fuzz target
//! `fuzz/fuzz_targets/subdivide.rs`, of the proptest suite `tests/subdivide_fuzz.rs` and of the
//! replay of the committed corpus `fuzz/corpus/subdivide/` on stable (one decoder, three engines).
//!
//! # Decoding
//! Byte 0 picks the mesh (its low 7 bits modulo 3): a 2×2 triangle grid (2-G-map), the Kuhn
//! cube k = 1 (6 tets) or one tetrahedron (3-G-maps), and the mode (its bit 7,
//! [`is_cut_mode`]). Then every 3 bytes make one [`Op`]: byte a picks the kind (a % 4: edge
//! split, triangle 1→4, tet 1→8, refinement around a ball; in 2D a tet 1→8 becomes a triangle
//! split and a ball becomes the bulk uniform refinement one level up, `refine_uniform`, or, where
//! that is refused as `NotUniform` (the map checked unchanged), a triangle split), bit 7 of a
//! whether the level goes up by one; bytes b, c pick the dart
//! (any live dart, `(b·256 + c) mod darts`) or, for a ball, its centre and radius. The level an
//! op asks for is at most [`MAX_FUZZ_LEVEL`]; a refinement around a ball splits a tet its zone held
//! back by a level skip past the level asked for (`refine_around`, finding 275), so the map's
//! maximum level can pass it (4 in the committed corpus; finding 328). The map stops growing at
//! [`MAX_DARTS`] darts: the ops after that are not applied.
//!
//! **Cut mode** (bit 7 of byte 0 set): a % 8 = 4 is a cut ([`Op::Cut`]:
//! [`LeveledMap::unsew_face`] of the face of the (b·256 + c)-th α3-sewn dart, at the maximum
//! level or one above) and a % 8 = 5 a save and reload ([`Op::Reload`], bit 7 of a: the binary
//! store form, else the text form); the other kinds are as above. In 2D (no face cut in a
//! 2-map) a cut is a reload too. The 3D ops go through the spring coupling, cuts included
//! ([`LeveledMechanics::unsew_face`], round 42), until the first reload; a reloaded copy has no
//! coupling (no file holds one), so its ops go to the map alone with its tet masses
//! ([`TetMasses`]: `subdivide_tet_with_mass`, `refine_around`) and must give the same maps,
//! outcomes and lumped vertex masses as the coupled original. Its laws are in [`cuts`]. Inputs whose byte 0 is below 128 (the whole
//! corpus before cut mode) decode as they always did.
//!
//! # Laws checked after every op (a failure is a bug in topomech)
//! - accepted op: [`LeveledMap::check_all`] (finest map valid, μt ≤ μf ≤ μa, every level a valid
//!   G-map); level k isomorphic to the finest map; the Euler characteristic of every level equals
//!   that of the input; a refinement around a ball keeps Σ tet mass and leaves every tet meeting
//!   the ball at the top level;
//! - refused op: only the documented refusals (`AlreadyAtLevel`, `NotATriangle`,
//!   `NotATetrahedron`, `FaceRefinedTooFar`, `OpenEdge`, `NotUniform`, and `FaceNotSewn` in cut
//!   mode), each true of the map it refused (the cell already at the level has that level, and
//!   so on: finding 325), and the map is unchanged (same darts, isomorphic, same maximum level).
//! - 3D: every op goes through a [`LeveledMechanics`] (springs and masses follow the map); after an
//!   accepted op its laws hold ([`LeveledMechanics::check`]), after a refused one it is unchanged.
//! - cut mode: the laws of [`cuts`] (a cut leaves the levels below it unchanged; a reloaded
//!   copy behaves as the original under every later op, stored bytes equal after each).

pub mod cuts;

use super::TetMasses;
use super::{tet_distance, CouplingError, LeveledMap, LeveledMechanics, SubdivideError};
use crate::generate::{grid_triangles, kuhn_cube};
use crate::gmap::{DartId, GMap};
use crate::mechanics::Material;

/// Highest level an op may reach.
pub const MAX_FUZZ_LEVEL: u8 = 3;
/// The map is not refined further once it has this many darts.
pub const MAX_DARTS: usize = 5_000;

/// The mesh an input starts from.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::{decode, Mesh};
/// // The first byte (its low 7 bits) modulo 3 picks the mesh.
/// assert_eq!(decode(&[0]).0, Mesh::Grid);
/// assert_eq!(decode(&[4]).0, Mesh::Cube);
/// assert_eq!(decode(&[2]).0, Mesh::Tet);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mesh {
    /// `grid_triangles(2)`: 8 triangles (2D).
    Grid,
    /// `kuhn_cube(1)`: 6 tets.
    Cube,
    /// One tetrahedron.
    Tet,
}

/// One decoded operation.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::{decode, Op};
/// let (_, ops) = decode(&[2, 0x82, 0, 3]);
/// assert_eq!(ops, vec![Op::Tet { pick: 3, up: true }]);
/// assert!(matches!(decode(&[0, 0x80, 0, 1]).1[..], [Op::SplitEdge { pick: 1, .. }]));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `split_edge` of the edge of dart pick % darts.
    SplitEdge {
        /// Dart selector.
        pick: u16,
        /// Level one above the current maximum.
        up: bool,
    },
    /// `subdivide_triangle`.
    Triangle {
        /// Dart selector.
        pick: u16,
        /// Level one above the current maximum.
        up: bool,
    },
    /// `subdivide_tet` (3D).
    Tet {
        /// Dart selector.
        pick: u16,
        /// Level one above the current maximum.
        up: bool,
    },
    /// `refine_around` a ball to one level above the current maximum (3D).
    Around {
        /// Centre selector: each coordinate is (byte / 255) in the unit cube.
        center: [u8; 2],
        /// Radius selector: byte / 255.
        radius: u8,
    },
    /// Cut mode: `unsew_face` of the face of the pick-th α3-sewn dart (any live dart when none
    /// is sewn), at the maximum level or one above (3D; a reload in 2D).
    Cut {
        /// Selector among the α3-sewn darts.
        pick: u16,
        /// Level one above the current maximum.
        up: bool,
    },
    /// Cut mode: save the map, load it back, and from then on apply every op to the copy too.
    Reload {
        /// The binary store form (else the text form).
        binary: bool,
    },
}

/// What [`run_bytes`] did.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::run_bytes;
/// // A grid, then one edge split one level up.
/// let r = run_bytes(&[0, 0x80, 0, 0]).unwrap();
/// assert_eq!((r.applied + r.refused, r.max_level), (1, r.applied as u8));
/// assert!(r.darts >= 8 * 6);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// Operations accepted.
    pub applied: usize,
    /// Operations refused with a documented error.
    pub refused: usize,
    /// Maximum level reached.
    pub max_level: u8,
    /// Darts at the end.
    pub darts: usize,
    /// Cuts accepted (cut mode; also counted in `applied`).
    pub cuts: usize,
    /// Saves and reloads (cut mode; counted in neither `applied` nor `refused`).
    pub reloads: usize,
}

/// Decodes bytes into a mesh and operations (see the [module docs](self)). Never fails.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::{decode, Mesh, Op};
/// let (mesh, ops) = decode(&[1, 0x80, 0, 5, 7]); // the trailing byte is ignored
/// assert_eq!(mesh, Mesh::Cube);
/// assert_eq!(ops, vec![Op::SplitEdge { pick: 5, up: true }]);
/// assert_eq!(decode(&[]), (Mesh::Grid, vec![]));
/// ```
pub fn decode(bytes: &[u8]) -> (Mesh, Vec<Op>) {
    let mesh = match bytes.first().map_or(0, |b| (b & 0x7f) % 3) {
        0 => Mesh::Grid,
        1 => Mesh::Cube,
        _ => Mesh::Tet,
    };
    let cut_mode = is_cut_mode(bytes);
    let op = |c: &[u8]| decode_op(c[0], c[1], c[2], cut_mode);
    let ops = bytes.get(1..).unwrap_or(&[]).chunks_exact(3).map(op).collect();
    (mesh, ops)
}

/// Whether `bytes` decode in cut mode (bit 7 of byte 0; module docs). O(1).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::{decode, is_cut_mode, Op};
/// assert!(!is_cut_mode(&[1, 4, 0, 0]) && is_cut_mode(&[0x81, 4, 0, 0]));
/// assert!(matches!(decode(&[1, 4, 0, 0]).1[..], [Op::SplitEdge { .. }])); // as before cut mode
/// assert_eq!(decode(&[0x81, 4, 0, 7]).1, vec![Op::Cut { pick: 7, up: false }]);
/// assert_eq!(decode(&[0x81, 0x85, 0, 0]).1, vec![Op::Reload { binary: true }]);
/// ```
pub fn is_cut_mode(bytes: &[u8]) -> bool {
    bytes.first().is_some_and(|b| b & 0x80 != 0)
}

fn decode_op(a: u8, b: u8, c: u8, cut_mode: bool) -> Op {
    let (pick, up) = (u16::from_be_bytes([b, c]), a & 0x80 != 0);
    match (a % 8, cut_mode) {
        (4, true) => return Op::Cut { pick, up },
        (5, true) => return Op::Reload { binary: up },
        _ => {}
    }
    match a % 4 {
        0 => Op::SplitEdge { pick, up },
        1 => Op::Triangle { pick, up },
        2 => Op::Tet { pick, up },
        _ => Op::Around { center: [b, c], radius: a.rotate_right(2) },
    }
}

/// Decodes and runs `bytes`, checking every law after every op.
///
/// # Errors
/// A message naming the op index and the law that broke (a bug in topomech).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::fuzz::run_bytes;
/// // One tetrahedron, then a 1→8 subdivision one level up.
/// let r = run_bytes(&[2, 0x82, 0, 0]).unwrap();
/// assert_eq!((r.applied, r.refused, r.max_level), (1, 0, 1));
/// assert_eq!(r.darts, 8 * 24);
/// ```
pub fn run_bytes(bytes: &[u8]) -> Result<Report, String> {
    let (mesh, ops) = decode(bytes);
    if is_cut_mode(bytes) {
        return cuts::run(mesh, &ops);
    }
    match mesh {
        Mesh::Grid => run(leveled_grid()?, &ops, apply_2d),
        Mesh::Cube | Mesh::Tet => {
            let m = leveled_3d(mesh)?;
            let mut mech = LeveledMechanics::new(&m, Material::default()).map_err(|e| e.to_string())?;
            run(m, &ops, |m, op| apply_3d(m, &mut mech, op))
        }
    }
}

/// The 2×2 triangle grid as a level-0 leveled map.
fn leveled_grid() -> Result<LeveledMap<2>, String> {
    let (points, tris) = grid_triangles(2);
    let (map, _) = GMap::<2>::from_triangles(points.len(), &tris).map_err(|e| e.to_string())?;
    Ok(LeveledMap::new(map, points))
}

/// The cube or the single tet of `mesh` (not [`Mesh::Grid`]) as a level-0 leveled map.
fn leveled_3d(mesh: Mesh) -> Result<LeveledMap<3>, String> {
    let (points, tets) = if mesh == Mesh::Cube {
        kuhn_cube(1)
    } else {
        (vec![[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 1.0, 0.1], [0.1, 0.3, 1.0]], vec![[0, 1, 2, 3]])
    };
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).map_err(|e| e.to_string())?;
    Ok(LeveledMap::new(map, points))
}

/// What applying one op gives: `Err` for a broken law, `Ok(Err)` for a refusal.
type Applied = Result<Result<(), SubdivideError>, String>;

fn run<const N: usize>(
    mut m: LeveledMap<N>,
    ops: &[Op],
    mut apply: impl FnMut(&mut LeveledMap<N>, Op) -> Applied,
) -> Result<Report, String> {
    let chi = m.map().euler_characteristic();
    let mut report = Report::default();
    for (k, &op) in ops.iter().enumerate() {
        if m.map().dart_count() >= MAX_DARTS {
            break;
        }
        let before = m.clone();
        match apply(&mut m, op).map_err(|e| format!("op {k} {op:?}: {e}"))? {
            Ok(()) => {
                report.applied += 1;
                check_accepted(&m, chi).map_err(|e| format!("op {k} {op:?} accepted: {e}"))?;
            }
            Err(e) => {
                report.refused += 1;
                check_refused(&before, &m, &e).map_err(|msg| format!("op {k} {op:?} refused ({e}): {msg}"))?;
            }
        }
    }
    report.max_level = m.max_level();
    report.darts = m.map().dart_count();
    Ok(report)
}

fn level_of<const N: usize>(m: &LeveledMap<N>, up: bool) -> u8 {
    let top = m.max_level();
    if up && top < MAX_FUZZ_LEVEL {
        top + 1
    } else {
        top
    }
}

fn pick_dart<const N: usize>(m: &LeveledMap<N>, pick: u16) -> DartId {
    let n = m.map().dart_count().max(1);
    m.map().darts().nth(pick as usize % n).expect("a live dart")
}

fn apply_2d(m: &mut LeveledMap<2>, op: Op) -> Applied {
    Ok(match op {
        Op::SplitEdge { pick, up } => m.split_edge(pick_dart(m, pick), level_of(m, up)).map(drop),
        Op::Triangle { pick, up } | Op::Tet { pick, up } => {
            m.subdivide_triangle(pick_dart(m, pick), level_of(m, up)).map(drop)
        }
        Op::Around { center, radius } => {
            let level = level_of(m, true);
            let before = m.clone();
            match m.refine_uniform(level) {
                Err(e @ SubdivideError::NotUniform { .. }) => {
                    check_refused(&before, m, &e).map_err(|msg| format!("bulk refusal ({e}): {msg}"))?;
                    let pick = u16::from_be_bytes(center) ^ u16::from(radius);
                    m.subdivide_triangle(pick_dart(m, pick), level).map(drop)
                }
                r => r.map(drop),
            }
        }
        Op::Cut { .. } | Op::Reload { .. } => return Err(format!("{op:?} outside cut mode")),
    })
}

/// An op through the coupling (a cut too, [`LeveledMechanics::unsew_face`]); its laws after an
/// accepted op, unchanged after a refused one.
fn apply_3d(m: &mut LeveledMap<3>, mech: &mut LeveledMechanics, op: Op) -> Applied {
    let before = mech.clone();
    let result = match op {
        Op::SplitEdge { pick, up } => mech.split_edge(m, pick_dart(m, pick), level_of(m, up)).map(drop),
        Op::Triangle { pick, up } => mech.subdivide_triangle(m, pick_dart(m, pick), level_of(m, up)).map(drop),
        Op::Tet { pick, up } => mech.subdivide_tet(m, pick_dart(m, pick), level_of(m, up)).map(drop),
        Op::Around { center, radius } => return around(m, mech, center, radius),
        Op::Cut { pick, up } => mech.unsew_face(m, cuts::pick_sewn(m, pick), level_of(m, up)).map(drop),
        Op::Reload { .. } => return Err("a reload is not an op of the map".into()),
    };
    match result {
        Ok(()) => mech.check(m).map(Ok).map_err(|e| format!("spring laws: {e}")),
        Err(CouplingError::Subdivide(e)) if *mech == before => Ok(Err(e)),
        Err(CouplingError::Subdivide(e)) => Err(format!("refused ({e}) but the spring coupling changed")),
        Err(e) => Err(format!("spring coupling: {e}")),
    }
}

/// `refine_around` with the mass, zone and spring laws checked. Tets created by hand-ordered ops
/// may not be refinable by a ball (`FaceRefinedTooFar` after a face was split twice): that is a
/// refusal, but only on a map that fails [`LeveledMap::check_faces_refinable`]; a map that
/// passes it is refused no tet for its faces and passes it afterwards (finding 272).
fn around(m: &mut LeveledMap<3>, mech: &mut LeveledMechanics, center: [u8; 2], radius: u8) -> Applied {
    let (c, r) = ball(center, radius);
    let levels = level_of(m, true);
    let (before, mech_before) = (m.clone(), mech.clone());
    let expected = masses_total(m)?;
    let refinable = m.check_faces_refinable().is_ok();
    if let Err(e) = mech.refine_around(m, c, r, levels) {
        // refine_around keeps the ops done before a refusal; the fuzz checks want all or nothing.
        (*m, *mech) = (before, mech_before);
        return match e {
            CouplingError::Subdivide(e @ SubdivideError::FaceRefinedTooFar { .. }) if refinable => {
                Err(format!("refused a map whose faces are refinable: {e}"))
            }
            CouplingError::Subdivide(e) => Ok(Err(e)),
            e => Err(format!("spring coupling: {e}")),
        };
    }
    let total = mech.masses.total(m);
    if (total - expected).abs() > 1e-12 * expected.max(1.0) {
        return Err(format!("Σ tet mass {total} after, {expected} before"));
    }
    ball_laws(m, (c, r), levels, refinable)?;
    mech.check(m).map(Ok).map_err(|e| format!("spring laws: {e}"))
}

/// The ball of an [`Op::Around`]: centre (b/255, c/255, 1/2), radius byte/255.
fn ball(center: [u8; 2], radius: u8) -> ([f64; 3], f64) {
    let c = [f64::from(center[0]) / 255.0, f64::from(center[1]) / 255.0, 0.5];
    (c, f64::from(radius) / 255.0)
}

/// The laws after an accepted refinement around the ball (c, r) up to `levels`: a map whose
/// faces were refinable before still is, and every tet meeting the ball reached `levels`.
/// O(darts).
fn ball_laws(m: &LeveledMap<3>, (c, r): ([f64; 3], f64), levels: u8, refinable: bool) -> Result<(), String> {
    if refinable {
        m.check_faces_refinable().map_err(|e| format!("refinable before, not after: {e}"))?;
    }
    for d in m.map().one_dart_per_cell(3) {
        let corners = m.tet_vertices(d).map_err(|e| e.to_string())?.map(|v| m.points()[v as usize]);
        // SUBDIVISION.md's law, from any state since finding 125 (such tets are caught up by a
        // level skip since round 18; since round 29 a tet that had to wait for a coarser
        // neighbour may end past `levels`, several levels past after a chain of blockers).
        if tet_distance(c, corners) <= r && levels >= 1 && m.mu(d).tet < levels {
            return Err(format!("the tet of {d} meets the ball but stayed at level {}", m.mu(d).tet));
        }
    }
    Ok(())
}

/// Σ ρ·V over the tets of `m` (ρ of the default material: every tet keeps m_t = ρ·V_t).
fn masses_total(m: &LeveledMap<3>) -> Result<f64, String> {
    let masses = TetMasses::from_density(m, Material::default().density).map_err(|e| e.to_string())?;
    Ok(masses.total(m))
}

/// The laws after an accepted operation: [`LeveledMap::check_all`], level k isomorphic to the
/// finest map, the Euler characteristic of every level equal to `chi` (the input's). Shared by the
/// fuzz decoder and the exhaustive checks of `proofs/`. O(k · capacity · n²).
///
/// # Errors
/// The first law broken, as a message.
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// # use topomech::subdivide::fuzz::check_accepted;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mut m = LeveledMap::new(map, pts);
/// let d = m.map().darts().next().unwrap();
/// m.subdivide_tet(d, 1).unwrap();
/// assert!(check_accepted(&m, 1).is_ok()); // χ of a tetrahedron: 4 − 6 + 4 − 1
/// assert!(check_accepted(&m, 2).is_err());
/// ```
pub fn check_accepted<const N: usize>(m: &LeveledMap<N>, chi: i64) -> Result<(), String> {
    m.check_all().map_err(|e| e.to_string())?;
    let top = m.level(m.max_level()).map_err(|e| e.to_string())?;
    if !top.map.is_isomorphic(m.map()) {
        return Err("level k is not isomorphic to the finest map".into());
    }
    for i in 0..=m.max_level() {
        let x = m.level(i).map_err(|e| e.to_string())?.map.euler_characteristic();
        if x != chi {
            return Err(format!("level {i} has Euler characteristic {x}, the input {chi}"));
        }
    }
    Ok(())
}

/// The laws after a refused operation: `e` is a documented refusal for a live dart at a valid level
/// and the map is unchanged (same darts, same maximum level, isomorphic) and still valid. Shared
/// by the fuzz decoder and `proofs/`. O(k · capacity · n²).
///
/// # Errors
/// The first law broken, as a message.
///
/// # Examples
///
/// ```
/// # use topomech::subdivide::LeveledMap;
/// # use topomech::GMap;
/// # use topomech::subdivide::fuzz::check_refused;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mut m = LeveledMap::new(map, pts);
/// let d = m.map().darts().next().unwrap();
/// let before = m.clone();
/// let e = m.subdivide_tet(d, 0).unwrap_err(); // μt is already 0
/// assert!(check_refused(&before, &m, &e).is_ok());
/// m.subdivide_tet(d, 1).unwrap();
/// assert!(check_refused(&before, &m, &e).is_err()); // the map changed
/// ```
pub fn check_refused<const N: usize>(
    before: &LeveledMap<N>,
    after: &LeveledMap<N>,
    e: &SubdivideError,
) -> Result<(), String> {
    let documented = matches!(
        e,
        SubdivideError::AlreadyAtLevel { .. }
            | SubdivideError::NotATriangle { .. }
            | SubdivideError::NotATetrahedron { .. }
            | SubdivideError::FaceRefinedTooFar { .. }
            | SubdivideError::OpenEdge(_)
            | SubdivideError::NotUniform { .. }
            | SubdivideError::FaceNotSewn(_)
    );
    if !documented {
        return Err("not a documented refusal for a live dart at a valid level".into());
    }
    refusal_holds(before, e)?;
    let same = before.map().dart_count() == after.map().dart_count()
        && before.max_level() == after.max_level()
        && before.map().is_isomorphic(after.map());
    if !same {
        return Err("the map changed".into());
    }
    after.check_all().map_err(|e| e.to_string())
}

/// What a refusal states about the map it refused, checked on that map (`before`; for a
/// refinement around a ball, the map before the call, which a refusal leaves or puts back): the dart it
/// names is live, a cell refused as already at the level has that level there (μa, μf or μt
/// by its dimension) and it is at least the level asked for, a face or volume refused for its
/// corners does not have 3 or 4, an open edge's dart is free for some αj with j < n. A refusal
/// that only names a documented variant is not enough: an operation that refused valid work
/// with such a variant passed every subdivision test (finding 325). O(1).
fn refusal_holds<const N: usize>(before: &LeveledMap<N>, e: &SubdivideError) -> Result<(), String> {
    let live = |d: DartId| {
        if before.map().contains(d) {
            Ok(())
        } else {
            Err(format!("{e}: {d} is not a live dart of the refused map"))
        }
    };
    match *e {
        SubdivideError::AlreadyAtLevel { dart, dim, cell_level, level } => {
            live(dart)?;
            let mu = before.mu(dart);
            let own = match dim {
                1 => mu.edge,
                2 => mu.face,
                3 => mu.tet,
                _ => return Err(format!("{e}: no level for dimension {dim}")),
            };
            if own != cell_level || cell_level < level {
                return Err(format!("{e}: the cell's level is {own}, asked for {level}"));
            }
        }
        SubdivideError::NotATriangle { dart, corners } | SubdivideError::NotATetrahedron { dart, corners } => {
            live(dart)?;
            // A tetrahedron has 4 corners; the 2D bulk path reports a face that is not a
            // triangle as `NotATetrahedron` too (its volumes are faces): N + 1 (finding 333).
            let expected = if matches!(e, SubdivideError::NotATriangle { .. }) { 3 } else { N + 1 };
            if corners == expected {
                return Err(format!("{e}: refused with {corners} corners"));
            }
        }
        SubdivideError::OpenEdge(d) => {
            live(d)?;
            if !(0..N).any(|j| before.map().is_free(j, d)) {
                return Err(format!("{e}: {d} is not free for any αj, j < {N}"));
            }
        }
        SubdivideError::FaceNotSewn(d) => {
            live(d)?;
            if N < 3 || !before.map().is_free(3, d) {
                return Err(format!("{e}: {d} is not α3-free"));
            }
        }
        SubdivideError::FaceRefinedTooFar { dart } | SubdivideError::NotUniform { dart, .. } => live(dart)?,
        _ => {}
    }
    Ok(())
}

//! Cut mode of the subdivision decoder ([parent module](super), bit 7 of byte 0): face cuts
//! ([`LeveledMap::unsew_face`]) and store round trips among the subdivisions, 2D and 3D. In 3D
//! the original runs every op through its spring coupling ([`LeveledMechanics`], cuts by
//! [`LeveledMechanics::unsew_face`]; its laws after every accepted op); a reloaded copy has none
//! (no file holds one) and runs the same ops on the map alone with its [`TetMasses`].
//!
//! # Laws, beyond those of every accepted or refused op (parent module)
//! - **Euler characteristic per level**: a subdivision keeps χ of every level, and a new level
//!   has the χ of the level below it; a cut at level L keeps χ of the levels below L.
//! - **A cut at level L** leaves every level below L as it was (isomorphic, the same number of
//!   darts: the coarser levels keep the face glued), and the finest map gains exactly one face,
//!   keeps its volumes and loses no vertex or edge.
//! - **Masses** (3D): Σ m_t is kept by every op (children share their parent's mass, a cut moves
//!   none) to a relative 1e-12, and the masses cover every live volume ([`TetMasses::check`]).
//! - **Reload**: the map saved in the text or binary store form loads back
//!   ([`crate::store::Document::into_leveled`]) with the same level records
//!   ([`LeveledMap::to_parts`]) and the same stored bytes. From then on every op is applied to
//!   the loaded copy too: it must give the same outcome (the same `Ok`, or the same error) and
//!   leave the same stored bytes and, in 3D, the same lumped vertex masses
//!   ([`TetMasses::vertex_masses`], which reads the split log the loader rebuilt: finding 336)
//!   to a relative 1e-12.

use super::{ball, ball_laws, check_refused, level_of, leveled_3d, leveled_grid, pick_dart, Applied};
use super::{Mesh, Op, Report, MAX_DARTS};
use crate::gmap::DartId;
use crate::mechanics::Material;
use crate::store::{self, Document, Format};
use crate::subdivide::{LeveledMap, LeveledMechanics, SubdivideError, TetMasses};

/// The state the ops apply to: the map and, in 3D, its spring coupling (the original) or its
/// tet masses alone (a reloaded copy).
#[derive(Clone)]
struct State<const N: usize> {
    m: LeveledMap<N>,
    masses: Option<TetMasses>,
    mech: Option<LeveledMechanics>,
}

/// What differs between 2D and 3D in cut mode.
trait Step {
    /// Applies a subdivision or a cut (never a reload). `Err` for a broken law.
    fn apply(&mut self, op: Op) -> Applied;
    /// The masses' laws against the total at the start (3D); nothing in 2D.
    fn mass_laws(&self, total: f64) -> Result<(), String>;
    /// The lumped vertex masses (3D).
    fn vertex_masses(&self) -> Option<Vec<f64>>;
    /// Σ m_t (3D; 0 in 2D).
    fn total_mass(&self) -> f64;
}

/// Runs `ops` in cut mode on `mesh` (module docs). O(ops · (op + k · darts · n²)).
pub(super) fn run(mesh: Mesh, ops: &[Op]) -> Result<Report, String> {
    match mesh {
        Mesh::Grid => run_on(State { m: leveled_grid()?, masses: None, mech: None }, ops),
        Mesh::Cube | Mesh::Tet => {
            let m = leveled_3d(mesh)?;
            let mech = LeveledMechanics::new(&m, Material::default()).map_err(|e| e.to_string())?;
            run_on(State { m, masses: None, mech: Some(mech) }, ops)
        }
    }
}

fn run_on<const N: usize>(mut state: State<N>, ops: &[Op]) -> Result<Report, String>
where
    State<N>: Step + Clone,
{
    let mut chis = vec![state.m.map().euler_characteristic()];
    let total = state.total_mass();
    let mut copy: Option<State<N>> = None;
    let mut report = Report::default();
    for (k, &op) in ops.iter().enumerate() {
        if state.m.map().dart_count() >= MAX_DARTS {
            break;
        }
        let op = match op {
            Op::Cut { up, .. } if N < 3 => Op::Reload { binary: up },
            op => op,
        };
        let at = |e: String| format!("op {k} {op:?}: {e}");
        if let Op::Reload { binary } = op {
            copy = Some(reload(&state, binary).map_err(at)?);
            report.reloads += 1;
            continue;
        }
        let cut_at = matches!(op, Op::Cut { .. }).then(|| level_of(&state.m, matches!(op, Op::Cut { up: true, .. })));
        let before = state.m.clone();
        let outcome = state.apply(op).map_err(at)?;
        if let Some(twin) = copy.as_mut() {
            let other = twin.apply(op).map_err(|e| at(format!("on the reloaded copy: {e}")))?;
            same_as_copy(&state, twin, &outcome, &other).map_err(at)?;
        }
        match outcome {
            Ok(()) => {
                report.applied += 1;
                report.cuts += usize::from(cut_at.is_some());
                accepted(&before, &state.m, cut_at, &mut chis).map_err(|e| at(format!("accepted: {e}")))?;
            }
            Err(e) => {
                report.refused += 1;
                check_refused(&before, &state.m, &e).map_err(|msg| at(format!("refused ({e}): {msg}")))?;
            }
        }
        state.mass_laws(total).map_err(at)?;
    }
    report.max_level = state.m.max_level();
    report.darts = state.m.map().dart_count();
    Ok(report)
}

/// χ of every level of `m`, index = level. O(k · darts).
fn level_chis<const N: usize>(m: &LeveledMap<N>) -> Result<Vec<i64>, String> {
    (0..=m.max_level()).map(|i| Ok(m.level(i).map_err(|e| e.to_string())?.map.euler_characteristic())).collect()
}

/// The laws after an accepted op (`cut_at`: the level of a cut) on the map `before` it, with
/// `chis` the χ per level before; `chis` becomes the χ per level after. O(k · darts · n²).
fn accepted<const N: usize>(
    before: &LeveledMap<N>,
    after: &LeveledMap<N>,
    cut_at: Option<u8>,
    chis: &mut Vec<i64>,
) -> Result<(), String> {
    after.check_all().map_err(|e| e.to_string())?;
    let top = after.level(after.max_level()).map_err(|e| e.to_string())?;
    if !top.map.is_isomorphic(after.map()) {
        return Err("level k is not isomorphic to the finest map".into());
    }
    let fresh = level_chis(after)?;
    let kept = usize::from(cut_at.unwrap_or(u8::MAX));
    for (i, &x) in fresh.iter().enumerate().take(kept) {
        let expected = chis[i.min(chis.len() - 1)];
        if x != expected {
            return Err(format!("level {i} has Euler characteristic {x}, {expected} before"));
        }
    }
    if let Some(level) = cut_at {
        cut_laws(before, after, level)?;
    }
    *chis = fresh;
    Ok(())
}

/// A cut at `level`: the levels below it unchanged, one more face at the finest level, the same
/// volumes, no vertex or edge fewer. O(level · darts · n²).
fn cut_laws<const N: usize>(before: &LeveledMap<N>, after: &LeveledMap<N>, level: u8) -> Result<(), String> {
    for i in 0..level {
        let (a, b) = (before.level(i).map_err(|e| e.to_string())?, after.level(i).map_err(|e| e.to_string())?);
        if a.map.dart_count() != b.map.dart_count() || !a.map.is_isomorphic(&b.map) {
            return Err(format!("the cut at level {level} changed level {i}"));
        }
    }
    let (a, b) = (before.map().count_cells().0, after.map().count_cells().0);
    let grew = |dim: usize| b[dim] as i64 - a[dim] as i64;
    if grew(2) != 1 || grew(3) != 0 || grew(0) < 0 || grew(1) < 0 {
        return Err(format!("the cut took the cell counts from {a:?} to {b:?}"));
    }
    Ok(())
}

/// The map's stored bytes (binary form): everything a save keeps, bit for bit. O(darts).
fn stored<const N: usize>(m: &LeveledMap<N>) -> Result<Vec<u8>, String> {
    store::encode(&Document::from_leveled(m), Format::Binary).map_err(|e| format!("cannot save: {e}"))
}

/// Saves `state` in the text or binary form and loads it back, with the reload's laws. O(darts · k).
fn reload<const N: usize>(state: &State<N>, binary: bool) -> Result<State<N>, String> {
    let format = if binary { Format::Binary } else { Format::Text };
    let bytes = store::encode(&Document::from_leveled(&state.m), format).map_err(|e| format!("cannot save: {e}"))?;
    let m = store::decode(&bytes)
        .and_then(|doc| doc.into_leveled::<N>())
        .map_err(|e| format!("the saved map ({format:?}) does not load back: {e}"))?;
    if m.to_parts() != state.m.to_parts() {
        return Err(format!("the map loaded from the {format:?} form has other level records"));
    }
    if stored(&m)? != stored(&state.m)? {
        return Err(format!("the map loaded from the {format:?} form saves other bytes"));
    }
    m.check_all().map_err(|e| format!("the loaded map breaks a law: {e}"))?;
    Ok(State { m, masses: state.tet_masses().cloned(), mech: None })
}

/// The reloaded copy `twin` after the same op as `state`: the same outcome, the same stored
/// bytes, the same lumped vertex masses. O(darts).
fn same_as_copy<const N: usize>(
    state: &State<N>,
    twin: &State<N>,
    outcome: &Result<(), SubdivideError>,
    other: &Result<(), SubdivideError>,
) -> Result<(), String>
where
    State<N>: Step,
{
    if outcome != other {
        return Err(format!("the original gave {outcome:?}, the reloaded copy {other:?}"));
    }
    if stored(&state.m)? != stored(&twin.m)? {
        return Err("the original and the reloaded copy save other bytes".into());
    }
    match (state.vertex_masses(), twin.vertex_masses()) {
        (Some(a), Some(b)) => {
            let scale = a.iter().fold(1.0f64, |s, x| s.max(x.abs()));
            let apart = a.len() != b.len() || a.iter().zip(&b).any(|(x, y)| (x - y).abs() > 1e-12 * scale);
            if apart {
                return Err("the original and the reloaded copy lump other vertex masses".into());
            }
            Ok(())
        }
        (None, None) => Ok(()),
        _ => Err("vertex masses on one side only".into()),
    }
}

/// The pick-th α3-sewn dart (any live dart when none is sewn: the cut is then refused). O(darts).
pub(super) fn pick_sewn(m: &LeveledMap<3>, pick: u16) -> DartId {
    let map = m.map();
    let sewn = || map.darts().filter(|&d| !map.is_free(3, d));
    match sewn().count() {
        0 => pick_dart(m, pick),
        n => sewn().nth(usize::from(pick) % n).expect("a sewn dart"),
    }
}

impl Step for State<2> {
    fn apply(&mut self, op: Op) -> Applied {
        super::apply_2d(&mut self.m, op)
    }

    fn mass_laws(&self, _: f64) -> Result<(), String> {
        Ok(())
    }

    fn vertex_masses(&self) -> Option<Vec<f64>> {
        None
    }

    fn total_mass(&self) -> f64 {
        0.0
    }
}

impl<const N: usize> State<N> {
    /// The tet masses: the coupling's, or the state's own.
    fn tet_masses(&self) -> Option<&TetMasses> {
        self.mech.as_ref().map(|mech| &mech.masses).or(self.masses.as_ref())
    }
}

impl Step for State<3> {
    fn apply(&mut self, op: Op) -> Applied {
        let State { m, masses, mech } = self;
        if let Some(mech) = mech {
            return super::apply_3d(m, mech, op);
        }
        let masses = masses.as_mut().ok_or("a 3D state without masses")?;
        Ok(match op {
            Op::SplitEdge { pick, up } => m.split_edge(pick_dart(m, pick), level_of(m, up)).map(drop),
            Op::Triangle { pick, up } => m.subdivide_triangle(pick_dart(m, pick), level_of(m, up)).map(drop),
            Op::Tet { pick, up } => m.subdivide_tet_with_mass(pick_dart(m, pick), level_of(m, up), masses).map(drop),
            Op::Cut { pick, up } => m.unsew_face(pick_sewn(m, pick), level_of(m, up)).map(drop),
            Op::Around { center, radius } => return around_alone(m, masses, center, radius),
            Op::Reload { .. } => return Err("a reload is not an op of the map".into()),
        })
    }

    fn mass_laws(&self, total: f64) -> Result<(), String> {
        let masses = self.tet_masses().ok_or("a 3D state without masses")?;
        masses.check(&self.m).map_err(|e| format!("tet masses: {e}"))?;
        let now = masses.total(&self.m);
        if (now - total).abs() > 1e-12 * total.max(1.0) {
            return Err(format!("Σ tet mass {now}, {total} at the start"));
        }
        Ok(())
    }

    fn vertex_masses(&self) -> Option<Vec<f64>> {
        match &self.mech {
            Some(mech) => mech.vertex_masses(&self.m).ok(),
            None => self.masses.as_ref().and_then(|w| w.vertex_masses(&self.m).ok()),
        }
    }

    fn total_mass(&self) -> f64 {
        self.tet_masses().map_or(0.0, |w| w.total(&self.m))
    }
}

/// [`LeveledMap::refine_around`] on the map alone, all or nothing (the parent's refusal rules:
/// `FaceRefinedTooFar` only for a map whose faces were not refinable), then the ball's laws.
fn around_alone(m: &mut LeveledMap<3>, masses: &mut TetMasses, center: [u8; 2], radius: u8) -> Applied {
    let (c, r) = ball(center, radius);
    let levels = level_of(m, true);
    let (before, masses_before) = (m.clone(), masses.clone());
    let refinable = m.check_faces_refinable().is_ok();
    if let Err(e) = m.refine_around(c, r, levels, masses) {
        (*m, *masses) = (before, masses_before);
        return match e {
            SubdivideError::FaceRefinedTooFar { .. } if refinable => {
                Err(format!("refused a map whose faces are refinable: {e}"))
            }
            e => Ok(Err(e)),
        };
    }
    ball_laws(m, (c, r), levels, refinable)?;
    Ok(Ok(()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmap::AlphaMask;

    fn cube() -> State<3> {
        let m = leveled_3d(Mesh::Cube).expect("builds");
        let masses = TetMasses::from_density(&m, 1.0).expect("masses");
        State { m, masses: Some(masses), mech: None }
    }

    fn glued(m: &LeveledMap<3>) -> DartId {
        m.map().darts().find(|&d| !m.map().is_free(3, d)).expect("a glued face")
    }

    /// The cut's laws accept a cut at its own level and refuse one that changed a level below
    /// the level it claims, or that did not add exactly one face.
    #[test]
    fn cut_laws_fail_on_a_changed_coarser_level_or_a_wrong_face_count() {
        let before = cube().m;
        let mut after = before.clone();
        after.unsew_face(glued(&after), 0).expect("cuts");
        assert_eq!(cut_laws(&before, &after, 0), Ok(()));
        let e = cut_laws(&before, &after, 1).unwrap_err();
        assert!(e.contains("changed level 0"), "{e}");
        let mut split = before.clone();
        split.split_edge(glued(&split), 1).expect("splits");
        let e = cut_laws(&before, &split, 1).unwrap_err();
        assert!(e.contains("cell counts"), "{e}");
    }

    /// χ per level: a subdivision that claims to keep a level whose χ moved is caught, and a
    /// new level inherits the χ of the level below.
    #[test]
    fn accepted_checks_the_euler_characteristic_of_every_level() {
        let before = cube().m;
        let mut after = before.clone();
        after.subdivide_tet(glued(&after), 1).expect("splits");
        let mut chis = vec![before.map().euler_characteristic()];
        assert_eq!(accepted(&before, &after, None, &mut chis), Ok(()));
        assert_eq!(chis, vec![1, 1]);
        let mut wrong = vec![2];
        assert!(accepted(&before, &after, None, &mut wrong).unwrap_err().contains("Euler characteristic"));
        // A cut of a face whose edges are all inner changes χ of its level (one face more, no
        // vertex or edge): accepted as a cut, refused as a subdivision.
        let (points, tets) = crate::generate::kuhn_cube(2);
        let (map, _) = crate::GMap::<3>::from_tets(points.len(), &tets).expect("builds");
        let big = LeveledMap::new(map, points);
        let moved = big.map().darts().filter(|&d| !big.map().is_free(3, d)).find_map(|d| {
            let mut cut = big.clone();
            cut.unsew_face(d, 0).expect("cuts");
            (level_chis(&cut) != level_chis(&big)).then_some(cut)
        });
        let cut = moved.expect("a face whose cut changes χ");
        let mut chis = level_chis(&big).expect("levels");
        assert!(accepted(&big, &cut, None, &mut chis).unwrap_err().contains("Euler characteristic"));
        assert_eq!(accepted(&big, &cut, Some(0), &mut chis), Ok(()));
        assert_eq!(chis, vec![2]);
    }

    /// A reload keeps everything; a copy that went another way, or a different outcome, is
    /// reported.
    #[test]
    fn a_reloaded_copy_must_stay_the_same_as_the_original() {
        let mut state = cube();
        state.apply(Op::Tet { pick: 0, up: true }).expect("no broken law").expect("splits");
        for binary in [false, true] {
            let copy = reload(&state, binary).expect("reloads");
            assert_eq!(same_as_copy(&state, &copy, &Ok(()), &Ok(())), Ok(()));
            let refusal = Err(SubdivideError::NoSuchDart(DartId(0)));
            assert!(same_as_copy(&state, &copy, &Ok(()), &refusal).unwrap_err().contains("gave"));
            let mut other = copy.clone();
            other.apply(Op::Cut { pick: 0, up: false }).expect("no broken law").expect("splits");
            assert!(same_as_copy(&state, &other, &Ok(()), &Ok(())).unwrap_err().contains("bytes"));
        }
        let mut heavier = reload(&state, true).expect("reloads");
        heavier.masses.as_mut().expect("3D").mass[0] *= 2.0;
        assert!(same_as_copy(&state, &heavier, &Ok(()), &Ok(())).unwrap_err().contains("vertex masses"));
    }

    /// Σ m_t is checked against the start, and so is the masses' cover of the live volumes.
    #[test]
    fn the_mass_laws_fail_on_a_changed_total_or_a_missing_mass() {
        let mut state = cube();
        let total = state.total_mass();
        assert_eq!(state.mass_laws(total), Ok(()));
        assert!(state.mass_laws(2.0 * total).unwrap_err().contains("Σ tet mass"));
        state.masses.as_mut().expect("3D").mass.pop();
        assert!(state.mass_laws(total).unwrap_err().contains("tet masses"));
    }

    /// A cut picks among the α3-sewn darts, so that it is rarely refused; a map with no sewn
    /// dart gets any dart (and the refusal).
    #[test]
    fn a_cut_picks_a_sewn_dart_when_there_is_one() {
        let m = cube().m;
        for pick in [0, 1, 77, u16::MAX] {
            assert!(!m.map().is_free(3, pick_sewn(&m, pick)));
        }
        let tet = leveled_3d(Mesh::Tet).expect("builds");
        let d = pick_sewn(&tet, 5);
        assert!(tet.map().is_free(3, d));
        assert_eq!(tet.map().orbit(d, AlphaMask::of(&[0, 1])).len(), 6);
    }
}

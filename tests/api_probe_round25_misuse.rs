//! Round 25 (b), findings F1 and F3: objects used with a map or a report they were not made for.
//!
//! F1: `Mechanics::update_normals(&mut self, map)` took any map its arrays covered (a copy of the
//! body's map taken before a cut, another body's map of the same size), rewrote the face flags
//! from that topology, `body.check()` stayed Ok and `save_body` wrote a file `load_body` refused.
//! Now the update is `Body::update_normals()` on the body's own map (the map-taking one is
//! crate-private), the face law (flag = α3-free, inner normal zero) is part of `Body::check`,
//! and `save_body` runs the reader's body-state check before writing.
//!
//! F3: `TouchedCells::record_change` stamped any report as the body's last change, so an empty
//! or an earlier report made `Projection::update` / `Simulation::update` take the incremental
//! path and call themselves current with springs missing. Now the body stamps the reports it
//! returns (identity, version, fingerprint of the lists) and any other report is recorded with
//! unknown coverage: the update rebuilds.

use topomech::embedding::CellRules;
use topomech::generate::kuhn_cube;
use topomech::gmap::CellChanges;
use topomech::mechanics::{
    Body, ConservationError, Integrator, Material, Projection, Simulation, StepConfig, TouchedCells,
};
use topomech::store::{self, Format, StoreError, Where};
use topomech::DartId;

fn body(k: usize) -> Body {
    let (points, tets) = kuhn_cube(k);
    Body::from_tets(&points, &tets, Material::default()).unwrap().0
}

fn inner_darts(b: &Body) -> Vec<DartId> {
    b.map().darts().filter(|&d| !b.map().is_free(3, d)).collect()
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("topomech-r25-{}-{name}", std::process::id()))
}

/// The flags of the two faces of a cut at `d` (its side, and the other side's `e`).
fn cut_flags(b: &Body, d: DartId, e: DartId) -> (bool, bool) {
    let (f1, f2) = (b.map().cell_id(2, d), b.map().cell_id(2, e));
    (b.attrs().face_is_boundary(f1), b.attrs().face_is_boundary(f2))
}

/// The probe's first reproducer, through the API that replaced it: a copy of the map taken
/// before a cut cannot be handed in any more (`Body::update_normals` takes none), the update
/// leaves both cut faces boundary faces, the body checks, and the file round-trips.
#[test]
fn update_normals_after_a_cut_uses_the_body_map_and_the_file_loads() {
    let mut b = body(2);
    let stale = b.map().clone();
    let d = inner_darts(&b)[0];
    let e = b.map().alpha::<3>(d);
    b.unsew3(d).unwrap();
    assert_eq!(cut_flags(&b, d, e), (true, true));
    assert!(stale.cell_id(2, d) == stale.cell_id(2, e), "the stale map still has one face there");
    b.attrs_mut().position_mut().as_mut_slice().iter_mut().for_each(|p| p[0] *= 2.0);
    let version = b.version();
    b.update_normals().unwrap();
    assert_eq!(b.version(), version, "not a topological change");
    assert_eq!(cut_flags(&b, d, e), (true, true));
    assert_eq!(b.check(), Ok(()));
    let path = temp("stale.tmapb");
    store::save_body(&b, &path, Format::Binary).unwrap();
    let back = store::load_body(&path);
    let _ = std::fs::remove_file(&path);
    let back = back.unwrap();
    assert_eq!(store::Document::from_body(&back), store::Document::from_body(&b));
}

/// The probe's second reproducer: an uncut body's map can no longer rewrite a cut body's
/// flags; each body's update reads its own map, and the two bodies keep different flags.
#[test]
fn update_normals_of_two_bodies_of_one_mesh_stay_apart() {
    let (mut a, mut b) = (body(2), body(2));
    let d = inner_darts(&a)[0];
    let e = a.map().alpha::<3>(d);
    a.unsew3(d).unwrap();
    let before = format!("{:?}", a.attrs());
    a.update_normals().unwrap();
    b.update_normals().unwrap();
    assert_eq!(format!("{:?}", a.attrs()), before, "the body's own map gives the flags it had");
    assert_eq!(cut_flags(&a, d, e), (true, true));
    let f = b.map().cell_id(2, d);
    assert!(!b.attrs().face_is_boundary(f), "b is not cut");
    assert_eq!((a.check(), b.check()), (Ok(()), Ok(())));
}

/// The one way left to write face flags from another map is a `CellRules` method called by
/// hand on attributes taken out of a body (since round 27 a body's own attributes cannot be
/// reached that way: `Body::attrs_mut` opens positions, velocities and pins only). The face law
/// names the face, and `Body::new` and the reader refuse such parts.
#[test]
fn flags_rewritten_from_a_stale_map_are_caught_by_the_face_law_and_refused() {
    let mut b = body(2);
    let stale = b.map().clone();
    let d = inner_darts(&b)[0];
    let e = b.map().alpha::<3>(d);
    let changes = b.unsew3(d).unwrap();
    let (map, mut mech) = b.into_parts();
    mech.after_operation(&stale, &changes); // the stale topology: the face is sewn there
    let flags = (mech.face_is_boundary(map.cell_id(2, d)), mech.face_is_boundary(map.cell_id(2, e)));
    assert_ne!(flags, (true, true), "the hand-called rule wrote the stale flags");
    let err = mech.check_faces(&map).unwrap_err();
    match err {
        ConservationError::FaceFlag { face, dart, flagged_boundary: false } => {
            assert!(map.cell_id(2, dart) == face && map.is_free(3, dart));
            assert!(face == map.cell_id(2, d) || face == map.cell_id(2, e));
        }
        other => panic!("expected FaceFlag, got {other:?}"),
    }
    assert!(err.to_string().contains("is flagged inner but is a boundary face"), "{err}");
    let doc = store::Document {
        map: store::RawMap::from_map(&map),
        mechanics: Some(store::RawMechanics::from_mechanics(&mech)),
        levels: None,
    };
    let read = store::decode(&store::encode(&doc, Format::Binary).unwrap()).unwrap().into_body().unwrap_err();
    assert!(
        matches!(&read, StoreError::Inconsistent { at: Where::Document, message } if message.contains("is flagged inner but is a boundary face of the map")),
        "{read:?}"
    );
    assert!(matches!(Body::new(map, mech).unwrap_err().error, ConservationError::FaceFlag { .. }));
}

/// The other direction: another body's cut map handed to an uncut body's rule flags a sewn
/// face as boundary (with a normal); the face law names it and `Body::new` refuses the parts.
#[test]
fn flags_rewritten_from_another_bodys_cut_map_are_named() {
    let mut cut = body(1);
    let d = inner_darts(&cut)[0];
    let changes = cut.unsew3(d).unwrap();
    let mut a = body(1);
    let e = a.map().alpha::<3>(d);
    a.unsew3(d).unwrap();
    a.sew3(d, e).unwrap(); // the same ids as `cut` has, with the face sewn
    let (map, mut mech) = a.into_parts();
    mech.after_operation(cut.map(), &changes);
    let err = mech.check_faces(&map).unwrap_err();
    match err {
        ConservationError::FaceFlag { face, dart, flagged_boundary: true } => {
            assert!(map.cell_id(2, dart) == face && !map.is_free(3, dart));
            assert_ne!(mech.face_normal(face), [0.0; 3]);
        }
        other => panic!("expected FaceFlag, got {other:?}"),
    }
    assert!(err.to_string().contains("is flagged boundary but is an inner face"), "{err}");
    assert!(matches!(Body::new(map, mech).unwrap_err().error, ConservationError::FaceFlag { .. }));
}

/// Positions so small that |n|² is subnormal: round 25 found the boundary normals off unit
/// length there and made `save_body` refuse such a body (the reader refused its file); since
/// round 26 (finding 254) the normals are unit at every scale, so the body saves and loads.
/// `save_body`'s refusal of an off-unit normal is tested in `store::tests`.
#[test]
fn a_body_with_tiny_coordinates_has_unit_normals_and_saves() {
    let mut b = body(1);
    b.attrs_mut().position_mut().as_mut_slice().iter_mut().for_each(|p| *p = p.map(|c| c * 3e-81));
    b.update_normals().unwrap();
    let map = b.map();
    for d in map.one_dart_per_cell(2).into_iter().filter(|&d| map.is_free(3, d)) {
        let n = b.attrs().face_normal(map.cell_id(2, d));
        let len = n.iter().map(|c| c * c).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() <= 1e-15, "{n:?}");
    }
    assert_eq!(b.check(), Ok(()));
    let path = temp("normal.tmap");
    store::save_body(&b, &path, Format::Text).unwrap();
    assert!(store::load_body(&path).is_ok());
    let _ = std::fs::remove_file(&path);
}

/// The probe's F3 reproducer: an empty report recorded as the last change is not trusted.
#[test]
fn an_empty_report_recorded_as_the_last_change_rebuilds() {
    let mut b = body(2);
    let mut p = Projection::build(&b, [0.0; 3]).unwrap();
    let d = inner_darts(&b)[0];
    let _real = b.unsew3(d).unwrap();
    let mut t = TouchedCells::default();
    t.record_change(&b, &CellChanges::default());
    assert_eq!(t.versions(&b), None);
    let incremental = p.update(&b, &t);
    assert!(!incremental, "an unstamped report is rebuilt from");
    assert!(p.is_current(&b));
    assert_eq!(p.equivalent(&Projection::build(&b, [0.0; 3]).unwrap()), Ok(()));
}

/// The probe's second F3 reproducer: the report of an earlier operation recorded as the last.
#[test]
fn a_stale_report_recorded_as_the_last_change_rebuilds() {
    let mut b = body(2);
    let g = [0.0, 0.0, -9.81];
    let mut sim = Simulation::new(&mut b, g, StepConfig::new(Integrator::Symplectic, 1e-3)).unwrap();
    let inner = inner_darts(&b);
    let first = b.unsew3(inner[0]).unwrap();
    let mut t = TouchedCells::default();
    t.record_change(&b, &first);
    assert_eq!(t.versions(&b), Some((0, 1)), "the real report, right after: trusted");
    sim.update(&mut b, &t).unwrap();
    let e = inner
        .iter()
        .copied()
        .find(|&e| !b.map().is_free(3, e) && b.map().cell_id(2, e) != b.map().cell_id(2, inner[0]))
        .unwrap();
    let _second = b.unsew3(e).unwrap();
    let mut t2 = TouchedCells::default();
    t2.record_change(&b, &first); // the first report again
    assert_eq!(t2.versions(&b), None);
    sim.update(&mut b, &t2).unwrap();
    assert!(sim.projection.is_current(&b));
    assert_eq!(sim.projection.equivalent(&Projection::build(&b, g).unwrap()), Ok(()));
    sim.step(&mut b).unwrap();
}

/// Other reports that are not the body's last: the kernel's own report of the same unsew, the
/// report of a clone's identical operation, and the body's real report edited (a pair or a
/// change removed, or the new sides of another report put in). All rebuild.
#[test]
fn kernel_foreign_and_edited_reports_rebuild() {
    let fresh = |b: &Body| Projection::build(b, [0.0; 3]).unwrap();
    let check = |b: &Body, p: &Projection, changes: &CellChanges, what: &str| {
        let mut p = p.clone();
        let mut t = TouchedCells::default();
        t.record_change(b, changes);
        assert_eq!(t.versions(b), None, "{what}: stamped");
        assert!(!p.update(b, &t), "{what}: taken incrementally");
        assert_eq!(p.equivalent(&fresh(b)), Ok(()), "{what}");
    };
    let mut b = body(2);
    let p = fresh(&b);
    let mut twin = b.clone();
    let mut kernel_map = b.map().clone();
    let d = inner_darts(&b)[0];
    let real = b.unsew3(d).unwrap();
    let kernel = kernel_map.unsew_dyn(3, d).unwrap();
    let twin_report = twin.unsew3(d).unwrap();
    assert!(kernel == real && twin_report == real, "the same operation: equal reports (the stamp is not compared)");
    check(&b, &p, &kernel, "the kernel's report");
    check(&b, &p, &twin_report, "a clone's report");
    check(&b, &p, &CellChanges::default(), "a default report");
    let mut fewer_pairs = real.clone();
    fewer_pairs.pairs.pop();
    check(&b, &p, &fewer_pairs, "a pair removed");
    let mut fewer_changes = real.clone();
    let k = fewer_changes.changes.len() - 1;
    fewer_changes.changes.remove(k);
    check(&b, &p, &fewer_changes, "a change removed");
    let mut swapped = real.clone();
    swapped.pairs.reverse();
    if swapped.pairs != real.pairs {
        check(&b, &p, &swapped, "pairs reordered");
    }
    let mut other_sides = real.clone();
    other_sides.new_sides = Default::default();
    if (0..real.changes.len()).any(|k| !real.new_side(k).is_empty()) {
        check(&b, &p, &other_sides, "new sides dropped");
    }
    // The real one, untouched (and a clone of it: the same report), is still trusted.
    for (r, what) in [(&real, "the real report"), (&real.clone(), "a clone of it")] {
        let mut p = p.clone();
        let mut t = TouchedCells::default();
        t.record_change(&b, r);
        assert_eq!(t.versions(&b), Some((0, 1)), "{what}");
        assert!(p.update(&b, &t), "{what}: incremental");
        assert_eq!(p.equivalent(&fresh(&b)), Ok(()), "{what}");
    }
}

/// The correct use stays incremental: each report of a chain of sews and unsews recorded right
/// after its operation, through `Projection::update` and `Simulation::update`, equal to a fresh
/// build; a report recorded one operation late (after the next one) is not trusted.
#[test]
fn reports_recorded_right_after_their_operation_update_incrementally() {
    let mut b = body(3);
    let g = [0.0, 0.0, -9.81];
    let mut p = Projection::build(&b, g).unwrap();
    let mut sim = Simulation::new(&mut b, g, StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
    let faces: Vec<DartId> =
        b.map().one_dart_per_cell(2).into_iter().filter(|&d| !b.map().is_free(3, d)).step_by(7).take(6).collect();
    let mut batch = TouchedCells::default();
    for (k, &d) in faces.iter().enumerate() {
        let e = b.map().alpha::<3>(d);
        let cut = b.unsew3(d).unwrap();
        let mut t = TouchedCells::default();
        t.record_change(&b, &cut);
        batch.extend(&t);
        if k % 2 == 1 {
            let sewn = b.sew3(d, e).unwrap(); // and back
            let mut t2 = TouchedCells::default();
            t2.record_change(&b, &sewn);
            batch.extend(&t2);
            t.extend(&t2);
        }
        assert_eq!(t.versions(&b).map(|(_, to)| to), Some(b.version()));
        assert!(p.update(&b, &t), "operation {k}: incremental");
        sim.update(&mut b, &t).unwrap();
        assert_eq!(p.equivalent(&Projection::build(&b, g).unwrap()), Ok(()), "operation {k}");
        assert_eq!(sim.projection.equivalent(&Projection::build(&b, g).unwrap()), Ok(()), "operation {k}");
        sim.step(&mut b).unwrap();
    }
    assert_eq!(batch.versions(&b), Some((0, b.version())));
    // A report recorded after a later operation: not the last, rebuilt.
    let d = inner_darts(&b)[0];
    let late = b.unsew3(d).unwrap();
    let e = inner_darts(&b)[0];
    let next = b.unsew3(e).unwrap();
    let mut t = TouchedCells::default();
    t.record_change(&b, &late);
    t.record_change(&b, &next);
    assert_eq!(t.versions(&b), None);
    assert!(!p.update(&b, &t));
    assert_eq!(p.equivalent(&Projection::build(&b, g).unwrap()), Ok(()));
}

/// One mark per vertex id; the law: every live vertex cell carries exactly 1. A split's new
/// vertex gets its 1 from `on_split`, unless the rule panics first (`panic_on_split`).
#[derive(Debug)]
struct VertexMarks {
    marks: Vec<u32>,
    panic_on_split: bool,
}

#[derive(Debug, thiserror::Error)]
#[error("vertex {0} carries {1} marks, not 1")]
struct MarkError(u32, u32);

impl CellRules<3> for VertexMarks {
    type Error = MarkError;
    fn grow_to(&mut self, map: &topomech::GMap<3>) {
        self.marks.resize(map.cell_id_bound(0), 0);
    }
    fn on_split(&mut self, _: &topomech::GMap<3>, split: &topomech::embedding::Split<'_>) {
        if split.dim == 0 {
            assert!(!self.panic_on_split, "rule panics on purpose");
            self.marks[split.new.index()] = 1;
        }
    }
    fn on_merge(&mut self, _: &topomech::GMap<3>, dim: usize, _: topomech::CellId, absorbed: topomech::CellId) {
        if dim == 0 {
            self.marks[absorbed.index()] = 0;
        }
    }
    fn check(&self, map: &topomech::GMap<3>) -> Result<(), MarkError> {
        for d in map.one_dart_per_cell(0) {
            let v = map.cell_id(0, d);
            match self.marks.get(v.index()).copied().unwrap_or(0) {
                1 => {}
                n => return Err(MarkError(v.0, n)),
            }
        }
        Ok(())
    }
}

/// F6 (documented on `CellRules`): a rule that panics unwinds out of `Embedded::unsew` after
/// the topological change — the map is unsewn, the attributes were not updated — and `check`
/// names the vertex the rule left without its mark. The same unsew without the panic keeps the
/// law (the test could tell the two apart).
#[test]
fn a_rule_that_panics_leaves_the_map_changed_and_check_names_the_broken_law() {
    // Two tets sharing the face 0-1-2: opening it splits the vertices 0, 1 and 2.
    for panic_on_split in [false, true] {
        let (map, _) = topomech::GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
        let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
        let marks = VertexMarks { marks: vec![1; map.cell_id_bound(0)], panic_on_split };
        let mut e = topomech::embedding::Embedded::new(map, marks).unwrap();
        assert!(e.check().is_ok());
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| e.unsew(3, d).map(|_| ())));
        assert!(e.map().is_free(3, d), "the map is unsewn either way");
        assert!(e.map().validate().is_ok());
        match (panic_on_split, result) {
            (false, Ok(Ok(()))) => assert!(e.check().is_ok()),
            (true, Err(_)) => {
                let err = e.check().unwrap_err();
                assert_eq!(err.1, 0, "{err}");
            }
            (p, r) => panic!("panic_on_split {p}: unexpected {:?}", r.map_err(|_| "panic")),
        }
    }
}

//! Round 38, finding 332: a `CellHandle` carries the identity of its map, and an id's generation
//! is the stamp of its last release (one process-wide counter), not a count. A handle is refused
//! on a map built apart, loaded from a file or extracted as a level (`StaleCell::OtherMap`), and a
//! clone that went its own way does not take its own reuse of an id for the original's.

use topomech::gmap::{CellHandle, StaleCell};
use topomech::store::{decode, encode, Document, Format};
use topomech::subdivide::LeveledMap;
use topomech::{CellId, DartId, GMap};

/// Two tets glued along the face {0, 1, 2}, and one dart of that face with its α3 partner.
fn glued_pair() -> (GMap<3>, DartId, DartId) {
    let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
    let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    let e = map.alpha::<3>(d);
    (map, d, e)
}

/// Unsews the glued face and sews it back: its three vertices split, then merge, releasing the
/// absorbed side's id; a second unsew hands that id to a new vertex. Returns the reused vertex id.
fn reuse_a_vertex_id(map: &mut GMap<3>, d: DartId, e: DartId) -> CellId {
    map.unsew::<3>(d).unwrap();
    let merged = map.sew::<3>(d, e).unwrap();
    let absorbed: Vec<CellId> = merged.merges(0).map(|(_, a)| a).collect();
    assert!(!absorbed.is_empty(), "the sew merged no vertex");
    map.unsew::<3>(d).unwrap();
    let reused: Vec<CellId> = absorbed.into_iter().filter(|&a| map.is_live_cell(0, a)).collect();
    assert!(!reused.is_empty(), "no released id was given out again");
    reused[0]
}

#[test]
fn f332_a_handle_is_refused_on_a_map_built_apart_with_the_same_ids() {
    let (a, ..) = glued_pair();
    let (b, ..) = glued_pair();
    let h = a.cell_handle(0, CellId(3)).unwrap();
    assert_eq!(a.resolve(h), Ok(CellId(3)));
    assert_eq!(a.clone().resolve(h), Ok(CellId(3)), "a clone is the same map");
    assert_eq!(b.resolve(h), Err(StaleCell::OtherMap { dim: 0, id: CellId(3) }));
    // The other map's own handle on the same id resolves there and is refused here.
    let hb = b.cell_handle(0, CellId(3)).unwrap();
    assert_eq!(b.resolve(hb), Ok(CellId(3)));
    assert!(matches!(a.resolve(hb), Err(StaleCell::OtherMap { .. })));
}

#[test]
fn f332_a_handle_is_refused_on_the_map_loaded_from_a_save_of_its_map() {
    let (mut map, d, e) = glued_pair();
    let reused = reuse_a_vertex_id(&mut map, d, e);
    let h = map.cell_handle(0, reused).unwrap();
    let untouched = map.cell_handle(0, CellId(3)).unwrap();
    for format in [Format::Text, Format::Binary] {
        let bytes = encode(&Document::from_map(&map), format).unwrap();
        let loaded: GMap<3> = decode(&bytes).unwrap().into_map().unwrap();
        assert!(loaded.is_live_cell(0, reused) && loaded.is_live_cell(0, CellId(3)));
        // Before finding 332 the reused id (generation ≠ 0) was `Reused` there, but the
        // untouched one (generation 0 in both) resolved on the loaded map.
        assert_eq!(loaded.resolve(h), Err(StaleCell::OtherMap { dim: 0, id: reused }), "{format:?}");
        assert_eq!(loaded.resolve(untouched), Err(StaleCell::OtherMap { dim: 0, id: CellId(3) }));
        let fresh = loaded.cell_handle(0, reused).unwrap();
        assert_eq!((fresh.generation(), loaded.resolve(fresh)), (0, Ok(reused)), "a loaded map has no history");
    }
}

#[test]
fn f332_a_level_view_is_another_map() {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut m = LeveledMap::new(map, pts);
    let h = m.map().cell_handle(0, CellId(0)).unwrap();
    let d = m.map().darts().next().unwrap();
    m.subdivide_tet(d, 1).unwrap();
    assert_eq!(m.map().resolve(h), Ok(CellId(0)), "a corner keeps its id through the split");
    let view = m.level(0).unwrap();
    assert!(matches!(view.map.resolve(h), Err(StaleCell::OtherMap { .. })));
}

/// Clones that went their own way: each reuses the same vertex id by its own operations. A handle
/// taken on one after its reuse names, on the other, a cell the other map gave that id by another
/// release: refused as `Reused`. A handle taken before the clone, on a vertex neither touched,
/// resolves in both. Before finding 332 (release counts) both maps counted one release of the id
/// and the handle resolved on the other clone.
#[test]
fn f332_diverged_clones_refuse_each_others_reuse_of_an_id() {
    let (mut a, d, e) = glued_pair();
    let apex = a.cell_handle(0, CellId(3)).unwrap();
    let mut b = a.clone();
    let ra = reuse_a_vertex_id(&mut a, d, e);
    let rb = reuse_a_vertex_id(&mut b, d, e);
    assert_eq!(ra, rb, "the same operations give the same id out again");
    let ha: CellHandle = a.cell_handle(0, ra).unwrap();
    let hb: CellHandle = b.cell_handle(0, rb).unwrap();
    assert_eq!((a.resolve(ha), b.resolve(hb)), (Ok(ra), Ok(rb)));
    assert_ne!(ha.generation(), hb.generation(), "two releases share a stamp");
    match b.resolve(ha) {
        Err(StaleCell::Reused { dim: 0, id, then, now }) => {
            assert_eq!((id, then, now), (ra, ha.generation(), hb.generation()));
        }
        other => panic!("a's handle on its reused id resolved on b as {other:?}"),
    }
    assert!(matches!(a.resolve(hb), Err(StaleCell::Reused { .. })));
    assert_eq!((a.resolve(apex), b.resolve(apex)), (Ok(CellId(3)), Ok(CellId(3))));
}

/// A clone kept as a backup and put back (the all-or-nothing pattern of the refinements) keeps the
/// handles taken before it, and refuses those taken on ids the abandoned branch reused.
#[test]
fn f332_a_restored_backup_keeps_the_handles_taken_before_it() {
    let (mut map, d, e) = glued_pair();
    let corners: Vec<CellHandle> = (0..5).map(|v| map.cell_handle(0, CellId(v)).unwrap()).collect();
    let backup = map.clone();
    let reused = reuse_a_vertex_id(&mut map, d, e);
    let branch = map.cell_handle(0, reused).unwrap();
    map = backup;
    for (v, &h) in corners.iter().enumerate() {
        assert_eq!(map.resolve(h), Ok(CellId(v as u32)), "vertex {v}");
    }
    assert!(map.resolve(branch).is_err(), "a handle from the abandoned branch resolved");
}

//! Round 37's probes, and the tests that close mutation sample 50.

mod fan_common;
use fan_common::double_cone;

use std::collections::BTreeSet;

use topomech::conformance::{replay_in, ConformanceError, Vector};
use topomech::cut::fan_darts;
use topomech::generate::kuhn_cube;
use topomech::GMap;

fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Mutation sample 50's survivors in the conformance comparison (`a == 0 || b == 0` → `&&`, and
/// `input_tets` → 0): where one side is exactly 0 (the emptied body of `single_tet_remove`), the
/// other may differ from it by up to 16·T·ε·s (T input tets, s the initial total; finding 311),
/// and not by more.
#[test]
fn a_value_within_the_floor_of_an_exact_zero_matches_and_beyond_it_does_not() {
    let v = Vector::read(&root().join("conformance/single_tet_remove.json")).unwrap();
    assert_eq!(v.steps[0].expect.total_mass, 0.0);
    replay_in(&v, root()).unwrap();
    let floor = 16.0 * 1.0 * f64::EPSILON * v.initial.total_mass;
    for (factor, matches) in [(0.5, true), (1.0, true), (4.0, false), (1e6, false)] {
        let mut w = v.clone();
        w.steps[0].expect.total_mass = factor * floor;
        match replay_in(&w, root()) {
            Ok(()) => assert!(matches, "{factor} × the floor matched an exact 0"),
            Err(e) => {
                assert!(!matches, "{factor} × the floor: {e}");
                assert!(matches!(e, ConformanceError::Mismatch { .. }), "{e}");
                assert_eq!((e.step(), e.field()), (Some(0), Some("total_mass")), "{e}");
            }
        }
    }
}

/// Mutation sample 50's survivor in `FacesSeen::insert` (`!set.is_empty()` → `set.is_empty()`):
/// a fan that is not closed (a vertex on the boundary) is walked twice from the start face, and
/// must list that face, like every other, once. Every dart of `kuhn_cube(2)` (boundary and inner
/// vertices) and of the double cones' ring vertices, whose fans reach past the short list.
#[test]
fn fans_at_boundary_vertices_list_each_face_once() {
    let (points, tets) = kuhn_cube(2);
    let cube = GMap::<3>::from_tets(points.len(), &tets).unwrap().0;
    let mut open = 0;
    for map in [cube, double_cone(5), double_cone(200)] {
        for d in map.darts() {
            let fan = fan_darts(&map, d);
            let faces: BTreeSet<u32> = fan.iter().map(|&e| map.cell_id(2, e).0).collect();
            assert_eq!(faces.len(), fan.len(), "dart {d:?}: a face listed twice");
            assert!(fan.iter().all(|&e| map.vertex_id(e) == map.vertex_id(d)));
            assert_eq!(fan[0], d);
            open += usize::from(fan.iter().any(|&e| map.is_free(3, map.alpha::<2>(e))));
        }
    }
    assert!(open > 100, "only {open} open fans");
}

// ---------------------------------------------------------------------------------------------
// Finding 315: a vertex id held across operations silently named another vertex once a later
// operation reused it. `CellHandle` tells the two apart.

use std::collections::HashMap;

use proptest::prelude::*;
use topomech::cut::remove_volume;
use topomech::gmap::{CellHandle, StaleCell};
use topomech::mechanics::{Body, Material};
use topomech::{CellId, DartId};

/// The round's reproducer: removing the tets around a point one by one frees vertex ids, and a
/// later removal (which splits a pinched vertex) hands a freed id to a vertex elsewhere. A handle
/// taken before is refused from the moment its id is freed, also once the id names the other
/// vertex; a vertex whose id never died keeps resolving to it.
#[test]
fn f315_a_handle_on_a_vertex_refuses_its_id_once_reused_elsewhere() {
    let liver = topomech::load::load_builtin().unwrap();
    let (points, tets) = (&liver.mesh.points, &liver.mesh.tets);
    let (mut body, _) = Body::from_tets(points, tets, Material::default()).unwrap();
    let handles: Vec<CellHandle> =
        (0..points.len() as u32).map(|v| body.map().cell_handle(0, CellId(v)).unwrap()).collect();
    let centre = [-2.2, 3.2, 0.6];
    let near = |t: &[u32; 4]| {
        let c: Vec<f64> = (0..3).map(|k| t.iter().map(|&v| points[v as usize][k]).sum::<f64>() / 4.0).collect();
        (0..3).map(|k| (c[k] - centre[k]).powi(2)).sum::<f64>() < 1.0
    };
    let mut dead = vec![false; points.len()];
    let (mut reused, mut removed) = (0, 0);
    for (t, _) in tets.iter().enumerate().filter(|(_, t)| near(t)) {
        remove_volume(&mut body, CellId(t as u32)).unwrap();
        removed += 1;
        let map = body.map();
        for (v, &h) in handles.iter().enumerate() {
            let id = CellId(v as u32);
            let live = map.is_live_cell(0, id);
            dead[v] |= !live;
            match map.resolve(h) {
                Ok(x) => assert!(x == id && live && !dead[v], "vertex {v}: resolved after its id died"),
                Err(StaleCell::Released { .. }) => assert!(!live, "vertex {v}: live but reported free"),
                Err(StaleCell::Reused { then, now, .. }) => {
                    assert!(live && dead[v] && now > then, "vertex {v}: reused {then} → {now}");
                    reused += 1;
                }
                Err(e) => panic!("vertex {v}: {e}"),
            }
        }
    }
    assert!(removed > 10 && reused > 0, "{removed} removals, {reused} reused ids seen");
    // Ids of vertices far from the removals still resolve.
    assert!(handles.iter().filter(|h| body.map().resolve(**h).is_ok()).count() > 400);
}

/// The law of `resolve` against an oracle built from the operations' own reports: on
/// `kuhn_cube(2)`, random α3 unsews and re-sews of original partners; a merge's `absorbed` id is
/// released (the only releases of sew and unsew). A handle resolves exactly when its id is live
/// and was not released since it was taken; otherwise the error says which.
fn check_handles(ops: &[(bool, u16)], takes: &[(u8, u16)]) -> [usize; 3] {
    let mut seen = [0; 3];
    let (points, tets) = kuhn_cube(2);
    let mut map = GMap::<3>::from_tets(points.len(), &tets).unwrap().0;
    let partner: Vec<DartId> = (0..map.cell_id_bound(3) as u32 * 24).map(|d| map.alpha::<3>(DartId(d))).collect();
    let mut released: HashMap<(usize, u32), u32> = HashMap::new();
    let mut held: Vec<(CellHandle, u32)> = Vec::new();
    for (k, &(sew, pick)) in ops.iter().enumerate() {
        let changes = if sew {
            let free: Vec<DartId> = map
                .darts()
                .filter(|&d| map.is_free(3, d) && partner[d.index()] != d && map.is_free(3, partner[d.index()]))
                .collect();
            match free.get(pick as usize % free.len().max(1)) {
                Some(&d) => map.sew::<3>(d, partner[d.index()]).ok(),
                None => None,
            }
        } else {
            let sewn: Vec<DartId> = map.darts().filter(|&d| !map.is_free(3, d)).collect();
            sewn.get(pick as usize % sewn.len().max(1)).map(|&d| map.unsew::<3>(d).unwrap())
        };
        for dim in 0..=3 {
            for (_, absorbed) in changes.iter().flat_map(|c| c.merges(dim)) {
                *released.entry((dim, absorbed.0)).or_default() += 1;
            }
        }
        let (dim, raw) = takes[k % takes.len()];
        let dim = dim as usize % 4;
        let id = CellId(raw as u32 % map.cell_id_bound(dim) as u32);
        if let Ok(h) = map.cell_handle(dim, id) {
            held.push((h, released.get(&(dim, id.0)).copied().unwrap_or(0)));
        }
        for &(h, at) in &held {
            let (dim, id) = (h.dim(), h.id());
            let now = released.get(&(dim, id.0)).copied().unwrap_or(0);
            let expected = if !map.is_live_cell(dim, id) {
                Err(StaleCell::Released { dim, id })
            } else if now != at {
                // The generation now is the one a fresh handle reads; it differs from the
                // handle's because a release happened since (finding 332: stamps, not counts).
                let fresh = map.cell_handle(dim, id).unwrap().generation();
                assert_ne!(fresh, h.generation(), "after op {k}: released since but same generation");
                Err(StaleCell::Reused { dim, id, then: h.generation(), now: fresh })
            } else {
                Ok(id)
            };
            assert_eq!(map.resolve(h), expected, "after op {k}");
            seen[match expected {
                Ok(_) => 0,
                Err(StaleCell::Released { .. }) => 1,
                Err(_) => 2,
            }] += 1;
        }
    }
    seen
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
    #[test]
    fn a_handle_resolves_exactly_while_its_id_is_unreleased(
        ops in prop::collection::vec((any::<bool>(), any::<u16>()), 1..40),
        takes in prop::collection::vec((any::<u8>(), any::<u16>()), 1..8),
    ) {
        check_handles(&ops, &takes);
    }
}

/// The same law on a fixed long sequence, so that reuse (a merge's released id given to a later
/// split) certainly occurs: an unsew, a sew back, an unsew again of one face, then others.
#[test]
fn handles_see_a_released_id_given_to_a_later_split() {
    let ops: Vec<(bool, u16)> = (0..60).map(|k| (k % 3 == 1, (k * 7919 % 65_521) as u16)).collect();
    let takes: Vec<(u8, u16)> = (0..60).map(|k| ((k % 4) as u8, (k * 104_729 % 65_521) as u16)).collect();
    let [resolved, released, reused] = check_handles(&ops, &takes);
    assert!(resolved > 0 && released > 0 && reused > 0, "{resolved} / {released} / {reused}");
}

/// docs/CUTTING.md's "Holding ids across cuts" example, as written there.
#[test]
fn the_cutting_docs_handle_example_runs() {
    let (points, tets) = kuhn_cube(2);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let grasp = body.map().cell_handle(0, CellId(13)).unwrap(); // the centre vertex
    remove_volume(&mut body, CellId(0)).unwrap();
    let v = body.map().resolve(grasp).unwrap(); // still the same vertex (or StaleCell: gone)
    assert_eq!(v, CellId(13));
    let text = std::fs::read_to_string(root().join("docs/CUTTING.md")).unwrap();
    assert!(text.contains("let grasp = body.map().cell_handle(0, CellId(13)).unwrap();"));
}

/// Finding 333: the 2D bulk path reports a face that is not a triangle as `NotATetrahedron`
/// (its volumes are faces), so the refusal check expects N + 1 corners: a 2D refusal naming 3
/// corners (a proper triangle refused) is a false refusal, one naming 2 is not.
#[test]
fn f333_a_2d_refusal_of_a_proper_triangle_is_flagged() {
    use topomech::generate::grid_triangles;
    use topomech::subdivide::fuzz::check_refused;
    use topomech::subdivide::{LeveledMap, SubdivideError};
    let (points, triangles) = grid_triangles(2);
    let map = GMap::<2>::from_triangles(points.len(), &triangles).unwrap().0;
    let m = LeveledMap::new(map, points);
    let dart = m.map().darts().next().unwrap();
    let refusal = |corners| SubdivideError::NotATetrahedron { dart, corners };
    assert!(check_refused(&m, &m, &refusal(3)).is_err());
    assert!(check_refused(&m, &m, &refusal(2)).is_ok());
}

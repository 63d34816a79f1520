//! API probe round 20, conforming closure of a cut leveled map (finding 171 of
//! `docs/VERIFICATION.md`): every `f171_*` test but the separating-cut one states a law the code
//! before the round broke.
//!
//! - 171: `LeveledMap::<3>::conforming_tets` returned `Ok` on a leveled map with cut (α3-free)
//!   faces whose vertices the cut had not split. Its output is a tet list keyed by vertex ids, and
//!   `GMap::from_tets` glues two tets exactly where they share three vertex ids: the two sides of
//!   such a cut came out as the same triangle and the rebuilt mesh was glued again
//!   (`kuhn_cube(2)` with one face cut: 50 boundary faces and [27, 99, 121, 48] in the leveled
//!   map, 48 and [27, 98, 120, 48] after `from_tets` on its closure). The closure now refuses it
//!   (`SubdivideError::CutNotExpressible`, naming the cut face side, the other side and the
//!   triangle) and expresses every other map exactly (same χ, components, orientability,
//!   vertices + Steiner points, boundary faces = Σ (k − 2) over `boundary_polygons()`).

use topomech::cut::ops::jittered_cube;
use topomech::generate::{kuhn_cube, SplitMix64};
use topomech::subdivide::{LeveledMap, SubdivideError, TetMasses};
use topomech::{AlphaMask, DartId, GMap};

/// The vertex ids of the face side of `d` (its ⟨α0, α1⟩ orbit), increasing, without repeats.
fn face_vertices(m: &LeveledMap<3>, d: DartId) -> Vec<u32> {
    let mut v: Vec<u32> = m.map().orbit(d, AlphaMask::of(&[0, 1])).iter().map(|&x| m.map().vertex_id(x).0).collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Every live dart with its four α images and its vertex id (to see that nothing changed).
fn rows(map: &GMap<3>) -> Vec<(DartId, [DartId; 4], u32)> {
    map.darts().map(|d| (d, [0, 1, 2, 3].map(|i| map.alpha_dyn(i, d)), map.vertex_id(d).0)).collect()
}

/// One dart of every face cell glued on both sides (α3-sewn).
fn glued_faces(map: &GMap<3>) -> Vec<DartId> {
    map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d)).collect()
}

/// Glued faces of the finest map whose vertices all lie within 0.12 of the plane x[axis] = at
/// (on a cube jittered by at most 0.1, refined at most twice: other vertices are ≥ 0.15 away).
fn plane_faces(m: &LeveledMap<3>, axis: usize, at: f64) -> Vec<DartId> {
    let on = |x: DartId| (m.points()[m.map().vertex_id(x).index()][axis] - at).abs() < 0.12;
    glued_faces(m.map()).into_iter().filter(|&f| m.map().orbit(f, AlphaMask::of(&[0, 1])).into_iter().all(on)).collect()
}

/// A leveled map of `map` (cut by `unsew_dyn` from the map of `tets`) with each vertex at the
/// position of the point its darts had before the cut.
fn leveled_after_cut(map: GMap<3>, points: &[[f64; 3]], tets: &[[u32; 4]]) -> LeveledMap<3> {
    let (orig, _) = GMap::<3>::from_tets(points.len(), tets).unwrap();
    let mut vp = vec![[0.0; 3]; map.cell_id_bound(0)];
    for d in map.darts() {
        vp[map.vertex_id(d).index()] = points[orig.vertex_id(d).index()];
    }
    LeveledMap::new(map, vp)
}

/// The law of finding 171: the closure either refuses with `CutNotExpressible` — naming an
/// α3-free face side and another side whose vertex ids both contain the triangle, and changing
/// nothing — or `GMap::from_tets` on it has the topology of the finest map: same χ, components
/// and orientability, one vertex per map vertex plus one per Steiner point, no pinched vertex,
/// boundary faces = Σ (k − 2) over `boundary_polygons()`, and exactly the same cell counts when
/// no volume was closed. Returns whether the closure was accepted.
fn closure_refuses_or_keeps_topology(m: &LeveledMap<3>, what: &str) -> bool {
    let (map, points) = (m.map().clone(), m.points().to_vec());
    let counts = map.count_cells().0;
    let polygons = m.boundary_polygons().unwrap();
    let triangles: usize = polygons.iter().map(|p| p.len() - 2).sum();
    match m.conforming_tets() {
        Err(SubdivideError::CutNotExpressible { dart, other, triangle }) => {
            assert!(map.contains(dart) && map.is_free(3, dart), "{what}: {dart} is not a cut face side");
            assert!(map.contains(other), "{what}: {other}");
            assert!(!map.orbit(dart, AlphaMask::of(&[0, 1])).contains(&other), "{what}: two sides");
            assert!(triangle[0] < triangle[1] && triangle[1] < triangle[2], "{what}: {triangle:?}");
            for side in [dart, other] {
                let v = face_vertices(m, side);
                assert!(triangle.iter().all(|t| v.contains(t)), "{what}: {triangle:?} ⊄ {v:?} of {side}");
            }
            assert!(rows(&map) == rows(m.map()) && points == m.points(), "{what}: the refusal changed the map");
            false
        }
        Err(e) => panic!("{what}: unexpected error {e}"),
        Ok(c) => {
            let (g, report) = GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap();
            let got = g.count_cells().0;
            assert_eq!(g.euler_characteristic(), map.euler_characteristic(), "{what}: χ");
            assert_eq!(g.components().len(), map.components().len(), "{what}: components");
            assert_eq!(g.is_orientable(), map.is_orientable(), "{what}: orientability");
            assert_eq!(g.boundary_cell_count(), triangles, "{what}: boundary faces ≠ Σ (k − 2)");
            assert!(report.pinched_vertices.is_empty(), "{what}: pinched {:?}", report.pinched_vertices);
            assert_eq!(got[0], counts[0] + c.closed, "{what}: vertices + Steiner points");
            assert_eq!(got[3], c.tets.len(), "{what}: tets");
            if c.closed == 0 {
                assert_eq!(got, counts, "{what}: cell counts of a closure without closed volumes");
            }
            true
        }
    }
}

/// Finding 171, the probe's reproducer: one glued face of `kuhn_cube(2)` cut at level 1 (none of
/// its vertices is on the boundary, so the cut splits none of them). The closure used to return
/// 48 tets whose rebuilt mesh had the face glued again (48 boundary faces, [27, 98, 120, 48]).
#[test]
fn f171_closure_refuses_a_cut_face_whose_vertices_stay_joined() {
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let f = glued_faces(m.map())[0];
    let triangle = face_vertices(&m, f);
    m.unsew_face(f, 1).unwrap();
    assert_eq!(m.map().boundary_cell_count(), 50);
    assert_eq!(m.map().count_cells().0, vec![27, 99, 121, 48]);
    let before = rows(m.map());
    let e = m.conforming_tets().unwrap_err();
    let SubdivideError::CutNotExpressible { dart, other, triangle: t } = e.clone() else { panic!("{e}") };
    assert_eq!(t.to_vec(), triangle, "the cut face's three vertex ids");
    assert!(m.map().is_free(3, dart) && m.map().is_free(3, other), "both sides of the cut");
    assert_eq!(face_vertices(&m, dart), triangle);
    assert_eq!(face_vertices(&m, other), triangle);
    assert!(rows(m.map()) == before, "nothing changed");
    let msg = e.to_string();
    assert!(msg.contains("cannot express the cut face") && msg.contains(&format!("{dart}")), "{msg}");
    assert!(!closure_refuses_or_keeps_topology(&m, "reproducer"));
}

/// Finding 171, the same cut on a map built from a cut body (`LeveledMap::new` on the map after
/// `unsew_dyn`, as the demo does), refined around the cut first: still refused, while the uncut
/// map refined the same way closes as before.
#[test]
fn f171_closure_refuses_the_cut_after_refinement_and_keeps_the_uncut_closure() {
    let (points, tets) = kuhn_cube(2);
    let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let uncut = LeveledMap::new(map.clone(), points.clone());
    let f = glued_faces(&map)[0];
    map.unsew_dyn(3, f).unwrap();
    for (mut m, cut) in [(uncut, false), (leveled_after_cut(map, &points, &tets), true)] {
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        m.refine_around([0.5, 0.5, 0.5], 0.3, 2, &mut masses).unwrap();
        assert!(m.max_level() == 2);
        let accepted = closure_refuses_or_keeps_topology(&m, if cut { "cut" } else { "uncut" });
        assert_eq!(accepted, !cut);
    }
}

/// Finding 171, what must keep working: a cut through the whole cube (every glued face of the
/// plane x = 1 of `kuhn_cube(2)`) splits every vertex of the plane, so the two sides have
/// distinct vertex ids and the closure expresses it exactly: two components, the cut faces on
/// the boundary — also after a refinement around the cut.
#[test]
fn f171_a_separating_cut_is_expressed_exactly() {
    let (points, tets) = kuhn_cube(2);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    let mut m = LeveledMap::new(map, points);
    let plane = plane_faces(&m, 0, 1.0);
    assert_eq!(plane.len(), 8, "2 × 2 unit squares, 2 triangles each");
    for f in plane {
        m.unsew_face(f, 0).unwrap();
    }
    assert_eq!(m.map().components().len(), 2);
    assert!(closure_refuses_or_keeps_topology(&m, "plane cut"));
    let (g, _) = {
        let c = m.conforming_tets().unwrap();
        GMap::<3>::from_tets(c.points.len(), &c.tets).unwrap()
    };
    assert_eq!((g.boundary_cell_count(), g.components().len()), (48 + 16, 2));
    let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
    m.refine_around([1.0, 1.0, 1.0], 0.2, 2, &mut masses).unwrap();
    assert!(m.conforming_tets().unwrap().closed > 0);
    assert!(closure_refuses_or_keeps_topology(&m, "plane cut, refined"));
}

/// Finding 171, the law on random cut sets of a jittered `kuhn_cube(3)`: random glued faces, a
/// whole plane, or a random part of a plane (a slit, whose rim vertices stay joined), cut on the
/// map before `LeveledMap::new` (then refined 0–2 levels around a random ball) or by
/// `LeveledMap::unsew_face` on the finest map after the refinement. The closure either refuses
/// or keeps the topology ([`closure_refuses_or_keeps_topology`]); both happen. The probe found
/// the topology changed on every one of 40 random sets.
#[test]
fn f171_law_random_cut_sets_closure_refuses_or_keeps_the_topology() {
    let (mut accepted_cut, mut refused) = (0, 0);
    for seed in 0..48u64 {
        let mut rng = SplitMix64(seed);
        let (points, tets) = jittered_cube(3, seed);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let mode = seed % 4;
        let (axis, at) = (rng.below(3), 1.0 + rng.below(2) as f64);
        let mut cut = 0;
        if mode < 3 {
            let probe = LeveledMap::new(map.clone(), points.clone());
            let faces = match mode {
                0 => {
                    let glued = glued_faces(&map);
                    (0..5 + rng.below(26)).map(|_| glued[rng.below(glued.len())]).collect()
                }
                1 => plane_faces(&probe, axis, at),
                _ => plane_faces(&probe, axis, at).into_iter().filter(|_| rng.below(2) == 0).collect::<Vec<_>>(),
            };
            for f in faces {
                if !map.is_free(3, f) {
                    map.unsew_dyn(3, f).unwrap();
                    cut += 1;
                }
            }
        }
        let mut m = leveled_after_cut(map, &points, &tets);
        let levels = rng.below(3) as u8;
        if levels > 0 {
            let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
            let c = [0, 1, 2].map(|_| rng.below(300) as f64 / 100.0);
            m.refine_around(c, 0.2 + rng.below(50) as f64 / 100.0, levels, &mut masses).unwrap();
        }
        if mode == 3 {
            let level = m.max_level();
            let mut faces = plane_faces(&m, axis, at);
            faces.retain(|_| rng.below(4) != 0);
            let glued = glued_faces(m.map());
            faces.extend((0..rng.below(3)).map(|_| glued[rng.below(glued.len())]));
            for f in faces {
                if !m.map().is_free(3, f) {
                    m.unsew_face(f, level).unwrap();
                    cut += 1;
                }
            }
        }
        let what = format!("seed {seed}, mode {mode}, {cut} cut faces, {levels} levels");
        if closure_refuses_or_keeps_topology(&m, &what) {
            accepted_cut += usize::from(cut > 0);
        } else {
            refused += 1;
        }
    }
    assert!(accepted_cut >= 8 && refused >= 12, "accepted with a cut {accepted_cut}, refused {refused}");
}

//! The flat flag of a leveled map is a law, not free data: a dart of level L is flat iff
//! L ≥ 1, its α1 partner e has level L, neither α1 link has changed since (no α1 history entry on
//! d or e), and α0^{L−1}(α0^L(d)) = α0^L(e) with both darts in B_{L−1} (its vertex was inserted on
//! one edge at level L and no face split has made it a corner since).
//!
//! A stored map (`.tmap` / `.tmapb`, or plain `LevelParts`) with one flipped flag used to be
//! accepted by `LeveledMap::from_parts`, `Document::into_leveled` and `check_all_laws`, and a
//! later subdivision then panicked ("checked: every face is a triangle") or gave wrong errors.
//! Since the flag is fully determined, flipping it at *any* dart must be refused with
//! `LevelError::FlatFlag` naming that dart: every dart of every map below is tried.

use topomech::generate::{grid_triangles, kuhn_cube};
use topomech::store::{self, Document, Finding, Format, StoreError};
use topomech::subdivide::{LevelError, LevelPartsError, LeveledMap, TetMasses};
use topomech::{DartId, GMap};

fn cube(k: usize) -> LeveledMap<3> {
    let (points, tets) = kuhn_cube(k);
    let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    LeveledMap::new(map, points)
}

fn one_tet() -> LeveledMap<3> {
    let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    LeveledMap::new(map, pts)
}

fn grid(n: usize) -> LeveledMap<2> {
    let (points, tris) = grid_triangles(n);
    let (map, _) = GMap::<2>::from_triangles(points.len(), &tris).unwrap();
    LeveledMap::new(map, points)
}

/// The leveled map's law check passes, the round trip is exact, and flipping the flag of each
/// live dart alone is refused by `from_parts` with `FlatFlag` naming that dart and the stored
/// (wrong) flag. Returns how many darts are flat (so callers can show the case is covered).
fn every_flip_is_refused<const N: usize>(m: &LeveledMap<N>) -> usize {
    m.check_all().expect("a map made by the operations keeps every law");
    let parts = m.to_parts();
    let back = LeveledMap::from_parts(m.map().clone(), parts.clone()).expect("the true flags are accepted");
    assert_eq!(back.to_parts(), parts);
    let mut flats = 0;
    for d in m.map().darts() {
        let mut bad = parts.clone();
        let flipped = !bad.darts[d.index()].flat;
        flats += usize::from(!flipped);
        bad.darts[d.index()].flat = flipped;
        let e = LeveledMap::from_parts(m.map().clone(), bad).expect_err("a flipped flat flag is refused");
        assert_eq!(e, LevelPartsError::Law(LevelError::FlatFlag { dart: d, flat: flipped }), "flip at {d}");
        assert!(e.to_string().contains(&d.to_string()), "the message names the dart: {e}");
    }
    flats
}

#[test]
fn the_reported_reproducer_is_refused_instead_of_panicking_later() {
    let mut l = cube(1);
    l.subdivide_tet(DartId(0), 1).unwrap();
    let mut parts = l.to_parts();
    parts.darts[2].flat ^= true;
    let flat = parts.darts[2].flat;
    let e = LeveledMap::from_parts(l.map().clone(), parts).unwrap_err();
    assert_eq!(e, LevelPartsError::Law(LevelError::FlatFlag { dart: DartId(2), flat }));
}

#[test]
fn kuhn_cube_with_one_tet_subdivided_refuses_every_flipped_flag() {
    let mut l = cube(1);
    l.subdivide_tet(DartId(0), 1).unwrap();
    // The neighbours of the split tet carry the inserted vertices of its faces' sides.
    assert!(every_flip_is_refused(&l) > 0);
}

#[test]
fn a_level_2_refinement_refuses_every_flipped_flag() {
    let mut l = cube(1);
    let children = l.subdivide_tet(DartId(0), 1).unwrap();
    l.subdivide_tet(children[0], 2).unwrap();
    // Level-1 inserted vertices made corners at level 2, next to level-2 inserted vertices.
    let flats = every_flip_is_refused(&l);
    assert!(flats > 0);
    let parts = l.to_parts();
    assert!(parts.darts.iter().any(|r| r.flat && r.level == 2), "level-2 inserted vertices exist");
    assert!(parts.darts.iter().any(|r| r.flat && r.level == 1), "level-1 inserted vertices remain");

    // Refinement by region (op by op), two levels around a corner of the cube.
    let mut r = cube(1);
    let mut masses = TetMasses::from_density(&r, 1.0).unwrap();
    r.refine_around([0.0; 3], 0.3, 2, &mut masses).unwrap();
    assert_eq!(r.max_level(), 2);
    assert!(every_flip_is_refused(&r) > 0);
}

#[test]
fn a_one_tet_map_refuses_every_flipped_flag_before_and_after_splits() {
    // No dart of an unsubdivided map is flat: a flag set on any of them used to give
    // NotATriangle / FaceRefinedTooFar on a plain tetrahedron.
    let mut l = one_tet();
    assert_eq!(every_flip_is_refused(&l), 0);
    let d = l.map().darts().next().unwrap();
    l.split_edge(d, 1).unwrap();
    assert!(every_flip_is_refused(&l) > 0);
    l.subdivide_tet(d, 2).unwrap();
    every_flip_is_refused(&l);
    // Uniform refinement makes no flat dart at all.
    let mut u = one_tet();
    u.refine_uniform(1, &mut TetMasses::from_density(&u, 1.0).unwrap()).unwrap();
    assert_eq!(every_flip_is_refused(&u), 0);
}

#[test]
fn a_face_split_at_the_level_of_an_inserted_vertex_keeps_it_flat_and_checked() {
    // 2D: triangle A split at level 1 inserts a vertex on the side it shares with B; a child of A
    // split at level 2 inserts a level-2 vertex on B's half side; B split at level 2 uses the
    // level-1 vertex as its midpoint, so one of B's children is a triangle of level 2 with a
    // level-2 inserted vertex on a side (flat although its level equals μf).
    let mut g = grid(1);
    let darts: Vec<DartId> = g.map().darts().collect();
    let a = darts[0];
    let b = darts.iter().copied().find(|&x| !g.map().same_orbit(x, a, topomech::gmap::AlphaMask::of(&[0, 1]))).unwrap();
    let kids = g.subdivide_triangle(a, 1).unwrap();
    for k in kids {
        if g.mu(k).face < 2 {
            g.subdivide_triangle(k, 2).unwrap();
        }
    }
    g.subdivide_triangle(b, 2).unwrap();
    let flats = every_flip_is_refused(&g);
    assert!(flats > 0);
    let parts = g.to_parts();
    assert!(parts.darts.iter().any(|r| r.flat && r.level == r.mu.face), "a flat vertex at its face's level");
}

#[test]
fn a_cut_leveled_map_refuses_every_flipped_flag() {
    let mut l = cube(1);
    l.subdivide_tet(DartId(0), 1).unwrap();
    let glued = l.map().darts().find(|&d| !l.map().is_free(3, d) && l.to_parts().darts[d.index()].flat).unwrap();
    l.unsew_face(glued, 2).unwrap();
    assert!(every_flip_is_refused(&l) > 0);
}

#[test]
fn a_flipped_flag_in_a_text_file_is_refused_and_reported_by_check_all_laws() {
    let mut l = cube(1);
    l.subdivide_tet(DartId(0), 1).unwrap();
    let doc = Document::from_leveled(&l);
    let text = String::from_utf8(store::encode(&doc, Format::Text).unwrap()).unwrap();
    // `l D LEVEL MUA MUF MUT FLAT H ...`: flip the FLAT field of dart 2.
    let mut edited = Vec::new();
    let mut hit = false;
    for line in text.lines() {
        let mut t: Vec<String> = line.split(' ').map(str::to_string).collect();
        if t.len() >= 8 && t[0] == "l" && t[1] == "2" {
            t[6] = if t[6] == "0" { "1".into() } else { "0".into() };
            hit = true;
        }
        edited.push(t.join(" "));
    }
    assert!(hit, "the file has a level line for dart 2");
    let bytes = (edited.join("\n") + "\n").into_bytes();
    let flat = !l.to_parts().darts[2].flat;

    let bad = store::decode(&bytes).expect("the file is well formed");
    let report = store::check_all_laws(&bad, usize::MAX);
    assert!(!report.valid, "check_all_laws reports the broken flat law");
    let named = |f: &Finding| matches!(f, Finding::Level(LevelPartsError::Law(LevelError::FlatFlag { dart, .. })) if dart.0 == 2);
    assert!(report.findings.iter().any(named), "{:?}", report.findings);
    assert_eq!(report.findings.len(), 1, "exactly one law is broken: {:?}", report.findings);

    let e = bad.into_leveled::<3>().unwrap_err();
    assert!(
        matches!(e, StoreError::Levels(LevelPartsError::Law(LevelError::FlatFlag { dart: DartId(2), flat: f })) if f == flat)
    );

    // The unedited file loads and keeps every law.
    let good = store::decode(text.as_bytes()).unwrap();
    assert!(store::check_all_laws(&good, usize::MAX).valid);
    good.into_leveled::<3>().unwrap();
}

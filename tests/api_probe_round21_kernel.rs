//! API probe round 21 (b), kernel and ambiguity study (findings B1–B6 of the round-21 probe):
//! `CombinatorialMap::is_valid` on rows of the wrong length, the single-end-incidence convention
//! of the 1-skeleton and the dual graph for folded cells, the OBJ writer's contract against the
//! mesh reader, `DartsJson::to_map` on links that break the quasi-manifold law,
//! `IndexedModel::audit` / `campaign::sub_complex` on out-of-range indices, and `Gluing::word`
//! on a side past the end and past 26 pairs.

use std::collections::BTreeMap;
use std::path::Path;

use topomech::ambiguity::campaign::sub_complex;
use topomech::ambiguity::catalogue::{catalogue, origin_text, Bounds};
use topomech::ambiguity::construct::{CutComplex, FaceGluing, Gluing};
use topomech::ambiguity::darts::{DartsError, DartsJson};
use topomech::ambiguity::finder::{complexes, Origin};
use topomech::ambiguity::indexed::{AuditError, IndexedError, IndexedModel};
use topomech::ambiguity::vector::VectorError;
use topomech::cut::dissociate_face;
use topomech::generate::kuhn_cube;
use topomech::gmap::CombinatorialMap;
use topomech::graph::{dual_graph, incidences, vertex_edge_graph};
use topomech::io::{parse_obj, ReadError};
use topomech::mechanics::{Body, Material};
use topomech::surface::{boundary_surface, boundary_surface_of_tets, SurfaceError};
use topomech::{AlphaMask, DartId, GMap};

/// `f()`, or `None` if it panicked.
fn no_panic<T>(f: impl FnOnce() -> T) -> Option<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok()
}

// ---------------------------------------------------------------------------------------------
// B1: `CombinatorialMap::is_valid` with rows of the wrong length.

fn cmap(beta1: Vec<u32>, beta: Vec<Vec<Option<u32>>>) -> CombinatorialMap {
    CombinatorialMap { origin: vec![DartId(0), DartId(1)], beta1, beta }
}

/// A β1 with fewer or more entries than darts is no permutation of the darts (the short one was
/// accepted: only injectivity was checked).
#[test]
fn b1_a_beta1_of_the_wrong_length_is_invalid() {
    assert!(cmap(vec![1, 0], vec![]).is_valid()); // the well-formed map
    assert!(!cmap(vec![0], vec![]).is_valid()); // short
    assert!(!cmap(vec![1, 0, 2], vec![]).is_valid()); // long, naming a third dart
}

/// A βi row with an entry past the darts let βi name a dart that does not exist (accepted), and a
/// short row panicked: both are invalid now, without a panic.
#[test]
fn b1_a_beta_row_of_the_wrong_length_is_invalid_without_panicking() {
    assert!(cmap(vec![1, 0], vec![vec![Some(1), Some(0)]]).is_valid()); // the well-formed map
    assert!(!cmap(vec![1, 0], vec![vec![Some(2), None, Some(0)]]).is_valid()); // long: β2(0) = 2
    assert!(!cmap(vec![1, 0], vec![vec![None, None, None]]).is_valid()); // long, all undefined
    assert_eq!(no_panic(|| cmap(vec![1, 0], vec![vec![None]]).is_valid()), Some(false));
    assert_eq!(no_panic(|| cmap(vec![1, 0], vec![vec![None, None], vec![]]).is_valid()), Some(false));
}

// ---------------------------------------------------------------------------------------------
// B2: a cell folded onto itself has one end incidence; a loop has two.

/// The number of ⟨α2, …, αn⟩ orbits (vertex incidences) of the edge of `d`, and whether the edge
/// is folded (α0(d) in the ⟨α2, …, αn⟩ orbit of d).
fn edge_ends<const N: usize>(m: &GMap<N>, d: DartId) -> (usize, bool) {
    let high: Vec<usize> = (2..=N).collect();
    let ends = AlphaMask::of(&high);
    let edge = m.orbit(d, AlphaMask::of(&[&[0][..], &high[..]].concat()));
    let mut seen: Vec<Vec<DartId>> = Vec::new();
    for &e in &edge {
        let mut o = m.orbit(e, ends);
        o.sort_unstable();
        if !seen.contains(&o) {
            seen.push(o);
        }
    }
    let folded = m.orbit(d, ends).contains(&m.alpha::<0>(d));
    (seen.len(), folded)
}

/// The 1-skeleton's total weight and its loops' total weight.
fn skeleton_weights<const N: usize>(m: &GMap<N>) -> (u32, u32) {
    let g = vertex_edge_graph(m);
    let total = g.edge_indices().map(|e| g[e]).sum();
    let loops = g
        .edge_indices()
        .filter(|&e| {
            let (a, b) = g.edge_endpoints(e).unwrap();
            a == b
        })
        .map(|e| g[e])
        .sum();
    (total, loops)
}

/// Reproducer 2a: one tet with face 2 glued onto face 3 (way 1) folds their shared edge onto
/// itself: it is α0-sewn, has one vertex incidence, and adds nothing to the 1-skeleton, as the
/// documented convention says (like a dangling half-edge). The other three edges count.
#[test]
fn b2_a_folded_edge_has_one_end_and_adds_nothing_to_the_skeleton() {
    let m = FaceGluing { tets: 1, pairs: vec![[2, 3, 1]] }.build().unwrap();
    m.validate().unwrap();
    assert!(m.darts().all(|d| !m.is_free(0, d))); // no dangling half-edge at all
    let edges = m.one_dart_per_cell(1);
    assert_eq!(edges.len(), 4);
    let ends: Vec<(usize, bool)> = edges.iter().map(|&d| edge_ends(&m, d)).collect();
    assert_eq!(ends.iter().filter(|e| **e == (1, true)).count(), 1, "{ends:?}");
    assert_eq!(ends.iter().filter(|e| **e == (2, false)).count(), 3, "{ends:?}");
    let folded = edges[ends.iter().position(|e| e.1).unwrap()];
    // The incidence graph keeps the folded edge, with multiplicity 1 at its vertex.
    let inc = incidences(&m, 0);
    let id = m.cell_id(1, folded).0;
    let at: Vec<u32> = inc.iter().filter(|((_, e), _)| *e == id).map(|(_, &k)| k).collect();
    assert_eq!(at, vec![1]);
    // One unit of weight per edge with two ends: 3, one of them a loop (two distinct ends at v3).
    assert_eq!(skeleton_weights(&m), (3, 1));
}

/// Reproducer 2b: a lone tet with one face α3-sewn to itself by its own reflection. The face is
/// not on the boundary, but it has one side (one ⟨α0, α1⟩ orbit): no loop in the dual graph.
#[test]
fn b2_a_face_folded_onto_itself_adds_nothing_to_the_dual_graph() {
    let (mut m, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    let d = DartId(0);
    let e = m.orbit(d, AlphaMask::of(&[0, 1])).into_iter().find(|&e| e != d && m.is_sewable::<3>(d, e)).unwrap();
    m.sew::<3>(d, e).unwrap();
    m.validate().unwrap();
    assert!(m.orbit(d, AlphaMask::of(&[0, 1])).contains(&m.alpha::<3>(d))); // folded
    let sewn: Vec<DartId> = m.one_dart_per_cell(2).into_iter().filter(|&f| !m.is_free(3, f)).collect();
    assert_eq!(sewn.len(), 1);
    assert_eq!(dual_graph(&m).edge_count(), 0);
    let face = m.cell_id(2, sewn[0]).0;
    let at: Vec<u32> = incidences(&m, 2).iter().filter(|((f, _), _)| *f == face).map(|(_, &k)| k).collect();
    assert_eq!(at, vec![1]); // one side
}

/// A genuine loop counts: an edge with two distinct end incidences at one vertex. In 2D the side
/// of a 1-gon (its two ends are the one corner, through α1); in 3D one tet with faces 2 and 3
/// glued the ways that do not fold their shared edge, where an edge gets both its ends at one
/// vertex by two different sews.
#[test]
fn b2_a_loop_with_two_distinct_ends_counts() {
    let monogon = Gluing { sides: vec![1], pairs: vec![] }.build().unwrap();
    let d = monogon.darts().next().unwrap();
    assert_eq!(edge_ends(&monogon, d), (2, false));
    assert_eq!(monogon.count_cells().0[0], 1); // one vertex
    assert_eq!(skeleton_weights(&monogon), (1, 1));
    let inc = incidences(&monogon, 0);
    assert_eq!(inc.values().copied().collect::<Vec<_>>(), vec![2]); // the vertex twice in ∂edge

    // 3D: every folded edge is dropped, every other edge (loops included) counts once.
    let mut loops_seen = 0;
    for way in 0..6u16 {
        let m = FaceGluing { tets: 1, pairs: vec![[2, 3, way]] }.build().unwrap();
        let mut with_two_ends = 0;
        let mut loops = 0;
        for d in m.one_dart_per_cell(1) {
            let (ends, folded) = edge_ends(&m, d);
            assert_eq!(ends == 1, folded, "way {way}: every edge of this map is α0-sewn");
            if ends == 2 {
                with_two_ends += 1;
                let other = m.alpha::<0>(d);
                loops += u32::from(m.vertex_id(d) == m.vertex_id(other));
            }
        }
        assert_eq!(skeleton_weights(&m), (with_two_ends, loops), "way {way}");
        loops_seen += loops;
    }
    assert!(loops_seen > 0);
}

/// The docs' count: within the catalogue bounds, 9 of the 39 3D classes have a folded edge (the
/// 3D `vertex_edge` groups of `docs/ambiguity.md` follow the convention).
#[test]
fn b2_the_catalogue_classes_with_a_folded_edge_are_as_documented() {
    let b = Bounds::CATALOGUE;
    let finder = complexes(b.points, b.max_tets, b.glue_tets, b.glue_pairs);
    let classes = finder.classes();
    assert_eq!(classes.len(), 39);
    let folded =
        classes.iter().filter(|c| c.map.one_dart_per_cell(1).into_iter().any(|d| edge_ends(&c.map, d).1)).count();
    assert_eq!(folded, 9);
}

// ---------------------------------------------------------------------------------------------
// B3: the OBJ writer against the mesh reader.

const TET: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn tmp(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("round21-kernel-{}-{name}", std::process::id()))
}

/// A triangle with a repeated corner (the fields are public) is refused by `check`, the measures
/// and the writers, naming the triangle, and nothing is written (it was written, and the reader
/// refused it as `RepeatedVertex`).
#[test]
fn b3_a_repeated_corner_is_refused_before_writing() {
    let mut s = boundary_surface_of_tets(&TET, &[[0, 1, 2, 3]]).unwrap();
    s.triangles[2] = [1, 3, 1];
    let refused =
        |r: Result<(), SurfaceError>| matches!(r, Err(SurfaceError::RepeatedCorner { triangle: 2, vertex: 1 }));
    assert!(refused(s.check()));
    assert!(refused(s.to_obj().map(drop)));
    assert!(refused(s.area().map(drop)));
    assert!(refused(s.enclosed_volume().map(drop)));
    let path = tmp("repeated.obj");
    let _ = std::fs::remove_file(&path);
    assert!(refused(s.write_obj(&path)));
    assert!(!path.exists());
    for tri in [[0, 0, 1], [0, 1, 1]] {
        s.triangles[2] = tri;
        assert!(matches!(s.check(), Err(SurfaceError::RepeatedCorner { triangle: 2, .. })), "{tri:?}");
    }
    assert_eq!(
        SurfaceError::RepeatedCorner { triangle: 2, vertex: 1 }.to_string(),
        "triangle 2 uses vertex 1 at two corners"
    );
}

/// The documented boundary, the accepted side: a surface without coincident triangles (here a
/// cut body whose slit vertices did not split is avoided: a plain cube) reads back bit for bit.
#[test]
fn b3_a_surface_without_slits_reads_back_bit_for_bit() {
    let (p, t) = kuhn_cube(2);
    let (body, _) = Body::from_tets(&p, &t, Material::default()).unwrap();
    let s = boundary_surface(&body);
    let mesh = parse_obj(s.to_obj().unwrap().as_bytes(), Path::new("s.obj")).unwrap();
    assert_eq!(mesh.triangles, s.triangles);
    assert_eq!(mesh.points.len(), s.positions.len());
    assert!(mesh.points.iter().zip(&s.positions).all(|(a, b)| (0..3).all(|k| a[k].to_bits() == b[k].to_bits())));
}

/// The documented boundary, the refused side: a face dissociated deep inside a body whose corners
/// did not split is a slit (two coincident triangles of opposite orientation); the writer writes
/// it (the demo writes such boundaries), and `parse_obj` refuses it as a duplicate. An empty
/// surface writes a header-only file the reader refuses as empty.
#[test]
fn b3_a_slit_or_empty_surface_is_written_and_refused_by_the_reader() {
    let (p, t) = kuhn_cube(3);
    let (mut body, _) = Body::from_tets(&p, &t, Material::default()).unwrap();
    let map = body.map();
    let pos = body.attrs().position();
    let inner = |x: DartId| pos[map.vertex_id(x)].iter().all(|&c| c > 0.5 && c < 2.5);
    let d = map
        .darts()
        .find(|&d| {
            !map.is_free(3, d) && [d, map.alpha::<0>(d), map.alpha::<0>(map.alpha::<1>(d))].into_iter().all(inner)
        })
        .unwrap();
    let cut = dissociate_face(&mut body, d).unwrap();
    assert!(cut.vertices.is_empty() && cut.edges.is_empty());
    let s = boundary_surface(&body);
    let path = tmp("slit.obj");
    s.write_obj(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(parse_obj(&bytes, &path), Err(ReadError::DuplicateElement { .. })));

    let empty = boundary_surface_of_tets(&[[0.0; 3]], &[]).unwrap();
    let text = empty.to_obj().unwrap();
    assert_eq!(text.lines().count(), 1); // the header
    assert!(parse_obj(text.as_bytes(), Path::new("e.obj")).is_err());
}

// ---------------------------------------------------------------------------------------------
// B4: `DartsJson::to_map` refuses links that break the quasi-manifold law.

/// Reproducer 5: edges 0–1 and 2–3, α2 linking 0 and 2 only (α0α2(0) = 3 but α0α2(3) = 2). The
/// orbit sew also linked 1 and 3, which the data stores as 2-free; the map was returned.
#[test]
fn b4_links_that_break_the_quasi_manifold_law_are_refused() {
    let json = DartsJson { dim: 2, alpha: vec![vec![1, 0, 2], vec![0, 1, 1], vec![3, 2, 0], vec![2, 3, 3]] };
    let e = json.to_map::<2>().unwrap_err();
    assert_eq!(e, DartsError::NotQuasiManifold { dart: 1, i: 2, stored: 1, rebuilt: 3 });
    assert!(e.to_string().contains("quasi-manifold"), "{e}");
    // The valid version (1 and 3 linked too) still loads, and exactly.
    let ok = DartsJson { dim: 2, alpha: vec![vec![1, 0, 2], vec![0, 1, 3], vec![3, 2, 0], vec![2, 3, 1]] };
    assert_eq!(DartsJson::of(&ok.to_map::<2>().unwrap()), ok);
}

/// Reproducer 6: a catalogue vector whose map a has two α2-linked darts stored as 2-free is no
/// G-map; `PairVector::check` passed it (the rebuild re-created the link), and refuses it now.
#[test]
fn b4_a_tampered_catalogue_vector_fails_its_check() {
    let cat = catalogue(Bounds::SMALL);
    let linked = |rows: &Vec<Vec<u32>>| {
        (0..rows.len())
            .find(|&d| rows[d][2] as usize != d && rows[rows[d][0] as usize][2] as usize != rows[d][0] as usize)
    };
    let mut v = cat.pairs.into_iter().find(|p| p.dim == 2 && linked(&p.a.darts.alpha).is_some()).unwrap();
    v.check().unwrap();
    let rows = &mut v.a.darts.alpha;
    let d = linked(rows).unwrap();
    let x = rows[d][0] as usize; // α0(d)
    let y = rows[x][2] as usize; // α2(α0(d))
    rows[x][2] = x as u32;
    rows[y][2] = y as u32;
    assert!(matches!(v.a.darts.to_map::<2>(), Err(DartsError::NotQuasiManifold { .. })));
    assert!(matches!(v.check(), Err(VectorError::Darts { .. })), "{:?}", v.check());
}

// ---------------------------------------------------------------------------------------------
// B5: out-of-range indices in `IndexedModel::audit` and `campaign::sub_complex`.

/// Reproducer 7: a cut naming tet 9 of 2 panicked in `audit`; it is refused as `cut` refuses it.
#[test]
fn b5_audit_refuses_a_cut_naming_a_tet_that_does_not_exist() {
    let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
    let model = IndexedModel::new(5, &tets).unwrap();
    let gmap = CutComplex { points: 5, tets: tets.to_vec(), cuts: vec![] }.build().unwrap();
    for (cuts, cut, tet) in [(vec![[0, 9]], 0, 9), (vec![[0, 1], [7, 0]], 1, 7), (vec![[u32::MAX, 1]], 0, u32::MAX)] {
        let Some(Err(e)) = no_panic(|| model.audit(&gmap, &cuts, &[])) else {
            panic!("{cuts:?}: panicked or accepted")
        };
        assert_eq!(e, AuditError::Cut { cut, source: IndexedError::NoSuchTet { tet, tets: 2 } });
    }
    assert!(model.audit(&gmap, &[[0, 1]], &[]).is_ok()); // a valid cut still audits
}

/// Reproducer 7: `sub_complex` panicked on a cut naming tet 9, on a kept tet 5 of 2 and on a tet
/// naming point 4 of 4; each gives `None`, as a cut naming a dropped tet does.
#[test]
fn b5_sub_complex_gives_none_for_any_out_of_range_index() {
    let tets = vec![[0, 1, 2, 3], [1, 2, 3, 4]];
    let cases = [
        (CutComplex { points: 5, tets: tets.clone(), cuts: vec![[0, 9]] }, vec![0]),
        (CutComplex { points: 5, tets: tets.clone(), cuts: vec![[9, 0]] }, vec![0, 1]),
        (CutComplex { points: 5, tets: tets.clone(), cuts: vec![] }, vec![5]),
        (CutComplex { points: 4, tets: tets.clone(), cuts: vec![] }, vec![1]),
    ];
    for (c, keep) in cases {
        assert_eq!(no_panic(|| sub_complex(&c, &keep)), Some(None), "{c:?} keep {keep:?}");
    }
    let c = CutComplex { points: 5, tets, cuts: vec![[0, 1]] };
    assert_eq!(sub_complex(&c, &[1, 0]).map(|s| s.cuts), Some(vec![[1, 0]]));
}

// ---------------------------------------------------------------------------------------------
// B6: `Gluing::word` and `origin_text`.

/// Reproducer 8: a side past the end (which `build` refuses) panicked in `word` and
/// `origin_text`; the word is `?`.
#[test]
fn b6_a_side_past_the_end_gives_a_question_mark() {
    for g in [Gluing { sides: vec![2], pairs: vec![[0, 5, 0]] }, Gluing { sides: vec![2], pairs: vec![[2, 0, 1]] }] {
        assert!(g.build().is_err());
        assert_eq!(no_panic(|| g.word()).as_deref(), Some("?"));
        assert_eq!(no_panic(|| origin_text(&Origin::Gluing(g.clone()))).as_deref(), Some("?"));
    }
}

/// Reproducer 8: past 26 pairs, letters were reused, so the word glued sides of different pairs
/// together; every pair gets its own name now (`a` … `z`, `a1` …).
#[test]
fn b6_past_26_pairs_every_pair_has_its_own_name() {
    let many = Gluing { sides: vec![4; 14], pairs: (0..28u16).map(|k| [2 * k, 2 * k + 1, 0]).collect() };
    assert!(many.build().is_ok());
    let word = many.word();
    assert!(word.starts_with("(a a' b b') (c c' d d')"), "{word}");
    assert!(word.ends_with("(y y' z z') (a1 a1' b1 b1')"), "{word}");
    let mut uses: BTreeMap<&str, usize> = BTreeMap::new();
    for token in word.split([' ', '(', ')']).filter(|t| !t.is_empty()) {
        *uses.entry(token.trim_end_matches('\'')).or_default() += 1;
    }
    assert_eq!(uses.len(), 28);
    assert!(uses.values().all(|&n| n == 2), "{uses:?}");
}

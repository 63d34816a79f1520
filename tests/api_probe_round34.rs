//! Round 34's probes (conformance to the seed papers). Finding 289: `tear_vertex` tore a vertex
//! with a NaN position on one of its boundary faces, which its docs say it refuses; the side of
//! the fan was then chosen from a NaN.

use std::collections::BTreeSet;

use topomech::cut::{tear_vertex, CutError};
use topomech::generate::kuhn_cube;
use topomech::mechanics::{Body, Material};
use topomech::CellId;

/// Version, dart and cell counts and every position bit for bit: what a refusal must keep.
fn state(body: &Body) -> (u64, usize, Vec<usize>, Vec<[u64; 3]>) {
    let pos = body.attrs().position().as_slice().iter().map(|p| p.map(f64::to_bits)).collect();
    (body.version(), body.map().dart_count(), body.map().count_cells().0, pos)
}

/// The report's reproducer: two tets glued on face {0, 1, 2}; corner 3 (on the boundary faces
/// {0, 1, 3} and {0, 2, 3} around vertex 0 only) is NaN. Tearing vertex 0 went through (one face
/// dissociated); it is refused naming vertex 3, the body unchanged.
#[test]
fn f289_a_nan_on_a_boundary_face_around_the_vertex_refuses_the_tear() {
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    let (mut body, _) = Body::from_tets(&points, &[[0, 1, 2, 3], [0, 1, 2, 4]], Material::default()).unwrap();
    body.attrs_mut().position_mut().as_mut_slice()[3] = [f64::NAN, 0.0, 1.0];
    let before = state(&body);
    let e = tear_vertex(&mut body, CellId(0), [0.0, 0.0, 1.0], None).unwrap_err();
    assert!(matches!(e, CutError::NonFinitePosition { vertex: CellId(3), .. }), "{e:?}");
    assert_eq!(state(&body), before);
}

/// On `kuhn_cube(2)`, for every vertex v and every neighbour w of v (each lies on a face around
/// v), w's position made NaN (one coordinate, or +∞): every tear of v is refused naming w, the
/// body unchanged (before: 24 went through). With a finite star the same tears succeed.
#[test]
fn f289_every_non_finite_neighbour_refuses_the_tear() {
    let (points, tets) = kuhn_cube(2);
    let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    let mut refused = 0;
    for v in 0..points.len() as u32 {
        let star: BTreeSet<u32> =
            tets.iter().filter(|t| t.contains(&v)).flatten().copied().filter(|&w| w != v).collect();
        for (k, &w) in star.iter().enumerate() {
            let mut b = body.clone();
            b.attrs_mut().position_mut().as_mut_slice()[w as usize][k % 3] =
                if k % 2 == 0 { f64::NAN } else { f64::INFINITY };
            let before = state(&b);
            let e = tear_vertex(&mut b, CellId(v), [0.3, 0.5, 0.8], None).unwrap_err();
            assert!(
                matches!(e, CutError::NonFinitePosition { vertex, .. } if vertex == CellId(w)),
                "v {v} w {w}: {e:?}"
            );
            assert_eq!(state(&b), before, "v {v} w {w}");
            refused += 1;
        }
        let mut b = body.clone();
        tear_vertex(&mut b, CellId(v), [0.3, 0.5, 0.8], None).unwrap();
    }
    // Each (v, w) is one end of an edge: every edge was met from both ends.
    let edges: BTreeSet<(u32, u32)> = tets
        .iter()
        .flat_map(|t| (0..4).flat_map(move |i| (i + 1..4).map(move |j| (t[i].min(t[j]), t[i].max(t[j])))))
        .collect();
    assert_eq!(refused, 2 * edges.len());
}

/// Finding 294: one `subdivide_tet` counted 1 + its unsplit faces (5 on a fresh tet) in
/// `LeveledMap::version`, whose docs promise one per accepted operation; the bulk
/// `refine_uniform` made the same change with 1. Now every tet split adds exactly one, whatever
/// its faces, and the per-op and bulk refinements of one tet agree.
#[test]
fn f294_one_tet_split_is_one_version() {
    use topomech::subdivide::{LeveledMap, TetMasses};
    use topomech::GMap;
    let tet = || {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        LeveledMap::new(map, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    };
    let mut m = tet();
    let d = m.map().darts().next().unwrap();
    let children = m.subdivide_tet(d, 1).unwrap();
    assert_eq!(m.version(), 1);
    m.subdivide_tet(children[0], 2).unwrap();
    assert_eq!(m.version(), 2);
    // A face split on its own counts one; the tet split after it one more (three faces left).
    let mut m = tet();
    m.subdivide_triangle(d, 1).unwrap();
    assert_eq!(m.version(), 1);
    m.subdivide_tet(d, 1).unwrap();
    assert_eq!(m.version(), 2);
    // Bulk and op by op, one tet to level 1: one operation each.
    for bulk in [true, false] {
        let mut m = tet();
        let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
        let r = if bulk {
            m.refine_around([0.1; 3], 10.0, 1, &mut masses)
        } else {
            m.refine_around_per_op([0.1; 3], 10.0, 1, &mut masses)
        };
        assert_eq!((r.unwrap().subdivided_per_level, m.version()), (vec![0, 1], 1), "bulk {bulk}");
    }
}

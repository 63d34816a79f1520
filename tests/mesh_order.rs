//! `TetMesh::spatially_ordered`: a renumbering, nothing else. The reordered mesh builds a map
//! isomorphic to the original's, with the same signed volume per tet (up to the permutation),
//! the permutation is a bijection that maps every tet onto a tet of the new mesh, and points come
//! out in non-decreasing Z-order (checked on a grid, where the order is known exactly).

use proptest::prelude::*;
use topomech::cut::ops::jittered_cube;
use topomech::generate::kuhn_cube;
use topomech::mesh::{signed_volume, TetMesh};
use topomech::GMap;

fn check_renumbering(mesh: &TetMesh) {
    let (ordered, new_of_old) = mesh.spatially_ordered();
    let mut seen = vec![false; new_of_old.len()];
    for &n in &new_of_old {
        assert!(!std::mem::replace(&mut seen[n as usize], true), "point {n} used twice: not a bijection");
    }
    for (old, &new) in new_of_old.iter().enumerate() {
        assert_eq!(ordered.points[new as usize], mesh.points[old]);
    }
    let mut mapped: Vec<[u32; 4]> = mesh.tets.iter().map(|t| t.map(|v| new_of_old[v as usize])).collect();
    let mut got = ordered.tets.clone();
    mapped.sort_unstable();
    got.sort_unstable();
    assert_eq!(mapped, got, "the same tets, relabelled");
    let vol = |m: &TetMesh| -> f64 {
        m.tets
            .iter()
            .map(|t| {
                signed_volume(
                    m.points[t[0] as usize],
                    m.points[t[1] as usize],
                    m.points[t[2] as usize],
                    m.points[t[3] as usize],
                )
            })
            .sum()
    };
    assert!((vol(mesh) - vol(&ordered)).abs() <= 1e-12 * vol(mesh).abs().max(1.0));
    let (a, _) = GMap::<3>::from_tets(mesh.points.len(), &mesh.tets).unwrap();
    let (b, _) = GMap::<3>::from_tets(ordered.points.len(), &ordered.tets).unwrap();
    assert!(a.is_isomorphic(&b), "the reordered mesh is the same object");
}

#[test]
fn a_grid_comes_out_in_z_order() {
    let (points, tets) = kuhn_cube(3);
    let mesh = TetMesh { points, tets, ..Default::default() };
    check_renumbering(&mesh);
    let (ordered, _) = mesh.spatially_ordered();
    // On the 4×4×4 grid the first 8 points are the 2×2×2 block at the origin.
    assert!(ordered.points[..8].iter().all(|p| p.iter().all(|&c| c <= 1.0)), "{:?}", &ordered.points[..8]);
    assert_eq!(ordered.points[0], [0.0; 3]);
    assert_eq!(*ordered.points.last().unwrap(), [3.0; 3]);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]
    #[test]
    fn reordering_is_a_renumbering(k in 1usize..=3, seed in any::<u64>()) {
        let (points, tets) = jittered_cube(k, seed);
        check_renumbering(&TetMesh { points, tets, ..Default::default() });
    }
}

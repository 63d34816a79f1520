//! `TetMesh::spatially_ordered` and `TetMesh::bandwidth_ordered` (reverse Cuthill–McKee): each a
//! renumbering, nothing else. The reordered mesh builds a map
//! isomorphic to the original's, with the same signed volume per tet (up to the permutation),
//! the permutation is a bijection that maps every tet onto a tet of the new mesh, and points come
//! out in non-decreasing Z-order (checked on a grid, where the order is known exactly).

use proptest::prelude::*;
use topomech::cut::ops::jittered_cube;
use topomech::generate::kuhn_cube;
use topomech::mesh::{signed_volume, TetMesh};
use topomech::GMap;

fn check_renumbering(mesh: &TetMesh) {
    check_renumbering_by(mesh, TetMesh::spatially_ordered);
    check_renumbering_by(mesh, TetMesh::bandwidth_ordered);
}

/// max |a − b| over the tets' edges.
fn bandwidth(mesh: &TetMesh) -> u32 {
    let edges = mesh.tets.iter().flat_map(|t| (0..4).flat_map(move |i| (0..4).map(move |j| (t[i], t[j]))));
    edges.map(|(a, b)| a.abs_diff(b)).max().unwrap_or(0)
}

fn check_renumbering_by(mesh: &TetMesh, reorder: fn(&TetMesh) -> (TetMesh, Vec<u32>)) {
    let (ordered, new_of_old) = reorder(mesh);
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

#[test]
fn reverse_cuthill_mckee_narrows_the_band_of_a_shuffled_grid() {
    let (points, tets) = kuhn_cube(6);
    let n = points.len();
    // Shuffle the points (a fixed LCG permutation) so that the file order has a wide band.
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut state = 12345u64;
    for i in (1..n).rev() {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        order.swap(i, (state >> 33) as usize % (i + 1));
    }
    let mut new_of_old = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        new_of_old[old as usize] = new as u32;
    }
    let shuffled = TetMesh {
        points: order.iter().map(|&o| points[o as usize]).collect(),
        tets: tets.iter().map(|t| t.map(|v| new_of_old[v as usize])).collect(),
        ..Default::default()
    };
    check_renumbering(&shuffled);
    let (rcm, _) = shuffled.bandwidth_ordered();
    let (grid, shuffled_band, rcm_band) =
        (bandwidth(&TetMesh { points, tets, ..Default::default() }), bandwidth(&shuffled), bandwidth(&rcm));
    // A 7×7×7 grid in row order has band 7·7 + 7 + 1 = 57; a shuffle spreads it to nearly n.
    assert_eq!(grid, 57);
    assert!(shuffled_band > 200, "shuffle band {shuffled_band}");
    assert!(rcm_band <= 2 * grid, "RCM band {rcm_band} vs grid band {grid}");
    // Two components stay two blocks: numbers of one never interleave with the other's.
    let (p2, t2) = kuhn_cube(1);
    let shift = p2.len() as u32;
    let two = TetMesh {
        points: p2
            .iter()
            .chain(p2.iter().map(|p| [p[0] + 5.0, p[1], p[2]]).collect::<Vec<_>>().iter())
            .copied()
            .collect(),
        tets: t2.iter().copied().chain(t2.iter().map(|t| t.map(|v| v + shift))).collect(),
        ..Default::default()
    };
    check_renumbering(&two);
    let (_, map) = two.bandwidth_ordered();
    let first: Vec<u32> = map[..shift as usize].to_vec();
    let block = |ids: &[u32]| ids.iter().max().unwrap() - ids.iter().min().unwrap();
    assert_eq!(block(&first), shift - 1, "component 1 got {first:?}");
}

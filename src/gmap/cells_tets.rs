//! Orbit counting on a map whose tets are as built: the fast path of
//! [`GMap::count_cells_by_traversal`] and [`GMap::count_all_cells_by_traversal`].
//!
//! While the tet layout law holds ([`Law::TetLayout`](super::Law::TetLayout)), the orbit of
//! ⟨αj : j ≠ i⟩ of a dart (i < 3) is a class of i-pieces of tets (corners, edges, faces: the
//! orbits of ⟨αj : j < 3, j ≠ i⟩ inside one tet, see the `validate_tets` module) joined by α3; a
//! volume is one tet; a connected component is a class of tets joined by α3. So
//! #i-cells = #i-pieces − #successful joins of a union-find over the i-pieces that meets every α3
//! link once, from its smaller dart, and #components is counted the same way over tets.
//!
//! Cost: one sequential pass over the α rows (the layout law is checked in it) and
//! O(darts · α(tets)) union-find over 4 + 6 + 4 + 1 = 15 nodes per tet, where the generic sweep
//! unions 5 forests of 24 darts per tet and reads every α. Precondition, as for the generic
//! sweep: α3 is an involution (a law `validate()` checks). No cell id is read.

use super::validate_tets::{join, piece_of, PIECES};
use super::GMap;
use crate::build::built_tet_links;

impl<const N: usize> GMap<N> {
    /// `[vertices, edges, faces, volumes, components]` of a 3-map flagged as built tets whose
    /// layout law holds (checked in the same pass); `None` for any other map, and when an α3
    /// image is out of range (the generic sweep then answers). O(darts · α(tets)).
    pub(super) fn count_built_tet_orbits(&self) -> Option<[usize; 5]> {
        let tets = self.live_tet_blocks().filter(|_| self.tets_as_built())?;
        let (w, capacity) = (N + 1, self.capacity() as u32);
        // Union-find forests over the corner, edge and face pieces, and over the tets.
        let mut forests: [Vec<u32>; 4] = std::array::from_fn(|dim| (0..(PIECES[dim] * tets) as u32).collect());
        let mut joins = [0usize; 4];
        for (t, rows) in self.alpha.chunks_exact(24 * w).enumerate() {
            for (k, row) in rows.chunks_exact(w).enumerate() {
                let (d, e) = ((24 * t + k) as u32, row[3]);
                if row[..3] != built_tet_links(d) {
                    return None; // the layout law fails
                }
                if e <= d {
                    continue; // free, or met from e
                }
                if e >= capacity {
                    return None;
                }
                for (dim, forest) in forests.iter_mut().enumerate().take(3) {
                    joins[dim] += usize::from(join(forest, piece_of(dim, d), piece_of(dim, e)));
                }
                joins[3] += usize::from(join(&mut forests[3], d / 24, e / 24));
            }
        }
        let pieces = |dim: usize| PIECES[dim] * tets;
        Some([pieces(0) - joins[0], pieces(1) - joins[1], pieces(2) - joins[2], tets, tets - joins[3]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{kuhn_cube, SplitMix64};
    use crate::{AlphaMask, DartId};

    /// The generic sweep's `[vertices, edges, faces, volumes, components]`.
    fn generic_counts(map: &GMap<3>) -> Vec<usize> {
        let mut masks: Vec<AlphaMask> = (0..=3).map(|i| AlphaMask::cell(3, i)).collect();
        masks.push(AlphaMask::all(3));
        map.count_orbits_in_one_sweep(&masks)
    }

    /// Random α3 rewirings that keep α3 an involution (unlink two darts, then link them or leave
    /// them free; or free a whole tet): most of them break the quasi-manifold law, none the
    /// layout law, so the tet path must count exactly what the generic sweep counts on every one.
    #[test]
    fn the_tet_path_counts_the_generic_sweeps_orbits_under_any_involutive_alpha3() {
        let mut rng = SplitMix64(2026);
        let mut seen = std::collections::HashSet::new();
        for k in 1..=3 {
            let (points, tets) = kuhn_cube(k);
            let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
            for step in 0..300 {
                let counts = map.count_built_tet_orbits().expect("the layout law holds");
                assert_eq!(counts.to_vec(), generic_counts(&map), "k = {k}, step {step}");
                seen.insert(counts);
                let cap = map.capacity();
                let (a, b) = (DartId(rng.below(cap) as u32), DartId(rng.below(cap) as u32));
                if rng.below(8) == 0 {
                    // Free the whole tet of a: it becomes a component of its own.
                    (a.0 - a.0 % 24..a.0 - a.0 % 24 + 24).for_each(|x| map.unlink_raw(3, DartId(x)));
                    continue;
                }
                map.unlink_raw(3, a);
                map.unlink_raw(3, b);
                if rng.below(2) > 0 {
                    map.link_raw(3, a, b);
                }
            }
        }
        let split = seen.iter().filter(|c| c[4] > 1).count();
        assert!(seen.len() > 400 && split > 100, "too few distinct counts: {} ({split} split)", seen.len());
    }

    /// α1 rewired inside a lone tet with the flag forced on: the pieces are no longer orbits, so
    /// the tet path must refuse and the dart sweep answer.
    #[test]
    fn a_tet_rewired_inside_is_left_to_the_dart_sweep() {
        let map = super::super::validate::tet_rewired_inside();
        assert_eq!(map.count_built_tet_orbits(), None);
        let (cells, components) = map.count_all_cells_by_traversal();
        assert_eq!([cells.0.clone(), vec![components]].concat(), generic_counts(&map));
        assert_ne!(cells.0[0], 4, "the rewiring changes the vertex orbits");
    }

    #[test]
    fn the_public_counts_take_the_tet_path_only_on_built_tets() {
        let (points, tets) = kuhn_cube(2);
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
        let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
        map.unsew::<3>(d).unwrap();
        assert!(map.count_built_tet_orbits().is_some());
        let (cells, components) = map.count_all_cells_by_traversal();
        assert_eq!((cells.clone(), components), (map.count_cells(), 1));
        assert_eq!(map.count_cells_by_traversal(), cells);
        // A dart added outside the tets clears the flag: the generic sweep answers.
        map.create_dart().unwrap();
        assert_eq!(map.count_built_tet_orbits(), None);
        let mut expected = cells.0.clone();
        expected.iter_mut().for_each(|c| *c += 1); // the lone dart is one cell of each dimension
        assert_eq!(map.count_all_cells_by_traversal(), (crate::gmap::CellCounts(expected), 2));
        let (map2, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
        assert_eq!(map2.count_built_tet_orbits(), None);
    }
}

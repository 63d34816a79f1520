//! Global characteristics: cell counts, components, boundary, Euler characteristic,
//! orientability.

use super::orbit::{generators, join_with_smaller};
use super::{AlphaMask, DartId, DartSet, GMap};

/// Number of i-cells for each i in 0..=n.
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let counts = map.count_cells();
/// assert_eq!(counts.0, vec![5, 9, 7, 2]); // vertices, edges, faces, volumes
/// assert_eq!(counts, map.count_cells_by_traversal());
/// assert_eq!(counts.euler_characteristic(), 5 - 9 + 7 - 2);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct CellCounts(pub Vec<usize>);

impl CellCounts {
    /// Σ (−1)^i · #i-cells.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::gmap::CellCounts;
    ///
    /// assert_eq!(CellCounts(vec![4, 6, 4, 1]).euler_characteristic(), 1); // a tetrahedron
    /// assert_eq!(CellCounts(vec![4, 6, 4]).euler_characteristic(), 2); // its surface
    /// ```
    pub fn euler_characteristic(&self) -> i64 {
        self.0.iter().enumerate().map(|(i, &c)| if i % 2 == 0 { c as i64 } else { -(c as i64) }).sum()
    }
}

/// The characteristics printed by `topomech info`.
///
/// # Examples
///
/// ```
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let s = map.summary();
/// assert_eq!((s.darts, s.boundary_faces, s.components), (24, 4, 1));
/// assert_eq!(s.cells.0, vec![4, 6, 4, 1]);
/// assert_eq!(s.euler_characteristic, 1);
/// assert!(s.orientable && s.valid);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct MapSummary {
    /// Live darts.
    pub darts: usize,
    /// i-cells per dimension.
    pub cells: CellCounts,
    /// (n−1)-cells on the boundary (made of αn-free darts).
    pub boundary_faces: usize,
    /// Connected components.
    pub components: usize,
    /// Σ (−1)^i · #i-cells.
    pub euler_characteristic: i64,
    /// Whether every component is orientable.
    pub orientable: bool,
    /// Whether `validate()` passed.
    pub valid: bool,
}

impl<const N: usize> GMap<N> {
    /// Number of i-cells for every i, read from the id allocators. O(n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// assert_eq!(map.count_cells().0, vec![8, 19, 18, 6]);
    /// ```
    pub fn count_cells(&self) -> CellCounts {
        CellCounts(self.ids.iter().map(|a| a.live()).collect())
    }

    /// Number of i-cells for every i, found by walking orbits (independent of cell ids).
    /// O(darts · n² · α(darts)).
    ///
    /// One sequential sweep over the darts reads each dart's α row once and, for every
    /// dimension i, joins d with each αj(d) < d (j ≠ i) in a union-find forest of dimension i:
    /// #i-cells = #live darts − #successful joins. Because every α is an involution (a law of
    /// the map), each link is met once, from its larger end. Rows are read in memory order and
    /// the forests' roots (the smallest dart of each orbit) stay in cache, unlike the random row
    /// reads of a flood.
    ///
    /// On a map whose tets are as built ([`Self::tets_as_built`], layout law checked in the same
    /// call) the union-find runs over the corners, edges and faces of the tets instead of darts,
    /// joined across α3 (15 nodes per tet instead of 24 per forest; same counts, tested against
    /// the dart sweep). O(darts · α(tets)) then.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(2);
    /// let (mut map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
    /// map.unsew::<3>(d).unwrap();
    /// assert_eq!(map.count_cells_by_traversal(), map.count_cells()); // ids and orbits agree
    /// ```
    pub fn count_cells_by_traversal(&self) -> CellCounts {
        if let Some(counts) = self.count_built_tet_orbits() {
            return CellCounts(counts[..4].to_vec());
        }
        let masks: Vec<AlphaMask> = (0..=N).map(|i| AlphaMask::cell(N, i)).collect();
        CellCounts(self.count_orbits_in_one_sweep(&masks))
    }

    /// Number of i-cells for every i and number of connected components, found by walking
    /// orbits (independent of cell ids) in one sweep: what CGAL's `count_all_cells` computes.
    /// O(darts · n² · α(darts)).
    ///
    /// Same sweep as [`Self::count_cells_by_traversal`] with one more union-find forest, over
    /// all n + 1 involutions, for the components (over tets joined by α3 on the tet path).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    /// let (cells, components) = map.count_all_cells_by_traversal();
    /// assert_eq!(cells.0, vec![8, 12, 8, 2]);
    /// assert_eq!(components, 2);
    /// assert_eq!((cells, components), (map.count_cells_by_traversal(), map.components().len()));
    /// ```
    pub fn count_all_cells_by_traversal(&self) -> (CellCounts, usize) {
        if let Some(counts) = self.count_built_tet_orbits() {
            return (CellCounts(counts[..4].to_vec()), counts[4]);
        }
        let mut masks: Vec<AlphaMask> = (0..=N).map(|i| AlphaMask::cell(N, i)).collect();
        masks.push(AlphaMask::all(N));
        let mut counts = self.count_orbits_in_one_sweep(&masks);
        let components = counts.pop().unwrap_or(0);
        (CellCounts(counts), components)
    }

    /// The number of orbits of each mask, from one sweep with one union-find forest per mask:
    /// each dart's row is read once, and a dart joins the trees of its neighbours below it with
    /// [`join_with_smaller`]. O(darts · Σ|mask| · α(darts)).
    pub(crate) fn count_orbits_in_one_sweep(&self, masks: &[AlphaMask]) -> Vec<usize> {
        let gens: Vec<([usize; 8], usize)> = masks.iter().map(|&mask| generators(N, mask)).collect();
        let mut forests: Vec<Vec<u32>> = gens.iter().map(|_| (0..self.capacity() as u32).collect()).collect();
        let mut joins = vec![0usize; gens.len()];
        self.for_each_live(|d| {
            let row = self.alpha_row(d);
            for ((forest, (g, len)), joins) in forests.iter_mut().zip(&gens).zip(joins.iter_mut()) {
                *joins += join_with_smaller(forest, d, row, &g[..*len]);
            }
        });
        joins.iter().map(|&j| self.dart_count() - j).collect()
    }

    /// Number of distinct orbits ⟨mask⟩ over all live darts. O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, AlphaMask, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// assert_eq!(map.count_orbits(AlphaMask::of(&[0, 1])), 24); // 4 faces per tet, one side each
    /// assert_eq!(map.count_orbits(AlphaMask::cell(3, 2)), 18); // the faces of the mesh
    /// ```
    pub fn count_orbits(&self, mask: AlphaMask) -> usize {
        self.for_each_orbit(mask, |_| {})
    }

    /// One dart per connected component (orbit of all involutions), smallest first. O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    /// let roots = map.components();
    /// assert_eq!(roots.len(), 2);
    /// assert_eq!(map.orbit(roots[1], topomech::AlphaMask::all(3)).len(), 24);
    /// ```
    pub fn components(&self) -> Vec<DartId> {
        let mut roots = Vec::new();
        self.for_each_orbit(AlphaMask::all(N), |d| roots.push(d));
        roots
    }

    /// Component index of every dart slot (`u32::MAX` for dead slots), and the count.
    /// O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{DartId, GMap};
    ///
    /// let (map, _) = GMap::<3>::from_tets(8, &[[0, 1, 2, 3], [4, 5, 6, 7]]).unwrap();
    /// let (label, count) = map.component_labels();
    /// assert_eq!(count, 2);
    /// assert_eq!(label[0], label[23]);
    /// assert_ne!(label[0], label[24]); // darts 24.. belong to the second tet
    /// assert!(map.contains(DartId(24)));
    /// ```
    pub fn component_labels(&self) -> (Vec<u32>, usize) {
        let mut label = vec![u32::MAX; self.capacity()];
        let mut stack = Vec::new();
        let mut count = 0u32;
        self.for_each_live(|d| {
            if label[d as usize] != u32::MAX {
                return;
            }
            label[d as usize] = count;
            stack.push(d);
            while let Some(x) = stack.pop() {
                for &y in self.alpha_row(x) {
                    if label[y as usize] == u32::MAX {
                        label[y as usize] = count;
                        stack.push(y);
                    }
                }
            }
            count += 1;
        });
        (label, count as usize)
    }

    /// The αn-free darts: the boundary. O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// assert_eq!(map.boundary_darts().count(), 12 * 6); // 12 boundary triangles, 6 darts each
    /// ```
    pub fn boundary_darts(&self) -> impl Iterator<Item = DartId> + '_ {
        self.darts().filter(|&d| self.is_free(N, d))
    }

    /// Number of (n−1)-cells on the boundary (distinct (n−1)-cell ids among αn-free darts).
    /// O(capacity).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(2);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// assert_eq!(map.boundary_cell_count(), 12 * 2 * 2); // 12k² for the k-cube
    /// ```
    pub fn boundary_cell_count(&self) -> usize {
        let mut seen = DartSet::with_capacity(self.cell_id_bound(N - 1));
        self.boundary_darts().filter(|&d| seen.insert(DartId(self.cell_id(N - 1, d).0))).count()
    }

    /// Σ (−1)^i · #i-cells. O(n).
    ///
    /// # Examples
    ///
    /// ```
    ///
    /// use topomech::GMap;
    ///
    /// // The surface of a tetrahedron is a sphere (χ = 2); the solid is a ball (χ = 1).
    /// let surface = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
    /// let (sphere, _) = GMap::<2>::from_triangles(4, &surface).unwrap();
    /// assert_eq!(sphere.euler_characteristic(), 2);
    /// let (ball, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// assert_eq!(ball.euler_characteristic(), 1);
    /// ```
    pub fn euler_characteristic(&self) -> i64 {
        self.count_cells().euler_characteristic()
    }

    /// A 2-colouring of the darts such that every non-free αi link joins two colours, if one
    /// exists (colour `u8::MAX` on dead slots). The map is orientable iff it exists. O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let colour = map.orientation().unwrap();
    /// for d in map.darts() {
    ///     for i in 0..=2 {
    ///         assert_ne!(colour[d.index()], colour[map.alpha_dyn(i, d).index()]);
    ///     }
    /// }
    /// assert_eq!(colour.iter().filter(|&&c| c == 0).count(), 12);
    /// ```
    pub fn orientation(&self) -> Option<Vec<u8>> {
        let mut colour = vec![u8::MAX; self.capacity()];
        let mut stack = Vec::new();
        for d in self.darts() {
            if colour[d.index()] != u8::MAX {
                continue;
            }
            colour[d.index()] = 0;
            stack.push(d);
            while let Some(x) = stack.pop() {
                let c = colour[x.index()];
                for i in 0..=N {
                    let y = self.alpha_dyn(i, x);
                    if y == x {
                        continue;
                    }
                    match colour[y.index()] {
                        u8::MAX => {
                            colour[y.index()] = 1 - c;
                            stack.push(y);
                        }
                        cy if cy == c => return None,
                        _ => {}
                    }
                }
            }
        }
        Some(colour)
    }

    /// Whether every component is orientable. O(darts · n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::GMap;
    ///
    /// // Five triangles {i, i+1, i+2} (mod 5) close up into a Möbius strip.
    /// let strip: Vec<[u32; 3]> = (0..5).map(|i| [i, (i + 1) % 5, (i + 2) % 5]).collect();
    /// let (mobius, _) = GMap::<2>::from_triangles(5, &strip).unwrap();
    /// assert!(!mobius.is_orientable());
    /// let (disc, _) = GMap::<2>::from_triangles(4, &[[0, 1, 2], [0, 2, 3]]).unwrap();
    /// assert!(disc.is_orientable());
    /// ```
    pub fn is_orientable(&self) -> bool {
        self.orientation().is_some()
    }

    /// Darts, cells, boundary, components, Euler characteristic, orientability and validity.
    /// O(darts · n²).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::{generate, GMap};
    ///
    /// let (points, tets) = generate::kuhn_cube(1);
    /// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
    /// let s = map.summary();
    /// assert_eq!(s.cells, map.count_cells());
    /// assert_eq!((s.boundary_faces, s.euler_characteristic, s.valid), (12, 1, true));
    /// ```
    pub fn summary(&self) -> MapSummary {
        let cells = self.count_cells();
        MapSummary {
            darts: self.dart_count(),
            euler_characteristic: cells.euler_characteristic(),
            cells,
            boundary_faces: self.boundary_cell_count(),
            components: self.components().len(),
            orientable: self.is_orientable(),
            valid: self.validate().is_ok(),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::generate::kuhn_cube;
    use crate::{AlphaMask, GMap};

    /// `count_orbits_in_one_sweep` (one forest per mask, one to sixteen masks per sweep) counts
    /// what the orbit sweep behind `count_orbits` counts, mask by mask, on a map with free
    /// faces, split edges and pinched vertices (every third tet removed) and freed darts.
    #[test]
    fn one_sweep_counts_like_one_sweep_per_mask() {
        let (points, tets) = kuhn_cube(3);
        let kept: Vec<[u32; 4]> = tets.iter().enumerate().filter(|(t, _)| t % 3 != 1).map(|(_, &t)| t).collect();
        let (mut map, _) = GMap::<3>::from_tets(points.len(), &kept).unwrap();
        let sewn: Vec<_> = map.darts().filter(|&d| !map.is_free(3, d)).step_by(7).collect();
        for d in sewn {
            if !map.is_free(3, d) {
                map.unsew::<3>(d).unwrap();
            }
        }
        let masks: Vec<AlphaMask> =
            (0u8..16).map(|bits| AlphaMask::of(&(0..4).filter(|&i| bits >> i & 1 == 1).collect::<Vec<_>>())).collect();
        let one_by_one: Vec<usize> = masks.iter().map(|&m| map.count_orbits(m)).collect();
        assert_eq!(map.count_orbits_in_one_sweep(&masks), one_by_one);
        for (k, &mask) in masks.iter().enumerate() {
            assert_eq!(map.count_orbits_in_one_sweep(&[mask]), vec![one_by_one[k]], "mask {k}");
        }
        assert_eq!(map.count_cells_by_traversal(), map.count_cells());
        assert!(one_by_one[0] == map.dart_count() && one_by_one[15] < one_by_one[1]);
    }
}

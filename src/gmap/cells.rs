//! Global characteristics: cell counts, components, boundary, Euler characteristic,
//! orientability.

use super::orbit::{generators, union_smaller_root};
use super::{AlphaMask, DartId, DartSet, GMap};

/// Number of i-cells for each i in 0..=n.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct CellCounts(pub Vec<usize>);

impl CellCounts {
    /// Σ (−1)^i · #i-cells.
    pub fn euler_characteristic(&self) -> i64 {
        self.0.iter().enumerate().map(|(i, &c)| if i % 2 == 0 { c as i64 } else { -(c as i64) }).sum()
    }
}

/// The characteristics printed by `topomech info`.
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
    pub fn count_cells_by_traversal(&self) -> CellCounts {
        let gens: Vec<([usize; 8], usize)> = (0..=N).map(|i| generators(N, AlphaMask::cell(N, i))).collect();
        let mut forests: Vec<Vec<u32>> = (0..=N).map(|_| (0..self.capacity() as u32).collect()).collect();
        let mut joins = vec![0usize; N + 1];
        self.for_each_live(|d| {
            let row = self.alpha_row(d);
            for (dim, forest) in forests.iter_mut().enumerate() {
                let (g, len) = &gens[dim];
                for &j in &g[..*len] {
                    let y = row[j];
                    if y < d {
                        joins[dim] += union_smaller_root(forest, d, y) as usize;
                    }
                }
            }
        });
        CellCounts(joins.iter().map(|&j| self.dart_count() - j).collect())
    }

    /// Number of distinct orbits ⟨mask⟩ over all live darts. O(darts · n).
    pub fn count_orbits(&self, mask: AlphaMask) -> usize {
        self.for_each_orbit(mask, |_| {})
    }

    /// One dart per connected component (orbit of all involutions), smallest first. O(darts · n).
    pub fn components(&self) -> Vec<DartId> {
        let mut roots = Vec::new();
        self.for_each_orbit(AlphaMask::all(N), |d| roots.push(d));
        roots
    }

    /// Component index of every dart slot (`u32::MAX` for dead slots), and the count.
    /// O(darts · n).
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
    pub fn boundary_darts(&self) -> impl Iterator<Item = DartId> + '_ {
        self.darts().filter(|&d| self.is_free(N, d))
    }

    /// Number of (n−1)-cells on the boundary (distinct (n−1)-cell ids among αn-free darts).
    /// O(capacity).
    pub fn boundary_cell_count(&self) -> usize {
        let mut seen = DartSet::with_capacity(self.cell_id_bound(N - 1));
        self.boundary_darts().filter(|&d| seen.insert(DartId(self.cell_id(N - 1, d).0))).count()
    }

    /// Σ (−1)^i · #i-cells. O(n).
    pub fn euler_characteristic(&self) -> i64 {
        self.count_cells().euler_characteristic()
    }

    /// A 2-colouring of the darts such that every non-free αi link joins two colours, if one
    /// exists (colour `u8::MAX` on dead slots). The map is orientable iff it exists. O(darts · n).
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
    pub fn is_orientable(&self) -> bool {
        self.orientation().is_some()
    }

    /// Darts, cells, boundary, components, Euler characteristic, orientability and validity.
    /// O(darts · n²).
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

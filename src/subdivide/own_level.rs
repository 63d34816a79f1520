//! The own-level law (findings 338, 339, and round 40's R40-1, R40-2): every cell of the finest
//! map is a cell of the level its resolution level names. For a k-cell c (1 ≤ k ≤ n) with
//! L = μ_k(c) (μa for an edge, μf for a face, μt for a volume): c has a dart of level ≤ L, and
//! the orbit ⟨α0, …, α(k−1)⟩ at level L from such a dart stays inside c. For a top cell (k = n)
//! also the converse, *minimality*: if L > 0, c was no cell at level L − 1 — it has no dart of a
//! level below L, or the orbit ⟨α0, …, α(n−1)⟩ at level L − 1 of one leaves c.
//!
//! Why it holds: c was made by an operation of level L (or is a level-0 cell), from darts of
//! level ≤ L; later operations of higher levels add darts to c (a neighbour's split puts a
//! hanging vertex on its side) but neither remove one nor move one to another cell, and the
//! orbits ⟨α0, …, α(k−1)⟩ keep off αk and α3, so a cut (an α3 change) does not reach them. The
//! operations raise μa and μf without a split (to keep μt ≤ μf ≤ μa), so minimality is a law of
//! top cells only. What it guards: the subdivision reads a cell at its own level (`tet_corners`,
//! the `AlreadyAtLevel` guard of a split). Records that named a level at which a tet had no
//! dart or was part of a coarser tet loaded and then refused the map's own tets (338, 339); a
//! split edge whose halves said μa = 0 loaded and then let `split_edge` split a half again at
//! the level that made it, which the operation's check caught as a bug (R40-1); a μt raised
//! above the level that made a tet loaded and refused a split the original makes (R40-2).

use super::{LevelError, LeveledMap, Mu};
use crate::gmap::{AlphaMask, DartId};

impl<const N: usize> LeveledMap<N> {
    /// The resolution level of the k-cell of `d`: μa, μf, μt for k = 1, 2, 3. O(1).
    fn level_of_cell(&self, k: usize, d: DartId) -> u8 {
        let Mu { edge, face, tet } = self.mu[d.index()];
        [0, edge, face, tet][k.min(3)]
    }

    /// The own-level law (module docs), up to `limit` violations: every dimension 1..=n, then
    /// the minimality of top cells. Needs every level closed ([`Self::level_link_errors`]
    /// empty). O(n · darts · history length).
    pub(crate) fn own_level_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        for k in 1..=N.min(3) {
            let cell_mask = AlphaMask::of(&(0..=N).filter(|&j| j != k).collect::<Vec<_>>());
            for d in self.map.one_dart_per_cell(k) {
                if out.len() >= limit {
                    return out;
                }
                let level = self.level_of_cell(k, d);
                let cell = self.map.orbit(d, cell_mask);
                let Some(&start) = cell.iter().find(|x| self.dart_level[x.index()] <= level) else {
                    out.push(LevelError::NotAtOwnLevel { dim: k, dart: d, level, escape: None });
                    continue;
                };
                if let Some(y) = self.escape(k, level, start) {
                    out.push(LevelError::NotAtOwnLevel { dim: k, dart: d, level, escape: Some(y) });
                }
                if k == N && level > 0 {
                    let older = cell.iter().find(|x| self.dart_level[x.index()] < level);
                    if older.is_some_and(|&x| self.escape(k, level - 1, x).is_none()) {
                        out.push(LevelError::AboveOwnLevel { dart: d, level });
                    }
                }
            }
        }
        out.truncate(limit);
        out
    }

    /// A dart of another k-cell than `d`'s met by the orbit ⟨α0, …, α(k−1)⟩ of `d` at level
    /// `level` ([`Self::orbit_at`]), if any: the first in breadth-first order. O(orbit · history
    /// length).
    fn escape(&self, k: usize, level: u8, d: DartId) -> Option<DartId> {
        let id = self.map.cell_id(k, d);
        self.orbit_at(level, k, d).into_iter().find(|&x| self.map.cell_id(k, x) != id)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmap::GMap;

    fn refined_tet() -> LeveledMap<3> {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let mut m = LeveledMap::new(map, pts);
        let d = m.map().darts().next().unwrap();
        m.subdivide_tet(d, 1).unwrap();
        m
    }

    /// Holds after a 1→8 split; a child tet's μt lowered to 0 is named: an inner (octahedron)
    /// child has no dart of level 0, a corner child's orbit at level 0 is its parent's.
    #[test]
    fn a_child_tet_named_at_its_parents_level_is_refused() {
        let m = refined_tet();
        assert!(m.own_level_errors(usize::MAX).is_empty());
        let volumes = m.map().one_dart_per_cell(3);
        let mut found = (false, false);
        for &t in &volumes {
            let mut bad = m.clone();
            for x in bad.map.orbit(t, AlphaMask::of(&[0, 1, 2])) {
                bad.mu[x.index()].tet = 0;
            }
            let errors = bad.own_level_errors(usize::MAX);
            assert_eq!(errors.len(), 1, "{t}");
            match errors[0] {
                LevelError::NotAtOwnLevel { dim: 3, level: 0, escape: None, .. } => found.0 = true,
                LevelError::NotAtOwnLevel { dim: 3, level: 0, escape: Some(y), .. } => {
                    assert_ne!(bad.map.cell_id(3, y), bad.map.cell_id(3, t));
                    found.1 = true;
                }
                ref e => panic!("{e}"),
            }
        }
        assert_eq!(found, (true, true), "both kinds of child are met");
    }

    /// A split edge whose halves are said to be of level 0 (R40-1: `split_edge` then split a half
    /// again at level 1): the law of dimension 1 names it — at level 0 the half's α0 reaches the
    /// other half. The tet itself keeps its laws.
    #[test]
    fn a_half_edge_named_at_its_parents_level_is_refused() {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut m = LeveledMap::new(map, vec![]);
        let d = m.map().darts().next().unwrap();
        m.split_edge(d, 1).unwrap();
        assert!(m.own_level_errors(usize::MAX).is_empty());
        let mut bad = m.clone();
        let halves: Vec<usize> = (0..bad.mu.len()).filter(|&k| bad.mu[k].edge == 1).collect();
        assert_eq!(halves.len(), 8);
        halves.into_iter().for_each(|k| bad.mu[k].edge = 0);
        let errors = bad.own_level_errors(usize::MAX);
        assert!(!errors.is_empty());
        assert!(
            errors.iter().all(|e| matches!(e, LevelError::NotAtOwnLevel { dim: 1, level: 0, escape: Some(_), .. })),
            "{errors:?}"
        );
    }

    /// μt raised to 1 on a tet no operation split (R40-2: it then refused a split the original
    /// makes): minimality names it; the children of a real 1→8 split keep the law.
    #[test]
    fn a_tet_said_to_be_finer_than_it_is_is_refused() {
        let mut m = refined_tet();
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut plain = LeveledMap::new(map, vec![]);
        plain.max_level = 1;
        plain.mu.iter_mut().for_each(|mu| *mu = Mu { edge: 1, face: 1, tet: 1 });
        assert!(matches!(plain.own_level_errors(usize::MAX)[..], [LevelError::AboveOwnLevel { level: 1, .. }]));
        assert!(m.own_level_errors(usize::MAX).is_empty());
        let d = m.map().darts().find(|&x| m.dart_level(x) == 0).unwrap();
        m.subdivide_tet(d, 2).unwrap(); // a corner child, split again: its children are of level 2
        assert!(m.own_level_errors(usize::MAX).is_empty());
    }

    /// Every dart said to be of level 1 with no history: level 0 is empty, and the law names the
    /// tet (it has no dart of its own level 0).
    #[test]
    fn a_tet_with_no_dart_of_its_level_is_refused() {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut m = LeveledMap::new(map, vec![]);
        m.max_level = 1;
        m.dart_level.iter_mut().for_each(|l| *l = 1);
        let errors = m.own_level_errors(usize::MAX);
        assert!(errors.iter().all(|e| matches!(e, LevelError::NotAtOwnLevel { level: 0, escape: None, .. })));
        // Every edge, face and the volume: 6 + 4 + 1 cells, none with a dart of level 0.
        assert_eq!(errors.len(), 11, "{errors:?}");
        assert!(matches!(m.check_all(), Err(LevelError::NotAtOwnLevel { .. })));
    }
}

//! The own-level law (findings 338, 339): every top cell of the finest map (a volume in 3D, a
//! face in 2D) is a cell of the level its resolution level names. With L = μt (μf in 2D, μa in
//! 1D) of a top cell c, c has a dart of level ≤ L, and the orbit ⟨α0, …, α(n−1)⟩ at level L from
//! such a dart stays inside c.
//!
//! Why it holds: c was made by an operation of level L (or is a level-0 cell), from darts of
//! level ≤ L; later operations of higher levels add darts to c (a neighbour's split puts a
//! hanging vertex on its side) but neither remove one nor move one to another cell, and a cut
//! (an α3 change) is no generator of a volume. What it guards: the subdivision reads a tet at
//! its own level (`tet_corners`), so records that name a level at which the cell has no dart,
//! or at which it is part of a coarser cell, made every later operation on the cell fail or
//! read the coarser cell's corners (a file whose μ said 0 after a 1→8 split, or whose darts all
//! said level 1, loaded and then refused its own tets).

use super::{LevelError, LeveledMap, Mu};
use crate::gmap::{AlphaMask, DartId};

impl<const N: usize> LeveledMap<N> {
    /// The resolution level of the top cell of `d`: μt in 3D, μf in 2D, μa in 1D. O(1).
    fn top_level(&self, d: DartId) -> u8 {
        let Mu { edge, face, tet } = self.mu[d.index()];
        match N {
            1 => edge,
            2 => face,
            _ => tet,
        }
    }

    /// The own-level law (module docs), up to `limit` violations. Needs every level closed
    /// ([`Self::level_link_errors`] empty). O(darts · history length).
    pub(crate) fn own_level_errors(&self, limit: usize) -> Vec<LevelError> {
        let mut out = Vec::new();
        let inside = AlphaMask::of(&(0..N).collect::<Vec<_>>());
        for d in self.map.one_dart_per_cell(N) {
            if out.len() >= limit {
                break;
            }
            let level = self.top_level(d);
            let cell = self.map.orbit(d, inside);
            let Some(&start) = cell.iter().find(|x| self.dart_level[x.index()] <= level) else {
                out.push(LevelError::NotAtOwnLevel { dart: d, level, escape: None });
                continue;
            };
            let id = self.map.cell_id(N, d);
            let escape = self.orbit_below_top(level, start).into_iter().find(|&y| self.map.cell_id(N, y) != id);
            if let Some(y) = escape {
                out.push(LevelError::NotAtOwnLevel { dart: d, level, escape: Some(y) });
            }
        }
        out
    }

    /// The orbit ⟨α0, …, α(n−1)⟩ of `d` at level `level`. O(orbit · history length).
    fn orbit_below_top(&self, level: u8, d: DartId) -> Vec<DartId> {
        let mut seen = std::collections::BTreeSet::from([d]);
        let mut out = vec![d];
        let mut k = 0;
        while k < out.len() {
            let x = out[k];
            k += 1;
            for j in 0..N {
                let y = self.alpha_at(level, j, x);
                if seen.insert(y) {
                    out.push(y);
                }
            }
        }
        out
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
                LevelError::NotAtOwnLevel { level: 0, escape: None, .. } => found.0 = true,
                LevelError::NotAtOwnLevel { level: 0, escape: Some(y), .. } => {
                    assert_ne!(bad.map.cell_id(3, y), bad.map.cell_id(3, t));
                    found.1 = true;
                }
                ref e => panic!("{e}"),
            }
        }
        assert_eq!(found, (true, true), "both kinds of child are met");
    }

    /// Every dart said to be of level 1 with no history: level 0 is empty, and the law names the
    /// tet (it has no dart of its own level 0).
    #[test]
    fn a_tet_with_no_dart_of_its_level_is_refused() {
        let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
        let mut m = LeveledMap::new(map, vec![]);
        m.max_level = 1;
        m.dart_level.iter_mut().for_each(|l| *l = 1);
        assert!(matches!(m.own_level_errors(1)[..], [LevelError::NotAtOwnLevel { level: 0, escape: None, .. }]));
        assert!(matches!(m.check_all(), Err(LevelError::NotAtOwnLevel { .. })));
    }
}

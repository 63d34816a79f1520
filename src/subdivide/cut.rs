//! Cutting a face of a leveled 3-map: α3-unsewing one face at a level, recorded like the links a
//! subdivision changes, so the coarser levels keep the face glued and every G_i stays exact.
//!
//! ```text
//!   level L − 1:  A | B   (glued through f)        level ≥ L:  A ‖ B   (f cut: two boundary sides)
//! ```
//! The vertices and edges the cut separates get fresh cell ids (the usual local relabelling of
//! the operations); a fresh vertex takes the position of the vertex it was split from.

use super::{LeveledMap, SubdivideError};
use crate::gmap::{AlphaMask, DartId};

impl LeveledMap<3> {
    /// Cuts the finest-level face of `d` at level `level`: every dart of its side (the ⟨α0, α1⟩
    /// orbit of d) is α3-unlinked from the other side. G_i for i < `level` still has the face
    /// glued; G_i for i ≥ `level` has it cut. Returns the number of darts unlinked on the side of
    /// d. O(face + touched cells).
    ///
    /// Errors: the level-order errors ([`SubdivideError::LevelTooHigh`],
    /// [`SubdivideError::LevelBelowMax`]), [`SubdivideError::NoPosition`] (points are given but
    /// not for some live vertex; a map without points is accepted), then
    /// [`SubdivideError::NoSuchDart`] and [`SubdivideError::FaceNotSewn`] (some dart of the face
    /// is α3-free). The map is unchanged on error.
    ///
    /// ```
    /// use topomech::gmap::{DartId, GMap};
    /// use topomech::subdivide::LeveledMap;
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let mut m = LeveledMap::new(map, vec![]);
    /// let glued = m.map().darts().find(|&d| !m.map().is_free(3, d)).unwrap();
    /// assert_eq!(m.unsew_face(glued, 1).unwrap(), 6);
    /// assert_eq!(m.level(0).unwrap().map.count_cells().0[0], 5); // still glued at level 0
    /// assert_eq!(m.level(1).unwrap().map.count_cells().0[0], 8); // cut at level 1
    /// ```
    pub fn unsew_face(&mut self, d: DartId, level: u8) -> Result<usize, SubdivideError> {
        self.check_op_level(level)?;
        if !self.map.contains(d) {
            return Err(SubdivideError::NoSuchDart(d));
        }
        let side = self.map.orbit(d, AlphaMask::of(&[0, 1]));
        if let Some(&x) = side.iter().find(|&&x| self.map.is_free(3, x)) {
            return Err(SubdivideError::FaceNotSewn(x));
        }
        // (dart, its vertex id, its position) on both sides, before the cut: `finish` records
        // the copies among them before it checks the laws.
        let before: Vec<(DartId, u32, [f64; 3])> = side
            .iter()
            .flat_map(|&x| [x, self.map.alpha::<3>(x)])
            .map(|x| (x, self.map.vertex_id(x).0, self.position(x)))
            .collect();
        self.begin(level);
        self.op.cut_darts = before;
        for &x in &side {
            self.unlink(3, x);
        }
        self.finish();
        Ok(side.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gmap::GMap;

    fn two_tets() -> LeveledMap<3> {
        let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).expect("builds");
        LeveledMap::new(map, points)
    }

    fn glued(m: &LeveledMap<3>) -> DartId {
        m.map().darts().find(|&d| !m.map().is_free(3, d)).expect("a glued face")
    }

    #[test]
    fn a_cut_face_stays_glued_below_its_level_and_split_vertices_keep_their_positions() {
        let mut m = two_tets();
        m.subdivide_tet(DartId(0), 1).expect("subdivides");
        let before = m.map().clone();
        let positions: Vec<(DartId, [f64; 3])> = before.darts().map(|x| (x, m.position(x))).collect();
        let d = glued(&m);
        m.unsew_face(d, 2).expect("cuts");
        m.check_all().expect("every level valid");
        let g1 = m.level(1).expect("level 1").map;
        assert!(g1.is_isomorphic(&before), "G_1 is the map before the cut");
        assert!(!m.level(2).expect("level 2").map.is_isomorphic(&before));
        assert!(m.map().count_cells().0[0] > before.count_cells().0[0], "the cut split vertices");
        for (x, p) in positions {
            assert_eq!(m.position(x), p, "the vertex of {x:?} kept its position");
        }
    }

    #[test]
    fn bad_cuts_are_errors_and_change_nothing() {
        let mut m = two_tets();
        let free = m.map().darts().find(|&d| m.map().is_free(3, d)).expect("a boundary face");
        assert_eq!(m.unsew_face(free, 0), Err(SubdivideError::FaceNotSewn(free)));
        m.subdivide_tet(DartId(0), 2).expect("subdivides");
        let d = glued(&m);
        assert_eq!(m.unsew_face(d, 1), Err(SubdivideError::LevelBelowMax { level: 1, max_level: 2 }));
        assert_eq!(m.unsew_face(DartId(1_000_000), 2), Err(SubdivideError::NoSuchDart(DartId(1_000_000))));
        assert!(!m.map().is_free(3, d));
    }
}

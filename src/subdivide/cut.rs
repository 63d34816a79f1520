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
    /// Errors: [`SubdivideError::NoSuchDart`], the level-order errors
    /// ([`SubdivideError::LevelBelowMax`], [`SubdivideError::LevelTooHigh`]),
    /// [`SubdivideError::FaceNotSewn`] (some dart of the face is α3-free). The map is unchanged on
    /// error.
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
        let positions: Vec<(DartId, [f64; 3])> =
            side.iter().flat_map(|&x| [x, self.map.alpha::<3>(x)]).map(|x| (x, self.position(x))).collect();
        self.begin(level);
        for &x in &side {
            self.unlink(3, x);
        }
        self.finish();
        if !self.points.is_empty() {
            for (x, p) in positions {
                let v = self.map.vertex_id(x).index();
                if self.points.len() <= v {
                    self.points.resize(v + 1, [0.0; 3]);
                }
                self.points[v] = p;
            }
        }
        Ok(side.len())
    }
}

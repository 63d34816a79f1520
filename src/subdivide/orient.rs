//! Whether the children of a 1→8 split keep their parent's orientation once their midpoints are
//! rounded to `f64` (finding 247).
//!
//! With exact midpoints every child of the regular 1→8 split has volume V/8 and the parent's
//! orientation, whichever diagonal splits the octahedron (its three diagonals cross at the
//! centroid). Rounded midpoints move each child corner by at most δ = ε·|x|: a tet valid but
//! nearly flat at its scale — corners within a few ulps of a plane — gives children that are
//! flat or inverted and would keep a share of the mass. The test here: a float filter that
//! accepts every tet whose volume is large against the worst change δ can make (every ordinary
//! tet, in O(1)), and otherwise the exact orientation (`crate::exact::orient3d`) of the 4
//! corner children and the 4 children around each of the 3 diagonals, each compared with the
//! parent's; a parent that is exactly flat has no orientation to keep and is accepted, as
//! before.

use super::tet::{child_tets, mid_label};
use super::{LeveledMap, SubdivideError};
use crate::exact::orient3d;
use crate::gmap::DartId;

type Vec3 = [f64; 3];

/// The corners (labels 0..3) and the rounded edge midpoints (label 4 + pair index) of the 1→8
/// split of the tet with corner positions `p`, as the operations place them
/// (`crate::mesh::midpoint`). O(1).
fn split_points(p: [Vec3; 4]) -> [Vec3; 10] {
    let mut out = [[0.0; 3]; 10];
    out[..4].copy_from_slice(&p);
    for x in 0..4u8 {
        for y in x + 1..4 {
            out[mid_label(x, y) as usize] = crate::mesh::midpoint(p[x as usize], p[y as usize]);
        }
    }
    out
}

/// Whether the float filter settles it: |det| of the parent (6V) exceeds, with a factor of 4
/// to spare, 8 × the largest change rounded midpoints can make to a child's det (each of its
/// corners moved by at most δ = ε·max|x| + the smallest normal: ≤ 3 · 2√3δ · (L + 4δ)² for
/// edges at most L) plus the float error of the det itself (≤ 8ε · 6L³). Infinite or NaN
/// terms fail it (the exact test decides). O(1).
fn clearly_kept(p: [Vec3; 4]) -> bool {
    let eps = f64::EPSILON;
    let m = p.iter().flatten().fold(0.0f64, |a, c| a.max(c.abs()));
    let delta = eps * m + f64::MIN_POSITIVE;
    let mut l2 = 0.0f64;
    for x in 0..4 {
        for y in x + 1..4 {
            l2 = l2.max((0..3).map(|k| (p[x][k] - p[y][k]).powi(2)).sum());
        }
    }
    let l = l2.sqrt();
    let child_change = 3.0 * 2.0 * 3f64.sqrt() * delta * (l + 4.0 * delta).powi(2);
    let bound = 4.0 * (8.0 * child_change + 48.0 * eps * l * l2);
    // 6V in floats (the plain determinant; its error, and that of ×6 and ÷6, is in the bound).
    (6.0 * crate::mesh::signed_volume(p[0], p[1], p[2], p[3])).abs() > bound
}

/// `Err(child)` with the labels of the first child of the 1→8 split of the tet with corner
/// positions `p` whose rounded corners are flat or oriented against the parent, for any of the
/// three diagonals (so the choice of diagonal, which ties can leave to vertex ids, does not
/// matter); `Ok` when every child keeps the parent's orientation, or the parent is exactly flat.
/// O(1): a float filter, then at most 16 exact orientations.
pub(super) fn children_keep_orientation(p: [Vec3; 4]) -> Result<(), [u8; 4]> {
    if clearly_kept(p) {
        return Ok(());
    }
    let parent = orient3d(p[0], p[1], p[2], p[3]);
    if parent == 0 {
        return Ok(());
    }
    // The signs the children have, label for label, for exact midpoints: read off a reference
    // tet whose midpoints f64 holds exactly.
    let reference = split_points([[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]);
    let ref_parent = orient3d(reference[0], reference[1], reference[2], reference[3]);
    let points = split_points(p);
    let sign =
        |q: &[Vec3; 10], t: [u8; 4]| orient3d(q[t[0] as usize], q[t[1] as usize], q[t[2] as usize], q[t[3] as usize]);
    for diag in [4u8, 5, 6] {
        for t in child_tets(diag) {
            let want = sign(&reference, t) * ref_parent * parent;
            if sign(&points, t) != want {
                return Err(t);
            }
        }
    }
    Ok(())
}

impl<const N: usize> LeveledMap<N> {
    /// [`SubdivideError::FlatChild`] when a child of the 1→8 split of the tet of `d` (corner
    /// vertex ids `corners`) would be flat or inverted once its midpoints are rounded
    /// ([`super::orient::children_keep_orientation`]). Nothing is checked on a map without the
    /// corners' positions. O(1).
    pub(super) fn check_children(&self, d: DartId, level: u8, corners: &[u32; 4]) -> Result<(), SubdivideError> {
        let p = corners.map(|v| self.points.get(v as usize).copied());
        let [Some(a), Some(b), Some(c), Some(e)] = p else { return Ok(()) };
        super::orient::children_keep_orientation([a, b, c, e]).map_err(|child| SubdivideError::FlatChild {
            level,
            dart: d,
            corners: *corners,
            child,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_tets_pass_the_filter_and_flat_ones_do_not() {
        let unit = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(clearly_kept(unit));
        let far = unit.map(|c| c.map(|x| x + 1e6));
        assert!(clearly_kept(far) && children_keep_orientation(far).is_ok());
        // Corners within a few ulps of the plane z = 1 across 2 units: the filter cannot tell.
        let thin = [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 2.0, 1.0], [1.0, 1.0, 1.0 + 4.0 * f64::EPSILON]];
        assert!(!clearly_kept(thin));
        assert!(orient3d(thin[0], thin[1], thin[2], thin[3]) != 0, "valid");
    }

    #[test]
    fn an_exactly_flat_tet_has_no_orientation_to_keep() {
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert_eq!(children_keep_orientation(flat), Ok(()));
    }

    #[test]
    fn every_child_of_the_reference_tet_is_positive_against_its_parent() {
        let p = [[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]];
        let q = split_points(p);
        for diag in [4u8, 5, 6] {
            for t in child_tets(diag) {
                let s = orient3d(q[t[0] as usize], q[t[1] as usize], q[t[2] as usize], q[t[3] as usize]);
                assert_ne!(s, 0, "child {t:?} of diagonal {diag} is flat");
            }
        }
    }
}

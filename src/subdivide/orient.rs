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
//!
//! The same holds for the 1→4 split of a triangle in a 2-G-map (the four children have the
//! parent's orientation for exact midpoints): there the orientation is that of the projection
//! onto a coordinate plane, the one where the parent's normal is largest, so a planar mesh in any
//! plane z = c is checked by its plain 2D orientation, and a surface triangle in 3D by its
//! dominant projection.

use super::tet::{child_tets, mid_label};
use super::{LeveledMap, SubdivideError};
use crate::exact::{det_sign, orient3d};
use crate::gmap::DartId;
use std::cmp::Ordering;

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

/// The four children of the 1→4 split of a triangle: labels 0..2 its corners, 3 + k the midpoint
/// of its side k = (k, k + 1 mod 3). Each is listed so that, for exact midpoints, it has the
/// parent's orientation: the three corner children are the parent halved towards a corner, the
/// central one the parent halved and turned by a half-turn.
pub(super) const TRIANGLE_CHILDREN: [[u8; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];

/// The exact sign of the `k`-th component of (b − a) × (c − a): the orientation of the triangle
/// projected onto the coordinate plane orthogonal to axis `k` (0 when it is collinear there or a
/// coordinate is not finite). It is det[b − a, c − a, e_k] ([`crate::exact`]). O(1).
fn orient_on_axis(a: Vec3, b: Vec3, c: Vec3, k: usize) -> i8 {
    let mut e = [0.0; 3];
    e[k] = 1.0;
    match det_sign([&[(false, b), (true, a)], &[(false, c), (true, a)], &[(false, e)]]) {
        Some(Ordering::Greater) => 1,
        Some(Ordering::Less) => -1,
        _ => 0,
    }
}

/// Whether the float filter settles the triangle case: |n_k| (the parent's normal on the axis of
/// the check, twice its projected area) exceeds, with a factor of 4 to spare, 4 × the largest
/// change rounded midpoints can make to a child's n_k (each child corner moved by at most
/// δ = ε·max|x| + the smallest normal per coordinate, edges at most L: ≤ 6δ(L + 4δ)) plus the
/// float error of n_k itself (≤ 8εL²), plus an allowance for products lost to underflow.
/// Infinite or NaN terms fail it (the exact test decides). O(1).
fn triangle_clearly_kept(p: [Vec3; 3], nk: f64) -> bool {
    let eps = f64::EPSILON;
    let m = p.iter().flatten().fold(0.0f64, |a, c| a.max(c.abs()));
    let delta = eps * m + f64::MIN_POSITIVE;
    let mut l2 = 0.0f64;
    for x in 0..3 {
        let y = (x + 1) % 3;
        l2 = l2.max((0..3).map(|k| (p[x][k] - p[y][k]).powi(2)).sum());
    }
    let child_change = 6.0 * delta * (l2.sqrt() + 4.0 * delta);
    let bound = 4.0 * (4.0 * child_change + 8.0 * eps * l2) + 1e-290;
    nk.abs() > bound
}

/// 2⁻⁹⁰⁰: the largest component of a plain float normal must reach it to name the axis of the
/// check; far above the subnormals, the products' underflow (at most 2⁻¹⁰⁷⁴ each) cannot move
/// the order of the components that matter.
const PLAIN_NORMAL_MIN: f64 = 1.1830521861667747e-271; // 2⁻⁹⁰⁰

/// |(b − a) × (c − a)| component by component, in floats, for the corners `p` as they are. O(1).
fn normal_magnitudes(p: [Vec3; 3]) -> [f64; 3] {
    let u: Vec3 = std::array::from_fn(|k| p[1][k] - p[0][k]);
    let v: Vec3 = std::array::from_fn(|k| p[2][k] - p[0][k]);
    [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]].map(f64::abs)
}

/// `Err(child)` with the labels ([`TRIANGLE_CHILDREN`]) of the first child of the 1→4 split of
/// the triangle with corners `p` that is collinear or oriented against the parent in the
/// projection onto the coordinate plane where the parent's float normal is largest (if the
/// parent's projection there is exactly collinear, the next largest where it is not; a normal
/// that overflows or underflows in plain floats is taken on the corners rescaled by a power of
/// two, finding 277); `Ok` when every child keeps the parent's orientation there, or the parent
/// is exactly collinear (no orientation to keep). `mids[k]` is the position of side k's midpoint (side k = (k, k + 1
/// mod 3)), `None` for the rounded midpoint of its ends (`crate::mesh::midpoint`, where the
/// split puts a new vertex). With rounded midpoints a float filter decides ordinary triangles;
/// other midpoints are always checked exactly. O(1): a float filter, then at most 7 exact
/// orientations.
pub(super) fn triangle_children_keep_orientation(p: [Vec3; 3], mids: [Option<Vec3>; 3]) -> Result<(), [u8; 3]> {
    let mut n = normal_magnitudes(p);
    // A plain normal that overflowed (∞, NaN) or fell near the subnormals (0 for a triangle
    // far from collinear) names no axis: it is taken again on the corners translated and
    // scaled by a power of two (finding 277), and then only the exact signs decide.
    let plain = n.iter().all(|c| c.is_finite()) && n.iter().any(|&c| c >= PLAIN_NORMAL_MIN);
    if !plain {
        let mut fitted = p;
        crate::mesh::fit_for_products(&mut fitted);
        n = normal_magnitudes(fitted);
    }
    let top = if n[0] >= n[1] && n[0] >= n[2] {
        0
    } else if n[1] >= n[2] {
        1
    } else {
        2
    };
    let rounded_mid = |k: usize| crate::mesh::midpoint(p[k], p[(k + 1) % 3]);
    let rounded = mids.iter().enumerate().all(|(k, m)| m.is_none_or(|q| q == rounded_mid(k)));
    if plain && rounded && triangle_clearly_kept(p, n[top]) {
        return Ok(());
    }
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&x, &y| n[y].total_cmp(&n[x]));
    let found = axes.iter().find_map(|&k| {
        let s = orient_on_axis(p[0], p[1], p[2], k);
        (s != 0).then_some((k, s))
    });
    let Some((k, parent)) = found else { return Ok(()) };
    let placed: [Vec3; 3] = std::array::from_fn(|k| mids[k].unwrap_or_else(|| rounded_mid(k)));
    let points = [p[0], p[1], p[2], placed[0], placed[1], placed[2]];
    for t in TRIANGLE_CHILDREN {
        let [a, b, c] = t.map(|l| points[l as usize]);
        if orient_on_axis(a, b, c, k) != parent {
            return Err(t);
        }
    }
    Ok(())
}

impl<const N: usize> LeveledMap<N> {
    /// [`SubdivideError::FlatTriangleChild`] when a child of the 1→4 split of the triangle of
    /// `d` (corner vertex ids `corners`, in the order of its sides) would be collinear or
    /// inverted with its midpoints placed: `mids[k]` is the position of side k's inserted vertex
    /// when it has one (`None`: the rounded midpoint the split will insert)
    /// ([`triangle_children_keep_orientation`]). Nothing is checked on a map without the
    /// corners' positions. O(1).
    pub(super) fn check_triangle_children(
        &self,
        d: DartId,
        level: u8,
        corners: [u32; 3],
        mids: [Option<Vec3>; 3],
    ) -> Result<(), SubdivideError> {
        let p = corners.map(|v| self.points.get(v as usize).copied());
        let [Some(a), Some(b), Some(c)] = p else { return Ok(()) };
        triangle_children_keep_orientation([a, b, c], mids).map_err(|child| SubdivideError::FlatTriangleChild {
            level,
            dart: d,
            corners,
            child,
        })
    }

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

    /// The listed children have the parent's orientation for exact midpoints, on every axis and
    /// for both orientations of the parent.
    #[test]
    fn every_child_of_a_reference_triangle_keeps_its_orientation() {
        for k in 0..3 {
            let lift = |x: f64, y: f64| -> Vec3 {
                let mut q = [5.0; 3];
                q[(k + 1) % 3] = x;
                q[(k + 2) % 3] = y;
                q
            };
            for p in
                [[lift(0.0, 0.0), lift(4.0, 0.0), lift(0.0, 4.0)], [lift(0.0, 0.0), lift(0.0, 4.0), lift(4.0, 0.0)]]
            {
                let mids = [0, 1, 2].map(|s| crate::mesh::midpoint(p[s], p[(s + 1) % 3]));
                let parent = orient_on_axis(p[0], p[1], p[2], k);
                assert_ne!(parent, 0);
                let points = [p[0], p[1], p[2], mids[0], mids[1], mids[2]];
                for t in TRIANGLE_CHILDREN {
                    let [a, b, c] = t.map(|l| points[l as usize]);
                    assert_eq!(orient_on_axis(a, b, c, k), parent, "child {t:?} on axis {k}");
                }
                assert_eq!(triangle_children_keep_orientation(p, [None; 3]), Ok(()));
                assert_eq!(triangle_children_keep_orientation(p, mids.map(Some)), Ok(()));
                assert!(triangle_clearly_kept(p, (4.0 * 4.0) * parent as f64));
            }
        }
    }

    #[test]
    fn a_thin_triangle_is_decided_exactly_and_a_collinear_one_is_kept() {
        let ulp = f64::EPSILON;
        // Corners within an ulp of the line y = 1 across 2 units: the filter cannot tell.
        let thin = [[1.0, 1.0, 0.0], [3.0, 1.0, 0.0], [2.0, 1.0 + ulp, 0.0]];
        let n = (thin[1][0] - thin[0][0]) * (thin[2][1] - thin[0][1]);
        assert!(!triangle_clearly_kept(thin, n));
        // The midpoint of sides 1 and 2 round onto y = 1 (1 + ulp/2 is not an f64 above 1):
        // the corner child at corner 2 keeps its height, the others go flat.
        assert!(triangle_children_keep_orientation(thin, [None; 3]).is_err());
        let line = [[0.0; 3], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(triangle_children_keep_orientation(line, [None; 3]), Ok(()));
        // A midpoint moved off its place is checked exactly, filter or not.
        let big = [[0.0; 3], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        assert_eq!(triangle_children_keep_orientation(big, [None; 3]), Ok(()));
        assert_eq!(triangle_children_keep_orientation(big, [Some([-1.0, 0.0, 0.0]), None, None]), Err([0, 3, 5]));
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

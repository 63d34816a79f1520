//! Incision by a plane: the face-separation approach (every inner face whose two tets lie on
//! opposite sides is dissociated; a tet's side is its centroid's).

use crate::mechanics::{Body, TouchedCells, Vec3};
use crate::{CellId, DartId};

use std::cmp::Ordering;

use super::{dissociate_face, CutError, Dissociation};
use crate::exact::plane_sign;

/// A cutting plane through `point` with normal `normal` (any length but zero).
///
/// # Examples
///
/// ```
/// use topomech::cut::Plane;
///
/// // The plane z = 1, positive side above.
/// let plane = Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 0.0, 1.0] };
/// assert!(plane.positive([0.3, 0.7, 2.0]));
/// assert!(!plane.positive([0.3, 0.7, 0.0]));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point of the plane.
    pub point: Vec3,
    /// Its normal; the positive side is where (x − point)·normal > 0 (a point on the plane is on
    /// the negative side, [`Plane::positive`]).
    pub normal: Vec3,
}

impl Plane {
    /// Whether `x` is strictly on the positive side: (x − point) · normal > 0, decided exactly.
    /// O(1).
    ///
    /// The sign is that of the exact real number (x − point) · normal formed from the `f64`
    /// inputs, never of a rounded one (`src/exact.rs`: a float evaluation with
    /// a forward error bound decides unless the value is within that bound of zero, then an
    /// exact fixed-point sum of the products decides). So the tie rule holds exactly: a point
    /// exactly on the plane is *not* positive, i.e. it is on the negative side, and a point one
    /// ulp off it is on the side it is on. [`incise_plane`] cuts a glued face when exactly one
    /// of its two tets is positive, so a tet whose centroid is on the plane goes with the tets
    /// below it. (Conformance vectors never rely on this rule: their planes keep every live
    /// centroid at least [`PLANE_MARGIN`](crate::conformance::PLANE_MARGIN) × the bounding-box
    /// diagonal away, and a vector that does not is refused as ambiguous;
    /// `docs/CONFORMANCE.md`.)
    ///
    /// Being exact, the answer depends only on the plane as a point set and on which side the
    /// normal points to: normals that are exact positive multiples of each other give the same
    /// side for every point, whatever the factor (2^k, or 0.1, 1/3 … whenever c·n is
    /// representable, e.g. `[-2.0, -1.0, -2.0]` and `[-0.2, -0.1, -0.2]`, the latter exactly
    /// f64(0.1) times the former). A normal scaled in floating point is rounded component by
    /// component and then is, in general, a slightly different plane: the decision is exact
    /// for the plane given. Nothing depends on the scale of the coordinates either: nothing is
    /// rounded, so nothing underflows (a normal `[5e-324, 0, 0]`) or overflows (coordinates and
    /// normals up to ±`f64::MAX`). A non-finite `x`, point or normal gives `false`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::Plane;
    ///
    /// let plane = Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 0.0, 2.0] };
    /// assert!(plane.positive([5.0, 5.0, 1.5]));
    /// assert!(!plane.positive([0.0, 0.0, 1.0])); // on the plane: not strictly positive
    /// assert!(!plane.positive([0.0, 0.0, -3.0]));
    /// // The smallest normal and the largest one give the same sides.
    /// let tiny = Plane { point: [1.0; 3], normal: [5e-324, 0.0, 0.0] };
    /// assert!(tiny.positive([1.25, 0.0, 0.0]) && !tiny.positive([0.75, 0.0, 0.0]));
    /// let huge = Plane { point: [1.0; 3], normal: [f64::MAX, -f64::MAX, 0.0] };
    /// assert!(huge.positive([4.0, 3.0, 1.0])); // 3·MAX − 2·MAX > 0, unscaled ∞ − ∞ = NaN
    /// // (1.25, 2.5, 3.75) is exactly on this plane: (−1.5)(−0.2) + 2(−0.1) + 0.5(−0.2) = 0 in
    /// // the f64 values; the rounded dot product says 2.8e-17 ("positive").
    /// let decimal = Plane { point: [2.75, 0.5, 3.25], normal: [-0.2, -0.1, -0.2] };
    /// assert!(!decimal.positive([1.25, 2.5, 3.75]));
    /// ```
    pub fn positive(&self, x: Vec3) -> bool {
        plane_sign(&[x], self.point, self.normal) == Some(Ordering::Greater)
    }

    /// [`CutError::BadPlane`] unless the point and normal are finite and the normal is not zero.
    pub(crate) fn check(&self) -> Result<(), CutError> {
        let finite = self.point.iter().chain(&self.normal).all(|c| c.is_finite());
        if !finite || self.normal.iter().all(|&c| c == 0.0) {
            return Err(CutError::BadPlane { point: self.point, normal: self.normal });
        }
        Ok(())
    }
}

/// What an incision did.
///
/// # Examples
///
/// ```
/// use topomech::cut::{components, incise_plane, Plane};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let cut = incise_plane(&mut body, &Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 0.0, 1.0] }).unwrap();
/// assert!(!cut.dissociations.is_empty());
/// assert_eq!(components(&body).len(), 2); // the plane z = 1 crosses the whole cube
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Incision {
    /// One dissociation per cut face, in face order.
    pub dissociations: Vec<Dissociation>,
    /// Everything the projection must re-read.
    pub touched: TouchedCells,
}

impl Incision {
    /// Number of faces cut. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::{incise_plane, Plane};
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mechanics::{Body, Material};
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
    /// let cut = incise_plane(&mut body, &Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 0.0, 1.0] }).unwrap();
    /// assert_eq!(cut.cut_faces(), cut.dissociations.len());
    /// assert_eq!(body.map().boundary_cell_count(), 48 + 2 * cut.cut_faces()); // both sides of each cut face
    /// ```
    pub fn cut_faces(&self) -> usize {
        self.dissociations.len()
    }
}

/// For every live volume id, whether its centroid (the exact mean of its distinct vertices'
/// current positions) is strictly on the positive side of `plane`; `None` for dead ids.
/// O(darts).
///
/// The side is decided exactly from the corners, without forming a rounded centroid: it is the
/// sign of Σ_corners (c − point) · normal = k · (centroid − point) · normal (k distinct
/// corners), evaluated exactly as in [`Plane::positive`] (float filter, exact fallback). So a
/// tet whose exact centroid is on the plane is on the negative side, and the answer depends
/// neither on the length of the normal (exact multiples, [`Plane::positive`]) nor on how the
/// points or the tets are numbered (no summation order enters an exact sum).
///
/// # Errors
/// [`CutError::NonFinitePosition`] for the smallest live vertex with a NaN or infinite position
/// (its tets have no side).
///
/// # Examples
///
/// ```
/// use topomech::cut::{tet_sides, Plane};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(2);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let sides = tet_sides(&body, &Plane { point: [0.0, 0.0, 1.0], normal: [0.0, 0.0, 1.0] }).unwrap();
/// assert_eq!(sides.iter().filter(|s| **s == Some(true)).count(), 24); // the upper layer
/// assert_eq!(sides.iter().filter(|s| **s == Some(false)).count(), 24);
/// ```
pub fn tet_sides(body: &Body, plane: &Plane) -> Result<Vec<Option<bool>>, CutError> {
    check_positions_finite(body)?;
    let (map, mech) = (body.map(), body.attrs());
    let mut side = vec![None; map.cell_id_bound(3)];
    let mut ids: Vec<CellId> = Vec::with_capacity(24);
    let mut corners: Vec<Vec3> = Vec::with_capacity(4);
    for d in map.one_dart_per_cell(3) {
        ids.clear();
        ids.extend(map.cell_darts(3, d).into_iter().map(|x| map.vertex_id(x)));
        ids.sort_unstable();
        ids.dedup();
        corners.clear();
        corners.extend(ids.iter().map(|&v| mech.position[v]));
        let positive = plane_sign(&corners, plane.point, plane.normal) == Some(Ordering::Greater);
        side[map.cell_id(3, d).index()] = Some(positive);
    }
    Ok(side)
}

/// [`CutError::NonFinitePosition`] for the smallest live vertex id whose position is NaN or
/// infinite. O(darts).
pub(crate) fn check_positions_finite(body: &Body) -> Result<(), CutError> {
    let (map, x) = (body.map(), body.attrs().position());
    let bad = map
        .one_dart_per_cell(0)
        .into_iter()
        .map(|d| map.vertex_id(d))
        .filter(|&v| !x[v].iter().all(|c| c.is_finite()))
        .min();
    bad.map_or(Ok(()), |vertex| Err(CutError::NonFinitePosition { vertex, position: x[vertex] }))
}

/// For every volume id, the centroid of the live volume (mean of its distinct vertices' current
/// positions), `None` for dead ids; [`CutError::NonFinitePosition`] as [`check_positions_finite`]
/// (a NaN centroid would put its tet on a side at random). O(darts).
pub(crate) fn tet_centroids(body: &Body) -> Result<Vec<Option<Vec3>>, CutError> {
    check_positions_finite(body)?;
    let (map, mech) = (body.map(), body.attrs());
    let mut centroid = vec![None; map.cell_id_bound(3)];
    for d in map.one_dart_per_cell(3) {
        let mut ids: Vec<CellId> = map.cell_darts(3, d).into_iter().map(|x| map.vertex_id(x)).collect();
        ids.sort_unstable();
        ids.dedup();
        let mut c = [0.0; 3];
        for v in &ids {
            for (c, p) in c.iter_mut().zip(mech.position[*v]) {
                *c += p / ids.len() as f64;
            }
        }
        centroid[map.cell_id(3, d).index()] = Some(c);
    }
    Ok(centroid)
}

/// Dissociates every inner face whose two tets' centroids lie on opposite sides of `plane`, as
/// [`tet_sides`] decides them: exactly, on the exact centroids (a centroid on the plane is on
/// the negative side, so such a face is cut when the other centroid is on the positive side)
/// (seed §3.2 face separation; a precise cut through tets needs refinement). The faces are found
/// first, then dissociated one by one, so the result does not depend on the order of
/// dissociation; and the set of faces cut (as vertex-position triples) depends only on the
/// geometry: not on the numbering of the points or the tets, nor on the length of the normal.
///
/// Cost: O(darts) to classify, plus one [`dissociate_face`] per cut face.
///
/// # Errors
/// [`CutError::BadPlane`], [`CutError::NonFinitePosition`] (body unchanged); [`CutError::Body`]
/// is a bug.
///
/// # Examples
///
/// ```
/// use topomech::cut::{components, incise_plane, Plane};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// // Split the 2×2×2 cube along x = 1.
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let cut = incise_plane(&mut body, &Plane { point: [1.0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] }).unwrap();
/// assert_eq!(cut.cut_faces(), 8); // 4 unit squares, 2 triangles each
/// let parts = components(&body);
/// assert_eq!(parts.len(), 2);
/// assert!(parts.iter().all(|p| p.volumes == 24 && (p.mass - 4.0).abs() < 1e-9));
/// ```
pub fn incise_plane(body: &mut Body, plane: &Plane) -> Result<Incision, CutError> {
    plane.check()?;
    let side = tet_sides(body, plane)?;
    let map = body.map();
    let faces: Vec<DartId> = map
        .one_dart_per_cell(2)
        .into_iter()
        .filter(|&d| {
            let other = map.alpha::<3>(d);
            other != d && side[map.cell_id(3, d).index()] != side[map.cell_id(3, other).index()]
        })
        .collect();
    dissociate_all(body, faces)
}

/// Dissociates `faces` (one dart each, all inner) in order and gathers what they did: the common
/// tail of the incisions. O(Σ dissociation costs).
pub(crate) fn dissociate_all(body: &mut Body, faces: Vec<DartId>) -> Result<Incision, CutError> {
    let mut out = Incision { dissociations: Vec::with_capacity(faces.len()), touched: TouchedCells::default() };
    let from = body.version();
    for d in faces {
        let dis = dissociate_face(body, d)?;
        out.touched.extend(&dis.touched);
        out.dissociations.push(dis);
    }
    out.touched.cover(body, from);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The side rule is strict: a point on the plane (a tet centroid there, say) is not on the
    /// positive side, whatever the normal's length or sign, and the nearest doubles off the
    /// plane are on the side the normal says.
    #[test]
    fn a_point_on_the_plane_is_not_positive() {
        let point = [0.25, 0.5, 0.75];
        let above = [0.25, 0.5, f64::from_bits(0.75f64.to_bits() + 1)];
        let below = [0.25, 0.5, f64::from_bits(0.75f64.to_bits() - 1)];
        for normal in [[0.0, 0.0, 1.0], [1.0, -2.0, 0.5], [0.0, 0.0, -3.0], [4.0, 0.0, 0.0]] {
            let plane = Plane { point, normal };
            assert!(!plane.positive(point), "on the plane, normal {normal:?}");
            assert_eq!(plane.positive(above), normal[2] > 0.0, "one ulp above, normal {normal:?}");
            assert_eq!(plane.positive(below), normal[2] < 0.0, "one ulp below, normal {normal:?}");
        }
    }
}

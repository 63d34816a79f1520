//! Incision along a swept polyline: a scalpel path P₀ … Pₙ pushed along a depth vector w.
//!
//! The cut surface is the union of the parallelograms
//!
//! ```text
//!   Qᵢ = { Pᵢ + s (Pᵢ₊₁ − Pᵢ) + t w  :  s, t ∈ [0, 1] },   i = 0 … n − 1,
//! ```
//!
//! an open, bounded, possibly bent surface (a plane is the special case of one segment and a
//! sweep long enough to cross the whole body). Unlike a plane it need not divide space, so the
//! face-separation rule is stated per face, not per tet: an inner face is cut when the segment
//! joining the centroids of its two tets crosses some Qᵢ (closed parameter ranges). For a plane
//! crossing the whole body this is exactly [`incise_plane`](super::incise_plane)'s rule; for a
//! slit that stops inside the body the tissue stays connected around the slit's end. One tie
//! differs: a centroid lying exactly on the surface counts as crossing here (closed ranges), while
//! the plane rule puts it on the negative side.
//!
//! The crossing test solves c₀ + u (c₁ − c₀) = Pᵢ + s eᵢ + t w for (u, s, t) by Cramer's rule
//! (one 3×3 determinant per quad); a segment parallel to Qᵢ (determinant below a relative 1e-12)
//! does not cross it. Cost: O(darts) for the centroids plus O(inner faces × n) tests, each
//! skipped when the segment's box misses the surface's box.

use crate::mechanics::{geom, Body, Vec3};
use crate::DartId;

use super::incise::{dissociate_all, tet_centroids};
use super::{CutError, Incision};

/// A polyline swept along a vector: the cut surface of [`incise_sweep`] (module docs).
///
/// # Examples
///
/// ```
/// use topomech::cut::PolylineSweep;
///
/// // A slit in the plane x = 1: the segment (1,0,2)–(1,1,2) pushed down by 1.5 along −z.
/// let slit = PolylineSweep { points: vec![[1.0, 0.0, 2.0], [1.0, 1.0, 2.0]], sweep: [0.0, 0.0, -1.5] };
/// assert!(slit.check().is_ok());
/// assert!(slit.crosses([0.5, 0.5, 1.0], [1.5, 0.5, 1.0])); // through the slit
/// assert!(!slit.crosses([0.5, 0.5, 0.2], [1.5, 0.5, 0.2])); // below its depth
/// assert!(!slit.crosses([0.5, 1.5, 1.0], [1.5, 1.5, 1.0])); // beside its end
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PolylineSweep {
    /// The path P₀ … Pₙ (at least two points, consecutive points distinct).
    pub points: Vec<Vec3>,
    /// The depth vector w (not zero, not along any segment).
    pub sweep: Vec3,
}

impl PolylineSweep {
    /// Checks the surface is well formed: at least two points, all coordinates finite, consecutive
    /// points distinct, w non-zero and no segment parallel to w. O(n).
    ///
    /// # Errors
    /// [`CutError::BadSweep`] naming the first problem.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::{CutError, PolylineSweep};
    ///
    /// let one_point = PolylineSweep { points: vec![[0.0; 3]], sweep: [0.0, 0.0, 1.0] };
    /// assert!(matches!(one_point.check(), Err(CutError::BadSweep { .. })));
    /// let along = PolylineSweep { points: vec![[0.0; 3], [0.0, 0.0, 2.0]], sweep: [0.0, 0.0, 1.0] };
    /// assert!(along.check().unwrap_err().to_string().contains("segment 0"));
    /// let nan = PolylineSweep { points: vec![[0.0; 3], [f64::NAN, 0.0, 0.0]], sweep: [0.0, 0.0, 1.0] };
    /// assert!(nan.check().is_err());
    /// ```
    pub fn check(&self) -> Result<(), CutError> {
        let bad = |reason: String| Err(CutError::BadSweep { reason });
        if self.points.len() < 2 {
            return bad(format!("a polyline needs at least 2 points, got {}", self.points.len()));
        }
        if let Some(i) = self.points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return bad(format!("point {i} {:?} is not finite", self.points[i]));
        }
        if self.sweep.iter().any(|c| !c.is_finite()) || geom::norm(self.sweep) == 0.0 {
            return bad(format!("sweep vector {:?} is not finite or is zero", self.sweep));
        }
        for (i, p) in self.points.windows(2).enumerate() {
            let e = geom::sub(p[1], p[0]);
            if geom::norm(e) == 0.0 {
                return bad(format!("segment {i} has zero length (points {i} and {} coincide)", i + 1));
            }
            if geom::norm(geom::cross(e, self.sweep)) <= 1e-12 * geom::norm(e) * geom::norm(self.sweep) {
                return bad(format!("segment {i} is parallel to the sweep vector: it sweeps no area"));
            }
        }
        Ok(())
    }

    /// Whether the closed segment a–b meets the surface (module docs). O(n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::PolylineSweep;
    ///
    /// // An L-shaped wall: x = 1 for y ≤ 1, then y = 1 for x ≥ 1, height 2.
    /// let wall = PolylineSweep {
    ///     points: vec![[1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [3.0, 1.0, 0.0]],
    ///     sweep: [0.0, 0.0, 2.0],
    /// };
    /// assert!(wall.crosses([0.5, 0.0, 1.0], [1.5, 0.0, 1.0])); // first leg
    /// assert!(wall.crosses([2.0, 0.5, 1.0], [2.0, 1.5, 1.0])); // second leg
    /// assert!(!wall.crosses([0.5, 2.0, 1.0], [0.8, 2.0, 1.0])); // outside the L
    /// ```
    pub fn crosses(&self, a: Vec3, b: Vec3) -> bool {
        let d = geom::sub(b, a);
        self.points.windows(2).any(|p| crosses_quad(a, d, p[0], geom::sub(p[1], p[0]), self.sweep))
    }

    /// The axis-aligned box of the surface. O(n).
    fn bounds(&self) -> (Vec3, Vec3) {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &self.points {
            for k in 0..3 {
                for c in [p[k], p[k] + self.sweep[k]] {
                    lo[k] = lo[k].min(c);
                    hi[k] = hi[k].max(c);
                }
            }
        }
        (lo, hi)
    }
}

/// Whether a + u d (u ∈ [0, 1]) meets p + s e + t w (s, t ∈ [0, 1]): Cramer's rule on
/// [d, −e, −w] (u, s, t)ᵀ = p − a. O(1).
fn crosses_quad(a: Vec3, d: Vec3, p: Vec3, e: Vec3, w: Vec3) -> bool {
    let r = geom::sub(p, a);
    let (ne, nw) = (geom::scale(e, -1.0), geom::scale(w, -1.0));
    let det = triple(d, ne, nw);
    let size = geom::norm(d) * geom::norm(e) * geom::norm(w);
    if det.abs() <= 1e-12 * size {
        return false;
    }
    let inside = |x: f64| (0.0..=1.0).contains(&x);
    inside(triple(r, ne, nw) / det) && inside(triple(d, r, nw) / det) && inside(triple(d, ne, r) / det)
}

/// The determinant of the matrix with columns a, b, c: a · (b × c). O(1).
fn triple(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    geom::dot(a, geom::cross(b, c))
}

/// Whether the boxes [lo, hi] and that of segment a–b overlap. O(1).
fn boxes_meet((lo, hi): (Vec3, Vec3), a: Vec3, b: Vec3) -> bool {
    (0..3).all(|k| a[k].min(b[k]) <= hi[k] && a[k].max(b[k]) >= lo[k])
}

/// The inner faces (one dart each, face order) whose tets' centroid segment crosses `surface`.
/// O(darts + inner faces × n). The body is not changed.
///
/// # Errors
/// [`CutError::BadSweep`].
///
/// # Examples
///
/// ```
/// use topomech::cut::{sweep_faces, PolylineSweep};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(2);
/// let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// // A slit through half of the plane x = 1 (y from −1 to 1, all z): 2 of the 4 unit squares.
/// let slit = PolylineSweep { points: vec![[1.0, -1.0, -1.0], [1.0, 1.0, -1.0]], sweep: [0.0, 0.0, 4.0] };
/// let faces = sweep_faces(&body, &slit).unwrap();
/// assert!(!faces.is_empty() && faces.len() < 8); // the whole plane x = 1 would be 8 triangles
/// ```
pub fn sweep_faces(body: &Body, surface: &PolylineSweep) -> Result<Vec<DartId>, CutError> {
    surface.check()?;
    let centroid = tet_centroids(body);
    let map = body.map();
    let bounds = surface.bounds();
    let faces = map
        .one_dart_per_cell(2)
        .into_iter()
        .filter(|&d| {
            let other = map.alpha::<3>(d);
            if other == d {
                return false;
            }
            let (a, b) = (centroid[map.cell_id(3, d).index()], centroid[map.cell_id(3, other).index()]);
            match (a, b) {
                (Some(a), Some(b)) => boxes_meet(bounds, a, b) && surface.crosses(a, b),
                _ => false,
            }
        })
        .collect();
    Ok(faces)
}

/// Dissociates every inner face whose two tets' centroid segment crosses the swept polyline
/// (module docs): a bounded incision, a slit or a bent cut. The faces are found first, then
/// dissociated one by one, so the result does not depend on the order; every dissociation
/// conserves mass and stiffness ([`dissociate_face`](super::dissociate_face)).
///
/// Cost: O(darts + inner faces × n) to select, plus one [`dissociate_face`](super::dissociate_face) per cut face.
///
/// # Errors
/// [`CutError::BadSweep`] (body unchanged); [`CutError::Body`] is a bug.
///
/// # Examples
///
/// ```
/// use topomech::cut::{components, incise_sweep, PolylineSweep};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// // A slit through half the cube: cut, but still one piece.
/// let slit = PolylineSweep { points: vec![[1.0, -1.0, -1.0], [1.0, 1.0, -1.0]], sweep: [0.0, 0.0, 4.0] };
/// let cut = incise_sweep(&mut body, &slit).unwrap();
/// assert!(cut.cut_faces() > 0);
/// assert_eq!(components(&body).len(), 1);
/// body.map().validate().unwrap();
/// ```
pub fn incise_sweep(body: &mut Body, surface: &PolylineSweep) -> Result<Incision, CutError> {
    let faces = sweep_faces(body, surface)?;
    dissociate_all(body, faces)
}

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
//! crossing the whole body this is [`incise_plane`](super::incise_plane)'s rule but for ties and
//! near ties: a centroid lying exactly on the surface counts as crossing here (closed ranges),
//! while the plane rule puts it on the negative side; and the centroids here are the `f64` ones
//! (each coordinate the sum, in increasing vertex id, of the corners' coordinates divided by
//! their count), while the plane rule decides the side of the exact centroid. For a slit that
//! stops inside the body the tissue stays connected around the slit's end.
//!
//! The crossing test solves c₀ + u (c₁ − c₀) = Pᵢ + s eᵢ + t w for (u, s, t) by Cramer's rule; a
//! segment parallel to Qᵢ (determinant below a relative 1e-12: a tolerance, the only one) does
//! not cross it. Otherwise the six comparisons 0 ≤ u, s, t ≤ 1 are decided **exactly** from the
//! `f64` inputs (the two centroids, the points, w): each is the sign of a determinant whose
//! columns are differences of inputs, taken by a float filter with a forward error bound and,
//! on a near tie, by an exact sum (`crosses_quad`). So a segment ending exactly on the surface —
//! at a Pᵢ, at Pᵢ + w, on an edge or inside — crosses, for decimal data as for dyadic.
//! Cost: O(darts) for the centroids plus O(inner faces × n) tests, each skipped when the
//! segment's box misses the surface's box.
//!
//! # Scale invariance
//! No test here (the well-formedness checks of [`PolylineSweep::check`] and the crossing test)
//! depends on the scale of the coordinates, for any finite coordinates. The tolerances (the
//! parallel tests of `check` and of the crossing) are computed on vectors each scaled by a power
//! of two (exactly) so that its largest component has a fixed magnitude, so no squared length
//! or product is formed from raw coordinates and nothing overflows for huge ones (up to
//! `f64::MAX`) or underflows for tiny ones; a difference that overflows is taken of halved
//! coordinates instead (a direction, finite even between ±`f64::MAX`). The exact comparisons
//! need no scaling: their exact path has the whole range of products of three `f64`s.
//! Multiplying every coordinate by a power of two therefore gives identical decisions, ties
//! included (a centroid exactly on the surface), unless a component of some vector is about
//! 2^1000 times smaller than its largest one (the parallel test); any other factor changes them
//! only through the rounding of the scaled coordinates themselves.

use std::cmp::Ordering;

use crate::mechanics::geom::{self, Scaled};
use crate::mechanics::{Body, Vec3};
use crate::DartId;

use super::incise::{dissociate_all, tet_centroids};
use super::{CutError, Incision};
use crate::exact::{det_sign, Term};

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
    /// The tests do not depend on the scale of the coordinates (module docs): two points are
    /// refused as coinciding only when they are equal (points that differ at all, even by one
    /// ulp of a tiny coordinate, make a segment), w only when all its components are zero, and
    /// "parallel" is a relative 1e-12 on the sine of the angle between the segment and w,
    /// computed from the two directions each scaled (by a power of two) so that its largest
    /// component is in [1, 2): neither huge (up to `f64::MAX`) nor tiny coordinates overflow or
    /// underflow.
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
    /// // Scale-invariant: a huge perpendicular slit and a tiny one are both well formed.
    /// let huge = PolylineSweep { points: vec![[0.0, -1e300, 0.0], [0.0, 1e300, 0.0]], sweep: [0.0, 0.0, 1e300] };
    /// assert!(huge.check().is_ok());
    /// let tiny = PolylineSweep { points: vec![[0.0; 3], [0.0, 2e-300, 0.0]], sweep: [0.0, 0.0, 2e-300] };
    /// assert!(tiny.check().is_ok());
    /// ```
    pub fn check(&self) -> Result<(), CutError> {
        let bad = |reason: String| Err(CutError::BadSweep { reason });
        if self.points.len() < 2 {
            return bad(format!("a polyline needs at least 2 points, got {}", self.points.len()));
        }
        if let Some(i) = self.points.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return bad(format!("point {i} {:?} is not finite", self.points[i]));
        }
        if self.sweep.iter().any(|c| !c.is_finite()) || self.sweep.iter().all(|&c| c == 0.0) {
            return bad(format!("sweep vector {:?} is not finite or is zero", self.sweep));
        }
        let w = Scaled::new(self.sweep, 0).dir;
        for (i, p) in self.points.windows(2).enumerate() {
            if p[0] == p[1] {
                return bad(format!("segment {i} has zero length (points {i} and {} coincide)", i + 1));
            }
            // Distinct finite points: the difference is not zero (gradual underflow).
            let e = Scaled::diff(p[1], p[0], 0).dir;
            if geom::norm(geom::cross(e, w)) <= 1e-12 * geom::norm(e) * geom::norm(w) {
                return bad(format!("segment {i} is parallel to the sweep vector: it sweeps no area"));
            }
        }
        Ok(())
    }

    /// Whether the closed segment a–b meets the surface (module docs): an end exactly on the
    /// surface counts, decided exactly from the `f64` inputs (only the parallel test is a
    /// tolerance). O(n). Scale-invariant: the answer is the same when a, b and the surface are
    /// all scaled by one power of two (module docs).
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
    /// // A segment ending exactly at the point P₂ of a bent slit with a decimal sweep: (u, s, t)
    /// // = (1, 1, 0) exactly, a crossing (rounded, u came out just above 1).
    /// let slit = PolylineSweep {
    ///     points: vec![[2.5, 0.25, 2.75], [3.0, 3.0, 2.0], [2.25, 0.75, 1.5]],
    ///     sweep: [0.3, 0.3, 0.3],
    /// };
    /// assert!(slit.crosses([1.75, 0.5, 1.25], [2.25, 0.75, 1.5]));
    /// ```
    pub fn crosses(&self, a: Vec3, b: Vec3) -> bool {
        let d = Scaled::diff(b, a, QUAD_EXP);
        let w = Scaled::new(self.sweep, QUAD_EXP);
        self.points
            .windows(2)
            .any(|p| crosses_quad([a, b], d, [p[0], p[1]], Scaled::diff(p[1], p[0], QUAD_EXP), (self.sweep, w)))
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

/// Whether a + u d (u ∈ [0, 1], d = b − a) meets p₀ + s e + t w (s, t ∈ [0, 1], e = p₁ − p₀):
/// [d, −e, −w] (u, s, t)ᵀ = p₀ − a, by Cramer's rule. O(1).
///
/// Two steps. (1) The parallel test, a tolerance: the segment misses the quad when
/// |det[d, e, w]| ≤ 1e-12 |d| |e| |w|, computed on d, e, w each scaled by [`Scaled`] to
/// `QUAD_EXP` (exact power-of-two scalings, so the test does not depend on the scale of the
/// coordinates and nothing overflows or underflows). Past it the sign σ of D = det[d, e, w] is
/// certain (far above the rounding of the scaled determinant). (2) The closed ranges, decided
/// exactly: with r = p₀ − a, u = det[r, e, w] / D, s = det[d, −r, w] / D and
/// t = det[d, e, −r] / D, and by multilinearity D − det[r, e, w] = det[b − p₀, e, w],
/// D − det[d, −r, w] = det[d, p₁ − a, w] and D − det[d, e, −r] = det[d, e, p₀ + w − a]: six
/// determinants whose columns are sums of at most three input `f64` vectors. The segment
/// crosses when σ times each is ≥ 0, each sign taken exactly from the inputs
/// ([`det_sign`]: a float filter, an exact sum on near ties). So a centroid exactly on the
/// surface (u, s or t exactly 0 or 1) counts as crossing for any data, dyadic or not.
fn crosses_quad([a, b]: [Vec3; 2], d: Scaled, [p0, p1]: [Vec3; 2], e: Scaled, (w_raw, w): (Vec3, Scaled)) -> bool {
    let det = triple(d.dir, e.dir, w.dir);
    let size = geom::norm(d.dir) * geom::norm(e.dir) * geom::norm(w.dir);
    if det.abs() <= 1e-12 * size {
        return false;
    }
    let sigma = if det > 0.0 { Ordering::Greater } else { Ordering::Less };
    let (pos, neg) = (false, true);
    let cd: &[Term] = &[(pos, b), (neg, a)];
    let ce: &[Term] = &[(pos, p1), (neg, p0)];
    let cw: &[Term] = &[(pos, w_raw)];
    let quantities: [[&[Term]; 3]; 6] = [
        [&[(pos, p0), (neg, a)], ce, cw],               // u ≥ 0
        [&[(pos, b), (neg, p0)], ce, cw],               // u ≤ 1
        [cd, &[(pos, a), (neg, p0)], cw],               // s ≥ 0
        [cd, &[(pos, p1), (neg, a)], cw],               // s ≤ 1
        [cd, ce, &[(pos, a), (neg, p0)]],               // t ≥ 0
        [cd, ce, &[(pos, p0), (pos, w_raw), (neg, a)]], // t ≤ 1
    ];
    // Finite inputs (checked by the callers' `check` and finite positions): `det_sign` is Some.
    quantities.iter().all(|&cols| det_sign(cols).is_some_and(|x| x == Ordering::Equal || x == sigma))
}

/// The exponent the largest component of each vector of the crossing test is scaled to: three of
/// them multiply to below 2^(3 · 301 + 3), far from overflow, and a component 2^-1000 times the
/// largest stays a normal number.
const QUAD_EXP: i32 = 300;

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
/// Scale-invariant (module docs): scaling the body's positions and the surface by one factor
/// selects the same faces, for any finite coordinates (a slit reaching ±`f64::MAX` included).
///
/// # Errors
/// [`CutError::BadSweep`]; [`CutError::NonFinitePosition`] for a live vertex with a NaN or
/// infinite position (its tets have no centroid to test).
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
    let centroid = tet_centroids(body)?;
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
/// The selection is scale-invariant ([`sweep_faces`]).
///
/// # Errors
/// [`CutError::BadSweep`], [`CutError::NonFinitePosition`] (body unchanged); [`CutError::Body`]
/// is a bug.
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

//! Refine-then-cut (issue 5, the paper's use of adaptive refinement): how closely an incision
//! follows its plane.
//!
//! [`crate::cut::incise_plane`] dissociates every inner face whose two tets have their centroids on
//! opposite sides of the plane, so the cut surface is made of mesh faces and deviates from the
//! plane by up to the size of the tets it crosses. Refining the zone first (and closing it with
//! [`super::LeveledMap::conforming_tets`] so that the mechanics runs on tets) makes the faces
//! smaller there, which bounds the error more tightly: a vertex x of a cut face shared by tets A
//! and B lies within max(|x − c_A|, |x − c_B|) of the plane, since the segment between the two
//! centroids crosses it. The error itself is not monotone in the level: the centroid rule may
//! pick other faces among the children (a Kuhn cube cut at z = 2.1 follows the layer z = 2 when
//! coarse, error 0.1, and a staircase with error 0.15 two levels finer; docs/SUBDIVISION.md).
//!
//! # The measure
//! For each dissociated face: the distances |(x − p) · n| / |n| of its three vertices x (current
//! positions) to the plane (p, n). Over the faces *measured* — every cut face, or with a zone
//! B(c, r) only those whose centroid lies in the closed ball, decided exactly on the positions
//! as given (a centroid on the sphere is in; the same faces for a copy scaled by a power of two
//! or translated without rounding) — the error is the maximum
//! vertex distance and the mean over faces of the mean vertex distance. With no face measured
//! both are NaN.

use crate::cut::{incise_plane, CutError, Dissociation, Incision, Plane};
use crate::gmap::AlphaMask;
use crate::mechanics::Body;
use crate::GMap;

/// The geometric error of a cut surface against its plane (module docs).
///
/// # Examples
///
/// ```
/// use topomech::cut::Plane;
/// use topomech::mechanics::{Body, Material};
/// use topomech::subdivide::cut_error;
/// let (points, tets) = topomech::generate::kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// // The diagonal plane x = y is made of mesh faces.
/// let plane = Plane { point: [0.0; 3], normal: [1.0, -1.0, 0.0] };
/// let e = cut_error(&mut body, &plane, None).unwrap();
/// assert_eq!(e.measured, e.faces);
/// assert!(e.faces > 0 && e.max < 1e-12 && e.mean <= e.max);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutSurfaceError {
    /// Faces the incision dissociated.
    pub faces: usize,
    /// Faces measured (all, or those with their centroid in the zone).
    pub measured: usize,
    /// Largest distance of a vertex of a measured face to the plane (NaN if none).
    pub max: f64,
    /// Mean over measured faces of the mean distance of their vertices to the plane (NaN if none).
    pub mean: f64,
}

/// Measures the faces of `incision` (already applied to `body`) against `plane`, restricted to the
/// faces whose centroid lies in the ball `zone = (centre, radius)` when given (module docs).
/// O(cut faces).
///
/// # Errors
/// [`CutError::BadPlane`], [`CutError::BadZone`] (non-finite centre, radius not finite and ≥ 0),
/// [`CutError::NoSuchDart`] for a dissociation whose dart is not live in `body`,
/// [`CutError::NotDissociated`] for one whose dart is live but not α3-free on the face the
/// dissociation reported (an incision of another body, in both cases).
///
/// # Examples
///
/// ```
/// use topomech::cut::{incise_plane, CutError, Plane};
/// use topomech::mechanics::{Body, Material};
/// use topomech::subdivide::measure_cut;
/// let (points, tets) = topomech::generate::kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let plane = Plane { point: [1.0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] };
/// let inc = incise_plane(&mut body, &plane).unwrap();
/// let all = measure_cut(&body, &inc, &plane, None).unwrap();
/// assert!(all.measured == all.faces && all.faces > 0 && all.max < 1e-12);
/// let none = measure_cut(&body, &inc, &plane, Some(([9.0; 3], 0.1))).unwrap();
/// assert!(none.measured == 0 && none.max.is_nan());
/// let nan = measure_cut(&body, &inc, &plane, Some(([1.0; 3], f64::NAN)));
/// assert!(matches!(nan, Err(CutError::BadZone { .. }))); // not "every face is inside"
/// ```
pub fn measure_cut(
    body: &Body,
    incision: &Incision,
    plane: &Plane,
    zone: Option<([f64; 3], f64)>,
) -> Result<CutSurfaceError, CutError> {
    plane.check()?;
    if let Some((center, radius)) = zone {
        check_zone(center, radius)?;
    }
    let (map, mech) = (body.map(), body.attrs());
    for dis in &incision.dissociations {
        check_applied(map, dis)?;
    }
    // The normal scaled by its largest component, so that a tiny (or huge) normal does not
    // underflow (overflow) in its squared length.
    let scale = plane.normal.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let unit = plane.normal.map(|c| c / scale);
    let len = unit.iter().map(|c| c * c).sum::<f64>().sqrt();
    let dist = |x: [f64; 3]| ((0..3).map(|k| (x[k] - plane.point[k]) * unit[k]).sum::<f64>() / len).abs();
    let (mut measured, mut max, mut sum) = (0usize, 0.0f64, 0.0);
    for dis in &incision.dissociations {
        let mut ids: Vec<_> =
            map.orbit(dis.dart, AlphaMask::of(&[0, 1])).into_iter().map(|x| map.vertex_id(x)).collect();
        ids.sort_unstable();
        ids.dedup();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&v| mech.position[v]).collect();
        if let Some((centre, r)) = zone {
            // Exact at every scale (finding 283; finding 80: no overflow for far zones); a
            // non-finite position is outside.
            if !crate::exact::centroid_in_ball(&pts, centre, r) {
                continue;
            }
        }
        measured += 1;
        let d: Vec<f64> = pts.iter().map(|&p| dist(p)).collect();
        max = d.iter().copied().fold(max, f64::max);
        sum += d.iter().sum::<f64>() / d.len() as f64;
    }
    let (max, mean) = if measured == 0 { (f64::NAN, f64::NAN) } else { (max, sum / measured as f64) };
    Ok(CutSurfaceError { faces: incision.cut_faces(), measured, max, mean })
}

/// `Ok` when the dissociation `dis` stands in `map`: both of its darts live, α3-free and on the
/// face ids it reported. An incision of another body (or of a copy cut elsewhere) fails it unless
/// that body was cut in the same places. O(1).
fn check_applied(map: &GMap<3>, dis: &Dissociation) -> Result<(), CutError> {
    for (d, face) in [(dis.dart, dis.faces.0), (dis.opposite, dis.faces.1)] {
        if !map.contains(d) {
            return Err(CutError::NoSuchDart(d));
        }
        if !map.is_free(3, d) || map.cell_id(2, d) != face {
            return Err(CutError::NotDissociated { dart: d, face });
        }
    }
    Ok(())
}

/// [`CutError::BadZone`] unless the centre is finite and the radius a finite number ≥ 0. O(1).
fn check_zone(center: [f64; 3], radius: f64) -> Result<(), CutError> {
    if center.iter().all(|c| c.is_finite()) && radius.is_finite() && radius >= 0.0 {
        return Ok(());
    }
    Err(CutError::BadZone { center, radius })
}

/// Incises `body` along `plane` ([`incise_plane`]) and measures the cut surface
/// ([`measure_cut`]). O(darts + cut faces · dissociation).
///
/// # Errors
/// [`CutError::BadZone`] and those of [`incise_plane`] (a bad plane or zone leaves the body
/// unchanged).
///
/// ```
/// use topomech::cut::Plane;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::subdivide::cut_error;
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// // The plane x = 1 is made of mesh faces: the cut follows it exactly.
/// let plane = Plane { point: [1.0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] };
/// let e = cut_error(&mut body, &plane, None).unwrap();
/// assert!(e.faces > 0 && e.max < 1e-12);
/// ```
pub fn cut_error(body: &mut Body, plane: &Plane, zone: Option<([f64; 3], f64)>) -> Result<CutSurfaceError, CutError> {
    if let Some((center, radius)) = zone {
        check_zone(center, radius)?;
    }
    let incision = incise_plane(body, plane)?;
    measure_cut(body, &incision, plane, zone)
}

//! Small 3-vector helpers used by the mechanics (no dependency needed for these few lines).

/// A point or vector of R³.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::Vec3;
///
/// let (points, _) = kuhn_cube(1);
/// let top: Vec<Vec3> = points.into_iter().filter(|p| p[2] == 1.0).collect();
/// assert_eq!(top.len(), 4);
/// assert!(top.iter().all(|&[x, y, _]| (x == 0.0 || x == 1.0) && (y == 0.0 || y == 1.0)));
/// ```
pub type Vec3 = [f64; 3];

#[inline(always)]
pub(crate) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub(crate) fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub(crate) fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub(crate) fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub(crate) fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline(always)]
pub(crate) fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// |det[b − a, c − a, d − a]| / 6: the unsigned volume of a tetrahedron.
pub(crate) fn tet_volume(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> f64 {
    (dot(cross(sub(b, a), sub(c, a)), sub(d, a)) / 6.0).abs()
}

/// Whether `a` and `b` agree to a relative tolerance `rel` (absolute below `f64::MIN_POSITIVE`).
pub(crate) fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

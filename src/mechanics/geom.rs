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

/// |det[b − a, c − a, d − a]| / 6: the unsigned volume of a tetrahedron. Plain for
/// [`plain_corners`] (the same bits as ever), else in wide floats (`crate::wide`), so it is ∞ or
/// 0 only when the volume itself is past `f64::MAX` or below the smallest subnormal (a sliver
/// 1e200 wide and 1e-200 thick has 1.67e199, not ∞ or 0). O(1).
pub(crate) fn tet_volume(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> f64 {
    if plain_corners([a, b, c, d]) {
        return (dot(cross(sub(b, a), sub(c, a)), sub(d, a)) / 6.0).abs();
    }
    crate::wide::signed_volume(a, b, c, d).abs()
}

/// Whether every component of the edge vectors c₁ − c₀, c₂ − c₀, c₃ − c₀ is 0 or has a
/// magnitude in [`crate::mesh::PLAIN_EXTENT`] (2⁻²⁵⁰ to 2²⁵⁰): then no product of up to four of
/// them (a volume, a squared length, a volume over a squared length) over- or underflows, and
/// the plain formulas are exact up to their rounding. Every ordinary tet. O(1).
pub(crate) fn plain_corners(c: [Vec3; 4]) -> bool {
    let edges = [sub(c[1], c[0]), sub(c[2], c[0]), sub(c[3], c[0])];
    edges.iter().flatten().all(|x| *x == 0.0 || crate::mesh::PLAIN_EXTENT.contains(&x.abs()))
}

/// Whether `a` and `b` agree to a relative tolerance `rel` (absolute below `f64::MIN_POSITIVE`).
pub(crate) fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

/// (m, e) with x = m · 2^e and 1 ≤ |m| < 2 for a finite non-zero x (subnormals included), read
/// from the bits (exact); (x, 0) for 0, ∞ and NaN. O(1).
pub(crate) fn split_exponent(x: f64) -> (f64, i64) {
    if x == 0.0 || !x.is_finite() {
        return (x, 0);
    }
    let e = crate::mesh::binary_exponent(x.abs());
    (crate::mesh::times_pow2(x, -e), e)
}

/// a · b / l² · 2^e with no intermediate overflow or underflow: the product and quotient are
/// taken on the mantissas (in (1/4, 4)), the exponents are added, and the result is scaled once
/// ([`crate::mesh::times_pow2`]), so it is ∞ or 0 only when the value itself is past `f64::MAX`
/// or below the smallest subnormal. For finite a, b and a finite l ≠ 0. O(1).
pub(crate) fn ratio_pow2(a: f64, b: f64, l: f64, e: i64) -> f64 {
    let [(ma, ea), (mb, eb), (ml, el)] = [a, b, l].map(split_exponent);
    crate::mesh::times_pow2(ma * mb / (ml * ml), ea + eb - 2 * el + e)
}

/// The rest length |b − a|: √(Σ dₖ²) as it is (the same bits as before) when the largest
/// difference is 0 or within [`crate::mesh::PLAIN_EXTENT`], where the squares neither overflow
/// nor underflow, else the scale-safe [`crate::mesh::distance`] (∞ only for a length past
/// `f64::MAX`). O(1).
pub(crate) fn rest_length(a: Vec3, b: Vec3) -> f64 {
    let d = sub(b, a);
    let largest = d.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if largest == 0.0 || crate::mesh::PLAIN_EXTENT.contains(&largest) {
        norm(d)
    } else {
        crate::mesh::distance(b, a)
    }
}

/// Whether the tet with corners `c` has exactly zero volume, its determinant taken in wide floats
/// (`crate::wide`: the plain bits for ordinary corners, no over- or underflow otherwise), so that
/// a tet whose volume under- or overflows f64 (tiny or huge, a needle 1e-170 thin beside a unit
/// edge, a sliver 1e-200 thick and 1e200 wide) is not called flat. O(1).
pub(crate) fn is_flat(c: [Vec3; 4]) -> bool {
    crate::wide::six_volume(c[0], c[1], c[2], c[3]).is_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_exponent_is_exact_for_normals_and_subnormals() {
        assert_eq!(split_exponent(12.0), (1.5, 3));
        assert_eq!(split_exponent(-0.75), (-1.5, -1));
        assert_eq!(split_exponent(5e-324), (1.0, -1074));
        assert_eq!(split_exponent(f64::MAX).1, 1023);
        assert_eq!(split_exponent(0.0), (0.0, 0));
    }

    #[test]
    fn ratio_pow2_has_no_intermediate_overflow() {
        assert!((ratio_pow2(1e300, 1e100, 1e100, 0) / 1e200 - 1.0).abs() < 1e-15); // E·V = ∞ on its own
        assert_eq!(ratio_pow2(3.0, 4.0, 2.0, 1), 6.0);
        assert!((ratio_pow2(1e-300, 1e-300, 1e-300, 0) / 1.0 - 1.0).abs() < 1e-15);
        assert_eq!(ratio_pow2(f64::MAX, 4.0, 1.0, 0), f64::INFINITY);
    }

    #[test]
    fn rest_length_is_plain_in_range_and_scale_safe_outside() {
        assert_eq!(rest_length([0.0; 3], [3.0, 4.0, 0.0]), 5.0);
        assert_eq!(rest_length([0.0; 3], [3e160, 4e160, 0.0]), 5e160);
        assert_eq!(rest_length([0.0; 3], [3e-160, 4e-160, 0.0]), 5e-160);
    }

    #[test]
    fn is_flat_decides_on_fitted_corners() {
        let s = 1e-110;
        assert!(!is_flat([[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]]));
        assert!(is_flat([[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0], [s, s, 0.0]]));
    }
}

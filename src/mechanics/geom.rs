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

/// |volume| of each tet of `tets`, up to one common positive factor (for ratios of volumes):
/// the plain |[`crate::mesh::signed_volume`]| (the same bits as ever) when every tet has
/// [`plain_corners`], else each |6V| in wide floats (`crate::wide`) divided by the largest, so
/// that for any finite corners no ratio is lost to an over- or underflow of the volumes
/// themselves (the children of a needle whose volume is below the smallest subnormal, or of a
/// sliver whose volume is past `f64::MAX`). All 0 when every volume is exactly 0. O(K).
pub(crate) fn volume_ratios<const K: usize>(tets: [[Vec3; 4]; K]) -> [f64; K] {
    if tets.iter().all(|&t| plain_corners(t)) {
        return tets.map(|t| crate::mesh::signed_volume(t[0], t[1], t[2], t[3]).abs());
    }
    let six = tets.map(|t| crate::wide::six_volume(t[0], t[1], t[2], t[3]).abs());
    let largest = six.iter().fold(crate::wide::Wide::new(0.0), |m, &v| if m.less_than(v) { v } else { m });
    if largest.is_zero() {
        return [0.0; K];
    }
    six.map(|v| v.div(largest).to_f64())
}

/// The exponent k with 2^k ≤ m < 2^(k+1), for finite m > 0 (subnormals included):
/// [`crate::mesh::binary_exponent`] as an `i32`. O(1).
pub(crate) fn exponent(m: f64) -> i32 {
    crate::mesh::binary_exponent(m) as i32
}

/// 2^e, exact for e in [−1074, 1023] (subnormals included), 0 below and +∞ above. O(1).
pub(crate) fn pow2(e: i32) -> f64 {
    match e {
        1024.. => f64::INFINITY,
        -1022..=1023 => f64::from_bits(((e + 1023) as u64) << 52),
        -1074..=-1023 => f64::from_bits(1u64 << (e + 1074)),
        _ => 0.0,
    }
}

/// Σ `values` with Neumaier's compensation: the rounding of the running sum is carried in a
/// second term, so the result is within about 2 ulp of the exact sum (plus n² ε² of Σ|x|)
/// however many terms there are, where a plain sum drifts by up to n ε Σ|x|. The conservation
/// checks compare totals of 10⁵–10⁶ terms to 1e-12 (finding 228). O(n).
pub(crate) fn compensated_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut acc = CompensatedSum::default();
    values.into_iter().for_each(|x| acc.add(x));
    acc.value()
}

/// A running [`compensated_sum`]: the sum and the rounding it has lost so far.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CompensatedSum {
    sum: f64,
    carry: f64,
}

impl CompensatedSum {
    /// Adds `x`. Once the running sum is not finite (an overflow, or an infinite or NaN term)
    /// it stays what a plain sum gives (±∞ or NaN) and the carry is no longer updated: the
    /// carry of an overflowed sum would be ∓∞ and turn the value into NaN (finding F3 of round
    /// 25). O(1).
    pub(crate) fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if t.is_finite() {
            self.carry += if self.sum.abs() >= x.abs() { (self.sum - t) + x } else { (x - t) + self.sum };
        }
        self.sum = t;
    }

    /// The sum so far: the plain sum itself when that is not finite. O(1).
    pub(crate) fn value(&self) -> f64 {
        if self.sum.is_finite() {
            self.sum + self.carry
        } else {
            self.sum
        }
    }
}

/// Whether `a` and `b` agree to a relative tolerance `rel` (absolute below `f64::MIN_POSITIVE`).
pub(crate) fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
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

/// Whether the tet with corners `c` is flat in the sense the model uses: its determinant
/// det[c₁ − c₀, c₂ − c₀, c₃ − c₀], computed with the plain formula's roundings (those of
/// `mesh::signed_volume`) but an unbounded exponent (`crate::wide`), is 0. So a tet whose volume
/// merely under- or overflows f64 (tiny or huge, a needle 1e-170 thin beside a unit edge, a sliver
/// 1e-200 thick and 1e200 wide) is not called flat. This is the rounded determinant, not the
/// exact volume: the products of the cross product round, so an exactly coplanar tet can have a
/// nonzero rounded determinant (it is then not flat here) and a tet of tiny nonzero volume a
/// zero one, even with exact differences. O(1).
pub(crate) fn is_flat(c: [Vec3; 4]) -> bool {
    crate::wide::six_volume(c[0], c[1], c[2], c[3]).is_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ratios of volumes: the plain bits for ordinary tets; for a needle whose volumes underflow
    /// f64 (and a sliver whose volumes overflow it), the true ratios, not 0/0.
    #[test]
    fn volume_ratios_survive_volumes_outside_f64() {
        let unit = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let double = unit.map(|c| c.map(|x| 2.0 * x));
        assert_eq!(volume_ratios([unit, double]), [1.0 / 6.0, 8.0 / 6.0]);
        for (w, l) in [(1e-200, 1.0), (1e-170, 1e-10), (1e-200, 1e200), (1e150, 1e150)] {
            let needle = [[0.0; 3], [l, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, w]];
            let thicker = [[0.0; 3], [l, 0.0, 0.0], [0.0, 2.0 * w, 0.0], [0.0, 0.0, 3.0 * w]];
            let r = volume_ratios([needle, thicker]);
            assert!(r.iter().all(|v| v.is_finite()), "{w} {l}: {r:?}");
            assert!((r[1] / r[0] - 6.0).abs() < 1e-14, "{w} {l}: {r:?}");
        }
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1e-300, 0.0]];
        assert_eq!(volume_ratios([flat, flat]), [0.0, 0.0]);
    }

    /// An overflowing or infinite sum is what a plain sum gives (+∞, −∞ or NaN), never the NaN
    /// of ∞ + (−∞) from an overflowed carry (round 25, F3); finite sums keep their compensation.
    #[test]
    fn compensated_sum_overflows_like_a_plain_sum() {
        let (max, inf) = (f64::MAX, f64::INFINITY);
        assert_eq!(compensated_sum([max, max]), inf);
        assert_eq!(compensated_sum([-max, -max, 1.0]), -inf);
        assert_eq!(compensated_sum([1.0, inf, 2.0]), inf);
        assert_eq!(compensated_sum([inf, 1.0]), inf);
        assert!(compensated_sum([inf, -inf]).is_nan());
        assert!(compensated_sum([1.0, f64::NAN]).is_nan());
        assert_eq!(compensated_sum([max, -max, max]), max);
        // compensation kept: 1 + 1e-16 × 10 loses every term in a plain sum
        let plain: f64 = std::iter::once(1.0).chain([1e-16; 10]).sum();
        assert_eq!(plain, 1.0);
        assert_eq!(compensated_sum(std::iter::once(1.0).chain([1e-16; 10])), 1.0 + 1e-15);
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

/// A vector v scaled by a power of two to `dir`, whose largest absolute component is in
/// [2^target, 2^(target+1)) (or `dir` zero for the zero vector). The scaling is exact unless a
/// component is about 2^1000 or more times smaller than the largest one, and cross and triple
/// products of `dir`s neither overflow nor lose their leading terms to underflow, whatever the
/// magnitude of v: the sweep's parallel test and well-formedness checks, the tear's face normals
/// and the stored boundary normals ([`super::Mechanics`]) use it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scaled {
    pub(crate) dir: Vec3,
}

impl Scaled {
    /// `v` scaled as above to `target` (|target| ≤ 300). O(1).
    pub(crate) fn new(v: Vec3, target: i32) -> Self {
        let m = v.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        if m == 0.0 {
            return Scaled { dir: v };
        }
        let k = exponent(m);
        // target − k ∈ [−1323, 1374]: two steps, each a normal power of two.
        let shift = target - k;
        let (f1, f2) = (pow2(shift / 2), pow2(shift - shift / 2));
        Scaled { dir: v.map(|c| c * f1 * f2) }
    }

    /// x − y for finite x, y, scaled to `target`. When the difference overflows it is taken of
    /// halved coordinates (finite even between ±`f64::MAX`, and exact up to the halving of
    /// subnormal coordinates): a direction, whose length is not kept. Zero only when x = y. O(1).
    pub(crate) fn diff(x: Vec3, y: Vec3, target: i32) -> Self {
        let v = sub(x, y);
        if v.iter().all(|c| c.is_finite()) {
            return Scaled::new(v, target);
        }
        Scaled::new(sub(scale(x, 0.5), scale(y, 0.5)), target)
    }
}

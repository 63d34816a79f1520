//! Wide floats: an `f64` mantissa with an `i64` binary exponent, for the geometry whose products
//! over- or underflow `f64` (volumes, cross products and squared lengths of cells at scales near
//! 2^±1000, or of needles and slivers whose thin side is 2^-600 of their long side).
//!
//! A [`Wide`] is m · 2^e with 1 ≤ |m| < 2 (or m = 0, ±∞, NaN with e = 0). Every operation rounds
//! its mantissa exactly as `f64` rounds the same operation on the plain values, and scales by
//! powers of two, which is exact; so a computation done in `Wide` gives **the same bits as the
//! plain `f64` computation wherever no plain intermediate over- or underflows**, and elsewhere the
//! value the plain one would give with an unbounded exponent. Converting back to `f64` over- or
//! underflows only when the final value itself is outside the range of `f64`. O(1) per operation.

use crate::mesh::{binary_exponent, times_pow2};

/// m · 2^e: 1 ≤ |m| < 2, or m ∈ {0, ±∞, NaN} with e = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Wide {
    m: f64,
    e: i64,
}

/// A sum term 2^-SMALL_TERM or less of the other is below half its ulp: adding it cannot change
/// the rounded sum (`f64` keeps 53 bits), and skipping it keeps the alignment exact.
const SMALL_TERM: i64 = 1000;

impl Wide {
    /// The value `x`, exactly. O(1).
    pub(crate) fn new(x: f64) -> Self {
        Self::scaled(x, 0)
    }

    /// x · 2^e, exactly, normalised. O(1).
    fn scaled(x: f64, e: i64) -> Self {
        if x == 0.0 || !x.is_finite() {
            return Wide { m: x, e: 0 };
        }
        let k = binary_exponent(x.abs());
        Wide { m: times_pow2(x, -k), e: e + k }
    }

    /// The nearest `f64`: ±∞ past `f64::MAX`, a subnormal or 0 below `f64::MIN_POSITIVE`. O(1).
    pub(crate) fn to_f64(self) -> f64 {
        times_pow2(self.m, self.e.clamp(-2200, 2200))
    }

    /// Whether the value is exactly 0. O(1).
    pub(crate) fn is_zero(self) -> bool {
        self.m == 0.0
    }

    /// Whether the value is > 0 (false for NaN). O(1).
    pub(crate) fn is_positive(self) -> bool {
        self.m > 0.0
    }

    /// Whether the value is finite. O(1).
    pub(crate) fn is_finite(self) -> bool {
        self.m.is_finite()
    }

    /// Whether self < other (false when either is NaN). O(1).
    pub(crate) fn less_than(self, other: Self) -> bool {
        self.sub(other).m < 0.0
    }

    /// The sign: 1.0, −1.0, or 0.0 for zero and NaN. O(1).
    pub(crate) fn signum(self) -> f64 {
        if self.m == 0.0 || self.m.is_nan() {
            0.0
        } else {
            self.m.signum()
        }
    }

    /// |self|. O(1).
    pub(crate) fn abs(self) -> Self {
        Wide { m: self.m.abs(), e: self.e }
    }

    /// −self. O(1).
    pub(crate) fn neg(self) -> Self {
        Wide { m: -self.m, e: self.e }
    }

    /// self · other, rounded once. O(1).
    pub(crate) fn mul(self, other: Self) -> Self {
        Self::scaled(self.m * other.m, self.e + other.e)
    }

    /// self / other, rounded once (±∞ or NaN for a zero divisor, as in `f64`). O(1).
    pub(crate) fn div(self, other: Self) -> Self {
        Self::scaled(self.m / other.m, self.e - other.e)
    }

    /// self + other, rounded once. O(1).
    pub(crate) fn add(self, other: Self) -> Self {
        if !(self.is_finite() && other.is_finite()) {
            return Wide { m: self.m + other.m, e: 0 };
        }
        if other.is_zero() {
            return self;
        }
        if self.is_zero() {
            return other;
        }
        let (big, small) = if self.e >= other.e { (self, other) } else { (other, self) };
        let gap = big.e - small.e;
        if gap > SMALL_TERM {
            return big;
        }
        Self::scaled(big.m + times_pow2(small.m, -gap), big.e)
    }

    /// self − other, rounded once. O(1).
    pub(crate) fn sub(self, other: Self) -> Self {
        self.add(other.neg())
    }

    /// √self, rounded once (NaN for a negative value). O(1).
    pub(crate) fn sqrt(self) -> Self {
        if self.is_zero() || !self.is_finite() || self.m < 0.0 {
            return Wide { m: self.m.sqrt(), e: 0 };
        }
        let odd = self.e.rem_euclid(2);
        Self::scaled((self.m * if odd == 1 { 2.0 } else { 1.0 }).sqrt(), (self.e - odd) / 2)
    }
}

/// A vector of wide components.
pub(crate) type WideVec = [Wide; 3];

/// b − a per coordinate, each rounded once (finite for any finite a, b). O(1).
pub(crate) fn difference(b: [f64; 3], a: [f64; 3]) -> WideVec {
    [0, 1, 2].map(|k| Wide::new(b[k]).sub(Wide::new(a[k])))
}

/// u × v, in the operation order of the plain cross product. O(1).
pub(crate) fn cross(u: WideVec, v: WideVec) -> WideVec {
    [u[1].mul(v[2]).sub(u[2].mul(v[1])), u[2].mul(v[0]).sub(u[0].mul(v[2])), u[0].mul(v[1]).sub(u[1].mul(v[0]))]
}

/// u · v, summed left to right. O(1).
pub(crate) fn dot(u: WideVec, v: WideVec) -> Wide {
    u[0].mul(v[0]).add(u[1].mul(v[1])).add(u[2].mul(v[2]))
}

/// |u| = √(u · u). O(1).
pub(crate) fn norm(u: WideVec) -> Wide {
    dot(u, u).sqrt()
}

/// 6 × the signed volume of the tet (a, b, c, d), det[b − a, c − a, d − a], in the operation
/// order of `mesh::signed_volume` (so its bits where that one neither over- nor underflows).
/// It is 0 exactly when the plain formula's rounded operations give 0 with an unbounded exponent
/// (no underflow can make it 0). That is the rounded determinant, not the exact one: the
/// differences, the products and the sums each round, so an exactly flat tet may get a nonzero
/// value and a tet of tiny nonzero volume 0, even when every difference is exact. O(1).
pub(crate) fn six_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Wide {
    dot(cross(difference(b, a), difference(c, a)), difference(d, a))
}

/// The signed volume of the tet (a, b, c, d) as an `f64`: ±∞ or 0 only when the volume itself is
/// past `f64::MAX` or below the smallest subnormal. O(1).
pub(crate) fn signed_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    six_volume(a, b, c, d).div(Wide::new(6.0)).to_f64()
}

/// Twice the area of the triangle (a, b, c), |(b − a) × (c − a)|. O(1).
pub(crate) fn twice_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Wide {
    norm(cross(difference(b, a), difference(c, a)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where no plain intermediate over- or underflows, the wide operations give the plain bits.
    #[test]
    fn plain_bits_in_range() {
        let xs = [1.0, -3.5, 0.1, 7e10, -2.5e-7, 1.0 / 3.0, 123456.789];
        for &x in &xs {
            for &y in &xs {
                let (a, b) = (Wide::new(x), Wide::new(y));
                assert_eq!(a.mul(b).to_f64(), x * y);
                assert_eq!(a.div(b).to_f64(), x / y);
                assert_eq!(a.add(b).to_f64(), x + y);
                assert_eq!(a.sub(b).to_f64(), x - y);
            }
            assert_eq!(Wide::new(x.abs()).sqrt().to_f64(), x.abs().sqrt());
        }
        let p = [[0.1, 0.2, 0.3], [1.3, 0.1, -0.2], [0.4, 1.7, 0.2], [0.3, 0.1, 1.9]];
        assert_eq!(signed_volume(p[0], p[1], p[2], p[3]), crate::mesh::signed_volume(p[0], p[1], p[2], p[3]));
    }

    /// Beyond the range of `f64` the wide values keep their digits, and come back to `f64`
    /// only as the final value allows.
    #[test]
    fn no_intermediate_overflow_or_underflow() {
        let big = Wide::new(1e300);
        assert_eq!(big.mul(big).div(big).to_f64(), 1e300);
        let tiny = Wide::new(1e-300);
        assert_eq!(tiny.mul(tiny).div(tiny).to_f64(), 1e-300);
        assert_eq!(big.mul(big).to_f64(), f64::INFINITY);
        assert_eq!(tiny.mul(tiny).to_f64(), 0.0);
        assert_eq!(Wide::new(5e-324).mul(Wide::new(2.0)).to_f64(), 1e-323);
        assert_eq!(Wide::new(f64::MAX).sub(Wide::new(-f64::MAX)).div(Wide::new(4.0)).to_f64(), f64::MAX / 2.0);
        assert_eq!(big.mul(big).sqrt().to_f64(), 1e300);
        assert_eq!(Wide::new(1.0).add(tiny.mul(tiny)).to_f64(), 1.0);
        assert!(Wide::new(-1.0).sqrt().to_f64().is_nan());
        assert!(Wide::new(f64::NAN).add(Wide::new(1.0)).to_f64().is_nan());
        assert_eq!(Wide::new(f64::INFINITY).mul(Wide::new(2.0)).to_f64(), f64::INFINITY);
        // Non-finite sums as in f64 (a survivor of the 37th mutation sample read `+` as `−`).
        assert_eq!(Wide::new(1.0).add(Wide::new(f64::INFINITY)).to_f64(), f64::INFINITY);
        assert_eq!(Wide::new(f64::NEG_INFINITY).add(Wide::new(2.0)).to_f64(), f64::NEG_INFINITY);
        assert!(Wide::new(f64::INFINITY).add(Wide::new(f64::NEG_INFINITY)).to_f64().is_nan());
    }

    /// A sliver 1e200 wide and 1e-200 thick has the volume 1e200 · 1e200 · 1e-200 / 6; a needle
    /// of unit length and width 1e-200 twice the area 1e-200.
    #[test]
    fn volumes_and_areas_of_slivers_and_needles() {
        let o = [0.0; 3];
        let v = signed_volume(o, [1e200, 0.0, 0.0], [0.0, 1e200, 0.0], [0.0, 0.0, 1e-200]);
        assert!((v / (1e200 / 6.0) - 1.0).abs() < 1e-15, "{v:e}");
        // V = 1e-340 / 6 is below the smallest f64, but not 0: ρ·V for ρ = 1e300 is 1.67e-41.
        let six = six_volume(o, [1.0, 0.0, 0.0], [0.0, 1e-170, 0.0], [0.0, 0.0, 1e-170]);
        assert_eq!(six.to_f64(), 0.0);
        let mass = six.div(Wide::new(6.0)).mul(Wide::new(1e300)).to_f64();
        assert!((mass / (1e-40 / 6.0) - 1.0).abs() < 1e-15, "{mass:e}");
        assert!(six_volume(o, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]).is_zero());
        assert_eq!(twice_area(o, [1.0, 0.0, 0.0], [1.0, 1e-200, 0.0]).to_f64(), 1e-200);
    }
}

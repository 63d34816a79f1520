//! Exact signs for the crate's geometric decisions: which side of a plane a set of corners lies
//! on (the cuts), and the sign of a 3×3 determinant whose entries are sums of up to three `f64`s
//! (the sweep, the tear's side, and the orientations of the refinement path).
//!
//! Each predicate first evaluates its expression in floating point with a forward error bound
//! (a filter); only when the value is within the bound of zero is it evaluated exactly. The
//! exact path writes every input `f64` as m · 2^e (m an integer of at most 53 bits) and adds
//! the products of one to three factors, each an integer of at most 159 bits at a known bit
//! position, into a fixed-point accumulator wide enough for the whole range of such products
//! (from 2^(−3·1074) up to past 2^(3·1024)): no rounding, no overflow, no underflow, for every
//! finite input, at any scale. Its cost is a few hundred integer operations, paid only on
//! exact or near ties.

use std::cmp::Ordering;

type Vec3 = [f64; 3];

/// The exponent of the accumulator's lowest bit: the lowest bit of a product of three
/// subnormal `f64`s.
const MIN_EXP: i32 = -3 * 1074;

/// Accumulator limbs: a product of three finite `f64`s is below 2^(3·1024), i.e. its highest
/// bit is at most 3·1024 − MIN_EXP = 6294 bits above the lowest, plus room for the carries of
/// a few thousand terms.
const LIMBS: usize = 101;

/// u = 2^-53, the unit roundoff.
const U: f64 = 1.0 / 9_007_199_254_740_992.0;

/// An allowance for underflow in a filter: every product that underflows is off by at most
/// 2^-1075 ≈ 2.5e-324, and a filter forms fewer than a hundred of them (values this small simply
/// take the exact path). A product that multiplies such an error by a large factor (the
/// determinant's dot) scales the allowance by that factor ([`det_sign`]).
const TINY: f64 = 1e-290;

/// A fixed-point sum of signed products of `f64`s: the positive and the negative terms in two
/// unsigned accumulators of [`LIMBS`] 64-bit limbs, bit 0 standing for 2^[`MIN_EXP`].
struct Accumulator {
    pos: [u64; LIMBS],
    neg: [u64; LIMBS],
}

/// `x` = m · 2^e exactly, with m < 2^53 (m = 0 for ±0), and whether x is negative. `x` finite.
fn split(x: f64) -> (bool, u64, i32) {
    let bits = x.to_bits();
    let negative = bits >> 63 == 1;
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    if biased == 0 {
        (negative, fraction, -1074)
    } else {
        (negative, fraction | (1u64 << 52), biased - 1075)
    }
}

impl Accumulator {
    fn new() -> Self {
        Accumulator { pos: [0; LIMBS], neg: [0; LIMBS] }
    }

    /// Adds (−1)^`negative` · Π `factors` (one to three finite `f64`s), exactly.
    fn add(&mut self, negative: bool, factors: &[f64]) {
        debug_assert!((1..=3).contains(&factors.len()));
        let mut negative = negative;
        let mut exp = 0i32;
        // The product of the integer parts, in three limbs (at most 53 · 3 = 159 bits).
        let mut m: [u64; 3] = [1, 0, 0];
        for &f in factors {
            let (s, mf, ef) = split(f);
            if mf == 0 {
                return;
            }
            negative ^= s;
            exp += ef;
            let lo = m[0] as u128 * mf as u128;
            let mid = m[1] as u128 * mf as u128 + (lo >> 64);
            let hi = m[2] as u128 * mf as u128 + (mid >> 64);
            m = [lo as u64, mid as u64, hi as u64];
        }
        let offset = (exp - MIN_EXP) as usize;
        let (limb, bit) = (offset / 64, offset % 64);
        let shifted = if bit == 0 {
            [m[0], m[1], m[2], 0]
        } else {
            [
                m[0] << bit,
                (m[1] << bit) | (m[0] >> (64 - bit)),
                (m[2] << bit) | (m[1] >> (64 - bit)),
                m[2] >> (64 - bit),
            ]
        };
        let target = if negative { &mut self.neg } else { &mut self.pos };
        let mut carry = false;
        let mut i = limb;
        for word in shifted {
            let (s1, c1) = target[i].overflowing_add(word);
            let (s2, c2) = s1.overflowing_add(carry as u64);
            target[i] = s2;
            carry = c1 || c2;
            i += 1;
        }
        while carry {
            let (s, c) = target[i].overflowing_add(1);
            target[i] = s;
            carry = c;
            i += 1;
        }
    }

    /// The sign of the sum. O(LIMBS).
    fn sign(&self) -> Ordering {
        for i in (0..LIMBS).rev() {
            match self.pos[i].cmp(&self.neg[i]) {
                Ordering::Equal => continue,
                other => return other,
            }
        }
        Ordering::Equal
    }
}

/// The exact sign of Σᵢ (xᵢ − p) · n over the points `xs` (for the corners of a tet, 4 times
/// the signed distance of their exact centroid, times |n|); `None` when an input is not
/// finite. A float filter decides unless the value is within its error bound of zero; then the
/// exact sum decides. O(|xs|).
pub(crate) fn plane_sign(xs: &[Vec3], p: Vec3, n: Vec3) -> Option<Ordering> {
    let finite = |v: &Vec3| v.iter().all(|c| c.is_finite());
    if !finite(&p) || !finite(&n) || !xs.iter().all(finite) {
        return None;
    }
    // Filter: each term fl(fl(x − p) · n) is within 2u (+ an underflow) of the exact one, the
    // recursive sum of N terms adds at most (N − 1) u Σ|terms|: |s − S| ≤ (N + 2) u A (1 + O(u))
    // plus N underflows, with A the float sum of |terms|, itself within (N − 1) u of its value.
    let (mut s, mut a) = (0.0f64, 0.0f64);
    for x in xs {
        for k in 0..3 {
            let t = (x[k] - p[k]) * n[k];
            s += t;
            a += t.abs();
        }
    }
    let bound = (2.0 * (3 * xs.len() + 4) as f64 * U) * a + TINY;
    if s.is_finite() && bound.is_finite() && s.abs() > bound {
        return Some(if s > 0.0 { Ordering::Greater } else { Ordering::Less });
    }
    let mut acc = Accumulator::new();
    for x in xs {
        for k in 0..3 {
            acc.add(false, &[x[k], n[k]]);
        }
    }
    for _ in 0..xs.len() {
        for k in 0..3 {
            acc.add(true, &[p[k], n[k]]);
        }
    }
    Some(acc.sign())
}

/// Whether the centroid of `xs` lies in the closed ball B(`centre`, `r`), exactly: the sign of
/// |Σ xᵢ − N c|² − N² r² (N = |xs|, the centroid's distance times N, squared), every product of
/// the expansion added without rounding. `false` when an input is not finite or `xs` is empty
/// (or past 2^26 points, where N² would round). Not filtered: O(N² · 3) products of a few hundred integer operations
/// each (finding 283: the rounded centroid and distance dropped faces exactly on the sphere and
/// moved with a translation).
pub(crate) fn centroid_in_ball(xs: &[Vec3], centre: Vec3, r: f64) -> bool {
    let finite = |v: &Vec3| v.iter().all(|c| c.is_finite());
    let n = xs.len() as f64;
    if xs.is_empty() || n > 67_108_864.0 || !finite(&centre) || !r.is_finite() || !xs.iter().all(finite) {
        return false;
    }
    let mut acc = Accumulator::new();
    for k in 0..3 {
        // (Σ xᵢ − N c)² = Σᵢ Σⱼ xᵢ xⱼ − 2N c Σᵢ xᵢ + N² c².
        for a in xs {
            for b in xs {
                acc.add(false, &[a[k], b[k]]);
            }
            acc.add(true, &[2.0 * n, centre[k], a[k]]);
        }
        acc.add(false, &[n * n, centre[k], centre[k]]);
    }
    acc.add(true, &[n * n, r, r]);
    acc.sign() != Ordering::Greater
}

/// One entry-wise term of a determinant column: the vector, negated when the flag is set.
pub(crate) type Term = (bool, Vec3);

/// The exact sign of det[c₀, c₁, c₂] = c₀ · (c₁ × c₂), each column the sum of its terms (one to
/// three signed `f64` vectors, e.g. `[(false, b), (true, a)]` for b − a); `None` when an input
/// is not finite. A float filter decides unless the value is within its error bound of zero;
/// then the exact sum of the expanded products decides. O(1).
pub(crate) fn det_sign(cols: [&[Term]; 3]) -> Option<Ordering> {
    if !cols.iter().all(|c| (1..=3).contains(&c.len()) && c.iter().all(|(_, v)| v.iter().all(|x| x.is_finite()))) {
        return None;
    }
    // Filter: a column summed left to right is off by at most u · (sum of its |partial sums|)
    // per component; with M = |column| + that sum, det is within about 8u · perm(M) of the
    // float one (3u from the columns, 5u from the products and sums), perm = |c₀| · (|c₁| × |c₂|)
    // with all signs positive.
    let mut val = [[0.0f64; 3]; 3];
    let mut mag = [[0.0f64; 3]; 3];
    for (j, col) in cols.iter().enumerate() {
        for k in 0..3 {
            let term = |t: &Term| if t.0 { -t.1[k] } else { t.1[k] };
            let mut s = term(&col[0]);
            let mut m = 0.0;
            for t in &col[1..] {
                s += term(t);
                m += s.abs();
            }
            val[j][k] = s;
            mag[j][k] = s.abs() + m;
        }
    }
    let det = dot(val[0], cross(val[1], val[2]));
    let perm = dot(mag[0], abs_cross(mag[1], mag[2]));
    // A product of the cross product that underflows is off by up to 2^-1075 absolutely, and the
    // dot multiplies that error by |c₀| (up to 2^1024): the underflow allowance scales with the
    // first column (finding 219), TINY covering the dot's own underflow.
    let bound = (16.0 * U) * perm + TINY * (1.0 + mag[0][0] + mag[0][1] + mag[0][2]);
    if det.is_finite() && bound.is_finite() && det.abs() > bound {
        return Some(if det > 0.0 { Ordering::Greater } else { Ordering::Less });
    }
    Some(det_exact(cols))
}

/// The sign of det[c₀, c₁, c₂] from the exact sum of its expanded products (no filter): the
/// reference [`det_sign`]'s filter must agree with. Finite inputs. O(27 · 6) products.
fn det_exact(cols: [&[Term]; 3]) -> Ordering {
    let mut acc = Accumulator::new();
    const PERMS: [([usize; 3], bool); 6] = [
        ([0, 1, 2], false),
        ([1, 2, 0], false),
        ([2, 0, 1], false),
        ([0, 2, 1], true),
        ([2, 1, 0], true),
        ([1, 0, 2], true),
    ];
    for (p, odd) in PERMS {
        for t0 in cols[0] {
            for t1 in cols[1] {
                for t2 in cols[2] {
                    acc.add(odd ^ t0.0 ^ t1.0 ^ t2.0, &[t0.1[p[0]], t1.1[p[1]], t2.1[p[2]]]);
                }
            }
        }
    }
    acc.sign()
}

/// The sign of det[b − a, c − a, d − a] (6 × the signed volume of the tet (a, b, c, d)) for the
/// exact values of the inputs: 1, −1, or 0 when the four points are coplanar, and 0 when a
/// coordinate is not finite (no orientation). At any finite scale, subnormal to `f64::MAX` and
/// mixed ([`det_sign`]). O(1).
pub(crate) fn orient3d(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> i8 {
    let from_a = |p: Vec3| [(false, p), (true, a)];
    match det_sign([&from_a(b), &from_a(c), &from_a(d)]) {
        Some(Ordering::Greater) => 1,
        Some(Ordering::Less) => -1,
        _ => 0,
    }
}

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The cross product with every product counted positive (for the error bound).
fn abs_cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] + a[2] * b[1], a[2] * b[0] + a[0] * b[2], a[0] * b[1] + a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact sum against an independent integer computation on small dyadic values, and
    /// sums whose float evaluation cancels to the wrong sign or to zero.
    #[test]
    fn accumulator_is_exact() {
        let mut acc = Accumulator::new();
        acc.add(false, &[1e300, 1e300, 1e-300]);
        acc.add(true, &[1e300, 1e300, 1e-300]);
        assert_eq!(acc.sign(), Ordering::Equal);
        acc.add(false, &[f64::from_bits(1), f64::from_bits(1), f64::from_bits(1)]);
        assert_eq!(acc.sign(), Ordering::Greater);
        // (1 + 2^-52)² − 1 − 2^-51 = 2^-104 > 0, while the float value is 0.
        let x = 1.0 + f64::EPSILON;
        let mut acc = Accumulator::new();
        acc.add(false, &[x, x]);
        acc.add(true, &[1.0]);
        acc.add(true, &[2.0 * f64::EPSILON]);
        assert_eq!(x * x - 1.0 - 2.0 * f64::EPSILON, 0.0);
        assert_eq!(acc.sign(), Ordering::Greater);
        // The extremes of the range do not overflow or wrap.
        let mut acc = Accumulator::new();
        for _ in 0..1000 {
            acc.add(true, &[f64::MAX, f64::MAX, f64::MAX]);
        }
        acc.add(false, &[f64::MAX, f64::MAX, 2.0]);
        assert_eq!(acc.sign(), Ordering::Less);
    }

    /// A point exactly on a plane is a zero whatever the normal's length; the nearest doubles
    /// on each side are not.
    #[test]
    fn plane_sign_is_exact() {
        // (1.25, 2.5, 3.75) on the plane through (2.75, 0.5, 3.25) with normal −(0.2, 0.1, 0.2).
        let (x, p) = ([1.25, 2.5, 3.75], [2.75, 0.5, 3.25]);
        for n in [[-2.0, -1.0, -2.0], [-0.2, -0.1, -0.2], [-2e-300, -1e-300, -2e-300], [-2e300, -1e300, -2e300]] {
            assert_eq!(plane_sign(&[x], p, n), Some(Ordering::Equal), "{n:?}");
        }
        let up = [1.25, 2.5, f64::from_bits(3.75f64.to_bits() + 1)];
        assert_eq!(plane_sign(&[up], p, [-0.2, -0.1, -0.2]), Some(Ordering::Less));
        assert_eq!(plane_sign(&[x], p, [f64::NAN, 0.0, 1.0]), None);
    }

    /// A determinant of differences that is exactly zero (three differences in the plane
    /// z = 0.1, rounded though they are) is zero, and one ulp above it has the exact sign.
    #[test]
    fn det_sign_is_exact() {
        let z: f64 = 0.1;
        let o = [0.1, 0.2, z];
        for (top, expected) in [(z, Ordering::Equal), (f64::from_bits(z.to_bits() + 1), Ordering::Less)] {
            let cols: [&[Term]; 3] = [
                &[(false, [0.3, 0.7, z]), (true, o)],
                &[(false, [0.9, 0.1, z]), (true, o)],
                &[(false, [0.5, 0.5, top]), (true, o)],
            ];
            // (0.2, 0.5, 0) × (0.8, −0.1, 0) points down: above the plane is negative.
            assert_eq!(det_sign(cols), Some(expected), "top {top}");
        }
    }

    const UNIT: [Vec3; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    #[test]
    fn orient3d_signs_of_ordinary_tets() {
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], UNIT[3]), 1);
        assert_eq!(orient3d(UNIT[0], UNIT[2], UNIT[1], UNIT[3]), -1);
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], [0.3, 0.7, 0.0]), 0);
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], UNIT[1]), 0);
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], [f64::NAN, 0.0, 1.0]), 0);
    }

    /// Near-coplanar cases: a point 2⁻⁶⁰ above a face of a unit tet, or on it ((0.1, 0.2, 0) is
    /// exactly on z = 0), and a dyadic point exactly on the slanted face x + y + z = 1.
    #[test]
    fn orient3d_near_ties() {
        let up = 2f64.powi(-60);
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], [0.1, 0.2, up]), 1);
        assert_eq!(orient3d(UNIT[0], UNIT[1], UNIT[2], [0.1, 0.2, -up]), -1);
        assert_eq!(orient3d(UNIT[1], UNIT[2], UNIT[3], [0.25, 0.5, 0.25]), 0);
        // z = 1 − 0.1 − 0.3 rounds to 0.6000000000000001; the exact sum of the three doubles is
        // 1 + 3·2⁻⁵⁵ (checked with rationals): beyond the face, away from UNIT[0].
        let p = [0.1, 0.3, 1.0 - 0.1 - 0.3];
        assert_eq!(orient3d(UNIT[1], UNIT[2], UNIT[3], p), -orient3d(UNIT[1], UNIT[2], UNIT[3], UNIT[0]));
    }

    /// Signs at every scale: the unit tet and a flat one scaled by 10^k (not a power of two, so
    /// the scaled corners round), a needle 1e-200 thin, zeros beside tiny and huge coordinates.
    #[test]
    fn orient3d_at_any_scale() {
        for k in -320..=307 {
            let s = 10f64.powi(k);
            if s == 0.0 {
                continue; // powi underflows before 1e-308
            }
            let t = UNIT.map(|p| p.map(|x| x * s));
            assert_eq!(orient3d(t[0], t[1], t[2], t[3]), 1, "1e{k}");
            assert_eq!(orient3d(t[1], t[0], t[2], t[3]), -1, "1e{k}");
            let mid = [0.5 * t[1][0], 0.5 * t[2][1], 0.0];
            assert_eq!(orient3d(t[0], t[1], t[2], mid), 0, "1e{k}");
        }
        assert_eq!(orient3d([0.0; 3], [1e-300, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, -0.0]), 0);
        assert_eq!(orient3d([0.0; 3], [1e-300, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 5e-324]), 1);
        let needle = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1e-200, 0.0], [0.0, 0.0, 1e-200]];
        assert_eq!(orient3d(needle[0], needle[1], needle[2], needle[3]), 1);
        assert_eq!(orient3d(needle[1], needle[0], needle[2], needle[3]), -1);
        let big = [[-f64::MAX, 0.0, 0.0], [f64::MAX, 0.0, 0.0], [0.0, f64::MAX, 0.0], [0.0, 0.0, 5e-324]];
        assert_eq!(orient3d(big[0], big[1], big[2], big[3]), 1);
    }
    /// Finding 219: a product of the cross product that underflows (5·2^-1076 → 2^-1074) is then
    /// multiplied by 2^1000; the determinant is +2^-77 exactly, the float value −2^-77.
    #[test]
    fn filter_allows_for_an_underflow_times_a_large_factor() {
        let p = |k: i32| 2f64.powi(k);
        let (a, b) = ([0.0; 3], [p(1000), -p(460), 0.0]);
        let (c, d) = ([0.0, 5.0 * p(-538), p(-537)], [1.0, p(-537), p(-538)]);
        assert_eq!(orient3d(a, b, c, d), 1);
        assert_eq!(orient3d(a, c, b, d), -1);
    }

    /// xorshift64: the next state (nonzero seed).
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    /// The filter never disagrees with the exact sum, on columns mixing every scale from
    /// subnormal to 2^1000 (a third of the entries zero, so products underflow and cancel).
    #[test]
    fn filter_agrees_with_the_exact_sum_at_mixed_scales() {
        let mut state = 0x219u64;
        let mut next = move || xorshift(&mut state);
        let exps = [-1074, -1060, -1000, -600, -538, -537, -460, -200, 0, 200, 460, 600, 1000];
        let mut value = || {
            let r = next();
            if r % 3 == 0 {
                return 0.0;
            }
            let mantissa = 1.0 + (r >> 40) as f64 / (1u64 << 24) as f64;
            let sign = if r & 2 == 0 { 1.0 } else { -1.0 };
            let e = exps[((r >> 8) % exps.len() as u64) as usize] + ((r >> 16) % 5) as i32;
            sign * mantissa * 2f64.powi(e.max(-1074))
        };
        let mut vec3 = || [value(), value(), value()];
        for _ in 0..200_000 {
            let (a, b, c, d) = (vec3(), vec3(), vec3(), vec3());
            let cols: [&[Term]; 3] = [&[(false, b), (true, a)], &[(false, c), (true, a)], &[(false, d), (true, a)]];
            assert_eq!(det_sign(cols), Some(det_exact(cols)), "{a:?} {b:?} {c:?} {d:?}");
        }
    }

    /// The filter never disagrees with the exact sum near ties: a fourth point put on the plane
    /// of three others and rounded, coordinates from 1e-3 to 1e3 in every component, so that any
    /// term of the error bound may be the one that matters.
    #[test]
    fn filter_agrees_with_the_exact_sum_near_ties() {
        let mut state = 0x2190u64;
        let mut unit = move || (xorshift(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        let mut disagree = 0;
        for case in 0..100_000 {
            let scale = [0, 1, 2].map(|k| 10f64.powi(((case / 3usize.pow(k)) % 3) as i32 * 3 - 3));
            let mut point = || [0, 1, 2].map(|k| (unit() - 0.5) * scale[k]);
            let (a, b, c) = (point(), point(), point());
            let (s, t) = (unit(), unit());
            let d = [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]));
            let cols: [&[Term]; 3] = [&[(false, b), (true, a)], &[(false, c), (true, a)], &[(false, d), (true, a)]];
            if det_sign(cols) != Some(det_exact(cols)) {
                disagree += 1;
            }
        }
        assert_eq!(disagree, 0);
    }
}

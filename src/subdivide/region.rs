//! Refinement driven by a region, with tet masses carried to the children (seed 004's use case:
//! refine the incision zone before cutting; issue 5, "mechanics coupling").
//!
//! # Zone
//! A tetrahedron is *in the zone* of the ball B(c, r) when its closed point set meets the ball:
//! dist(c, T) ≤ r, computed exactly (0 inside T, else the distance to the nearest face).
//!
//! # Order
//! [`LeveledMap::refine_around`] works level by level: at level L it subdivides 1→8 every tet of
//! the finest map with μt = L − 1 that is in the zone. All level-L operations end before any
//! level-(L+1) one, so every face a subdivided tet sees is either unsplit or split once (the
//! support of [`LeveledMap::subdivide_tet`]), and a coarser tet outside the zone is never touched
//! again (its faces on the zone side may carry several levels; that is the adaptive picture).
//!
//! # Mass rule
//! [`TetMasses`] holds one mass per volume id. When a tet of mass m is split into children of rest
//! volumes V_1..V_8, child k gets m · V_k / ΣV (the last one m minus the others), so Σ m_k = m up to
//! one rounding. Vertex masses are derived, never stored: m_v = Σ_{tets t ∋ v} m_t / 4 (seed 000,
//! §3.1), so Σ_v m_v = Σ_t m_t holds by construction.

use super::balance::LevelSplit;
use super::{LeveledMap, SubdivideError};
use crate::gmap::{AlphaMask, CellId, DartId};
use crate::mechanics::geom::{cross, dot, sub};

/// ρ · |V| of the tet with finite corners `p`: plain for ordinary corners
/// (`mechanics::geom::plain_corners`), else in wide floats with the same operation order
/// (`crate::wide`), so that V under- or overflowing f64 on its own does not make a representable
/// mass 0 or ∞ ([`TetMasses::from_density`]). O(1).
fn density_mass(density: f64, p: [[f64; 3]; 4]) -> f64 {
    if crate::mechanics::geom::plain_corners(p) {
        return density * crate::mesh::signed_volume(p[0], p[1], p[2], p[3]).abs();
    }
    use crate::wide::{six_volume, Wide};
    six_volume(p[0], p[1], p[2], p[3]).abs().div(Wide::new(6.0)).mul(Wide::new(density)).to_f64()
}

/// One mass per volume id of a [`LeveledMap<3>`] (index = volume cell id).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::{LeveledMap, TetMasses};
/// use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let m = LeveledMap::new(map, pts);
/// let masses = TetMasses::from_density(&m, 6.0).unwrap(); // volume 1/6
/// let t = m.map().cell_id(3, m.map().darts().next().unwrap());
/// assert!((masses.mass[t.index()] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMasses {
    /// `mass[t]`: the mass of volume t (0 for ids no volume uses). The operations that share
    /// masses and [`TetMasses::vertex_masses`] refuse masses without an entry for some live
    /// volume ([`SubdivideError::NoMass`]: masses made for a smaller map, or a volume created
    /// by an operation without masses) or with a negative or non-finite one
    /// ([`SubdivideError::BadMass`]); [`TetMasses::total`] counts a missing entry as 0.
    pub mass: Vec<f64>,
}

/// What [`LeveledMap::refine_around`] did.
///
/// # Examples
///
/// ```
/// use topomech::subdivide::{LeveledMap, TetMasses};
/// use topomech::GMap;
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let mut m = LeveledMap::new(map, pts);
/// let mut masses = TetMasses::from_density(&m, 1.0).unwrap();
/// let r = m.refine_around([0.1; 3], 10.0, 1, &mut masses).unwrap();
/// assert_eq!(r.subdivided_per_level, vec![0, 1]);
/// assert!((r.total_mass_after - r.total_mass_before).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Refinement {
    /// Tets subdivided at each level (index 0 unused, always 0).
    pub subdivided_per_level: Vec<usize>,
    /// Σ tet mass before.
    pub total_mass_before: f64,
    /// Σ tet mass after.
    pub total_mass_after: f64,
}

impl TetMasses {
    /// Masses ρ · |V_t| from the positions of the map's vertices. O(darts).
    ///
    /// The product is formed scale-safely: for ordinary corners as ρ · |V| (the same bits as
    /// ever), otherwise in wide floats (an f64 mantissa with an unbounded exponent), so that V
    /// under- or overflowing f64 on its own does not make a representable mass 0 or ∞ (ρ = 1e300
    /// at edge 1e-110, ρ = 1e-100 at edge 1e110, ρ = 1e300 for a needle 1e-170 thin).
    ///
    /// Errors: [`SubdivideError::BadDensity`] unless the density is finite and > 0;
    /// [`SubdivideError::NotATetrahedron`] if a volume does not have 4 vertices;
    /// [`SubdivideError::NoPosition`] for a vertex without a position;
    /// [`SubdivideError::MassOverflow`] when a mass or their sum is past `f64::MAX` (what
    /// [`Self::check`] refuses).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// # use topomech::subdivide::{SubdivideError, TetMasses};
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map.clone(), pts.clone());
    /// let masses = TetMasses::from_density(&m, 6.0).unwrap(); // the volume is 1/6
    /// assert!(matches!(TetMasses::from_density(&m, f64::NAN), Err(SubdivideError::BadDensity(_))));
    /// let short = LeveledMap::new(map, pts[..3].to_vec()); // vertex 3 has no position
    /// assert!(matches!(TetMasses::from_density(&short, 6.0), Err(SubdivideError::NoPosition { vertex: 3, points: 3 })));
    /// assert!((masses.total(&m) - 1.0).abs() < 1e-12);
    /// let big = LeveledMap::new(m.map().clone(), pts.iter().map(|p| p.map(|c| 2.0 * c)).collect());
    /// assert!(TetMasses::from_density(&m, f64::MAX).is_ok()); // MAX · 1/6
    /// let e = TetMasses::from_density(&big, f64::MAX).unwrap_err(); // MAX · 8/6 overflows
    /// assert!(matches!(e, SubdivideError::MassOverflow { .. }));
    /// ```
    pub fn from_density(m: &LeveledMap<3>, density: f64) -> Result<Self, SubdivideError> {
        if !(density.is_finite() && density > 0.0) {
            return Err(SubdivideError::BadDensity(density));
        }
        let map = m.map();
        let mut mass = vec![0.0; map.cell_id_bound(3)];
        for d in map.one_dart_per_cell(3) {
            let corners = m.corner_positions(m.tet_vertices(d)?)?;
            let t = map.cell_id(3, d);
            mass[t.index()] = density_mass(density, corners);
            // A tet that is not flat weighs something: 0 here is ρ·V below f64 (finding 268).
            if mass[t.index()] == 0.0 && !crate::mechanics::geom::is_flat(corners) {
                return Err(SubdivideError::MassTooSmall { volume: t.0, mass: 0.0 });
            }
        }
        let total = mass.iter().sum::<f64>();
        if !total.is_finite() {
            return Err(SubdivideError::MassOverflow { total });
        }
        let masses = TetMasses { mass };
        for d in map.one_dart_per_cell(3) {
            masses.check_mass(map.cell_id(3, d))?;
        }
        Ok(masses)
    }

    /// Σ of the tet masses of the live volumes, summed with compensation (within about 2 ulp of
    /// the exact sum at any size: finding 228). O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// # use topomech::subdivide::TetMasses;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// let mut masses = TetMasses::from_density(&m, 12.0).unwrap();
    /// m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    /// assert!((masses.total(&m) - 2.0).abs() < 1e-12);
    /// assert_eq!(TetMasses::default().total(&m), 0.0); // ids past the end weigh nothing
    /// ```
    pub fn total(&self, m: &LeveledMap<3>) -> f64 {
        let map = m.map();
        crate::mechanics::geom::compensated_sum(
            map.one_dart_per_cell(3).into_iter().map(|d| self.of(map.cell_id(3, d))),
        )
    }

    /// The mass of volume `t`, 0 past the end of `mass`. O(1).
    fn of(&self, t: CellId) -> f64 {
        self.mass.get(t.index()).copied().unwrap_or(0.0)
    }

    /// [`SubdivideError::NoMass`] unless every live volume of `m` has an entry: O(1) when the
    /// entries reach the map's volume id bound, else O(darts).
    pub(crate) fn check_cover(&self, m: &LeveledMap<3>) -> Result<(), SubdivideError> {
        let map = m.map();
        if self.mass.len() >= map.cell_id_bound(3) {
            return Ok(());
        }
        match map.one_dart_per_cell(3).into_iter().map(|d| map.cell_id(3, d)).find(|t| t.index() >= self.mass.len()) {
            Some(t) => Err(SubdivideError::NoMass { volume: t.0, masses: self.mass.len() }),
            None => Ok(()),
        }
    }

    /// Every live volume of `m` has an entry ([`SubdivideError::NoMass`]) whose mass is finite and ≥ 0
    /// ([`SubdivideError::BadMass`]), and their sum is finite ([`SubdivideError::MassOverflow`]).
    /// O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::{LeveledMap, SubdivideError, TetMasses};
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
    /// let m = LeveledMap::new(map, vec![]);
    /// assert_eq!(TetMasses { mass: vec![1.0, 2.0] }.check(&m), Ok(()));
    /// assert_eq!(TetMasses { mass: vec![1.0] }.check(&m), Err(SubdivideError::NoMass { volume: 1, masses: 1 }));
    /// assert!(matches!(TetMasses { mass: vec![1.0, f64::NAN] }.check(&m), Err(SubdivideError::BadMass { volume: 1, .. })));
    /// let huge = TetMasses { mass: vec![f64::MAX, f64::MAX] }; // each finite, the sum is not
    /// assert!(matches!(huge.check(&m), Err(SubdivideError::MassOverflow { .. })));
    /// ```
    pub fn check(&self, m: &LeveledMap<3>) -> Result<(), SubdivideError> {
        self.check_cover(m)?;
        let map = m.map();
        let mut total = 0.0;
        for t in map.one_dart_per_cell(3).into_iter().map(|d| map.cell_id(3, d)) {
            total += self.check_mass(t)?;
        }
        if !total.is_finite() {
            return Err(SubdivideError::MassOverflow { total });
        }
        Ok(())
    }

    /// [`SubdivideError::BadMass`] unless the entry of volume t (which must exist) is finite
    /// and ≥ 0. O(1).
    /// [`SubdivideError::MassTooSmall`] for a positive mass whose quarter (the least a vertex of
    /// the tet can weigh) has no finite inverse: below about 8.9e-308, where f64 loses relative
    /// precision and the mass laws could not hold (finding 268; a body refuses such masses too).
    fn check_mass(&self, t: CellId) -> Result<f64, SubdivideError> {
        match self.mass[t.index()] {
            mass if mass > 0.0 && !(4.0 / mass).is_finite() => Err(SubdivideError::MassTooSmall { volume: t.0, mass }),
            mass if mass.is_finite() && mass >= 0.0 => Ok(mass),
            mass => Err(SubdivideError::BadMass { volume: t.0, mass }),
        }
    }

    /// [`Self::check_mass`] for a tet about to be split 1→8: its children take about an eighth
    /// each, so a positive mass below 64 / `f64::MAX` (about 3.6e-307) is
    /// [`SubdivideError::MassTooSmall`] too (the children's quarters would have no finite
    /// inverse, finding 268). O(1).
    pub(super) fn check_split_mass(&self, t: CellId) -> Result<f64, SubdivideError> {
        match self.check_mass(t)? {
            mass if mass > 0.0 && !(64.0 / mass).is_finite() => Err(SubdivideError::MassTooSmall { volume: t.0, mass }),
            mass => Ok(mass),
        }
    }

    /// Vertex masses indexed by vertex id, lumped as [`super::LeveledMechanics::vertex_masses`]
    /// lumps them: m_v = Σ_{t ∋ v} m_t / 4 on a conforming map; a coarse volume with hanging
    /// vertices (inserted on its sides by a refined neighbour) gives each of them a share drawn
    /// from its corners, so no vertex is massless and Σ_v m_v = Σ_t m_t (round 25, F4: hanging
    /// vertices had no mass here). O(darts + splits).
    ///
    /// # Errors
    /// As [`Self::check`].
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// # use topomech::subdivide::TetMasses;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let masses = TetMasses::from_density(&m, 6.0).unwrap();
    /// let v = masses.vertex_masses(&m).unwrap();
    /// assert!(v.iter().all(|&x| (x - 0.25).abs() < 1e-12));
    /// assert!(TetMasses::default().vertex_masses(&m).is_err()); // no mass for volume 0
    /// let d = m.map().darts().next().unwrap();
    /// m.split_edge(d, 1).unwrap(); // vertex 4 hangs on a side of the tet
    /// let v = masses.vertex_masses(&m).unwrap();
    /// assert!((v[4] - 0.05).abs() < 1e-12 && (v.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    /// ```
    pub fn vertex_masses(&self, m: &LeveledMap<3>) -> Result<Vec<f64>, SubdivideError> {
        self.check(m)?;
        Ok(self.lumped(m))
    }

    /// [`Self::vertex_masses`] without the check (a volume without an entry weighs nothing).
    /// O(darts + splits).
    pub(crate) fn lumped(&self, m: &LeveledMap<3>) -> Vec<f64> {
        let map = m.map();
        let parents = super::springs::split_parents(m);
        let mut out = vec![0.0; map.cell_id_bound(0)];
        for t in map.one_dart_per_cell(3) {
            for (v, share) in super::springs::volume_shares_by_id(m, t, self.of(map.cell_id(3, t)), &parents) {
                out[v as usize] += share;
            }
        }
        out
    }
}

/// Distance from `p` to the segment [a, b]; finite for coordinate differences in
/// [2⁻²⁵⁰, 2²⁵⁰] ([`tet_distance`] scales its input there first). O(1).
fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 { (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    // The ends exactly: a + 1·(b − a) need not be b (for a needle's end 2⁻²⁵⁰ times its length
    // from the origin, it lost that end's coordinate).
    let q = match t {
        0.0 => a,
        1.0 => b,
        _ => [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]],
    };
    dot(sub(p, q), sub(p, q)).sqrt()
}

/// Distance from `p` to the closed triangle (a, b, c): the distance to its plane when the
/// projection falls inside, else the distance to the nearest side; for coordinate differences in
/// [2⁻²⁵⁰, 2²⁵⁰], as [`segment_distance`]. O(1).
fn triangle_distance(p: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    let nn = dot(n, n);
    if nn > 0.0 {
        let h = dot(sub(p, a), n) / nn;
        let q = [p[0] - h * n[0], p[1] - h * n[1], p[2] - h * n[2]];
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(x, y)| dot(cross(sub(y, x), sub(q, x)), n) >= 0.0);
        if inside {
            return h.abs() * nn.sqrt();
        }
    }
    segment_distance(p, a, b).min(segment_distance(p, b, c)).min(segment_distance(p, c, a))
}

/// m · v / total: the share of the mass m of a parent for a child of volume v out of the
/// children's total volume. Formed as m · (v / total) when m · v overflows (masses near
/// `f64::MAX`, which [`TetMasses::check`] accepts as long as their sum is finite), so a finite
/// mass never gives an infinite or NaN share; bit for bit m · v / total otherwise. O(1).
pub(super) fn share(m: f64, v: f64, total: f64) -> f64 {
    let mv = m * v;
    if mv.is_finite() {
        mv / total
    } else {
        m * (v / total)
    }
}

/// Distance from `p` to the closed tetrahedron with corners `t`: **exactly 0 when `p` lies in the
/// closed tet** (inside, or on a face, an edge or a corner), else the distance to the nearest
/// face, which is then > 0; NaN when a coordinate of `p` or `t` is NaN (not the infinity a
/// minimum that skips NaN would give).
///
/// The in-or-out decision is exact (finding 214): the signs of the four volumes
/// [face, `p`] against that of the tet are exact orientation signs of the given coordinates (a
/// float filter, integers when it cannot decide), so it does not depend on the order of the
/// corners nor on the scale, and a point on the tet is never measured as 1e-17 away (the
/// rounded signed volumes of a corner gave ±1e-33 instead of 0, so `refine_around(v, 0.0, …)`
/// left part of the star of v coarse). A tet of exactly zero volume (flat) has no inside: its
/// distance is that of its faces, as below.
///
/// The distance of an outside point is computed in floating point, to a few ulps (its rounding
/// depends on the corner order; a point outside is given at least the smallest positive `f64`, so
/// a ball of radius 0 meets exactly the tets that contain its centre). At any scale of finite
/// coordinates: when the largest coordinate difference is outside [2⁻²⁵⁰, 2²⁵⁰] (squares of
/// products of differences would over- or underflow), the corners are translated to `p` and
/// scaled by one power of two for the distance, which is scaled back (∞ only for a distance past
/// `f64::MAX`); inside that range nothing is translated or scaled. With an infinite coordinate
/// (and none NaN) the faces' distances decide (∞ or NaN). O(1).
///
/// # Examples
///
/// ```
/// use topomech::subdivide::tet_distance;
/// let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// assert_eq!(tet_distance([0.1, 0.1, 0.1], t), 0.0);
/// assert_eq!(tet_distance(t[2], t), 0.0); // a corner
/// assert_eq!(tet_distance([0.25, 0.5, 0.25], t), 0.0); // on the slanted face
/// assert!((tet_distance([0.0, 0.0, -3.0], t) - 3.0).abs() < 1e-12);
/// assert!(tet_distance([f64::NAN, 0.0, 0.0], t).is_nan());
/// let huge = t.map(|c| c.map(|x| x * 1e110)); // squared differences would overflow
/// assert_eq!(tet_distance([1e109; 3], huge), 0.0);
/// assert!((tet_distance([2e200, 0.0, 0.0], t) / 2e200 - 1.0).abs() < 1e-15);
/// ```
pub fn tet_distance(p: [f64; 3], t: [[f64; 3]; 4]) -> f64 {
    if p.iter().chain(t.iter().flatten()).any(|c| c.is_nan()) {
        return f64::NAN;
    }
    if p.iter().chain(t.iter().flatten()).any(|c| c.is_infinite()) {
        return faces_distance(p, t); // ∞ or NaN, decided by the plain formula
    }
    // Exact, on the coordinates as given (the fitting below rounds its translation).
    if closed_tet_contains(p, t) {
        return 0.0;
    }
    // p first: a fitted p is the origin. Nothing moves for a plain extent (k = 0).
    let mut points = [p, t[0], t[1], t[2], t[3]];
    let k = crate::mesh::fit_for_products(&mut points);
    let [p, t @ ..] = points;
    let d = crate::mesh::times_pow2(faces_distance(p, t), -k);
    // p is outside (exactly): a rounded or underflowed 0 would put it in a ball of radius 0.
    if d == 0.0 {
        f64::from_bits(1)
    } else {
        d
    }
}

/// The exact sign of the signed volume of the tet `c` (1, −1 or 0; 0 for a non-finite
/// coordinate), by exact orientation (`crate::exact::orient3d`), at any scale. O(1).
fn volume_sign(c: [[f64; 3]; 4]) -> f64 {
    f64::from(crate::exact::orient3d(c[0], c[1], c[2], c[3]))
}

/// Whether `p` lies in the closed tet `t` (finite coordinates), exactly: the tet has a nonzero
/// volume and `p` is on the inner side of, or on, each of the four face planes. The answer is a
/// property of the point set, the same for every order of the corners. O(1).
fn closed_tet_contains(p: [f64; 3], t: [[f64; 3]; 4]) -> bool {
    let faces = [[t[1], t[2], t[3]], [t[0], t[3], t[2]], [t[0], t[1], t[3]], [t[0], t[2], t[1]]];
    let vol = volume_sign(t);
    // Each face is listed so that the opposite corner gives the sign of −vol: p is inside when it
    // is on that side (or on the plane) of all four faces. Signs compared, never multiplied.
    vol != 0.0
        && faces.iter().all(|f| {
            let s = volume_sign([f[0], f[1], f[2], p]);
            s == 0.0 || s != vol
        })
}

/// The distance from `p` to the nearest face of `t` (the four closed triangles), without
/// scaling: finite results for coordinate differences in [2⁻²⁵⁰, 2²⁵⁰]. O(1).
fn faces_distance(p: [f64; 3], t: [[f64; 3]; 4]) -> f64 {
    let faces = [[t[1], t[2], t[3]], [t[0], t[3], t[2]], [t[0], t[1], t[3]], [t[0], t[2], t[1]]];
    faces.iter().map(|&f| triangle_distance(p, f)).fold(f64::INFINITY, f64::min)
}

/// The splitter of [`LeveledMap::refine_around`] on maps with level skips
/// ([`LeveledMap::refine_mixed`]): masses shared by rest volume, the bulk path where it applies.
struct PlainSplit<'a> {
    masses: &'a mut TetMasses,
    bulk: bool,
    center: [f64; 3],
    radius: f64,
}

impl LevelSplit for PlainSplit<'_> {
    type Error = SubdivideError;

    fn split(&mut self, m: &mut LeveledMap<3>, d: DartId, level: u8) -> Result<(), SubdivideError> {
        m.subdivide_tet_with_mass(d, level, self.masses).map(|_| ())
    }

    fn bulk(&mut self, m: &mut LeveledMap<3>, level: u8) -> Result<Option<usize>, SubdivideError> {
        if !(self.bulk && m.bulk_applies(self.center, self.radius, level)) {
            return Ok(None);
        }
        match m.refine_uniform(level, self.masses) {
            Ok(r) => Ok(Some(r.subdivided_per_level[level as usize])),
            Err(e @ SubdivideError::DartLimit { .. }) => Err(e),
            Err(_) => Ok(None),
        }
    }

    fn check_zone(&mut self, m: &LeveledMap<3>, level: u8, zone: &[DartId]) -> Result<(), SubdivideError> {
        m.check_zone(level, zone, self.masses)
    }
}

impl LeveledMap<3> {
    /// The four corner vertex ids of the tet of `d` at its own level μt, in increasing order (a
    /// tet outside a refined zone may carry inserted vertices of its neighbours on its sides in
    /// the finest map; they are not corners). O(volume).
    ///
    /// Errors: [`SubdivideError::NoSuchDart`] when `d` is not live,
    /// [`SubdivideError::NotATetrahedron`] when the volume at its level is not a tet,
    /// [`SubdivideError::OpenEdge`] when it is not closed.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// assert_eq!(m.tet_vertices(d).unwrap(), [0, 1, 2, 3]);
    /// assert!(m.tet_vertices(topomech::DartId(99)).is_err()); // no such dart
    /// let children = m.subdivide_tet(d, 1).unwrap();
    /// assert!(children.iter().all(|&c| m.tet_vertices(c).unwrap().iter().all(|&v| v < 10)));
    /// ```
    pub fn tet_vertices(&self, d: DartId) -> Result<[u32; 4], SubdivideError> {
        if !self.map.contains(d) {
            return Err(SubdivideError::NoSuchDart(d));
        }
        let mut corners = self.tet_corners(d, self.mu[d.index()].tet)?;
        corners.sort_unstable();
        Ok(corners)
    }

    /// Signed volume of the tet of `d` from the stored positions (vertex ids in increasing
    /// order). O(volume).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// assert!((m.tet_volume(d).unwrap().abs() - 1.0 / 6.0).abs() < 1e-15);
    /// let children = m.subdivide_tet(d, 1).unwrap();
    /// let sum: f64 = children.iter().map(|&c| m.tet_volume(c).unwrap().abs()).sum();
    /// assert!((sum - 1.0 / 6.0).abs() < 1e-14);
    /// ```
    pub fn tet_volume(&self, d: DartId) -> Result<f64, SubdivideError> {
        let p = self.corner_positions(self.tet_vertices(d)?)?;
        Ok(crate::mesh::signed_volume(p[0], p[1], p[2], p[3]))
    }

    /// The positions of the corners `t`; [`SubdivideError::NoPosition`] for one without,
    /// [`SubdivideError::NonFinitePosition`] for one that is NaN or infinite. O(1).
    fn corner_positions(&self, t: [u32; 4]) -> Result<[[f64; 3]; 4], SubdivideError> {
        let mut p = [[0.0; 3]; 4];
        for (k, &v) in t.iter().enumerate() {
            p[k] = *self
                .points
                .get(v as usize)
                .ok_or(SubdivideError::NoPosition { vertex: v, points: self.points.len() })?;
            if !p[k].iter().all(|c| c.is_finite()) {
                return Err(SubdivideError::NonFinitePosition { vertex: v, position: p[k] });
            }
        }
        Ok(p)
    }

    /// Whether the tet of `d` meets the closed ball B(center, radius). O(volume).
    ///
    /// Errors: [`SubdivideError::BadBall`] unless the centre is finite and the radius finite and
    /// ≥ 0; those of [`Self::tet_vertices`]; [`SubdivideError::NoPosition`].
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// assert!(m.tet_in_ball(d, [2.0, 0.0, 0.0], 1.5).unwrap());
    /// assert!(!m.tet_in_ball(d, [2.0, 0.0, 0.0], 0.5).unwrap());
    /// assert!(m.tet_in_ball(d, [2.0, 0.0, 0.0], f64::NAN).is_err()); // BadBall, not "no"
    /// ```
    pub fn tet_in_ball(&self, d: DartId, center: [f64; 3], radius: f64) -> Result<bool, SubdivideError> {
        Self::check_ball(center, radius)?;
        let p = self.corner_positions(self.tet_vertices(d)?)?;
        Ok(tet_distance(center, p) <= radius)
    }

    /// Subdivides the tet of `d` 1→8 at `level` (see [`Self::subdivide_tet`]) and shares its mass
    /// among the children in proportion to their rest volumes (module docs). O(volume + touched).
    ///
    /// Errors: those of [`Self::tet_volume`] for the tet of `d` (no such dart, a corner without a
    /// finite position: the volumes are needed), [`SubdivideError::NoMass`] when some live
    /// volume has no entry in `masses` (O(1) when they reach the volume id bound),
    /// [`SubdivideError::BadMass`] for the parent's, and those of [`Self::subdivide_tet`] (among
    /// them [`SubdivideError::BelowPrecision`]); the map and the masses are unchanged on error.
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::{LeveledMap, SubdivideError};
    /// # use topomech::{DartId, GMap};
    /// # use topomech::subdivide::TetMasses;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut bare = LeveledMap::new(map.clone(), vec![]); // no geometry: no volumes to share by
    /// let mut masses = TetMasses { mass: vec![1.0] };
    /// let e = bare.subdivide_tet_with_mass(DartId(0), 1, &mut masses).unwrap_err();
    /// assert!(matches!(e, SubdivideError::NoPosition { points: 0, .. }));
    /// assert_eq!(bare.map().dart_count(), 24); // refused before any change
    /// let mut m = LeveledMap::new(map, pts);
    /// assert!(matches!(m.subdivide_tet_with_mass(DartId(9999), 1, &mut masses), Err(SubdivideError::NoSuchDart(_))));
    /// let d = m.map().darts().next().unwrap();
    /// let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    /// let children = m.subdivide_tet_with_mass(d, 1, &mut masses).unwrap();
    /// let cell = |c| m.map().cell_id(3, c).index();
    /// let shared: f64 = children.iter().map(|&c| masses.mass[cell(c)]).sum();
    /// assert!((shared - 1.0).abs() < 1e-12);
    /// ```
    pub fn subdivide_tet_with_mass(
        &mut self,
        d: DartId,
        level: u8,
        masses: &mut TetMasses,
    ) -> Result<[DartId; 8], SubdivideError> {
        // The parent's volume first: a dead dart, a corner without a (finite) position or a
        // volume that is no tet is refused here, before the map changes (the children's corners
        // are the parent's and midpoints of its edges).
        self.tet_volume(d)?;
        masses.check_cover(self)?;
        let parent = masses.check_split_mass(self.map.cell_id(3, d))?;
        let children = self.subdivide_tet(d, level)?;
        let volumes = self.volumes_of_children(&children)?;
        let total: f64 = volumes.iter().sum();
        masses.mass.resize(self.map.cell_id_bound(3).max(masses.mass.len()), 0.0);
        let mut given = 0.0;
        for (k, &c) in children.iter().enumerate() {
            let share = if k + 1 == children.len() {
                // The rest, so that the sum is the parent's; ≥ 0 (a child of a nearly flat
                // parent may come out of zero computed volume, the others' shares a few ulps over).
                (parent - given).max(0.0)
            } else if total > 0.0 {
                share(parent, volumes[k], total)
            } else {
                parent / children.len() as f64
            };
            given += share;
            masses.mass[self.map.cell_id(3, c).index()] = share;
        }
        Ok(children)
    }

    /// |volume| of each of the eight `children` of a subdivided tet, up to one common factor
    /// (`geom::volume_ratios`: 1 for ordinary corners), so that their ratios are finite for any
    /// finite corners. O(1).
    ///
    /// Errors: those of [`Self::tet_vertices`] and of the corner positions (not met for the
    /// children of a tet whose corners have finite positions: their corners are those and the
    /// finite midpoints of its edges).
    fn volumes_of_children(&self, children: &[DartId; 8]) -> Result<[f64; 8], SubdivideError> {
        let mut tets = [[[0.0; 3]; 4]; 8];
        for (t, &c) in tets.iter_mut().zip(children) {
            *t = self.corner_positions(self.tet_vertices(c)?)?;
        }
        Ok(crate::mechanics::geom::volume_ratios(tets))
    }

    /// Refines the zone of the ball B(center, radius) up to level `levels` (module docs), with
    /// **zones balanced across faces** (finding 264, `super::balance`, SUBDIVISION.md): level by
    /// level from max(1, k) (k the map's maximum level), the zone of level L is every tet with
    /// μt < min(L, `levels`) within up to three face rings of a tet meeting the ball, and the tets
    /// that must be split before one of them (read off the faces: a neighbour that would see a
    /// face refined twice); the zone tets nothing blocks are split 1→8 at L (a tet below
    /// μt = L − 1 by a level skip), their masses shared by [`Self::subdivide_tet_with_mass`], and
    /// the others wait for a later level, if need be past `levels` (then
    /// `subdivided_per_level` has more entries): a chain of blockers can hold a tet back for
    /// several levels (finding 275), and a tet held back is split by a level skip, so its
    /// children have the size of the level it waited at and a μt that can be several levels past
    /// `levels`. So no face is ever refined twice, and every tet stays splittable
    /// ([`Self::check_faces_refinable`]). When the ball holds every vertex and every tet is at
    /// level L − 1, level L is done by the bulk [`Self::refine_uniform`] (same
    /// result, numbering aside); otherwise, or if it refuses, op by op
    /// ([`Self::refine_around_per_op`]). On a map at level 0 each level is checked before its
    /// first split and the levels done before a refusal stay; on a map above level 0 the call is
    /// all or nothing (the map and the masses are copied first, O(darts) memory, and put back on
    /// any error). Returns the count per level and the mass totals. After `Ok`, every tet of the
    /// finest map that meets the ball has μt ≥ `levels`. O(Σ_L (darts + zone volumes ·
    /// (neighbours + edge rings))); O(darts) per bulk level.
    ///
    /// Errors: [`SubdivideError::LevelTooHigh`] for `levels` above [`super::MAX_LEVEL`],
    /// [`SubdivideError::LevelBelowMax`] below the map's level, [`SubdivideError::BadBall`] for a
    /// non-finite centre or radius or a negative radius, those of [`TetMasses::check`], before
    /// any change; on a level-0 map, at a level, [`SubdivideError::DartLimit`] for a level whose
    /// darts (counted exactly before it starts) would pass the dart limit, and the refusals of
    /// [`Self::subdivide_tet_with_mass`] for any tet of its zone
    /// ([`SubdivideError::BelowPrecision`] for an edge too short for its midpoint to be
    /// representable strictly between its ends: about 52 − log2(|coordinates| / edge length)
    /// levels can be made; [`SubdivideError::FlatChild`]), all checked on the whole level before
    /// its first split, so an error leaves the map and the masses as the levels before it left
    /// them: unchanged when it comes at the first level, the earlier levels done when it comes
    /// later (a split mass check, [`SubdivideError::MassTooSmall`], can pass at one level and
    /// fail on the children at the next: finding 273); on a map above level 0,
    /// the same refusals and [`SubdivideError::FaceRefinedTooFar`] for a tet whose face single
    /// operations refined twice, with the map and the masses put back.
    ///
    /// ```
    /// use topomech::subdivide::{LeveledMap, TetMasses};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, points);
    /// let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    /// let r = m.refine_around([0.1, 0.1, 0.1], 10.0, 2, &mut masses).unwrap();
    /// assert_eq!(r.subdivided_per_level, vec![0, 1, 8]);
    /// assert_eq!(m.map().count_cells().0[3], 64);
    /// assert!((r.total_mass_after - 1.0).abs() < 1e-12);
    /// ```
    pub fn refine_around(
        &mut self,
        center: [f64; 3],
        radius: f64,
        levels: u8,
        masses: &mut TetMasses,
    ) -> Result<Refinement, SubdivideError> {
        let result = self.refine_zone(center, radius, levels, masses, true);
        self.expensive_check_all("a refinement around a ball");
        result
    }

    /// [`Self::refine_around`] op by op only ([`Self::subdivide_tet_with_mass`] on every tet of
    /// the zone, level by level), never the bulk path: the reference the bulk path is tested and
    /// benchmarked against. Same errors and result (numbering aside).
    ///
    /// ```
    /// use topomech::subdivide::{LeveledMap, TetMasses};
    /// use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, points);
    /// let mut masses = TetMasses::from_density(&m, 6.0).unwrap();
    /// let r = m.refine_around_per_op([0.1, 0.1, 0.1], 10.0, 1, &mut masses).unwrap();
    /// assert_eq!(r.subdivided_per_level, vec![0, 1]);
    /// ```
    pub fn refine_around_per_op(
        &mut self,
        center: [f64; 3],
        radius: f64,
        levels: u8,
        masses: &mut TetMasses,
    ) -> Result<Refinement, SubdivideError> {
        let result = self.refine_zone(center, radius, levels, masses, false);
        self.expensive_check_all("a refinement around a ball");
        result
    }

    /// [`Self::refine_around`] (`bulk`: a level may go through [`Self::refine_uniform`]) or
    /// [`Self::refine_around_per_op`] (not `bulk`). On a map above level 0 by
    /// [`Self::refine_mixed`], all or nothing: the map and the masses are copied first and put
    /// back on any error.
    fn refine_zone(
        &mut self,
        center: [f64; 3],
        radius: f64,
        levels: u8,
        masses: &mut TetMasses,
        bulk: bool,
    ) -> Result<Refinement, SubdivideError> {
        self.check_op_level(levels)?;
        Self::check_ball(center, radius)?;
        masses.check(self)?;
        let before = masses.total(self);
        if self.max_level == 0 {
            // Levels done before a refusal stay (each level checked before its first split).
            let per_level =
                self.refine_mixed(center, radius, levels, &mut PlainSplit { masses, bulk, center, radius })?;
            let after = masses.total(self);
            return Ok(Refinement {
                subdivided_per_level: per_level,
                total_mass_before: before,
                total_mass_after: after,
            });
        }
        let saved = (self.clone(), masses.clone());
        let mut splitter = PlainSplit { masses, bulk, center, radius };
        match self.refine_mixed(center, radius, levels, &mut splitter) {
            Ok(per_level) => Ok(Refinement {
                subdivided_per_level: per_level,
                total_mass_before: before,
                total_mass_after: masses.total(self),
            }),
            Err(e) => {
                (*self, *masses) = saved;
                Err(e)
            }
        }
    }

    /// The refusals [`Self::subdivide_tet_with_mass`] at `level` would make for the tets of `zone`
    /// (one dart each, all at μt = level − 1, as [`Self::zone_tets`] gives them), made on the map
    /// as it is, before any of them is split: the mass entries, the tet's volume (live dart,
    /// corners at its level, finite corner positions), its faces (the checks of
    /// [`Self::subdivide_tet`]: each a triangle, unsplit or a child of one 1→4 split with single
    /// inner sides, else `FaceRefinedTooFar`; an unsplit face with μf ≥ level is `AlreadyAtLevel`),
    /// the midpoints of the edges it splits (`BelowPrecision`: the edges are the sides without an
    /// inserted vertex of its unsplit faces, whose ends do not move during the level) and the
    /// finite positions of the vertices that become corners of its children (the flat vertices
    /// reused as midpoints, the corners of its split faces). O(Σ zone volumes).
    ///
    /// Why it suffices: splitting zone tets in any order at `level` cannot make another zone tet N
    /// refuse once every one has passed here.
    /// - A tet of μt = t has, at its creation (or at level 0), only unsplit faces, all with μf ≥ t
    ///   (`set_tet_levels`; a parent refuses a face refined twice, so a child never starts with a
    ///   split face); a face is split only at a level above its μf. So every split face of a zone
    ///   tet was split at `level` itself (the operations before came at levels ≤ `level`), and its
    ///   children carry μf = `level` on both sides (`set_child_levels` walks the α3 side too).
    /// - Splitting a zone tet T first splits its unsplit faces F at `level`. For N behind F, F was
    ///   either unsplit (now split once at `level`: three corner children and a centre whose
    ///   corners are N's, single new inner sides; `check_tet_faces` accepts it, and F is no longer
    ///   among the unsplit faces μf is checked on) or a child of a split face of N; the latter
    ///   would refine N's face twice, but then F carries μf = `level` by the first point, and T
    ///   was refused here. The sides of F without a flat vertex are split: for N they are sides
    ///   of an unsplit face (flats allowed) or outer half-sides of a split child (allowed); an
    ///   inner side of N's split child was made at `level` with faces of μf = `level` only, so it
    ///   is no side of T's unsplit F (μf < `level`).
    /// - Then μf (and μa) are raised to `level` on the faces of T's children: T's split faces and
    ///   their children seen from N, never one that stays unsplit for N with μf < `level`.
    /// - N's corners are read at μt = level − 1 (`alpha_at`), which operations at `level` do not
    ///   change; no dart becomes free; N's volume id, mass and corner positions stay; the
    ///   midpoints created meanwhile get finite positions (midpoints of finite corners).
    pub(super) fn check_zone(&self, level: u8, zone: &[DartId], masses: &TetMasses) -> Result<(), SubdivideError> {
        masses.check_cover(self)?;
        for &d in zone {
            self.tet_volume(d)?;
            masses.check_split_mass(self.map.cell_id(3, d))?;
            self.check_zone_tet(d, level)?;
        }
        Ok(())
    }

    /// The face checks of [`Self::check_zone`] for the tet of `d`, in the order
    /// [`Self::subdivide_tet`] makes them (the same faces and the same first error), then the
    /// positions of the corners of its children that are not its own corners. O(volume).
    fn check_zone_tet(&self, d: DartId, level: u8) -> Result<(), SubdivideError> {
        let corners = self.tet_corners(d, self.mu[d.index()].tet)?;
        let mut midpoints = Vec::new();
        let unsplit = self.check_tet_faces_visiting(d, &corners, |sides, is_corner| {
            for (s, &corner) in sides.iter().zip(is_corner) {
                if !corner {
                    midpoints.push(self.map.vertex_id(s.start).0);
                } else if is_corner.iter().all(|&c| c) {
                    // The flat vertex the split of this unsplit face takes as the midpoint of
                    // the side (`side_midpoint`: the one of lowest dart level), if any.
                    let oldest = s.flats.iter().min_by_key(|(a, _)| self.dart_level[a.index()]);
                    midpoints.extend(oldest.map(|&(a, _)| self.map.vertex_id(a).0));
                }
            }
        })?;
        if let Some(&f) = unsplit.iter().find(|f| self.mu[f.index()].face >= level) {
            let cell_level = self.mu[f.index()].face;
            return Err(SubdivideError::AlreadyAtLevel { dart: f, dim: 2, cell_level, level });
        }
        self.check_split_midpoints(&unsplit, level)?;
        self.check_children(d, level, &corners)?;
        for v in midpoints {
            self.corner_positions([v; 4])?;
        }
        Ok(())
    }

    /// After a level of [`Self::refine_mixed`] that split `tets` tets, starting at `darts` live
    /// darts: [`SubdivideError::DartLimit`] if the map now passes its limit (the exact count
    /// before such a level can be short for a zone mixing levels; the caller puts its copy
    /// back). O(1).
    pub(super) fn check_caught_up(&self, darts: usize, tets: usize) -> Result<(), SubdivideError> {
        let (estimate, limit) = (self.map.dart_count(), self.max_darts);
        if estimate > limit {
            return Err(SubdivideError::DartLimit { level: self.max_level, tets, darts, estimate, limit });
        }
        Ok(())
    }

    /// Refuses a ball with a non-finite centre or a radius that is not a finite number ≥ 0. O(1).
    pub(super) fn check_ball(center: [f64; 3], radius: f64) -> Result<(), SubdivideError> {
        if center.iter().all(|c| c.is_finite()) && radius.is_finite() && radius >= 0.0 {
            return Ok(());
        }
        Err(SubdivideError::BadBall { center, radius })
    }

    /// Refuses splitting every tet of `zone` 1→8 at `level` (a level of `refine_around`, or a
    /// level of [`Self::refine_mixed`]) when the darts after it, counted exactly by [`Self::zone_darts_added`], exceed
    /// the limit ([`SubdivideError::DartLimit`]). O(Σ zone volumes + rings of the edges it splits).
    pub(super) fn check_zone_darts(&self, level: u8, zone: &[DartId]) -> Result<(), SubdivideError> {
        let after = self.map.dart_count().saturating_add(self.zone_darts_added(zone));
        self.check_dart_limit(level, zone.len(), after)
    }

    /// The darts that splitting every tet of `zone` 1→8 adds, counted on the map as it is:
    ///
    /// Δ = 96 · |zone| + Σ_{faces F} 12 · sides(F) + Σ_{edges E} |orbit(E)|
    ///
    /// - 96 per tet: its 8 inner triangles, two sides of 6 darts each;
    /// - F over the distinct unsplit faces of zone tets (three corners of the tet): each side
    ///   (2 if α3-sewn, else 1) gets the 3 inner edges of a 1→4 split, 4 darts each;
    /// - E over the distinct edges those splits split (their sides without an inserted vertex):
    ///   every dart of the orbit gets a partner, 4 per tet of the edge's ring (zone or not).
    ///
    /// Exact for a zone of one level (a level of `refine_around`), whatever the order of the
    /// splits: a face or edge is split once, by the first zone tet that has it (the others then
    /// see it split and reuse it), and the orbit of such an edge does not change before it is
    /// split (the splits meanwhile add faces only along edges between midpoints, which no unsplit
    /// face of a zone tet has as a side: [`Self::check_zone`]). A zone mixing levels can
    /// pass it by 4 darts per edge ([`Self::refine_mixed`] checks again). A tet some zone check
    /// refuses counts for the faces it passes (the level is refused anyway).
    /// O(Σ zone volumes + Σ_E |orbit(E)|).
    fn zone_darts_added(&self, zone: &[DartId]) -> usize {
        let (mut faces, mut edges) = (Vec::new(), Vec::new());
        for &d in zone {
            self.zone_tet_splits(d, &mut faces, &mut edges);
        }
        faces.sort_unstable();
        faces.dedup_by_key(|f| f.0);
        edges.sort_unstable_by_key(|e| e.0);
        edges.dedup_by_key(|e| e.0);
        let face_darts: usize = faces.iter().map(|&(_, sides)| 12 * sides).sum();
        let edge_orbit = |&(_, x): &(u32, DartId)| self.map.orbit(x, AlphaMask::cell(3, 1)).len();
        let edge_darts: usize = edges.iter().map(edge_orbit).sum();
        zone.len().saturating_mul(96).saturating_add(face_darts).saturating_add(edge_darts)
    }

    /// The faces that the split of the tet of `d` splits 1→4 (its unsplit faces, as (face id,
    /// sides)) and the edges those split (their sides without an inserted vertex, as (edge id, a
    /// dart)); the faces before the first one [`Self::check_tet_faces_visiting`] refuses.
    /// O(volume).
    pub(super) fn zone_tet_splits(&self, d: DartId, faces: &mut Vec<(u32, usize)>, edges: &mut Vec<(u32, DartId)>) {
        let Ok(corners) = self.tet_corners(d, self.mu[d.index()].tet) else { return };
        let _ = self.check_tet_faces_visiting(d, &corners, |sides, is_corner| {
            if !is_corner.iter().all(|&c| c) {
                return;
            }
            let f = sides[0].start;
            faces.push((self.map.cell_id(2, f).0, if self.map.is_free(3, f) { 1 } else { 2 }));
            let split = sides.iter().filter(|s| s.flats.is_empty());
            edges.extend(split.map(|s| (self.map.cell_id(1, s.start).0, s.start)));
        });
    }

    /// Whether a level of `refine_around` may take the bulk path: the ball holds every vertex and
    /// every tet is at level − 1 (so the zone is the whole mesh). O(points + darts).
    pub(super) fn bulk_applies(&self, center: [f64; 3], radius: f64, level: u8) -> bool {
        self.ball_holds_all(center, radius) && self.all_tets_at(level - 1)
    }

    /// Whether every stored vertex position lies in the closed ball (then every tet meets it), by
    /// the scale-safe [`crate::mesh::distance`] (with squared differences, a vertex 1e200 from the
    /// centre was at ∞, outside a ball of radius 2e200). O(points).
    fn ball_holds_all(&self, center: [f64; 3], radius: f64) -> bool {
        let inside = |p: &[f64; 3]| crate::mesh::distance(*p, center) <= radius;
        if self.points.is_empty() {
            return inside(&[0.0; 3]);
        }
        self.points.iter().all(inside)
    }

    /// Whether every live dart has μt = `lt` (a quick filter before the bulk path). O(darts).
    fn all_tets_at(&self, lt: u8) -> bool {
        self.map.darts().all(|d| self.mu[d.index()].tet == lt)
    }

    /// The tets of the finest map as vertex quadruples (positive orientation: the exact sign of
    /// the signed volume of the stored positions, at any scale, finding 216; a tet of exactly zero
    /// volume keeps its increasing order) with their μt, for output. O(darts).
    ///
    /// # Examples
    ///
    /// ```
    /// # use topomech::subdivide::LeveledMap;
    /// # use topomech::GMap;
    /// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
    /// let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mut m = LeveledMap::new(map, pts);
    /// let d = m.map().darts().next().unwrap();
    /// m.subdivide_tet(d, 1).unwrap();
    /// let tets = m.finest_tets().unwrap();
    /// assert_eq!(tets.len(), 8);
    /// assert!(tets.iter().all(|&(_, level, _)| level == 1));
    /// ```
    pub fn finest_tets(&self) -> Result<Vec<([u32; 4], u8, CellId)>, SubdivideError> {
        let mut out = Vec::new();
        for d in self.map.one_dart_per_cell(3) {
            let mut t = self.tet_vertices(d)?;
            let p = self.corner_positions(t)?;
            if volume_sign(p) < 0.0 {
                t.swap(2, 3);
            }
            out.push((t, self.mu[d.index()].tet, self.map.cell_id(3, d)));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const UNIT: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    /// The sign of a volume that underflows f64 is still its determinant's: a needle of width
    /// 1e-170 beside a unit edge, in either orientation; a flat tet has sign 0.
    #[test]
    fn volume_sign_reads_needles_in_wide_floats() {
        let needle = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1e-170, 0.0], [0.0, 0.0, 1e-170]];
        assert_eq!(crate::mesh::signed_volume(needle[0], needle[1], needle[2], needle[3]), 0.0);
        assert_eq!(volume_sign(needle), 1.0);
        assert_eq!(volume_sign([needle[1], needle[0], needle[2], needle[3]]), -1.0);
        assert_eq!(volume_sign(UNIT), 1.0);
        assert_eq!(volume_sign([UNIT[0], UNIT[1], UNIT[2], [0.5, 0.5, 0.0]]), 0.0);
        let inside = [0.1, 1e-173, 1e-173];
        assert_eq!(tet_distance(inside, needle), 0.0);
        assert!(tet_distance([0.1, -1e-100, 0.0], needle) > 0.0);
    }

    #[test]
    fn tet_distance_is_zero_inside_and_euclidean_outside() {
        assert_eq!(tet_distance([0.1, 0.1, 0.1], UNIT), 0.0);
        assert!((tet_distance([-2.0, 0.0, 0.0], UNIT) - 2.0).abs() < 1e-15);
        // Nearest point of the slanted face x + y + z = 1 from (1, 1, 1): distance 2/√3.
        assert!((tet_distance([1.0, 1.0, 1.0], UNIT) - 2.0 / 3f64.sqrt()).abs() < 1e-12);
        // Nearest feature an edge: from (-1, -1, 0.5) to the z-axis edge, √2.
        assert!((tet_distance([-1.0, -1.0, 0.5], UNIT) - 2f64.sqrt()).abs() < 1e-12);
        // Orientation of the corners does not matter.
        let flipped = [UNIT[0], UNIT[2], UNIT[1], UNIT[3]];
        assert_eq!(tet_distance([0.1, 0.1, 0.1], flipped), 0.0);
    }
}

//! Indexed meshes: the plain arrays that mesh files are read into, before a generalized map is
//! built from them.
//!
//! A [`TetMesh`] is a list of points and a list of tetrahedra given by four 0-based point
//! indices; a [`TriMesh`] is the same for triangles. Both have a `check` method that separates
//! *errors* (the mesh cannot be used: [`MeshError`]) from *warnings* (the mesh can be used but
//! something looks wrong: [`MeshReport`], [`TriMeshReport`]).
//!
//! | condition | [`TetMesh::check`] | [`TriMesh::check`] |
//! |---|---|---|
//! | no cells at all | error [`MeshError::Empty`] | error [`MeshError::Empty`] |
//! | corner index `>= points.len()` | error [`MeshError::IndexOutOfRange`] | error [`MeshError::IndexOutOfRange`] |
//! | a cell uses the same point twice | error [`MeshError::RepeatedVertex`] | error [`MeshError::RepeatedVertex`] |
//! | NaN or infinite coordinate | error [`MeshError::NonFiniteCoordinate`] | error [`MeshError::NonFiniteCoordinate`] |
//! | `node_tags` neither empty nor one per point | error [`MeshError::TagCountMismatch`] | — |
//! | more than `u32::MAX - 1` points | error [`MeshError::TooManyPoints`] | error [`MeshError::TooManyPoints`] |
//! | two cells with the same corners, in any order | error [`MeshError::DuplicateTet`] | error [`MeshError::DuplicateTriangle`] |
//! | zero volume / zero area (see [`DEGENERACY_TOLERANCE`]) | warning | warning |
//! | negative signed volume (inverted tet) | warning | — |
//! | signed volume not a finite number (coordinates so large that it overflows f64) | warning | — |
//! | point used by no cell | warning | warning |
//! | file triangles that are not boundary faces, or boundary faces missing from the file | warning | — |

use std::fmt;

use crate::mechanics::geom::{cross, dot, norm, sub};

/// Relative tolerance under which a cell counts as degenerate (a warning, not an error).
///
/// A tetrahedron is *zero-volume* when `|6 V| <= DEGENERACY_TOLERANCE * l^3`, where `l` is its
/// longest edge; a triangle is *zero-area* when `|2 A| <= DEGENERACY_TOLERANCE * l^2`. The test
/// is scale-invariant, so a tiny but well-shaped cell is not reported.
pub const DEGENERACY_TOLERANCE: f64 = 1e-12;

/// A tetrahedral volume mesh with 0-based indices into `points`.
///
/// # Examples
///
/// ```
/// use topomech::generate::kuhn_cube;
/// use topomech::mesh::TetMesh;
///
/// let (points, tets) = kuhn_cube(1);
/// let mesh = TetMesh { points, tets, ..Default::default() };
/// assert_eq!((mesh.points.len(), mesh.tets.len()), (8, 6)); // the unit cube in 6 tets
/// assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < mesh.points.len()));
/// let report = mesh.check().unwrap();
/// assert!(report.zero_volume_tets.is_empty() && report.unreferenced_points.is_empty());
/// assert!((mesh.total_volume().unwrap() - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Tetrahedra, four indices into `points` each.
    pub tets: Vec<[u32; 4]>,
    /// The file's triangle elements (if any), remapped to indices into `points`. They do not take
    /// part in the volume; [`TetMesh::check`] uses them only as a cross-check of the boundary.
    pub boundary_triangles: Vec<[u32; 3]>,
    /// `node_tags[i]` is the tag (number) that point `i` had in the file, for error messages.
    /// Either empty (mesh built in code) or exactly one entry per point.
    pub node_tags: Vec<u64>,
}

/// A triangle surface mesh with 0-based indices into `points`.
///
/// # Examples
///
/// ```
/// use topomech::generate::grid_triangles;
/// use topomech::mesh::TriMesh;
///
/// let (points, triangles) = grid_triangles(1);
/// let mesh = TriMesh { points, triangles };
/// assert_eq!((mesh.points.len(), mesh.triangles.len()), (4, 2)); // a unit square, two halves
/// assert!(mesh.check().unwrap().is_clean());
/// assert!((mesh.total_area().unwrap() - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Triangles, three indices into `points` each.
    pub triangles: Vec<[u32; 3]>,
}

/// The kind of cell an error is about.
///
/// # Examples
///
/// ```
/// use topomech::mesh::{CellKind, MeshError, TriMesh};
///
/// let mesh = TriMesh { points: vec![[0.0; 3]; 3], triangles: vec![[0, 1, 7]] };
/// let err = mesh.check().unwrap_err();
/// assert!(matches!(err, MeshError::IndexOutOfRange { kind: CellKind::Triangle, corner: 2, value: 7, .. }));
/// assert_eq!(CellKind::Tet.to_string(), "tet");
/// assert_eq!(CellKind::BoundaryTriangle.to_string(), "boundary triangle");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    /// An entry of [`TetMesh::tets`].
    Tet,
    /// An entry of [`TetMesh::boundary_triangles`].
    BoundaryTriangle,
    /// An entry of [`TriMesh::triangles`].
    Triangle,
}

impl fmt::Display for CellKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CellKind::Tet => "tet",
            CellKind::BoundaryTriangle => "boundary triangle",
            CellKind::Triangle => "triangle",
        })
    }
}

/// A defect that makes a mesh unusable (see the table in the [module docs](self)).
///
/// Cell ids are 0-based positions in the cell list, point ids 0-based positions in `points`.
///
/// # Examples
///
/// ```
/// use topomech::mesh::{MeshError, TetMesh};
///
/// let mesh = TetMesh { points: vec![[0.0; 3]; 4], tets: vec![[0, 1, 2, 2]], ..Default::default() };
/// assert!(matches!(mesh.check(), Err(MeshError::RepeatedVertex { vertex: 2, .. })));
/// let empty = TetMesh::default();
/// assert!(matches!(empty.check(), Err(MeshError::Empty(_))));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// The mesh has no cell of the kind that makes it (no tetrahedra / no triangles).
    #[error("empty mesh: no {0} cells")]
    Empty(CellKind),
    /// A corner refers to a point that does not exist.
    #[error(
        "index out of range: {kind} {cell} corner {corner} refers to point {value}, \
         but the mesh has {point_count} points"
    )]
    IndexOutOfRange {
        /// Which cell list.
        kind: CellKind,
        /// Cell id.
        cell: usize,
        /// Corner position within the cell (0-based).
        corner: usize,
        /// The offending index.
        value: u32,
        /// Number of points in the mesh.
        point_count: usize,
    },
    /// A cell uses the same point at two corners.
    #[error("repeated vertex: {kind} {cell} uses point {vertex}{} more than once", tag_suffix(.tag))]
    RepeatedVertex {
        /// Which cell list.
        kind: CellKind,
        /// Cell id.
        cell: usize,
        /// The repeated point.
        vertex: u32,
        /// The file tag of that point, when known.
        tag: Option<u64>,
    },
    /// Two tets have the same four corners: a volume listed twice overlaps itself (its copies
    /// would sew into a closed two-tet component and double its mass). The readers report it
    /// with the file's element numbers and node tags instead (`io::ReadError::DuplicateElement`).
    #[error(
        "duplicate tet: tets {first} and {second} have the same corners {corners:?} (0-based tet and point indices)"
    )]
    DuplicateTet {
        /// The lower tet id.
        first: usize,
        /// The other tet id.
        second: usize,
        /// Their corners as listed by `first`.
        corners: [u32; 4],
    },
    /// Two triangles of a [`TriMesh`] have the same three corners: a surface listed twice (its
    /// copies would sew into a closed two-triangle "pillow").
    #[error(
        "duplicate triangle: triangles {first} and {second} have the same corners {corners:?} \
         (0-based triangle and point indices)"
    )]
    DuplicateTriangle {
        /// The lower triangle id.
        first: usize,
        /// The other triangle id.
        second: usize,
        /// Their corners as listed by `first`.
        corners: [u32; 3],
    },
    /// A coordinate is NaN or infinite.
    #[error("non-finite coordinate: point {point}{} is {coords:?}", tag_suffix(.tag))]
    NonFiniteCoordinate {
        /// Point id.
        point: usize,
        /// The file tag of that point, when known.
        tag: Option<u64>,
        /// Its coordinates.
        coords: [f64; 3],
    },
    /// `node_tags` is neither empty nor one entry per point.
    #[error("node_tags has {tags} entries but there are {points} points")]
    TagCountMismatch {
        /// `node_tags.len()`.
        tags: usize,
        /// `points.len()`.
        points: usize,
    },
    /// More points than `u32` indices can address (`u32::MAX` is reserved).
    #[error("too many points: {0} (at most u32::MAX - 1 = 4294967294)")]
    TooManyPoints(usize),
}

fn tag_suffix(tag: &Option<u64>) -> String {
    match tag {
        Some(t) => format!(" (file tag {t})"),
        None => String::new(),
    }
}

/// Warnings found by [`TetMesh::check`]: the mesh is usable, but these may indicate a problem.
/// All ids are sorted ascending.
///
/// # Examples
///
/// ```
/// use topomech::mesh::TetMesh;
///
/// let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [5.0; 3]];
/// let mesh = TetMesh { points: unit, tets: vec![[0, 1, 2, 3]], ..Default::default() };
/// let report = mesh.check().unwrap();
/// assert_eq!(report.unreferenced_points, vec![4]); // point 4 belongs to no tet
/// assert!(report.inverted_tets.is_empty() && report.zero_volume_tets.is_empty());
/// assert!(!report.is_clean());
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MeshReport {
    /// Tets whose volume is zero up to [`DEGENERACY_TOLERANCE`].
    pub zero_volume_tets: Vec<usize>,
    /// Tets with negative signed volume (and not zero-volume): inverted orientation.
    pub inverted_tets: Vec<usize>,
    /// Tets whose volume is not a finite f64: finite coordinates so far apart (a regular tet of
    /// edge about 1e103) that the volume itself is past `f64::MAX`. Listed here instead of as
    /// zero-volume or inverted (the test is made with an unbounded exponent, so a flat one is
    /// still zero-volume); [`TetMesh::total_volume`] is then not finite and a body refuses them.
    pub unmeasurable_tets: Vec<usize>,
    /// Points that no tet uses.
    pub unreferenced_points: Vec<usize>,
    /// Entries of `boundary_triangles` that are not a boundary face of the tets.
    pub file_triangles_not_on_boundary: Vec<usize>,
    /// Number of boundary faces of the tets that are not among `boundary_triangles` (0 when the
    /// file gave no triangles: the cross-check is then skipped).
    pub boundary_faces_missing_from_file: usize,
}

impl MeshReport {
    /// True when there is no warning at all. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::MeshReport;
    ///
    /// assert!(MeshReport::default().is_clean());
    /// assert!(!MeshReport { unreferenced_points: vec![3], ..Default::default() }.is_clean());
    /// ```
    pub fn is_clean(&self) -> bool {
        self.zero_volume_tets.is_empty()
            && self.inverted_tets.is_empty()
            && self.unmeasurable_tets.is_empty()
            && self.unreferenced_points.is_empty()
            && self.file_triangles_not_on_boundary.is_empty()
            && self.boundary_faces_missing_from_file == 0
    }
}

/// Warnings found by [`TriMesh::check`]. All ids are sorted ascending.
///
/// # Examples
///
/// ```
/// use topomech::mesh::TriMesh;
///
/// let points = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// let mesh = TriMesh { points, triangles: vec![[0, 1, 2], [0, 1, 3]] };
/// let report = mesh.check().unwrap();
/// assert_eq!(report.zero_area_triangles, vec![0]); // collinear corners
/// assert_eq!(report.unreferenced_points, Vec::<usize>::new());
/// assert!(!report.is_clean());
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TriMeshReport {
    /// Triangles whose area is zero up to [`DEGENERACY_TOLERANCE`].
    pub zero_area_triangles: Vec<usize>,
    /// Points that no triangle uses.
    pub unreferenced_points: Vec<usize>,
}

impl TriMeshReport {
    /// True when there is no warning at all. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TriMesh;
    ///
    /// let square = vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mesh = TriMesh { points: square, triangles: vec![[0, 1, 2], [0, 2, 3]] };
    /// assert!(mesh.check().unwrap().is_clean());
    /// ```
    pub fn is_clean(&self) -> bool {
        self.zero_area_triangles.is_empty() && self.unreferenced_points.is_empty()
    }
}

/// The mean of `points`, each divided by their count before the sum, so that no partial sum
/// overflows (a sum first is ∞ for coordinates past `f64::MAX` / n), and kept within the
/// points' range per coordinate (the divisions round: 5e-324 / 3 is 0, so three points at
/// 5e-324 would average to 0; the centroid of identical points is the point). The origin for
/// none. O(points).
///
/// # Examples
///
/// ```
/// use topomech::mesh::centroid;
/// assert_eq!(centroid(&[[0.0; 3], [2.0, 4.0, 6.0]]), [1.0, 2.0, 3.0]);
/// let huge = f64::MAX / 2.0;
/// assert_eq!(centroid(&[[huge; 3]; 4]), [huge; 3]); // a sum first would be ∞
/// assert_eq!(centroid(&[]), [0.0; 3]);
/// assert_eq!(centroid(&[[5e-324; 3]; 3]), [5e-324; 3]); // each 5e-324 / 3 rounds to 0
/// ```
pub fn centroid(points: &[[f64; 3]]) -> [f64; 3] {
    centroid_of(points.iter().copied())
}

/// [`centroid`] of points given by an iterator that knows its length, so that a caller holding
/// ids rather than points needs no buffer. Same law and cost: each point divided by the count
/// before the sum; the origin for none. O(points), no allocation.
///
/// # Examples
///
/// ```
/// use topomech::mesh::{centroid, centroid_of};
/// let x = [[0.0; 3], [2.0, 4.0, 6.0], [9.0; 3]];
/// let ids = [0usize, 1];
/// assert_eq!(centroid_of(ids.iter().map(|&i| x[i])), centroid(&x[..2]));
/// assert_eq!(centroid_of(std::iter::empty()), [0.0; 3]);
/// ```
pub fn centroid_of(points: impl ExactSizeIterator<Item = [f64; 3]>) -> [f64; 3] {
    let n = points.len() as f64;
    if n == 0.0 {
        return [0.0; 3];
    }
    let (mut c, mut lo, mut hi) = ([0.0; 3], [f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for k in 0..3 {
            c[k] += p[k] / n;
            (lo[k], hi[k]) = (lo[k].min(p[k]), hi[k].max(p[k]));
        }
    }
    // The divisions round (5e-324 / 3 is 0): the mean is kept within the points' range.
    [0, 1, 2].map(|k| {
        if c[k] < lo[k] {
            lo[k]
        } else if c[k] > hi[k] {
            hi[k]
        } else {
            c[k]
        }
    })
}

/// |a − b|, with the components scaled by the largest before squaring, so that neither
/// overflows nor underflows (a plain √(Σ dₖ²) is ∞ for a distance of 1e200, and a ball test
/// Σ dₖ² ≤ r² is then ∞ ≤ ∞: true). NaN when a coordinate is NaN; ∞ only when the distance itself
/// is past `f64::MAX`. O(1).
///
/// # Examples
///
/// ```
/// use topomech::mesh::distance;
/// assert_eq!(distance([0.0; 3], [3.0, 4.0, 0.0]), 5.0);
/// assert_eq!(distance([1e200, 0.0, 0.0], [0.0; 3]), 1e200); // no overflow in the squares
/// assert!(distance([1e201; 3], [0.0; 3]) > 1e200);
/// assert!(distance([f64::NAN, 0.0, 0.0], [0.0; 3]).is_nan());
/// ```
pub fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    if d.iter().any(|c| c.is_nan()) {
        return f64::NAN;
    }
    let s = d.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if s == 0.0 || s.is_infinite() {
        return s;
    }
    let q = d.map(|c| c / s);
    s * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt()
}

/// The larger of `a` and `b`, NaN if either is NaN ([`f64::max`] drops a NaN, so a fold of
/// magnitudes with it reports a lost state as its other values). For `fold(0.0, nan_max)` over
/// magnitudes: 0 for none. O(1).
///
/// # Examples
///
/// ```
/// use topomech::mesh::nan_max;
/// assert_eq!([3.0, 7.0, 5.0].into_iter().fold(0.0, nan_max), 7.0);
/// assert!([3.0, f64::NAN, 5.0].into_iter().fold(0.0, nan_max).is_nan()); // f64::max gives 5
/// ```
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// The midpoint of `a` and `b`, ½(a + b) per coordinate, and ½a + ½b where a + b overflows (both
/// are the correctly rounded midpoint for normal numbers, so the bits are the same wherever the
/// first is finite). NaN in, NaN out. O(1).
///
/// # Examples
///
/// ```
/// use topomech::mesh::midpoint;
/// assert_eq!(midpoint([0.0, 1.0, -2.0], [2.0, 2.0, 2.0]), [1.0, 1.5, 0.0]);
/// let big = f64::MAX;
/// assert_eq!(midpoint([big; 3], [big / 2.0; 3]), [0.75 * big; 3]); // a + b would be ∞
/// ```
pub fn midpoint(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| {
        let sum = a[k] + b[k];
        if sum.is_finite() {
            0.5 * sum
        } else {
            0.5 * a[k] + 0.5 * b[k]
        }
    })
}

/// Extents (largest coordinate differences) of 2⁻²⁵⁰ to 2²⁵⁰, exactly: their products up to
/// the fourth power (a face normal times a difference, squared lengths, volumes) neither
/// overflow nor underflow, so [`fit_for_products`] leaves them as they are.
pub(crate) const PLAIN_EXTENT: std::ops::RangeInclusive<f64> = 5.527147875260445e-76..=1.8092513943330656e75;

/// `x` · 2^`e`, exact unless the result over- or underflows (in steps of at most 2^±1022, the
/// largest normal powers of two). O(|e| / 1022).
pub(crate) fn times_pow2(mut x: f64, mut e: i64) -> f64 {
    while e != 0 {
        let step = e.clamp(-1022, 1022);
        x *= f64::from_bits(((1023 + step) as u64) << 52);
        e -= step;
    }
    x
}

/// The largest coordinate range of `points`, max over k of (max pₖ − min pₖ); ∞ when that
/// range is past `f64::MAX`. O(points).
fn coordinate_extent(points: &[[f64; 3]]) -> f64 {
    (0..3)
        .map(|k| {
            let (lo, hi) =
                points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[k]), h.max(p[k])));
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// e with 2^e ≤ x < 2^(e+1), for a finite x > 0, read from the bits (exact, subnormals
/// included). O(1).
pub(crate) fn binary_exponent(x: f64) -> i64 {
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i64;
    if biased == 0 {
        binary_exponent(x * 2f64.powi(64)) - 64 // subnormal: 2^64 x is normal
    } else {
        biased - 1023
    }
}

/// Prepares finite `points` for products of their differences (volumes, squared lengths,
/// distances) that neither overflow nor underflow: when their extent is outside
/// [`PLAIN_EXTENT`], translates them to the first point (which becomes the origin) and scales
/// them by a power of two so that the extent is in [2²⁴⁹, 2²⁵⁰), the top of the plain range (an
/// extent past `f64::MAX` is quartered first): a huge extent is scaled down no further than
/// needed, so short differences beside it (a needle's width) keep as many binary orders of
/// magnitude above underflow as they can. Returns k, the points now being (p − p₀) · 2^k:
/// lengths changed by 2^k, volumes by 2^3k (ratios of volumes and the order of lengths are
/// kept; a length computed on the fitted points is the true one times 2^k). Inside the range,
/// or for an extent of 0 or NaN, nothing changes (the same bits as before) and k = 0. The
/// scaling is exact; the translation rounds each difference once. O(points).
pub(crate) fn fit_for_products(points: &mut [[f64; 3]]) -> i64 {
    let extent = coordinate_extent(points);
    if extent == 0.0 || PLAIN_EXTENT.contains(&extent) || extent.is_nan() || points.is_empty() {
        return 0;
    }
    let (base, quarter) = (points[0], extent.is_infinite());
    for p in points.iter_mut() {
        for k in 0..3 {
            p[k] = if quarter { 0.25 * p[k] - 0.25 * base[k] } else { p[k] - base[k] };
        }
    }
    let quartered = if quarter { -2 } else { 0 };
    let extent = coordinate_extent(points);
    if extent == 0.0 || !extent.is_finite() {
        return quartered;
    }
    let k = 249 - binary_exponent(extent);
    for p in points.iter_mut() {
        *p = p.map(|c| times_pow2(c, k));
    }
    quartered + k
}

/// Signed volume of the tetrahedron `(a, b, c, d)`: `det[b - a, c - a, d - a] / 6`.
///
/// Positive when `d` lies on the side of the plane `(a, b, c)` towards which
/// `(b - a) x (c - a)` points. O(1).
///
/// # Examples
///
/// ```
/// use topomech::mesh::signed_volume;
///
/// let (o, x, y, z) = ([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
/// assert!((signed_volume(o, x, y, z) - 1.0 / 6.0).abs() < 1e-15);
/// assert!((signed_volume(o, y, x, z) + 1.0 / 6.0).abs() < 1e-15); // swapping two corners flips the sign
/// assert_eq!(signed_volume(o, x, y, [1.0, 1.0, 0.0]), 0.0); // flat
/// ```
pub fn signed_volume(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a)) / 6.0
}

/// Area of the triangle `(a, b, c)` (always `>= 0`), `½|(b − a) × (c − a)|`. O(1).
///
/// The plain formula where it is safe: the cross product w of the edge vectors finite with its
/// largest component between 2⁻⁵⁰⁰ and 2⁵⁰⁰ (every ordinary triangle: a product lost to
/// underflow there is below 2⁻⁵²² of w, and the squares of w neither overflow nor underflow).
/// Otherwise the same formula in wide floats (an `f64` mantissa with an unbounded exponent,
/// the same rounding), so that neither the edge vectors, the cross product nor its squares
/// over- or underflow: legs of 1e-90 give 5e-181, not 0, legs of 1e80 give 5e159, not ∞, a
/// needle (0, 0, 0), (1, 0, 0), (1, 1e-200, 0) gives 5e-201. The result is ∞ only when the
/// area itself is past `f64::MAX`, 0 only when it is below the smallest subnormal or the
/// triangle is flat; NaN when a coordinate is.
///
/// # Examples
///
/// ```
/// use topomech::mesh::triangle_area;
///
/// assert_eq!(triangle_area([0.0; 3], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]), 6.0);
/// assert_eq!(triangle_area([0.0; 3], [1.0; 3], [2.0; 3]), 0.0); // collinear
/// assert_eq!(triangle_area([0.0; 3], [1e-90, 0.0, 0.0], [0.0, 1e-90, 0.0]), 0.5 * 1e-90 * 1e-90);
/// assert_eq!(triangle_area([0.0; 3], [1e80, 0.0, 0.0], [0.0, 1e80, 0.0]), 0.5 * 1e80 * 1e80);
/// assert_eq!(triangle_area([0.0; 3], [1e200, 0.0, 0.0], [0.0, 1e-200, 0.0]), 0.5); // a needle
/// assert_eq!(triangle_area([0.0; 3], [1e200, 0.0, 0.0], [1e200, 1e-120, 0.0]), 5e79);
/// assert_eq!(triangle_area([0.0; 3], [1.0, 0.0, 0.0], [1.0, 1e-200, 0.0]), 5e-201);
/// assert_eq!(triangle_area([-f64::MAX, 0.0, 0.0], [f64::MAX, 0.0, 0.0], [0.0, f64::MAX, 0.0]), f64::INFINITY);
/// ```
pub fn triangle_area(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let w = cross(sub(b, a), sub(c, a));
    let largest = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if SAFE_CROSS.contains(&largest) && w.iter().all(|x| x.is_finite()) {
        return 0.5 * norm(w);
    }
    crate::wide::twice_area(a, b, c).mul(crate::wide::Wide::new(0.5)).to_f64()
}

/// 2⁻⁵⁰⁰ to 2⁵⁰⁰: a cross product whose largest component lies here is right as computed and
/// its squares neither overflow nor underflow ([`triangle_area`]).
const SAFE_CROSS: std::ops::RangeInclusive<f64> = 3.054936363499605e-151..=3.273390607896142e150;

/// How [`TetMesh::check`] classes a tet.
enum TetShape {
    Unmeasurable,
    ZeroVolume,
    Inverted,
    Positive,
}

/// The corner pairs of a tet's six edges.
const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// The class of the tet with corners `c`: unmeasurable when its volume is not a finite f64
/// (past `f64::MAX`, or NaN), zero-volume when |6V| ≤ [`DEGENERACY_TOLERANCE`] · l³ (l its
/// longest edge), else inverted for V < 0. Plain for ordinary corners
/// (`mechanics::geom::plain_corners`), else in wide floats (an f64 mantissa with an unbounded
/// exponent), so the test stays scale-invariant where 6V or l³ under- or overflows f64: a
/// regular tet of edge 1e-150 is not zero-volume. Both branches make the same operations in the
/// same order — 6V the raw determinant det[c₁ − c₀, c₂ − c₀, c₃ − c₀], l the largest
/// `√(x² + y² + z²)` of the six edges, the bound `((TOL · l) · l) · l` — so they give the same
/// bits, and the class does not change when the tet is scaled by a power of two across the gate
/// (no plain intermediate over- or underflows for ordinary corners). O(1).
fn tet_shape(c: [[f64; 3]; 4]) -> TetShape {
    use crate::wide::{self, Wide};
    let (six, small) = if crate::mechanics::geom::plain_corners(c) {
        let six = dot(cross(sub(c[1], c[0]), sub(c[2], c[0])), sub(c[3], c[0]));
        let l = EDGES.iter().fold(0.0_f64, |m, &(i, j)| m.max(norm(sub(c[j], c[i]))));
        (Wide::new(six), six.abs() <= DEGENERACY_TOLERANCE * l * l * l)
    } else {
        let six = wide::six_volume(c[0], c[1], c[2], c[3]);
        let lengths = EDGES.map(|(i, j)| wide::norm(wide::difference(c[j], c[i])));
        let l = lengths.iter().fold(lengths[0], |a, &x| if a.less_than(x) { x } else { a });
        let bound = Wide::new(DEGENERACY_TOLERANCE).mul(l).mul(l).mul(l);
        (six, !bound.less_than(six.abs()))
    };
    if !six.is_finite() || !six.div(Wide::new(6.0)).to_f64().is_finite() {
        TetShape::Unmeasurable
    } else if small {
        TetShape::ZeroVolume
    } else if six.signum() < 0.0 {
        TetShape::Inverted
    } else {
        TetShape::Positive
    }
}

/// The longest distance between two of `corners`: `|p − q|` as it is when the components of
/// `p − q` lie between about 2⁻²⁵⁰ and 2²⁵⁰ (every ordinary cell, bit for bit), the scale-safe
/// [`distance`] outside that range (a plain square root of the sum of squares is ∞ for edges of
/// 1e155, and loses the digits of edges below 1e-154). O(corners²).
fn longest_edge(corners: &[[f64; 3]]) -> f64 {
    let mut longest = 0.0_f64;
    for (i, &p) in corners.iter().enumerate() {
        for &q in &corners[i + 1..] {
            let d = sub(p, q);
            let m = d.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let length = if m == 0.0 || PLAIN_EXTENT.contains(&m) { norm(d) } else { distance(p, q) };
            longest = longest.max(length);
        }
    }
    longest
}

/// The faces of tet `[a, b, c, d]`, each ordered so that its normal (right-hand rule) points
/// out of the tet when the tet has positive [`signed_volume`]. Face `i` is opposite corner `i`.
pub(crate) fn oriented_faces(t: [u32; 4]) -> [[u32; 3]; 4] {
    let [a, b, c, d] = t;
    [[b, c, d], [a, d, c], [a, b, d], [a, c, b]]
}

fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// [`MeshError::IndexOutOfRange`] for the first corner of `cells` not below `point_count`. O(cells).
fn check_in_range<const N: usize>(kind: CellKind, cells: &[[u32; N]], point_count: usize) -> Result<(), MeshError> {
    for (cell, corners) in cells.iter().enumerate() {
        if let Some((corner, &value)) = corners.iter().enumerate().find(|(_, &v)| v as usize >= point_count) {
            return Err(MeshError::IndexOutOfRange { kind, cell, corner, value, point_count });
        }
    }
    Ok(())
}

/// Checks that every index in `cells` is below `point_count` and no cell repeats a point.
fn check_cells<const N: usize>(
    kind: CellKind,
    cells: &[[u32; N]],
    point_count: usize,
    tags: &[u64],
) -> Result<(), MeshError> {
    for (cell, corners) in cells.iter().enumerate() {
        for (corner, &value) in corners.iter().enumerate() {
            if value as usize >= point_count {
                return Err(MeshError::IndexOutOfRange { kind, cell, corner, value, point_count });
            }
            if corners[..corner].contains(&value) {
                return Err(MeshError::RepeatedVertex {
                    kind,
                    cell,
                    vertex: value,
                    tag: tags.get(value as usize).copied(),
                });
            }
        }
    }
    Ok(())
}

/// The first pair of cells (N ≤ 4 corners) with the same corner set, as (first, second): the
/// lowest second id, paired with the first cell of its corners. The sorted corners are packed
/// into one `u128` key and the keys sorted (16 bytes per cell); only when two keys are equal are
/// the cells looked for, in one pass. O(C log C).
pub(crate) fn duplicate_cells<const N: usize>(cells: &[[u32; N]]) -> Option<(usize, usize)> {
    let key = |c: &[u32; N]| {
        let mut k = *c;
        k.sort_unstable();
        k.iter().fold(0u128, |acc, &v| acc << 32 | u128::from(v))
    };
    let mut keys: Vec<u128> = cells.iter().map(key).collect();
    keys.sort_unstable();
    if keys.windows(2).all(|w| w[0] != w[1]) {
        return None;
    }
    let mut first_of: rustc_hash::FxHashMap<u128, usize> = rustc_hash::FxHashMap::default();
    for (t, c) in cells.iter().enumerate() {
        if let Some(&first) = first_of.get(&key(c)) {
            return Some((first, t));
        }
        first_of.insert(key(c), t);
    }
    None
}

fn check_points(points: &[[f64; 3]], tags: &[u64]) -> Result<(), MeshError> {
    if points.len() >= u32::MAX as usize {
        return Err(MeshError::TooManyPoints(points.len()));
    }
    for (point, p) in points.iter().enumerate() {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(MeshError::NonFiniteCoordinate { point, tag: tags.get(point).copied(), coords: *p });
        }
    }
    Ok(())
}

/// Ids of points that appear in no cell, ascending. O(P + C).
fn unreferenced<const N: usize>(point_count: usize, cells: &[[u32; N]]) -> Vec<usize> {
    let mut used = vec![false; point_count];
    for c in cells {
        for &v in c {
            if let Some(u) = used.get_mut(v as usize) {
                *u = true;
            }
        }
    }
    (0..point_count).filter(|&i| !used[i]).collect()
}

impl TetMesh {
    /// The file's node tags of `points`, when the mesh knows a tag for each (error messages name
    /// points by them: they survive the reorderings, point indices do not). O(points).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// let mut mesh = TetMesh { points: vec![[0.0; 3]; 3], ..TetMesh::default() };
    /// assert_eq!(mesh.file_tags(&[0, 2]), None); // no tags read (a generated mesh)
    /// mesh.node_tags = vec![10, 20, 30];
    /// assert_eq!(mesh.file_tags(&[2, 0]), Some(vec![30, 10]));
    /// assert_eq!((mesh.file_tags(&[5]), mesh.file_tags(&[])), (None, None)); // no such point, nothing asked
    /// ```
    pub fn file_tags(&self, points: &[u32]) -> Option<Vec<u64>> {
        points
            .iter()
            .map(|&p| self.node_tags.get(p as usize).copied())
            .collect::<Option<Vec<u64>>>()
            .filter(|t| !t.is_empty())
    }

    /// The same mesh renumbered along a Z-order (Morton) space-filling curve: points sorted by the
    /// Morton code of their position (21 bits per axis over the bounding box, ties by old
    /// index), tets relabelled and sorted by the code of their centroid, file triangles relabelled.
    /// Neighbouring points and tets then get nearby numbers, so the maps, cell ids, springs and
    /// state arrays built from it are walked with far fewer cache misses on large meshes.
    /// Returns the new mesh and `new_of_old` (point i of `self` is point `new_of_old[i]`).
    /// O(P log P + T log T). Non-finite coordinates sort last (`check` refuses them anyway).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// let points = vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let mesh = TetMesh { points, tets: vec![[0, 1, 2, 3]], ..Default::default() };
    /// let (ordered, new_of_old) = mesh.spatially_ordered();
    /// // Z-order interleaves the bits x, y, z from the top: (0,0,0) < (0,1,0) < (1,0,0) < (1,1,1).
    /// assert_eq!(new_of_old, vec![3, 0, 2, 1]);
    /// assert_eq!(ordered.points[0], [0.0, 0.0, 0.0]);
    /// assert_eq!(ordered.tets, vec![[3, 0, 2, 1]]);
    /// ```
    pub fn spatially_ordered(&self) -> (TetMesh, Vec<u32>) {
        let (lo, hi) = bounding_box(&self.points);
        let code = |p: [f64; 3]| morton_code(p, lo, hi);
        let mut order: Vec<u32> = (0..self.points.len() as u32).collect();
        order.sort_by_key(|&i| (code(self.points[i as usize]), i));
        let mut new_of_old = vec![0u32; self.points.len()];
        for (new, &old) in order.iter().enumerate() {
            new_of_old[old as usize] = new as u32;
        }
        let points: Vec<[f64; 3]> = order.iter().map(|&i| self.points[i as usize]).collect();
        let relabel = |v: u32| new_of_old.get(v as usize).copied().unwrap_or(v);
        let mut tets: Vec<[u32; 4]> = self.tets.iter().map(|t| t.map(relabel)).collect();
        let centroid = |t: &[u32; 4]| {
            let c = t
                .iter()
                .filter_map(|&v| points.get(v as usize))
                .fold([0.0; 3], |a, p| [a[0] + p[0] / 4.0, a[1] + p[1] / 4.0, a[2] + p[2] / 4.0]);
            code(c)
        };
        tets.sort_by_cached_key(|t| (centroid(t), *t));
        let boundary_triangles = self.boundary_triangles.iter().map(|t| t.map(relabel)).collect();
        let node_tags = if self.node_tags.len() == self.points.len() {
            order.iter().map(|&i| self.node_tags[i as usize]).collect()
        } else {
            self.node_tags.clone()
        };
        (TetMesh { points, tets, boundary_triangles, node_tags }, new_of_old)
    }

    /// The same mesh renumbered by reverse Cuthill–McKee: per connected component of the edge
    /// graph, a breadth-first walk from a pseudo-peripheral point (the far end of two sweeps
    /// started at a point of least degree), each point's unvisited neighbours taken by
    /// increasing degree (ties by old index), the whole order then reversed. Edge ends get
    /// close numbers (a small bandwidth max |a − b|), so a pass over springs sorted by their
    /// first end reads the other ends from a window of a few thousand points that stays in
    /// cache, where a Z-order leaves far jumps. Tets are relabelled and sorted by their sorted
    /// corners, file triangles relabelled. Returns the new mesh and `new_of_old` as
    /// [`TetMesh::spatially_ordered`] does. Corners out of range are kept as they are (`check`
    /// refuses them). O(P + T log T).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// // Two tets sharing the face (1, 2, 3); points 0 and 4 are the far tips.
    /// let points = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0; 3]];
    /// let mesh = TetMesh { points, tets: vec![[0, 1, 2, 3], [4, 1, 2, 3]], ..Default::default() };
    /// let (ordered, new_of_old) = mesh.bandwidth_ordered();
    /// let mut seen = new_of_old.clone();
    /// seen.sort_unstable();
    /// assert_eq!(seen, vec![0, 1, 2, 3, 4]); // a permutation
    /// assert_eq!(new_of_old[0].min(new_of_old[4]), 0); // a tip at one end…
    /// assert_eq!(new_of_old[0].max(new_of_old[4]), 4); // …the other tip at the other
    /// assert_eq!(ordered.tets.len(), 2);
    /// ```
    pub fn bandwidth_ordered(&self) -> (TetMesh, Vec<u32>) {
        let n = self.points.len();
        let neighbours = edge_graph(n, &self.tets);
        let degree = |v: usize| neighbours[v].len();
        let mut visited = vec![false; n];
        let mut order: Vec<u32> = Vec::with_capacity(n);
        let mut by_degree: Vec<u32> = (0..n as u32).collect();
        by_degree.sort_by_key(|&v| (degree(v as usize), v));
        let mut scratch = vec![false; n];
        for &seed in &by_degree {
            if visited[seed as usize] {
                continue;
            }
            let mut start = seed as usize;
            for _ in 0..2 {
                let level = bfs_levels(&neighbours, start, &mut scratch);
                start = level.into_iter().min_by_key(|&v| (degree(v), v)).unwrap_or(start);
            }
            let first = order.len();
            order.push(start as u32);
            visited[start] = true;
            let mut head = first;
            while head < order.len() {
                let v = order[head] as usize;
                head += 1;
                let mut next: Vec<u32> = neighbours[v].iter().copied().filter(|&w| !visited[w as usize]).collect();
                next.sort_by_key(|&w| (degree(w as usize), w));
                for w in next {
                    visited[w as usize] = true;
                    order.push(w);
                }
            }
        }
        order.reverse();
        let mut new_of_old = vec![0u32; n];
        for (new, &old) in order.iter().enumerate() {
            new_of_old[old as usize] = new as u32;
        }
        let relabel = |v: u32| new_of_old.get(v as usize).copied().unwrap_or(v);
        let points = order.iter().map(|&i| self.points[i as usize]).collect();
        let mut tets: Vec<[u32; 4]> = self.tets.iter().map(|t| t.map(relabel)).collect();
        tets.sort_by_cached_key(|t| {
            let mut k = *t;
            k.sort_unstable();
            (k, *t)
        });
        let boundary_triangles = self.boundary_triangles.iter().map(|t| t.map(relabel)).collect();
        let node_tags = if self.node_tags.len() == n {
            order.iter().map(|&i| self.node_tags[i as usize]).collect()
        } else {
            self.node_tags.clone()
        };
        (TetMesh { points, tets, boundary_triangles, node_tags }, new_of_old)
    }

    /// Checks the mesh: `Err` for a defect that makes it unusable, otherwise the list of
    /// warnings. See the table in the [module docs](self) for what is which.
    ///
    /// Cost: O(P + T log T) (the duplicate test sorts one key per tet) plus
    /// O((T + B) log(T + B)) for the boundary cross-check when `boundary_triangles` is not empty
    /// (P points, T tets, B file triangles).
    ///
    /// # Errors
    /// [`MeshError::Empty`], [`MeshError::TooManyPoints`], [`MeshError::TagCountMismatch`],
    /// [`MeshError::NonFiniteCoordinate`], [`MeshError::IndexOutOfRange`],
    /// [`MeshError::RepeatedVertex`] (for tets and for `boundary_triangles`),
    /// [`MeshError::DuplicateTet`] (a tet listed twice, in any corner order).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// // The second tet lists its corners in the opposite orientation.
    /// let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0; 3]];
    /// let mesh = TetMesh { points: unit, tets: vec![[0, 1, 2, 3], [2, 1, 3, 4]], ..Default::default() };
    /// let report = mesh.check().unwrap();
    /// assert_eq!(report.inverted_tets, vec![1]);
    /// assert!(!report.is_clean());
    /// ```
    pub fn check(&self) -> Result<MeshReport, MeshError> {
        if self.tets.is_empty() {
            return Err(MeshError::Empty(CellKind::Tet));
        }
        if !self.node_tags.is_empty() && self.node_tags.len() != self.points.len() {
            return Err(MeshError::TagCountMismatch { tags: self.node_tags.len(), points: self.points.len() });
        }
        check_points(&self.points, &self.node_tags)?;
        let n = self.points.len();
        check_cells(CellKind::Tet, &self.tets, n, &self.node_tags)?;
        check_cells(CellKind::BoundaryTriangle, &self.boundary_triangles, n, &self.node_tags)?;
        if let Some((first, second)) = duplicate_cells(&self.tets) {
            return Err(MeshError::DuplicateTet { first, second, corners: self.tets[first] });
        }
        let mut report = MeshReport::default();
        for (i, t) in self.tets.iter().enumerate() {
            let c = t.map(|v| self.points[v as usize]);
            match tet_shape(c) {
                TetShape::Unmeasurable => report.unmeasurable_tets.push(i),
                TetShape::ZeroVolume => report.zero_volume_tets.push(i),
                TetShape::Inverted => report.inverted_tets.push(i),
                TetShape::Positive => {}
            }
        }
        report.unreferenced_points = unreferenced(n, &self.tets);
        if !self.boundary_triangles.is_empty() {
            self.cross_check_boundary(&mut report);
        }
        Ok(report)
    }

    /// Compares `boundary_triangles` (as unoriented vertex sets) with the boundary faces of
    /// the tets. O((T + B) log(T + B)).
    fn cross_check_boundary(&self, report: &mut MeshReport) {
        let mut boundary: Vec<[u32; 3]> = self.boundary_triangles_of_tets().into_iter().map(sorted3).collect();
        boundary.sort_unstable();
        let mut in_file: Vec<[u32; 3]> = Vec::with_capacity(self.boundary_triangles.len());
        for (i, &t) in self.boundary_triangles.iter().enumerate() {
            let key = sorted3(t);
            if boundary.binary_search(&key).is_err() {
                report.file_triangles_not_on_boundary.push(i);
            } else {
                in_file.push(key);
            }
        }
        in_file.sort_unstable();
        in_file.dedup();
        report.boundary_faces_missing_from_file = boundary.len() - in_file.len();
    }

    /// Sum of the absolute tet volumes `sum |signed_volume|`. O(T).
    ///
    /// Equals the enclosed volume for a valid mesh; inverted tets count positively. Not finite
    /// when a tet's volume overflows f64 ([`MeshReport::unmeasurable_tets`]); +0.0 for no tets.
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`] naming the first tet corner past the points.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// let unit = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mesh = TetMesh { points: unit, tets: vec![[0, 1, 2, 3]], ..Default::default() };
    /// assert!(mesh.check().unwrap().is_clean());
    /// assert!((mesh.total_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
    /// assert_eq!((mesh.edge_count(), mesh.boundary_face_count()), (6, 4));
    /// let bad = TetMesh { tets: vec![[0, 1, 2, 4]], ..mesh };
    /// assert!(bad.total_volume().is_err()); // corner 3 names point 4 of 4
    /// ```
    pub fn total_volume(&self) -> Result<f64, MeshError> {
        check_in_range(CellKind::Tet, &self.tets, self.points.len())?;
        let volume = |t: &[u32; 4]| {
            let c = t.map(|v| self.points[v as usize]);
            crate::mechanics::geom::tet_volume(c[0], c[1], c[2], c[3])
        };
        Ok(self.tets.iter().map(volume).fold(0.0, |sum, v| sum + v))
    }

    /// The distinct edges of the tets, each as `[lo, hi]` with `lo < hi`, sorted. O(T log T).
    ///
    /// Computed from sorted 64-bit keys, independently of any map structure, so tests can use
    /// it as an oracle.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// let mesh = TetMesh { points: vec![[0.0; 3]; 5], tets: vec![[0, 1, 2, 3], [4, 2, 1, 0]], ..Default::default() };
    /// let edges = mesh.edges();
    /// assert_eq!(edges.len(), 9); // 6 + 6 − 3 shared
    /// assert!(edges.windows(2).all(|w| w[0] < w[1]) && edges.iter().all(|e| e[0] < e[1]));
    /// ```
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut keys: Vec<u64> = Vec::with_capacity(6 * self.tets.len());
        for &[a, b, c, d] in &self.tets {
            keys.extend([
                edge_key(a, b),
                edge_key(a, c),
                edge_key(a, d),
                edge_key(b, c),
                edge_key(b, d),
                edge_key(c, d),
            ]);
        }
        keys.sort_unstable();
        keys.dedup();
        keys.into_iter().map(|k| [(k >> 32) as u32, (k & 0xffff_ffff) as u32]).collect()
    }

    /// Number of distinct edges (= springs of a mass/spring model). O(T log T); see
    /// [`TetMesh::edges`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mesh::TetMesh;
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let mesh = TetMesh { points, tets, ..Default::default() };
    /// assert_eq!(mesh.edge_count(), 98); // 3k(k+1)² + 3k²(k+1) + k³
    /// assert_eq!(mesh.edge_count(), mesh.edges().len());
    /// ```
    pub fn edge_count(&self) -> usize {
        self.edges().len()
    }

    /// Faces used by exactly one tet, each ordered so that its normal points out of its tet
    /// (for a positively oriented tet), sorted by their sorted vertex triple. O(T log T).
    ///
    /// Computed from sorted keys, independently of any map structure. A face shared by three
    /// or more tets (non-manifold) is not reported as boundary.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::{signed_volume, TetMesh};
    ///
    /// let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mesh = TetMesh { points: points.clone(), tets: vec![[0, 1, 2, 3]], ..Default::default() };
    /// let faces = mesh.boundary_triangles_of_tets();
    /// assert_eq!(faces.len(), 4);
    /// // Every face's normal points out: the centre lies behind each one.
    /// let p = |i: u32| points[i as usize];
    /// assert!(faces.iter().all(|f| signed_volume(p(f[0]), p(f[1]), p(f[2]), [0.25; 3]) < 0.0));
    /// ```
    pub fn boundary_triangles_of_tets(&self) -> Vec<[u32; 3]> {
        let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(4 * self.tets.len());
        for &t in &self.tets {
            for f in oriented_faces(t) {
                faces.push((sorted3(f), f));
            }
        }
        faces.sort_unstable_by_key(|&(key, _)| key);
        let mut out = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            if j - i == 1 {
                out.push(faces[i].1);
            }
            i = j;
        }
        out
    }

    /// Number of faces used by exactly one tet. O(T log T); see
    /// [`TetMesh::boundary_triangles_of_tets`].
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::kuhn_cube;
    /// use topomech::mesh::TetMesh;
    ///
    /// let (points, tets) = kuhn_cube(2);
    /// let mesh = TetMesh { points, tets, ..Default::default() };
    /// assert_eq!(mesh.boundary_face_count(), 48); // 12k²
    /// ```
    pub fn boundary_face_count(&self) -> usize {
        let mut keys: Vec<[u32; 3]> = Vec::with_capacity(4 * self.tets.len());
        for &t in &self.tets {
            keys.extend(oriented_faces(t).map(sorted3));
        }
        keys.sort_unstable();
        let mut count = 0;
        let mut i = 0;
        while i < keys.len() {
            let mut j = i + 1;
            while j < keys.len() && keys[j] == keys[i] {
                j += 1;
            }
            count += usize::from(j - i == 1);
            i = j;
        }
        count
    }

    /// Drops the points that no tet uses and renumbers the rest, keeping their order.
    ///
    /// Returns the new mesh and the map `old index -> new index` (`u32::MAX` for a dropped
    /// point). `node_tags` follow their points; a boundary triangle with a dropped corner is
    /// dropped. O(P + T + B).
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`] naming the first tet or boundary-triangle corner past the
    /// points.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TetMesh;
    ///
    /// let points = vec![[9.0; 3], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    /// let mesh = TetMesh { points, tets: vec![[1, 2, 3, 4]], ..Default::default() };
    /// let (small, old_to_new) = mesh.compact().unwrap();
    /// assert_eq!(small.tets, vec![[0, 1, 2, 3]]);
    /// assert_eq!(old_to_new, vec![u32::MAX, 0, 1, 2, 3]);
    /// assert_eq!(small.total_volume(), mesh.total_volume());
    /// ```
    pub fn compact(&self) -> Result<(TetMesh, Vec<u32>), MeshError> {
        check_in_range(CellKind::Tet, &self.tets, self.points.len())?;
        check_in_range(CellKind::BoundaryTriangle, &self.boundary_triangles, self.points.len())?;
        let mut used = vec![false; self.points.len()];
        for t in &self.tets {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut map = vec![u32::MAX; self.points.len()];
        let mut points = Vec::new();
        let mut node_tags = Vec::new();
        for (old, slot) in map.iter_mut().enumerate() {
            if used[old] {
                *slot = points.len() as u32;
                points.push(self.points[old]);
                if let Some(&tag) = self.node_tags.get(old) {
                    node_tags.push(tag);
                }
            }
        }
        let tets = self.tets.iter().map(|t| t.map(|v| map[v as usize])).collect();
        let boundary_triangles = self
            .boundary_triangles
            .iter()
            .map(|t| t.map(|v| map[v as usize]))
            .filter(|t| !t.contains(&u32::MAX))
            .collect();
        let mesh = TetMesh { points, tets, boundary_triangles, node_tags };
        Ok((mesh, map))
    }
}

impl TriMesh {
    /// Checks the mesh: `Err` for a defect that makes it unusable, otherwise the list of
    /// warnings (zero-area triangles, unreferenced points). See the table in the
    /// [module docs](self). The zero-area test is scale-invariant at every scale: a well-shaped
    /// triangle with legs of 1e-90 or 1e155, or corners ±`f64::MAX` apart, is not zero-area.
    /// O(P + T log T).
    ///
    /// # Errors
    /// [`MeshError::Empty`], [`MeshError::TooManyPoints`], [`MeshError::NonFiniteCoordinate`],
    /// [`MeshError::IndexOutOfRange`], [`MeshError::RepeatedVertex`] (a degenerate triangle),
    /// [`MeshError::DuplicateTriangle`] (a triangle listed twice, in any corner order).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::{MeshError, TriMesh};
    ///
    /// let points = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    /// let report = TriMesh { points: points.clone(), triangles: vec![[0, 1, 2]] }.check().unwrap();
    /// assert_eq!(report.zero_area_triangles, vec![0]); // collinear corners
    /// assert_eq!(report.unreferenced_points, vec![3]);
    /// assert!(!report.is_clean());
    /// let bad = TriMesh { points, triangles: vec![[0, 1, 4]] };
    /// assert!(matches!(bad.check(), Err(MeshError::IndexOutOfRange { .. })));
    /// ```
    pub fn check(&self) -> Result<TriMeshReport, MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty(CellKind::Triangle));
        }
        check_points(&self.points, &[])?;
        let n = self.points.len();
        check_cells(CellKind::Triangle, &self.triangles, n, &[])?;
        if let Some((first, second)) = duplicate_cells(&self.triangles) {
            return Err(MeshError::DuplicateTriangle { first, second, corners: self.triangles[first] });
        }
        let mut report = TriMeshReport::default();
        for (i, t) in self.triangles.iter().enumerate() {
            let mut c = t.map(|v| self.points[v as usize]);
            // Scale-invariant: a triangle outside the ordinary range of sizes is first brought to
            // a size just below 2^250 by a power of two (ordinary ones are kept bit for bit), so
            // neither 2A nor l² underflows (legs of 1e-90) or overflows (legs of 1e155: ∞ ≤ ∞).
            fit_for_products(&mut c);
            let two_a = 2.0 * triangle_area(c[0], c[1], c[2]);
            if two_a <= DEGENERACY_TOLERANCE * longest_edge(&c).powi(2) {
                report.zero_area_triangles.push(i);
            }
        }
        report.unreferenced_points = unreferenced(n, &self.triangles);
        Ok(report)
    }

    /// Sum of the triangle areas ([`triangle_area`], safe from under- and overflow when the
    /// area is representable). O(T).
    ///
    /// ∞ when a triangle's area, or the sum, is past `f64::MAX` (corners ±`f64::MAX` apart, say:
    /// [`TriMesh::check`] still finds such a triangle well shaped, not zero-area); NaN for a NaN
    /// coordinate.
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`] naming the first corner past the points.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::mesh::TriMesh;
    ///
    /// let points = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 2.0, 0.0]];
    /// let mesh = TriMesh { points, triangles: vec![[0, 1, 2], [1, 3, 2]] };
    /// assert!(mesh.check().unwrap().is_clean());
    /// assert!((mesh.total_area().unwrap() - 4.0).abs() < 1e-12);
    /// ```
    pub fn total_area(&self) -> Result<f64, MeshError> {
        check_in_range(CellKind::Triangle, &self.triangles, self.points.len())?;
        let area = |t: &[u32; 3]| {
            let c = t.map(|v| self.points[v as usize]);
            triangle_area(c[0], c[1], c[2])
        };
        Ok(self.triangles.iter().map(area).fold(0.0, |sum, a| sum + a))
    }
}

/// The distinct neighbours of each of the `n` points along the tets' edges (corners out of
/// range skipped), each list sorted. O(P + T log T).
fn edge_graph(n: usize, tets: &[[u32; 4]]) -> Vec<Vec<u32>> {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in tets {
        for i in 0..4 {
            for j in 0..4 {
                if i != j && (t[i] as usize) < n && (t[j] as usize) < n && t[i] != t[j] {
                    neighbours[t[i] as usize].push(t[j]);
                }
            }
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    neighbours
}

/// The last level of a breadth-first walk from `start` (the points farthest from it). `seen`
/// must be all false on entry and is all false again on return. O(size of the component).
fn bfs_levels(neighbours: &[Vec<u32>], start: usize, seen: &mut [bool]) -> Vec<usize> {
    let (mut level, mut all) = (vec![start], vec![start]);
    seen[start] = true;
    loop {
        let mut next = Vec::new();
        for &v in &level {
            for &w in &neighbours[v] {
                if !std::mem::replace(&mut seen[w as usize], true) {
                    next.push(w as usize);
                }
            }
        }
        if next.is_empty() {
            break;
        }
        all.extend_from_slice(&next);
        level = next;
    }
    for v in all {
        seen[v] = false;
    }
    level
}

/// The axis-aligned bounding box of the finite points ((0,0,0), (0,0,0) when there is none). O(P).
fn bounding_box(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let finite = points.iter().filter(|p| p.iter().all(|c| c.is_finite()));
    let (lo, hi) = finite.fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
        ([lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])], [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])])
    });
    if lo[0] > hi[0] {
        ([0.0; 3], [0.0; 3])
    } else {
        (lo, hi)
    }
}

/// The 63-bit Morton code of `p` in the box [lo, hi]: 21 bits per axis, interleaved x, y, z from
/// the most significant bit. Non-finite points get `u64::MAX`. O(1).
fn morton_code(p: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> u64 {
    if p.iter().any(|c| !c.is_finite()) {
        return u64::MAX;
    }
    const CELLS: f64 = ((1u32 << 21) - 1) as f64;
    let q = |k: usize| {
        let extent = hi[k] - lo[k];
        let t = if extent > 0.0 { ((p[k] - lo[k]) / extent).clamp(0.0, 1.0) } else { 0.0 };
        (t * CELLS) as u64
    };
    let (x, y, z) = (q(0), q(1), q(2));
    let mut code = 0u64;
    for bit in (0..21).rev() {
        code = (code << 3) | (((x >> bit) & 1) << 2) | (((y >> bit) & 1) << 1) | ((z >> bit) & 1);
    }
    code
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `nan_max` is the maximum, except that a NaN on either side wins; a fold from 0 over
    /// nothing is 0 (closes a survivor of the thirty-second mutation sample).
    #[test]
    fn nan_max_keeps_a_nan_and_is_the_maximum_otherwise() {
        assert_eq!((nan_max(1.0, 2.5), nan_max(2.5, 1.0), nan_max(-3.0, 0.0)), (2.5, 2.5, 0.0));
        assert!(nan_max(f64::NAN, 1.0).is_nan() && nan_max(1.0, f64::NAN).is_nan());
        assert_eq!([3.0, 7.0, 5.0].into_iter().fold(0.0, nan_max), 7.0);
        assert!([3.0, f64::NAN, 5.0].into_iter().fold(0.0, nan_max).is_nan());
        assert_eq!(std::iter::empty::<f64>().fold(0.0, nan_max), 0.0);
    }

    /// `fit_for_products` keeps ordinary points bit for bit, and brings huge, tiny and
    /// past-`f64::MAX` extents to about 1 keeping the ratio of volumes.
    #[test]
    fn fitting_keeps_plain_points_and_volume_ratios() {
        let unit = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.5]];
        let mut same = unit;
        fit_for_products(&mut same);
        assert_eq!(same, unit);
        let ratio = |p: &[[f64; 3]]| signed_volume(p[0], p[1], p[2], p[4]) / signed_volume(p[0], p[1], p[2], p[3]);
        for (scale, shift) in
            [(1e110, 0.0), (1e-200, 0.0), (1e-200, 3e-200), (2f64.powi(1000), -(2f64.powi(1020))), (2e-310, 0.0)]
        {
            let mut p = unit.map(|q| q.map(|c| c * scale + shift));
            fit_for_products(&mut p);
            let extent = coordinate_extent(&p);
            assert!((2f64.powi(249)..2f64.powi(250)).contains(&extent), "{scale} {shift}: extent {extent}");
            assert!((ratio(&p) - 0.5).abs() < 1e-12, "{scale} {shift}: {}", ratio(&p));
        }
        let mut wide = [[-f64::MAX, 0.0, 0.0], [f64::MAX, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 1e300]];
        fit_for_products(&mut wide);
        assert!(wide.iter().flatten().all(|c| c.is_finite()) && coordinate_extent(&wide) < 2f64.powi(250));
        assert!(signed_volume(wide[0], wide[1], wide[2], wide[3]) > 0.0);
        assert_eq!(midpoint([f64::MAX; 3], [-f64::MAX; 3]), [0.0; 3]);
    }

    fn unit_tet() -> TetMesh {
        TetMesh {
            points: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            tets: vec![[0, 1, 2, 3]],
            boundary_triangles: vec![],
            node_tags: vec![10, 20, 30, 40],
        }
    }

    #[test]
    fn unit_tet_volume_edges_faces() {
        let m = unit_tet();
        assert!((m.total_volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
        assert_eq!(m.edge_count(), 6);
        assert_eq!(m.boundary_face_count(), 4);
        assert!(m.check().unwrap().is_clean());
    }

    #[test]
    fn oriented_faces_point_outwards() {
        let m = unit_tet();
        let centroid = [0.25, 0.25, 0.25];
        for f in m.boundary_triangles_of_tets() {
            let c = f.map(|v| m.points[v as usize]);
            // The centroid must be behind every outward face.
            assert!(signed_volume(c[0], c[1], c[2], centroid) < 0.0, "{f:?}");
        }
    }

    #[test]
    fn inverted_and_flat_are_warnings() {
        let mut m = unit_tet();
        m.tets[0] = [1, 0, 2, 3];
        assert_eq!(m.check().unwrap().inverted_tets, vec![0]);
        m.points[3] = [0.5, 0.5, 0.0];
        let r = m.check().unwrap();
        assert_eq!(r.zero_volume_tets, vec![0]);
        assert!(r.inverted_tets.is_empty());
    }

    #[test]
    fn errors_carry_ids() {
        let mut m = unit_tet();
        m.tets[0] = [0, 1, 1, 3];
        let e = m.check().unwrap_err();
        assert_eq!(e, MeshError::RepeatedVertex { kind: CellKind::Tet, cell: 0, vertex: 1, tag: Some(20) });
        assert!(e.to_string().contains("file tag 20"), "{e}");
        m.tets[0] = [0, 1, 9, 3];
        assert!(matches!(m.check(), Err(MeshError::IndexOutOfRange { value: 9, corner: 2, .. })));
        m.tets[0] = [0, 1, 2, 3];
        m.points[2][1] = f64::NAN;
        let e = m.check().unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
        assert!(e.to_string().contains("file tag 30"), "{e}");
        m.tets.clear();
        assert_eq!(m.check(), Err(MeshError::Empty(CellKind::Tet)));
    }

    #[test]
    fn compact_drops_unused_points() {
        let mut m = unit_tet();
        m.points.insert(0, [9., 9., 9.]);
        m.node_tags.insert(0, 99);
        m.tets[0] = [1, 2, 3, 4];
        assert_eq!(m.check().unwrap().unreferenced_points, vec![0]);
        let (c, map) = m.compact().unwrap();
        assert_eq!(map, vec![u32::MAX, 0, 1, 2, 3]);
        assert_eq!(c, unit_tet());
    }

    #[test]
    fn boundary_cross_check() {
        let mut m = unit_tet();
        m.boundary_triangles = vec![[0, 2, 1], [3, 2, 1]];
        let r = m.check().unwrap();
        assert!(r.file_triangles_not_on_boundary.is_empty());
        assert_eq!(r.boundary_faces_missing_from_file, 2);
    }

    #[test]
    fn tri_mesh_check() {
        let mut m = TriMesh {
            points: vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [2., 0., 0.]],
            triangles: vec![[0, 1, 2]],
        };
        let r = m.check().unwrap();
        assert_eq!(r.unreferenced_points, vec![3]);
        assert!((m.total_area().unwrap() - 0.5).abs() < 1e-15);
        m.triangles.push([0, 1, 3]);
        assert_eq!(m.check().unwrap().zero_area_triangles, vec![1]);
        m.triangles.push([0, 0, 3]);
        assert!(m.check().unwrap_err().to_string().contains("repeated vertex"));
    }
}

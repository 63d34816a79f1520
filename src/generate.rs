//! Seeded and structured mesh factories shared by tests, benchmarks and the demo.
//!
//! Every factory numbers its points with `u32` ids, so none makes more than `u32::MAX` points or
//! elements. The `try_` factories check that, with checked arithmetic, before they allocate, and
//! return [`GenerateError`]; the plain ones (for tests and examples with literal sizes) panic on
//! the same sizes.

/// Why a factory refused a size. Every variant names the factory's parameter and its value.
///
/// # Examples
///
/// ```
/// use topomech::generate::{try_kuhn_cube, GenerateError, KUHN_CUBE_MAX_K};
///
/// let err = try_kuhn_cube(2000).unwrap_err(); // 2001³ points do not fit u32 ids
/// assert_eq!(err, GenerateError::TooLarge { what: "kuhn_cube k", size: 2000, limit: KUHN_CUBE_MAX_K });
/// assert!(err.to_string().contains("2000"));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GenerateError {
    /// The parameter would make more than `u32::MAX` points or elements (or overflow `usize` on
    /// the way); `limit` is the largest value accepted.
    #[error("{what} = {size} is past {limit}: the mesh would need more than u32::MAX points or elements")]
    TooLarge {
        /// The factory and its parameter, e.g. `"kuhn_cube k"`.
        what: &'static str,
        /// The value given.
        size: usize,
        /// The largest value accepted.
        limit: usize,
    },
    /// The parameter is below the smallest value that makes the documented shape.
    #[error("{what} = {size} is below {min}")]
    TooSmall {
        /// The factory and its parameter, e.g. `"disk_fan n"`.
        what: &'static str,
        /// The value given.
        size: usize,
        /// The smallest value accepted.
        min: usize,
    },
    /// The allocator refused the array (the size passed the id check but not the memory at hand).
    /// A system that overcommits memory may accept the allocation instead and end the process
    /// later, when the pages are touched.
    #[error("cannot allocate {count} {what}")]
    OutOfMemory {
        /// The array, e.g. `"kuhn_cube tets"`.
        what: &'static str,
        /// The number of entries asked for.
        count: usize,
    },
}

/// Points and tets, each tet four indices into the points.
pub type TetArrays = (Vec<[f64; 3]>, Vec<[u32; 4]>);

/// Points and triangles, each triangle three indices into the points.
pub type TriangleArrays = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// The largest `k` [`try_kuhn_cube`] accepts: 6k³ tets must not pass `u32::MAX` (6 · 894³ =
/// 4 287 101 904; the (k+1)³ points stay below it too).
pub const KUHN_CUBE_MAX_K: usize = 894;

/// The largest `n` [`try_grid_triangles`] accepts: 2n² triangles must not pass `u32::MAX`
/// (2 · 46 340² = 4 294 739 200; the (n+1)² points stay below it too).
pub const GRID_TRIANGLES_MAX_N: usize = 46_340;

/// The largest `n` [`try_disk_fan`] accepts: its n + 1 points must not pass `u32::MAX`.
pub const DISK_FAN_MAX_N: u32 = u32::MAX - 1;

/// The smallest `n` [`try_disk_fan`] accepts: fewer rim points make no disk (n = 2 gives two
/// triangles on the same three vertices, n = 1 a triangle with a repeated vertex).
pub const DISK_FAN_MIN_N: u32 = 3;

/// `Some(count)` when `count` fits `u32` ids (at most `u32::MAX` entries).
fn fits_u32(count: Option<usize>) -> Option<usize> {
    count.filter(|&c| c <= u32::MAX as usize)
}

/// An empty vector with room for exactly `count` entries, or [`GenerateError::OutOfMemory`].
fn reserve<T>(what: &'static str, count: usize) -> Result<Vec<T>, GenerateError> {
    let mut v = Vec::new();
    v.try_reserve_exact(count).map_err(|_| GenerateError::OutOfMemory { what, count })?;
    Ok(v)
}

/// (points, tets) of the Kuhn cube of side k: ((k+1)³, 6k³), `None` when either passes
/// `u32::MAX` or the arithmetic overflows. O(1).
fn kuhn_counts(k: usize) -> Option<(usize, usize)> {
    let side = k.checked_add(1)?;
    let points = fits_u32(side.checked_mul(side).and_then(|s| s.checked_mul(side)))?;
    let tets = fits_u32(k.checked_mul(k).and_then(|s| s.checked_mul(k)).and_then(|s| s.checked_mul(6)))?;
    Some((points, tets))
}

/// (points, triangles) of the n × n grid: ((n+1)², 2n²), `None` past `u32::MAX` or on overflow.
/// O(1).
fn grid_counts(n: usize) -> Option<(usize, usize)> {
    let side = n.checked_add(1)?;
    let points = fits_u32(side.checked_mul(side))?;
    let triangles = fits_u32(n.checked_mul(n).and_then(|s| s.checked_mul(2)))?;
    Some((points, triangles))
}

/// (points, triangles) of the fan of n triangles: (n + 1, n), `None` past `u32::MAX`. O(1).
fn fan_counts(n: u32) -> Option<(usize, usize)> {
    let n = usize::try_from(n).ok()?;
    Some((fits_u32(n.checked_add(1))?, n))
}

/// The cube \[0,k\]³ cut into k³ unit cubes, each cut into 6 tetrahedra around its 000–111
/// diagonal (the Kuhn / Freudenthal split, conforming across cubes).
///
/// Closed forms (used as test oracles): V = (k+1)³, T = 6k³,
/// E = 3k(k+1)² + 3k²(k+1) + k³, F = 12k³ + 6k², boundary faces = 12k², darts = 144k³.
/// O(k³). Point `x + (k+1)(y + (k+1)z)` is at (x, y, z).
///
/// # Panics
/// For k > [`KUHN_CUBE_MAX_K`] (894: 6k³ tets would pass `u32::MAX`), or when the allocator
/// refuses the arrays. [`try_kuhn_cube`] returns those as errors.
///
/// # Examples
///
/// ```
/// use topomech::{generate, GMap};
///
/// let (points, tets) = generate::kuhn_cube(2);
/// assert_eq!((points.len(), tets.len()), (27, 48)); // (k+1)³ and 6k³
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// assert_eq!(map.count_cells().0, vec![27, 98, 120, 48]);
/// assert_eq!(map.boundary_cell_count(), 48); // 12k²
/// ```
pub fn kuhn_cube(k: usize) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    try_kuhn_cube(k).unwrap_or_else(|e| panic!("kuhn_cube({k}): {e} (use try_kuhn_cube to get the error)"))
}

/// [`kuhn_cube`], refusing the sizes it panics on. O(k³); the size check is O(1) and comes
/// before any allocation.
///
/// # Errors
/// [`GenerateError::TooLarge`] for k > [`KUHN_CUBE_MAX_K`] (the (k+1)³ points or 6k³ tets would
/// pass `u32::MAX`); [`GenerateError::OutOfMemory`] when the allocator refuses an array.
///
/// # Examples
///
/// ```
/// use topomech::generate::{kuhn_cube, try_kuhn_cube, GenerateError};
///
/// assert_eq!(try_kuhn_cube(2).unwrap(), kuhn_cube(2));
/// assert!(matches!(try_kuhn_cube(895), Err(GenerateError::TooLarge { size: 895, limit: 894, .. })));
/// assert!(try_kuhn_cube(usize::MAX).is_err()); // (k+1)³ overflows: refused, no panic
/// ```
pub fn try_kuhn_cube(k: usize) -> Result<TetArrays, GenerateError> {
    let too_large = GenerateError::TooLarge { what: "kuhn_cube k", size: k, limit: KUHN_CUBE_MAX_K };
    let (point_count, tet_count) = kuhn_counts(k).ok_or(too_large)?;
    let mut points = reserve("kuhn_cube points", point_count)?;
    let mut tets = reserve("kuhn_cube tets", tet_count)?;
    let side = k + 1;
    // Lossless: every id is below point_count <= u32::MAX (kuhn_counts).
    let id = |x: usize, y: usize, z: usize| (x + side * (y + side * z)) as u32;
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                points.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    const AXIS_ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    for z in 0..k {
        for y in 0..k {
            for x in 0..k {
                for order in AXIS_ORDERS {
                    let mut c = [x, y, z];
                    let mut tet = [id(c[0], c[1], c[2]); 4];
                    for (step, &axis) in order.iter().enumerate() {
                        c[axis] += 1;
                        tet[step + 1] = id(c[0], c[1], c[2]);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    Ok((points, tets))
}

/// The square \[0,n\]² cut into n² unit squares, each cut into two triangles along its diagonal.
/// V = (n+1)², T = 2n², E = 3n² + 2n, boundary edges = 4n. O(n²).
///
/// # Panics
/// For n > [`GRID_TRIANGLES_MAX_N`] (46 340: 2n² triangles would pass `u32::MAX`), or when the
/// allocator refuses the arrays. [`try_grid_triangles`] returns those as errors.
///
/// # Examples
///
/// ```
/// use topomech::generate;
///
/// let (points, triangles) = generate::grid_triangles(3);
/// assert_eq!((points.len(), triangles.len()), (16, 18)); // (n+1)² and 2n²
/// assert!(points.iter().all(|p| p[2] == 0.0 && p[0] <= 3.0 && p[1] <= 3.0));
/// ```
pub fn grid_triangles(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    try_grid_triangles(n)
        .unwrap_or_else(|e| panic!("grid_triangles({n}): {e} (use try_grid_triangles to get the error)"))
}

/// [`grid_triangles`], refusing the sizes it panics on. O(n²); the size check is O(1) and comes
/// before any allocation.
///
/// # Errors
/// [`GenerateError::TooLarge`] for n > [`GRID_TRIANGLES_MAX_N`] (the (n+1)² points or 2n²
/// triangles would pass `u32::MAX`); [`GenerateError::OutOfMemory`] when the allocator refuses
/// an array.
///
/// # Examples
///
/// ```
/// use topomech::generate::{grid_triangles, try_grid_triangles, GenerateError};
///
/// assert_eq!(try_grid_triangles(3).unwrap(), grid_triangles(3));
/// assert!(matches!(try_grid_triangles(46_341), Err(GenerateError::TooLarge { size: 46_341, .. })));
/// ```
pub fn try_grid_triangles(n: usize) -> Result<TriangleArrays, GenerateError> {
    let too_large = GenerateError::TooLarge { what: "grid_triangles n", size: n, limit: GRID_TRIANGLES_MAX_N };
    let (point_count, triangle_count) = grid_counts(n).ok_or(too_large)?;
    let mut points = reserve("grid_triangles points", point_count)?;
    let mut triangles = reserve("grid_triangles triangles", triangle_count)?;
    let side = n + 1;
    // Lossless: every id is below point_count <= u32::MAX (grid_counts).
    let id = |x: usize, y: usize| (x + side * y) as u32;
    points.extend((0..point_count).map(|k| [(k % side) as f64, (k / side) as f64, 0.0]));
    for y in 0..n {
        for x in 0..n {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    Ok((points, triangles))
}

/// A disk: n ≥ 3 triangles fanned around a centre (point 0) whose rim points 1..=n lie on the
/// unit circle in the plane z = 0. V = n + 1, T = n, E = 2n, boundary edges = n: the one inner
/// vertex of degree n. O(n).
///
/// # Panics
/// For n < [`DISK_FAN_MIN_N`] (3: no disk), for n > [`DISK_FAN_MAX_N`] (`u32::MAX` − 1: the
/// n + 1 points would pass `u32::MAX`), or when the allocator refuses the arrays.
/// [`try_disk_fan`] returns those as errors.
///
/// # Examples
///
/// ```
/// use topomech::generate;
///
/// let (points, triangles) = generate::disk_fan(7);
/// assert_eq!((points.len(), triangles.len()), (8, 7));
/// assert!(triangles.iter().all(|t| t[0] == 0)); // every triangle has the centre
/// assert!(points[1..].iter().all(|p| (p[0].hypot(p[1]) - 1.0).abs() < 1e-12));
/// ```
pub fn disk_fan(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    try_disk_fan(n).unwrap_or_else(|e| panic!("disk_fan({n}): {e} (use try_disk_fan to get the error)"))
}

/// [`disk_fan`], refusing the sizes it panics on. O(n); the size check is O(1) and comes before
/// any allocation.
///
/// # Errors
/// [`GenerateError::TooSmall`] for n < [`DISK_FAN_MIN_N`] (3); [`GenerateError::TooLarge`] for
/// n > [`DISK_FAN_MAX_N`] (the n + 1 points would pass `u32::MAX`);
/// [`GenerateError::OutOfMemory`] when the allocator refuses an array.
///
/// # Examples
///
/// ```
/// use topomech::generate::{disk_fan, try_disk_fan, GenerateError};
///
/// assert_eq!(try_disk_fan(7).unwrap(), disk_fan(7));
/// assert_eq!(try_disk_fan(2), Err(GenerateError::TooSmall { what: "disk_fan n", size: 2, min: 3 }));
/// assert!(matches!(try_disk_fan(u32::MAX), Err(GenerateError::TooLarge { .. })));
/// ```
pub fn try_disk_fan(n: u32) -> Result<TriangleArrays, GenerateError> {
    let size = n as usize;
    if n < DISK_FAN_MIN_N {
        return Err(GenerateError::TooSmall { what: "disk_fan n", size, min: DISK_FAN_MIN_N as usize });
    }
    let too_large = GenerateError::TooLarge { what: "disk_fan n", size, limit: DISK_FAN_MAX_N as usize };
    let (point_count, triangle_count) = fan_counts(n).ok_or(too_large)?;
    let mut points = reserve("disk_fan points", point_count)?;
    let mut triangles = reserve("disk_fan triangles", triangle_count)?;
    points.push([0.0; 3]);
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        points.push([a.cos(), a.sin(), 0.0]);
        // No overflow: k + 1 <= n <= u32::MAX - 1.
        triangles.push([0, 1 + k, 1 + (k + 1) % n]);
    }
    Ok((points, triangles))
}

/// A small deterministic pseudo-random generator (SplitMix64), so factories need no dependency.
///
/// # Examples
///
/// ```
/// use topomech::generate::SplitMix64;
///
/// let (mut a, mut b) = (SplitMix64(42), SplitMix64(42));
/// assert_eq!(a.next_u64(), b.next_u64()); // same seed, same sequence
/// assert_ne!(a.next_u64(), a.next_u64());
/// assert!((0..100).all(|_| a.below(7) < 7));
/// ```
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::SplitMix64;
    ///
    /// let mut rng = SplitMix64(1);
    /// let first = rng.next_u64();
    /// assert_eq!(SplitMix64(1).next_u64(), first); // deterministic
    /// assert_ne!(rng.next_u64(), first);
    /// ```
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in 0..max(n, 1): uniform up to a bias of n / 2⁶⁴ (the remainder of one 64-bit
    /// draw), and 0 for n = 0 — the range is taken as at least {0} so that the call is total
    /// (no division by zero). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::generate::SplitMix64;
    ///
    /// let mut rng = SplitMix64(7);
    /// let rolls: Vec<usize> = (0..600).map(|_| rng.below(6)).collect();
    /// assert!(rolls.iter().all(|&r| r < 6));
    /// assert!((0..6).all(|face| rolls.contains(&face))); // every value turns up
    /// assert_eq!(rng.below(0), 0); // the empty range is taken as {0}
    /// ```
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % (n as u64).max(1)) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The published limits are exactly the last sizes whose counts fit u32 ids.
    #[test]
    fn limits_are_the_last_sizes_that_fit() {
        assert!(kuhn_counts(KUHN_CUBE_MAX_K).is_some() && kuhn_counts(KUHN_CUBE_MAX_K + 1).is_none());
        assert!(grid_counts(GRID_TRIANGLES_MAX_N).is_some() && grid_counts(GRID_TRIANGLES_MAX_N + 1).is_none());
        assert!(fan_counts(DISK_FAN_MAX_N).is_some() && fan_counts(DISK_FAN_MAX_N + 1).is_none());
        assert!(kuhn_counts(usize::MAX).is_none() && grid_counts(usize::MAX).is_none());
        assert!((0..=KUHN_CUBE_MAX_K).step_by(97).all(|k| kuhn_counts(k) == Some(((k + 1).pow(3), 6 * k.pow(3)))));
    }
}

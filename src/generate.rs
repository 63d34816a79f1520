//! Seeded and structured mesh factories shared by tests, benchmarks and the demo.

/// The cube \[0,k\]³ cut into k³ unit cubes, each cut into 6 tetrahedra around its 000–111
/// diagonal (the Kuhn / Freudenthal split, conforming across cubes).
///
/// Closed forms (used as test oracles): V = (k+1)³, T = 6k³,
/// E = 3k(k+1)² + 3k²(k+1) + k³, F = 12k³ + 6k², boundary faces = 12k², darts = 144k³.
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
    let side = k + 1;
    let id = |x: usize, y: usize, z: usize| (x + side * (y + side * z)) as u32;
    let mut points = Vec::with_capacity(side * side * side);
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                points.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    const AXIS_ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    let mut tets = Vec::with_capacity(6 * k * k * k);
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
    (points, tets)
}

/// The square \[0,n\]² cut into n² unit squares, each cut into two triangles along its diagonal.
/// V = (n+1)², T = 2n², E = 3n² + 2n, boundary edges = 4n.
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
    let side = n + 1;
    let id = |x: usize, y: usize| (x + side * y) as u32;
    let points = (0..side * side).map(|k| [(k % side) as f64, (k / side) as f64, 0.0]).collect();
    let mut triangles = Vec::with_capacity(2 * n * n);
    for y in 0..n {
        for x in 0..n {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    (points, triangles)
}

/// A disk: n ≥ 3 triangles fanned around a centre (point 0) whose rim points 1..=n lie on the
/// unit circle in the plane z = 0. V = n + 1, T = n, E = 2n, boundary edges = n: the one inner
/// vertex of degree n. O(n).
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
    let mut points = vec![[0.0; 3]];
    let mut triangles = Vec::with_capacity(n as usize);
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        points.push([a.cos(), a.sin(), 0.0]);
        triangles.push([0, 1 + k, 1 + (k + 1) % n]);
    }
    (points, triangles)
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

    /// A number in 0..n (n > 0).
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
    /// ```
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

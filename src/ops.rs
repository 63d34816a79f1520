//! One generator of kernel operations shared by every verification suite.
//!
//! Property tests (proptest, quickcheck), the cargo-fuzz target, the corpus replay test and the
//! exhaustive proofs all drive the kernel through the same three steps:
//!
//! 1. [`decode`] turns *any* byte string into a bounded list of [`KernelOp`]s (it is total: no
//!    input is rejected, missing bytes read as zero, at most [`MAX_OPS`] operations);
//! 2. [`apply`] runs one operation on a [`GMap`], mapping dart indices modulo the capacity so
//!    that random numbers usually name real darts;
//! 3. [`check_after_op`] states the laws that must hold after every step (validity, exact cell
//!    counts, Euler characteristic, refused operations change nothing, sew/unsew are inverse up
//!    to isomorphism, …) and returns the first one broken as a message.
//!
//! [`run_bytes`] chains the three for a whole input (the first byte picks the dimension), which
//! is what the fuzz target and the replay test call.
//!
//! The module also holds helpers that rebuild a map through the public API only
//! ([`alpha_table`], [`from_alpha_table`], [`permuted_copy`]), the law checks shared with the
//! proofs ([`check_cell_ids_exact`], [`check_cell_changes`]) and, for the proofs of
//! `validate()` itself, [`raw_edit_unchecked`], the one public way to break a map on purpose.

use crate::build::BuildError;
use crate::generate::{kuhn_cube, SplitMix64};
use crate::gmap::{CellChanges, DartError, SewError};
use crate::{AlphaMask, CellId, DartId, GMap};

/// At most this many operations are decoded from one input.
pub const MAX_OPS: usize = 256;

/// A [`KernelOp::Grow`] is refused when the map already has this many darts (keeps runs fast).
pub const MAX_DARTS: usize = 4096;

/// One operation on a map. Dart and index fields are raw numbers: [`apply`] reduces dart numbers
/// modulo the capacity and the index modulo n + 2 (so an out-of-range index is tried too).
///
/// # Examples
///
/// ```
/// use topomech::ops::{decode, encode, run_ops, KernelOp, Seed};
/// use topomech::GMap;
///
/// let ops = vec![KernelOp::Grow { kind: Seed::Structured, seed: 1 }, KernelOp::Unsew { i: 3, a: 40 }];
/// assert_eq!(decode(&encode(&ops)), ops);
/// let mut map = GMap::<3>::new();
/// assert_eq!(run_ops(&mut map, &ops), Ok(())); // every law holds after each op
/// assert!(map.dart_count() > 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum KernelOp {
    /// `create_dart()`.
    CreateDart,
    /// `delete_dart(d)`.
    DeleteDart(u32),
    /// `sew_dyn(i, a, b)`.
    Sew {
        /// Index of the involution.
        i: u8,
        /// First dart number.
        a: u32,
        /// Second dart number.
        b: u32,
    },
    /// `sew_dyn(i, x, y)` where x and y are the a-th and b-th i-free darts (modulo their number):
    /// random sews that succeed often.
    SewFree {
        /// Index of the involution.
        i: u8,
        /// Rank of the first dart among the i-free ones.
        a: u32,
        /// Rank of the second.
        b: u32,
    },
    /// `unsew_dyn(i, a)`.
    Unsew {
        /// Index of the involution.
        i: u8,
        /// Dart number.
        a: u32,
    },
    /// Adds a seeded map as new components, built with `create_dart` + `sew` only (see [`Seed`]).
    Grow {
        /// Which family.
        kind: Seed,
        /// Seed of the random choices.
        seed: u32,
    },
}

/// Families of seeded maps added by [`KernelOp::Grow`], for each dimension.
///
/// # Examples
///
/// ```
/// use topomech::ops::{from_alpha_table, seeded_table, Seed};
///
/// let table = seeded_table::<3>(Seed::Structured, 0).unwrap(); // the Kuhn cube k = 1
/// assert_eq!(table.len(), 6 * 24);
/// let map = from_alpha_table::<3>(&table).unwrap();
/// assert_eq!(map.count_cells().0, [8, 19, 18, 6]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Seed {
    /// n = 3: the Kuhn cube k = 1 (6 tets); n = 2: a triangle grid of side 1..=3; n = 1: a closed
    /// polygon of 1..=6 edges.
    Structured,
    /// n = 3: a random subset of the tets of the Kuhn cube k = 2; n = 2: a random triangle soup
    /// on at most 5 points (may be refused as non-manifold; a draw that repeats a triangle gives
    /// the pillow: two triangles glued along their three edges); n = 1: an open chain of 1..=6
    /// edges.
    Soup,
    /// n = 3: random tets on at most 6 points (may be refused; a draw that repeats a tet gives
    /// the pillow: two tets glued along their four faces, a closed map); n = 2: the boundary of
    /// a tetrahedron (a sphere); n = 1: a single edge.
    Wild,
}

impl Seed {
    fn from_byte(b: u8) -> Seed {
        match b % 3 {
            0 => Seed::Structured,
            1 => Seed::Soup,
            _ => Seed::Wild,
        }
    }

    fn to_byte(self) -> u8 {
        match self {
            Seed::Structured => 0,
            Seed::Soup => 1,
            Seed::Wild => 2,
        }
    }
}

/// Reads bytes, returning 0 past the end (so decoding is total).
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn u8(&mut self) -> u8 {
        let b = self.bytes.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    fn u16(&mut self) -> u32 {
        u32::from(self.u8()) | u32::from(self.u8()) << 8
    }

    fn done(&self) -> bool {
        self.pos >= self.bytes.len()
    }
}

/// Decodes any bytes into at most [`MAX_OPS`] operations. Total and deterministic. O(len).
///
/// Format: one tag byte per operation, `tag % 8` picks it — 0, 1: create; 2: delete (u16 dart);
/// 3: sew (u8 i, u16 a, u16 b); 4: sew-free (same fields); 5, 6: unsew (u8 i, u16 a);
/// 7: grow (u8 kind, u16 seed). Integers are little-endian; missing bytes read as 0.
///
/// # Examples
///
/// ```
/// use topomech::ops::{decode, KernelOp};
///
/// // tag 0: create; tag 2: delete, dart 5 as a little-endian u16.
/// assert_eq!(decode(&[0, 2, 5, 0]), vec![KernelOp::CreateDart, KernelOp::DeleteDart(5)]);
/// assert!(decode(&[]).is_empty());
/// assert_eq!(decode(&[3]), vec![KernelOp::Sew { i: 0, a: 0, b: 0 }]); // missing bytes read as 0
/// ```
pub fn decode(bytes: &[u8]) -> Vec<KernelOp> {
    let mut r = Reader { bytes, pos: 0 };
    let mut ops = Vec::new();
    while !r.done() && ops.len() < MAX_OPS {
        let op = match r.u8() % 8 {
            0 | 1 => KernelOp::CreateDart,
            2 => KernelOp::DeleteDart(r.u16()),
            3 => KernelOp::Sew { i: r.u8(), a: r.u16(), b: r.u16() },
            4 => KernelOp::SewFree { i: r.u8(), a: r.u16(), b: r.u16() },
            5 | 6 => KernelOp::Unsew { i: r.u8(), a: r.u16() },
            _ => KernelOp::Grow { kind: Seed::from_byte(r.u8()), seed: r.u16() },
        };
        ops.push(op);
    }
    ops
}

/// The decoder's law, shared by the unit tests, the proptest and the Kani harness: at most one
/// operation per input byte and at most [`MAX_OPS`], and [`encode`] inverts [`decode`]. Returns
/// the decoded operations. O(len).
///
/// # Errors
/// Which part of the law failed, with the input's length.
///
/// # Examples
///
/// ```
/// use topomech::ops::{check_decode, MAX_OPS};
///
/// assert_eq!(check_decode(&[0u8; 10_000]).unwrap().len(), MAX_OPS);
/// assert!(check_decode(&[]).unwrap().is_empty());
/// ```
pub fn check_decode(bytes: &[u8]) -> Result<Vec<KernelOp>, String> {
    let ops = decode(bytes);
    if ops.len() > bytes.len().min(MAX_OPS) {
        return Err(format!("{} bytes decoded into {} operations (at most {MAX_OPS})", bytes.len(), ops.len()));
    }
    if decode(&encode(&ops)) != ops {
        return Err(format!("encode does not invert decode on {} bytes", bytes.len()));
    }
    Ok(ops)
}

/// The bytes that [`decode`] turns back into `ops` (dart numbers are kept modulo 2^16, which is
/// all decode can produce). O(len).
///
/// # Examples
///
/// ```
/// use topomech::ops::{decode, encode, KernelOp};
///
/// let ops = vec![KernelOp::CreateDart, KernelOp::Sew { i: 2, a: 1, b: 300 }, KernelOp::Unsew { i: 0, a: 7 }];
/// assert_eq!(decode(&encode(&ops)), ops);
/// assert_eq!(encode(&[KernelOp::DeleteDart(5)]), vec![2, 5, 0]);
/// ```
pub fn encode(ops: &[KernelOp]) -> Vec<u8> {
    let mut out = Vec::new();
    let u16 = |out: &mut Vec<u8>, x: u32| out.extend_from_slice(&(x as u16).to_le_bytes());
    for op in ops {
        match *op {
            KernelOp::CreateDart => out.push(0),
            KernelOp::DeleteDart(d) => {
                out.push(2);
                u16(&mut out, d);
            }
            KernelOp::Sew { i, a, b } | KernelOp::SewFree { i, a, b } => {
                out.push(if matches!(op, KernelOp::Sew { .. }) { 3 } else { 4 });
                out.push(i);
                u16(&mut out, a);
                u16(&mut out, b);
            }
            KernelOp::Unsew { i, a } => {
                out.push(5);
                out.push(i);
                u16(&mut out, a);
            }
            KernelOp::Grow { kind, seed } => {
                out.push(7);
                out.push(kind.to_byte());
                u16(&mut out, seed);
            }
        }
    }
    out
}

/// An operation with its dart numbers resolved against a map: what [`apply`] actually runs.
///
/// # Examples
///
/// ```
/// use topomech::ops::{resolve, KernelOp, Resolved};
/// use topomech::{DartId, GMap};
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let op = KernelOp::Sew { i: 7, a: 25, b: 2 }; // 24 darts, indices modulo n + 2 = 5
/// assert_eq!(resolve(&map, &op), Resolved::Sew { i: 2, a: DartId(1), b: DartId(2) });
/// assert_eq!(resolve(&map, &KernelOp::CreateDart), Resolved::Create);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resolved {
    /// Create a dart.
    Create,
    /// Delete this dart slot (maybe dead).
    Delete(DartId),
    /// i-sew a with b.
    Sew {
        /// Index (may exceed n).
        i: usize,
        /// First dart.
        a: DartId,
        /// Second dart.
        b: DartId,
    },
    /// i-unsew a.
    Unsew {
        /// Index (may exceed n).
        i: usize,
        /// The dart.
        a: DartId,
    },
    /// Grow by a seeded map.
    Grow {
        /// Family.
        kind: Seed,
        /// Seed.
        seed: u32,
    },
    /// Nothing to do (no dart slot, or no free dart for a sew-free).
    Nothing,
}

/// Resolves dart numbers modulo the capacity and indices modulo n + 2. O(capacity) for a
/// sew-free (it ranks the free darts), O(1) otherwise.
///
/// # Examples
///
/// ```
/// use topomech::ops::{resolve, KernelOp, Resolved};
/// use topomech::{DartId, GMap};
///
/// let mut map = GMap::<2>::new();
/// map.create_dart().unwrap();
/// map.create_dart().unwrap();
/// assert_eq!(resolve(&map, &KernelOp::DeleteDart(5)), Resolved::Delete(DartId(1))); // 5 mod 2
/// assert_eq!(resolve(&GMap::<2>::new(), &KernelOp::DeleteDart(5)), Resolved::Nothing);
/// ```
pub fn resolve<const N: usize>(map: &GMap<N>, op: &KernelOp) -> Resolved {
    let cap = map.capacity() as u32;
    let dart = |x: u32| DartId(x % cap.max(1));
    let index = |i: u8| usize::from(i) % (N + 2);
    match *op {
        KernelOp::CreateDart => Resolved::Create,
        KernelOp::Grow { kind, seed } => Resolved::Grow { kind, seed },
        _ if cap == 0 => Resolved::Nothing,
        KernelOp::DeleteDart(d) => Resolved::Delete(dart(d)),
        KernelOp::Sew { i, a, b } => Resolved::Sew { i: index(i), a: dart(a), b: dart(b) },
        KernelOp::Unsew { i, a } => Resolved::Unsew { i: index(i), a: dart(a) },
        KernelOp::SewFree { i, a, b } => {
            let i = usize::from(i) % (N + 1);
            let free: Vec<DartId> = map.darts().filter(|&d| map.is_free(i, d)).collect();
            if free.is_empty() {
                return Resolved::Nothing;
            }
            let pick = |x: u32| free[x as usize % free.len()];
            Resolved::Sew { i, a: pick(a), b: pick(b) }
        }
    }
}

/// What a successful [`apply`] did.
///
/// # Examples
///
/// ```
/// use topomech::ops::{apply, Applied, KernelOp};
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let Ok(Applied::Unsewn { i, a, partner, .. }) = apply(&mut map, &KernelOp::Unsew { i: 0, a: 3 }) else { panic!() };
/// assert_eq!(i, 0);
/// assert!(map.is_free(0, a) && map.is_free(0, partner) && a != partner);
/// assert_eq!(apply(&mut GMap::<3>::new(), &KernelOp::DeleteDart(0)), Ok(Applied::Nothing));
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Applied {
    /// A dart was created.
    Created(DartId),
    /// A dart was deleted.
    Deleted(DartId),
    /// i-sew of a and b, with the kernel's report.
    Sewn {
        /// Index.
        i: usize,
        /// First dart.
        a: DartId,
        /// Second dart.
        b: DartId,
        /// Cell changes reported by the kernel.
        changes: CellChanges,
    },
    /// i-unsew of a from its former partner, with the kernel's report.
    Unsewn {
        /// Index.
        i: usize,
        /// The dart.
        a: DartId,
        /// Its αi image before the unsew.
        partner: DartId,
        /// Cell changes reported by the kernel.
        changes: CellChanges,
    },
    /// New darts were added (their ids, in creation order).
    Grown(Vec<DartId>),
    /// Nothing was done.
    Nothing,
}

/// Why [`apply`] did not change the map (or, for [`OpError::Rebuild`], failed half way).
///
/// # Examples
///
/// ```
/// use topomech::ops::{apply, from_alpha_table, KernelOp, OpError};
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// assert!(matches!(apply(&mut map, &KernelOp::DeleteDart(0)), Err(OpError::Dart(_)))); // not isolated
/// assert!(matches!(apply(&mut map, &KernelOp::Sew { i: 0, a: 0, b: 5 }), Err(OpError::Sew(_))));
/// let table = vec![vec![1, 0, 0, 0]]; // α0 sends dart 0 to a row that does not exist
/// assert!(matches!(from_alpha_table::<3>(&table), Err(OpError::BadTable { row: 0, .. })));
/// ```
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OpError {
    /// The kernel refused a dart creation or deletion.
    #[error(transparent)]
    Dart(#[from] DartError),
    /// The kernel refused a sew or unsew.
    #[error(transparent)]
    Sew(#[from] SewError),
    /// The builder refused the seeded mesh (e.g. not a quasi-manifold).
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The map is too large to grow.
    #[error("the map has {0} darts; growing is refused past {MAX_DARTS}")]
    TooLarge(usize),
    /// Rebuilding a valid alpha table through create_dart + sew failed: a kernel bug, since the
    /// table came from a valid map. The map may hold the darts created so far.
    #[error("rebuilding a valid map through the public API failed at {dart:?}, alpha{i}: {source}")]
    Rebuild {
        /// The dart being sewn.
        dart: DartId,
        /// The involution.
        i: usize,
        /// The kernel's refusal.
        source: SewError,
    },
    /// The alpha table given to [`from_alpha_table`] is not a valid n-G-map.
    #[error("alpha table row {row}: {what}")]
    BadTable {
        /// Row (dart rank).
        row: usize,
        /// What is wrong.
        what: &'static str,
    },
}

/// Runs one operation. Errors are refusals by the kernel or the builder (the map is then
/// unchanged), except [`OpError::Rebuild`]. Cost: that of the kernel operation, plus O(capacity)
/// for a sew-free and the size of the new map for a grow.
///
/// # Examples
///
/// ```
/// use topomech::ops::{apply, Applied, KernelOp};
/// use topomech::GMap;
///
/// let mut map = GMap::<2>::new();
/// let Ok(Applied::Created(a)) = apply(&mut map, &KernelOp::CreateDart) else { panic!() };
/// let Ok(Applied::Created(b)) = apply(&mut map, &KernelOp::CreateDart) else { panic!() };
/// assert!(matches!(apply(&mut map, &KernelOp::Sew { i: 2, a: 0, b: 1 }), Ok(Applied::Sewn { .. })));
/// assert_eq!(map.alpha_dyn(2, a), b);
/// assert!(apply(&mut map, &KernelOp::DeleteDart(0)).is_err()); // a is sewn, so not isolated
/// ```
pub fn apply<const N: usize>(map: &mut GMap<N>, op: &KernelOp) -> Result<Applied, OpError> {
    match resolve(map, op) {
        Resolved::Nothing => Ok(Applied::Nothing),
        Resolved::Create => Ok(Applied::Created(map.create_dart()?)),
        Resolved::Delete(d) => {
            map.delete_dart(d)?;
            Ok(Applied::Deleted(d))
        }
        Resolved::Sew { i, a, b } => {
            let changes = map.sew_dyn(i, a, b)?;
            Ok(Applied::Sewn { i, a, b, changes })
        }
        Resolved::Unsew { i, a } => {
            let partner = if i <= N && map.contains(a) { map.alpha_dyn(i, a) } else { a };
            let changes = map.unsew_dyn(i, a)?;
            Ok(Applied::Unsewn { i, a, partner, changes })
        }
        Resolved::Grow { kind, seed } => {
            if map.dart_count() >= MAX_DARTS {
                return Err(OpError::TooLarge(map.dart_count()));
            }
            let table = seeded_table::<N>(kind, seed)?;
            Ok(Applied::Grown(append_alpha_table(map, &table)?))
        }
    }
}

/// An alpha table: row r lists αi of dart rank r for i = 0..=n, as ranks.
///
/// # Examples
///
/// ```
/// use topomech::ops::{alpha_table, from_alpha_table, AlphaTable};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]]).unwrap();
/// let table: AlphaTable = alpha_table(&map);
/// assert_eq!((table.len(), table[0].len()), (6, 3)); // 6 darts, α0..α2
/// assert!(table.iter().enumerate().all(|(r, row)| row[2] as usize == r)); // one triangle: 2-free
/// assert!(from_alpha_table::<2>(&table).unwrap().is_isomorphic(&map));
/// ```
pub type AlphaTable = Vec<Vec<u32>>;

/// The alpha table of a map, darts ranked in increasing id order. O(darts · n).
///
/// # Examples
///
/// ```
/// use topomech::ops::{alpha_table, check_alpha_table};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let table = alpha_table(&map);
/// assert_eq!(table.len(), 24);
/// assert!(table.iter().all(|row| row.len() == 4));
/// assert!(check_alpha_table::<3>(&table).is_ok());
/// ```
pub fn alpha_table<const N: usize>(map: &GMap<N>) -> AlphaTable {
    let mut rank = vec![u32::MAX; map.capacity()];
    for (r, d) in map.darts().enumerate() {
        rank[d.index()] = r as u32;
    }
    map.darts().map(|d| (0..=N).map(|i| rank[map.alpha_dyn(i, d).index()]).collect()).collect()
}

/// Checks that a table has n + 1 entries per row, in range, forming involutions that satisfy
/// the quasi-manifold law. O(rows · n²).
///
/// # Examples
///
/// ```
/// use topomech::ops::check_alpha_table;
///
/// // One edge: α0 swaps the two darts, α1 fixes both.
/// assert!(check_alpha_table::<1>(&vec![vec![1, 0], vec![0, 1]]).is_ok());
/// assert!(check_alpha_table::<1>(&vec![vec![1, 0], vec![1, 1]]).is_err()); // α0 not an involution
/// assert!(check_alpha_table::<1>(&vec![vec![2, 0], vec![0, 1]]).is_err()); // image out of range
/// assert!(check_alpha_table::<2>(&vec![vec![1, 0], vec![0, 1]]).is_err()); // rows too short
/// ```
pub fn check_alpha_table<const N: usize>(table: &AlphaTable) -> Result<(), OpError> {
    let k = table.len();
    for (row, r) in table.iter().enumerate() {
        if r.len() != N + 1 {
            return Err(OpError::BadTable { row, what: "wrong number of involutions" });
        }
        if r.iter().any(|&x| x as usize >= k) {
            return Err(OpError::BadTable { row, what: "image out of range" });
        }
    }
    for (row, r) in table.iter().enumerate() {
        for i in 0..=N {
            if table[r[i] as usize][i] as usize != row {
                return Err(OpError::BadTable { row, what: "not an involution" });
            }
            for j in i + 2..=N {
                if table[r[j] as usize][i] != table[r[i] as usize][j] {
                    return Err(OpError::BadTable { row, what: "quasi-manifold law broken" });
                }
            }
        }
    }
    Ok(())
}

/// Adds the darts of a valid alpha table to `map` (through `create_dart`, so freed slots are
/// reused) and links them with `sew_dyn` only, in increasing i. Returns the new darts in rank
/// order. O(rows · n) sews.
///
/// Why increasing i always works on a valid table: when αi is sewn, α0..α(i−1) are complete and
/// α(i+1).. are empty, so the orbit the kernel sews is ⟨α0..α(i−2)⟩(x), which the table's αi maps
/// isomorphically onto that of αi(x) by the quasi-manifold law.
///
/// # Examples
///
/// ```
/// use topomech::ops::{alpha_table, append_alpha_table};
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let table = alpha_table(&map);
/// let new = append_alpha_table(&mut map, &table).unwrap();
/// assert_eq!((new.len(), map.dart_count()), (24, 48));
/// assert_eq!(map.components().len(), 2);
/// ```
pub fn append_alpha_table<const N: usize>(map: &mut GMap<N>, table: &AlphaTable) -> Result<Vec<DartId>, OpError> {
    check_alpha_table::<N>(table)?;
    let darts = (0..table.len()).map(|_| map.create_dart()).collect::<Result<Vec<_>, _>>()?;
    for i in 0..=N {
        for (r, row) in table.iter().enumerate() {
            let (x, y) = (darts[r], darts[row[i] as usize]);
            if x == y || !map.is_free(i, x) {
                continue;
            }
            map.sew_dyn(i, x, y).map_err(|source| OpError::Rebuild { dart: x, i, source })?;
        }
    }
    Ok(darts)
}

/// A new map holding a valid alpha table, built through the public API only. O(rows · n) sews.
///
/// # Examples
///
/// ```
/// use topomech::ops::{alpha_table, from_alpha_table};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let copy: GMap<3> = from_alpha_table(&alpha_table(&map)).unwrap();
/// assert!(copy.is_isomorphic(&map));
/// assert!(from_alpha_table::<1>(&vec![vec![1, 0], vec![1, 1]]).is_err());
/// ```
pub fn from_alpha_table<const N: usize>(table: &AlphaTable) -> Result<GMap<N>, OpError> {
    let mut map = GMap::new();
    append_alpha_table(&mut map, table)?;
    Ok(map)
}

/// A copy of a valid map whose dart of rank r becomes dart `perm[r]` (`perm` a permutation of
/// 0..darts), built with `create_dart` + `sew` only. The copy is isomorphic to `map`. Errors if
/// `perm` is not a permutation of the right length, or on a kernel bug. O(darts · n) sews.
///
/// # Examples
///
/// ```
/// use topomech::ops::{permuted_copy, random_permutation};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let copy = permuted_copy(&map, &random_permutation(24, 7)).unwrap();
/// assert!(copy.is_isomorphic(&map));
/// assert!(permuted_copy(&map, &[0, 1, 2]).is_err()); // wrong length
/// ```
pub fn permuted_copy<const N: usize>(map: &GMap<N>, perm: &[u32]) -> Result<GMap<N>, OpError> {
    let table = alpha_table(map);
    let k = table.len();
    let mut seen = vec![false; k];
    for (row, &p) in perm.iter().enumerate() {
        if p as usize >= k || std::mem::replace(&mut seen[p as usize], true) {
            return Err(OpError::BadTable { row, what: "not a permutation" });
        }
    }
    if perm.len() != k {
        return Err(OpError::BadTable { row: perm.len(), what: "permutation has the wrong length" });
    }
    let mut permuted = vec![Vec::new(); k];
    for (r, row) in table.iter().enumerate() {
        permuted[perm[r] as usize] = row.iter().map(|&x| perm[x as usize]).collect();
    }
    from_alpha_table(&permuted)
}

/// A random permutation of 0..k (Fisher–Yates with SplitMix64). O(k).
///
/// # Panics
/// If `k` exceeds 2³² (the entries are `u32` dart indices).
///
/// # Examples
///
/// ```
/// use topomech::ops::random_permutation;
///
/// let p = random_permutation(10, 42);
/// assert_eq!(p, random_permutation(10, 42)); // deterministic
/// let mut sorted = p.clone();
/// sorted.sort_unstable();
/// assert_eq!(sorted, (0..10).collect::<Vec<u32>>());
/// ```
pub fn random_permutation(k: usize, seed: u64) -> Vec<u32> {
    assert!(k as u64 <= 1 << 32, "a permutation of {k} entries does not fit u32 indices");
    let mut rng = SplitMix64(seed);
    let mut p: Vec<u32> = (0..=u32::MAX).take(k).collect();
    for j in (1..k).rev() {
        p.swap(j, rng.below(j + 1));
    }
    p
}

/// The alpha table of a seeded map of the given family for dimension N (see [`Seed`]).
/// Dimensions other than 1, 2, 3 get a closed polygon's table lifted to n (higher αi free).
///
/// # Examples
///
/// ```
/// use topomech::ops::{check_alpha_table, seeded_table, Seed};
///
/// let cube = seeded_table::<3>(Seed::Structured, 0).unwrap(); // Kuhn cube k = 1: 6 tets
/// assert_eq!(cube.len(), 6 * 24);
/// assert!(check_alpha_table::<3>(&cube).is_ok());
/// assert_eq!(seeded_table::<2>(Seed::Wild, 0).unwrap().len(), 4 * 6); // tetrahedron boundary
/// ```
pub fn seeded_table<const N: usize>(kind: Seed, seed: u32) -> Result<AlphaTable, OpError> {
    let mut rng = SplitMix64(u64::from(seed) ^ 0x5EED_0000);
    match N {
        3 => seeded_table_3(kind, &mut rng),
        2 => seeded_table_2(kind, &mut rng),
        _ => Ok(lift::<N>(seeded_table_1(kind, &mut rng))),
    }
}

fn lift<const N: usize>(table: AlphaTable) -> AlphaTable {
    table
        .into_iter()
        .enumerate()
        .map(|(r, row)| (0..=N).map(|i| row.get(i).copied().unwrap_or(r as u32)).collect())
        .collect()
}

fn seeded_table_1(kind: Seed, rng: &mut SplitMix64) -> AlphaTable {
    let edges = match kind {
        Seed::Wild => 1,
        _ => 1 + rng.below(6),
    };
    let closed = kind == Seed::Structured;
    let k = 2 * edges as u32;
    (0..k)
        .map(|d| {
            let a0 = d ^ 1;
            let a1 = match d % 2 {
                1 if d + 1 < k => d + 1,
                1 if closed => 0,
                0 if d > 0 => d - 1,
                0 if closed => k - 1,
                _ => d,
            };
            vec![a0, a1]
        })
        .collect()
}

fn seeded_table_2(kind: Seed, rng: &mut SplitMix64) -> Result<AlphaTable, OpError> {
    let (points, triangles) = match kind {
        Seed::Structured => {
            let (p, t) = crate::generate::grid_triangles(1 + rng.below(3));
            (p.len(), t)
        }
        Seed::Soup => {
            let points = 3 + rng.below(3);
            let count = 1 + rng.below(6);
            (points, (0..count).map(|_| distinct::<3>(rng, points)).collect())
        }
        Seed::Wild => (4, vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]]),
    };
    if repeats_a_cell(&triangles) {
        let (one, _) = GMap::<2>::from_triangles(3, &[[0, 1, 2]])?;
        return Ok(pillow(&alpha_table(&one)));
    }
    let (map, _) = GMap::<2>::from_triangles(points, &triangles)?;
    Ok(alpha_table(&map))
}

fn seeded_table_3(kind: Seed, rng: &mut SplitMix64) -> Result<AlphaTable, OpError> {
    let (points, tets) = match kind {
        Seed::Structured => {
            let (p, t) = kuhn_cube(1);
            (p.len(), t)
        }
        Seed::Soup => {
            let (p, t) = kuhn_cube(2);
            let mut chosen: Vec<[u32; 4]> = t.into_iter().filter(|_| rng.below(6) == 0).take(8).collect();
            if chosen.is_empty() {
                chosen.push([0, 1, 4, 13]);
            }
            (p.len(), chosen)
        }
        Seed::Wild => {
            let points = 4 + rng.below(3);
            let count = 1 + rng.below(4);
            (points, (0..count).map(|_| distinct::<4>(rng, points)).collect())
        }
    };
    if repeats_a_cell(&tets) {
        let (one, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]])?;
        return Ok(pillow(&alpha_table(&one)));
    }
    let (map, _) = GMap::<3>::from_tets(points, &tets)?;
    Ok(alpha_table(&map))
}

/// Whether two of `cells` have the same vertex set (the builders refuse such a list). O(c log c).
fn repeats_a_cell<const K: usize>(cells: &[[u32; K]]) -> bool {
    let mut keys: Vec<[u32; K]> = cells
        .iter()
        .map(|c| {
            let mut k = *c;
            k.sort_unstable();
            k
        })
        .collect();
    keys.sort_unstable();
    keys.windows(2).any(|w| w[0] == w[1])
}

/// The pillow of one n-simplex's table: two copies of it glued along every facet (dart r of
/// the copy is r + darts, αn exchanges r and r + darts), a closed map of two n-cells with no
/// boundary — the 3-sphere of two tets, the 2-sphere of two triangles. A random draw that
/// repeats a cell yields it, so the seeds keep producing closed two-cell maps although the
/// builders refuse repeated cells. αn of the simplex must be free (every row r has αn(r) = r).
/// O(darts · n).
fn pillow(simplex: &AlphaTable) -> AlphaTable {
    let darts = simplex.len() as u32;
    let copy = |offset: u32, across: u32| {
        simplex.iter().enumerate().map(move |(r, row)| {
            let n = row.len() - 1;
            let mut out: Vec<u32> = row.iter().map(|&a| a + offset).collect();
            out[n] = r as u32 + across;
            out
        })
    };
    copy(0, darts).chain(copy(darts, 0)).collect()
}

/// K distinct random numbers below `points` (points ≥ K).
fn distinct<const K: usize>(rng: &mut SplitMix64, points: usize) -> [u32; K] {
    let perm = random_permutation(points, rng.next_u64());
    std::array::from_fn(|k| perm[k])
}

/// Whether two maps are equal slot for slot: same live darts, links, cell ids and id bounds.
/// Stronger than isomorphism; what "a refused operation leaves the map unchanged" means.
/// O(capacity · n).
///
/// # Examples
///
/// ```
/// use topomech::ops::same_raw;
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// let before = map.clone();
/// assert!(same_raw(&before, &map));
/// map.create_dart().unwrap();
/// assert!(!same_raw(&before, &map));
/// ```
pub fn same_raw<const N: usize>(a: &GMap<N>, b: &GMap<N>) -> bool {
    a.capacity() == b.capacity()
        && a.dart_count() == b.dart_count()
        && a.count_cells() == b.count_cells()
        && (0..=N).all(|i| a.cell_id_bound(i) == b.cell_id_bound(i))
        && a.darts().eq(b.darts())
        && a.darts()
            .all(|d| (0..=N).all(|i| a.alpha_dyn(i, d) == b.alpha_dyn(i, d) && a.cell_id(i, d) == b.cell_id(i, d)))
}

/// The laws that hold after every operation (see the [module docs](self)): `before` is a copy of
/// the map taken just before [`apply`], `after` the map now, `result` what apply returned.
///
/// Checked: `validate()`; allocator counts equal traversal counts; χ from both agree and moves
/// by the right amount on create/delete; component count; a refused sew/unsew/delete/grow left
/// the map slot-for-slot unchanged; `is_sewable` agrees with `sew`; a delete of a non-isolated
/// dart is refused; a sew is undone by an unsew of the same dart (and conversely) up to
/// isomorphism; cell counts move by the merges/splits reported; cell ids match a from-scratch
/// labelling by orbits and the reported changes. Cost: O(darts · n²) plus one clone.
///
/// # Examples
///
/// ```
/// use topomech::ops::{apply, check_after_op, KernelOp};
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// for op in [KernelOp::Unsew { i: 2, a: 5 }, KernelOp::DeleteDart(3), KernelOp::CreateDart] {
///     let before = map.clone();
///     let result = apply(&mut map, &op);
///     assert_eq!(check_after_op(&before, &map, &op, &result), Ok(()));
/// }
/// ```
pub fn check_after_op<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    op: &KernelOp,
    result: &Result<Applied, OpError>,
) -> Result<(), String> {
    check_map_laws(after)?;
    let resolved = resolve(before, op);
    match result {
        Err(OpError::Rebuild { .. }) => Err(format!("{op:?}: {}", result.as_ref().unwrap_err())),
        Err(e) => check_refused(before, after, resolved, e),
        Ok(applied) => check_applied(before, after, resolved, applied),
    }
    .map_err(|m| format!("{op:?} resolved as {resolved:?}: {m}"))
}

/// The laws every valid map satisfies, whatever happened before. O(darts · n²).
///
/// # Examples
///
/// ```
/// use topomech::ops::check_map_laws;
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// assert_eq!(check_map_laws(&map), Ok(()));
/// assert_eq!(check_map_laws(&GMap::<2>::new()), Ok(()));
/// ```
pub fn check_map_laws<const N: usize>(map: &GMap<N>) -> Result<(), String> {
    map.validate().map_err(|e| format!("validate(): {e}"))?;
    let (counts, walked) = (map.count_cells(), map.count_cells_by_traversal());
    if counts != walked {
        return Err(format!("count_cells() = {:?} but traversal finds {:?}", counts.0, walked.0));
    }
    if map.euler_characteristic() != walked.euler_characteristic() {
        return Err("Euler characteristic disagrees with the traversal counts".into());
    }
    if map.components().len() != map.count_orbits(AlphaMask::all(N)) {
        return Err("components() disagrees with count_orbits(all)".into());
    }
    let (all_cells, components) = map.count_all_cells_by_traversal();
    if all_cells != walked || components != map.component_labels().1 {
        return Err(format!(
            "count_all_cells_by_traversal() = ({:?}, {components}) but the traversal counts are {:?} and the \
             component flood finds {}",
            all_cells.0,
            walked.0,
            map.component_labels().1
        ));
    }
    match map.orientation() {
        Some(colour) => {
            let bad = map.darts().find(|&d| {
                (0..=N).any(|i| map.alpha_dyn(i, d) != d && colour[map.alpha_dyn(i, d).index()] == colour[d.index()])
            });
            if let Some(d) = bad {
                return Err(format!("orientation() colours {d:?} like one of its neighbours"));
            }
        }
        None if two_colourable(map) => {
            return Err("orientation() is None but the darts have a proper 2-colouring".to_string());
        }
        None => {}
    }
    check_cell_ids_exact(map)
}

/// Whether the darts can be 2-coloured so that every αi link (not a fixed point) joins two
/// colours: the orientability test, written again here (a breadth-first search) so that a wrong
/// `None` from [`GMap::orientation`] is caught. O(darts · n).
fn two_colourable<const N: usize>(map: &GMap<N>) -> bool {
    let mut colour = vec![None; map.capacity()];
    let mut queue = std::collections::VecDeque::new();
    for root in map.darts() {
        if colour[root.index()].is_some() {
            continue;
        }
        colour[root.index()] = Some(false);
        queue.push_back(root);
        while let Some(x) = queue.pop_front() {
            let c = colour[x.index()] == Some(true);
            for y in (0..=N).map(|i| map.alpha_dyn(i, x)).filter(|&y| y != x) {
                match colour[y.index()] {
                    None => {
                        colour[y.index()] = Some(!c);
                        queue.push_back(y);
                    }
                    Some(same) if same == c => return false,
                    Some(_) => {}
                }
            }
        }
    }
    true
}

/// Cell ids equal a from-scratch labelling by orbits: for every dimension, two darts share an id
/// iff they lie in the same orbit ⟨⟩N−{i} (computed here by an independent flood over αj), every
/// id is live, and the live ids are exactly the cells. O(darts · n²).
///
/// # Examples
///
/// ```
/// use topomech::ops::check_cell_ids_exact;
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// assert_eq!(check_cell_ids_exact(&map), Ok(()));
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// map.unsew::<3>(d).unwrap(); // splits vertices, edges and the face: ids must follow
/// assert_eq!(check_cell_ids_exact(&map), Ok(()));
/// ```
pub fn check_cell_ids_exact<const N: usize>(map: &GMap<N>) -> Result<(), String> {
    for dim in 0..=N {
        let label = orbit_labels(map, dim);
        let cells = label.iter().filter(|&&l| l != u32::MAX).max().map_or(0, |&m| m as usize + 1);
        let mut id_of_orbit = vec![None; cells];
        // A BTreeMap, not a HashMap: deterministic, and no random state under Kani.
        let mut orbit_of_id = std::collections::BTreeMap::new();
        for d in map.darts() {
            let (l, id) = (label[d.index()] as usize, map.cell_id(dim, d));
            if !map.is_live_cell(dim, id) {
                return Err(format!("{d:?} carries dead {dim}-cell id {id:?}"));
            }
            if *id_of_orbit[l].get_or_insert(id) != id {
                return Err(format!("{dim}-cell of {d:?} carries two ids"));
            }
            if *orbit_of_id.entry(id).or_insert(l) != l {
                return Err(format!("{dim}-cell id {id:?} is shared by two orbits (one at {d:?})"));
            }
        }
        if map.count_cells().0[dim] != cells {
            return Err(format!("{} live {dim}-cell ids but {cells} orbits", map.count_cells().0[dim]));
        }
    }
    Ok(())
}

/// Orbit index of every dart slot for the dim-cells, by a flood written here (u32::MAX on dead
/// slots). O(darts · n).
fn orbit_labels<const N: usize>(map: &GMap<N>, dim: usize) -> Vec<u32> {
    let mut label = vec![u32::MAX; map.capacity()];
    let mut next = 0;
    let mut stack = Vec::new();
    for d in map.darts() {
        if label[d.index()] != u32::MAX {
            continue;
        }
        label[d.index()] = next;
        stack.push(d);
        while let Some(x) = stack.pop() {
            for j in (0..=N).filter(|&j| j != dim) {
                let y = map.alpha_dyn(j, x);
                if label[y.index()] == u32::MAX {
                    label[y.index()] = next;
                    stack.push(y);
                }
            }
        }
        next += 1;
    }
    label
}

fn check_refused<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    resolved: Resolved,
    e: &OpError,
) -> Result<(), String> {
    if !same_raw(before, after) || !after.is_isomorphic(before) {
        return Err(format!("refused with `{e}` but the map changed"));
    }
    match resolved {
        Resolved::Sew { i, a, b } if before.is_sewable_dyn(i, a, b) => {
            Err(format!("is_sewable is true but sew failed: {e}"))
        }
        Resolved::Delete(d) if before.contains(d) && before.is_isolated(d) => {
            Err(format!("delete of an isolated dart refused: {e}"))
        }
        Resolved::Unsew { i, a } if i <= N && before.contains(a) && !before.is_free(i, a) => {
            Err(format!("unsew of a sewn dart refused: {e}"))
        }
        Resolved::Create | Resolved::Nothing => Err(format!("refused an operation that cannot fail: {e}")),
        _ => Ok(()),
    }
}

fn check_applied<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    resolved: Resolved,
    applied: &Applied,
) -> Result<(), String> {
    let signed: i64 = (0..=N).map(|i| if i % 2 == 0 { 1 } else { -1 }).sum();
    let chi = |m: &GMap<N>| m.euler_characteristic();
    match applied {
        Applied::Nothing => same_raw(before, after).then_some(()).ok_or_else(|| "a no-op changed the map".to_string()),
        Applied::Created(d) => {
            let ok = after.is_isolated(*d)
                && after.dart_count() == before.dart_count() + 1
                && chi(after) == chi(before) + signed;
            ok.then_some(())
                .ok_or_else(|| format!("create_dart gave {d:?}: not isolated, or dart count / χ moved wrongly"))
        }
        Applied::Deleted(d) => {
            let ok = before.is_isolated(*d)
                && !after.contains(*d)
                && after.dart_count() + 1 == before.dart_count()
                && chi(after) + signed == chi(before);
            ok.then_some(())
                .ok_or_else(|| format!("delete_dart({d:?}) accepted a non-isolated dart or moved counts wrongly"))
        }
        Applied::Sewn { i, a, b, changes } => check_sewn(before, after, (*i, *a, *b), changes),
        Applied::Unsewn { i, a, partner, changes } => check_unsewn(before, after, (*i, *a, *partner), changes),
        Applied::Grown(darts) => {
            let ok =
                after.dart_count() == before.dart_count() + darts.len() && matches!(resolved, Resolved::Grow { .. });
            ok.then_some(()).ok_or_else(|| "grow added the wrong number of darts".to_string())
        }
    }
}

fn check_sewn<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    (i, a, b): (usize, DartId, DartId),
    changes: &CellChanges,
) -> Result<(), String> {
    if !before.is_sewable_dyn(i, a, b) {
        return Err("sew succeeded but is_sewable was false".into());
    }
    if after.alpha_dyn(i, a) != b {
        return Err(format!("after the sew alpha{i}({a:?}) = {:?}, not {b:?}", after.alpha_dyn(i, a)));
    }
    check_cell_changes(before, after, i, changes, true)?;
    if let Some(dim) = (0..=N).find(|&dim| after.cell_id(dim, a) != before.cell_id(dim, a)) {
        return Err(format!("the sew changed the {dim}-cell id of d1 = {a:?}, which must survive"));
    }
    let mut undone = after.clone();
    undone.unsew_dyn(i, a).map_err(|e| format!("unsew after sew refused: {e}"))?;
    if !undone.is_isomorphic(before) {
        return Err("sew then unsew of the same dart is not isomorphic to the start".into());
    }
    Ok(())
}

fn check_unsewn<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    (i, a, partner): (usize, DartId, DartId),
    changes: &CellChanges,
) -> Result<(), String> {
    if !after.is_free(i, a) || !after.is_free(i, partner) {
        return Err(format!("after the unsew {a:?} or {partner:?} is still {i}-sewn"));
    }
    check_cell_changes(before, after, i, changes, false)?;
    if !after.is_sewable_dyn(i, a, partner) {
        return Err("an unsewn pair is not sewable again".into());
    }
    let mut redone = after.clone();
    redone.sew_dyn(i, a, partner).map_err(|e| format!("sew after unsew refused: {e}"))?;
    if !redone.is_isomorphic(before) {
        return Err("unsew then sew back is not isomorphic to the start".into());
    }
    Ok(())
}

/// The reported [`CellChanges`] of an i-sew (`sewing`) or i-unsew agree with the maps: the pairs
/// are exactly the changed αi links; i-cell ids never change; for every other dimension each
/// dart's new id is its old id followed through the reported merges (sew) or splits (unsew);
/// cell counts move by the number of merges/splits. (That d1 keeps its ids is checked by the
/// caller, which knows d1.)
/// O(darts · n).
///
/// # Examples
///
/// ```
/// use topomech::ops::check_cell_changes;
/// use topomech::GMap;
///
/// let (mut map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
/// let before = map.clone();
/// let d = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
/// let changes = map.unsew::<3>(d).unwrap();
/// assert_eq!(check_cell_changes(&before, &map, 3, &changes, false), Ok(()));
/// assert!(check_cell_changes(&before, &map, 3, &changes, true).is_err()); // not a sew
/// ```
pub fn check_cell_changes<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    i: usize,
    changes: &CellChanges,
    sewing: bool,
) -> Result<(), String> {
    check_pairs(before, after, i, changes, sewing)?;
    for dim in 0..=N {
        let (merges, splits) = (changes.merges(dim).count(), changes.splits(dim).count());
        if dim == i && merges + splits > 0 {
            return Err(format!("an {i}-(un)sew reported a change of {i}-cells"));
        }
        let expected = before.count_cells().0[dim] as i64 + splits as i64 - merges as i64;
        if after.count_cells().0[dim] as i64 != expected || (sewing && splits > 0) || (!sewing && merges > 0) {
            return Err(format!(
                "{dim}-cells: {} after, expected {expected} from the report",
                after.count_cells().0[dim]
            ));
        }
        let follow = id_successors(changes, dim, sewing);
        for d in before.darts() {
            let (old, new) = (before.cell_id(dim, d), after.cell_id(dim, d));
            if !reaches(&follow, old, new, sewing) {
                return Err(format!("{dim}-cell id of {d:?} went {old:?} -> {new:?}, not explained by the report"));
            }
        }
    }
    Ok(())
}

/// The reported pairs are i-free before and linked after (sew), or the reverse (unsew), and no
/// other αi link changed.
fn check_pairs<const N: usize>(
    before: &GMap<N>,
    after: &GMap<N>,
    i: usize,
    changes: &CellChanges,
    sewing: bool,
) -> Result<(), String> {
    let (linked, unlinked) = if sewing { (after, before) } else { (before, after) };
    for &(x, y) in &changes.pairs {
        if linked.alpha_dyn(i, x) != y || !unlinked.is_free(i, x) || !unlinked.is_free(i, y) {
            return Err(format!("reported pair ({x:?}, {y:?}) is not a changed alpha{i} link"));
        }
    }
    let changed = before.darts().filter(|&d| (0..=N).any(|j| before.alpha_dyn(j, d) != after.alpha_dyn(j, d))).count();
    let expected: usize = changes.pairs.iter().map(|&(x, y)| if x == y { 1 } else { 2 }).sum();
    if changed != expected {
        return Err(format!("{changed} darts changed links but the report lists {expected}"));
    }
    Ok(())
}

/// Edges old id → new id of one dimension: absorbed → kept for a sew, kept → new for an unsew.
fn id_successors(changes: &CellChanges, dim: usize, sewing: bool) -> Vec<(CellId, CellId)> {
    if sewing {
        changes.merges(dim).map(|(kept, absorbed)| (absorbed, kept)).collect()
    } else {
        changes.splits(dim).map(|(kept, new, _, _)| (kept, new)).collect()
    }
}

/// Whether `to` is reachable from `from` along the edges (a sew must follow them to the end:
/// an absorbed id is dead).
fn reaches(edges: &[(CellId, CellId)], from: CellId, to: CellId, must_end: bool) -> bool {
    let mut frontier = vec![from];
    let mut seen = vec![from];
    while let Some(x) = frontier.pop() {
        let next: Vec<CellId> = edges.iter().filter(|e| e.0 == x).map(|e| e.1).collect();
        if x == to && (!must_end || next.is_empty()) {
            return true;
        }
        for y in next {
            if !seen.contains(&y) && seen.len() <= edges.len() {
                seen.push(y);
                frontier.push(y);
            }
        }
    }
    false
}

/// Applies `ops` in order, checking [`check_after_op`] after each; returns the index and message
/// of the first broken law. Cost: Σ over steps of O(darts · n²).
///
/// # Examples
///
/// ```
/// use topomech::ops::{run_ops, KernelOp};
/// use topomech::GMap;
///
/// let ops = [KernelOp::CreateDart, KernelOp::CreateDart, KernelOp::Sew { i: 2, a: 0, b: 1 }];
/// let mut map = GMap::<2>::new();
/// assert_eq!(run_ops(&mut map, &ops), Ok(()));
/// assert_eq!((map.dart_count(), map.is_free(2, topomech::DartId(0))), (2, false));
/// ```
pub fn run_ops<const N: usize>(map: &mut GMap<N>, ops: &[KernelOp]) -> Result<(), String> {
    for (k, op) in ops.iter().enumerate() {
        let before = map.clone();
        let result = apply(map, op);
        check_after_op(&before, map, op, &result).map_err(|m| format!("step {k} (n = {N}): {m}"))?;
    }
    Ok(())
}

/// Runs a whole fuzz input: byte 0 picks n = 1 + byte % 3, the rest is [`decode`]d and run from
/// an empty map with [`run_ops`]. Returns the first broken law.
///
/// # Examples
///
/// ```
/// use topomech::ops::run_bytes;
///
/// assert_eq!(run_bytes(&[]), Ok(()));
/// // n = 3; grow a Kuhn cube, then unsew dart 10 along α3 and create a dart.
/// assert_eq!(run_bytes(&[2, 7, 0, 1, 0, 5, 3, 10, 0, 0]), Ok(()));
/// ```
pub fn run_bytes(bytes: &[u8]) -> Result<(), String> {
    let Some((&first, rest)) = bytes.split_first() else { return Ok(()) };
    let ops = decode(rest);
    match first % 3 {
        0 => run_ops(&mut GMap::<1>::new(), &ops),
        1 => run_ops(&mut GMap::<2>::new(), &ops),
        _ => run_ops(&mut GMap::<3>::new(), &ops),
    }
}

/// One deliberate corruption of a map, below the kernel's laws (for proofs of `validate()`).
///
/// # Examples
///
/// ```
/// use topomech::ops::{check_map_laws, raw_edit_unchecked, RawEdit};
/// use topomech::{DartId, GMap};
///
/// let (mut map, _) = GMap::<3>::from_tets(4, &[[0, 1, 2, 3]]).unwrap();
/// assert!(check_map_laws(&map).is_ok());
/// assert!(raw_edit_unchecked(&mut map, RawEdit::SetCell { dim: 0, d: DartId(0), id: 3 }));
/// assert!(check_map_laws(&map).is_err()); // the vertex orbit of dart 0 no longer has one id
/// assert!(!raw_edit_unchecked(&mut map, RawEdit::Unlink { i: 9, a: DartId(0) })); // i > n: refused
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RawEdit {
    /// Set αi(a) = b and αi(b) = a, nothing else (b may be a dead slot).
    Link {
        /// Involution.
        i: usize,
        /// One dart.
        a: DartId,
        /// The other.
        b: DartId,
    },
    /// Make a and its αi image i-free.
    Unlink {
        /// Involution.
        i: usize,
        /// The dart.
        a: DartId,
    },
    /// Overwrite the dim-cell id of d (ids are not released or allocated).
    SetCell {
        /// Dimension.
        dim: usize,
        /// The dart.
        d: DartId,
        /// The new id (may be dead or never allocated).
        id: u32,
    },
}

/// Applies a raw edit with no check at all: the map may break any law afterwards, and later
/// public mutators may then panic on their own checks. Meant only for tests of `validate()`.
/// Returns false (and does nothing) if an index is out of range (i > n or a dart slot ≥
/// capacity). O(1).
#[doc(hidden)]
pub fn raw_edit_unchecked<const N: usize>(map: &mut GMap<N>, edit: RawEdit) -> bool {
    let cap = map.capacity();
    match edit {
        RawEdit::Link { i, a, b } if i <= N && a.index() < cap && b.index() < cap => map.link_raw(i, a, b),
        RawEdit::Unlink { i, a } if i <= N && map.contains(a) && map.contains(map.alpha_dyn(i, a)) => {
            map.unlink_raw(i, a)
        }
        RawEdit::SetCell { dim, d, id } if dim <= N && d.index() < cap => map.set_cell_raw(dim, d, id),
        _ => return false,
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_is_total_and_bounded() {
        assert!(decode(&[]).is_empty());
        assert_eq!(decode(&[3]), vec![KernelOp::Sew { i: 0, a: 0, b: 0 }]);
        assert_eq!(check_decode(&[0u8; 10_000]).unwrap().len(), MAX_OPS);
    }

    #[test]
    fn encode_inverts_decode() {
        let ops = vec![
            KernelOp::CreateDart,
            KernelOp::DeleteDart(7),
            KernelOp::Sew { i: 2, a: 300, b: 1 },
            KernelOp::SewFree { i: 1, a: 5, b: 9 },
            KernelOp::Unsew { i: 3, a: 65_535 },
            KernelOp::Grow { kind: Seed::Soup, seed: 42 },
        ];
        assert_eq!(decode(&encode(&ops)), ops);
    }

    /// Draws that repeat a cell give the pillow (a closed two-cell map), often enough to matter:
    /// for n = 3 Wild draws on 4 points with 2 or more tets, for n = 2 Soup draws that repeat a
    /// triangle. The pillow is valid, has no boundary dart, and its cells are those of two
    /// simplices glued along every facet.
    #[test]
    fn draws_that_repeat_a_cell_give_the_closed_pillow() {
        let pillows = |table_of: &dyn Fn(u32) -> Result<AlphaTable, OpError>, darts: usize| {
            (0..200).filter(|&s| table_of(s).is_ok_and(|t| t.len() == darts)).count()
        };
        let three = pillows(&|s| seeded_table::<3>(Seed::Wild, s), 48);
        let two = pillows(&|s| seeded_table::<2>(Seed::Soup, s), 12);
        assert!(three >= 20 && two >= 20, "pillows among 200 draws: {three} (n = 3), {two} (n = 2)");
        let seed3 = (0..200).find(|&s| seeded_table::<3>(Seed::Wild, s).unwrap().len() == 48).unwrap();
        let map3 = from_alpha_table::<3>(&seeded_table::<3>(Seed::Wild, seed3).unwrap()).unwrap();
        assert_eq!(map3.validate(), Ok(()));
        assert_eq!(map3.count_cells().0, [4, 6, 4, 2]);
        assert!(map3.darts().all(|d| !map3.is_free(3, d)), "the pillow of two tets is closed");
        let seed2 = (0..200).find(|&s| seeded_table::<2>(Seed::Soup, s).is_ok_and(|t| t.len() == 12)).unwrap();
        let map2 = from_alpha_table::<2>(&seeded_table::<2>(Seed::Soup, seed2).unwrap()).unwrap();
        assert_eq!(map2.validate(), Ok(()));
        assert_eq!(map2.count_cells().0, [3, 3, 2]);
        assert!(map2.darts().all(|d| !map2.is_free(2, d)), "the pillow of two triangles is closed");
    }

    #[test]
    fn seeded_tables_are_valid_for_each_dimension() {
        for seed in 0..20 {
            for kind in [Seed::Structured, Seed::Soup, Seed::Wild] {
                if let Ok(t) = seeded_table::<1>(kind, seed) {
                    check_alpha_table::<1>(&t).unwrap();
                }
                if let Ok(t) = seeded_table::<2>(kind, seed) {
                    check_alpha_table::<2>(&t).unwrap();
                }
                if let Ok(t) = seeded_table::<3>(kind, seed) {
                    check_alpha_table::<3>(&t).unwrap();
                }
            }
        }
    }

    #[test]
    fn a_broken_table_is_refused() {
        let table = vec![vec![1, 0], vec![1, 1]];
        assert!(matches!(check_alpha_table::<1>(&table), Err(OpError::BadTable { row: 0, .. })));
    }
}

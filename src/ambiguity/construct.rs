//! How the maps of the study are made: polygons glued along edges (2D), and small tetrahedral
//! complexes with some interior faces dissociated (3D). Both are plain data, stored in the test
//! vectors next to the darts, so a vector can be rebuilt two ways.

use crate::gmap::{DartId, GMap, SewError};
use crate::BuildError;

/// A 2-G-map made of polygons glued edge to edge.
///
/// Polygon p with s sides has darts 2(o + k) and 2(o + k) + 1 on its side k (o = sides of the
/// polygons before p): α0 joins the two darts of a side, α1 joins dart 2(o + k) + 1 to
/// 2(o + (k + 1) mod s). Dart 2(o + k) is the *start* of side k when walking around the polygon.
/// A glued pair of sides (a, b) 2-sews start(a) to start(b) when `same_direction` (the word
/// `… x … x …`, orientation-reversing for consistently walked polygons) or to end(b) otherwise
/// (`… x … x⁻¹ …`). Unglued sides are boundary.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::Gluing;
///
/// // The word (a b a b): both pairs of opposite sides glued the same direction, the real
/// // projective plane (non-orientable, χ = 1).
/// let rp2 = Gluing { sides: vec![4], pairs: vec![[0, 2, 1], [1, 3, 1]] };
/// let map = rp2.build().unwrap();
/// assert_eq!(rp2.word(), "(a b a b)");
/// assert!(!map.is_orientable() && map.boundary_darts().count() == 0);
/// assert_eq!(map.euler_characteristic(), 1);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Gluing {
    /// Number of sides of each polygon (1-gons and 2-gons are allowed in a G-map).
    pub sides: Vec<u8>,
    /// Glued sides `[a, b, same_direction]` (global side indices, same_direction 0 or 1; any other
    /// value is refused by [`Gluing::build`] with [`ConstructError::BadWay`]).
    pub pairs: Vec<[u16; 3]>,
}

/// Why a construction could not be turned into a map.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::{ConstructError, FaceGluing};
/// let bad = FaceGluing { tets: 1, pairs: vec![[0, 9, 0]] };
/// let e = bad.build().unwrap_err();
/// assert!(matches!(e, ConstructError::BadSide { side: 9, sides: 4 }));
/// assert!(e.to_string().contains("side 9"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConstructError {
    /// A side (a polygon's side for [`Gluing`], a tet's face for [`FaceGluing`]) index past the
    /// last one, a side glued twice or to itself. Refused before any sew.
    #[error(
        "side {side} cannot be glued (there are {sides} sides; each side is glued at most once, and not to itself)"
    )]
    BadSide {
        /// The side.
        side: u16,
        /// Number of sides.
        sides: usize,
    },
    /// The kernel refused a sew.
    #[error(transparent)]
    Sew(#[from] SewError),
    /// The tetrahedra do not form a quasi-manifold.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// A cut names two tets that do not share a glued face.
    #[error("tets {0} and {1} do not share a glued face")]
    NoSharedFace(u32, u32),
    /// A polygon with no side, or too many darts.
    #[error("polygon {0} has no side")]
    EmptyPolygon(usize),
    /// A glued pair whose last entry is not one of its ways: a [`Gluing`] direction flag other
    /// than 0 or 1, a [`FaceGluing`] way k ≥ 6. Refused before any sew.
    #[error("glued pair {pair} has way {way}, not one of 0..{ways} (a side pair's direction is 0 or 1, a face pair's k is in 0..6)")]
    BadWay {
        /// The index of the pair in `pairs`.
        pair: usize,
        /// The value given.
        way: u16,
        /// The number of ways (2 for sides, 6 for faces).
        ways: u16,
    },
}

impl Gluing {
    /// Total number of sides.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::Gluing;
    ///
    /// let g = Gluing { sides: vec![4, 3], pairs: vec![[0, 4, 0]] };
    /// assert_eq!(g.side_count(), 7);
    /// assert_eq!(g.build().unwrap().dart_count(), 2 * 7);
    /// ```
    pub fn side_count(&self) -> usize {
        self.sides.iter().map(|&s| s as usize).sum()
    }

    /// The 2-G-map (2 darts per side, one α0 pair). Errors name the first bad side (past the
    /// last, glued twice or to itself), the first pair whose direction is not 0 or 1, or the
    /// refused sew. O(sides).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::{ConstructError, Gluing};
    ///
    /// let torus = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] };
    /// let map = torus.build().unwrap();
    /// assert_eq!(map.count_cells().0, vec![1, 2, 1]);
    /// assert!(map.is_orientable() && map.boundary_darts().count() == 0);
    /// let twice = Gluing { sides: vec![3], pairs: vec![[0, 1, 0], [1, 2, 0]] };
    /// assert!(matches!(twice.build(), Err(ConstructError::BadSide { side: 1, .. })));
    /// let seven = Gluing { sides: vec![4], pairs: vec![[0, 2, 7]] };
    /// assert_eq!(seven.build().unwrap_err(), ConstructError::BadWay { pair: 0, way: 7, ways: 2 });
    /// ```
    pub fn build(&self) -> Result<GMap<2>, ConstructError> {
        let total = self.side_count();
        let mut map = GMap::<2>::new();
        for _ in 0..2 * total {
            map.create_dart().map_err(|_| ConstructError::BadSide { side: 0, sides: total })?;
        }
        let mut offset = 0u32;
        for (p, &s) in self.sides.iter().enumerate() {
            if s == 0 {
                return Err(ConstructError::EmptyPolygon(p));
            }
            let s = s as u32;
            for k in 0..s {
                map.sew::<0>(DartId(2 * (offset + k)), DartId(2 * (offset + k) + 1))?;
            }
            for k in 0..s {
                map.sew::<1>(DartId(2 * (offset + k) + 1), DartId(2 * (offset + (k + 1) % s)))?;
            }
            offset += s;
        }
        check_pairs(&self.pairs, total, 2)?;
        for &[a, b, same] in &self.pairs {
            let target = if same == 1 { 2 * b as u32 } else { 2 * b as u32 + 1 };
            map.sew::<2>(DartId(2 * a as u32), DartId(target))?;
        }
        Ok(map)
    }

    /// The gluing as a word per polygon: letters for glued sides (`x'` = x⁻¹), `·` for boundary
    /// sides, e.g. `(a b a' b')` for the torus. O(sides).
    ///
    /// Pair k is named by the letter `a` + k mod 26, followed from the 27th pair on by the round
    /// k / 26 (`a` … `z`, then `a1` … `z1`, `a2` …), so that distinct pairs always get distinct
    /// names. The fields are public, so a gluing may name a side past the last one (which
    /// [`Gluing::build`] refuses with [`ConstructError::BadSide`]): its word is then `?`, and
    /// never a panic.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::Gluing;
    ///
    /// let klein = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 1]] };
    /// assert_eq!(klein.word(), "(a b a' b)");
    /// let open = Gluing { sides: vec![3, 1], pairs: vec![] };
    /// assert_eq!(open.word(), "(· · ·) (·)");
    /// let bad = Gluing { sides: vec![2], pairs: vec![[0, 5, 0]] }; // side 5 of 2
    /// assert_eq!(bad.word(), "?");
    /// let squares = Gluing { sides: vec![4; 14], pairs: (0..28u16).map(|k| [2 * k, 2 * k + 1, 0]).collect() };
    /// assert!(squares.word().ends_with("(y y' z z') (a1 a1' b1 b1')"));
    /// ```
    pub fn word(&self) -> String {
        let total = self.side_count();
        if self.pairs.iter().any(|&[a, b, _]| a as usize >= total || b as usize >= total) {
            return "?".to_string();
        }
        let mut label = vec!["·".to_string(); total];
        for (n, &[a, b, same]) in self.pairs.iter().enumerate() {
            let mut letter = char::from(b'a' + (n % 26) as u8).to_string();
            if n >= 26 {
                letter.push_str(&(n / 26).to_string());
            }
            label[a as usize] = letter.clone();
            label[b as usize] = if same != 0 { letter } else { format!("{letter}'") };
        }
        let mut out = Vec::new();
        let mut offset = 0;
        for &s in &self.sides {
            out.push(format!("({})", label[offset..offset + s as usize].join(" ")));
            offset += s as usize;
        }
        out.join(" ")
    }
}

/// Every gluing of polygons with 1..=`max_polygon` sides, `max_sides` sides in total, the
/// polygons in non-increasing size, every partial matching of sides with both directions.
/// Connectedness is not required here (the finder drops disconnected maps). Bounded: for
/// `max_sides` = 6 there are a few thousand. The recursion depth is at most `max_sides`.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::gluings;
///
/// // Polygons (1), (2), (1 1): 1 + 3 + 3 gluings (none, or one pair in either direction).
/// let all = gluings(2, 2);
/// assert_eq!(all.len(), 7);
/// assert!(all.iter().all(|g| g.side_count() <= 2 && g.build().is_ok()));
/// ```
pub fn gluings(max_sides: usize, max_polygon: usize) -> Vec<Gluing> {
    let mut out = Vec::new();
    let mut partitions = Vec::new();
    partitions_into(max_sides, max_polygon, &mut Vec::new(), &mut partitions);
    for sides in partitions {
        let total: usize = sides.iter().map(|&s| s as usize).sum();
        let mut matchings = Vec::new();
        matchings_of(&mut vec![false; total], &mut Vec::new(), &mut matchings);
        for pairs in matchings {
            for bits in 0u32..(1 << pairs.len()) {
                let pairs = pairs.iter().enumerate().map(|(k, &(a, b))| [a, b, ((bits >> k) & 1) as u16]).collect();
                out.push(Gluing { sides: sides.clone(), pairs });
            }
        }
    }
    out
}

/// Non-increasing sequences of parts in 1..=max_part with sum in 1..=budget.
fn partitions_into(budget: usize, max_part: usize, prefix: &mut Vec<u8>, out: &mut Vec<Vec<u8>>) {
    for part in (1..=max_part.min(budget)).rev() {
        prefix.push(part as u8);
        out.push(prefix.clone());
        partitions_into(budget - part, part, prefix, out);
        prefix.pop();
    }
}

/// Every partial matching of the sides not yet used: the first unused side is either left alone
/// or paired with a later unused side.
fn matchings_of(used: &mut [bool], prefix: &mut Vec<(u16, u16)>, out: &mut Vec<Vec<(u16, u16)>>) {
    let Some(first) = used.iter().position(|&u| !u) else {
        out.push(prefix.clone());
        return;
    };
    used[first] = true;
    matchings_of(used, prefix, out);
    for other in first + 1..used.len() {
        if used[other] {
            continue;
        }
        used[other] = true;
        prefix.push((first as u16, other as u16));
        matchings_of(used, prefix, out);
        prefix.pop();
        used[other] = false;
    }
    used[first] = false;
}

/// A tetrahedral complex with some interior faces dissociated: `GMap::from_tets` then one
/// `unsew::<3>` per cut, a cut naming the two tets whose common face is dissociated.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::CutComplex;
///
/// let ring = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [0, 1, 3, 4], [0, 1, 4, 2]], cuts: vec![[0, 1]] };
/// let map = ring.build().unwrap();
/// assert_eq!(map.count_cells().0[0], 6); // point 3 split in two; the ring stays connected
/// assert_eq!(map.components().len(), 1);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct CutComplex {
    /// Number of points.
    pub points: usize,
    /// The tetrahedra.
    pub tets: Vec<[u32; 4]>,
    /// The cuts `[t1, t2]`, in order.
    pub cuts: Vec<[u32; 2]>,
}

impl CutComplex {
    /// The 3-G-map after the cuts. Errors: the build's, or a cut whose tets no longer share a
    /// glued face. O(tets + cuts).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::{glued_faces, ConstructError, CutComplex};
    ///
    /// let c = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![[0, 1]] };
    /// let map = c.build().unwrap();
    /// assert!(glued_faces(&map).is_empty());
    /// assert_eq!(map.count_cells().0, vec![8, 12, 8, 2]);
    /// let again = CutComplex { cuts: vec![[0, 1], [0, 1]], ..c };
    /// assert!(matches!(again.build(), Err(ConstructError::NoSharedFace(0, 1))));
    /// ```
    pub fn build(&self) -> Result<GMap<3>, ConstructError> {
        let (mut map, _) = GMap::<3>::from_tets(self.points, &self.tets)?;
        for &[t1, t2] in &self.cuts {
            let d = shared_face_dart(&map, t1, t2).ok_or(ConstructError::NoSharedFace(t1, t2))?;
            map.unsew::<3>(d)?;
        }
        Ok(map)
    }
}

/// A dart of tet `t1` that is 3-sewn to tet `t2`, for maps laid out by `GMap::from_tets` (darts
/// 24·t .. 24·t + 24; unsew does not move darts). O(24).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::{construct::shared_face_dart, indexed::dart_in_tet};
/// use topomech::GMap;
///
/// let (map, _) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]).unwrap();
/// let d = shared_face_dart(&map, 0, 1).unwrap();
/// assert!(dart_in_tet(d, 0) && dart_in_tet(map.alpha::<3>(d), 1));
/// assert_eq!(shared_face_dart(&map, 0, 0), None);
/// assert_eq!(shared_face_dart(&map, 5, 1), None);
/// ```
pub fn shared_face_dart(map: &GMap<3>, t1: u32, t2: u32) -> Option<DartId> {
    let first = 24 * t1 as usize;
    if first + 24 > map.capacity() {
        return None;
    }
    (first..first + 24)
        .map(|d| DartId(d as u32))
        .find(|&d| map.contains(d) && !map.is_free(3, d) && map.cell_id(3, map.alpha::<3>(d)).0 == t2)
}

/// The pairs of tets sharing a glued face, `[t1, t2]` with t1 < t2, each once. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::glued_faces;
/// use topomech::{generate, GMap};
///
/// let (points, tets) = generate::kuhn_cube(1);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let faces = glued_faces(&map);
/// assert_eq!(faces.len(), 6); // the six tets around the cube's diagonal
/// assert!(faces.iter().all(|&[a, b]| a < b));
/// ```
pub fn glued_faces(map: &GMap<3>) -> Vec<[u32; 2]> {
    let mut out: Vec<[u32; 2]> = map
        .sewn_pairs(3)
        .map(|(x, y)| {
            let (a, b) = (map.cell_id(3, x).0, map.cell_id(3, y).0);
            [a.min(b), a.max(b)]
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// Every connected complex of at most `max_tets` tets on points 0..`points` whose first tet is
/// [0, 1, 2, 3] and whose tets are in increasing lexicographic order, that builds (no face shared
/// by three tets), with every subset of its glued faces cut. Bounded: C(C(points, 4) − 1,
/// max_tets − 1) complexes times 2^(glued faces) cut sets. None for fewer than 4 points or
/// `max_tets` = 0 (no tet fits).
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::cut_complexes;
///
/// // One tet, or [0, 1, 2, 3] plus one of the four other tets on 5 points (each shares a face
/// // with it), with that face glued or cut: 1 + 4 · 2 complexes.
/// let all = cut_complexes(5, 2);
/// assert_eq!(all.len(), 9);
/// assert!(all.iter().all(|c| c.tets[0] == [0, 1, 2, 3] && c.build().is_ok()));
/// assert!(cut_complexes(3, 2).is_empty() && cut_complexes(5, 0).is_empty());
/// ```
pub fn cut_complexes(points: usize, max_tets: usize) -> Vec<CutComplex> {
    if points < 4 || max_tets == 0 {
        return Vec::new(); // no tet on fewer than 4 points, none allowed at 0
    }
    let all: Vec<[u32; 4]> = combinations4(points as u32);
    let mut out = Vec::new();
    let mut chosen = vec![0usize];
    subsets_from(&all, 1, max_tets, &mut chosen, &mut |idx| {
        let tets: Vec<[u32; 4]> = idx.iter().map(|&i| all[i]).collect();
        let used = tets.iter().flatten().copied().max().map_or(0, |m| m as usize + 1);
        if !points_connected(&tets) {
            return;
        }
        let Ok((map, _)) = GMap::<3>::from_tets(used, &tets) else { return };
        let faces = glued_faces(&map);
        for bits in 0u32..(1 << faces.len()) {
            let cuts = (0..faces.len()).filter(|&k| (bits >> k) & 1 == 1).map(|k| faces[k]).collect();
            out.push(CutComplex { points: used, tets: tets.clone(), cuts });
        }
    });
    out
}

fn combinations4(n: u32) -> Vec<[u32; 4]> {
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    out.push([a, b, c, d]);
                }
            }
        }
    }
    out
}

/// Calls `visit` on `chosen` and on every extension by increasing indices ≥ `from`, up to `max`
/// elements. Recursion depth ≤ `max`.
fn subsets_from(all: &[[u32; 4]], from: usize, max: usize, chosen: &mut Vec<usize>, visit: &mut dyn FnMut(&[usize])) {
    visit(chosen);
    if chosen.len() >= max {
        return;
    }
    for next in from..all.len() {
        chosen.push(next);
        subsets_from(all, next + 1, max, chosen, visit);
        chosen.pop();
    }
}

/// Whether the tets are connected through shared points. O(tets²).
fn points_connected(tets: &[[u32; 4]]) -> bool {
    let mut reached = vec![false; tets.len()];
    let mut stack = vec![0];
    reached[0] = true;
    while let Some(t) = stack.pop() {
        for u in 0..tets.len() {
            if !reached[u] && tets[u].iter().any(|p| tets[t].contains(p)) {
                reached[u] = true;
                stack.push(u);
            }
        }
    }
    reached.iter().all(|&r| r)
}

/// A 3-G-map made of tetrahedra whose faces are glued to each other (the 3D analogue of
/// [`Gluing`]): tet t has darts 24·t + 6·f + k as laid out by `GMap::from_tets` (face f, flag k);
/// a glued pair `[a, b, k]` of faces (global index 4·t + f) 3-sews dart 0 of face a to dart k of
/// face b, one of the six ways to match two triangles.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::FaceGluing;
/// let none = FaceGluing { tets: 2, pairs: vec![] };
/// assert_eq!(none.build().unwrap().components().len(), 2);
/// let glued = FaceGluing { tets: 2, pairs: vec![[1, 6, 0]] };
/// assert_eq!(glued.build().unwrap().components().len(), 1);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct FaceGluing {
    /// Number of tetrahedra.
    pub tets: u8,
    /// Glued faces `[a, b, k]` with k in 0..6.
    pub pairs: Vec<[u16; 3]>,
}

impl FaceGluing {
    /// The 3-G-map (24 darts per tet). Errors, found before any sew: a face index past the last
    /// face, a face glued twice or to itself ([`ConstructError::BadSide`], as for [`Gluing`]), a
    /// way k ≥ 6 ([`ConstructError::BadWay`]); then a sew the kernel refuses. O(tets + pairs).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::ambiguity::construct::{ConstructError, FaceGluing};
    ///
    /// let two = FaceGluing { tets: 2, pairs: vec![[0, 4, 0]] };
    /// let map = two.build().unwrap();
    /// assert_eq!(map.components().len(), 1);
    /// assert_eq!(map.boundary_darts().count(), 48 - 12);
    /// let bad = FaceGluing { tets: 2, pairs: vec![[0, 8, 0]] };
    /// assert!(matches!(bad.build(), Err(ConstructError::BadSide { side: 8, sides: 8 })));
    /// let itself = FaceGluing { tets: 1, pairs: vec![[0, 0, 1]] };
    /// assert!(matches!(itself.build(), Err(ConstructError::BadSide { side: 0, sides: 4 })));
    /// ```
    pub fn build(&self) -> Result<GMap<3>, ConstructError> {
        let n = self.tets as u32;
        let tets: Vec<[u32; 4]> = (0..n).map(|t| [4 * t, 4 * t + 1, 4 * t + 2, 4 * t + 3]).collect();
        let (mut map, _) = GMap::<3>::from_tets(4 * n as usize, &tets)?;
        check_pairs(&self.pairs, 4 * self.tets as usize, 6)?;
        for &[a, b, k] in &self.pairs {
            map.sew::<3>(DartId(6 * a as u32), DartId(6 * b as u32 + k as u32))?;
        }
        Ok(map)
    }
}

/// Checks glued pairs `[a, b, way]` over `sides` sides before anything is sewn: each side index
/// below `sides` and used at most once over all pairs (so never glued to itself), each way below
/// `ways`. The first fault in pair order, a before b, is named. O(sides + pairs).
fn check_pairs(pairs: &[[u16; 3]], sides: usize, ways: u16) -> Result<(), ConstructError> {
    let mut used = vec![false; sides];
    for (pair, &[a, b, way]) in pairs.iter().enumerate() {
        for side in [a, b] {
            let slot = used.get_mut(side as usize).ok_or(ConstructError::BadSide { side, sides })?;
            if *slot {
                return Err(ConstructError::BadSide { side, sides });
            }
            *slot = true;
        }
        if way >= ways {
            return Err(ConstructError::BadWay { pair, way, ways });
        }
    }
    Ok(())
}

/// Every gluing of the faces of 1..=`max_tets` tets with at most `max_pairs` glued pairs, in
/// the six ways each. Bounded: for 2 tets and 2 pairs, about eight thousand.
///
/// # Examples
///
/// ```
/// use topomech::ambiguity::construct::face_gluings;
///
/// // One tet: no pair, or one of the C(4, 2) = 6 pairs of faces glued in one of six ways.
/// let all = face_gluings(1, 1);
/// assert_eq!(all.len(), 1 + 6 * 6);
/// assert!(all.iter().all(|g| g.tets == 1 && g.pairs.len() <= 1));
/// ```
pub fn face_gluings(max_tets: u8, max_pairs: usize) -> Vec<FaceGluing> {
    let mut out = Vec::new();
    for tets in 1..=max_tets {
        let mut matchings = Vec::new();
        matchings_of(&mut vec![false; 4 * tets as usize], &mut Vec::new(), &mut matchings);
        for pairs in matchings.into_iter().filter(|m| m.len() <= max_pairs) {
            let ways = 6usize.pow(pairs.len() as u32);
            for code in 0..ways {
                let mut c = code;
                let pairs = pairs
                    .iter()
                    .map(|&(a, b)| {
                        let k = (c % 6) as u16;
                        c /= 6;
                        [a, b, k]
                    })
                    .collect();
                out.push(FaceGluing { tets, pairs });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_and_klein_bottle_words_build_closed_surfaces() {
        let torus = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 0]] };
        let klein = Gluing { sides: vec![4], pairs: vec![[0, 2, 0], [1, 3, 1]] };
        assert_eq!(torus.word(), "(a b a' b')");
        for (g, orientable) in [(&torus, true), (&klein, false)] {
            let map = g.build().expect("valid gluing");
            assert!(map.validate().is_ok());
            assert_eq!(map.count_cells().0, vec![1, 2, 1]);
            assert_eq!(map.is_orientable(), orientable);
            assert_eq!(map.boundary_darts().count(), 0);
        }
    }

    #[test]
    fn gluing_a_side_twice_is_refused() {
        let bad = Gluing { sides: vec![3], pairs: vec![[0, 1, 0], [1, 2, 0]] };
        assert!(matches!(bad.build(), Err(ConstructError::BadSide { side: 1, .. })));
    }

    #[test]
    fn enumeration_counts_match_the_closed_forms() {
        // One 2-gon: matchings of 2 sides are {} and {01} with two directions: 3 gluings; the
        // partitions of ≤ 2 into parts ≤ 2 are (1), (2), (1 1): 1 + 3 + 3 = 7 gluings.
        assert_eq!(gluings(2, 2).len(), 7);
    }

    /// `combinations4(n)` lists the C(n, 4) strictly increasing quadruples of 0..n, in
    /// lexicographic order (hence each once).
    #[test]
    fn combinations4_lists_each_increasing_quadruple_once() {
        for n in 0..9u32 {
            let all = combinations4(n);
            let choose4 = (0..4).map(|i| n.saturating_sub(i)).product::<u32>() / 24;
            assert_eq!(all.len() as u32, choose4, "n = {n}");
            assert!(all.iter().all(|q| q.windows(2).all(|w| w[0] < w[1]) && q[3] < n), "n = {n}");
            assert!(all.windows(2).all(|w| w[0] < w[1]), "n = {n}");
        }
    }

    /// A glued pair matches two triangles in one of six ways, k in 0..6: k = 6 is refused even
    /// when both faces exist (rather than sewing a dart of another face).
    #[test]
    fn a_face_gluing_way_out_of_range_is_refused() {
        assert!(FaceGluing { tets: 2, pairs: vec![[0, 4, 5]] }.build().is_ok());
        let bad = FaceGluing { tets: 2, pairs: vec![[0, 4, 6]] };
        assert_eq!(bad.build().unwrap_err(), ConstructError::BadWay { pair: 0, way: 6, ways: 6 });
    }

    #[test]
    fn a_cut_complex_dissociates_the_named_face() {
        let c = CutComplex { points: 5, tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]], cuts: vec![[0, 1]] };
        let map = c.build().expect("valid complex");
        assert!(glued_faces(&map).is_empty());
        assert_eq!(map.count_cells().0, vec![8, 12, 8, 2]);
        let again = CutComplex { cuts: vec![[0, 1], [0, 1]], ..c };
        assert!(matches!(again.build(), Err(ConstructError::NoSharedFace(0, 1))));
    }
}

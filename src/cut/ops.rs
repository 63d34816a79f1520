//! One generator of cut sequences for the proptest suite, the `cuts` fuzz target and the corpus
//! replay test (STYLE §9): an [`Op`] enum, a byte decoder ([`decode`]), and a [`Harness`] that
//! applies each op to a [`Body`] and to an [`Oracle`] that never looks at the map, then checks
//! every law ([`Harness::check`]).
//!
//! ```text
//!   bytes ──decode──▶ Scenario { k, seed, ops } ──Harness::new(jittered Kuhn cube k)──▶
//!        for op: Harness::apply(op)  (body op + oracle op + Projection::update)
//!                Harness::check()    validate, conservation, totals, union-find counts,
//!                                    components, incremental ≡ fresh projection
//! ```
//!
//! The oracle is a union-find over (tet, corner), (tet, edge) and tets built from the tet list
//! and the set of dissociated or removed faces only. Ops address glued faces and live tets by
//! position among what the oracle offers (modulo their number), so every byte string decodes to a
//! meaningful sequence.

use std::collections::{HashMap, HashSet};

use crate::generate::{kuhn_cube, SplitMix64};
use crate::mechanics::{check_conservation, Body, Material, Projection, TouchedCells, Vec3};
use crate::{CellId, DartId};

use super::{CutError, Plane};

/// The six edges of a tet as local corner pairs.
pub const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Gravity of the projections the harness compares.
pub const G: Vec3 = [0.0, 0.0, -9.81];

/// The material of the harness's bodies.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::material;
///
/// let m = material();
/// assert!(m.density > 0.0 && m.young > 0.0);
/// assert_eq!(m, material());
/// ```
pub fn material() -> Material {
    Material { density: 1.7, young: 900.0, damping: 0.002, viscosity: 0.5 }
}

/// Union-find with path halving (the oracle's engine).
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::Uf;
///
/// let mut uf = Uf::new(4);
/// uf.union(0, 2);
/// uf.union(1, 3);
/// assert_eq!(uf.find(2), uf.find(0));
/// assert_ne!(uf.find(0), uf.find(3));
/// ```
#[derive(Clone, Debug)]
pub struct Uf(Vec<usize>);

impl Uf {
    /// n singletons. O(n).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::Uf;
    ///
    /// let mut uf = Uf::new(4);
    /// assert_ne!(uf.find(0), uf.find(1));
    /// uf.union(0, 1);
    /// assert_eq!(uf.find(0), uf.find(1));
    /// ```
    pub fn new(n: usize) -> Self {
        Uf((0..n).collect())
    }
    /// The representative of x. O(α(n)) amortised.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::Uf;
    ///
    /// let mut uf = Uf::new(3);
    /// assert_eq!(uf.find(2), 2); // a singleton is its own representative
    /// uf.union(2, 0);
    /// assert_eq!(uf.find(2), uf.find(0));
    /// ```
    pub fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] != x {
            self.0[x] = self.0[self.0[x]];
            x = self.0[x];
        }
        x
    }
    /// Joins the classes of a and b. O(α(n)) amortised.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::Uf;
    ///
    /// let mut uf = Uf::new(5);
    /// uf.union(0, 1);
    /// uf.union(3, 1);
    /// assert_eq!(uf.find(3), uf.find(0));
    /// assert_ne!(uf.find(4), uf.find(0));
    /// ```
    pub fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        self.0[a] = b;
    }
}

/// A glued inner face: its sorted points and the two (tet, local face) sharing it.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{face_points, jittered_cube, Glued, Oracle};
///
/// let (points, tets) = jittered_cube(1, 0);
/// let oracle = Oracle::new(points, tets.clone());
/// let (triple, sides): Glued = oracle.glued()[0];
/// for (t, f) in sides {
///     assert_eq!(face_points(&tets[t], f), triple); // both tets name the same face
/// }
/// ```
pub type Glued = ([u32; 3], [(usize, usize); 2]);

/// The cut mesh as the tet list sees it.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{jittered_cube, Oracle};
///
/// let (points, tets) = jittered_cube(1, 0);
/// let oracle = Oracle::new(points, tets);
/// assert!(oracle.alive.iter().all(|&a| a) && oracle.cut.is_empty());
/// assert_eq!(oracle.inner.len(), 6); // the six inner faces of the Kuhn cube
/// ```
#[derive(Clone, Debug)]
pub struct Oracle {
    /// Input points.
    pub points: Vec<Vec3>,
    /// Input tets (tet t = volume id t, darts 24t..24t+24).
    pub tets: Vec<[u32; 4]>,
    /// Whether tet t is still there.
    pub alive: Vec<bool>,
    /// Sorted point triple → the two (tet, local face) that share it.
    pub inner: HashMap<[u32; 3], [(usize, usize); 2]>,
    /// Triples dissociated so far.
    pub cut: HashSet<[u32; 3]>,
}

/// Points of face f of a tet (the face opposite corner f), sorted. O(1).
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::face_points;
///
/// assert_eq!(face_points(&[7, 3, 5, 1], 0), [1, 3, 5]); // opposite corner 0 (point 7), sorted
/// assert_eq!(face_points(&[7, 3, 5, 1], 3), [3, 5, 7]);
/// ```
pub fn face_points(tet: &[u32; 4], f: usize) -> [u32; 3] {
    let mut p = [0u32; 3];
    let mut k = 0;
    for (c, &v) in tet.iter().enumerate() {
        if c != f {
            p[k] = v;
            k += 1;
        }
    }
    p.sort_unstable();
    p
}

impl Oracle {
    /// The uncut mesh. O(T).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Oracle};
    ///
    /// let (points, tets) = jittered_cube(1, 0);
    /// let oracle = Oracle::new(points, tets);
    /// assert_eq!(oracle.inner.len(), 6); // the Kuhn cube's 6 tets share 6 inner faces
    /// assert!(oracle.alive.iter().all(|&a| a) && oracle.cut.is_empty());
    /// ```
    pub fn new(points: Vec<Vec3>, tets: Vec<[u32; 4]>) -> Self {
        let mut seen: HashMap<[u32; 3], (usize, usize)> = HashMap::new();
        let mut inner = HashMap::new();
        for (t, tet) in tets.iter().enumerate() {
            for f in 0..4 {
                let key = face_points(tet, f);
                if let Some(first) = seen.remove(&key) {
                    inner.insert(key, [first, (t, f)]);
                } else {
                    seen.insert(key, (t, f));
                }
            }
        }
        let alive = vec![true; tets.len()];
        Oracle { points, tets, alive, inner, cut: HashSet::new() }
    }

    /// Inner faces still glued (both tets alive, not dissociated), sorted for determinism.
    /// O(F log F).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Oracle};
    ///
    /// let (points, tets) = jittered_cube(1, 0);
    /// let mut oracle = Oracle::new(points, tets);
    /// let first = oracle.glued()[0].0;
    /// oracle.cut.insert(first);
    /// assert_eq!(oracle.glued().len(), 5);
    /// ```
    pub fn glued(&self) -> Vec<Glued> {
        let mut v: Vec<_> = self
            .inner
            .iter()
            .filter(|(k, [(a, _), (b, _)])| self.alive[*a] && self.alive[*b] && !self.cut.contains(*k))
            .map(|(k, v)| (*k, *v))
            .collect();
        v.sort_unstable();
        v
    }

    /// Which face triple the face (t, f) is. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{face_points, jittered_cube, Oracle};
    ///
    /// let (points, tets) = jittered_cube(1, 0);
    /// let oracle = Oracle::new(points, tets.clone());
    /// assert_eq!(oracle.triple(2, 1), face_points(&tets[2], 1));
    /// ```
    pub fn triple(&self, t: usize, f: usize) -> [u32; 3] {
        face_points(&self.tets[t], f)
    }

    /// Expected [V, E, F, T], boundary faces, components. O(T α(T)).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Oracle};
    ///
    /// let (points, tets) = jittered_cube(1, 0);
    /// let mut oracle = Oracle::new(points, tets);
    /// let ([v, e, f, t], boundary, comps) = oracle.counts();
    /// assert_eq!(v as i64 - e as i64 + f as i64 - t as i64, 1); // a ball: χ = 1
    /// assert_eq!((v, t, boundary, comps), (8, 6, 12, 1));
    /// oracle.cut.extend(oracle.glued().iter().map(|g| g.0)); // dissociate every inner face
    /// assert_eq!(oracle.counts(), ([24, 36, 24, 6], 24, 6));
    /// ```
    pub fn counts(&self) -> ([usize; 4], usize, usize) {
        let n = self.tets.len();
        let (mut uv, mut ue, mut ut) = (Uf::new(4 * n), Uf::new(6 * n), Uf::new(n));
        let glued = self.glued();
        for (key, [(a, _), (b, _)]) in &glued {
            ut.union(*a, *b);
            for &p in key {
                let ca =
                    self.tets[*a].iter().position(|&x| x == p).expect("a glued face's points are corners of both tets");
                let cb =
                    self.tets[*b].iter().position(|&x| x == p).expect("a glued face's points are corners of both tets");
                uv.union(4 * a + ca, 4 * b + cb);
            }
            for (ea, &(i, j)) in EDGES.iter().enumerate() {
                let pa = sorted2(self.tets[*a][i], self.tets[*a][j]);
                if !key.contains(&pa[0]) || !key.contains(&pa[1]) {
                    continue;
                }
                let eb = EDGES
                    .iter()
                    .position(|&(k, l)| sorted2(self.tets[*b][k], self.tets[*b][l]) == pa)
                    .expect("a glued face's edges are edges of both tets");
                ue.union(6 * a + ea, 6 * b + eb);
            }
        }
        let live: Vec<usize> = (0..n).filter(|&t| self.alive[t]).collect();
        let classes = |uf: &mut Uf, per: usize| {
            let mut roots: Vec<usize> = live.iter().flat_map(|&t| (0..per).map(move |k| per * t + k)).collect();
            let mut r: Vec<usize> = roots.drain(..).map(|x| uf.find(x)).collect();
            r.sort_unstable();
            r.dedup();
            r.len()
        };
        let v = classes(&mut uv, 4);
        let e = classes(&mut ue, 6);
        let comps = classes(&mut ut, 1);
        let t = live.len();
        ([v, e, 4 * t - glued.len(), t], 4 * t - 2 * glued.len(), comps)
    }

    /// Centroid of tet t, rounded: the mean over its sorted vertices (the harness places its
    /// planes near it; which side a tet is on is [`Self::positive`]'s exact decision). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::Oracle;
    ///
    /// let points = vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]];
    /// let oracle = Oracle::new(points, vec![[0, 1, 2, 3]]);
    /// assert_eq!(oracle.centroid(0), [1.0, 1.0, 1.0]);
    /// ```
    pub fn centroid(&self, t: usize) -> Vec3 {
        let mut ids = self.tets[t];
        ids.sort_unstable();
        let mut c = [0.0; 3];
        for v in ids {
            for (c, p) in c.iter_mut().zip(self.points[v as usize]) {
                *c += p / 4.0;
            }
        }
        c
    }

    /// Whether tet t lies strictly on the positive side of `plane` by the rule the cut module
    /// documents: the exact sign of Σ (corner − point) · normal over its four corners, i.e. its
    /// exact centroid's side (finding 221: no rounded centroid). O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::Oracle;
    /// use topomech::cut::Plane;
    ///
    /// let points = vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]];
    /// let oracle = Oracle::new(points, vec![[0, 1, 2, 3]]);
    /// assert!(oracle.positive(0, &Plane { point: [0.5; 3], normal: [1.0, 0.0, 0.0] }));
    /// assert!(!oracle.positive(0, &Plane { point: [1.0; 3], normal: [1.0, 0.0, 0.0] })); // on it
    /// ```
    pub fn positive(&self, t: usize, plane: &Plane) -> bool {
        let corners = self.tets[t].map(|v| self.points[v as usize]);
        crate::exact::plane_sign(&corners, plane.point, plane.normal) == Some(std::cmp::Ordering::Greater)
    }
}

fn sorted2(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// One step of a random cut sequence; the numbers pick among what the oracle offers.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{jittered_cube, Harness, Op};
///
/// let (points, tets) = jittered_cube(1, 1);
/// let mut h = Harness::new(points, tets).unwrap();
/// h.apply(Op::Dissociate(0)).unwrap();
/// h.apply(Op::DissociateBoundary(0)).unwrap(); // refused by the body, as it must be
/// assert_eq!(h.oracle.cut.len(), 1);
/// assert!(h.check().is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// Dissociate the k-th glued face.
    Dissociate(usize),
    /// Try to dissociate a boundary face (must fail and change nothing).
    DissociateBoundary(usize),
    /// Remove the k-th live tet.
    Remove(usize),
    /// Try to remove the k-th removed tet again (must fail).
    RemoveAgain(usize),
    /// Incise along the plane through the centroid of the k-th live tet with normal n.
    Incise(usize, Vec3),
    /// Tear the vertex of the k-th live tet's corner with direction n.
    Tear(usize, Vec3),
}

/// The body, its incrementally updated projection, the oracle and the running totals.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{jittered_cube, Harness, Op};
///
/// let (points, tets) = jittered_cube(1, 3);
/// let mut h = Harness::new(points, tets).unwrap();
/// assert!(h.stiffness > 0.0 && h.removed_stiffness == 0.0);
/// h.apply(Op::Remove(2)).unwrap();
/// assert!(h.removed_mass > 0.0 && h.removed_mass < h.mass);
/// assert!(h.check().is_ok());
/// ```
#[derive(Debug)]
pub struct Harness {
    /// The body under test.
    pub body: Body,
    /// Its projection, only ever updated incrementally.
    pub projection: Projection,
    /// The independent model of the cut mesh.
    pub oracle: Oracle,
    /// Initial Σ m_v.
    pub mass: f64,
    /// Initial Σ k_e.
    pub stiffness: f64,
    /// Σ of the removed tets' masses.
    pub removed_mass: f64,
    /// Σ of the removed tets' stiffness contributions.
    pub removed_stiffness: f64,
}

/// A copy whose projection follows the copied body ([`Projection::for_clone`]), so that it is
/// still only ever updated incrementally (a plain clone of the projection would be for the
/// original body, and its first update a rebuild).
impl Clone for Harness {
    fn clone(&self) -> Self {
        let body = self.body.clone();
        let projection = match self.projection.for_clone(&self.body, &body) {
            Some(p) => p,
            None => Projection::build_raw(&body, self.projection.system.gravity),
        };
        Harness {
            body,
            projection,
            oracle: self.oracle.clone(),
            mass: self.mass,
            stiffness: self.stiffness,
            removed_mass: self.removed_mass,
            removed_stiffness: self.removed_stiffness,
        }
    }
}

/// Σ k_e over the live edges of `body`. O(darts).
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{jittered_cube, total_stiffness, Harness};
///
/// let (points, tets) = jittered_cube(1, 3);
/// let h = Harness::new(points, tets).unwrap();
/// assert!(total_stiffness(&h.body) > 0.0);
/// assert_eq!(total_stiffness(&h.body), h.stiffness);
/// ```
pub fn total_stiffness(body: &Body) -> f64 {
    let map = body.map();
    map.one_dart_per_cell(1).into_iter().map(|d| body.attrs().edge_stiffness(map.cell_id(1, d))).sum()
}

fn rel_close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-11 * a.abs().max(b.abs()).max(1e-300)
}

impl Harness {
    /// The body of `tets` over `points` with [`material`], its projection and the oracle.
    /// O(T log T).
    ///
    /// # Errors
    /// The body could not be built (degenerate tet, non-finite point, bad mesh).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Harness};
    ///
    /// let (points, tets) = jittered_cube(1, 3);
    /// let h = Harness::new(points.clone(), tets).unwrap();
    /// assert_eq!(h.removed_mass, 0.0);
    /// assert!(h.mass > 0.0 && h.check().is_ok());
    /// assert!(Harness::new(points, vec![[0, 0, 1, 2]]).is_err()); // degenerate tet
    /// ```
    pub fn new(points: Vec<Vec3>, tets: Vec<[u32; 4]>) -> Result<Self, crate::mechanics::ModelError> {
        let (body, _) = Body::from_tets(&points, &tets, material())?;
        let projection = Projection::build_raw(&body, G);
        let mass = body.total_vertex_mass();
        let stiffness = total_stiffness(&body);
        let oracle = Oracle::new(points, tets);
        Ok(Harness { body, projection, oracle, mass, stiffness, removed_mass: 0.0, removed_stiffness: 0.0 })
    }

    /// Applies `op` to body and oracle, then updates the projection incrementally. Refused ops
    /// (boundary face, removed tet) must fail with the right [`CutError`] and change nothing.
    /// O(op + T) for the oracle's bookkeeping.
    ///
    /// # Errors
    /// A description of what went wrong (an operation failed or misbehaved).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Harness, Op};
    ///
    /// let (points, tets) = jittered_cube(1, 3);
    /// let mut h = Harness::new(points, tets).unwrap();
    /// h.apply(Op::Remove(0)).unwrap();
    /// assert!(h.removed_mass > 0.0);
    /// h.apply(Op::RemoveAgain(0)).unwrap(); // refused by the body, as it must be
    /// assert_eq!(h.oracle.alive.iter().filter(|&&a| a).count(), 5);
    /// ```
    pub fn apply(&mut self, op: Op) -> Result<(), String> {
        let mut touched = TouchedCells::default();
        match op {
            Op::Dissociate(k) => self.apply_dissociate(k, &mut touched)?,
            Op::DissociateBoundary(k) => self.apply_dissociate_boundary(k)?,
            Op::Remove(k) => self.apply_remove(k, &mut touched)?,
            Op::RemoveAgain(k) => self.apply_remove_again(k)?,
            Op::Incise(k, n) => self.apply_incise(k, n, &mut touched)?,
            Op::Tear(k, n) => self.apply_tear(k, n, &mut touched)?,
        }
        // The operations' own lists must always be taken incrementally: a rebuild here would
        // make the "incremental ≡ fresh" law of `check` hold trivially.
        if !self.projection.update(&self.body, &touched) {
            return Err(format!("{op:?}: the operation's touched cells were not taken incrementally"));
        }
        Ok(())
    }

    /// [`Op::Dissociate`]: the k-th glued face (mod their number).
    fn apply_dissociate(&mut self, k: usize, touched: &mut TouchedCells) -> Result<(), String> {
        let glued = self.oracle.glued();
        if glued.is_empty() {
            return Ok(());
        }
        let (key, [(t, f), _]) = glued[k % glued.len()];
        let d = DartId((24 * t + 6 * f) as u32);
        let dis = super::dissociate_face(&mut self.body, d).map_err(|e| e.to_string())?;
        self.oracle.cut.insert(key);
        touched.extend(&dis.touched);
        Ok(())
    }

    /// [`Op::DissociateBoundary`]: the k-th boundary face must be refused, the body unchanged.
    fn apply_dissociate_boundary(&mut self, k: usize) -> Result<(), String> {
        let live: Vec<(usize, usize)> = (0..self.oracle.tets.len())
            .filter(|&t| self.oracle.alive[t])
            .flat_map(|t| (0..4).map(move |f| (t, f)))
            .filter(|&(t, f)| {
                let key = self.oracle.triple(t, f);
                !self.oracle.glued().iter().any(|(k, _)| *k == key)
            })
            .collect();
        if live.is_empty() {
            return Ok(());
        }
        let (t, f) = live[k % live.len()];
        let before = (self.body.version(), self.body.map().count_cells());
        match super::dissociate_face(&mut self.body, DartId((24 * t + 6 * f) as u32)) {
            Err(CutError::BoundaryFace { .. }) => {}
            other => return Err(format!("boundary face ({t}, {f}): expected BoundaryFace, got {other:?}")),
        }
        if before != (self.body.version(), self.body.map().count_cells()) {
            return Err("a refused dissociation changed the body".into());
        }
        Ok(())
    }

    /// [`Op::Remove`]: the k-th live tet (none when one is left).
    fn apply_remove(&mut self, k: usize, touched: &mut TouchedCells) -> Result<(), String> {
        let live: Vec<usize> = (0..self.oracle.tets.len()).filter(|&t| self.oracle.alive[t]).collect();
        if live.len() <= 1 {
            return Ok(());
        }
        let t = live[k % live.len()];
        let r = super::remove_volume(&mut self.body, CellId(t as u32)).map_err(|e| e.to_string())?;
        self.oracle.alive[t] = false;
        self.removed_mass += r.removed_mass;
        self.removed_stiffness += r.removed_stiffness;
        touched.extend(&r.touched);
        Ok(())
    }

    /// [`Op::RemoveAgain`]: the k-th removed tet must be refused, the body unchanged.
    fn apply_remove_again(&mut self, k: usize) -> Result<(), String> {
        let dead: Vec<usize> = (0..self.oracle.tets.len()).filter(|&t| !self.oracle.alive[t]).collect();
        if dead.is_empty() {
            return Ok(());
        }
        let t = dead[k % dead.len()];
        let version = self.body.version();
        match super::remove_volume(&mut self.body, CellId(t as u32)) {
            Err(CutError::NoSuchVolume(v)) if v == CellId(t as u32) => {}
            other => return Err(format!("removing tet {t} again: got {other:?}")),
        }
        if version != self.body.version() {
            return Err("a refused removal changed the body".into());
        }
        Ok(())
    }

    /// [`Op::Incise`]: a plane of normal n near the k-th live tet's centroid; cuts what the oracle expects.
    fn apply_incise(&mut self, k: usize, n: Vec3, touched: &mut TouchedCells) -> Result<(), String> {
        let live: Vec<usize> = (0..self.oracle.tets.len()).filter(|&t| self.oracle.alive[t]).collect();
        // Off the centroid: a centroid exactly on the plane is decided by rounding.
        let c = self.oracle.centroid(live[k % live.len()]);
        let point = [c[0] + 0.0137 * n[0], c[1] + 0.0137 * n[1], c[2] + 0.0137 * n[2]];
        let plane = Plane { point, normal: n };
        let inc = super::incise_plane(&mut self.body, &plane).map_err(|e| e.to_string())?;
        let mut expected = 0;
        for (key, [(a, _), (b, _)]) in self.oracle.glued() {
            if self.oracle.positive(a, &plane) != self.oracle.positive(b, &plane) {
                self.oracle.cut.insert(key);
                expected += 1;
            }
        }
        if inc.cut_faces() != expected {
            return Err(format!("incision cut {} faces, oracle expects {expected}", inc.cut_faces()));
        }
        touched.extend(&inc.touched);
        Ok(())
    }

    /// [`Op::Tear`]: a tear at a vertex of the k-th live tet, each face dissociated once.
    fn apply_tear(&mut self, k: usize, n: Vec3, touched: &mut TouchedCells) -> Result<(), String> {
        let live: Vec<usize> = (0..self.oracle.tets.len()).filter(|&t| self.oracle.alive[t]).collect();
        let t = live[k % live.len()];
        let d = DartId((24 * t + (k / 7) % 24) as u32);
        let v = self.body.map().vertex_id(d);
        let tear = super::tear_vertex(&mut self.body, v, n, Some(d)).map_err(|e| e.to_string())?;
        for dis in &tear.dissociations {
            let x = dis.dart.index();
            let key = self.oracle.triple(x / 24, (x % 24) / 6);
            if !self.oracle.cut.insert(key) {
                return Err(format!("tear dissociated face {key:?} twice"));
            }
        }
        touched.extend(&tear.touched);
        Ok(())
    }

    /// Every law after a step: `validate()`, the conservation laws, totals = initial − removed,
    /// cell counts (by id allocator and by traversal), boundary faces and components against the
    /// oracle, component masses, incremental projection ≡ fresh projection, spring darts on
    /// their edges. O(darts + T log T).
    ///
    /// # Errors
    /// A description of the first law found broken.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::cut::ops::{jittered_cube, Harness, Op};
    ///
    /// let (points, tets) = jittered_cube(1, 3);
    /// let mut h = Harness::new(points, tets).unwrap();
    /// h.apply(Op::Dissociate(0)).unwrap();
    /// assert_eq!(h.check(), Ok(()));
    /// h.removed_mass += 1.0; // the bookkeeping no longer matches the body
    /// assert!(h.check().unwrap_err().contains("mass"));
    /// ```
    pub fn check(&self) -> Result<(), String> {
        let map = self.body.map();
        map.validate().map_err(|e| format!("validate: {e}"))?;
        check_conservation(map, self.body.attrs()).map_err(|e| format!("conservation: {e}"))?;
        let (cells, boundary, comps) = self.oracle.counts();
        let got = map.count_cells().0;
        if got != cells.to_vec() {
            return Err(format!("cells {got:?}, union-find oracle {cells:?}"));
        }
        if map.count_cells_by_traversal().0 != got {
            return Err("cell counts by id allocator and by traversal differ".into());
        }
        if map.boundary_cell_count() != boundary {
            return Err(format!("boundary faces {} vs oracle {boundary}", map.boundary_cell_count()));
        }
        let parts = super::components(&self.body);
        if parts.len() != comps {
            return Err(format!("components {} vs oracle {comps}", parts.len()));
        }
        let mass = self.body.total_vertex_mass();
        if !rel_close(mass, self.mass - self.removed_mass) {
            return Err(format!("mass {mass} != {} - {}", self.mass, self.removed_mass));
        }
        let parts_mass: f64 = parts.iter().map(|c| c.mass).sum();
        if !rel_close(parts_mass, mass) {
            return Err(format!("component masses sum to {parts_mass}, body {mass}"));
        }
        let k = total_stiffness(&self.body);
        if !rel_close(k, self.stiffness - self.removed_stiffness) {
            return Err(format!("stiffness {k} != {} - {}", self.stiffness, self.removed_stiffness));
        }
        let fresh = Projection::build_raw(&self.body, G);
        self.projection.equivalent(&fresh).map_err(|e| format!("incremental projection: {e}"))?;
        if !self.projection.is_current(&self.body) {
            return Err("projection not current after update".into());
        }
        for s in 0..self.projection.system.springs() {
            let (d, e) = (self.projection.dart_of_spring(s), self.projection.edge_of_spring(s));
            if !map.contains(d) || map.cell_id(1, d) != e {
                return Err(format!("spring {s}: dart {d} is not on edge {e}"));
            }
        }
        Ok(())
    }
}

/// A decoded byte string: a jittered Kuhn cube of side `k` and the ops to run on it.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{decode, Op, Scenario};
///
/// let s: Scenario = decode(&[0, 3, 9, 1, 0, 0]);
/// assert_eq!((s.k, s.seed), (1, 3));
/// assert_eq!(s.ops, vec![Op::RemoveAgain(1)]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Kuhn cube resolution (1 or 2).
    pub k: usize,
    /// Seed of the point jitter.
    pub seed: u64,
    /// The cut sequence.
    pub ops: Vec<Op>,
}

/// Bytes per op in the encoding of [`decode`].
pub const OP_BYTES: usize = 4;
/// Ops decoded at most (longer inputs are cut).
pub const MAX_OPS: usize = 24;

/// Decodes bytes into a [`Scenario`]; every byte string is valid. Byte 0 picks k = 1 + (b & 1),
/// byte 1 the jitter seed; then each group of [`OP_BYTES`] bytes [tag, lo, hi, dir] is one op:
/// tag mod 13 picks Dissociate (0–5), DissociateBoundary (6), Remove (7–8), RemoveAgain (9),
/// Incise (10), Tear (11–12); lo + 256·hi is the index; dir packs a direction (3 bits x,
/// 3 bits y, 2 bits z ∈ {0.1, 0.4, 0.7, 1}). A trailing partial group is ignored. O(len).
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{decode, Op};
///
/// let s = decode(&[1, 9, 7, 2, 0, 0, 13, 1, 0, 0, 5]); // the trailing byte is a partial group
/// assert_eq!((s.k, s.seed), (2, 9));
/// assert_eq!(s.ops, vec![Op::Remove(2), Op::Dissociate(1)]);
/// assert_eq!(decode(&[]).ops, vec![]);
/// ```
pub fn decode(bytes: &[u8]) -> Scenario {
    let k = 1 + (bytes.first().copied().unwrap_or(0) & 1) as usize;
    let seed = bytes.get(1).copied().unwrap_or(0) as u64;
    let body = bytes.get(2..).unwrap_or(&[]);
    let ops = body.chunks_exact(OP_BYTES).take(MAX_OPS).map(|c| decode_op([c[0], c[1], c[2], c[3]])).collect();
    Scenario { k, seed, ops }
}

fn decode_op([tag, lo, hi, dir]: [u8; 4]) -> Op {
    let i = lo as usize | (hi as usize) << 8;
    let unit = |bits: u8| (bits as f64 - 3.5) / 3.5;
    let n: Vec3 = [unit(dir & 7), unit((dir >> 3) & 7), (1 + 3 * (dir >> 6)) as f64 / 10.0];
    match tag % 13 {
        0..=5 => Op::Dissociate(i),
        6 => Op::DissociateBoundary(i),
        7 | 8 => Op::Remove(i),
        9 => Op::RemoveAgain(i),
        10 => Op::Incise(i, n),
        _ => Op::Tear(i, n),
    }
}

/// The Kuhn cube of side k with every point moved by up to ±0.1 per coordinate (seeded), so no
/// centroid falls exactly on a cutting plane. O(k³).
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::jittered_cube;
/// use topomech::generate::kuhn_cube;
///
/// let ((points, tets), (exact, exact_tets)) = (jittered_cube(1, 5), kuhn_cube(1));
/// assert_eq!(tets, exact_tets);
/// let moved = points.iter().zip(&exact).all(|(p, q)| (0..3).all(|c| (p[c] - q[c]).abs() <= 0.1));
/// assert!(moved && points != exact);
/// ```
pub fn jittered_cube(k: usize, seed: u64) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let (mut points, tets) = kuhn_cube(k);
    let mut rng = SplitMix64(seed);
    for p in &mut points {
        for c in p.iter_mut() {
            *c += (rng.below(1000) as f64 / 1000.0 - 0.5) * 0.2;
        }
    }
    (points, tets)
}

/// Runs `ops` on `harness`, checking every law before the first op and after each one.
/// O(ops · (darts + T log T)).
///
/// # Errors
/// The step and a description of the first failure.
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::{jittered_cube, run_ops, Harness, Op};
///
/// let (points, tets) = jittered_cube(1, 2);
/// let mut h = Harness::new(points, tets).unwrap();
/// let ops = [Op::Dissociate(3), Op::DissociateBoundary(0), Op::Incise(1, [0.0, 0.6, 0.8])];
/// assert_eq!(run_ops(&mut h, &ops), Ok(()));
/// ```
pub fn run_ops(harness: &mut Harness, ops: &[Op]) -> Result<(), String> {
    harness.check().map_err(|e| format!("before any op: {e}"))?;
    for (i, &op) in ops.iter().enumerate() {
        harness.apply(op).map_err(|e| format!("step {i} {op:?}: {e}"))?;
        harness.check().map_err(|e| format!("after step {i} {op:?}: {e}"))?;
    }
    Ok(())
}

/// Decodes `bytes` and runs the scenario on its jittered Kuhn cube: the whole fuzz target.
///
/// # Errors
/// As [`run_ops`].
///
/// # Examples
///
/// ```
/// use topomech::cut::ops::run_bytes;
///
/// assert_eq!(run_bytes(&[]), Ok(()));
/// // k = 1, seed 4: dissociate glued face 2, then remove live tet 0.
/// assert_eq!(run_bytes(&[0, 4, 0, 2, 0, 0, 7, 0, 0, 0]), Ok(()));
/// ```
pub fn run_bytes(bytes: &[u8]) -> Result<(), String> {
    let s = decode(bytes);
    let (points, tets) = jittered_cube(s.k, s.seed);
    let mut h = Harness::new(points, tets).map_err(|e| format!("building the cube: {e}"))?;
    run_ops(&mut h, &s.ops)
}

//! Running a vector's operations on a [`Body`]: generation records what happens, replay compares
//! it with what the vector says. Both share [`Runner`], so the two cannot drift apart.

use std::path::{Component, Path};

use crate::cut::ops::{self as shared, Oracle};
use crate::cut::{self, CutError, Plane};
use crate::generate::kuhn_cube;
use crate::load;
use crate::mechanics::{check_conservation, Body, Vec3};
use crate::{CellId, DartId};

use super::schema::{Expect, MaterialSpec, MeshSpec, Op, Refusal, Step, Vector};
use super::{check_name, ConformanceError, DETAIL_MAX_VERTICES, FORMAT, TOLERANCE, VERSION};

/// How a [`Recipe`] gives its operations.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, replay, MeshSpec, Ops, Recipe};
///
/// let recipe = Recipe {
///     name: "shared".into(), description: "fuzz bytes".into(), mesh: MeshSpec::KuhnCube { k: 1 },
///     material: topomech::mechanics::Material::default().into(),
///     ops: Ops::Shared(vec![0, 0, 7, 0, 0, 0]), // one op: remove live tet 0
/// };
/// let v = generate(&recipe).unwrap();
/// assert_eq!(v.steps.len(), 1);
/// assert_eq!(v.steps[0].expect.cells[3], 5);
/// replay(&v).unwrap();
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum Ops {
    /// These operations, in order.
    Listed(Vec<Op>),
    /// The cut generator shared with the proptest suite and the fuzz target
    /// ([`decode`](crate::cut::ops::decode) of these bytes; its mesh bytes are ignored): each
    /// decoded op is translated to an [`Op`] against the current state, as
    /// [`Harness::apply`](crate::cut::ops::Harness::apply) chooses it; ops that have nothing to
    /// act on (or target an input boundary face) are skipped.
    Shared(Vec<u8>),
}

/// What [`generate`] needs: a name, a description, a mesh, a material and the operations.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, MeshSpec, Op, Ops, Recipe};
///
/// let recipe = Recipe {
///     name: "halves".into(), description: "cut the cube at z = 0.4".into(), mesh: MeshSpec::KuhnCube { k: 1 },
///     material: topomech::mechanics::Material::default().into(),
///     ops: Ops::Listed(vec![Op::Incise { point: [0.0, 0.0, 0.4], normal: [0.0, 0.0, 1.0] }]),
/// };
/// let v = generate(&recipe).unwrap();
/// assert_eq!((v.name.as_str(), v.description.as_str()), ("halves", "cut the cube at z = 0.4"));
/// assert!(!v.steps[0].expect.dissociated.is_empty());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    /// File stem: 1 to [`MAX_NAME_LEN`](super::MAX_NAME_LEN) characters of `A–Z a–z 0–9 _ - .`
    /// ([`generate_in`] refuses any other name).
    pub name: String,
    /// What the vector exercises.
    pub description: String,
    /// The input mesh.
    pub mesh: MeshSpec,
    /// The material.
    pub material: MaterialSpec,
    /// The operations.
    pub ops: Ops,
}

/// The largest Kuhn cube a vector may ask for (6·16³ tets).
const MAX_KUHN: usize = 16;

/// Smallest allowed distance of a live tet centroid from an incision plane, relative to the
/// diagonal of the bounding box of the points the input tets use (removed ones included): generation and replay refuse a plane
/// closer than this ([`ConformanceError::AmbiguousPlane`]), as rounding (or a tie rule) would
/// then decide the side of that tet.
pub const PLANE_MARGIN: f64 = 1e-6;

/// What one operation did.
struct Outcome {
    refused: Option<Refusal>,
    dissociated: Vec<[u32; 2]>,
}

/// A body under a vector's operations, with the union-find model of the cut tet list.
struct Runner {
    name: String,
    body: Body,
    oracle: Oracle,
}

/// Runs `recipe` with topomech and records the state before and after every operation. Mesh
/// files are looked up relative to the current directory (see [`generate_in`]).
///
/// Cost: O(T log T) to build, plus per step the operation and O(darts + T) to observe and check.
///
/// # Errors
/// As [`generate_in`].
///
/// # Examples
///
/// ```
/// use topomech::conformance::generate;
/// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
/// # let recipe = Recipe {
/// #     name: "one".into(),
/// #     description: "remove a tet".into(),
/// #     mesh: MeshSpec::KuhnCube { k: 1 },
/// #     material: topomech::mechanics::Material::default().into(),
/// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
/// # };
/// let v = generate(&recipe).unwrap();
/// assert_eq!((v.initial.cells, v.initial.components), ([8, 19, 18, 6], 1));
/// assert_eq!(v.steps.len(), 1);
/// assert_eq!(v.steps[0].expect.darts, 5 * 24);
/// ```
pub fn generate(recipe: &Recipe) -> Result<Vector, ConformanceError> {
    generate_in(recipe, Path::new("."))
}

/// [`generate`] with mesh files relative to `root`. The laws are checked after every step, and
/// incision planes must keep `PLANE_MARGIN` (10⁻⁶ of the diagonal of the bounding box of the
/// points the tets use) from every live centroid; a plane normal of any nonzero finite length is
/// accepted (as [`incise_plane`](crate::cut::incise_plane) accepts it). The recipe's name must be a
/// plain name and the vector produced passes [`Vector::check_fields`], so it can be replayed.
///
/// # Errors
/// [`ConformanceError::BadName`], [`ConformanceError::Mesh`], [`ConformanceError::OutsideRoot`],
/// [`ConformanceError::BadOp`], [`ConformanceError::Law`], [`ConformanceError::AmbiguousPlane`],
/// then as [`Vector::check_fields`].
///
/// ```
/// use topomech::conformance::{generate, replay, MeshSpec, Op, Ops, Recipe};
/// let recipe = Recipe {
///     name: "one".into(),
///     description: "remove the only tet".into(),
///     mesh: MeshSpec::KuhnCube { k: 1 },
///     material: topomech::mechanics::Material::default().into(),
///     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
/// };
/// let v = generate(&recipe).unwrap();
/// assert_eq!(v.steps[0].expect.cells[3], 5);
/// replay(&v).unwrap();
/// ```
pub fn generate_in(recipe: &Recipe, root: &Path) -> Result<Vector, ConformanceError> {
    check_name(&recipe.name)?;
    let mut r = Runner::new(&recipe.name, &recipe.mesh, recipe.material, root)?;
    r.check_laws(None)?;
    let initial = r.observe(Outcome { refused: None, dissociated: Vec::new() });
    let ops: Vec<Op> = match &recipe.ops {
        Ops::Listed(ops) => ops.clone(),
        Ops::Shared(bytes) => {
            let decoded = shared::decode(bytes).ops;
            let mut out = Vec::new();
            let mut steps = Vec::new();
            for op in decoded {
                let Some(op) = r.translate(op) else { continue };
                let step = out.len();
                steps.push(r.run_generating(step, &op)?);
                out.push(op);
            }
            return vector(recipe, initial, steps);
        }
    };
    let mut steps = Vec::with_capacity(ops.len());
    for (k, op) in ops.iter().enumerate() {
        steps.push(r.run_generating(k, op)?);
    }
    vector(recipe, initial, steps)
}

/// The vector of a generation, checked as replay will check it; the per-cell fields are kept only
/// up to [`DETAIL_MAX_VERTICES`] initial vertices.
fn vector(recipe: &Recipe, mut initial: Expect, mut steps: Vec<Step>) -> Result<Vector, ConformanceError> {
    if initial.cells[0] > DETAIL_MAX_VERTICES {
        for e in std::iter::once(&mut initial).chain(steps.iter_mut().map(|s| &mut s.expect)) {
            (e.vertex_masses, e.edge_stiffnesses) = (None, None);
        }
    }
    let v = Vector {
        format: FORMAT.to_string(),
        version: VERSION,
        name: recipe.name.clone(),
        description: recipe.description.clone(),
        tolerance: TOLERANCE,
        mesh: recipe.mesh.clone(),
        material: recipe.material,
        initial,
        steps,
    };
    v.check_fields()?;
    Ok(v)
}

/// Replays `v` with mesh files relative to the current directory (see [`replay_in`]).
///
/// # Errors
/// As [`replay_in`].
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, replay};
/// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
/// # let recipe = Recipe {
/// #     name: "one".into(),
/// #     description: "remove a tet".into(),
/// #     mesh: MeshSpec::KuhnCube { k: 1 },
/// #     material: topomech::mechanics::Material::default().into(),
/// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
/// # };
/// let mut v = generate(&recipe).unwrap();
/// assert!(replay(&v).is_ok());
/// v.steps[0].expect.components = 2;
/// assert!(replay(&v).is_err());
/// ```
pub fn replay(v: &Vector) -> Result<(), ConformanceError> {
    replay_in(v, Path::new("."))
}

/// Runs [`Vector::check_fields`] (the checks decoding runs: format, version, name, tolerance,
/// material, finite expectations), then rebuilds the body of `v` (mesh files relative to `root`,
/// and they must resolve inside it, symbolic links followed; `data/liver_547_v22.msh` falls back
/// to the copy compiled into topomech), compares the initial state, then applies each step and
/// compares every field of its [`Expect`] (floats to the vector's relative tolerance). Before an
/// `incise` step it checks the plane margin, as [`generate_in`] does. After every step it also
/// checks `validate()`, the conservation laws and the union-find model's counts.
///
/// Cost: O(T log T) + Σ steps (operation + O(darts + T)).
///
/// # Errors
/// The first problem: as [`Vector::check_fields`], [`ConformanceError::Mesh`],
/// [`ConformanceError::OutsideRoot`],
/// [`ConformanceError::BadOp`], [`ConformanceError::AmbiguousPlane`] (an `incise` step whose plane
/// passes within [`PLANE_MARGIN`] · diagonal of a live tet centroid: the vector does not decide
/// that tet's side, so it is refused before the step is applied, as generation refuses it),
/// [`ConformanceError::Mismatch`] (step, field, expected, got; a `refused` value is printed as
/// its JSON, `"boundary_face"`, `"removed_tet"` or `null`) or [`ConformanceError::Law`].
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, replay_in};
/// use std::path::Path;
/// # use topomech::conformance::{MeshSpec, Op, Ops, Recipe};
/// # let recipe = Recipe {
/// #     name: "one".into(),
/// #     description: "remove a tet".into(),
/// #     mesh: MeshSpec::KuhnCube { k: 1 },
/// #     material: topomech::mechanics::Material::default().into(),
/// #     ops: Ops::Listed(vec![Op::Remove { tet: 0 }]),
/// # };
/// let v = generate(&recipe).unwrap();
/// assert!(replay_in(&v, Path::new("/no/such/root")).is_ok()); // the mesh is generated, no file read
/// let mut bad = v.clone();
/// bad.tolerance = -1.0;
/// assert!(replay_in(&bad, Path::new(".")).is_err());
/// let mut foreign = v.clone();
/// foreign.version = 99; // refused in memory as in a file
/// assert!(replay_in(&foreign, Path::new(".")).is_err());
/// ```
pub fn replay_in(v: &Vector, root: &Path) -> Result<(), ConformanceError> {
    v.check_fields()?;
    let mut r = Runner::new(&v.name, &v.mesh, v.material, root)?;
    r.check_laws(None)?;
    let got = r.observe(Outcome { refused: None, dissociated: Vec::new() });
    compare(v, None, &v.initial, &got)?;
    for (k, step) in v.steps.iter().enumerate() {
        let outcome = r.run(k, &step.op)?;
        let got = r.observe(outcome);
        compare(v, Some(k), &step.expect, &got)?;
    }
    Ok(())
}

/// The first field of `want` that `got` does not match.
fn compare(v: &Vector, step: Option<usize>, want: &Expect, got: &Expect) -> Result<(), ConformanceError> {
    let fail = |field: &'static str, expected: String, got: String| ConformanceError::Mismatch {
        vector: v.name.clone(),
        step,
        field,
        expected,
        got,
    };
    // `want` is finite (`check_fields`); a non-finite `got` never matches (|x − ∞| ≤ tol · ∞).
    // Relative to the larger value; where one side is exactly 0 (an emptied body's sums), also
    // within the rounding of a sum of the vector's T input tets at its initial total s of that
    // kind, 16·T·ε·s (finding 300; a floor on every value made small ones unchecked: 311).
    let floor = |s: f64| 16.0 * input_tets(&v.mesh) as f64 * f64::EPSILON * s.abs();
    let (mass, stiffness) = (floor(v.initial.total_mass), floor(v.initial.total_stiffness));
    let close = |a: f64, b: f64, zero: f64| {
        let d = (a - b).abs();
        let relative = d <= v.tolerance * a.abs().max(b.abs());
        b.is_finite() && (relative || (v.tolerance > 0.0 && (a == 0.0 || b == 0.0) && d <= zero))
    };
    macro_rules! exact {
        ($field:ident) => {
            if want.$field != got.$field {
                return Err(fail(stringify!($field), format!("{:?}", want.$field), format!("{:?}", got.$field)));
            }
        };
    }
    // `refused` in the vector's vocabulary: its JSON value, `"boundary_face"`, `"removed_tet"`,
    // or `null` for an operation that is applied (the field absent).
    if want.refused != got.refused {
        let json = |r: &Option<Refusal>| serde_json::to_string(r).expect("a refusal serialises");
        return Err(fail("refused", json(&want.refused), json(&got.refused)));
    }
    exact!(dissociated);
    exact!(darts);
    exact!(cells);
    exact!(boundary_faces);
    exact!(components);
    exact!(euler);
    for (field, a, b, scale) in [
        ("total_mass", want.total_mass, got.total_mass, mass),
        ("total_stiffness", want.total_stiffness, got.total_stiffness, stiffness),
    ] {
        if !close(a, b, scale) {
            return Err(fail(field, format!("{a:?}"), format!("{b:?}")));
        }
    }
    let (a, b) = (&want.component_masses, &got.component_masses);
    if a.len() != b.len() || a.iter().zip(b).any(|(&x, &y)| !close(x, y, mass)) {
        return Err(fail("component_masses", format!("{a:?}"), format!("{b:?}")));
    }
    let none: &[f64] = &[];
    for (field, a, b, zero) in [
        ("vertex_masses", want.vertex_masses.as_deref(), got.vertex_masses.as_deref().unwrap_or(none), mass),
        (
            "edge_stiffnesses",
            want.edge_stiffnesses.as_deref(),
            got.edge_stiffnesses.as_deref().unwrap_or(none),
            stiffness,
        ),
    ] {
        // A per-cell field the vector does not hold is skipped; a long list is reported by its
        // length or its first differing entry, not printed whole (finding 312).
        let Some(a) = a else { continue };
        if a.len() != b.len() {
            return Err(fail(field, format!("{} entries", a.len()), format!("{} entries", b.len())));
        }
        if let Some(i) = (0..a.len()).find(|&i| !close(a[i], b[i], zero)) {
            return Err(fail(field, format!("[{i}] {:?}", a[i]), format!("[{i}] {:?}", b[i])));
        }
    }
    Ok(())
}

/// The number of input tets of a mesh spec (the file's declared count for a file). O(1).
fn input_tets(spec: &MeshSpec) -> usize {
    match spec {
        MeshSpec::Inline { tets, .. } => tets.len(),
        MeshSpec::KuhnCube { k } => 6 * k * k * k,
        MeshSpec::File { tets, .. } => *tets,
    }
}

/// Points and tets of a mesh spec.
fn mesh_of(name: &str, spec: &MeshSpec, root: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 4]>), ConformanceError> {
    let fail = |message: String| ConformanceError::Mesh { vector: name.to_string(), message };
    match spec {
        MeshSpec::Inline { points, tets } => Ok((points.clone(), tets.clone())),
        MeshSpec::KuhnCube { k } if (1..=MAX_KUHN).contains(k) => Ok(kuhn_cube(*k)),
        MeshSpec::KuhnCube { k } => Err(fail(format!("kuhn_cube k = {k} is outside 1..={MAX_KUHN}"))),
        MeshSpec::File { path, points, tets } => {
            let inside = |c: Component<'_>| matches!(c, Component::Normal(_) | Component::CurDir);
            if path.is_empty() || !Path::new(path).components().all(inside) {
                return Err(fail(format!(
                    "mesh path {path:?} must be relative to the repository root and stay inside it (no root, no '..')"
                )));
            }
            let full = root.join(path);
            let loaded = if !full.exists() && Path::new(path) == Path::new("data/liver_547_v22.msh") {
                load::load_builtin()
            } else {
                load::load_tet_map(&inside_root(name, path, root)?)
            };
            let mesh = loaded.map_err(|e| fail(e.to_string()))?.mesh;
            if (mesh.points.len(), mesh.tets.len()) != (*points, *tets) {
                return Err(fail(format!(
                    "{path} has {} points and {} tets, the vector declares {points} and {tets}",
                    mesh.points.len(),
                    mesh.tets.len()
                )));
            }
            Ok((mesh.points, mesh.tets))
        }
    }
}

/// `root/path` with every symbolic link resolved, when that lies inside `root` (also resolved).
/// A path that does not exist is reported as missing only when its deepest existing ancestor
/// lies inside `root`; nothing outside is read, so no error can echo an outside file.
fn inside_root(name: &str, path: &str, root: &Path) -> Result<std::path::PathBuf, ConformanceError> {
    let fail = |message: String| ConformanceError::Mesh { vector: name.to_string(), message };
    let outside =
        || ConformanceError::OutsideRoot { vector: name.to_string(), path: path.to_string(), root: root.to_path_buf() };
    let base = root.canonicalize().map_err(|e| fail(format!("repository root {}: {e}", root.display())))?;
    let full = root.join(path);
    match full.canonicalize() {
        Ok(resolved) if resolved.starts_with(&base) => Ok(resolved),
        Ok(_) => Err(outside()),
        Err(e) => {
            let existing = full.ancestors().skip(1).find_map(|a| a.canonicalize().ok());
            match existing {
                Some(a) if a.starts_with(&base) => Err(fail(format!("{path}: {e}"))),
                _ => Err(outside()),
            }
        }
    }
}

/// The sorted common points of two tets.
fn common(a: &[u32; 4], b: &[u32; 4]) -> Vec<u32> {
    let mut c: Vec<u32> = a.iter().copied().filter(|p| b.contains(p)).collect();
    c.sort_unstable();
    c
}

impl Runner {
    fn new(name: &str, spec: &MeshSpec, material: MaterialSpec, root: &Path) -> Result<Self, ConformanceError> {
        let (points, tets) = mesh_of(name, spec, root)?;
        let (body, _) = Body::from_tets(&points, &tets, material.into())
            .map_err(|e| ConformanceError::Mesh { vector: name.to_string(), message: e.to_string() })?;
        Ok(Runner { name: name.to_string(), body, oracle: Oracle::new(points, tets) })
    }

    fn bad(&self, step: usize, message: String) -> ConformanceError {
        ConformanceError::BadOp { vector: self.name.clone(), step: Some(step), message }
    }

    fn law(&self, step: Option<usize>, message: String) -> ConformanceError {
        ConformanceError::Law { vector: self.name.clone(), step, message }
    }

    /// Input tet `t`, or a bad-op error naming the range.
    fn tet(&self, step: usize, t: u32) -> Result<[u32; 4], ConformanceError> {
        let n = self.oracle.tets.len();
        self.oracle
            .tets
            .get(t as usize)
            .copied()
            .ok_or_else(|| self.bad(step, format!("tet {t} is out of range (the mesh has {n} tets)")))
    }

    /// The live dart 24t + k of input tet t (the builder's numbering, `docs/ARCHITECTURE.md`),
    /// or `None` if the tet was removed.
    fn dart(&self, t: u32, k: usize) -> Option<DartId> {
        let map = self.body.map();
        let d = DartId(24 * t + k as u32);
        (map.contains(d) && map.cell_id(3, d) == CellId(t)).then_some(d)
    }

    /// The tet of a live dart.
    fn tet_of(&self, d: DartId) -> u32 {
        self.body.map().cell_id(3, d).0
    }

    /// Runs one step while generating ([`Runner::run`]) and records the state after it.
    fn run_generating(&mut self, k: usize, op: &Op) -> Result<Step, ConformanceError> {
        let outcome = self.run(k, op)?;
        Ok(Step { op: op.clone(), expect: self.observe(outcome) })
    }

    /// Runs step `k`, the same way for generation and replay: an incision plane must keep the
    /// margin from every live centroid ([`Runner::check_margin`], before anything is applied),
    /// then the operation is applied and the laws are checked.
    fn run(&mut self, k: usize, op: &Op) -> Result<Outcome, ConformanceError> {
        if let Op::Incise { point, normal } = op {
            self.check_margin(k, &Plane { point: *point, normal: *normal })?;
        }
        let outcome = self.apply(k, op)?;
        self.check_laws(Some(k))?;
        Ok(outcome)
    }

    fn apply(&mut self, step: usize, op: &Op) -> Result<Outcome, ConformanceError> {
        match *op {
            Op::Dissociate { tets, face } => self.dissociate(step, tets, face),
            Op::Remove { tet } => self.remove(step, tet),
            Op::Incise { point, normal } => self.incise(step, Plane { point, normal }),
            Op::Tear { tet, vertex, direction } => self.tear(step, tet, vertex, direction),
        }
    }

    fn dissociate(&mut self, step: usize, tets: [u32; 2], face: [u32; 3]) -> Result<Outcome, ConformanceError> {
        let (a, b) = (self.tet(step, tets[0])?, self.tet(step, tets[1])?);
        if tets[0] >= tets[1] {
            return Err(self.bad(step, format!("tets {tets:?} must be two different tets, smaller first")));
        }
        let shared = common(&a, &b);
        if shared != face {
            return Err(self.bad(step, format!("tets {tets:?} share points {shared:?}, not the face {face:?}")));
        }
        let (Some(_), Some(_)) = (self.dart(tets[0], 0), self.dart(tets[1], 0)) else {
            return Ok(Outcome { refused: Some(Refusal::RemovedTet), dissociated: Vec::new() });
        };
        let f = a.iter().position(|p| !face.contains(p)).expect("a tet has one corner off each of its faces");
        let d = self.dart(tets[0], 6 * f).expect("tet checked live above");
        match cut::dissociate_face(&mut self.body, d) {
            Err(CutError::BoundaryFace { .. }) => {
                Ok(Outcome { refused: Some(Refusal::BoundaryFace), dissociated: vec![] })
            }
            Err(e) => Err(self.law(Some(step), format!("dissociating {tets:?}: {e}"))),
            Ok(dis) => {
                if self.tet_of(dis.opposite) != tets[1] {
                    return Err(self.law(
                        Some(step),
                        format!(
                            "face {face:?} of tet {} was glued to tet {}, not {}",
                            tets[0],
                            self.tet_of(dis.opposite),
                            tets[1]
                        ),
                    ));
                }
                self.oracle.cut.insert(face);
                Ok(Outcome { refused: None, dissociated: vec![tets] })
            }
        }
    }

    fn remove(&mut self, step: usize, t: u32) -> Result<Outcome, ConformanceError> {
        self.tet(step, t)?;
        if self.dart(t, 0).is_none() {
            return Ok(Outcome { refused: Some(Refusal::RemovedTet), dissociated: Vec::new() });
        }
        let r = cut::remove_volume(&mut self.body, CellId(t))
            .map_err(|e| self.law(Some(step), format!("removing tet {t}: {e}")))?;
        self.oracle.alive[t as usize] = false;
        let pairs = r.dissociations.iter().map(|dis| pair(t, self.tet_of(dis.opposite))).collect();
        Ok(Outcome { refused: None, dissociated: sorted(pairs) })
    }

    fn incise(&mut self, step: usize, plane: Plane) -> Result<Outcome, ConformanceError> {
        let inc = cut::incise_plane(&mut self.body, &plane).map_err(|e| match e {
            CutError::BadPlane { .. } => self.bad(step, e.to_string()),
            e => self.law(Some(step), e.to_string()),
        })?;
        let pairs =
            inc.dissociations.iter().map(|dis| pair(self.tet_of(dis.dart), self.tet_of(dis.opposite))).collect();
        self.record_cut(step, sorted(pairs))
    }

    fn tear(&mut self, step: usize, t: u32, vertex: u32, direction: Vec3) -> Result<Outcome, ConformanceError> {
        let tet = self.tet(step, t)?;
        if !tet.contains(&vertex) {
            return Err(self.bad(step, format!("point {vertex} is not a corner of tet {t} {tet:?}")));
        }
        if direction.iter().any(|c| !c.is_finite()) || direction == [0.0; 3] {
            return Err(self.bad(step, format!("tear direction {direction:?} is not finite and non-zero")));
        }
        if self.dart(t, 0).is_none() {
            return Ok(Outcome { refused: Some(Refusal::RemovedTet), dissociated: Vec::new() });
        }
        let at = self.oracle.points[vertex as usize];
        let (map, mech) = (self.body.map(), self.body.attrs());
        let d = (0..24)
            .filter_map(|k| self.dart(t, k))
            .find(|&d| mech.rest_position[map.vertex_id(d)] == at)
            .ok_or_else(|| self.law(Some(step), format!("no dart of tet {t} rests at point {vertex}")))?;
        let v = map.vertex_id(d);
        let tear = cut::tear_vertex(&mut self.body, v, direction, Some(d))
            .map_err(|e| self.law(Some(step), format!("tearing point {vertex} of tet {t}: {e}")))?;
        let pairs =
            tear.dissociations.iter().map(|dis| pair(self.tet_of(dis.dart), self.tet_of(dis.opposite))).collect();
        self.record_cut(step, sorted(pairs))
    }

    /// Marks the dissociated faces in the oracle.
    fn record_cut(&mut self, step: usize, pairs: Vec<[u32; 2]>) -> Result<Outcome, ConformanceError> {
        for &[a, b] in &pairs {
            let face = common(&self.oracle.tets[a as usize], &self.oracle.tets[b as usize]);
            let face: [u32; 3] =
                face.try_into().map_err(|f| self.law(Some(step), format!("tets {a}, {b} share {f:?}, not a face")))?;
            self.oracle.cut.insert(face);
        }
        Ok(Outcome { refused: None, dissociated: pairs })
    }

    /// Generation and replay: every live tet centroid keeps [`PLANE_MARGIN`] · diagonal from the
    /// plane, the diagonal of the bounding box of the points the input tets use (an unused point
    /// does not widen it). Closer, the side of that tet would be decided by rounding (topomech's
    /// tie rule puts a centroid on the plane on the negative side, another engine may not), so
    /// the vector does not determine the outcome of the step. Lengths are taken scale-safe
    /// (divided by the largest component first), so every nonzero finite normal is accepted, as
    /// [`cut::incise_plane`] accepts it. O(T).
    fn check_margin(&self, step: usize, plane: &Plane) -> Result<(), ConformanceError> {
        plane.check().map_err(|e| self.bad(step, e.to_string()))?;
        let n = plane.normal;
        let scale = n.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        let unit = {
            let m = n.map(|c| c / scale);
            let len = norm(m);
            m.map(|c| c / len)
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in self.oracle.tets.iter().flatten().map(|&i| self.oracle.points[i as usize]) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let diagonal = if self.oracle.tets.is_empty() { 0.0 } else { norm([0, 1, 2].map(|k| hi[k] - lo[k])) };
        let margin = PLANE_MARGIN * diagonal;
        // The closest live centroid (the smallest tet id among equals).
        let closest = (0..self.oracle.tets.len())
            .filter(|&t| self.oracle.alive[t])
            .map(|t| {
                let c = self.oracle.centroid(t);
                (t, ((0..3).map(|k| (c[k] - plane.point[k]) * unit[k]).sum::<f64>()).abs())
            })
            .filter(|(_, d)| !d.is_nan()) // overflowing coordinates: no distance (as before)
            .fold(None, |best: Option<(usize, f64)>, (t, d)| match best {
                Some((_, b)) if b <= d => best,
                _ => Some((t, d)),
            });
        match closest {
            Some((tet, distance)) if distance < margin => Err(ConformanceError::AmbiguousPlane {
                vector: self.name.clone(),
                step: Some(step),
                tet: tet as u32,
                distance,
                margin,
            }),
            _ => Ok(()),
        }
    }

    /// `validate()`, conservation, and the union-find model's counts.
    fn check_laws(&self, step: Option<usize>) -> Result<(), ConformanceError> {
        let map = self.body.map();
        map.validate().map_err(|e| self.law(step, format!("validate: {e}")))?;
        check_conservation(map, self.body.attrs()).map_err(|e| self.law(step, format!("conservation: {e}")))?;
        let (cells, boundary, comps) = self.oracle.counts();
        let got = (map.count_cells().0, map.boundary_cell_count(), cut::components(&self.body).len());
        if got != (cells.to_vec(), boundary, comps) {
            return Err(self.law(
                step,
                format!(
                    "map (cells, boundary faces, components) {got:?}, union-find model {:?}",
                    (cells, boundary, comps)
                ),
            ));
        }
        Ok(())
    }

    fn observe(&self, outcome: Outcome) -> Expect {
        let map = self.body.map();
        let counts = map.count_cells();
        let c = &counts.0;
        let parts = cut::components(&self.body);
        let mut masses: Vec<f64> = parts.iter().map(|p| p.mass).collect();
        masses.sort_by(f64::total_cmp);
        let attrs = self.body.attrs();
        let ascending = |mut x: Vec<f64>| {
            x.sort_by(f64::total_cmp);
            x.into_iter().map(|m| m + 0.0).collect::<Vec<f64>>()
        };
        let vertex_masses =
            ascending(map.one_dart_per_cell(0).into_iter().map(|d| attrs.vertex_mass(map.vertex_id(d))).collect());
        let edge_stiffnesses =
            ascending(map.one_dart_per_cell(1).into_iter().map(|d| attrs.edge_stiffness(map.cell_id(1, d))).collect());
        Expect {
            refused: outcome.refused,
            dissociated: outcome.dissociated,
            darts: map.dart_count(),
            cells: [c[0], c[1], c[2], c[3]],
            boundary_faces: map.boundary_cell_count(),
            components: parts.len(),
            euler: counts.euler_characteristic(),
            // `+ 0.0` turns the −0.0 of an empty sum into 0.0.
            total_mass: self.body.total_vertex_mass() + 0.0,
            total_stiffness: shared::total_stiffness(&self.body) + 0.0,
            component_masses: masses,
            vertex_masses: Some(vertex_masses),
            edge_stiffnesses: Some(edge_stiffnesses),
        }
    }

    /// The [`Op`] that [`Harness::apply`](shared::Harness::apply) would run for `op` now, or
    /// `None` when it does nothing (or targets an input boundary face, which has no tet pair).
    fn translate(&self, op: shared::Op) -> Option<Op> {
        let o = &self.oracle;
        let live: Vec<usize> = (0..o.tets.len()).filter(|&t| o.alive[t]).collect();
        match op {
            shared::Op::Dissociate(k) => {
                let glued = o.glued();
                let (face, [(a, _), (b, _)]) = *glued.get(k % glued.len().max(1))?;
                Some(Op::Dissociate { tets: pair(a as u32, b as u32), face })
            }
            shared::Op::DissociateBoundary(k) => {
                let glued: Vec<[u32; 3]> = o.glued().into_iter().map(|(f, _)| f).collect();
                let free: Vec<[u32; 3]> = live
                    .iter()
                    .flat_map(|&t| (0..4).map(move |f| o.triple(t, f)))
                    .filter(|f| !glued.contains(f))
                    .collect();
                let face = *free.get(k % free.len().max(1))?;
                let [(a, _), (b, _)] = *o.inner.get(&face)?;
                Some(Op::Dissociate { tets: pair(a as u32, b as u32), face })
            }
            shared::Op::Remove(k) => (live.len() > 1).then(|| Op::Remove { tet: live[k % live.len()] as u32 }),
            shared::Op::RemoveAgain(k) => {
                let dead: Vec<usize> = (0..o.tets.len()).filter(|&t| !o.alive[t]).collect();
                dead.get(k % dead.len().max(1)).map(|&t| Op::Remove { tet: t as u32 })
            }
            shared::Op::Incise(k, n) => {
                let c = o.centroid(*live.get(k % live.len().max(1))?);
                let point = [c[0] + 0.0137 * n[0], c[1] + 0.0137 * n[1], c[2] + 0.0137 * n[2]];
                Some(Op::Incise { point, normal: n })
            }
            shared::Op::Tear(k, n) => {
                let t = *live.get(k % live.len().max(1))?;
                let d = DartId((24 * t + (k / 7) % 24) as u32);
                let rest = self.body.attrs().rest_position[self.body.map().vertex_id(d)];
                let vertex = *o.tets[t].iter().find(|&&p| o.points[p as usize] == rest)?;
                Some(Op::Tear { tet: t as u32, vertex, direction: n })
            }
        }
    }
}

/// |v|, scale-safe ([`crate::mesh::distance`] from the origin). O(1).
fn norm(v: Vec3) -> f64 {
    crate::mesh::distance(v, [0.0; 3])
}

fn pair(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

fn sorted(mut pairs: Vec<[u32; 2]>) -> Vec<[u32; 2]> {
    pairs.sort_unstable();
    pairs
}

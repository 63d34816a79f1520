//! The JSON schema of a conformance vector (field by field in `docs/CONFORMANCE.md`).

use crate::mechanics::{Material, Vec3};

/// One conformance vector: a mesh, a material, the expected initial state and the steps.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, standard::recipes, Vector, FORMAT, TOLERANCE, VERSION};
///
/// let recipe = recipes().into_iter().find(|r| r.name == "single_tet_remove").unwrap();
/// let v: Vector = generate(&recipe).unwrap();
/// assert_eq!((v.format.as_str(), v.version, v.tolerance), (FORMAT, VERSION, TOLERANCE));
/// assert_eq!(v.name, recipe.name);
/// assert_eq!(Vector::from_json(&v.to_json(), "mem").unwrap(), v);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vector {
    /// Always [`FORMAT`](super::FORMAT).
    pub format: String,
    /// Always [`VERSION`](super::VERSION).
    pub version: u32,
    /// File stem (`topomech conformance check` fails a file whose stem differs); names the vector
    /// in every error. 1 to [`MAX_NAME_LEN`](super::MAX_NAME_LEN) characters of
    /// `A–Z a–z 0–9 _ - .` ([`Vector::check_fields`]).
    pub name: String,
    /// What the vector exercises, for a human reader.
    pub description: String,
    /// Relative tolerance of the floating-point fields: |a − b| ≤ tolerance · max(|a|, |b|), in
    /// 0 ..= [`MAX_TOLERANCE`](super::MAX_TOLERANCE).
    pub tolerance: f64,
    /// The input mesh.
    pub mesh: MeshSpec,
    /// The material constants.
    pub material: MaterialSpec,
    /// The state of the uncut body.
    pub initial: Expect,
    /// The operations and the state after each.
    pub steps: Vec<Step>,
}

/// The input mesh: inline, generated, or a file of the repository.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, MeshSpec, Ops, Recipe};
///
/// let inline = MeshSpec::Inline {
///     points: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
///     tets: vec![[0, 1, 2, 3]],
/// };
/// let material = topomech::mechanics::Material::default().into();
/// let recipe = Recipe { name: "t".into(), description: "one tet".into(), mesh: inline, material, ops: Ops::Listed(vec![]) };
/// assert_eq!(generate(&recipe).unwrap().initial.cells, [4, 6, 4, 1]);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MeshSpec {
    /// Points and tets in the vector itself (the self-contained form).
    Inline {
        /// Point coordinates; point i is `points[i]`.
        points: Vec<Vec3>,
        /// Tets as four point indices; tet t is `tets[t]`.
        tets: Vec<[u32; 4]>,
    },
    /// The Kuhn cube \[0, k\]³ of [`kuhn_cube`](crate::generate::kuhn_cube) (k ≤ 16).
    KuhnCube {
        /// Cubes per side.
        k: usize,
    },
    /// A mesh file, relative to the repository root; the declared sizes are checked.
    File {
        /// Path relative to the repository root (e.g. `data/liver_547_v22.msh`); a root or a `..`
        /// component is refused, and the path with its symbolic links resolved must lie inside the
        /// resolved root, so a vector reads nothing outside the repository.
        path: String,
        /// Points the file holds.
        points: usize,
        /// Tets the file holds.
        tets: usize,
    },
}

/// The material constants (the fields of [`Material`]).
///
/// # Examples
///
/// ```
/// use topomech::conformance::MaterialSpec;
/// use topomech::mechanics::Material;
///
/// let spec = MaterialSpec::from(Material::default());
/// assert_eq!(spec.density, Material::default().density);
/// assert_eq!(Material::from(spec), Material::default()); // lossless both ways
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Mass density ρ; m_t = ρ·V_t.
    pub density: f64,
    /// Young's modulus E; each tet gives each of its edges E·V_t/L_e².
    pub young: f64,
    /// Spring damping β (seconds); not used by any expected field.
    pub damping: f64,
    /// Ambient viscosity ν (1/s); not used by any expected field.
    pub viscosity: f64,
}

impl From<Material> for MaterialSpec {
    fn from(m: Material) -> Self {
        MaterialSpec { density: m.density, young: m.young, damping: m.damping, viscosity: m.viscosity }
    }
}

impl From<MaterialSpec> for Material {
    fn from(m: MaterialSpec) -> Self {
        Material { density: m.density, young: m.young, damping: m.damping, viscosity: m.viscosity }
    }
}

/// One operation and the state after it.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, MeshSpec, Op, Ops, Recipe};
///
/// let recipe = Recipe {
///     name: "one".into(), description: "remove a tet".into(), mesh: MeshSpec::KuhnCube { k: 1 },
///     material: topomech::mechanics::Material::default().into(), ops: Ops::Listed(vec![Op::Remove { tet: 2 }]),
/// };
/// let step = &generate(&recipe).unwrap().steps[0];
/// assert_eq!(step.op, Op::Remove { tet: 2 });
/// assert_eq!((step.expect.darts, step.expect.refused), (5 * 24, None));
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// The operation.
    pub op: Op,
    /// The state after it.
    pub expect: Expect,
}

/// A cutting operation, naming things by input tet and point indices.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, MeshSpec, Op, Ops, Recipe};
///
/// let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
/// let mesh = MeshSpec::Inline { points, tets: vec![[0, 1, 2, 3], [0, 1, 2, 4]] };
/// let op = Op::Dissociate { tets: [0, 1], face: [0, 1, 2] };
/// let material = topomech::mechanics::Material::default().into();
/// let recipe = Recipe { name: "d".into(), description: "split".into(), mesh, material, ops: Ops::Listed(vec![op]) };
/// let after = &generate(&recipe).unwrap().steps[0].expect;
/// assert_eq!((after.dissociated.clone(), after.components), (vec![[0, 1]], 2));
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Op {
    /// Dissociate the inner face shared by two input tets.
    Dissociate {
        /// The two tets, smaller index first.
        tets: [u32; 2],
        /// Their common points, sorted (a cross-check of `tets`).
        face: [u32; 3],
    },
    /// Remove an input tet (its glued faces are dissociated first).
    Remove {
        /// The tet.
        tet: u32,
    },
    /// Dissociate every glued face whose two tets' centroids are on opposite sides of a plane.
    Incise {
        /// A point of the plane.
        point: Vec3,
        /// Its normal (any nonzero finite length).
        normal: Vec3,
    },
    /// Tear the vertex of `tet` at input point `vertex` along `direction` (seed §5.1). The faces
    /// it dissociates are listed in [`Expect::dissociated`]: another engine replays a tear as those
    /// dissociations.
    Tear {
        /// A tet that holds the vertex (chooses which copy, if the point was split already).
        tet: u32,
        /// The input point.
        vertex: u32,
        /// The stress direction.
        direction: Vec3,
    },
}

/// Why an operation was refused (the state is then unchanged).
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, MeshSpec, Op, Ops, Recipe, Refusal};
///
/// let ops = Ops::Listed(vec![Op::Remove { tet: 0 }, Op::Remove { tet: 0 }]);
/// let material = topomech::mechanics::Material::default().into();
/// let recipe = Recipe { name: "r".into(), description: "twice".into(), mesh: MeshSpec::KuhnCube { k: 1 }, material, ops };
/// let v = generate(&recipe).unwrap();
/// assert_eq!(v.steps[1].expect.refused, Some(Refusal::RemovedTet));
/// assert_eq!(v.steps[1].expect.cells, v.steps[0].expect.cells); // state unchanged
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Refusal {
    /// The face was dissociated before (both its tets are still there): nothing to dissociate.
    BoundaryFace,
    /// A tet the operation names was removed earlier.
    RemovedTet,
}

/// The state of the body at one point of the sequence.
///
/// # Examples
///
/// ```
/// use topomech::conformance::{generate, standard::recipes};
///
/// let v = generate(&recipes().into_iter().find(|r| r.name == "single_tet_remove").unwrap()).unwrap();
/// let e = &v.initial;
/// let [vs, es, fs, ts] = e.cells;
/// assert_eq!(e.euler, vs as i64 - es as i64 + fs as i64 - ts as i64);
/// assert_eq!((e.darts, e.component_masses.len()), (24 * ts, e.components));
/// assert!((e.component_masses.iter().sum::<f64>() - e.total_mass).abs() <= 1e-12 * e.total_mass);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// Set when the operation must be refused (state unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refused: Option<Refusal>,
    /// The inner faces the step dissociated, as sorted tet pairs, sorted.
    pub dissociated: Vec<[u32; 2]>,
    /// Darts: 24 per live tet.
    pub darts: usize,
    /// Vertices, edges, faces, volumes.
    pub cells: [usize; 4],
    /// Faces on the boundary (one side only).
    pub boundary_faces: usize,
    /// Connected components (tets joined through glued faces).
    pub components: usize,
    /// V − E + F − T.
    pub euler: i64,
    /// Σ_v m_v (= ρ · Σ live V_t). Finite, as are the other two float fields.
    pub total_mass: f64,
    /// Σ_e k_e (= Σ over live tets and their edges of E·V_t/L_e²).
    pub total_stiffness: f64,
    /// The mass of each component, ascending.
    pub component_masses: Vec<f64>,
    /// The mass of every vertex (Σ m_t/4 over the live tets of its class of corners), ascending:
    /// how a split vertex shares its mass (m = m1 + m2), which the totals above cannot see.
    /// Written for vectors of at most [`DETAIL_MAX_VERTICES`](super::DETAIL_MAX_VERTICES)
    /// initial vertices; absent otherwise and in vectors written before 2026-12-07 (a replay
    /// then skips it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex_masses: Option<Vec<f64>>,
    /// The stiffness of every edge (Σ over the live tets of its class of tet edges of
    /// E·V_t/L_e²), ascending: how a split edge shares its stiffness (Kirchhoff: k = k1 + k2).
    /// [`generate`](super::generate) writes it exactly when it writes [`Expect::vertex_masses`];
    /// a replay compares each one that is present.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_stiffnesses: Option<Vec<f64>>,
}

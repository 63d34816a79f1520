//! The JSON schema of a conformance vector (field by field in `docs/CONFORMANCE.md`).

use crate::mechanics::{Material, Vec3};

/// One conformance vector: a mesh, a material, the expected initial state and the steps.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vector {
    /// Always [`FORMAT`](super::FORMAT).
    pub format: String,
    /// Always [`VERSION`](super::VERSION).
    pub version: u32,
    /// File stem; names the vector in every error.
    pub name: String,
    /// What the vector exercises, for a human reader.
    pub description: String,
    /// Relative tolerance of the floating-point fields: |a − b| ≤ tolerance · max(|a|, |b|).
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
        /// Path relative to the repository root (e.g. `data/liver_547_v22.msh`).
        path: String,
        /// Points the file holds.
        points: usize,
        /// Tets the file holds.
        tets: usize,
    },
}

/// The material constants (the fields of [`Material`]).
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// The operation.
    pub op: Op,
    /// The state after it.
    pub expect: Expect,
}

/// A cutting operation, naming things by input tet and point indices.
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
        /// Its normal (any nonzero length).
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Refusal {
    /// The face was dissociated before (both its tets are still there): nothing to dissociate.
    BoundaryFace,
    /// A tet the operation names was removed earlier.
    RemovedTet,
}

/// The state of the body at one point of the sequence.
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
    /// Σ_v m_v (= ρ · Σ live V_t).
    pub total_mass: f64,
    /// Σ_e k_e (= Σ over live tets and their edges of E·V_t/L_e²).
    pub total_stiffness: f64,
    /// The mass of each component, ascending.
    pub component_masses: Vec<f64>,
}

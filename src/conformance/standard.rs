//! The standard set of vectors committed under `conformance/` (`topomech conformance generate`).
//!
//! | name | mesh | what it exercises |
//! |---|---|---|
//! | `single_tet_remove` | 1 tet, inline | removal down to the empty body; removing again is refused |
//! | `two_tets_dissociate` | 2 tets, inline | one dissociation: 1 → 2 components; again is refused |
//! | `chain_remove_middle` | 3 tets in a chain, inline | a removal that leaves two tets touching along an edge only: 2 components, pinched edge |
//! | `kuhn2_incise_planes` | Kuhn cube k = 2, inline | incisions by an axis plane (2 halves), then an oblique one |
//! | `kuhn2_edge_then_vertex_split` | Kuhn cube k = 2, inline | a dissociation that splits an edge only, then one that splits a vertex; Σ k constant (k = k1 + k2) |
//! | `kuhn2_tear_center` | Kuhn cube k = 2, generated | tearing the centre vertex, then a removal |
//! | `jittered_cube_shared_sequence` | jittered Kuhn cube k = 2, inline | a seeded sequence of the shared cut generator (`cut::ops`) |
//! | `liver_short_sequence` | `data/liver_547_v22.msh` | a short fixed sequence of the shared generator on the built-in liver |
//! | `pinch_edge_glued_dissociate` | 3 tets, inline | two glued tets and a third touching them along an edge only; a dissociation that splits vertices and edges |
//! | `pinch_edge_remove` | 2 tets sharing an edge only, inline | a pinched edge in the input (two edges, four vertices); a removal |
//! | `pinch_vertex_remove` | 2 tets sharing a point only, inline | a pinched point in the input (two vertices); a removal |

use crate::cut::ops::{self as shared, jittered_cube, Oracle};
use crate::generate::{kuhn_cube, SplitMix64};
use crate::mechanics::Material;

use super::runner::{generate_in, Ops, Recipe};
use super::schema::{MeshSpec, Op, Vector};
use super::ConformanceError;

/// The recipes of the standard set, in file-name order. O(k³) for the cube meshes.
///
/// # Examples
///
/// ```
/// use topomech::conformance::standard::recipes;
///
/// let names: Vec<String> = recipes().into_iter().map(|r| r.name).collect();
/// assert_eq!(names.len(), 11);
/// assert!(names.windows(2).all(|w| w[0] < w[1])); // file-name order
/// assert!(names.iter().any(|n| n == "single_tet_remove"));
/// ```
pub fn recipes() -> Vec<Recipe> {
    vec![
        chain_remove_middle(),
        jittered_cube_shared_sequence(),
        kuhn2_edge_then_vertex_split(),
        kuhn2_incise_planes(),
        kuhn2_tear_center(),
        liver_short_sequence(),
        pinch_edge_glued_dissociate(),
        pinch_edge_remove(),
        pinch_vertex_remove(),
        single_tet_remove(),
        two_tets_dissociate(),
    ]
}

/// Generates every recipe of [`recipes`], with mesh files relative to `root`.
///
/// # Errors
/// As [`generate_in`].
///
/// # Examples
///
/// ```
/// use topomech::conformance::{replay_in, standard::generate_all};
/// use std::path::Path;
///
/// let root = Path::new(env!("CARGO_MANIFEST_DIR"));
/// let vectors = generate_all(root).unwrap();
/// assert_eq!(vectors.len(), 11);
/// assert!(vectors.iter().all(|v| replay_in(v, root).is_ok()));
/// ```
pub fn generate_all(root: &std::path::Path) -> Result<Vec<Vector>, ConformanceError> {
    recipes().iter().map(|r| generate_in(r, root)).collect()
}

fn recipe(name: &str, description: &str, mesh: MeshSpec, ops: Ops) -> Recipe {
    Recipe {
        name: name.to_string(),
        description: description.to_string(),
        mesh,
        material: Material::default().into(),
        ops,
    }
}

fn inline((points, tets): (Vec<[f64; 3]>, Vec<[u32; 4]>)) -> MeshSpec {
    MeshSpec::Inline { points, tets }
}

/// The inner face with these points, as a dissociation of its two tets.
fn dissociate(oracle: &Oracle, mut face: [u32; 3]) -> Op {
    face.sort_unstable();
    let [(a, _), (b, _)] = oracle.inner[&face];
    Op::Dissociate { tets: [a.min(b) as u32, a.max(b) as u32], face }
}

/// Two tets glued on a face and a third touching them along an edge only (finding 299: no vector
/// had a point the input shares only through an edge or a vertex).
fn pinch_edge_glued_dissociate() -> Recipe {
    let points = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [0.0, -1.0, 0.3],
        [0.0, -0.5, -1.0],
    ];
    recipe(
        "pinch_edge_glued_dissociate",
        "Tets 0 and 1 glued on the face {0,1,2}; tet 2 touches them along the edge {0,1} only, so in the \
         input points 0 and 1 are two vertices each and {0,1} two edges (9 vertices, 15 edges, 2 \
         components). Step 0 dissociates {0,1,2}: its three vertices and three edges split (3 components); \
         vertex_masses and edge_stiffnesses show each side keeping its own tets' shares.",
        inline((points, vec![[0, 1, 2, 3], [0, 1, 2, 4], [0, 1, 5, 6]])),
        Ops::Listed(vec![Op::Dissociate { tets: [0, 1], face: [0, 1, 2] }]),
    )
}

/// Two tets sharing the edge {0, 1} only (finding 299).
fn pinch_edge_remove() -> Recipe {
    let points =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
    recipe(
        "pinch_edge_remove",
        "Two tets sharing only the edge {0,1} in the input: points 0 and 1 are two vertices each and the \
         edge two edges (8 vertices, 12 edges, 8 faces, 2 components). Step 0 removes tet 0: one tet left.",
        inline((points, vec![[0, 1, 2, 3], [0, 1, 4, 5]])),
        Ops::Listed(vec![Op::Remove { tet: 0 }]),
    )
}

/// Two tets sharing the point 0 only (finding 299).
fn pinch_vertex_remove() -> Recipe {
    let points = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    recipe(
        "pinch_vertex_remove",
        "Two tets sharing only the point 0 in the input: it is two vertices (8 vertices, 12 edges, 8 faces, \
         2 components). Step 0 removes tet 1: one tet left.",
        inline((points, vec![[0, 1, 2, 3], [0, 4, 5, 6]])),
        Ops::Listed(vec![Op::Remove { tet: 1 }]),
    )
}

fn single_tet_remove() -> Recipe {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    recipe(
        "single_tet_remove",
        "One unit right tetrahedron (volume 1/6). Step 0 removes it: every count and the mass drop to zero. \
         Step 1 removes it again and must be refused (removed_tet) with the state unchanged.",
        inline((points, vec![[0, 1, 2, 3]])),
        Ops::Listed(vec![Op::Remove { tet: 0 }, Op::Remove { tet: 0 }]),
    )
}

fn two_tets_dissociate() -> Recipe {
    let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
    let op = Op::Dissociate { tets: [0, 1], face: [1, 2, 3] };
    recipe(
        "two_tets_dissociate",
        "Two tets sharing the face {1,2,3}. Step 0 dissociates it: the three shared vertices and three shared \
         edges split (8 vertices, 12 edges, 8 faces, 2 components); mass and Σ stiffness are unchanged \
         (m = m1 + m2, k = k1 + k2). Step 1 dissociates it again and must be refused (boundary_face).",
        inline((points, vec![[0, 1, 2, 3], [1, 2, 3, 4]])),
        Ops::Listed(vec![op.clone(), op]),
    )
}

fn chain_remove_middle() -> Recipe {
    // t0 = {0,1,2,3}, t1 = {1,2,3,4}, t2 = {2,3,4,5}; point 5 lies across the face {2,3,4} from 1.
    let points =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.5, 1.5]];
    recipe(
        "chain_remove_middle",
        "Three tets in a chain (each shares a face with the next; the first and the last share only the \
         edge {2,3}). Step 0 removes the middle tet: two components remain that touch along that edge only, \
         so in the map points 2 and 3 and the edge {2,3} each become two cells (connectivity is through \
         faces). Mass and Σ stiffness drop by exactly the removed tet's share. Step 1 dissociates the face \
         tets 0 and 1 shared, which must be refused (removed_tet).",
        inline((points, vec![[0, 1, 2, 3], [1, 2, 3, 4], [2, 3, 4, 5]])),
        Ops::Listed(vec![Op::Remove { tet: 1 }, Op::Dissociate { tets: [0, 1], face: [1, 2, 3] }]),
    )
}

fn kuhn2_incise_planes() -> Recipe {
    recipe(
        "kuhn2_incise_planes",
        "Kuhn cube [0,2]^3 (27 points, 48 tets). Step 0 incises by the plane z = 1 (normal +z): every glued \
         face between a tet below and a tet above is dissociated, leaving 2 components. Step 1 incises by an \
         oblique plane through (1,1,1). A tet's side is that of its centroid; no centroid is near either plane.",
        inline(kuhn_cube(2)),
        Ops::Listed(vec![
            Op::Incise { point: [1.0, 1.0, 1.0], normal: [0.0, 0.0, 1.0] },
            Op::Incise { point: [1.0, 1.0, 1.0], normal: [1.0, 0.37, 0.0] },
        ]),
    )
}

fn kuhn2_edge_then_vertex_split() -> Recipe {
    let (points, tets) = kuhn_cube(2);
    let oracle = Oracle::new(points.clone(), tets.clone());
    // Points: 0 = (0,0,0), 4 = (1,1,0), 10 = (1,0,1), 13 = (1,1,1).
    recipe(
        "kuhn2_edge_then_vertex_split",
        "Kuhn cube [0,2]^3. Step 0 dissociates the face {0,4,13}: the boundary edge {0,4} has an open fan of two \
         tets, so it splits in two while no vertex splits (E + 1, V unchanged). Step 1 dissociates the face \
         {0,10,13}: together the two cuts separate the star of the corner point 0, which splits (V + 1), and \
         the edges {0,13} and {0,10} split. Σ stiffness and the mass stay constant throughout \
         (Kirchhoff: k = k1 + k2, m = m1 + m2).",
        inline((points, tets)),
        Ops::Listed(vec![dissociate(&oracle, [0, 4, 13]), dissociate(&oracle, [0, 10, 13])]),
    )
}

fn kuhn2_tear_center() -> Recipe {
    let (_, tets) = kuhn_cube(2);
    let t = tets.iter().position(|t| t.contains(&13)).expect("the centre is a corner of some tet") as u32;
    recipe(
        "kuhn2_tear_center",
        "Kuhn cube [0,2]^3 given by its generator (mesh kind kuhn_cube). Step 0 tears the centre point 13 = \
         (1,1,1) along (0.2, 0.3, 1): the fan of faces around it that starts with the face whose normal is \
         closest to the direction is dissociated; the faces are listed in expect.dissociated, so another \
         engine can replay the tear as those dissociations (the body stays in one piece: 1 component). \
         Step 1 removes tet 0; step 2 tears point 13 as seen from tet 0, which must be refused (removed_tet).",
        MeshSpec::KuhnCube { k: 2 },
        Ops::Listed(vec![
            Op::Tear { tet: t, vertex: 13, direction: [0.2, 0.3, 1.0] },
            Op::Remove { tet: 0 },
            Op::Tear { tet: 0, vertex: 13, direction: [0.2, 0.3, 1.0] },
        ]),
    )
}

fn jittered_cube_shared_sequence() -> Recipe {
    let mut rng = SplitMix64(2026);
    let mut bytes: Vec<u8> = (0..2 + 4 * 16).map(|_| rng.next_u64() as u8).collect();
    bytes[0] |= 1; // k = 2
    let scenario = shared::decode(&bytes);
    let mut r = recipe(
        "jittered_cube_shared_sequence",
        "Kuhn cube [0,2]^3 with every point moved by up to 0.1 per coordinate (inline). The operations are a \
         seeded sequence (SplitMix64 seed 2026) of the cut generator shared with topomech's property tests \
         and fuzz target, translated into this schema: tears, dissociations, an incision and removals.",
        inline(jittered_cube(scenario.k, scenario.seed)),
        Ops::Shared(bytes),
    );
    r.material = shared::material().into();
    r
}

fn liver_short_sequence() -> Recipe {
    let bytes = vec![
        0,
        0, // mesh bytes of the shared generator (ignored: the mesh is the liver)
        0,
        100,
        0,
        0, // dissociate the 100th glued face
        1,
        0xd0,
        7,
        0, // dissociate the 2000th
        7,
        37,
        0,
        0, // remove a tet
        9,
        0,
        0,
        0, // remove it again (refused)
        10,
        250,
        0,
        0b1001_1101, // incise through (near) a tet's centroid
        11,
        0x09,
        3,
        0b0101_0110, // tear a vertex
        3,
        44,
        1,
        0, // dissociate the 300th glued face
    ];
    recipe(
        "liver_short_sequence",
        "The built-in liver mesh (data/liver_547_v22.msh, 547 points, 1852 tets; by path, not inline). A \
         short fixed sequence of the shared cut generator: two dissociations, a removal, a refused repeat \
         removal, an incision, a tear and a dissociation.",
        MeshSpec::File { path: "data/liver_547_v22.msh".into(), points: 547, tets: 1852 },
        Ops::Shared(bytes),
    )
}

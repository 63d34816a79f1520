//! topomech: n-dimensional generalized maps (n-G-maps) that stay valid after every operation,
//! built from real tetrahedral and triangle meshes.
//!
//! An n-G-map is G = (B, α0, …, αn): a finite set of darts B, each αi an involution on B, and
//! αi∘αj an involution whenever j ≥ i + 2 (the quasi-manifold law). Every public mutating
//! operation of [`GMap`] leaves those laws, and the exact cell ids that embeddings hang on, intact;
//! [`GMap::validate`] checks them all and names the dart and law that broke.
//!
//! ```
//! use topomech::{AlphaMask, GMap};
//!
//! // Two tetrahedra sharing the face {0, 1, 2}.
//! let (mut map, _report) = GMap::<3>::from_tets(5, &[[0, 1, 2, 3], [0, 1, 2, 4]]).unwrap();
//! assert_eq!(map.count_cells().0, vec![5, 9, 7, 2]);
//! assert_eq!(map.boundary_cell_count(), 6);
//!
//! // Dissociate the shared face: 3-unsew one of its darts (the whole face goes).
//! let inner = map.darts().find(|&d| !map.is_free(3, d)).unwrap();
//! let changes = map.unsew::<3>(inner).unwrap();
//! assert_eq!(map.components().len(), 2);
//! assert_eq!(map.count_cells().0, vec![8, 12, 8, 2]);
//! assert_eq!(changes.splits(0).count(), 3); // the three shared vertices split
//! map.validate().unwrap();
//! # let _ = AlphaMask::all(3);
//! ```
//!
//! See `docs/ARCHITECTURE.md` for the map from the seed paper's definitions to modules.
// No unsafe code, but for the one audited exception: the `multiversion!` macro of `mechanics::simd`
// (calls into `#[target_feature]` copies of the hot loops after run-time detection).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod ambiguity;
pub mod build;
pub mod conformance;
pub mod cut;
pub mod embedding;
mod exact;
pub mod generate;
pub mod gmap;
pub mod graph;
pub mod io;
pub mod load;
pub mod mechanics;
pub mod mesh;
pub mod ops;
pub mod render;
mod spare;
pub mod store;
pub mod subdivide;
pub mod surface;
pub mod vtk;
mod wide;

#[doc = include_str!("../docs/TUTORIAL.md")]
pub mod tutorial {}

pub use build::{BuildError, BuildReport};
pub use gmap::{AlphaMask, CellId, DartId, GMap, InvariantViolation};

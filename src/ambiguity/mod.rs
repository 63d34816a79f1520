//! Where adjacency graphs are ambiguous: g-maps versus graphs and indexed meshes (seed 000, §1).
//!
//! The seed claims that "several objects that are not topologically equivalent share one
//! adjacency graph" and that indexed models "cannot prevent ill-structured results" of cutting,
//! while g-maps can. This module makes both claims checkable:
//!
//! - [`finder`]: exhaustive search over small maps (polygon gluings in 2D, small tet complexes
//!   with dissociated faces in 3D) for non-isomorphic maps with isomorphic graphs
//!   ([`crate::graph`]);
//! - [`indexed`]: the naive indexed model (tet list, points duplicated on cut) and its audit
//!   against the g-map cut the same way;
//! - [`campaign`]: random cut sequences on real meshes, statistics, and the delta-debugging
//!   shrinker;
//! - [`mixed`], [`refine`]: random interleavings of cuts and tetrahedron subdivisions, the
//!   leveled g-map against the indexed model refined with an edge → midpoint hash;
//! - [`vector`]: the JSON test vectors of the catalogue (`tests/vectors/ambiguity/`);
//! - [`fuzz`]: the byte-driven comparison behind the cargo-fuzz target.
//!
//! The catalogue of pairs found and the campaign statistics are in `docs/ambiguity.md`.

pub mod campaign;
pub mod catalogue;
pub mod construct;
pub mod darts;
pub mod finder;
pub mod fuzz;
pub mod indexed;
pub mod mixed;
pub mod refine;
pub mod vector;

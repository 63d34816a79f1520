//! Proofs by exhaustion and Kani-style harnesses for the kernel (`cargo test --test proofs`).
//!
//! * [`enumerate`]: every n-G-map on up to k darts (n = 1, 2, 3; all tuples of involutions
//!   satisfying the quasi-manifold law), and on each every sew and unsew: a refusal changes
//!   nothing and agrees with `is_sewable`; an accepted one leaves a valid map whose cell ids
//!   equal a labelling by orbits and agree with the reported changes. Also `is_isomorphic`
//!   against brute force over all relabellings.
//! * [`invalid`]: every single raw corruption of small valid maps; `validate()` must fail iff
//!   some law is broken, and must name a law that is broken, with a true witness. Also every
//!   single α3 or cell-id edit of 1-, 2- and 3-tet complexes built by `from_tets`, which keeps
//!   `tets_as_built` and so exercises `validate()`'s tet path.
//! * [`cut_dissociation`]: every order of dissociating every subset of inner faces (and removing
//!   tets) on two tets, a closed fan of three and the Kuhn cube k = 1, every cut law checked.
//! * [`subdivision`]: every sequence of a few edge splits, triangle 1→4 and tet 1→8 (one dart per
//!   cell, levels ≤ 2) on one or two triangles and one or two tets, every level law checked.
//! * [`harnesses`]: Kani proof harnesses that run here as seeded randomized tests through
//!   [`kani_shim`], and unchanged under `cargo kani --tests`.
//!
//! The laws themselves live in shared `check_*` functions (`topomech::ops` and [`laws`]).
//! Scope: `TOPOMECH_PROOF_DARTS` overrides the dart bound (see docs/VERIFICATION.md).
#![allow(unexpected_cfgs)]

mod cut_dissociation;
mod enumerate;
#[cfg(any(kani, test))]
mod harnesses;
mod invalid;
mod kani_shim;
mod laws;
mod subdivision;

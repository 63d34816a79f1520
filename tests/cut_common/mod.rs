//! The cut suites share `topomech::cut::ops` (one generator for proptest, fuzz and replay).
#![allow(unused_imports)]

pub use topomech::cut::ops::*;

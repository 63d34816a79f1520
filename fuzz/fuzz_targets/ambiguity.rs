//! Fuzz target: bytes → a cut sequence (byte 0 < 128) or an interleaving of cuts and tet
//! subdivisions (byte 0 ≥ 128) on a small mesh, run on the g-map and the naive indexed model side
//! by side; the comparison invariants of `topomech::ambiguity::fuzz` must hold. The same decoder
//! drives `tests/ambiguity_props.rs` (proptest).
//! Corpus: `fuzz/corpus/ambiguity/` (replayed by `tests/ambiguity_fuzz_replay.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(failure) = topomech::ambiguity::fuzz::check_bytes(data) {
        panic!("ambiguity invariant broken: {failure}");
    }
});

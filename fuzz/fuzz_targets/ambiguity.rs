//! Fuzz target: bytes → a cut sequence on a small mesh, run on the g-map and the naive indexed
//! model side by side; the comparison invariants of `topomech::ambiguity::fuzz` must hold.
//! Corpus: `fuzz/corpus/ambiguity/` (replayed by `tests/ambiguity_fuzz_replay.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(failure) = topomech::ambiguity::fuzz::check_bytes(data) {
        panic!("ambiguity invariant broken: {failure}");
    }
});

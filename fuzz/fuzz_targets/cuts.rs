//! Fuzz target: any bytes are decoded by `topomech::cut::ops` into a cut sequence (dissociate,
//! refused dissociate, remove, refused remove, incise, tear) on a jittered Kuhn cube k = 1 or 2;
//! after every step `Harness::check` verifies validate(), conservation, totals, union-find cell,
//! boundary and component counts, and incremental ≡ fresh projection (`expensive-checks` also
//! validates inside every mutator). A broken law panics with its message.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(message) = topomech::cut::ops::run_bytes(data) {
        panic!("cut law broken: {message}");
    }
});

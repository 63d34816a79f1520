//! Fuzz target: any bytes are decoded by `topomech::ops` into kernel operations (byte 0 picks
//! the dimension 1, 2 or 3) and run from an empty map; every law of `ops::check_after_op` is
//! checked after every step, and the `expensive-checks` feature runs `validate()` inside every
//! mutator as well. A broken law panics with its message.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(message) = topomech::ops::run_bytes(data) {
        panic!("kernel law broken: {message}");
    }
});

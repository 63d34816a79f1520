//! Fuzz target: any bytes go to the mesh readers and the store through `topomech::io::fuzz`
//! (the first byte picks MSH, MSH triangles, TetGen, OBJ, the store, or all of them); every
//! reader must return, a rejection must name the file, an accepted mesh must be sound and build
//! a valid map, an accepted document must round-trip. A broken law panics with its message.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(message) = topomech::io::fuzz::run_bytes(data) {
        panic!("reader law broken: {message}");
    }
});

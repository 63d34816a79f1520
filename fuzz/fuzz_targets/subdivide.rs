//! Fuzz target: any bytes are decoded by `topomech::subdivide::fuzz` into a subdivision sequence
//! (edge splits, triangle 1→4, tet 1→8, refinement around a ball; 2D and 3D, any dart, levels
//! asked up to 3, a ball's balancing may go past it; in cut mode, bit 7 of byte 0, also face cuts
//! and saves and reloads whose copy gets every later op); after every op every level law is
//! checked (see the module docs). A broken law panics with its message.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(message) = topomech::subdivide::fuzz::run_bytes(data) {
        panic!("subdivision law broken: {message}");
    }
});

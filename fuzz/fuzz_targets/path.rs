//! Fuzz target: the path file reader and the course step (see `formation_fuzz::path`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::path(data);
});

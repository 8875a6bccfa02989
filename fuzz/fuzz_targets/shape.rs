//! Fuzz target: the shape file reader (see `formation_fuzz::shape`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::shape(data);
});

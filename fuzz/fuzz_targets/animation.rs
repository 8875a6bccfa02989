//! Fuzz target: the animation file reader (see `formation_fuzz::animation`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::animation(data);
});

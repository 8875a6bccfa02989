//! Fuzz target: the target file reader (see `formation_fuzz::target`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::target(data);
});

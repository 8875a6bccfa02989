//! Fuzz target: the params file reader (see `formation_fuzz::params`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::params(data);
});

//! Fuzz target: the bird model (.glb) reader and the exports that carry it (see
//! `formation_fuzz::bird_model`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::bird_model(data);
});

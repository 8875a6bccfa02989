//! Fuzz target: TRex's .npz reader (zip, deflate, .npy), then extraction.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::trex_npz(data);
});

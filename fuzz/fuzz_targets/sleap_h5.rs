//! Fuzz target: SLEAP's analysis HDF5 reader (HDF5 decoding, gzip chunks), then extraction.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::sleap_h5(data);
});

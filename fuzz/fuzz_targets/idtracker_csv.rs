//! Fuzz target: annotation reader, IdTracker format (a tracker's file), then extraction.
#![no_main]

use formation::annotations::Format;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::annotations(data, Format::IdTracker);
});

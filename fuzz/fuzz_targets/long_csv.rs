//! Fuzz target: annotation reader, LongCsv format (SPEC §4.1), then extraction.
#![no_main]

use formation::annotations::Format;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::annotations(data, Format::LongCsv);
});

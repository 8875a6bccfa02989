//! Fuzz target: an animation file with its frames in a frames file (the text, a zero byte, the
//! frames file's bytes), then what reading an animation goes on to do.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    formation_fuzz::animation_frames(data);
});

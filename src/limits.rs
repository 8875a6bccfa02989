//! Size limits shared by every stage: requests beyond them are refused up front, before
//! any work, with a one-line message naming the flag or file (exit 2), instead of running out of
//! memory, disk or patience hours later. They are far above what a line formation needs (the
//! paper's flocks have 5–30 birds) and are documented with their memory cost in
//! `docs/reliability.md`.
//!
//! Memory per *bird-frame* (one bird in one frame of an animation): 8 numbers × 8 bytes in
//! memory (about 130 bytes resident with copies), about 200 bytes of pretty-printed JSON on disk.
//! Hence the bound on the product birds × frames rather than on each factor alone.

/// Most birds in an animation (`steady.birds`, `birds` of an animation file).
pub const MAX_BIRDS: usize = 100_000;

/// Most birds in one formation's steady flight (`steady.birds` of a flock of one formation, and
/// each formation of a larger flock, see [`crate::skein`]). Algorithm 1 is
/// quadratic in a formation's birds (every pair interacts): measured on the shared 2-core machine,
/// 1000 birds take 1.7 s and 2000 birds 6.3 s for one key shape, so 5000 birds take about 40 s
/// and the 100 000 that [`MAX_BIRDS`] allows would have taken hours.
pub const MAX_FORMATION_BIRDS: usize = 5_000;

/// Most frames in an animation (`steady.frames`, or `seconds` × `steady.fps`): 9¼ hours at
/// 30 fps.
pub const MAX_FRAMES: usize = 1_000_000;

/// Most bird-frames (birds × frames) in an animation: 2·10⁷, e.g. 10 000 birds for a minute of
/// take-off and flight at 30 fps, or 1000 birds for 11 minutes. An animation takes 88 bytes per
/// bird-frame in memory, so 1.8 GB at the limit, and its file about 90 (126 for a wide sky of
/// formations, whose coordinates have more digits; 248 with `pretty`): within
/// [`crate::io::MAX_INPUT_BYTES`], so every file written can be read back.
pub const MAX_BIRD_FRAMES: usize = 20_000_000;

/// Most memory a run takes per bird-frame while it makes an animation (the take-off's history,
/// the frames, the wingbeats' work arrays), bytes: measured 110 at the peak of a 300-bird
/// take-off and 30 s flight; 160 leaves room.
pub const RUN_BYTES_PER_BIRD_FRAME: u64 = 160;

/// The memory this process may still use, bytes: the smaller of the machine's available memory
/// (`MemAvailable` in `/proc/meminfo`) and the address-space limit (`ulimit -v`, less what the
/// process has mapped already); `None` where neither is known. Checks of a request's size up
/// front compare with it, so that what cannot fit is refused before the work, not by running out.
pub fn memory_budget() -> Option<u64> {
    let kib = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line[key.len()..]
            .split_whitespace()
            .next()?
            .parse::<u64>()
            .ok()
    };
    let available = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| kib(&t, "MemAvailable:"))
        .map(|k| k.saturating_mul(1024));
    let limit = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|t| {
            let line = t.lines().find(|l| l.starts_with("Max address space"))?;
            let soft = line["Max address space".len()..]
                .split_whitespace()
                .next()?;
            let soft: u64 = soft.parse().ok()?;
            let used = std::fs::read_to_string("/proc/self/status")
                .ok()
                .and_then(|s| kib(&s, "VmSize:"))
                .map_or(0, |k| k.saturating_mul(1024));
            Some(soft.saturating_sub(used))
        });
    match (available, limit) {
        (Some(a), Some(l)) => Some(a.min(l)),
        (a, l) => a.or(l),
    }
}

/// Most pixels in one picture (width × height): 8K UHD, 7680 × 4320.
pub const MAX_FRAME_PIXELS: u64 = 7680 * 4320;

/// Most pixels over all frames of one picture output (GIF or PNG frames), frames × width ×
/// height: 2·10¹⁰, i.e. 20 GB of raw 8-bit frames (a GIF compresses it to a few percent). E.g.
/// 1920 × 1080 at 25 fps allows about 6½ minutes; a request for a 10-GB GIF is far beyond it.
pub const MAX_PICTURE_PIXELS: u64 = 20_000_000_000;

/// Most birds in a shape or target (`power`, `solve`). `power` is quadratic in birds (10 000
/// birds: about a second); one `formation solve` of 10 000 birds from a perturbed start takes
/// about 2 s on the shared 2-core machine under load 8–10 (a progress bar shows from 1000 birds;
/// `docs/performance.md`).
pub const MAX_SHAPE_BIRDS: usize = 10_000;

/// Largest coordinate in an animation file or shape, wingspans in magnitude (10⁷ wingspans is
/// 15 000 km of 1.5 m birds): every exported number then stays well inside f32 (glTF, USD) and
/// keeps centimetre precision.
pub const MAX_COORDINATE: f64 = 1e7;

/// Smallest wingspan of a bird, metres (1 cm; the smallest birds span about 10 cm): below it
/// the exported geometry underflows to zero.
pub const MIN_WINGSPAN_M: f64 = 0.01;

/// Largest `wingspan_m` of an animation file, metres (a flock of 747s is 68 m).
pub const MAX_WINGSPAN_M: f64 = 1000.0;

/// Largest frame rate of an animation file, frames per second.
pub const MAX_FPS: f64 = 10_000.0;

/// Largest magnitude of other per-frame numbers of an animation file (headings and wing phases
/// in radians, speeds in wingspans per second, savings): far beyond any flight, inside f32.
pub const MAX_FRAME_VALUE: f64 = 1e9;

/// Checks the bird count of a shape or target, naming `what`.
pub fn check_shape_size(what: &str, birds: usize) -> crate::Result<()> {
    if birds > MAX_SHAPE_BIRDS {
        return Err(crate::Error::parameter(
            what,
            format!("{birds} birds: at most {MAX_SHAPE_BIRDS}"),
        ));
    }
    Ok(())
}

/// Most RANSAC samples per model and frame (`extract.max_samples`). Each sample costs a pass
/// over the frame's birds, so the limit bounds a frame of 1000 birds to about 3·10⁸ distance
/// evaluations (three families), well under a second; the default is 2000.
pub const MAX_RANSAC_SAMPLES: usize = 100_000;

/// Most birds marked in one annotated frame (matching ids across frames is cubic in this).
pub const MAX_ANNOTATED_BIRDS: usize = 1_000;

/// Most annotated frames in one annotation file or directory.
pub const MAX_ANNOTATED_FRAMES: usize = 100_000;

/// Largest spacing statistic of a params file (`mu_x`, `sigma_x`, `mu_y`, `sigma_y`), wingspans
/// in magnitude: neighbours in a formation are a wingspan or so apart. Found by fuzzing: a finite
/// but huge `sigma_x` (10⁹⁴) made the steady flight's ranges NaN.
pub const MAX_PARAM_SPACING: f64 = 100.0;

/// Largest coordinate or shape coefficient in a params file, in magnitude (the annotation readers
/// refuse birds more than a million wingspans from the image origin).
pub const MAX_PARAM_COORDINATE: f64 = 1e6;

/// Checks an animation's size: `birds`, `frames` and their product, naming `what` (a flag such
/// as `steady.frames`, or a file) in the message.
pub fn check_animation_size(what: &str, birds: usize, frames: usize) -> crate::Result<()> {
    let err = |msg: String| Err(crate::Error::parameter(what, msg));
    if birds > MAX_BIRDS {
        return err(format!("{birds} birds: at most {MAX_BIRDS}"));
    }
    if frames > MAX_FRAMES {
        return err(format!(
            "{frames} frames: at most {MAX_FRAMES} (9 hours at 30 fps); shorten the animation"
        ));
    }
    match birds.checked_mul(frames) {
        Some(p) if p <= MAX_BIRD_FRAMES => Ok(()),
        _ => err(format!(
            "{birds} birds × {frames} frames is more than {MAX_BIRD_FRAMES} bird-frames (memory and file size); use fewer birds or frames"
        )),
    }
}

/// Lightest body mass accepted, kg (the smallest hummingbirds weigh about 2 g): a lighter mass
/// is a unit slip, and far lighter ones make the power curve's numbers underflow.
pub const MIN_BIRD_MASS_KG: f64 = 0.0015;

/// Heaviest body mass accepted, kg (no flying bird is heavier than about 20 kg).
pub const MAX_BIRD_MASS_KG: f64 = 50.0;

/// Fastest airspeed accepted, m/s.
pub const MAX_AIRSPEED_MS: f64 = 100.0;

/// Checks a body mass in kilograms (positive, from [`MIN_BIRD_MASS_KG`] to
/// [`MAX_BIRD_MASS_KG`]); the error names `what`. A mass no bird has would make every saving
/// of total power NaN or nonsense.
pub fn check_bird_mass(what: &str, kg: f64) -> crate::Result<()> {
    let err = |msg: String| Err(crate::Error::parameter(what, msg));
    if !(kg.is_finite() && kg > 0.0) {
        return err(format!(
            "{kg}: the body mass (kg) must be a positive number"
        ));
    }
    if kg < MIN_BIRD_MASS_KG {
        return err(format!(
            "{kg}: no flying bird is lighter than about 2 g; give the mass in kilograms"
        ));
    }
    if kg > MAX_BIRD_MASS_KG {
        return err(format!(
            "{kg}: no flying bird is heavier than about 20 kg; give the mass in kilograms"
        ));
    }
    Ok(())
}

/// Checks an airspeed in m/s (in (0, [`MAX_AIRSPEED_MS`]]); the error names `what`.
pub fn check_airspeed(what: &str, ms: f64) -> crate::Result<()> {
    if ms.is_finite() && ms > 0.0 && ms <= MAX_AIRSPEED_MS {
        Ok(())
    } else {
        Err(crate::Error::parameter(
            what,
            format!("{ms}: the airspeed must be a number of metres per second in (0, 100]"),
        ))
    }
}

/// Largest first frame number of an animation's outputs (`start_frame`): far beyond a studio's
/// 1001, and small enough that 32-bit glTF key times keep sub-frame samples apart.
pub const MAX_START_FRAME: u64 = 1_000_000;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked_without_overflow() {
        assert!(check_animation_size("steady.frames", 9, 300).is_ok());
        assert!(check_animation_size("steady.frames", 100, 100_000).is_ok());
        for (b, f) in [
            (1_000_000, 10),
            (9, 10_000_000),
            (10_000, 10_000),
            (usize::MAX, usize::MAX),
        ] {
            let e = check_animation_size("steady.frames", b, f).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            assert!(e.to_string().starts_with("steady.frames: "), "{e}");
        }
    }
}

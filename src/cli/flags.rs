//! The one table from library option paths (`initiate.max_turn_rate`, see
//! `formation::pipeline::Config`) to the flags of each command. Library errors name option paths;
//! [`name_flags`] rewrites every path that the command that was run has a flag for, in the error's
//! name and in its message, so that every message names a flag that exists for that command.
//! Paths without a flag (options only a config file can set) are left as they are. A row may
//! also hold a path with its value (`initiation false`), for a switch whose flag sets that value.

use formation::Error;

/// The commands (and `plot` charts) whose flags the table knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cmd {
    /// `formation extract`.
    Extract,
    /// `formation power`.
    Power,
    /// `formation solve`.
    Solve,
    /// `formation steady`.
    Steady,
    /// `formation initiate`.
    Initiate,
    /// `formation animate`.
    Animate,
    /// `formation render`.
    Render,
    /// `formation plot power`.
    PlotPower,
    /// `formation plot xi`.
    PlotXi,
    /// `formation plot shape`.
    PlotShape,
    /// `formation plot paths`.
    PlotPaths,
    /// `formation plot wingbeat`.
    PlotWingbeat,
    /// `formation plot savings`.
    PlotSavings,
    /// `formation report`.
    Report,
    /// `formation track`.
    Track,
    /// `formation annotate`.
    Annotate,
    /// `formation view`.
    View,
}

use Cmd::*;

const READ: &[Cmd] = &[Extract, PlotShape, Animate, Report, Annotate];
const FIT: &[Cmd] = &[Extract, PlotShape, Report];
const STEADY: &[Cmd] = &[Steady, Animate];
const INITIATE: &[Cmd] = &[Initiate, Animate];
const WINGBEAT: &[Cmd] = &[Steady, Initiate, Animate];
const PICTURES: &[Cmd] = &[Render, Animate];
const SCENE_COURSE: &[Cmd] = &[Steady, Initiate, Animate];
const SCENE: &[Cmd] = &[Steady, Initiate, Animate, Render];
/// Every command: an empty list in [`FLAGS`].
const EVERY: &[Cmd] = &[];

/// (option path, flag, commands that have the flag; [`EVERY`] for all). A path may appear several times with
/// different flags for different commands (`steady.frames` is `--frames` of `steady` but
/// `--seconds` of `animate`, which derives the frame count from the length).
pub const FLAGS: &[(&str, &str, &[Cmd])] = &[
    // The output files (`export::write_outputs`' `outputs`, `io::OutputKind`).
    ("output", "-o", EVERY),
    ("report", "--report", &[Steady]),
    ("review", "--review", &[Track]),
    ("track.polarity", "--polarity", &[Track]),
    ("track.every", "--every", &[Track]),
    ("track.frames", "--frames", &[Track]),
    ("track.roi", "--roi", &[Track]),
    ("track.fps", "--fps", &[Track]),
    ("track.wingspan_px", "--wingspan-px", &[Track]),
    ("track.debug_frames", "--debug-frames", &[Track]),
    ("annotate.images", "--images", &[Annotate]),
    ("read.heading", "--heading", READ),
    ("read.wingspan_px", "--wingspan-px", READ),
    ("read.y_origin", "--y-origin", READ),
    ("read.bodypart", "--bodypart", READ),
    ("extract.inlier_threshold", "--threshold", FIT),
    ("extract.kind", "--kind", FIT),
    ("extract.max_samples", "--max-samples", FIT),
    ("extract.j_offset", "--j-offset", FIT),
    ("extract.wingspan_m", "--wingspan-m", &[Extract, Report]),
    ("solve.tolerance", "--tolerance", &[Solve]),
    ("seconds", "--seconds", &[Animate, Steady]),
    ("shot_seconds", "--shot-seconds", &[Animate]),
    ("steady.birds", "--birds", STEADY),
    ("steady.frames", "--frames", &[Steady]),
    ("steady.frames", "--seconds", &[Animate]),
    ("steady.fps", "--fps", STEADY),
    ("steady.keys.key_every_s", "--key-every", STEADY),
    ("steady.speed", "--speed", STEADY),
    ("steady.keys.epsilon", "--epsilon", STEADY),
    ("steady.keys.c1", "--c1", STEADY),
    ("steady.keys.c2", "--c2", STEADY),
    ("steady.wingspan_m", "--wingspan-m", STEADY),
    ("steady.flight.mass_kg", "--mass-kg", STEADY),
    ("steady.flight.speed_ms", "--speed-ms", STEADY),
    ("aero.core_radius", "--core-radius", STEADY),
    ("aero.model", "--aero-model", STEADY),
    ("aero.wake", "--wake", STEADY),
    ("steady.keys.max_jump", "--max-jump", STEADY),
    ("steady.jostle.scale", "--jostle", STEADY),
    (
        "steady.reorganise.leader_changes",
        "--leader-changes",
        STEADY,
    ),
    ("steady.reorganise.swaps", "--swaps", STEADY),
    ("steady.reorganise.joiners", "--joiners", STEADY),
    (
        "extract.footage_fps",
        "--footage-fps",
        &[Extract, Report, Animate],
    ),
    ("steady.loop", "--loop", STEADY),
    ("land", "--land", SCENE_COURSE),
    ("landing.surface", "--land-on", SCENE_COURSE),
    ("course.path", "--path", SCENE_COURSE),
    ("course.units", "--path-units", SCENE_COURSE),
    ("course.cruise_altitude", "--cruise-altitude", STEADY),
    ("skein.formations", "--formations", STEADY),
    // `initiate` reads a steady flight, whose formations the steady flight's command made.
    (
        "skein.formations 1",
        "`formation steady` with --formations 1",
        &[Initiate],
    ),
    // `animate` has the take-off on unless `--no-initiation`.
    ("initiation false", "--no-initiation", &[Animate]),
    ("skein.formation_size", "--formation-size", STEADY),
    ("skein.clearance", "--clearance", STEADY),
    ("skein.layout", "--skein-layout", STEADY),
    ("initiate.max_steps", "--max-steps", INITIATE),
    ("initiate.max_time", "--max-seconds", INITIATE),
    ("initiate.perception.mode", "--perception", INITIATE),
    (
        "initiate.perception.mode.hpr.gamma",
        "--hpr-gamma",
        INITIATE,
    ),
    ("initiate.perception.fov_per_eye", "--fov", INITIATE),
    (
        "initiate.perception.reference_cone",
        "--reference-cone",
        INITIATE,
    ),
    ("initiate.alpha", "--alpha", INITIATE),
    ("initiate.k", "--k", INITIATE),
    ("initiate.max_turn_rate", "--max-turn-rate", INITIATE),
    ("initiate.max_accel", "--max-accel", INITIATE),
    ("initiate.min_speed", "--min-speed", INITIATE),
    ("initiate.max_speed", "--max-speed", INITIATE),
    ("initiate.separation_distance", "--separation", INITIATE),
    ("initiate.avoid_distance", "--avoid-distance", INITIATE),
    ("initiate.tolerance", "--tolerance", INITIATE),
    ("initiate.hold", "--hold", INITIATE),
    ("initiate.start", "--start", INITIATE),
    ("initiate.takeoff", "--takeoff", INITIATE),
    ("initiate.ground_seconds", "--ground-seconds", INITIATE),
    ("initiate.cruise_altitude", "--cruise-altitude", INITIATE),
    ("initiate.climb_rate", "--climb-rate", INITIATE),
    (
        "initiate.start.ground.width/initiate.start.ground.depth",
        "--start-width/--start-depth",
        INITIATE,
    ),
    ("initiate.start.width", "--start-width", INITIATE),
    ("initiate.start.depth", "--start-depth", INITIATE),
    (
        "initiate.start.heading_spread",
        "--heading-spread",
        INITIATE,
    ),
    ("initiate.start.ground.width", "--start-width", INITIATE),
    ("initiate.start.ground.depth", "--start-depth", INITIATE),
    (
        "initiate.start.ground.heading_spread",
        "--heading-spread",
        INITIATE,
    ),
    ("initiate.start.random.width", "--start-width", INITIATE),
    ("initiate.start.random.depth", "--start-depth", INITIATE),
    (
        "initiate.start.random.heading_spread",
        "--heading-spread",
        INITIATE,
    ),
    ("wingbeat.species", "--species", WINGBEAT),
    ("wingbeat.species", "--species", &[PlotWingbeat]),
    ("wingbeat.phase_mode", "--phase", WINGBEAT),
    ("wingbeat.glide", "--glide", WINGBEAT),
    ("wingbeat.variation", "--wing-variation", WINGBEAT),
    // Width and height are one flag, `--size WxH`.
    ("render.width/render.height", "--size", PICTURES),
    ("render.width", "--size", PICTURES),
    ("render.height", "--size", PICTURES),
    ("render.fps", "--picture-fps", &[Render, Animate]),
    ("render.wingspan_m", "--wingspan-m", &[Render]),
    ("render.keys", "--keys", SCENE),
    ("render.clips", "--clips", SCENE),
    ("render.start_frame", "--start-frame", SCENE),
    ("view.every", "--every", &[View]),
    ("render.subframes", "--subframes", SCENE),
    ("render.units", "--units", SCENE),
    ("render.up", "--up", SCENE),
    ("render.path_out", "--path-out", SCENE),
    ("render.binary_frames", "--binary-frames", SCENE),
    ("render.usd_mode", "--usd-mode", SCENE),
    ("render.gltf_mode", "--gltf-mode", SCENE),
    ("render.crowd_pose_error", "--crowd-pose-error", SCENE),
    ("render.animation_fps", "--fps", &[Render]),
    ("render.bird_model", "--bird-model", SCENE),
    ("render.joint_map", "--joint-map", SCENE),
    ("render.size_variation", "--size-variation", SCENE),
    ("render.camera", "--camera", PICTURES),
    ("render.camera.fixed", "--view", PICTURES),
    ("render.background", "--background", PICTURES),
    ("render.min_bird_px", "--min-bird-px", PICTURES),
    ("render.gif_tolerance", "--gif-tolerance", PICTURES),
    // Chart selections (`plot::power::PowerOf`, `plot::shape::ShapeChart::from_params`).
    ("plot.key", "--key", &[PlotPower]),
    ("plot.key/plot.frame", "--key/--frame", &[PlotPower]),
    (
        "plot.formation",
        "--formation",
        &[PlotPower, PlotXi, PlotPaths],
    ),
    ("plot.frame", "--frame", &[PlotPower, PlotShape]),
    (
        "plot.dpi",
        "--dpi",
        &[
            PlotPower,
            PlotXi,
            PlotShape,
            PlotPaths,
            PlotWingbeat,
            PlotSavings,
        ],
    ),
];

/// `text` with every option path that `cmd` has a flag for replaced by the flag. A path is
/// replaced only as a whole word (`steady.keys.c1` is not found in `steady.keys.c10`); longer paths first,
/// so that `render.width/render.height` becomes one `--size`. Paths without a dot (`seconds`,
/// `output`) are ordinary words in running text, so they are replaced only in an error's name
/// ([`rewrite_name`]); a path with its value (`initiation false`) is no ordinary phrase and is
/// replaced everywhere.
pub fn rewrite(cmd: Cmd, text: &str) -> String {
    replace_paths(cmd, text, true)
}

/// An error's name: the whole name may also be a top-level path without a dot.
pub fn rewrite_name(cmd: Cmd, name: &str) -> String {
    match FLAGS
        .iter()
        .find(|(p, _, cmds)| *p == name && applies(cmds, cmd))
    {
        Some((_, f, _)) => f.to_string(),
        None => replace_paths(cmd, name, true),
    }
}

/// Whether a row of [`FLAGS`] for `cmds` is a flag of `cmd`.
fn applies(cmds: &[Cmd], cmd: Cmd) -> bool {
    cmds.is_empty() || cmds.contains(&cmd)
}

fn replace_paths(cmd: Cmd, text: &str, dotted_only: bool) -> String {
    let mut paths: Vec<(&str, &str)> = FLAGS
        .iter()
        .filter(|(p, _, cmds)| {
            applies(cmds, cmd) && (!dotted_only || p.contains('.') || p.contains(' '))
        })
        .map(|(p, f, _)| (*p, *f))
        .collect();
    paths.sort_by_key(|(p, _)| std::cmp::Reverse(p.len()));
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    'scan: while i < text.len() {
        let before_ok = !matches!(text[..i].chars().next_back(), Some(c) if is_word(c));
        if before_ok {
            for (p, f) in &paths {
                if text[i..].starts_with(p) {
                    let rest = &text[i + p.len()..];
                    // A trailing full stop ends a sentence; any other word character continues
                    // a longer path.
                    let mut after = rest.chars();
                    let after_ok = match after.next() {
                        None => true,
                        Some('.') => !matches!(after.next(), Some(c) if is_word(c)),
                        Some(c) => !is_word(c),
                    };
                    if after_ok {
                        out.push_str(f);
                        i += p.len();
                        continue 'scan;
                    }
                }
            }
        }
        let c = text[i..].chars().next().unwrap_or(' ');
        out.push(c);
        i += c.len_utf8();
    }
    out
}

/// `e` with option paths replaced by the flags of `cmd` (see [`rewrite`]).
pub fn name_flags(cmd: Cmd, e: Error) -> Error {
    match e {
        Error::Parameter { name, message } => Error::Parameter {
            name: rewrite_name(cmd, &name),
            message: rewrite(cmd, &message),
        },
        Error::Format { path, message } => Error::Format {
            path,
            message: rewrite(cmd, &message),
        },
        Error::Unreachable(m) => Error::Unreachable(rewrite(cmd, &m)),
        Error::NotConverged(m) => Error::NotConverged(rewrite(cmd, &m)),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_become_the_flags_of_the_command() {
        assert_eq!(
            rewrite(Steady, "steady.frames: 0; lower steady.frames."),
            "--frames: 0; lower --frames."
        );
        assert_eq!(rewrite(Animate, "steady.frames: x"), "--seconds: x");
        assert_eq!(rewrite_name(Animate, "seconds"), "--seconds");
        assert_eq!(
            rewrite(Animate, "a number of seconds, got 1"),
            "a number of seconds, got 1"
        );
        assert_eq!(rewrite_name(Render, "output"), "-o");
        assert_eq!(rewrite(Animate, "render.fps: 3"), "--picture-fps: 3");
        assert_eq!(rewrite(Render, "render.fps: 3"), "--picture-fps: 3");
        assert_eq!(
            rewrite(Render, "give e.g. render.width/render.height 960x540"),
            "give e.g. --size 960x540"
        );
        // Only whole paths, and only those the command has.
        assert_eq!(
            rewrite(Steady, "steady.keys.c10 xsteady.keys.c1"),
            "steady.keys.c10 xsteady.keys.c1"
        );
        assert_eq!(rewrite(Steady, "steady.keys.c1: 2"), "--c1: 2");
        assert_eq!(rewrite(Extract, "steady.fps"), "steady.fps");
        assert_eq!(
            rewrite(Initiate, "initiate.min_speed/initiate.max_speed: x"),
            "--min-speed/--max-speed: x"
        );
        // Paths with a value: the switch that sets it, and a flag of the command that made
        // `initiate`'s input.
        assert_eq!(
            rewrite(Animate, "without the take-off (initiation false)"),
            "without the take-off (--no-initiation)"
        );
        assert_eq!(rewrite(Steady, "(initiation false)"), "(initiation false)");
        assert_eq!(
            rewrite(Initiate, "one formation (skein.formations 1)"),
            "one formation (`formation steady` with --formations 1)"
        );
        assert_eq!(
            rewrite(Animate, "one formation (skein.formations 1)"),
            "one formation (--formations 1)"
        );
    }
}

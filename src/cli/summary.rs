//! The one-paragraph summary that `animate`, `steady` and `initiate` print on stderr after
//! their outputs are committed: the shape learnt, the formations, the take-off time,
//! the flock's saving and the files written with their sizes. `--quiet` hides it.

use std::path::PathBuf;
use std::sync::Mutex;

use formation::animation::Animation;
use formation::extract::FormationParams;

/// Lines to print once every output is committed (their sizes are known then).
static DEFERRED: Mutex<Vec<(String, Vec<PathBuf>)>> = Mutex::new(Vec::new());

/// Prints `text` and the sizes of `outputs` after the command's outputs are committed.
pub fn defer(text: String, outputs: &[PathBuf]) {
    if let Ok(mut d) = DEFERRED.lock() {
        d.push((text, outputs.to_vec()));
    }
}

/// Prints what [`defer`] queued (called once the outputs exist).
pub fn print_deferred() {
    let items = DEFERRED
        .lock()
        .map(|mut d| std::mem::take(&mut *d))
        .unwrap_or_default();
    for (text, outputs) in items {
        let files: Vec<String> = outputs
            .iter()
            .map(|p| {
                format!(
                    "{} ({})",
                    super::stdout::file_name(p),
                    human_size(&size_of(p))
                )
            })
            .collect();
        if files.is_empty() {
            super::stdout::diagnostic(&text);
        } else {
            super::stdout::diagnostic(&format!("{text}\nwrote {}", files.join(", ")));
        }
        for p in &outputs {
            if let Some(hint) = binary_frames_hint(p) {
                super::stdout::diagnostic(&hint);
            }
            // A point-instanced crowd: its prototypes and the wing-pose error they make.
            if let Some((n, err)) = formation::export::crowd::recorded_pose_error(p) {
                super::stdout::diagnostic(&format!(
                    "{}: {n} prototypes; wing-pose error {err}",
                    super::stdout::file_name(p)
                ));
            }
        }
    }
}

/// Text animation files from this size up get a hint of `--binary-frames`.
const LARGE_JSON_BYTES: u64 = 1_000_000_000;

/// For an animation `.json` of [`LARGE_JSON_BYTES`] or more (a frames file beside a JSON keeps
/// it small): that `--binary-frames` would write it in less than half the size.
fn binary_frames_hint(p: &std::path::Path) -> Option<String> {
    let json = p
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let size = std::fs::metadata(p).ok()?.len();
    (json && size >= LARGE_JSON_BYTES).then(|| {
        format!(
            "{}: {} of text; --binary-frames writes its frames to a single-precision file beside it, less than half the size, which every command reads back (docs/formats.md)",
            super::stdout::file_name(p),
            human_size(&size)
        )
    })
}

/// Bytes of a file, or of every file in a directory (PNG frames).
fn size_of(p: &std::path::Path) -> u64 {
    match std::fs::metadata(p) {
        Ok(m) if m.is_dir() => std::fs::read_dir(p)
            .map(|rd| {
                rd.filter_map(|e| e.ok())
                    .filter_map(|e| e.metadata().ok())
                    .map(|m| m.len())
                    .sum()
            })
            .unwrap_or(0),
        Ok(m) => m.len(),
        Err(_) => 0,
    }
}

/// `7.3 MB`, `12 kB`, `512 B`.
pub fn human_size(bytes: &u64) -> String {
    let b = *bytes as f64;
    if b >= 1e6 {
        format!("{:.1} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.0} kB", b / 1e3)
    } else {
        format!("{bytes} B")
    }
}

/// The kinds fitted over the frames of `p`: `V in 20/20 frames`.
pub fn kinds_text(p: &FormationParams) -> String {
    let parts: Vec<String> = p
        .kind_counts()
        .iter()
        .map(|(k, c)| format!("{} in {c}/{}", k.to_uppercase(), p.frames.len()))
        .collect();
    format!("{} frames", parts.join(", "))
}

/// The summary of an animation: `what` names the command.
pub fn animation_text(what: &str, anim: &Animation, params: Option<&FormationParams>) -> String {
    animation_text_with(what, anim, params, None)
}

/// When the take-off's V formed and how long the climb took, for the summary:
/// `V formed after 8.9 s, climb to cruise height 20.4 s` (the climb from the first lift-off
/// until every bird is at the cruise altitude and level).
pub fn takeoff_text(s: &formation::initiate::InitiateStats) -> Option<String> {
    let mut parts = Vec::new();
    match s.formed_seconds {
        Some(t) => parts.push(format!("V formed after {t:.1} s")),
        None => parts.push("the V did not form".to_string()),
    }
    if let Some(t) = s.cruise_height_seconds {
        parts.push(format!(
            "climb to cruise height {:.1} s",
            (t - s.first_liftoff).max(0.0)
        ));
    }
    Some(parts.join(", "))
}

/// [`animation_text`] with the take-off's details from its statistics `takeoff`.
pub fn animation_text_with(
    what: &str,
    anim: &Animation,
    params: Option<&FormationParams>,
    takeoff: Option<&formation::initiate::InitiateStats>,
) -> String {
    let s = formation::animation::stats::AnimationStats::of(anim);
    let mut parts = vec![format!("{what}: {} birds", anim.birds)];
    if let Some(p) = params {
        parts.push(format!(
            "shape {} (learnt from {})",
            dominant(p),
            kinds_text(p)
        ));
    }
    parts.push(format!(
        "{} formation{}",
        s.formations,
        if s.formations == 1 { "" } else { "s" }
    ));
    if let Some(t) = s.takeoff_s {
        match takeoff.and_then(takeoff_text) {
            Some(d) => parts.push(format!("take-off {t:.1} s ({d})")),
            None => parts.push(format!("take-off {t:.1} s")),
        }
    }
    if let Some(t) = s.steady_s {
        parts.push(format!("steady flight {t:.1} s"));
    }
    if let Some(t) = s.landing_s {
        parts.push(format!("landing {t:.1} s"));
    }
    if let Some(line) = s
        .steady_saving
        .and_then(|e| super::savings::animation_line(anim, e))
    {
        parts.push(line);
    }
    parts.join(", ")
}

/// The most frequent kind of `p`, upper case.
pub fn dominant(p: &FormationParams) -> String {
    p.kind_counts()
        .first()
        .map_or("?".into(), |(k, _)| k.to_uppercase())
}

/// `initiate`'s summary (one call from its command, so that its file stays its own).
pub fn initiate(
    g: super::Global,
    anim: &Animation,
    stats: &formation::initiate::InitiateStats,
    outputs: &[PathBuf],
) {
    if g.quiet {
        return;
    }
    let mut text = animation_text_with("initiate", anim, None, Some(stats));
    if !stats.converged {
        text.push_str(" (the take-off did not converge)");
    }
    defer(text, outputs);
}

/// `animate`'s summary.
pub fn animate(
    g: super::Global,
    anim: &Animation,
    report: &formation::pipeline::Report,
    outputs: &[PathBuf],
) {
    if g.quiet {
        return;
    }
    let mut text = animation_text_with(
        "animate",
        anim,
        Some(&report.params),
        report.initiate.as_ref(),
    );
    if report.initiate.as_ref().is_some_and(|s| !s.converged) {
        text.push_str(" (the take-off did not converge)");
    }
    text.push_str(&clearance_text(anim));
    defer(text, outputs);
}

/// The clearance of what was written: the clash count per stage (the wing and body test of
/// docs/formats.md; 0 is the expectation) and the closest approach.
pub fn clearance_text(anim: &Animation) -> String {
    use formation::animation::clearance::Clearance;
    let mut all = Clearance::default();
    let mut where_ = Vec::new();
    for (name, c) in Clearance::by_stage(anim) {
        if c.clashes() > 0 {
            where_.push(format!("{} in the {name}", c.clashes()));
        }
        all.add(&c);
    }
    let closest = all.closest.map_or(String::new(), |c| {
        format!(
            ", closest {:.2} wingspans (birds {} and {}, frame {})",
            c.distance, c.birds.0, c.birds.1, c.frame
        )
    });
    if all.clashes() == 0 {
        format!("; clearance: no two birds clash in any frame{closest}")
    } else {
        format!(
            "; clearance: {} wing and {} body clashes in {} frames ({}){closest}",
            all.wing,
            all.body,
            all.frames_with_clash,
            where_.join(", ")
        )
    }
}

/// `solve`'s summary: converged or not, the residual, the evaluations, the flock's total E.
pub fn solve(
    g: super::Global,
    birds: usize,
    rep: &formation::keyshape::solve::SolveReport,
    tolerance: f64,
    aero: &formation::aero::AeroOptions,
    output: &std::path::Path,
) {
    if g.quiet {
        return;
    }
    defer(
        format!(
            "solve: {birds} birds, {} (residual ‖ξ − ξ̂‖ = {:.2e}, tolerance {:.1e}) after {} evaluations; E = {:.4} by Hummel's model, core {} wingspans (the key shape lies in one plane, where both wakes agree)",
            if rep.converged { "converged" } else { "NOT converged" },
            rep.residual,
            tolerance,
            rep.evaluations,
            rep.total,
            aero.core_radius
        ),
        &[output.to_path_buf()],
    );
}

/// `render`'s summary: what was written (the animation's frames at the rate they were written
/// at, resampled by `--fps` or not, and the picture outputs' frames and rate), from which file.
pub fn render(
    g: super::Global,
    anim: &Animation,
    opts: &formation::export::RenderOptions,
    input: &std::path::Path,
    outputs: &[PathBuf],
) {
    if g.quiet {
        return;
    }
    defer(render_text(anim, opts, input, outputs), outputs);
}

/// The text of [`render`]'s summary line.
pub fn render_text(
    anim: &Animation,
    opts: &formation::export::RenderOptions,
    input: &std::path::Path,
    outputs: &[PathBuf],
) -> String {
    use formation::io::OutputKind;
    let stages: Vec<&str> = anim.stages.iter().map(|s| s.name.as_str()).collect();
    let stages = if stages.is_empty() {
        "no stages".to_string()
    } else {
        stages.join(" + ")
    };
    let (frames, fps) = match opts.animation_fps {
        Some(f) if f != anim.fps => (formation::animation::resample::resampled_count(anim, f), f),
        _ => (anim.frames.len(), anim.fps),
    };
    let resampled = if fps != anim.fps {
        format!(
            ", resampled from {} frames at {} fps",
            anim.frames.len(),
            anim.fps
        )
    } else {
        String::new()
    };
    let mut text = format!(
        "render: {} birds, {frames} frames at {fps} fps ({:.1} s; {stages}{resampled}) from {}",
        anim.birds,
        frames as f64 / fps,
        super::stdout::file_name(input)
    );
    // The picture outputs: their frame count at their own rate.
    let mut shown = Vec::new();
    for o in outputs {
        let ext = o
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        let kind = match ext.as_deref() {
            Some("gif") => OutputKind::Gif,
            Some("mp4") => OutputKind::Mp4,
            Some("webm") => OutputKind::Webm,
            _ if o.is_dir() => OutputKind::Directory,
            _ => continue,
        };
        // The pictures are drawn from the (resampled) animation; their count depends only on
        // its time span and the picture rate.
        let pfps = formation::export::picture_fps(anim, kind, opts);
        let n = formation::export::sample::output_count(anim, pfps);
        let t = format!("{n} pictures at {} fps", (pfps * 1000.0).round() / 1000.0);
        if !shown.contains(&t) {
            shown.push(t);
        }
    }
    if !shown.is_empty() {
        text.push_str(&format!(
            "; {} ({}x{})",
            shown.join(", "),
            opts.width,
            opts.height
        ));
    }
    text
}

/// A chart's or a page's summary: `what` says what it shows.
pub fn chart(
    g: super::Global,
    command: &str,
    what: &str,
    input: &std::path::Path,
    output: &std::path::Path,
) {
    if g.quiet {
        return;
    }
    defer(
        format!(
            "{command}: {what}, from {}",
            super::stdout::file_name(input)
        ),
        &[output.to_path_buf()],
    );
}

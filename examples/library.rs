//! formation as a library, in a few lines: a V of nine geese marked by hand in three video frames
//! (image pixels, kept in memory — no file) → the whole pipeline (§4 extraction, §5 steady flight,
//! §6 take-off, wingbeats) → an `Animation` of 14 birds → a glTF binary for a DCC tool or engine.
//!
//! Then the two things a library user asks next: how a large flock is split into formations
//! (skeins) and how to keep it as one formation, and where each bird's power saving is.
//!
//! ```text
//! cargo run --release --example library -- flock.glb
//! ```

use formation::animation::stats::AnimationStats;
use formation::annotations::{Annotations, Heading};
use formation::export::{write_outputs, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;

fn main() -> formation::Result<()> {
    let annotations = hand_marked()?;

    let mut config = Config {
        seed: 7,
        seconds: Some(6.0),
        ..Config::default()
    };
    config.steady.birds = 14;
    let (animation, report) = Pipeline::from_annotations(annotations).run(&config)?;

    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "flock.glb".into());
    write_outputs(
        &animation,
        &[out.clone().into()],
        &RenderOptions::default(),
        &Silent,
    )?;
    println!(
        "{out}: {} birds, {} frames at {} fps ({} of take-off), {} key shapes",
        animation.birds,
        animation.frames.len(),
        animation.fps,
        report.initiate.map_or(0, |s| s.steps),
        report.steady.key_frames.len()
    );

    // Each bird's saving (the fraction of its solo induced power that the others' upwash saves
    // it, in steady flight) and its rank, from the animation itself.
    let stats = AnimationStats::of(&animation);
    if let Some(e) = stats.steady_saving {
        println!(
            "flock saving in steady flight: {:.1} % of induced power",
            100.0 * e
        );
    }
    for b in stats.birds.iter().take(3) {
        println!(
            "  bird {}: rank {:.1}{}, saving {:.1} %",
            b.bird,
            b.rank,
            if b.leader { " (leader)" } else { "" },
            100.0 * b.saving
        );
    }

    // A flock more than twice the footage's size (here 9 birds) flies as several formations of
    // about the footage's size, as real skeins do: `report.skein` says how it was split.
    config.steady.birds = 30;
    config.seconds = Some(2.0);
    config.initiation = false;
    let pipeline = Pipeline::from_annotations(hand_marked()?);
    let (_, report) = pipeline.run(&config)?;
    if let Some(skein) = &report.skein {
        println!(
            "30 birds: {} formations of {:?} birds",
            skein.formations.len(),
            skein.sizes
        );
    }
    // `skein.formations = Some(1)` keeps all of them in one formation (a V of 30).
    config.skein.formations = Some(1);
    let (one, report) = pipeline.run(&config)?;
    println!(
        "30 birds, skein.formations = 1: {} formation(s), {} birds",
        report.skein.map_or(1, |s| s.formations.len()),
        one.birds
    );
    Ok(())
}

/// Three frames of a 9-bird V flying up the image, 40 px per wingspan: leader at the apex,
/// four birds down each arm, a little jitter between frames.
fn hand_marked() -> formation::Result<Annotations> {
    let frames: Vec<Vec<[f64; 2]>> = (0..3)
        .map(|f| {
            let jitter = 1.5 * f as f64;
            (0..9)
                .map(|i| {
                    let rank = ((i + 1) / 2) as f64;
                    let side = if i % 2 == 1 { 1.0 } else { -1.0 };
                    [
                        480.0 + side * 36.0 * rank + jitter,
                        200.0 + 24.0 * rank - jitter,
                    ]
                })
                .collect()
        })
        .collect();
    Annotations::from_points("hand-marked geese", Heading::Up, 40.0, &frames)
}

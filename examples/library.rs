//! formation as a library, in a few lines: a V of nine geese marked by hand in three video frames
//! (image pixels, kept in memory — no file) → the whole pipeline (§4 extraction, §5 steady flight,
//! §6 take-off, wingbeats) → an `Animation` of 14 birds → a glTF binary for a DCC tool or engine.
//!
//! ```text
//! cargo run --release --example library -- flock.glb
//! ```

use formation::annotations::{Annotations, Heading};
use formation::export::{write_outputs, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;

fn main() -> formation::Result<()> {
    // Three frames of a 9-bird V flying up the image, 40 px per wingspan: leader at the apex,
    // four birds down each arm, a little jitter between frames.
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
    let annotations = Annotations::from_points("hand-marked geese", Heading::Up, 40.0, &frames)?;

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
    Ok(())
}

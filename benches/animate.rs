//! The main job end to end: what `formation animate examples_data/barnacle_geese_v.json
//! --birds 14 -o flock.gif` does (read and extract the 9-goose annotations, 20 s of steady flight
//! at 30 fps for 14 birds, the take-off before it, wingbeats, the 960×540 GIF), and the same
//! without the GIF (the simulation alone). Results: docs/performance.md.

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use formation::annotations::ReadOptions;
use formation::export::{write_outputs, RenderOptions};
use formation::extract::{params_from_path, ExtractOptions};
use formation::keyshape::steady::{steady_flight, SteadyOptions};
use formation::progress::Silent;
use formation::{initiate, rng, wingbeat, Animation};

fn simulate() -> Animation {
    let input = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    let params = params_from_path(
        &input,
        &ReadOptions::default(),
        &ExtractOptions::default(),
        &mut rng::stream(0, "extract"),
    )
    .unwrap();
    let opts = SteadyOptions {
        birds: 14,
        frames: 600,
        ..SteadyOptions::default()
    };
    let steady = steady_flight(&params, &opts, &mut rng::stream(0, "steady"), &Silent).unwrap();
    let (mut anim, _) = initiate::initiate(
        &steady,
        &initiate::InitiateOptions::default(),
        &mut rng::stream(0, "initiate"),
        &Silent,
    )
    .unwrap();
    wingbeat::assign_phases(&mut anim, &wingbeat::WingbeatOptions::default()).unwrap();
    anim
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("animate");
    g.sample_size(10);
    g.bench_function("geese_14_birds_20s_simulation", |b| b.iter(simulate));
    let dir = std::env::temp_dir().join(format!("formation-bench-animate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gif: PathBuf = dir.join("flock.gif");
    let anim = simulate();
    eprintln!(
        "animation: {} frames ({} s) of which {} take-off",
        anim.frames.len(),
        anim.frames.len() as f64 / anim.fps,
        anim.stage("initiation").map_or(0, |s| s.end - s.start)
    );
    g.bench_function("geese_14_birds_20s_with_gif_960x540", |b| {
        b.iter(|| {
            let anim = simulate();
            write_outputs(
                &anim,
                std::slice::from_ref(&gif),
                &RenderOptions::default(),
                &Silent,
            )
            .unwrap()
        })
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);

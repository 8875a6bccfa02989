//! Shared bodies of the fuzz targets: each takes arbitrary bytes and runs exactly what the
//! `formation` binary runs on a file of that content (the library's `pipeline` stages), then a cheap downstream
//! consumer of whatever was accepted. Every call must return `Ok` or `Err`: a panic, a hang
//! (libFuzzer `-timeout`) or an allocation beyond `-rss_limit_mb` is a finding.

use std::path::Path;

use formation::annotations::{parse_str, Format, Heading, ReadOptions};
use formation::pipeline::{extract_stage, steady_stage, Config};
use formation::progress::Silent;

/// The path named in messages (no file is read or written).
pub const PATH: &str = "fuzz-input";

/// UTF-8 text of the input, as `io::read_text` would accept it.
pub fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// Annotation readers: `formation extract FILE` reads with `annotations::read` → `parse_str`,
/// then extracts. Runs both with the file's own settings and with `--wingspan-px`/`--heading`
/// overrides (CSV files carry no scale), and extracts with a small sample budget.
pub fn annotations(data: &[u8], expect: Format) {
    let Some(t) = text(data) else { return };
    let options = [
        ReadOptions::default(),
        ReadOptions {
            wingspan_px: Some(20.0),
            heading: Some(Heading::Degrees(-30.0)),
            ..ReadOptions::default()
        },
    ];
    for o in &options {
        if let Ok(ann) = parse_str(Path::new(PATH), t, o) {
            // Another format than the target's is fine (detection is by content), but the
            // downstream stage only runs for the target's own format to keep executions fast.
            if ann.format != expect {
                continue;
            }
            let mut config = Config::default();
            config.extract.max_samples = 64;
            let _ = extract_stage(&ann, &config, &Silent);
        }
    }
}

/// TRex's `.npz` reader (one individual's archive: zip, deflate, `.npy` headers), then
/// extraction of whatever it accepts, with a scale and heading given.
pub fn trex_npz(data: &[u8]) {
    let o = ReadOptions {
        wingspan_px: Some(20.0),
        heading: Some(Heading::Degrees(90.0)),
        ..ReadOptions::default()
    };
    if let Ok(ann) = formation::annotations::parse_trex_bytes(Path::new(PATH), data, &o) {
        let mut config = Config::default();
        config.extract.max_samples = 64;
        let _ = extract_stage(&ann, &config, &Silent);
    }
}

/// SLEAP's analysis HDF5 reader (the pure-Rust HDF5 decoder: superblock, object headers,
/// B-trees, gzip chunks, strings), then extraction of whatever it accepts.
pub fn sleap_h5(data: &[u8]) {
    let o = ReadOptions {
        wingspan_px: Some(20.0),
        heading: Some(Heading::Degrees(90.0)),
        ..ReadOptions::default()
    };
    if let Ok(ann) =
        formation::annotations::parse_sleap_h5_bytes(Path::new(PATH), data.to_vec(), &o)
    {
        let mut config = Config::default();
        config.extract.max_samples = 64;
        let _ = extract_stage(&ann, &config, &Silent);
    }
}

/// Params file (`formation steady PARAMS`, `plot shape PARAMS`): `FormationParams::read` is
/// `io::parse_json` + `validate`; whatever validates drives a tiny steady flight (6 birds, 4 frames).
pub fn params(data: &[u8]) {
    use formation::extract::params::FormationParams;
    let Some(t) = text(data) else { return };
    let path = Path::new(PATH);
    let Ok(p) = formation::io::parse_json::<FormationParams>(path, t) else {
        return;
    };
    if p.validate(path).is_err() {
        return;
    }
    let mut config = Config {
        seconds: None,
        ..Config::default()
    };
    config.steady.birds = 6;
    config.steady.frames = 4;
    config.steady.keys.key_every_s = 0.05;
    let _ = steady_stage(&p, &config, &Silent);
}

/// Animation file (`render`, `initiate`, `plot xi|power|paths`): `Animation::read` is
/// `io::read_json_streaming` (the same reader, here over the bytes) + `validate`; `render` adds
/// `check_times`, `initiate` adds `check_steady`.
/// Whatever is accepted is exported in memory (CSV, glTF) and one picture frame is drawn small.
pub fn animation(data: &[u8]) {
    use formation::Animation;
    let path = Path::new(PATH);
    let input = formation::io::TextInput::new(path, data, formation::io::MAX_INPUT_BYTES);
    let Ok(a) = formation::io::parse_json_streaming::<Animation, _>(input) else {
        return;
    };
    accepted_animation(a);
}

/// An animation file whose frames are in a frames file: the input is the animation file's
/// text, a zero byte, then the frames file's bytes; read as `Animation::read` reads the pair
/// (the header parsed, then `animation::binary::read_frames_from`), then as [`animation`].
pub fn animation_frames(data: &[u8]) {
    use formation::Animation;
    let path = Path::new(PATH);
    let (head, frames) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &data[data.len()..]),
    };
    let input = formation::io::TextInput::new(path, head, formation::io::MAX_INPUT_BYTES);
    let Ok(mut a) = formation::io::parse_json_streaming::<Animation, _>(input) else {
        return;
    };
    let frames_path = Path::new("fuzz-input.frames");
    if formation::animation::binary::read_frames_from(
        &mut a,
        path,
        frames_path,
        frames,
        frames.len() as u64,
    )
    .is_err()
    {
        return;
    }
    accepted_animation(a);
}

/// What reading an animation file goes on to do with one it parsed: validation, then the checks
/// of `initiate` and `render`, and small exports of whatever is accepted.
fn accepted_animation(a: formation::Animation) {
    use formation::export::{gltf, pictures::Film, raster, sample, table};
    let path = Path::new(PATH);
    if a.validate(path).is_err() {
        return;
    }
    let _ = formation::initiate::check_steady(&a, path);
    let _ = formation::plot::paths::PathsChart::from_animation(&a);
    if sample::check_times(&a, path).is_err() {
        return;
    }
    let mut csv = Vec::new();
    let _ = table::write_csv(&a, &mut csv);
    let _ = gltf::glb_bytes(&a, a.wingspan_m);
    // As `export::write_outputs` does before drawing: refuse absurd frame counts first.
    if sample::output_count(&a, 25.0) > formation::export::MAX_FRAMES {
        return;
    }
    let film = Film::new(&a, 25.0, 32, 24);
    if !film.is_empty() {
        let mut canvas = raster::Canvas::new(32, 24);
        let mut mask = raster::Mask::new();
        film.draw(film.len() - 1, &mut canvas, &mut mask, true);
    }
}

/// Shape file (`formation power SHAPE`, `plot power SHAPE`): `io::parse_json::<Shape>`,
/// `validate(path, 2)`, then Hummel's power reduction.
pub fn shape(data: &[u8]) {
    use formation::Shape;
    let Some(t) = text(data) else { return };
    let path = Path::new(PATH);
    let Ok(s) = formation::io::parse_json::<Shape>(path, t) else {
        return;
    };
    if s.validate(path, 2).is_err() {
        return;
    }
    let _ = s.leader();
    let _ = formation::aero::power_reduction(&s.xs(), &s.ys());
}

/// Target file of `formation solve TARGET`: the same structure as the binary's (`src/cli/solve.rs`,
/// `deny_unknown_fields`), then `keyshape::solve` with the default options.
pub fn target(data: &[u8]) {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Target {
        x: Vec<f64>,
        xi: Vec<f64>,
        #[serde(default)]
        y: Option<Vec<f64>>,
    }
    let Some(t) = text(data) else { return };
    let path = Path::new(PATH);
    let Ok(target) = formation::io::parse_json::<Target>(path, t) else {
        return;
    };
    let opts = formation::keyshape::SolveOptions::default();
    let _ = formation::keyshape::solve(&target.x, &target.xi, target.y.as_deref(), &opts);
}

/// Two small steady flights (5 birds, 2 s at 10 fps, a key every second; one plain, one looped)
/// flown once, that the `path` target maps onto each accepted path (and `bird_model` exports).
fn path_flights() -> &'static [formation::Animation; 2] {
    use formation::extract::params::FormationParams;
    static FLIGHTS: std::sync::OnceLock<[formation::Animation; 2]> = std::sync::OnceLock::new();
    FLIGHTS.get_or_init(|| {
        let path = Path::new("steady_v9_params.json");
        let text = include_str!("../../tests/data/steady_v9_params.json");
        let p: FormationParams = formation::io::parse_json(path, text).expect("params");
        let fly = |looped: bool| {
            let mut config = Config {
                seconds: None,
                ..Config::default()
            };
            config.steady.birds = 5;
            config.steady.frames = 20;
            config.steady.fps = 10.0;
            // A loop needs at least one key interval.
            config.steady.keys.key_every_s = 1.0;
            config.steady.looped = looped;
            steady_stage(&p, &config, &Silent).expect("steady").0
        };
        [fly(false), fly(true)]
    })
}

/// Path file (`--path FILE` of `steady`, `initiate`, `animate`): `course::file::read` is
/// `io::read_text` + `course::file::parse_str`, tried with the file's units and with `--path-units
/// m`. Whatever is accepted goes through the course step (`pipeline::course_stage`: the
/// backwards check, turn widening, the loop's laps, banks and pitches) on a small plain and a
/// small looped steady flight.
pub fn path(data: &[u8]) {
    use formation::course::{file, PathUnits};
    let Some(t) = text(data) else { return };
    let origin = Path::new(PATH);
    for units in [None, Some(PathUnits::M)] {
        let Ok(points) = file::parse_str(origin, t, units, 1.5) else {
            continue;
        };
        for flight in path_flights() {
            let mut anim = flight.clone();
            let mut config = Config::default();
            config.course.path = Some(origin.to_path_buf());
            let _ = formation::pipeline::course_stage(&mut anim, Some(&points), &config);
        }
    }
}

/// Bird model (`--bird-model FILE.glb` of `render`, `steady`, `initiate`, `animate`):
/// `export::bird_model::load` is `io::read_bytes` + `bird_model::parse`. Whatever is accepted is
/// put on the birds of a small flight in a glTF binary and a USD text; a number in the USD text
/// that is not finite is a finding too (the model would have reached the file poisoned).
pub fn bird_model(data: &[u8]) {
    use formation::export::{bird_model, gltf, usd};
    use formation::wingbeat::Species;
    let Ok(asset) = bird_model::parse(Path::new(PATH), data, Species::Goose) else {
        return;
    };
    let anim = &path_flights()[0];
    let opts = gltf::SceneOptions {
        assets: vec![asset],
        ..gltf::SceneOptions::default()
    };
    let _ = gltf::glb_bytes_with(anim, 1.5, &opts);
    let mut text = Vec::new();
    if usd::write_usda(anim, 1.5, &opts, &mut text).is_ok() {
        let text = String::from_utf8_lossy(&text);
        let poisoned = text
            .split(|c: char| !c.is_ascii_alphanumeric())
            .any(|w| w == "NaN" || w == "inf");
        assert!(
            !poisoned,
            "a non-finite number in the USD text of an accepted bird model"
        );
    }
}

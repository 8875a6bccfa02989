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
            y_origin: None,
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
/// `io::parse_json` + `validate`; `render` adds `check_times`, `initiate` adds `check_steady`.
/// Whatever is accepted is exported in memory (CSV, glTF) and one picture frame is drawn small.
pub fn animation(data: &[u8]) {
    use formation::export::{gltf, pictures::Film, raster, sample, table};
    use formation::Animation;
    let Some(t) = text(data) else { return };
    let path = Path::new(PATH);
    let Ok(a) = formation::io::parse_json::<Animation>(path, t) else {
        return;
    };
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

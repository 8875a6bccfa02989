//! Pictures worth showing (issue 15): the follow camera's minimum bird size on real animations of
//! 14 and 100 birds, clouds without a tile period, transparent `--background none` frames, video
//! checked by ffprobe, and the one-line refusals of bad camera, background, view and video
//! requests.

use std::path::Path;
use std::process::Command;

use formation::export::{Background, CameraKind, Film, RenderOptions};
use formation::Animation;

mod support;

use support::{assert_usage_error, bin, run as formation, s, scratch as tmpdir};

const GEESE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples_data/barnacle_geese_v.json"
);
const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flock_small.json");

/// A real animation (extraction, steady flight, take-off) of `birds` geese.
fn animate(birds: usize, d: &Path) -> Animation {
    animate_for(birds, d, "6")
}

/// As [`animate`], with `seconds` of steady flight after the take-off.
fn animate_for(birds: usize, d: &Path, seconds: &str) -> Animation {
    let json = d.join(format!("flock{birds}_{seconds}.json"));
    // One formation of all birds: a larger flock would fly as several formations (issue 13),
    // which the follow camera frames whole (tests/skeins.rs).
    let out = formation(&[
        "animate",
        GEESE,
        "--birds",
        &birds.to_string(),
        "--formations",
        "1",
        "--seconds",
        seconds,
        "-o",
        s(&json),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Animation::read(&json).unwrap()
}

#[test]
fn follow_camera_never_draws_birds_below_the_minimum_size() {
    let d = tmpdir("minsize");
    for birds in [14, 100] {
        let anim = animate(birds, &d);
        for min in [12.0, 30.0] {
            let opts = RenderOptions {
                min_bird_px: min,
                ..RenderOptions::default()
            };
            let film = Film::with_options(&anim, 25.0, &opts);
            assert!(film.len() > 100);
            let mut in_view_lead = 0;
            for (k, v) in film.views.iter().enumerate() {
                let st = film.states(k);
                assert!(
                    v.scale() >= min - 1e-9,
                    "{birds} birds, min {min}: frame {k} draws {:.2} px per wingspan",
                    v.scale()
                );
                // Some bird is always in the picture (the camera follows the leaders).
                let seen = st.iter().any(|b| {
                    let (x, y) = v.to_pixel(b.x, b.y, 960, 540);
                    (0.0..960.0).contains(&x) && (0.0..540.0).contains(&y)
                });
                assert!(seen, "{birds} birds: frame {k} shows no bird");
                in_view_lead += seen as usize;
            }
            assert_eq!(in_view_lead, film.len());
            // Smooth: the zoom changes by under 4 % between frames.
            for w in film.views.windows(2) {
                assert!((w[1].scale() / w[0].scale() - 1.0).abs() < 0.04);
            }
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// Normalised autocorrelation of `v` at `lag`.
fn autocorr(v: &[f64], lag: usize) -> f64 {
    let n = v.len() - lag;
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var: f64 = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64;
    let c: f64 = (0..n).map(|i| (v[i] - m) * (v[i + lag] - m)).sum::<f64>() / n as f64;
    c / var.max(1e-12)
}

#[test]
fn clouds_have_no_tile_period_at_any_zoom() {
    // Cloud layers seen over a frame, zoomed far out (where a tiled texture shows its grid) and
    // in: the autocorrelation along each row, averaged over rows, falls off and never rises
    // again to a peak at some tile period.
    let anim = formation::export::synthetic::synthetic_flock(
        &mut formation::rng::seeded(1),
        &formation::export::synthetic::SyntheticParams {
            seconds: 1.0,
            ..Default::default()
        },
    );
    for half in [20.0, 2_000.0, 200_000.0] {
        let opts = RenderOptions {
            camera: CameraKind::Fixed([-half, -half * 0.5625, half, half * 0.5625]),
            ..RenderOptions::default()
        };
        let film = Film::with_options(&anim, 25.0, &opts);
        let (w, h) = (960usize, 540usize);
        for layer in 0..2 {
            let rows: Vec<Vec<f64>> = (0..h)
                .step_by(20)
                .map(|r| {
                    (0..w)
                        .map(|c| {
                            film.backdrop()
                                .cloud_alpha(&film.views[0], layer, c as f64, r as f64)
                                .unwrap() as f64
                        })
                        .collect()
                })
                .collect();
            let total: f64 = rows.iter().flatten().sum();
            // Zoomed in, a window may fall in clear sky; zoomed out every layer shows.
            assert!(
                total > 0.0 || half < 1000.0,
                "zoom {half}: layer {layer} shows no cloud at all"
            );
            let acf: Vec<f64> = (0..w / 2)
                .map(|lag| {
                    let rs: Vec<f64> = rows
                        .iter()
                        .filter(|r| r.iter().any(|&v| v != r[0]))
                        .map(|r| autocorr(r, lag))
                        .collect();
                    rs.iter().sum::<f64>() / rs.len().max(1) as f64
                })
                .collect();
            // Correlation length: first lag where the correlation drops under 0.2.
            let Some(l0) = acf.iter().position(|&a| a < 0.2) else {
                // Features wider than half the frame: no room for a tile to repeat.
                continue;
            };
            let peak = acf[2 * l0.max(4)..]
                .iter()
                .cloned()
                .fold(f64::MIN, f64::max);
            assert!(
                peak < 0.45,
                "view ±{half} wingspans, layer {layer}: autocorrelation rises to {peak:.2} after falling to 0.2 at lag {l0}"
            );
        }
    }
}

#[test]
fn background_none_writes_transparent_sky_and_opaque_birds() {
    let d = tmpdir("alpha");
    let frames = d.join("frames/");
    let out = formation(&[
        "render",
        FIXTURE,
        "-o",
        s(&frames),
        "--background",
        "none",
        "--size",
        "320x180",
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = image::open(d.join("frames/frame_00010.png")).unwrap();
    assert_eq!(png.color(), image::ColorType::Rgba8);
    let px = png.to_rgba8();
    let clear = px.pixels().filter(|p| p[3] == 0).count();
    let solid = px.pixels().filter(|p| p[3] == 255).count();
    assert!(clear > 320 * 180 * 8 / 10, "{clear} transparent pixels");
    assert!(solid > 50, "{solid} opaque (bird) pixels");
    assert_eq!(px.get_pixel(0, 0)[3], 0);
    // A flat colour fills every pixel.
    let frames2 = d.join("flat/");
    let out = formation(&[
        "render",
        FIXTURE,
        "-o",
        s(&frames2),
        "--background",
        "#102030",
        "--size",
        "320x180",
        "--quiet",
    ]);
    assert!(out.status.success());
    // In flight (the last frame) the flat colour fills the sky; the birds that sit at the start
    // are drawn on the field under them, laid over it.
    let mut names: Vec<_> = std::fs::read_dir(d.join("flat"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    let px = image::open(names.last().unwrap()).unwrap().to_rgb8();
    assert_eq!(px.get_pixel(0, 0).0, [0x10, 0x20, 0x30]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_camera_background_view_and_video_requests_exit_2_with_one_line() {
    let d = tmpdir("bad");
    let gif = d.join("a.gif");
    let g = s(&gif);
    let out = formation(&["render", FIXTURE, "-o", g, "--camera", "orbit"]);
    assert_usage_error(&out, &["--camera", "orbit", "follow, ground or fixed"]);
    let out = formation(&["render", FIXTURE, "-o", g, "--background", "blue"]);
    assert_usage_error(&out, &["--background", "blue"]);
    let out = formation(&[
        "render", FIXTURE, "-o", g, "--camera", "fixed", "--view", "0,0,0,5",
    ]);
    assert_usage_error(&out, &["--view", "zero"]);
    let out = formation(&["render", FIXTURE, "-o", g, "--camera", "fixed"]);
    assert_usage_error(&out, &["--view"]);
    let out = formation(&["render", FIXTURE, "-o", g, "--view", "1,2,3"]);
    assert_usage_error(&out, &["--view"]);
    let out = formation(&["render", FIXTURE, "-o", g, "--background", "none"]);
    assert_usage_error(&out, &["--background", "PNG frames"]);
    let out = formation(&["render", FIXTURE, "-o", g, "--min-bird-px", "-3"]);
    assert_usage_error(&out, &["--min-bird-px"]);
    // Video without ffmpeg: how to install it, and no file.
    let mp4 = d.join("a.mp4");
    let out = bin()
        .args(["render", FIXTURE, "-o", s(&mp4)])
        .env("FORMATION_FFMPEG", "/nonexistent/ffmpeg")
        .output()
        .unwrap();
    assert_usage_error(&out, &["a.mp4", "apt-get install ffmpeg"]);
    assert!(!mp4.exists() && !gif.exists());
    let out = formation(&["render", FIXTURE, "-o", s(&mp4), "--size", "321x180"]);
    assert_usage_error(&out, &["--size", "even"]);
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "nothing written");
    std::fs::remove_dir_all(&d).unwrap();
}

fn have(prog: &str) -> bool {
    Command::new(prog)
        .arg("-version")
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

fn probe(path: &Path) -> serde_json::Value {
    let out = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-count_frames",
            "-select_streams",
            "v:0",
            "-show_entries",
            "stream=codec_name,width,height,r_frame_rate,nb_read_frames:format=duration",
            "-of",
            "json",
        ])
        .arg(path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn ffprobe_agrees_with_frame_count_and_rate() {
    if !(have("ffmpeg") && have("ffprobe")) {
        eprintln!("skipped: ffmpeg/ffprobe not on PATH (apt-get install ffmpeg); CI installs them");
        return;
    }
    let d = tmpdir("video");
    let (mp4, webm) = (d.join("f.mp4"), d.join("f.webm"));
    let out = formation(&[
        "render",
        FIXTURE,
        "-o",
        s(&mp4),
        "-o",
        s(&webm),
        "--size",
        "320x180",
        "--picture-fps",
        "24",
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let anim = Animation::read(Path::new(FIXTURE)).unwrap();
    let frames = formation::export::sample::output_count(&anim, 24.0);
    for (p, codec) in [(&mp4, "h264"), (&webm, "vp9")] {
        let j = probe(p);
        let st = &j["streams"][0];
        assert_eq!(st["codec_name"], codec);
        assert_eq!(st["width"], 320);
        assert_eq!(st["height"], 180);
        assert_eq!(st["r_frame_rate"], "24/1");
        let n: usize = st["nb_read_frames"].as_str().unwrap().parse().unwrap();
        assert_eq!(n, frames, "{}", p.display());
        let dur: f64 = j["format"]["duration"].as_str().unwrap().parse().unwrap();
        assert!((dur - frames as f64 / 24.0).abs() < 0.06, "{dur}");
    }
    // No temporaries left beside the outputs.
    let names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn ground_camera_keeps_the_flock_in_the_picture_from_take_off_to_the_pass() {
    // The observer stands beside the course and turns and zooms like a camera operator: the
    // flock is in the picture in every frame, from the take-off on the field to the pass and
    // away, drawn large enough to read, and nearer birds are drawn larger than far ones.
    let d = tmpdir("ground");
    // The pass (70 % of the picture) falls in the steady flight, after the ground take-off
    // (about 16 s for 14 birds), when the flock is formed.
    let anim = animate_for(14, &d, "40");
    let opts = RenderOptions {
        camera: CameraKind::Ground,
        background: Background::Sky,
        ..RenderOptions::default()
    };
    let film = Film::with_options(&anim, 25.0, &opts);
    let in_view = |k: usize| -> Vec<f64> {
        let v = &film.views[k];
        film.states(k)
            .iter()
            .filter_map(|b| v.project([b.x, b.y, b.z], 960, 540))
            .filter(|&(c, r, _)| (0.0..960.0).contains(&c) && (0.0..540.0).contains(&r))
            .map(|(_, _, s)| s)
            .collect()
    };
    let birds = film.states(0).len();
    let mut fewest = (birds, 0);
    let mut sizes = Vec::new();
    for k in 0..film.len() {
        let seen = in_view(k);
        if seen.len() < fewest.0 {
            fewest = (seen.len(), k);
        }
        let mut s = seen.clone();
        s.sort_by(f64::total_cmp);
        if let Some(m) = s.get(s.len() / 2) {
            sizes.push(*m);
        }
    }
    assert!(
        fewest.0 * 10 >= birds * 8,
        "only {} of {birds} birds in the picture at frame {}",
        fewest.0,
        fewest.1
    );
    sizes.sort_by(f64::total_cmp);
    let median = sizes[sizes.len() / 2];
    assert!(median > 8.0, "median bird drawn {median:.1} px wide");
    // Around the pass the nearest birds are drawn larger than the farthest.
    let last = (film.len() - 1) as f64;
    let pass = in_view((last * 0.7).round() as usize);
    let (lo, hi) = pass
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), &s| (a.min(s), b.max(s)));
    assert!(hi > 1.1 * lo, "sizes at the pass {lo:.1}..{hi:.1} px");
    std::fs::remove_dir_all(&d).unwrap();
}

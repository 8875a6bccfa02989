//! Birds at rest are drawn on the ground they sit on (the README job's first frames are not sky
//! behind folded birds), on any background but a transparent one; the ground camera shows a
//! horizon on a plain dark colour; the take-off's summary says when the V formed and how long
//! the climb took, in the text and in `initiate --json`.

use std::path::Path;

use formation::export::raster::{Canvas, Mask};
use formation::export::{Background, CameraKind, Film, RenderOptions};
use formation::Animation;

mod support;

use support::{run as formation, s, scratch};

const GEESE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples_data/barnacle_geese_v.json"
);

/// The README job (14 barnacle geese) with 2 s of steady flight, and its summary.
fn readme_job(d: &Path) -> (Animation, String) {
    let json = d.join("anim.json");
    let out = formation(&[
        "animate",
        GEESE,
        "--birds",
        "14",
        "--species",
        "barnacle-goose",
        "--seconds",
        "2",
        "-o",
        s(&json),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        Animation::read(&json).unwrap(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// Frame at `t` seconds of `anim` drawn with `opts` (as the GIF draws it), RGBA.
fn frame(anim: &Animation, opts: &RenderOptions, t: f64) -> Canvas {
    let fps = 25.0;
    let film = Film::with_options(anim, fps, opts);
    let k = (t * fps).round() as usize;
    let mut c = Canvas::new(opts.width as usize, opts.height as usize);
    let mut m = Mask::new();
    film.draw(k, &mut c, &mut m, true);
    c
}

/// Share of the pixels of the lower third that are near `colour` (within 12 levels each).
fn share_near(c: &Canvas, colour: [u8; 3]) -> f64 {
    let (w, h) = (c.width, c.height);
    let mut near = 0usize;
    let mut all = 0usize;
    for r in 2 * h / 3..h {
        for px in c.rgba[r * w * 4..(r + 1) * w * 4].chunks_exact(4) {
            all += 1;
            if (0..3).all(|k| (px[k] as i32 - colour[k] as i32).abs() <= 12) {
                near += 1;
            }
        }
    }
    near as f64 / all as f64
}

/// Median of the blue-minus-green of the lower third: the sky is blue (about +47 at its middle:
/// (114, 167, 214)), a grass field is not (104, 122, 84: −38).
fn median_blue_excess(c: &Canvas) -> i32 {
    let (w, h) = (c.width, c.height);
    let mut v: Vec<i32> = c.rgba[2 * h / 3 * w * 4..]
        .chunks_exact(4)
        .map(|p| p[2] as i32 - p[1] as i32)
        .collect();
    v.sort();
    v[v.len() / 2]
}

#[test]
fn birds_at_rest_are_drawn_on_the_ground_and_the_sky_comes_in_as_they_climb() {
    let d = scratch("ground-pictures");
    let (anim, summary) = readme_job(&d);
    let sky = RenderOptions::default();
    // 0.5 s in, the flock sits: the lower third is the field, not the sky (before: median
    // pixel (114, 167, 214), sky blue).
    let sitting = frame(&anim, &sky, 0.5);
    let ground = formation::export::scene::Style::default().ground;
    let on_ground = share_near(&sitting, ground);
    assert!(
        on_ground > 0.9,
        "{on_ground:.3} of the lower third is ground"
    );
    assert!(
        median_blue_excess(&sitting) < 0,
        "{}",
        median_blue_excess(&sitting)
    );
    // In steady flight, high up, the sky is back.
    let t_steady = anim.frames.last().unwrap().t - 0.5;
    let flying = frame(&anim, &sky, t_steady);
    assert!(share_near(&flying, ground) < 0.01);
    assert!(
        median_blue_excess(&flying) > 20,
        "{}",
        median_blue_excess(&flying)
    );
    // On a dark plain colour the field stands out (a horizon between field and background).
    let dark = [0x10, 0x10, 0x18];
    let plain = RenderOptions {
        background: Background::Colour(dark),
        ..RenderOptions::default()
    };
    let c = frame(&anim, &plain, 0.5);
    let g = formation::export::scene::ground_for(dark);
    assert!(share_near(&c, g) > 0.9);
    assert!(
        (0..3)
            .map(|k| (g[k] as i32 - dark[k] as i32).abs())
            .sum::<i32>()
            > 100
    );
    // Transparent stays transparent (compositing).
    let none = RenderOptions {
        background: Background::None,
        ..RenderOptions::default()
    };
    let c = frame(&anim, &none, 0.5);
    let clear = c.rgba.chunks_exact(4).filter(|p| p[3] == 0).count();
    assert!(clear > c.width * c.height / 2, "{clear}");
    // The ground camera over a dark colour: ground below a horizon, the colour above it.
    let ground_cam = RenderOptions {
        background: Background::Colour(dark),
        camera: CameraKind::Ground,
        ..RenderOptions::default()
    };
    let c = frame(&anim, &ground_cam, 0.5);
    let (w, h) = (c.width, c.height);
    let at = |r: usize| c.rgba[(r * w + 2) * 4..(r * w + 2) * 4 + 3].to_vec();
    assert_eq!(at(0), dark.to_vec(), "sky row");
    let bottom = at(h - 1);
    assert!(
        (0..3)
            .map(|k| (bottom[k] as i32 - dark[k] as i32).abs())
            .sum::<i32>()
            > 60,
        "{bottom:?}"
    );
    // The summary says when the V formed and how long the climb took.
    assert!(summary.contains("V formed after "), "{summary}");
    assert!(summary.contains("climb to cruise height "), "{summary}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn initiate_json_reports_when_the_v_formed_and_the_climb() {
    let d = scratch("ground-pictures-json");
    let steady = d.join("steady.json");
    let params = support::data("steady_v9_params.json");
    let out = formation(&[
        "steady",
        s(&params),
        "--birds",
        "9",
        "--seconds",
        "1",
        "-o",
        s(&steady),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let anim = d.join("anim.json");
    let out = formation(&[
        "initiate",
        s(&steady),
        "-o",
        s(&anim),
        "--takeoff",
        "12",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let start = text.find('{').expect("JSON");
    let end = text.rfind('}').expect("JSON") + 1;
    let v: serde_json::Value = serde_json::from_str(&text[start..end]).expect(&text);
    let formed = v["formed_seconds"].as_f64().expect("formed_seconds");
    let high = v["cruise_height_seconds"]
        .as_f64()
        .expect("cruise_height_seconds");
    let first = v["first_liftoff"].as_f64().expect("first_liftoff");
    let total = v["seconds"].as_f64().unwrap();
    assert!((formed - 12.0).abs() <= 3.0, "formed after {formed} s");
    assert!(first > 0.0 && first < high && high <= total + 1e-9, "{v}");
    assert!(formed <= total + 1e-9, "{v}");
    std::fs::remove_dir_all(&d).unwrap();
}

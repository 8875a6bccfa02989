//! The ground camera frames the flock from the first frame: in the README job (a take-off from
//! a field 340 wingspans from the observer), every bird is in the picture and drawn at least at
//! the follow camera's minimum size in every frame from t = 0, while the flock sits, runs,
//! climbs, passes and recedes; the zoom changes smoothly at the same rate in seconds at any
//! picture rate; the sitting birds are seen (their side view), not lines on the horizon; a
//! landing far away and a loop are framed too.

use std::path::Path;

use formation::export::camera::View;
use formation::export::raster::{Canvas, Mask};
use formation::export::{Background, CameraKind, Film, RenderOptions};
use formation::Animation;

mod support;

use support::{run as formation, s, scratch};

const GEESE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples_data/barnacle_geese_v.json"
);

/// The follow camera's default smallest bird, pixels per wingspan.
const MIN_PX: f64 = 12.0;

fn animate(d: &Path, name: &str, extra: &[&str]) -> Animation {
    let json = d.join(name);
    let mut args = vec![
        "animate",
        GEESE,
        "--birds",
        "14",
        "--species",
        "barnacle-goose",
        "-o",
        s(&json),
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let out = formation(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Animation::read(&json).unwrap()
}

fn ground() -> RenderOptions {
    RenderOptions {
        camera: CameraKind::Ground,
        ..RenderOptions::default()
    }
}

/// Checks every frame of `anim` at `fps`: every bird in front of the eye and inside the
/// picture, each drawn at least `min_px` pixels a wingspan (focal length / depth). Returns the
/// on-screen wingspan of the smallest bird per frame, and the largest change of the log focal
/// length per second between consecutive frames.
fn check(anim: &Animation, fps: f64, min_px: f64, what: &str) -> (Vec<f64>, f64) {
    let opts = ground();
    let film = Film::with_options(anim, fps, &opts);
    let (w, h) = (film.width, film.height);
    let mut smallest = Vec::with_capacity(film.len());
    let mut rate = 0.0f64;
    let mut prev: Option<f64> = None;
    for k in 0..film.len() {
        let View::Ground(eye) = film.views[k] else {
            panic!("{what}: not a ground view")
        };
        // Level horizon: the image's right is horizontal.
        assert!(eye.right[2].abs() < 1e-9, "{what}: frame {k} rolls");
        let mut least = f64::MAX;
        for (b, bird) in film.states(k).iter().enumerate() {
            let (c, r, px) = film.views[k]
                .project([bird.x, bird.y, bird.z], w, h)
                .unwrap_or_else(|| panic!("{what}: frame {k}: bird {b} behind the eye"));
            assert!(
                (0.0..w as f64).contains(&c) && (0.0..h as f64).contains(&r),
                "{what}: frame {k} ({:.1} s): bird {b} at ({c:.0}, {r:.0}) outside the picture",
                k as f64 / fps
            );
            least = least.min(px);
        }
        assert!(
            least >= min_px,
            "{what}: frame {k} ({:.1} s): a bird {least:.1} px a wingspan",
            k as f64 / fps
        );
        smallest.push(least);
        if let Some(p) = prev {
            rate = rate.max((eye.focal_px / p).ln().abs() * fps);
        }
        prev = Some(eye.focal_px);
    }
    (smallest, rate)
}

#[test]
fn the_readme_job_is_framed_from_the_first_frame_and_the_zoom_is_smooth_in_seconds() {
    let d = scratch("ground-camera-readme");
    let anim = animate(&d, "anim.json", &[]);
    let (at10, rate10) = check(&anim, 10.0, MIN_PX, "README job at 10 fps");
    let (at50, rate50) = check(&anim, 50.0, MIN_PX, "README job at 50 fps");
    // While the flock sits 340 wingspans away (0 to 1 s) the birds are drawn well above the
    // minimum: about 37 px a wingspan (22 before the lens framed the flock by the picture's
    // width; a sitting flock is wide and flat).
    for t in [0.0, 0.5, 1.0, 3.0, 6.0] {
        let px = at10[(t * 10.0f64).round() as usize];
        assert!(px >= 2.0 * MIN_PX, "{t} s: {px:.1} px a wingspan");
        let px50 = at50[(t * 50.0f64).round() as usize];
        assert!((px50 / px - 1.0).abs() < 0.1, "{t} s: {px:.1} vs {px50:.1}");
    }
    // The zoom's speed is a property of the motion in seconds: at most ~0.3 (35 % a second)
    // at either picture rate, and the same at both.
    assert!(rate10 < 0.5 && rate50 < 0.5, "{rate10:.3}/s, {rate50:.3}/s");
    assert!(
        (rate10 / rate50 - 1.0).abs() < 0.15,
        "{rate10:.3} vs {rate50:.3}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// Pixels of `c` at least half covered (the birds over a transparent background).
fn covered(c: &Canvas) -> usize {
    c.rgba.chunks_exact(4).filter(|p| p[3] >= 128).count()
}

#[test]
fn sitting_birds_are_seen_from_the_ground_not_lines_on_the_horizon() {
    let d = scratch("ground-camera-sitting");
    let anim = animate(&d, "anim.json", &["--seconds", "1"]);
    let opts = RenderOptions {
        background: Background::None,
        ..ground()
    };
    let film = Film::with_options(&anim, 10.0, &opts);
    let mut c = Canvas::new(film.width, film.height);
    let mut m = Mask::new();
    // 0.5 s: the flock sits on its field, head-on to the observer, level with the eye.
    film.draw(5, &mut c, &mut m, false);
    let n = covered(&c);
    // The 14 birds cover 135 pixels (each its body seen from in front, about 0.14 wingspans
    // square, and its folded wings edge-on); drawn flat, as from above, they were lines on the
    // horizon that did not half cover a single pixel.
    assert!(n >= 14 * 8, "{n} pixels covered by 14 sitting birds");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_landing_far_away_and_a_loop_stay_framed() {
    let d = scratch("ground-camera-land-loop");
    // Take-off, 4 s of flight, landing: the flock sits far away at both ends.
    let land = animate(&d, "land.json", &["--seconds", "4", "--land"]);
    let (sizes, rate) = check(&land, 10.0, MIN_PX, "landing");
    let last = *sizes.last().unwrap();
    assert!(last >= 2.0 * MIN_PX, "landed flock {last:.1} px a wingspan");
    assert!(rate < 0.5, "{rate:.3}/s");
    // A loop of steady flight: the framing wraps, no jump from the last frame to the first.
    let lp = animate(
        &d,
        "loop.json",
        &["--seconds", "6", "--loop", "--no-initiation"],
    );
    assert!(lp.looped);
    let film = Film::with_options(&lp, 10.0, &ground());
    let focal = |k: usize| match film.views[k] {
        View::Ground(e) => e.focal_px,
        _ => unreachable!(),
    };
    let aim = |k: usize| match film.views[k] {
        View::Ground(e) => e.forward,
        _ => unreachable!(),
    };
    let step = |i: usize, j: usize| {
        let (a, b) = (aim(i), aim(j));
        let cos = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0);
        cos.acos() + (focal(i) / focal(j)).ln().abs()
    };
    let n = film.len();
    let inner = (1..n).map(|k| step(k - 1, k)).fold(0.0, f64::max);
    let wrap = step(n - 1, 0);
    assert!(
        wrap <= 1.5 * inner + 1e-6,
        "wrap {wrap:.2e}, largest step {inner:.2e}"
    );
    check(&lp, 10.0, MIN_PX, "loop");
    std::fs::remove_dir_all(&d).unwrap();
}

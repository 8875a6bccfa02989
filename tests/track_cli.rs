//! `formation track` on the command line: a directory of frames, a glob and a video made by
//! ffmpeg from them give annotations that `extract` reads, with the true birds found; bad input
//! (a file ffmpeg cannot decode, an empty directory, a frame without birds, `--every 0`, a region
//! outside the frame) exits 2 with one line and writes nothing.

mod support;
mod track_support;

use std::path::Path;

use serde_json::Value;
use support::{run_quiet, s, scratch};
use track_support::{fixed, save_png, shoot, v_flock};

/// 16 frames of a 7-bird V, 16 px a wingspan, as PNG files in `dir`; the true positions.
fn frames(dir: &Path) -> Vec<Vec<(f64, f64)>> {
    let a = v_flock(7, 60.0, 16, "goose", (0.0, 0.0));
    let shot = shoot(&a, &fixed(&a, 16.0, true), 3.0);
    for (k, g) in shot.frames.iter().enumerate() {
        save_png(g, &dir.join(format!("frame_{k:04}.png")));
    }
    shot.truth
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every true bird of every frame has a tracked bird within a fifth of a wingspan.
fn check_found(ann: &Value, truth: &[Vec<(f64, f64)>], first: usize, every: usize) {
    let frames = ann["frames"].as_array().unwrap();
    assert!(!frames.is_empty());
    for f in frames {
        let k = f["index"].as_u64().unwrap() as usize;
        assert_eq!((k - first) % every, 0);
        let birds = f["birds"].as_array().unwrap();
        assert_eq!(birds.len(), truth[k].len(), "frame {k}");
        for &(x, y) in &truth[k] {
            assert!(
                birds.iter().any(|b| {
                    let (bx, by) = (b["x"].as_f64().unwrap(), b["y"].as_f64().unwrap());
                    (bx - x).hypot(by - y) < 0.2 * 16.0
                }),
                "frame {k}: no bird near ({x:.1}, {y:.1})"
            );
        }
        for b in birds {
            let c = b["confidence"].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&c));
        }
    }
}

#[test]
fn directories_globs_and_videos_become_annotations_extract_reads() {
    let dir = scratch("track-cli");
    let shots = dir.join("shots");
    std::fs::create_dir_all(&shots).unwrap();
    let truth = frames(&shots);
    // A directory.
    let out = dir.join("dir.json");
    let (code, err) = run_quiet(&["track", s(&shots), "-o", s(&out), "--fps", "25"]);
    assert_eq!(code, 0, "{err}");
    let ann = read(&out);
    check_found(&ann, &truth, 0, 1);
    assert_eq!(ann["fps"].as_f64(), Some(25.0));
    let span = ann["wingspan_px"].as_f64().unwrap();
    assert!((span / 16.0 - 1.0).abs() <= 0.1, "wingspan {span}");
    let heading = ann["heading"].as_f64().unwrap();
    assert!((heading - 60.0).abs() <= 5.0, "heading {heading}");
    let params = dir.join("p.json");
    let (code, err) = run_quiet(&["extract", s(&out), "-o", s(&params)]);
    assert_eq!(code, 0, "{err}");
    let p = read(&params);
    assert_eq!(p["birds"].as_u64(), Some(7));
    // A glob, every second frame from frame 2 to 11.
    let out = dir.join("glob.json");
    let glob = shots.join("frame_*.png");
    let (code, err) = run_quiet(&[
        "track",
        s(&glob),
        "-o",
        s(&out),
        "--every",
        "2",
        "--frames",
        "2..12",
    ]);
    assert_eq!(code, 0, "{err}");
    let ann = read(&out);
    assert_eq!(ann["frames"].as_array().unwrap().len(), 5);
    check_found(&ann, &truth, 2, 1 + 1);
    assert!(ann.get("fps").is_none());
    // A video made by ffmpeg (lossless, so the frames are the same).
    let video = dir.join("clip.mkv");
    let ok = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-y", "-framerate", "25", "-i"])
        .arg(shots.join("frame_%04d.png"))
        .args(["-c:v", "ffv1"])
        .arg(&video)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    assert!(ok, "ffmpeg could not make the test video");
    let out = dir.join("video.json");
    let (code, err) = run_quiet(&["track", s(&video), "-o", s(&out)]);
    assert_eq!(code, 0, "{err}");
    let ann = read(&out);
    check_found(&ann, &truth, 0, 1);
    assert_eq!(ann["fps"].as_f64(), Some(25.0));
    assert_eq!(ann["frames"][3]["t"].as_f64(), Some(0.12));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Exit 2, one line containing `needle`, and no output file.
fn refused(args: &[&str], out: &Path, needle: &str) {
    let (code, err) = run_quiet(args);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: {err} (expected {needle:?})"
    );
    assert!(!out.exists(), "{args:?} left {}", out.display());
}

#[test]
fn bad_footage_and_flags_exit_2_with_one_line() {
    let dir = scratch("track-cli-bad");
    let out = dir.join("a.json");
    let o = s(&out);
    // A file ffmpeg cannot decode.
    let junk = dir.join("junk.mp4");
    std::fs::write(&junk, b"this is not a video").unwrap();
    refused(&["track", s(&junk), "-o", o], &out, "junk.mp4");
    // An empty directory.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(&["track", s(&empty), "-o", o], &out, "no image");
    // A frame with no bird: plain sky.
    let sky = dir.join("sky");
    std::fs::create_dir_all(&sky).unwrap();
    let g = formation::track::detect::Gray {
        width: 64,
        height: 48,
        data: (0..64 * 48).map(|i| 150 + (i / 64) as u8).collect(),
    };
    save_png(&g, &sky.join("f0.png"));
    refused(&["track", s(&sky), "-o", o], &out, "frame 0: no bird found");
    // Flags.
    let shots = dir.join("shots");
    std::fs::create_dir_all(&shots).unwrap();
    frames(&shots);
    let sh = s(&shots);
    refused(&["track", sh, "-o", o, "--every", "0"], &out, "--every");
    refused(
        &["track", sh, "-o", o, "--roi", "400,200,100,100"],
        &out,
        "--roi",
    );
    refused(
        &["track", sh, "-o", o, "--frames", "5..3"],
        &out,
        "--frames",
    );
    refused(
        &["track", sh, "-o", o, "--frames", "50..60"],
        &out,
        "--frames",
    );
    refused(
        &["track", sh, "-o", o, "--polarity", "grey"],
        &out,
        "--polarity",
    );
    refused(&["track", sh, "-o", o, "--fps", "0"], &out, "--fps");
    refused(
        &["track", sh, "-o", s(&dir.join("a.txt"))],
        &dir.join("a.txt"),
        "a.txt",
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_review_page_is_one_self_contained_file() {
    let dir = scratch("track-review");
    let out = dir.join("a.json");
    let page = dir.join("review.html");
    let frames = support::data("track_frames");
    let (code, err) = run_quiet(&["track", s(&frames), "-o", s(&out), "--review", s(&page)]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    // No fetch from anywhere: every frame is a data URL, no script or style is linked.
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert!(!html.contains("src=\"") && !html.contains("href=\""));
    assert_eq!(html.matches("data:image/jpeg;base64,").count(), 3);
    // The annotations it edits are the ones written, and Save suggests their name.
    let ann = read(&out);
    assert!(html.contains("\"name\":\"a.json\""));
    let start = html.find("id=\"data\">").unwrap() + "id=\"data\">".len();
    let end = start + html[start..].find("</script>").unwrap();
    let data: Value = serde_json::from_str(&html[start..end].replace("<\\/", "</")).unwrap();
    assert_eq!(data["annotations"], ann);
    // A page with a wrong extension is refused.
    let (code, err) = run_quiet(&[
        "track",
        s(&frames),
        "-o",
        s(&out),
        "--review",
        s(&dir.join("r.png")),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("--review"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

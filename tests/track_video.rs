//! `track` on videos as they come: through a FIFO fed by `cat` and through `<(cat video)` (one
//! ffmpeg reads the pipe once and tells the frame size), a phone video with rotation metadata
//! (the frames are the upright ones ffmpeg hands over), and a video cut at 60 % or with 4 KB of
//! its middle overwritten (tracked, with one warning naming the file and the frames decoded).
//! Needs ffmpeg, as `.ci/run` installs it.

mod support;

use std::path::Path;
use std::process::Command;

use serde_json::Value;
use support::{bin, data, s, scratch};

fn ffmpeg(args: &[&str]) {
    let ok = Command::new("ffmpeg")
        .args(["-v", "error", "-y"])
        .args(args)
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    assert!(ok, "ffmpeg {args:?} failed");
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Birds per frame of an annotation file.
fn counts(v: &Value) -> Vec<usize> {
    v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["birds"].as_array().unwrap().len())
        .collect()
}

#[test]
fn pipes_rotated_and_damaged_videos() {
    let dir = scratch("track-video");
    let frames = data("track_frames");
    let clip = dir.join("clip.mkv");
    ffmpeg(&[
        "-framerate",
        "25",
        "-i",
        s(&frames.join("f%d.png")),
        "-c:v",
        "ffv1",
        s(&clip),
    ]);
    let plain = dir.join("plain.json");
    let out = bin()
        .args(["track", s(&clip), "-o", s(&plain), "-q"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let want = counts(&read(&plain));
    assert_eq!(want, vec![5, 5, 5]);

    // A FIFO fed by cat, and a process substitution.
    let fifo = dir.join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let feeder = {
        let (clip, fifo) = (clip.clone(), fifo.clone());
        std::thread::spawn(move || std::fs::write(&fifo, std::fs::read(&clip).unwrap()))
    };
    let got = dir.join("fifo.json");
    let out = bin()
        .args(["track", s(&fifo), "-o", s(&got), "-q"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    feeder.join().unwrap().unwrap();
    assert_eq!(counts(&read(&got)), want);
    assert_eq!(read(&got)["fps"].as_f64(), Some(25.0));
    let got = dir.join("sub.json");
    let script = format!(
        "exec {} track <(cat {}) -o {} -q",
        support::bin_path(),
        s(&clip),
        s(&got)
    );
    let out = Command::new("bash").args(["-c", &script]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(counts(&read(&got)), want);

    // Rotation metadata: stored 160x90, shown (and decoded) 90x160.
    let mp4 = dir.join("clip.mp4");
    ffmpeg(&["-i", s(&clip), "-c:v", "libx264", "-crf", "12", s(&mp4)]);
    let rot = dir.join("rot.mp4");
    ffmpeg(&[
        "-i",
        s(&mp4),
        "-c",
        "copy",
        "-metadata:s:v:0",
        "rotate=90",
        s(&rot),
    ]);
    let got = dir.join("rot.json");
    let out = bin()
        .args(["track", s(&rot), "-o", s(&got), "-q"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = read(&got);
    assert_eq!(v["image_size"], serde_json::json!([90, 160]));
    assert_eq!(counts(&v), want);

    // Cut at 60 %: the frames before the cut, and a warning.
    let long = dir.join("long.mkv");
    ffmpeg(&[
        "-loop",
        "1",
        "-framerate",
        "25",
        "-t",
        "2",
        "-i",
        s(&frames.join("f0.png")),
        "-c:v",
        "libx264",
        "-crf",
        "12",
        "-g",
        "5",
        s(&long),
    ]);
    let bytes = std::fs::read(&long).unwrap();
    let cut = dir.join("cut.mkv");
    std::fs::write(&cut, &bytes[..bytes.len() * 6 / 10]).unwrap();
    let got = dir.join("cut.json");
    let out = bin()
        .args(["track", s(&cut), "-o", s(&got)])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let warning: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warning.len(), 1, "{err}");
    let n = counts(&read(&got)).len();
    assert!(n > 0 && n < 50, "{n} frames of a cut 50-frame video");
    assert!(
        warning[0].contains("cut.mkv") && warning[0].contains(&format!("decoded {n} frames")),
        "{err}"
    );
    // With --strict the warning is the error: exit 2, nothing written.
    let strict = dir.join("strict.json");
    let out = bin()
        .args(["track", s(&cut), "-o", s(&strict), "--strict", "-q"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(!strict.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

//! `track` at its limits: 1000 birds in a frame are tracked (the frame-to-frame flock-shift vote
//! and the assignment no longer grow with a power of the birds beyond the neighbours a bird
//! has); more birds in a frame than annotations hold (1000) exit 2 naming the frame, as do more
//! frames than annotations hold (100 000, through a glob).

mod support;
mod track_support;

use formation::track::detect::Gray;
use formation::track::{TrackOptions, Tracking};
use support::{run_quiet, s, scratch};

/// A sky with `cols × rows` dark discs 24 px apart, all shifted by `shift`.
fn grid_frame(cols: usize, rows: usize, shift: (f64, f64)) -> Gray {
    let (w, h) = (cols * 24 + 40, rows * 24 + 40);
    let mut data = vec![200u8; w * h];
    for r in 0..rows {
        for c in 0..cols {
            let cx = 20.0 + 24.0 * c as f64 + shift.0 + 3.0 * ((r * 7 + c * 3) % 5) as f64 / 5.0;
            let cy = 20.0 + 24.0 * r as f64 + shift.1;
            for y in (cy as usize).saturating_sub(5)..(cy as usize + 6).min(h) {
                for x in (cx as usize).saturating_sub(5)..(cx as usize + 6).min(w) {
                    if (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) < 3.5 {
                        data[y * w + x] = 40;
                    }
                }
            }
        }
    }
    Gray {
        width: w,
        height: h,
        data,
    }
}

#[test]
fn a_thousand_birds_a_frame_are_tracked_and_more_refused() {
    let mut t = Tracking::new(&TrackOptions::default()).unwrap();
    for k in 0..3 {
        let g = grid_frame(40, 25, (9.0 * k as f64, 4.0 * k as f64));
        t.push(k, None, &g, std::path::Path::new("grid")).unwrap();
    }
    let tr = t.finish("grid", None).unwrap();
    for f in &tr.frames {
        assert_eq!(f.birds.len(), 1000, "frame {}", f.index);
    }
    // The flock moved 9.8 px a frame, less than the 24-px spacing but more than the gate: each
    // bird keeps its id.
    assert_eq!(tr.track_count(), 1000);

    // 1001 birds: refused, naming the frame.
    let dir = scratch("track-limits");
    let many = dir.join("many");
    std::fs::create_dir_all(&many).unwrap();
    track_support::save_png(&grid_frame(41, 25, (0.0, 0.0)), &many.join("f0.png"));
    let out = dir.join("a.json");
    let (code, err) = run_quiet(&["track", s(&many), "-o", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("f0.png") && err.contains("frame 0: 1025 birds found"),
        "{err}"
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn more_frames_than_annotations_hold_are_refused_up_front() {
    // 100 001 empty files matching a glob: refused before any is read.
    let dir = scratch("track-many-frames");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for k in 0..100_001 {
        std::fs::File::create(frames.join(format!("f{k:06}.png"))).unwrap();
    }
    let out = dir.join("a.json");
    let (code, err) = run_quiet(&["track", s(&frames.join("f*.png")), "-o", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("--frames") && err.contains("100001 frames"),
        "{err}"
    );
    assert!(!out.exists());
    // --every brings them within the limit (the first file, empty, is then refused by name).
    let (code, err) = run_quiet(&[
        "track",
        s(&frames.join("f*.png")),
        "-o",
        s(&out),
        "--every",
        "2",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("f000000.png"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

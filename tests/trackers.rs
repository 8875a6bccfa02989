//! The trackers' files (SLEAP analysis CSV, DeepLabCut multi-animal CSV, MOTChallenge text,
//! idtracker.ai trajectories.csv): a small file of each, written to the tracker's published
//! layout from the same birds, is detected by content and read to the same points with the same
//! identities; damaged files exit 2 naming the file and the row.

mod support;

use std::path::Path;

use formation::annotations::{parse_str, Format, ReadOptions};
use support::{run_quiet, s, scratch};

/// Bird `i` of frame `k`, pixels (x right, y down): a 4-bird V moving right.
fn bird(k: usize, i: usize) -> (f64, f64) {
    let lat: f64 = [0.0, -1.0, 1.0, -2.0][i];
    (
        300.0 + 5.0 * k as f64 - 14.0 * lat.abs(),
        200.0 + 22.0 * lat + 0.25 * k as f64,
    )
}

const FRAMES: usize = 3;
const BIRDS: usize = 4;

fn sleap() -> String {
    let mut t = String::from(
        "track,frame_idx,instance.score,head.x,head.y,head.score,tail.x,tail.y,tail.score\n",
    );
    for k in 0..FRAMES {
        for i in 0..BIRDS {
            let (x, y) = bird(k, i);
            t += &format!("track_{i},{k},0.97,{x},{y},0.9,{},{},0.8\n", x - 8.0, y);
        }
    }
    t
}

fn dlc() -> String {
    let mut rows = [
        "scorer".to_string(),
        "individuals".to_string(),
        "bodyparts".to_string(),
        "coords".to_string(),
    ];
    for i in 0..BIRDS {
        for part in ["body", "beak"] {
            for c in ["x", "y", "likelihood"] {
                rows[0] += ",DLC_resnet50_geeseJan1shuffle1_100000";
                rows[1] += &format!(",bird{}", i + 1);
                rows[2] += &format!(",{part}");
                rows[3] += &format!(",{c}");
            }
        }
    }
    let mut t = rows.join("\n") + "\n";
    for k in 0..FRAMES {
        t += &k.to_string();
        for i in 0..BIRDS {
            let (x, y) = bird(k, i);
            t += &format!(",{x},{y},0.99,{},{},0.95", x + 6.0, y);
        }
        t += "\n";
    }
    t
}

fn mot() -> String {
    let mut t = String::new();
    for k in 0..FRAMES {
        for i in 0..BIRDS {
            let (x, y) = bird(k, i);
            // A 16 × 6 box centred on the bird; frames and ids from 1.
            t += &format!(
                "{},{},{},{},16,6,1,-1,-1,-1\n",
                k + 1,
                i + 1,
                x - 8.0,
                y - 3.0
            );
        }
    }
    t
}

fn idtracker() -> String {
    let mut t = String::from("time");
    for i in 0..BIRDS {
        t += &format!(",x{0},y{0}", i + 1);
    }
    t += "\n";
    for k in 0..FRAMES {
        t += &format!("{}", k as f64 / 25.0);
        for i in 0..BIRDS {
            let (x, y) = bird(k, i);
            t += &format!(",{x},{y}");
        }
        t += "\n";
    }
    t
}

#[test]
fn every_tracker_file_reads_to_the_same_birds() {
    let opts = ReadOptions {
        wingspan_px: Some(20.0),
        ..ReadOptions::default()
    };
    for (name, text, format, first_frame) in [
        ("sleap.csv", sleap(), Format::Sleap, 0),
        ("dlc.csv", dlc(), Format::Dlc, 0),
        ("gt.txt", mot(), Format::Mot, 1),
        ("trajectories.csv", idtracker(), Format::IdTracker, 0),
    ] {
        let a = parse_str(Path::new(name), &text, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(a.format, format, "{name}");
        assert!(a.ids_given, "{name}");
        assert_eq!(a.frames.len(), FRAMES, "{name}");
        // The same bird keeps one id over the frames, and every bird is where it was drawn.
        let mut ids = [None; BIRDS];
        for (k, f) in a.frames.iter().enumerate() {
            assert_eq!(f.index, (k + first_frame) as i64, "{name}");
            assert_eq!(f.birds.len(), BIRDS, "{name}");
            for (i, slot) in ids.iter_mut().enumerate() {
                let (x, y) = bird(k, i);
                let b = f
                    .birds
                    .iter()
                    .find(|b| (b.px - x).abs() < 1e-9 && (b.py - y).abs() < 1e-9)
                    .unwrap_or_else(|| panic!("{name}: frame {k}: no bird at ({x}, {y})"));
                assert_eq!(
                    *slot.get_or_insert(b.id),
                    b.id,
                    "{name}: bird {i} changed id"
                );
            }
        }
        let mut distinct: Vec<_> = ids.iter().flatten().collect();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), BIRDS, "{name}");
    }
}

#[test]
fn missing_birds_are_left_out() {
    let opts = ReadOptions {
        wingspan_px: Some(20.0),
        ..ReadOptions::default()
    };
    // idtracker.ai and DeepLabCut write NaN or nothing for an animal not seen.
    let t = idtracker().replacen(&format!("{}", bird(1, 3).0), "NaN", 1);
    let t = t.replacen(&format!("{}", bird(1, 3).1), "NaN", 1);
    let a = parse_str(Path::new("t.csv"), &t, &opts).unwrap();
    assert_eq!(a.frames[1].birds.len(), BIRDS - 1);
    let d = dlc();
    let mut lines: Vec<String> = d.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    for c in &mut cells[1..7] {
        c.clear();
    }
    lines[5] = cells.join(",");
    let a = parse_str(Path::new("d.csv"), &(lines.join("\n") + "\n"), &opts).unwrap();
    assert_eq!(a.frames[1].birds.len(), BIRDS - 1);
}

#[test]
fn damaged_tracker_files_exit_2_naming_file_and_row() {
    let dir = scratch("trackers-bad");
    let out = dir.join("p.json");
    let cases = [
        (
            "sleap.csv",
            sleap().replace("track_2,1,0.97,", "track_2,one,0.97,"),
            "row 7",
        ),
        ("dlc.csv", dlc().replacen("\n1,", "\n1,abc", 1), "row 2"),
        ("gt.txt", mot().replacen("\n2,1,", "\n2,1,x", 1), "row 5"),
        (
            "trajectories.csv",
            idtracker().replacen("\n0.04,", "\n0.04,zz", 1),
            "row 2",
        ),
    ];
    for (name, text, row) in cases {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, err) = run_quiet(&["extract", s(&p), "--wingspan-px", "20", "-o", s(&out)]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(name) && err.contains(row), "{name}: {err}");
        assert!(!out.exists());
    }
    // And a good one extracts.
    let p = dir.join("ok.csv");
    std::fs::write(&p, sleap()).unwrap();
    let (code, err) = run_quiet(&[
        "extract",
        s(&p),
        "--wingspan-px",
        "20",
        "--heading",
        "right",
        "-o",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--bodypart`: the SLEAP node or DeepLabCut body part giving each bird's position, matched
/// without case; a name the file lacks is refused listing the file's, and a format with one point
/// per bird refuses the option.
#[test]
fn a_body_part_is_chosen_by_name() {
    for (name, text, part, dx) in [
        ("sleap.csv", sleap(), "tail", -8.0),
        ("sleap.csv", sleap(), "HEAD", 0.0),
        ("dlc.csv", dlc(), "beak", 6.0),
        ("dlc.csv", dlc(), "Body", 0.0),
    ] {
        let opts = ReadOptions {
            wingspan_px: Some(20.0),
            bodypart: Some(part.to_string()),
            ..ReadOptions::default()
        };
        let a = parse_str(Path::new(name), &text, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        for (k, f) in a.frames.iter().enumerate() {
            assert_eq!(f.birds.len(), BIRDS, "{name} {part}");
            for i in 0..BIRDS {
                let (x, y) = bird(k, i);
                assert!(
                    f.birds
                        .iter()
                        .any(|b| (b.px - (x + dx)).abs() < 1e-9 && (b.py - y).abs() < 1e-9),
                    "{name} {part}: frame {k}: no bird at ({}, {y})",
                    x + dx
                );
            }
        }
    }
    let d = scratch("bodypart");
    std::fs::write(d.join("dlc.csv"), dlc()).unwrap();
    std::fs::write(d.join("sleap.csv"), sleap()).unwrap();
    std::fs::write(d.join("gt.txt"), mot()).unwrap();
    for (file, part, needles) in [
        (
            "dlc.csv",
            "wing",
            &["--bodypart", "no body part \"wing\"", "body, beak"][..],
        ),
        (
            "sleap.csv",
            "wing",
            &["--bodypart", "no node \"wing\"", "head, tail"][..],
        ),
        ("gt.txt", "head", &["--bodypart", "one point per bird"][..]),
    ] {
        let f = d.join(file);
        let out = d.join("p.json");
        let (code, err) = run_quiet(&[
            "extract",
            s(&f),
            "--wingspan-px",
            "20",
            "--bodypart",
            part,
            "-o",
            s(&out),
        ]);
        assert_eq!(code, 2, "{file}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{file}: {err}");
        for n in needles {
            assert!(err.contains(n), "{file}: {n}: {err}");
        }
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(&d).unwrap();
}

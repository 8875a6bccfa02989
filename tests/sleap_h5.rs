//! SLEAP's analysis HDF5: the fixture `tests/data/sleap/flock.analysis.h5` (written by
//! `scripts/sleap_h5_fixture.py` with h5py in SLEAP's layout: transposed, chunked, gzip) is
//! detected by content and read to the same points and ids as the SLEAP analysis CSV of the
//! same birds; damaged files exit 2 with one line naming the file.

mod support;

use std::path::{Path, PathBuf};

use formation::annotations::{detect, parse_str, read, Format, ReadOptions};
use support::{run_quiet, s, scratch};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sleap/flock.analysis.h5")
}

/// The birds of the fixture (tests/trackers.rs's 4-bird V), as SLEAP's analysis CSV.
fn sleap_csv() -> String {
    let mut t = String::from(
        "track,frame_idx,instance.score,head.x,head.y,head.score,tail.x,tail.y,tail.score\n",
    );
    for k in 0..3usize {
        for i in 0..4usize {
            if i == 3 && k == 1 {
                continue;
            }
            let lat: f64 = [0.0, -1.0, 1.0, -2.0][i];
            let (x, y) = (
                300.0 + 5.0 * k as f64 - 14.0 * lat.abs(),
                200.0 + 22.0 * lat + 0.25 * k as f64,
            );
            t += &format!("track_{i},{k},0.97,{x},{y},0.9,{},{},0.8\n", x - 8.0, y);
        }
    }
    t
}

fn opts(bodypart: Option<&str>) -> ReadOptions {
    ReadOptions {
        wingspan_px: Some(20.0),
        bodypart: bodypart.map(str::to_string),
        ..ReadOptions::default()
    }
}

#[test]
fn the_hdf5_reads_to_the_csv_points() {
    assert_eq!(detect(&fixture()).unwrap(), Format::SleapH5);
    for node in [None, Some("TAIL")] {
        let h = read(&fixture(), &opts(node)).unwrap();
        let c = parse_str(Path::new("sleap.csv"), &sleap_csv(), &opts(node)).unwrap();
        assert_eq!(h.format, Format::SleapH5);
        assert!(h.ids_given);
        assert_eq!(h.frames.len(), c.frames.len());
        for (a, b) in h.frames.iter().zip(&c.frames) {
            assert_eq!(a.index, b.index);
            let mut pa: Vec<(usize, f64, f64)> =
                a.birds.iter().map(|m| (m.id, m.px, m.py)).collect();
            let mut pb: Vec<(usize, f64, f64)> =
                b.birds.iter().map(|m| (m.id, m.px, m.py)).collect();
            pa.sort_by_key(|p| p.0);
            pb.sort_by_key(|p| p.0);
            assert_eq!(pa, pb, "frame {} node {node:?}", a.index);
        }
    }
    // Bird 3 is not seen in frame 1.
    let h = read(&fixture(), &opts(None)).unwrap();
    assert_eq!(h.frames[1].birds.len(), 3);
    let e = read(&fixture(), &opts(Some("wing")))
        .unwrap_err()
        .to_string();
    assert!(e.contains("head, tail"), "{e}");
}

#[test]
fn damaged_hdf5_files_exit_2_naming_the_file() {
    let dir = scratch("sleap-h5-bad");
    let out = dir.join("p.json");
    let good = std::fs::read(fixture()).unwrap();
    let mut flipped = good.clone();
    // Past the superblock: object headers, B-trees and compressed chunks.
    for i in (200..flipped.len()).step_by(97) {
        flipped[i] ^= 0x5a;
    }
    for (name, bytes) in [
        ("truncated.h5", good[..good.len() / 3].to_vec()),
        ("signature-only.h5", good[..8].to_vec()),
        ("flipped.h5", flipped),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let (code, err) = run_quiet(&["extract", s(&p), "--wingspan-px", "20", "-o", s(&out)]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
        assert!(!out.exists());
    }
    // And the fixture extracts.
    let (code, err) = run_quiet(&[
        "extract",
        s(&fixture()),
        "--wingspan-px",
        "20",
        "-o",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.exists());
}

/// A fuzz finding (`fuzz/` target `sleap_h5`, 29 s in): a damaged names dataset declared a
/// dataset far larger than the file, and the decoder's allocation aborted the process. The
/// shapes, element sizes and chunk shapes are now checked before any data is read.
#[test]
fn a_huge_declared_dataset_is_refused_not_allocated() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz/sleap_h5-oom-8c51924d.h5");
    let bytes = std::fs::read(&p).unwrap();
    let r = formation::annotations::parse_sleap_h5_bytes(&p, bytes, &opts(None));
    assert!(r.is_err());
}

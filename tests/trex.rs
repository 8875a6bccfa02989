//! TRex's tracks (one NumPy `.npz` per individual), read without Python: the fixtures of
//! `tests/data/trex/` were written by NumPy itself (`scripts/trex_fixture.py`: `np.savez` and
//! `np.savez_compressed`) in TRex's layout, with the birds of `tests/trackers.rs`. Read from one
//! individual's file or the directory, both give the same points and ids, the frame rate from
//! `time`, and leave out the frames an individual is missing from; damaged archives exit 2 naming
//! the file, and no damage makes the reader panic.

mod support;

use std::path::{Path, PathBuf};

use formation::annotations::{parse_trex_bytes, read, Format, ReadOptions};
use rand::{Rng, SeedableRng};
use support::{run_quiet, s, scratch};

/// Bird `i` of frame `k`, pixels (as in tests/trackers.rs and scripts/trex_fixture.py).
fn bird(k: usize, i: usize) -> (f64, f64) {
    let lat: f64 = [0.0, -1.0, 1.0, -2.0][i];
    (
        300.0 + 5.0 * k as f64 - 14.0 * lat.abs(),
        200.0 + 22.0 * lat + 0.25 * k as f64,
    )
}

fn fixture(kind: &str) -> PathBuf {
    support::data("trex").join(kind)
}

fn opts() -> ReadOptions {
    ReadOptions {
        wingspan_px: Some(20.0),
        ..ReadOptions::default()
    }
}

#[test]
fn trex_archives_read_to_the_birds_numpy_wrote() {
    for kind in ["stored", "compressed"] {
        for path in [fixture(kind), fixture(kind).join("flock_fish2.npz")] {
            let a = read(&path, &opts()).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let what = path.display().to_string();
            assert_eq!(a.format, Format::Trex, "{what}");
            assert!(a.ids_given, "{what}");
            assert_eq!(a.fps, Some(25.0), "{what}: the rate from frame and time");
            assert_eq!(a.frames.len(), 3, "{what}");
            for (k, f) in a.frames.iter().enumerate() {
                assert_eq!(f.index, k as i64, "{what}");
                // Bird 2 is tracked from frame 1 on; bird 3 is missing in frame 1.
                let want: Vec<usize> = (0..4)
                    .filter(|&i| !((i == 2 && k == 0) || (i == 3 && k == 1)))
                    .collect();
                let mut ids: Vec<usize> = f.birds.iter().map(|b| b.id).collect();
                ids.sort_unstable();
                assert_eq!(ids, want, "{what}: frame {k}");
                for b in &f.birds {
                    // The body centre (X#wcentroid), not the head (X, 3 px ahead); float32
                    // arrays hold the positions to float32.
                    let (x, y) = bird(k, b.id);
                    assert!(
                        (b.px - x).abs() < 1e-4 && (b.py - y).abs() < 1e-4,
                        "{what}: frame {k} bird {}: ({}, {}) vs ({x}, {y})",
                        b.id,
                        b.px,
                        b.py
                    );
                }
            }
        }
    }
}

#[test]
fn extract_reads_trex_from_the_command_line() {
    let dir = scratch("trex_cli");
    let out = dir.join("p.json");
    let (code, err) = run_quiet(&[
        "extract",
        s(&fixture("compressed").join("flock_fish0.npz")),
        "--wingspan-px",
        "20",
        "--heading",
        "90",
        "-o",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.exists());
    // A body part is for SLEAP and DeepLabCut only.
    let (code, err) = run_quiet(&[
        "extract",
        s(&fixture("stored")),
        "--wingspan-px",
        "20",
        "--bodypart",
        "head",
        "-o",
        s(&dir.join("q.json")),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("TRex") && err.contains("--bodypart"), "{err}");
    assert!(!dir.join("q.json").exists());
}

/// A stored zip of `members` (name, bytes), as np.savez writes it.
fn zip(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (name, data) in members {
        let mut crc = flate2::Crc::new();
        crc.update(data);
        let offset = out.len() as u32;
        let head = |sig: u32, central: bool| {
            let mut h = sig.to_le_bytes().to_vec();
            if central {
                h.extend(20u16.to_le_bytes());
            }
            h.extend(20u16.to_le_bytes()); // version needed
            h.extend(0u16.to_le_bytes()); // flags
            h.extend(0u16.to_le_bytes()); // stored
            h.extend(0u32.to_le_bytes()); // time, date
            h.extend(crc.sum().to_le_bytes());
            h.extend((data.len() as u32).to_le_bytes());
            h.extend((data.len() as u32).to_le_bytes());
            h.extend((name.len() as u16).to_le_bytes());
            h.extend(0u16.to_le_bytes()); // extra
            if central {
                h.extend([0u8; 6]); // comment, disk, internal attributes
                h.extend(0u32.to_le_bytes()); // external attributes
                h.extend(offset.to_le_bytes());
            }
            h.extend(name.as_bytes());
            h
        };
        out.extend(head(0x0403_4b50, false));
        out.extend(data);
        central.extend(head(0x0201_4b50, true));
    }
    let at = out.len() as u32;
    out.extend(&central);
    out.extend(0x0605_4b50u32.to_le_bytes());
    out.extend([0u8; 4]);
    out.extend((members.len() as u16).to_le_bytes());
    out.extend((members.len() as u16).to_le_bytes());
    out.extend((central.len() as u32).to_le_bytes());
    out.extend(at.to_le_bytes());
    out.extend(0u16.to_le_bytes());
    out
}

/// A .npy of `values` with dtype `descr` ('<f8' values are written as such; others as given).
fn npy(descr: &str, n: usize, data: &[u8]) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({n},), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((header.len() as u16).to_le_bytes());
    out.extend(header.as_bytes());
    out.extend(data);
    out
}

fn f8(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn damaged_trex_archives_exit_2_naming_the_file() {
    let dir = scratch("trex_bad");
    let good = std::fs::read(fixture("compressed").join("flock_fish0.npz")).unwrap();
    let x = f8(&[1.0, 2.0, 3.0]);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "truncated",
            good[..good.len() / 2].to_vec(),
            "end of central directory",
        ),
        (
            "lengths differ",
            zip(&[
                ("X.npy", npy("<f8", 3, &x)),
                ("Y.npy", npy("<f8", 3, &x)),
                ("frame.npy", npy("<f8", 2, &f8(&[0.0, 1.0]))),
            ]),
            "array frame has 2 rows",
        ),
        (
            "no positions",
            zip(&[("SPEED.npy", npy("<f8", 3, &x))]),
            "no positions",
        ),
        (
            "complex numbers",
            zip(&[
                ("X.npy", npy("<c16", 3, &[0u8; 48])),
                ("Y.npy", npy("<f8", 3, &x)),
            ]),
            "dtype <c16",
        ),
        (
            "short data",
            zip(&[("X.npy", npy("<f8", 30, &x)), ("Y.npy", npy("<f8", 3, &x))]),
            "truncated",
        ),
        (
            "fractional frame",
            zip(&[
                ("X.npy", npy("<f8", 3, &x)),
                ("Y.npy", npy("<f8", 3, &x)),
                ("frame.npy", npy("<f8", 3, &f8(&[0.0, 1.5, 2.0]))),
            ]),
            "row 1: frame 1.5",
        ),
    ];
    for (what, bytes, needle) in cases {
        let sub = dir.join(what.replace(' ', "_"));
        std::fs::create_dir_all(&sub).unwrap();
        let file = sub.join("flock_fish0.npz");
        std::fs::write(&file, &bytes).unwrap();
        let out = sub.join("p.json");
        let (code, err) = run_quiet(&["extract", s(&file), "--wingspan-px", "20", "-o", s(&out)]);
        assert_eq!(code, 2, "{what}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{what}: {err}");
        assert!(err.contains(s(&file)), "{what}: {err}");
        assert!(err.contains(needle), "{what}: {err}");
        assert!(!out.exists(), "{what}");
    }
    // A flipped byte inside a deflated member: refused (damaged data or checksum), named.
    let mut bytes = good.clone();
    let at = bytes.len() / 3;
    bytes[at] ^= 0x55;
    let e = parse_trex_bytes(Path::new("flipped.npz"), &bytes, &opts()).unwrap_err();
    assert!(e.to_string().contains("flipped.npz"), "{e}");
}

#[test]
fn no_damage_makes_the_reader_panic() {
    // Seeded byte flips, truncations and insertions of both fixtures: each ends in Ok or Err.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut refused = 0;
    for kind in ["stored", "compressed"] {
        let good = std::fs::read(fixture(kind).join("flock_fish3.npz")).unwrap();
        for _ in 0..400 {
            let mut b = good.clone();
            match rng.random_range(0..3) {
                0 => {
                    for _ in 0..rng.random_range(1..8) {
                        let i = rng.random_range(0..b.len());
                        b[i] = rng.random();
                    }
                }
                1 => b.truncate(rng.random_range(0..b.len())),
                _ => {
                    let i = rng.random_range(0..b.len());
                    b.insert(i, rng.random());
                }
            }
            if parse_trex_bytes(Path::new("fuzzed.npz"), &b, &opts()).is_err() {
                refused += 1;
            }
        }
    }
    assert!(
        refused > 400,
        "most damage is noticed (checksums): {refused} of 800"
    );
}

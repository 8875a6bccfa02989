//! 3-D tracks kept 3-D through extract: a synthetic V with a known height pattern, written as a
//! DLTdv `xyzpts` CSV and as a long CSV with `z` (metres, z up, no heading given: it comes from
//! the motion), read and extracted: the params' measured heights equal the pattern's; the
//! steady flight from those params draws heights with the measured spread; a 2-D file has no
//! heights in its params.

mod support;

use formation::annotations::{read, ReadOptions};
use formation::extract::{extract, ExtractOptions, FormationParams};
use formation::keyshape::heights::{heights, heights_for, HeightOptions};
use formation::keyshape::{steady_flight, JostleOptions, SteadyOptions};
use formation::progress::Silent;
use formation::rng::{seeded, stream};
use support::scratch;

/// Wingspan, metres (the files' unit).
const W: f64 = 1.5;
/// Heights above the leader, wingspans, left to right (the leader is the 5th).
const PATTERN: [f64; 9] = [0.62, 0.41, 0.35, 0.12, 0.0, -0.18, -0.05, -0.44, -0.71];
const LEADER: usize = 4;

/// World positions (x east, y north, z up; metres) of the 9 birds in frame `k`: a V (one
/// wingspan apart laterally, 0.8 behind per rank) flying 15 m/s at 30° east of north, 25 fps.
fn world(k: usize) -> Vec<[f64; 3]> {
    let th = 30f64.to_radians();
    let (f, r) = ((th.sin(), th.cos()), (th.cos(), -th.sin()));
    let t = k as f64 / 25.0;
    let c = (100.0 + 15.0 * t * f.0, -40.0 + 15.0 * t * f.1);
    (0..9)
        .map(|i| {
            let x = (i as f64 - LEADER as f64) * W;
            let y = (i as f64 - LEADER as f64).abs() * 0.8 * W;
            [
                c.0 + x * r.0 - y * f.0,
                c.1 + x * r.1 - y * f.1,
                50.0 + PATTERN[i] * W,
            ]
        })
        .collect()
}

/// The pattern's statistics: (spread, neighbour, ahead mean, ahead sd).
fn truth() -> (f64, f64, f64, f64) {
    let n = PATTERN.len() as f64;
    let m = PATTERN.iter().sum::<f64>() / n;
    let spread = (PATTERN.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n).sqrt();
    let nb = (PATTERN
        .windows(2)
        .map(|w| (w[1] - w[0]).powi(2))
        .sum::<f64>()
        / (n - 1.0))
        .sqrt();
    let ahead: Vec<f64> = (0..9)
        .filter(|&i| i != LEADER)
        .map(|i| PATTERN[i] - PATTERN[if i < LEADER { i + 1 } else { i - 1 }])
        .collect();
    let am = ahead.iter().sum::<f64>() / ahead.len() as f64;
    let asd = (ahead.iter().map(|v| (v - am).powi(2)).sum::<f64>() / ahead.len() as f64).sqrt();
    (spread, nb, am, asd)
}

fn xyzpts(frames: usize) -> String {
    let mut s = (1..=9)
        .map(|n| format!("pt{n}_X,pt{n}_Y,pt{n}_Z"))
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    for k in 0..frames {
        let row: Vec<String> = world(k)
            .iter()
            .flat_map(|p| p.iter().map(|v| format!("{v:.9}")))
            .collect();
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

fn long_csv(frames: usize) -> String {
    let mut s = String::from("frame,bird,x,y,z\n");
    for k in 0..frames {
        for (i, p) in world(k).iter().enumerate() {
            s.push_str(&format!("{k},{i},{:.9},{:.9},{:.9}\n", p[0], p[1], p[2]));
        }
    }
    s
}

fn params_of(path: &std::path::Path) -> FormationParams {
    let opts = ReadOptions {
        wingspan_px: Some(W),
        ..ReadOptions::default()
    };
    let ann = read(path, &opts).unwrap();
    // The heading comes from the motion: 30° clockwise from north (y up, seen from above).
    assert!(
        (ann.frames[0].heading_deg - 30.0).abs() < 1e-6,
        "{}",
        ann.frames[0].heading_deg
    );
    extract(&ann, &ExtractOptions::default(), &mut stream(1, "extract")).unwrap()
}

#[test]
fn xyzpts_and_long_csv_with_z_give_the_measured_heights() {
    let dir = scratch("heights_3d_read");
    let (spread, nb, am, asd) = truth();
    for (name, text) in [("xyzpts.csv", xyzpts(12)), ("long.csv", long_csv(12))] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let p = params_of(&path);
        let h = p.heights.unwrap_or_else(|| panic!("{name}: no heights"));
        assert_eq!(h.frames, 12, "{name}");
        for (got, want, what) in [
            (h.spread, spread, "spread"),
            (h.neighbour, nb, "neighbour"),
            (h.ahead_mean, am, "ahead_mean"),
            (h.ahead_sd, asd, "ahead_sd"),
        ] {
            // Written to 1e-9 m: exact up to rounding.
            assert!((got - want).abs() < 1e-6, "{name}: {what} {got} vs {want}");
        }
        // The V itself is found as in 2-D.
        assert_eq!(p.frames[0].shape.kind(), "v", "{name}");
        // The params file keeps the heights.
        let back: FormationParams =
            serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(back.heights, p.heights);
    }
}

#[test]
fn a_2d_file_has_no_heights_and_steady_keeps_the_defaults() {
    let dir = scratch("heights_3d_2d");
    let path = dir.join("long2d.csv");
    let mut s = String::from("# wingspan_px: 1.5\nframe,bird,x,y\n");
    for k in 0..4 {
        for (i, p) in world(k).iter().enumerate() {
            s.push_str(&format!("{k},{i},{:.9},{:.9}\n", p[0], -p[1]));
        }
    }
    std::fs::write(&path, s).unwrap();
    let ann = read(&path, &ReadOptions::default()).unwrap();
    assert!(ann.frames[0].birds.iter().all(|b| b.height.is_none()));
    let p = extract(&ann, &ExtractOptions::default(), &mut stream(1, "extract")).unwrap();
    assert!(p.heights.is_none());
    assert!(!serde_json::to_string(&p).unwrap().contains("\"heights\""));
    assert_eq!(
        heights_for(&p, &HeightOptions::default()),
        HeightOptions::default()
    );
}

#[test]
fn mixed_heights_are_refused_naming_the_bird() {
    let dir = scratch("heights_3d_mixed");
    let path = dir.join("mixed.json");
    std::fs::write(
        &path,
        r#"{"wingspan_px": 10, "frames": [{"index": 0, "birds": [
            {"id": 0, "x": 0, "y": 10, "z": 1}, {"id": 1, "x": 10, "y": 0, "z": 2},
            {"id": 2, "x": 20, "y": 10}]}]}"#,
    )
    .unwrap();
    let e = read(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("frames[0].birds[2]") && e.contains("z"), "{e}");
}

/// Within-frame standard deviation of heights, root mean square over `fields`.
fn rms_spread(fields: &[Vec<f64>]) -> f64 {
    let v: f64 = fields
        .iter()
        .map(|h| {
            let m = h.iter().sum::<f64>() / h.len() as f64;
            h.iter().map(|x| (x - m).powi(2)).sum::<f64>() / h.len() as f64
        })
        .sum::<f64>()
        / fields.len() as f64;
    v.sqrt()
}

#[test]
fn steady_flight_draws_the_measured_height_spread() {
    let dir = scratch("heights_3d_steady");
    let path = dir.join("xyzpts.csv");
    std::fs::write(&path, xyzpts(8)).unwrap();
    let p = params_of(&path);
    let m = p.heights.unwrap();
    let h = heights_for(&p, &HeightOptions::default());
    assert_eq!(h.spread, m.spread);
    assert!(h.neighbour <= m.spread * std::f64::consts::SQRT_2 + 1e-12);
    // The drawn field: 400 flights of 10 keys (4000 fields, about 700 independent ones at the
    // key-to-key correlation 0.7): the RMS spread is within 5 % of the measured one (the
    // variance's relative standard error is about √(2/700) ≈ 5 %, the SD's half that).
    let x: Vec<f64> = (0..9).map(|i| i as f64 - 4.0).collect();
    let mut fields = Vec::new();
    let mut rng = seeded(7);
    for _ in 0..400 {
        fields.extend(heights(9, &x, LEADER, 10, &h, false, &mut rng));
    }
    let drawn = rms_spread(&fields);
    assert!(
        (drawn / m.spread - 1.0).abs() < 0.05,
        "drawn {drawn} vs measured {}",
        m.spread
    );
    // The animation: its birds' heights spread as measured, not as the default 0.14 wingspans.
    // One flight is one draw of the slowly varying field, so only the scale is checked: within
    // a factor 2 of the measured spread (0.42), which the default (0.14) is not.
    let opts = SteadyOptions {
        birds: 9,
        frames: 25 * 40,
        jostle: JostleOptions {
            scale: 0.0,
            ..JostleOptions::default()
        },
        ..SteadyOptions::default()
    };
    let a = steady_flight(&p, &opts, &mut seeded(3), &Silent).unwrap();
    let zs: Vec<Vec<f64>> = a.frames.iter().map(|f| f.z.clone()).collect();
    let got = rms_spread(&zs);
    assert!(
        got > m.spread / 2.0 && got < m.spread * 2.0,
        "animation spread {got}, measured {}",
        m.spread
    );
    let mut p2 = p.clone();
    p2.heights = None;
    let b = steady_flight(&p2, &opts, &mut seeded(3), &Silent).unwrap();
    let zs: Vec<Vec<f64>> = b.frames.iter().map(|f| f.z.clone()).collect();
    let default = rms_spread(&zs);
    eprintln!(
        "measured {:.4}, drawn {drawn:.4}, animation {got:.4}, default animation {default:.4}",
        m.spread
    );
    assert!(default < m.spread / 2.0, "default spread {default}");
}

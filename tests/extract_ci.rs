//! `extract`'s 95 % bootstrap intervals against synthetic footage with a known answer: for many
//! flocks, the interval from 20 frames covers the flock's true median (the median of the same
//! per-frame quantity over 400 frames of the same flock) in at least 90 of 100 seeds; and the
//! intervals are in the params file and the summary.

mod support;

use std::fs;

use formation::annotations::synth::{generate, SynthSpec};
use formation::annotations::{read, ReadOptions};
use formation::extract::bootstrap::{median, nearest_ahead};
use formation::extract::{extract, ExtractOptions, FormationParams, ShapeKind};
use formation::rng::stream;
use support::scratch;

fn spec(seed: u64, frames: usize) -> SynthSpec {
    SynthSpec {
        kind: ShapeKind::V,
        birds: 9 + (seed % 4) as usize,
        frames,
        noise: 0.04,
        drift: 0.0,
        slope_left: 0.55 + 0.05 * (seed % 3) as f64,
        slope_right: 0.6,
        leader_at: 0.5,
        wingspan_px: 30.0,
        heading_deg: 20.0 * (seed % 5) as f64,
        ..SynthSpec::default()
    }
}

fn extracted(seed: u64, frames: usize, dir: &std::path::Path) -> FormationParams {
    let flock = generate(&spec(seed, frames), &mut stream(seed, "ci-flock"));
    let p = dir.join(format!("a{frames}.json"));
    fs::write(
        &p,
        flock.native_json("ci", true, &mut stream(seed, "write")),
    )
    .unwrap();
    let ann = read(&p, &ReadOptions::default()).unwrap();
    extract(&ann, &ExtractOptions::default(), &mut stream(7, "extract")).unwrap()
}

/// The five point quantities of a params file: medians over frames (apex, depth, WTS) and over
/// every bird of every frame (nearest bird ahead).
fn truth(p: &FormationParams) -> [Option<f64>; 5] {
    let g: Vec<_> = p.frames.iter().filter_map(|f| f.geometry).collect();
    let mut apex: Vec<f64> = g.iter().filter_map(|g| g.apex_deg).collect();
    let mut depth: Vec<f64> = g.iter().map(|g| g.depth).collect();
    let mut wts: Vec<f64> = g.iter().map(|g| g.wingtip_spacing).collect();
    let ahead: Vec<(f64, f64)> = p.frames.iter().flat_map(nearest_ahead).collect();
    let mut lat: Vec<f64> = ahead.iter().map(|a| a.0).collect();
    let mut beh: Vec<f64> = ahead.iter().map(|a| a.1).collect();
    [
        median(&mut apex),
        median(&mut lat),
        median(&mut beh),
        median(&mut depth),
        median(&mut wts),
    ]
}

#[test]
fn intervals_cover_the_true_value_in_at_least_90_of_100_seeds() {
    let dir = scratch("extract-ci");
    let names = ["apex_deg", "lateral", "behind", "depth", "wts"];
    let mut covered = [0usize; 5];
    let mut widths = [0.0f64; 5];
    for seed in 0..100u64 {
        let short = extracted(seed, 20, &dir);
        let long = extracted(seed, 400, &dir);
        // The first 20 frames of the long footage are the short footage.
        assert_eq!(short.frames[..], long.frames[..20]);
        let ci = *short.ci.clone().expect("intervals");
        let t = truth(&long);
        let got = [ci.apex_deg, ci.lateral, ci.behind, ci.depth, ci.wts];
        for q in 0..5 {
            let [lo, hi] = got[q].unwrap_or_else(|| panic!("seed {seed}: no {}", names[q]));
            let v = t[q].unwrap();
            assert!(lo <= hi && lo.is_finite(), "seed {seed}: {}", names[q]);
            // The interval is around the footage's own estimate.
            let own = truth(&short)[q].unwrap();
            assert!(
                lo <= own && own <= hi,
                "seed {seed}: {} {own} not in [{lo}, {hi}]",
                names[q]
            );
            if lo <= v && v <= hi {
                covered[q] += 1;
            }
            widths[q] += (hi - lo) / 100.0;
        }
    }
    eprintln!("covered {covered:?} of 100; mean widths {widths:?}");
    for q in 0..5 {
        assert!(
            covered[q] >= 90,
            "{}: covered the truth in {} of 100 seeds",
            names[q],
            covered[q]
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

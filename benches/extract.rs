//! Benchmarks of the extract stage (criterion). Results: docs/performance.md.
//!
//! - `extract/41x1000`: §4 steps 1–2 on 1000 frames of a 41-bird V with 4 outliers (the issue's
//!   target: under 1 s), from parsed annotations.
//! - `read+extract/41x1000`: the same including parsing the native JSON text.
//! - `ransac_line/2000_arms`: the RANSAC line fits alone, one per V arm (2000 fits), which is
//!   what scikit-learn's `RANSACRegressor` is compared with: before criterion runs, the arms are
//!   written to `target/extract-bench-arms.csv` and `benches/extract_sklearn.py` is run on them
//!   (when python3 with scikit-learn is available) in the same process, and its timing printed.

use std::hint::black_box;
use std::io::Write as _;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use formation::annotations::synth::{generate, SynthSpec};
use formation::annotations::{parse_str, ReadOptions};
use formation::extract::ransac::{ransac, Line, RansacOptions};
use formation::extract::{extract, ExtractOptions, ShapeKind, ShapeModel};
use formation::rng::stream;

fn flock_text() -> String {
    let spec = SynthSpec {
        kind: ShapeKind::V,
        birds: 41,
        frames: 1000,
        slope_left: 0.55,
        slope_right: 0.5,
        leader_at: 0.45,
        noise: 0.06,
        drift: 0.03,
        outliers: 4,
        ..SynthSpec::default()
    };
    let flock = generate(&spec, &mut stream(1, "bench"));
    flock.native_json("bench", true, &mut stream(1, "w"))
}

fn bench(c: &mut Criterion) {
    let text = flock_text();
    let path = Path::new("bench.json");
    let ann = parse_str(path, &text, &ReadOptions::default()).expect("bench annotations");
    let opts = ExtractOptions::default();

    // The arms of every frame (leader in both), for the line-fit comparison.
    let params = extract(&ann, &opts, &mut stream(0, "e")).expect("extract");
    let ro = RansacOptions {
        threshold: opts.inlier_threshold,
        max_samples: opts.max_samples,
        refine_rounds: opts.refine_rounds,
    };
    let mut arms: Vec<Vec<(f64, f64)>> = Vec::new();
    for f in &params.frames {
        let pts: Vec<(f64, f64)> = f.positions.iter().map(|p| (p.x, p.y)).collect();
        arms.push(pts.iter().copied().filter(|p| p.0 <= 0.0).collect());
        arms.push(pts.iter().copied().filter(|p| p.0 >= 0.0).collect());
    }
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    let csv_path = target.join("extract-bench-arms.csv");
    if let Ok(mut f) = std::fs::File::create(&csv_path) {
        let mut rng = stream(0, "arms");
        let _ = writeln!(f, "fit,x,y,rust_slope,rust_intercept");
        for (k, arm) in arms.iter().enumerate() {
            if let Some((l, _)) = ransac::<Line>(arm, &ro, &mut rng) {
                for p in arm {
                    let _ = writeln!(f, "{k},{},{},{},{}", p.0, p.1, l.s, l.c);
                }
            }
        }
        drop(f);
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/extract_sklearn.py");
        match std::process::Command::new("python3")
            .arg(&script)
            .arg(&csv_path)
            .output()
        {
            Ok(o) if o.status.success() => {
                println!(
                    "scikit-learn RANSACRegressor on the same arms: {}",
                    String::from_utf8_lossy(&o.stdout).trim()
                )
            }
            Ok(o) => println!(
                "scikit-learn comparison skipped: {}",
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
            ),
            Err(e) => println!("scikit-learn comparison skipped: {e}"),
        }
    }
    let kinds = params
        .frames
        .iter()
        .filter(|f| matches!(f.shape, ShapeModel::V { .. }))
        .count();
    println!("extract on the bench flock: {kinds}/1000 frames fitted as V");

    let mut g = c.benchmark_group("extract");
    g.sample_size(10);
    g.bench_function("extract/41x1000", |b| {
        b.iter(|| extract(black_box(&ann), &opts, &mut stream(0, "e")).expect("extract"))
    });
    g.bench_function("read+extract/41x1000", |b| {
        b.iter(|| {
            let a = parse_str(path, black_box(&text), &ReadOptions::default()).expect("read");
            extract(&a, &opts, &mut stream(0, "e")).expect("extract")
        })
    });
    g.bench_function("ransac_line/2000_arms", |b| {
        b.iter(|| {
            let mut rng = stream(0, "arms");
            for arm in &arms {
                black_box(ransac::<Line>(arm, &ro, &mut rng));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! No two birds clash along a path (the clash test of docs/formats.md): a flight taking off into
//! the tightest turn the flock can fly (a right-angle corner, widened to that radius), turning
//! again and landing at the path's end; a loop on a closed circuit of radius 35 wingspans; 41
//! birds through the corner. Birds on the inside of a turn fly slower and closer along the track
//! than on the outside (docs/paths.md): the key shapes' fore-aft step (0.35 wingspans) shrinks to
//! no less than 0.6 of itself there, still more than the clash test's chord, and the landing
//! keeps its along-track gaps for the bent course. Before the landing allowed for the bend, 2 of
//! 20 such flights clashed in the landing (10 and 2 bird-frames).

mod support;

use formation::animation::clearance::Clearance;
use formation::animation::Animation;
use support::{example_arg, run, s, scratch};

/// Runs `animate` with `args` and returns the clearance of each stage it wrote.
fn stages(dir: &std::path::Path, args: &[&str]) -> Vec<(String, Clearance)> {
    let out = dir.join("a.json");
    let mut all = vec!["animate", "-o", s(&out), "--quiet"];
    all.extend_from_slice(args);
    let o = run(&all);
    assert!(
        o.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    Clearance::by_stage(&Animation::read(&out).expect("read the animation back"))
}

fn assert_clear(stages: &[(String, Clearance)], what: &str) {
    assert!(!stages.is_empty(), "{what}: no stages");
    for (name, c) in stages {
        assert!(c.frames > 0, "{what}: an empty {name} stage");
        assert_eq!(
            (c.wing, c.body),
            (0, 0),
            "{what}, {name}: {} wing and {} body clashes in {} frames, closest {:?}",
            c.wing,
            c.body,
            c.frames_with_clash,
            c.closest
        );
    }
}

#[test]
fn a_tight_turn_with_take_off_and_landing_stays_clear() {
    let dir = scratch("clearance-path-turn");
    // A right-angle corner 40 wingspans after the start (widened to the flock's smallest
    // radius, about 25 wingspans), another, and a climb; the flock lands at the end.
    let path = dir.join("turns.json");
    std::fs::write(
        &path,
        r#"{"points": [[0,0,10],[0,40,10],[-100,40,10],[-100,-60,12],[60,-60,10]]}"#,
    )
    .unwrap();
    let geese = example_arg("barnacle_geese_v.json");
    let pelicans = example_arg("pelicans_u_labelme");
    for (input, fps, seed) in [
        (&geese, "30", "0"),
        (&geese, "30", "1"),
        (&geese, "30", "2"),
        (&geese, "24", "0"),
        (&geese, "60", "0"),
        (&pelicans, "30", "1"),
    ] {
        let st = stages(
            &dir,
            &[
                input,
                "--birds",
                "14",
                "--path",
                s(&path),
                "--seconds",
                "30",
                "--land",
                "--fps",
                fps,
                "--seed",
                seed,
            ],
        );
        assert!(st.iter().any(|(n, _)| n == "landing"));
        assert_clear(
            &st,
            &format!("{input} through two tight turns, seed {seed} at {fps} fps"),
        );
    }
    // 41 birds (a wider V: its outer birds fly farther inside and outside the turn).
    let corner = dir.join("corner.json");
    std::fs::write(
        &corner,
        r#"{"points": [[0,0,10],[0,150,10],[-150,150,10]]}"#,
    )
    .unwrap();
    let st = stages(
        &dir,
        &[
            &geese,
            "--birds",
            "41",
            "--path",
            s(&corner),
            "--no-initiation",
            "--seconds",
            "30",
        ],
    );
    assert_clear(&st, "41 birds through a tight corner");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_loop_on_a_tight_circuit_stays_clear() {
    let dir = scratch("clearance-path-loop");
    let circle = dir.join("circle.json");
    let pts: Vec<String> = (0..=16)
        .map(|k| {
            let a = std::f64::consts::TAU * (k % 16) as f64 / 16.0;
            format!("[{:.6},{:.6},10]", 35.0 * a.cos(), 35.0 * a.sin())
        })
        .collect();
    std::fs::write(&circle, format!(r#"{{"points": [{}]}}"#, pts.join(","))).unwrap();
    let geese = example_arg("barnacle_geese_v.json");
    for seed in ["0", "1", "2"] {
        let st = stages(
            &dir,
            &[
                &geese,
                "--birds",
                "14",
                "--path",
                s(&circle),
                "--loop",
                "--no-initiation",
                "--seconds",
                "22",
                "--seed",
                seed,
            ],
        );
        assert_clear(
            &st,
            &format!("a loop on a circuit of radius 35, seed {seed}"),
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

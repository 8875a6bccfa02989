//! No two birds clash in any frame of a take-off or a landing (the clash test of
//! docs/formats.md: in a bird's heading frame under 1 wingspan laterally, 0.15 fore and aft and
//! 0.08 vertically is a wing clash; bodies under 0.3 wingspans apart clash). Every example
//! footage, seeds 0–9 at 30 frames per second and seeds 0–2 at 24 and 60, 14 birds taking off,
//! flying 2 s and landing; and the README job itself (default length) over seeds 0–4.
//! Before the take-off kept the wing envelope (docs/initiation.md), 13 of the 40 runs at 30 fps
//! clashed in the take-off (3 to 26 bird-frames each), and the README job 3 (seed 0) and 33
//! (seed 2).

mod support;

use formation::animation::clearance::Clearance;
use support::clearance::{animate, assert_clear, examples};
use support::{example_arg, scratch};

/// Runs `animate` on `input` with `args` and returns the clearance of each stage it wrote.
fn stages(dir: &std::path::Path, input: &str, args: &[&str]) -> Vec<(String, Clearance)> {
    Clearance::by_stage(&animate(dir, input, args))
}

/// Asserts that stage `name` of `stages` was written and is clear.
fn assert_stage_clear(stages: &[(String, Clearance)], name: &str, what: &str) {
    let c = stages
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{what}: no {name} stage"))
        .1;
    assert!(c.frames > 0, "{what}: an empty {name} stage");
    assert_clear(&c, &format!("{what}, {name}"));
}

#[test]
fn every_example_and_seed_takes_off_and_lands_clear_at_any_frame_rate() {
    let dir = scratch("clearance-takeoff");
    for (name, input, read) in examples() {
        for (fps, seeds) in [("30", 0..10), ("24", 0..3), ("60", 0..3)] {
            for seed in seeds {
                let seed = seed.to_string();
                let mut args = read.clone();
                args.extend_from_slice(&[
                    "--birds",
                    "14",
                    "--seconds",
                    "2",
                    "--land",
                    "--fps",
                    fps,
                    "--seed",
                    &seed,
                ]);
                let st = stages(&dir, &input, &args);
                let what = format!("{name} seed {seed} at {fps} fps");
                assert_stage_clear(&st, "initiation", &what);
                assert_stage_clear(&st, "landing", &what);
            }
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_readme_job_takes_off_clear() {
    let dir = scratch("clearance-takeoff-readme");
    let geese = example_arg("barnacle_geese_v.json");
    for seed in ["0", "1", "2", "3", "4"] {
        let st = stages(
            &dir,
            &geese,
            &[
                "--birds",
                "14",
                "--species",
                "barnacle-goose",
                "--seed",
                seed,
            ],
        );
        assert_stage_clear(&st, "initiation", &format!("the README job, seed {seed}"));
    }
    let _ = std::fs::remove_dir_all(dir);
}

//! No two birds clash in any frame of a steady flight (the clash test of docs/formats.md: in a
//! bird's heading frame under 1 wingspan laterally, 0.15 fore and aft and 0.08 vertically is a
//! wing clash; bodies under 0.3 wingspans apart clash). Every example footage, seeds 0–9 at
//! 30 frames per second and seeds 0–2 at 24 and 60, with the default living flight (position
//! keeping, leader changes, swaps); three leader changes and six swaps a minute over two
//! minutes, seeds 0–9; late birds joining; 1000 birds in skeins.

mod support;

use formation::animation::clearance::Clearance;
use support::clearance::{animate, assert_clear, examples};
use support::{example_arg, scratch};

/// Runs `animate` on `input` with `args` (steady flight only) and returns the clearance of
/// what it wrote.
fn clearance(dir: &std::path::Path, input: &str, args: &[&str]) -> Clearance {
    let mut all = vec!["--no-initiation"];
    all.extend_from_slice(args);
    Clearance::of(&animate(dir, input, &all))
}

#[test]
fn every_example_and_seed_flies_clear_at_any_frame_rate() {
    let dir = scratch("clearance-examples");
    for (name, input, read) in examples() {
        for (fps, seeds) in [("30", 0..10), ("24", 0..3), ("60", 0..3)] {
            for seed in seeds {
                let seed = seed.to_string();
                let mut args = read.clone();
                args.extend_from_slice(&[
                    "--birds",
                    "14",
                    "--seconds",
                    "20",
                    "--fps",
                    fps,
                    "--seed",
                    &seed,
                ]);
                let c = clearance(&dir, &input, &args);
                assert!(c.frames > 0);
                assert_clear(&c, &format!("{name} seed {seed} at {fps} fps"));
            }
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn busy_flights_stay_clear() {
    let dir = scratch("clearance-busy");
    let geese = example_arg("barnacle_geese_v.json");
    for seed in 0..=9 {
        let seed = &seed.to_string();
        let c = clearance(
            &dir,
            &geese,
            &[
                "--birds",
                "14",
                "--seconds",
                "120",
                "--leader-changes",
                "3",
                "--swaps",
                "6",
                "--seed",
                seed,
            ],
        );
        assert_clear(
            &c,
            &format!("3 leader changes and 6 swaps a minute, seed {seed}"),
        );
    }
    for seed in ["0", "1", "2"] {
        let c = clearance(
            &dir,
            &geese,
            &[
                "--birds",
                "9",
                "--seconds",
                "30",
                "--joiners",
                "2",
                "--seed",
                seed,
            ],
        );
        assert_clear(&c, &format!("two late birds joining, seed {seed}"));
    }
    let c = clearance(&dir, &geese, &["--birds", "1000", "--seconds", "4"]);
    assert_clear(&c, "1000 birds in skeins");
    let _ = std::fs::remove_dir_all(dir);
}

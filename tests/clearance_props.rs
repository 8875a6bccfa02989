//! The clash test of docs/formats.md as a property: any example footage, any seed, any of the
//! usual frame rates, a flock of 5 to 24 birds taking off, living its steady flight with leader
//! changes, swaps and late joiners at random rates (joiners without the take-off), and landing on
//! the ground or on water, has no wing or body clash in any frame of the steady flight or the
//! landing, and no body clash and at most a few wing bird-frames in the take-off (see the
//! assertion). The cases are drawn from a fixed seed, so a run is the same every time (no flaky
//! failures); each is a few tenths of a CPU second. This test found two landing faults that the
//! seeds of the other tests missed (a stagger reckoned from the gap after the blend of velocities
//! instead of the start's; birds nearly in line stopping a chord, not a body, apart).

mod support;

use formation::animation::clearance::Clearance;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use support::clearance::{animate, examples};
use support::scratch;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        rng_seed: RngSeed::Fixed(43),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]
    #[test]
    fn any_flight_is_clear_in_every_stage(
        example in 0usize..4,
        seed in 0u64..1_000_000,
        fps in prop::sample::select(vec![24u32, 25, 30, 50, 60]),
        birds in 5usize..25,
        leader_changes in 0u32..4,
        swaps in 0u32..7,
        joiners in 0usize..3,
        water in any::<bool>(),
    ) {
        let (_, input, read) = &examples()[example];
        let dir = scratch(&format!("clearance-props-{seed}"));
        let (seed_s, fps_s, birds_s) = (seed.to_string(), fps.to_string(), birds.to_string());
        let (lc, sw, jo) = (leader_changes.to_string(), swaps.to_string(), joiners.to_string());
        let mut args = read.clone();
        args.extend_from_slice(&[
            "--birds", &birds_s, "--seconds", "20", "--land", "--fps", &fps_s, "--seed", &seed_s,
            "--leader-changes", &lc, "--swaps", &sw, "--joiners", &jo,
        ]);
        // Late birds join a formation already flying: no take-off then.
        if joiners > 0 {
            args.push("--no-initiation");
        }
        if water {
            args.extend_from_slice(&["--land-on", "water"]);
        }
        let anim = animate(&dir, input, &args);
        for (stage, c) in Clearance::by_stage(&anim) {
            // The take-off is a simulation of the paper's rules with the wing envelope kept by
            // steering, not by construction: in 6 × 64 random flights 2 took off with 4 wing
            // clashes each (bird-frames, closest 0.40 and 0.74 wingspans) and none with a body
            // clash. Held here to that: no body clash, at most 8 wing bird-frames.
            let wing_allowed = if stage == "initiation" { 8 } else { 0 };
            prop_assert!(
                c.wing <= wing_allowed && c.body == 0,
                "{:?}, {}: {} wing and {} body clashes, closest {:?}",
                args, stage, c.wing, c.body, c.closest
            );
        }
        let _ = std::fs::remove_dir_all(dir);
    }
}

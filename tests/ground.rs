//! Birds on the ground (take-off): at rest they sit, wings folded, not flapping; the run starts
//! the wingbeat; no part of the built-in bird goes below the ground in any frame.

mod support;

use std::path::Path;

use formation::animation::Animation;
use formation::export::bird::{self, BirdAsset};
use formation::pipeline::{Config, Pipeline};
use formation::wingbeat::rest::{stance, REST_SPEED_MS};
use formation::wingbeat::{self, Flapper, Species, WingPose};
use glam::{Quat, Vec3};
use support::rig::{legs, lowest_vertex, wings};

fn lowest(asset: &BirdAsset, pose: &WingPose) -> f32 {
    lowest_vertex(asset, pose, 0.0, Vec3::ZERO, Quat::IDENTITY)
}

#[test]
fn the_stance_keeps_the_built_in_bird_above_the_ground_folded_and_flapping() {
    for sp in [Species::Goose, Species::Crane, Species::Pelican] {
        let a = BirdAsset::builtin(sp);
        let st = stance(sp);
        let folded = lowest(&a, &wingbeat::FOLDED);
        let flap = wingbeat::wingbeat_curve(sp, 256)
            .iter()
            .map(|(_, p)| lowest(&a, p))
            .fold(f32::INFINITY, f32::min);
        // Sitting: the belly on the ground (within 5 mm for a goose), never under it.
        assert!(
            st.sit as f32 + folded >= 0.0,
            "{sp}: sits {} under",
            st.sit as f32 + folded
        );
        assert!(
            st.sit as f32 + folded < 0.004,
            "{sp}: sits {} above",
            st.sit as f32 + folded
        );
        // Standing: the lowest wingtip of a full downstroke clears the ground.
        assert!(
            st.stand as f32 + flap >= 0.0,
            "{sp}: a downstroke reaches {}",
            st.stand as f32 + flap
        );
        assert!(st.stand > st.sit);
    }
}

fn take_off(birds: usize, species: Species, seed: u64) -> Animation {
    let mut c = Config {
        seed,
        seconds: Some(1.0),
        ..Config::default()
    };
    c.steady.birds = birds;
    c.wingbeat.species = species;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    Pipeline::from_path(path)
        .run(&c)
        .expect("the take-off runs")
        .0
}

/// Checks every frame of the take-off on the rig: no vertex under the ground; at rest folded and
/// not flapping; the wingbeat under way within 0.2 s of the run's start. Returns the lowest
/// vertex over the take-off (wingspans).
fn check_on_the_rig(anim: &Animation, species: Species) -> f32 {
    let asset = BirdAsset::builtin(species);
    let flapper = Flapper::from_animation(anim);
    let ws = anim.wingspan_m;
    let stage = anim.stage("initiation").expect("a take-off").clone();
    let mut lowest_all = f32::INFINITY;
    for b in 0..anim.birds {
        let flight = bird::flight(anim, b, ws);
        let mut run_start: Option<f64> = None;
        let mut flapping_from: Option<f64> = None;
        for k in stage.start..stage.end {
            let f = &anim.frames[k];
            let v_ms = f.speed[b] * ws;
            let pose = flapper.pose(k, b);
            if v_ms < REST_SPEED_MS && f.z[b] < 1.0 {
                assert_eq!(
                    wings(pose),
                    wingbeat::FOLDED,
                    "bird {b} frame {k}: at rest, wings folded"
                );
                if k > stage.start {
                    let before = &anim.frames[k - 1];
                    if before.speed[b] * ws < REST_SPEED_MS {
                        assert_eq!(
                            flapper.phase(k, b),
                            flapper.phase(k - 1, b),
                            "bird {b} frame {k}: no wingbeat at rest"
                        );
                    }
                }
            }
            if run_start.is_none() && f.speed[b] > 0.0 && f.z[b] < 1.0 {
                run_start = Some(f.t);
            }
            if flapping_from.is_none() && wings(pose) != wingbeat::FOLDED {
                flapping_from = Some(f.t);
            }
            let root = flight.translation[k] / ws as f32;
            if root.y > 0.7 {
                continue; // every pose fits in a sphere of 0.6 wingspans
            }
            let low = lowest_vertex(&asset, &pose, flight.bank[k], root, flight.yaw[k]);
            assert!(
                low >= -1e-4,
                "bird {b} frame {k}: a vertex {low} wingspans under the ground; z {} v {} bank {} root {root:?} pose {pose:?} {}",
                f.z[b], f.speed[b], flight.bank[k], anim.species.clone().unwrap_or_default()
            );
            lowest_all = lowest_all.min(low);
        }
        if let (Some(r), Some(fl)) = (run_start, flapping_from) {
            assert!(
                fl - r <= 0.2 + 1e-9,
                "bird {b}: runs at {r:.3} s, flaps at {fl:.3} s"
            );
        } else if run_start.is_some() {
            panic!("bird {b} runs but never flaps");
        }
    }
    lowest_all
}

#[test]
fn take_offs_sit_fold_run_and_flap_above_the_ground() {
    for (birds, species, seed) in [
        (9, Species::Goose, 1),
        (14, Species::Goose, 0),
        (14, Species::Crane, 2),
        (14, Species::Pelican, 3),
        (41, Species::Goose, 4),
        (100, Species::Goose, 5),
        // The crane's legs swing (down while it runs, back after lift-off).
        (9, Species::Crane, 1),
        (41, Species::Crane, 4),
        (100, Species::Crane, 5),
    ] {
        let anim = take_off(birds, species, seed);
        let low = check_on_the_rig(&anim, species);
        // The flock sat on the ground first: its lowest point touches it.
        assert!(low < 0.01, "{birds} {species}: lowest point {low}");
        // Sitting for the default second before the first run.
        let first_run = (0..anim.birds)
            .filter_map(|b| anim.frames.iter().find(|f| f.speed[b] > 0.0).map(|f| f.t))
            .fold(f64::INFINITY, f64::min);
        assert!(
            (first_run - 1.0).abs() < 0.05,
            "{birds}: the first run starts at {first_run} s"
        );
    }
}

/// The crane's legs on the rig over a take-off: folded forward under the belly while it sits,
/// straight down under the body while it stands and runs, trailing behind once it has climbed
/// away (the swing back takes `LEG_SWING_S` after lift-off).
#[test]
fn a_crane_sits_on_folded_legs_runs_on_them_and_trails_them_after_lift_off() {
    use formation::wingbeat::rest::{leg, LEG_SWING_S, LIFT_OFF_BAND};
    let sp = Species::Crane;
    let anim = take_off(14, sp, 2);
    let asset = BirdAsset::builtin(sp);
    let flapper = Flapper::from_animation(&anim);
    let (st, reach) = (stance(sp), leg(sp).reach as f32);
    let ws = anim.wingspan_m;
    let (mut sat, mut ran, mut trailed) = (0, 0, 0);
    for b in 0..anim.birds {
        let flight = bird::flight(&anim, b, ws);
        let mut lift_off: Option<f64> = None;
        for (k, f) in anim.frames.iter().enumerate() {
            let pose = flapper.pose(k, b);
            let root = flight.translation[k] / ws as f32;
            let rot = flight.yaw[k];
            for (hip, toe) in legs(&asset, &pose, flight.bank[k], root, rot) {
                // The leg in the body's frame: +Z forward, +Y up.
                let l = rot.inverse() * (toe - hip);
                let z = f.z[b];
                if z <= st.sit + 1e-9 && f.speed[b] == 0.0 {
                    assert!(l.z > 0.8 * reach, "bird {b} frame {k}: sitting, leg {l}");
                    sat += 1;
                } else if (z - st.stand).abs() < 1e-6 && f.speed[b] * ws > REST_SPEED_MS {
                    assert!(
                        (toe - hip).y < -0.95 * reach && l.z.abs() < 0.2 * reach,
                        "bird {b} frame {k}: running, leg {l}"
                    );
                    ran += 1;
                }
                if lift_off.is_some_and(|t| f.t > t + LEG_SWING_S) {
                    assert!(l.z < -0.99 * reach, "bird {b} frame {k}: climbing, leg {l}");
                    trailed += 1;
                }
            }
            if lift_off.is_none() && f.z[b] > st.stand + LIFT_OFF_BAND {
                lift_off = Some(f.t);
            }
        }
        assert!(lift_off.is_some(), "bird {b} never lifted off");
    }
    assert!(sat > 0 && ran > 0 && trailed > 0, "{sat} {ran} {trailed}");
}

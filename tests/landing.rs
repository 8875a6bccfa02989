//! Landing (`--land`): checked on the rig in every frame of the landing for 9, 14, 41 and 100
//! birds: no vertex of the built-in bird under the ground, birds slower than 0.5 m/s folded and
//! not flapping, every bird at rest at the end in its order of arrival, at least 0.3 wingspans
//! from any other, no two birds closer than 0.3 wingspans at any time, the same landing at 24
//! and 60 fps; bad inputs refused in one line.

mod support;

use std::path::Path;

use formation::animation::Animation;
use formation::export::bird::{self, BirdAsset};
use formation::initiate::landing::{Surface, FLOAT_HEIGHT};
use formation::pipeline::{Config, Pipeline};
use formation::wingbeat::rest::{stance, REST_SPEED_MS};
use formation::wingbeat::{self, Flapper, Species, WingPose};
use support::rig::{legs, lowest_vertex, wings};
use support::{bin, example_arg, scratch};

fn landing(birds: usize, seed: u64, fps: f64, surface: Surface, takeoff: bool) -> Animation {
    landing_of(Species::Goose, birds, seed, fps, surface, takeoff)
}

fn landing_of(
    species: Species,
    birds: usize,
    seed: u64,
    fps: f64,
    surface: Surface,
    takeoff: bool,
) -> Animation {
    let mut c = Config {
        seed,
        seconds: Some(1.0),
        initiation: takeoff,
        land: true,
        ..Config::default()
    };
    c.steady.birds = birds;
    c.steady.fps = fps;
    c.landing.surface = surface;
    c.wingbeat.species = species;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    Pipeline::from_path(path)
        .run(&c)
        .expect("the landing runs")
        .0
}

/// Every check of the landing stage on the rig; returns the smallest distance between two birds
/// over the landing (wingspans).
fn check_on_the_rig(anim: &Animation, species: Species) -> f64 {
    let asset = BirdAsset::builtin(species);
    let flapper = Flapper::from_animation(anim);
    let ws = anim.wingspan_m;
    let stage = anim.stage("landing").expect("a landing").clone();
    assert_eq!(
        stage.end,
        anim.frames.len(),
        "the landing ends the animation"
    );
    let water = anim
        .landing
        .as_ref()
        .is_some_and(|l| l.surface == Surface::Water);
    let fold_frames = (wingbeat::rest::UNFOLD_S * anim.fps).ceil() as usize + 1;
    for b in 0..anim.birds {
        let flight = bird::flight(anim, b, ws);
        for k in stage.start..stage.end {
            let pose = flapper.pose(k, b);
            let resting = |k: usize| {
                let f = &anim.frames[k];
                f.speed[b] * ws < REST_SPEED_MS && f.z[b] < 1.0
            };
            if resting(k) {
                // Folded once the wings have had their time to fold.
                let settled = k
                    .checked_sub(fold_frames)
                    .is_some_and(|s| (s..=k).all(resting));
                if settled && water {
                    // Floating, the folded wings lie level on the water.
                    let folded = wingbeat::FOLDED;
                    assert!(
                        (pose.dihedral - folded.dihedral).abs() < 0.01
                            && WingPose {
                                dihedral: folded.dihedral,
                                ..wings(pose)
                            } == folded,
                        "bird {b} frame {k}: folded at rest, {pose:?}"
                    );
                } else if settled {
                    assert_eq!(
                        wings(pose),
                        wingbeat::FOLDED,
                        "bird {b} frame {k}: folded at rest"
                    );
                }
                let before = &anim.frames[k - 1];
                if before.speed[b] * ws < REST_SPEED_MS {
                    assert_eq!(
                        flapper.phase(k, b),
                        flapper.phase(k - 1, b),
                        "bird {b} frame {k}: no wingbeat below 0.5 m/s"
                    );
                }
            }
            let root = flight.translation[k] / ws as f32;
            if root.y > 0.7 {
                continue; // every pose fits in a sphere of 0.6 wingspans
            }
            let low = lowest_vertex(&asset, &pose, flight.bank[k], root, flight.yaw[k]);
            // On water the body floats: its lower part (the body's depth, about 0.1 wingspans)
            // is under the waterline, and the tail touches it in the flare.
            let floor = if water { -0.1 } else { -1e-4 };
            assert!(
                low >= floor,
                "bird {b} frame {k}: a vertex {low} wingspans under the ground"
            );
        }
    }
    // No collisions: the closest two birds over the landing.
    let mut closest = f64::INFINITY;
    for f in &anim.frames[stage.start..stage.end] {
        for i in 0..anim.birds {
            for j in 0..i {
                let d = (f.x[i] - f.x[j])
                    .hypot(f.y[i] - f.y[j])
                    .hypot(f.z[i] - f.z[j]);
                closest = closest.min(d);
            }
        }
    }
    closest
}

/// Each bird's touch-down (first frame on the ground) and stop (first frame at rest for good)
/// times from the frames alone.
fn arrivals(anim: &Animation, ground: f64) -> Vec<(f64, f64)> {
    let stage = anim.stage("landing").unwrap();
    (0..anim.birds)
        .map(|b| {
            let frames = &anim.frames[stage.start..stage.end];
            let down = frames
                .iter()
                .find(|f| f.z[b] <= ground + 1e-9)
                .map(|f| f.t)
                .expect("every bird touches down");
            let stop = frames
                .iter()
                .rposition(|f| f.speed[b] > 0.0)
                .map(|k| frames[(k + 1).min(frames.len() - 1)].t)
                .unwrap_or(frames[0].t);
            (down, stop)
        })
        .collect()
}

#[test]
fn landings_touch_down_in_turn_stop_apart_and_sit_on_the_ground() {
    let st = stance(Species::Goose);
    for (birds, seed) in [(9, 1), (14, 0), (41, 4), (100, 5)] {
        let anim = landing(birds, seed, 30.0, Surface::Ground, true);
        let closest = check_on_the_rig(&anim, Species::Goose);
        assert!(closest >= 0.3, "{birds} birds: two came {closest} apart");
        let last = anim.frames.last().unwrap();
        for b in 0..birds {
            assert_eq!(last.speed[b], 0.0, "{birds}: bird {b} still moving");
            assert!(
                (last.z[b] - st.sit).abs() < 1e-9,
                "{birds}: bird {b} not sitting"
            );
        }
        for i in 0..birds {
            for j in 0..i {
                let d = (last.x[i] - last.x[j]).hypot(last.y[i] - last.y[j]);
                assert!(d >= 0.3, "{birds}: birds {i}, {j} rest {d} wingspans apart");
            }
        }
        // Touch-downs one after another, front first; birds stop in the order they arrived.
        let times = arrivals(&anim, st.stand);
        let rec = anim.landing.as_ref().unwrap();
        let order = rec.arrival_order();
        for w in order.windows(2) {
            let (a, b) = (times[w[0]], times[w[1]]);
            assert!(
                a.0 <= b.0 + 1.0 / 30.0 + 1e-9,
                "{birds}: {w:?} land {a:?} {b:?}"
            );
            assert!(
                a.1 <= b.1 + 1.0 / 30.0 + 1e-9,
                "{birds}: {w:?} stop {a:?} {b:?}"
            );
        }
        let spread = rec.touchdown[order[birds - 1]] - rec.touchdown[order[0]];
        assert!(spread > 0.2, "{birds}: all touched down within {spread} s");
        // Speeds and sink rates bounded and smooth over the landing.
        let stage = anim.stage("landing").unwrap();
        let dt = 1.0 / anim.fps;
        for w in anim.frames[stage.start - 1..stage.end].windows(2) {
            for b in 0..birds {
                let accel = (w[1].speed[b] - w[0].speed[b]).abs() / dt * anim.wingspan_m;
                assert!(
                    accel < 9.0,
                    "{birds}: bird {b} at {:.2} s: {accel} m/s²",
                    w[1].t
                );
                let sink = (w[1].z[b] - w[0].z[b]).abs() / dt * anim.wingspan_m;
                assert!(
                    sink < 4.0,
                    "{birds}: bird {b} at {:.2} s: {sink} m/s",
                    w[1].t
                );
            }
        }
    }
}

#[test]
fn on_water_the_flock_settles_at_the_waterline() {
    let anim = landing(14, 2, 30.0, Surface::Water, true);
    check_on_the_rig(&anim, Species::Goose);
    let last = anim.frames.last().unwrap();
    assert!(last.z.iter().all(|&z| (z - FLOAT_HEIGHT).abs() < 1e-9));
    assert!(last.speed.iter().all(|&v| v == 0.0));
}

#[test]
fn a_steady_flight_alone_lands_from_its_cruise_altitude() {
    let anim = landing(9, 3, 30.0, Surface::Ground, false);
    let stage = anim.stage("landing").unwrap();
    let start = &anim.frames[stage.start];
    assert!(
        start.z.iter().all(|&z| (z - 10.0).abs() < 1.0),
        "{:?}",
        start.z
    );
    check_on_the_rig(&anim, Species::Goose);
}

#[test]
fn the_same_seed_lands_the_same_at_24_and_60_fps() {
    let a = landing(9, 7, 24.0, Surface::Ground, false);
    let b = landing(9, 7, 60.0, Surface::Ground, false);
    let (ra, rb) = (a.landing.unwrap(), b.landing.unwrap());
    for i in 0..9 {
        assert!(
            (ra.touchdown[i] - rb.touchdown[i]).abs() < 0.05,
            "bird {i}: {} and {} s",
            ra.touchdown[i],
            rb.touchdown[i]
        );
    }
    let (fa, fb) = (a.frames.last().unwrap(), b.frames.last().unwrap());
    for i in 0..9 {
        let d = (fa.x[i] - fb.x[i]).hypot(fa.y[i] - fb.y[i]);
        assert!(d < 0.1, "bird {i} rests {d} wingspans apart");
    }
}

#[test]
fn bad_landings_are_refused_in_one_line() {
    let dir = scratch("landing_bad");
    let out = dir.join("x.json");
    let run = |extra: &[&str]| {
        let o = bin()
            .args([
                "animate",
                &example_arg("barnacle_geese_v.json"),
                "--birds",
                "9",
            ])
            .args(["--seconds", "6", "-o", out.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    for (extra, word) in [
        (&["--land", "--loop", "--no-initiation"][..], "--land"),
        (&["--land", "--loop"][..], "--land"),
        (&["--land-on", "lava"][..], "--land-on"),
        (
            &["--land", "--ground-seconds", "-1"][..],
            "--ground-seconds",
        ),
    ] {
        let (code, err) = run(extra);
        assert_eq!(code, Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
        assert!(err.contains(word), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} left a file");
    }
}

#[test]
fn on_a_path_the_flock_comes_to_rest_at_its_end() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/path_turn_climb.json");
    let mut c = Config {
        seed: 2,
        seconds: Some(1.0),
        land: true,
        ..Config::default()
    };
    c.steady.birds = 9;
    c.course.path = Some(path);
    let geese = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    let (anim, report) = Pipeline::from_path(geese).run(&c).expect("lands");
    assert!(
        report.course.warnings.is_empty(),
        "{:?}",
        report.course.warnings
    );
    // The path ends at (450, 350), heading east, 30 wingspans up: the front bird rests under it.
    let last = anim.frames.last().unwrap();
    let front = (0..9)
        .max_by(|&a, &b| last.x[a].total_cmp(&last.x[b]))
        .unwrap();
    assert!(
        (last.x[front] - 450.0).abs() < 1.0,
        "front at {}",
        last.x[front]
    );
    assert!(last.x.iter().all(|&x| x <= 450.0 + 1e-6));
    assert!(last.y.iter().all(|&y| (y - 350.0).abs() < 5.0));
    check_on_the_rig(&anim, Species::Goose);
}

#[test]
fn a_shot_length_cuts_the_steady_flight_so_that_the_landing_ends_it() {
    let mut c = Config {
        seed: 4,
        shot_seconds: Some(45.0),
        land: true,
        ..Config::default()
    };
    c.steady.birds = 9;
    let geese = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json");
    let (anim, _) = Pipeline::from_path(geese).run(&c).expect("lands");
    assert_eq!(anim.frames.len(), 1350);
    assert_eq!(anim.stage("landing").map(|s| s.end), Some(1350));
    assert!(anim.frames.last().unwrap().speed.iter().all(|&v| v == 0.0));
    // Too short for the take-off and the landing: refused, naming the shot's length.
    c.shot_seconds = Some(12.0);
    let e = Pipeline::from_path(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json"),
    )
    .run(&c)
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("shot_seconds: "), "{e}");
}

/// The crane's legs on the rig over a landing of 9, 14, 41 and 100 birds: trailing in the glide,
/// swung down (toes below the hips) through the last third of the flare, straight down under the
/// body while the bird stands and runs out, folded forward under the belly once it sits; and no
/// vertex under the ground in any frame (with the checks of every landing).
#[test]
fn a_crane_lowers_its_legs_in_the_flare_and_lands_on_them() {
    use formation::wingbeat::rest::leg;
    let sp = Species::Crane;
    let (st, reach) = (stance(sp), leg(sp).reach as f32);
    let asset = BirdAsset::builtin(sp);
    for (birds, seed) in [(9, 1), (14, 0), (41, 4), (100, 5)] {
        let anim = landing_of(sp, birds, seed, 30.0, Surface::Ground, true);
        check_on_the_rig(&anim, sp);
        let flapper = Flapper::from_animation(&anim);
        let rec = anim.landing.clone().expect("a landing record");
        let fs = rec.flare_seconds;
        let stage = anim.stage("landing").unwrap().clone();
        let ws = anim.wingspan_m;
        let (mut glide, mut flare, mut stood, mut sat) = (0, 0, 0, 0);
        for b in 0..birds {
            let flight = bird::flight(&anim, b, ws);
            let td = rec.touchdown[b];
            for k in stage.start..stage.end {
                let f = &anim.frames[k];
                let pose = flapper.pose(k, b);
                let rot = flight.yaw[k];
                let root = flight.translation[k] / ws as f32;
                for (hip, toe) in legs(&asset, &pose, flight.bank[k], root, rot) {
                    let l = rot.inverse() * (toe - hip);
                    let at = format!("{birds} birds, bird {b} at {:.3} s: leg {l}", f.t);
                    if f.t < td - fs {
                        assert!(l.z < -0.99 * reach, "{at}: trailing in the glide");
                        glide += 1;
                    } else if f.t >= td - fs / 3.0 && f.t <= td {
                        assert!((toe - hip).y < -0.5 * reach, "{at}: down in the flare");
                        flare += 1;
                    }
                    if f.t >= td && (f.z[b] - st.stand).abs() < 1e-6 {
                        assert!(
                            (toe - hip).y < -0.8 * reach && l.z.abs() < 0.2 * reach,
                            "{at}: standing on them (body pitched {:.1}°)",
                            f.pitch.as_ref().map_or(0.0, |p| p[b].to_degrees())
                        );
                        stood += 1;
                    }
                    if f.t > td && f.speed[b] == 0.0 && (f.z[b] - st.sit).abs() < 1e-9 {
                        assert!(l.z > 0.8 * reach, "{at}: folded under the sitting bird");
                        sat += 1;
                    }
                }
            }
        }
        assert!(
            glide > 0 && flare > 0 && stood > 0 && sat > 0,
            "{birds}: {glide} {flare} {stood} {sat}"
        );
    }
}

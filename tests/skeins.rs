//! Issue 13: large flocks fly as several formations (skeins). The 1000-bird flock from the
//! 9-goose example (take-off and steady flight), one formation where it should be, determinism,
//! the clearance between formations, and one-line exit-2 errors for bad flags.

mod support;

use formation::animation::{Animation, FormationRecord};
use formation::pipeline::{Config, Pipeline};
use formation::skein::min_separation;
use support::{assert_usage_error, example, run, s, scratch};

fn config(birds: usize, seed: u64, seconds: f64) -> Config {
    let mut c = Config {
        seed,
        seconds: Some(seconds),
        ..Config::default()
    };
    c.steady.birds = birds;
    c
}

/// Smallest distance between two birds of the same formation in frame `f`, wingspans.
fn min_within(a: &Animation, f: usize) -> f64 {
    let fr = &a.frames[f];
    let mut best = f64::INFINITY;
    for fm in a.formations.as_ref().unwrap() {
        for (p, &i) in fm.birds.iter().enumerate() {
            for &j in &fm.birds[..p] {
                let d = ((fr.x[i] - fr.x[j]).powi(2)
                    + (fr.y[i] - fr.y[j]).powi(2)
                    + (fr.z[i] - fr.z[j]).powi(2))
                .sqrt();
                best = best.min(d);
            }
        }
    }
    best
}

#[test]
fn a_thousand_geese_take_off_into_many_line_formations() {
    // Line formations of key shapes (the leader front-most even where its nearest neighbours
    // fly almost abreast): without position keeping, whose fore-aft moves can bring an abreast
    // neighbour level with the leader. The clearance between formations is checked with it.
    let mut c = config(1000, 0, 20.0);
    c.steady.jostle.scale = 0.0;
    let (a, report) = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap();
    a.validate(std::path::Path::new("flock")).unwrap();
    let fs = a.formations.as_ref().expect("several formations");
    assert!(fs.len() >= 20, "{} formations", fs.len());
    assert!(fs.iter().all(|f| f.birds.len() <= 40 && f.birds.len() >= 3));
    assert_eq!(fs.iter().map(|f| f.birds.len()).sum::<usize>(), 1000);
    let stats = report.initiate.as_ref().unwrap();
    assert!(stats.converged && stats.birds == 1000);
    let sk = report.skein.as_ref().unwrap();
    assert!(sk.min_separation >= 5.0, "{}", sk.min_separation);
    assert_eq!(a.leaders(), fs.iter().map(|f| f.leader).collect::<Vec<_>>());
    let of = a.formation_of_birds();
    for (k, f) in fs.iter().enumerate() {
        assert!(f.birds.iter().all(|&b| of[b] == k));
        assert!(!f.key_shapes.is_empty());
    }
    // Every formation is a line formation in every steady frame sampled: the leader front-most,
    // every follower behind it, and each follower with a bird of its formation ahead of it
    // within formation spacing.
    let steady = a.stage("steady").unwrap().clone();
    assert_eq!(steady.end - steady.start, 600);
    for f in (steady.start..steady.end).step_by(60) {
        let fr = &a.frames[f];
        for fm in fs {
            let l = fm.leader;
            for &i in &fm.birds {
                if i == l {
                    continue;
                }
                // Behind along the leader's heading (formations drift by up to 1° of heading;
                // the leader's nearest neighbours fly almost abreast at the footage's spacing:
                // 0.018 wingspans behind at the least for this seed).
                let h = fr.heading[l];
                let behind = -((fr.x[i] - fr.x[l]) * h.sin() + (fr.y[i] - fr.y[l]) * h.cos());
                assert!(
                    behind > 0.005,
                    "frame {f}: bird {i} not behind its leader {l} ({behind} wingspans)"
                );
                let near = fm
                    .birds
                    .iter()
                    .filter(|&&j| j != i && fr.y[j] > fr.y[i])
                    .map(|&j| (fr.x[j] - fr.x[i]).hypot(fr.y[j] - fr.y[i]))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    near < 3.0,
                    "frame {f}: bird {i} is {near} wingspans from the bird ahead"
                );
            }
        }
    }
    // No two birds closer than 0.3 wingspans in any frame; formations never within the
    // clearance (checked with the library's pruned search, and by brute force on some frames).
    for f in 0..a.frames.len() {
        let d = min_within(&a, f);
        assert!(d >= 0.3, "frame {f}: two birds {d} wingspans apart");
    }
    assert!(min_separation(&a) >= 5.0);
    for f in (0..a.frames.len()).step_by(97) {
        let fr = &a.frames[f];
        for i in 0..1000 {
            for j in 0..i {
                if of[i] != of[j] {
                    let d = (fr.x[i] - fr.x[j]).hypot(fr.y[i] - fr.y[j]);
                    assert!(
                        d >= 5.0,
                        "frame {f}: birds {i} and {j} of different formations {d} apart"
                    );
                }
            }
        }
    }
}

#[test]
fn small_flocks_and_formations_one_stay_one_formation() {
    let dir = scratch("skeins-one");
    let geese = example("barnacle_geese_v.json");
    for (birds, extra, want) in [
        ("14", vec![], None),
        ("18", vec![], None),
        ("19", vec![], Some(2)),
        ("60", vec!["--formations", "1"], None),
        ("60", vec!["--formation-size", "20"], Some(3)),
        ("60", vec!["--formations", "4"], Some(4)),
    ] {
        let out = dir.join(format!("a{birds}-{}.json", extra.len()));
        let mut args = vec![
            "animate",
            s(&geese),
            "--birds",
            birds,
            "--no-initiation",
            "--seconds",
            "2",
            "-q",
            "-o",
            s(&out),
        ];
        args.extend(extra.iter().copied());
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let a = Animation::read(&out).unwrap();
        assert_eq!(
            a.formations.as_ref().map(|f| f.len()),
            want,
            "{birds} {extra:?}"
        );
        if want.is_none() {
            let text = std::fs::read_to_string(&out).unwrap();
            assert!(!text.contains("\"formations\""));
            assert!(!a.key_shapes.is_empty());
        }
    }
}

/// How each follower of `fm` has moved against its leader since the first frame, across the
/// course (`z` false) or in height (`z` true), wingspans: `[frame][follower]`, the followers in
/// the formation's order. Formations of one size fill their slots in the same order, so equal
/// plans would give equal tables whatever each formation's own gaps.
fn moves_against_leader(a: &Animation, fm: &FormationRecord, z: bool) -> Vec<Vec<f64>> {
    let of = |f: &formation::animation::Frame, i: usize| if z { f.z[i] } else { f.x[i] };
    let first = &a.frames[0];
    a.frames
        .iter()
        .map(|f| {
            fm.birds
                .iter()
                .filter(|&&i| i != fm.leader)
                .map(|&i| (of(f, i) - of(f, fm.leader)) - (of(first, i) - of(first, fm.leader)))
                .collect()
        })
        .collect()
}

/// The steady flight's slow lateral drift and the birds' heights are drawn per formation
/// (`rng::Scope::Formation`): formations of one size must not breathe sideways or step in
/// height in lock-step (they did when both were drawn from the run's seed alone: the lateral
/// moves of every two formations of one size agreed to 1e-14 wingspans).
#[test]
fn formations_of_equal_size_breathe_independently() {
    for seed in [0, 1, 2] {
        let mut c = config(120, seed, 20.0);
        c.initiation = false;
        let (a, _) = Pipeline::from_path(example("barnacle_geese_v.json"))
            .run(&c)
            .unwrap();
        let fs = a.formations.as_ref().expect("several formations");
        let mut pairs = 0;
        for (p, fp) in fs.iter().enumerate() {
            for (q, fq) in fs.iter().enumerate().skip(p + 1) {
                if fp.birds.len() != fq.birds.len() {
                    continue;
                }
                pairs += 1;
                for (z, what) in [(false, "lateral"), (true, "height")] {
                    let (mp, mq) = (
                        moves_against_leader(&a, fp, z),
                        moves_against_leader(&a, fq, z),
                    );
                    let most = mp
                        .iter()
                        .flatten()
                        .zip(mq.iter().flatten())
                        .map(|(u, v)| (u - v).abs())
                        .fold(0.0, f64::max);
                    // Independent drifts of about 0.1 wingspans (lateral) and heights of 0.14
                    // differ by 0.3 wingspans or more somewhere over 20 s.
                    assert!(
                        most > 0.05,
                        "seed {seed}: formations {p} and {q} ({} birds) move in lock-step ({what}: they differ by at most {most:.2e} wingspans)",
                        fp.birds.len()
                    );
                }
            }
        }
        assert!(pairs >= 5, "seed {seed}: only {pairs} pairs of equal size");
        if seed == 0 {
            let (b, _) = Pipeline::from_path(example("barnacle_geese_v.json"))
                .run(&c)
                .unwrap();
            assert!(
                serde_json::to_string(&a).unwrap() == serde_json::to_string(&b).unwrap(),
                "same seed, another flock"
            );
        }
    }
}

#[test]
fn equal_seeds_give_equal_bytes_and_other_seeds_another_flock() {
    let dir = scratch("skeins-seeds");
    let geese = example("barnacle_geese_v.json");
    let make = |seed: &str, name: &str| {
        let (j, c) = (
            dir.join(format!("{name}.json")),
            dir.join(format!("{name}.csv")),
        );
        let o = run(&[
            "animate",
            s(&geese),
            "--birds",
            "120",
            "--seconds",
            "3",
            "--seed",
            seed,
            "-q",
            "-o",
            s(&j),
            "-o",
            s(&c),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        (std::fs::read(j).unwrap(), std::fs::read(c).unwrap())
    };
    let a = make("7", "a");
    let b = make("7", "b");
    let c = make("8", "c");
    assert!(a == b, "same seed, different bytes");
    assert!(a.0 != c.0);
}

#[test]
fn the_clearance_holds_for_many_seeds_and_is_settable() {
    for seed in 0..6 {
        for clearance in [5.0, 12.0] {
            let mut c = config(150, seed, 10.0);
            c.initiation = false;
            c.skein.clearance = clearance;
            let (a, r) = Pipeline::from_path(example("barnacle_geese_v.json"))
                .run(&c)
                .unwrap();
            let sep = min_separation(&a);
            assert!(sep >= clearance, "seed {seed}: {sep} < {clearance}");
            assert_eq!(r.skein.unwrap().min_separation, sep);
            // Drift: the formations' headings differ from the course by at most about 1° (the
            // mean over the birds); each bird's own heading also carries its position keeping
            // (lateral moves of ~0.3 wingspans/s at ~10 wingspans/s: a few degrees).
            let f = a.frames.last().unwrap();
            let mean = f.heading.iter().sum::<f64>() / f.heading.len() as f64;
            assert!(
                mean.abs() < 2f64.to_radians(),
                "seed {seed}: mean heading {mean}"
            );
            assert!(f.heading.iter().all(|h| h.abs() < 8f64.to_radians()));
        }
    }
}

#[test]
fn a_steady_flock_file_takes_off_formation_by_formation() {
    let dir = scratch("skeins-initiate");
    let (p, st, init) = (dir.join("p.json"), dir.join("s.json"), dir.join("i.json"));
    let geese = example("barnacle_geese_v.json");
    assert!(run(&["extract", s(&geese), "-q", "-o", s(&p)])
        .status
        .success());
    let o = run(&[
        "steady",
        s(&p),
        "--birds",
        "60",
        "--frames",
        "60",
        "-q",
        "-o",
        s(&st),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&["initiate", s(&st), "-q", "-o", s(&init)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = Animation::read(&init).unwrap();
    assert_eq!(a.formation_count(), 7);
    assert!(a.stage("initiation").is_some());
    assert!(min_separation(&a) >= 5.0);
    let chart = dir.join("k.png");
    for cmd in ["power", "xi", "paths"] {
        let o = run(&["plot", cmd, s(&init), "--formation", "6", "-o", s(&chart)]);
        assert!(
            o.status.success(),
            "{cmd}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = run(&[
        "plot",
        "power",
        s(&init),
        "--formation",
        "7",
        "-o",
        s(&chart),
    ]);
    assert_usage_error(&o, &["--formation", "7", "7 formation(s)"]);
}

#[test]
fn bad_formation_flags_are_one_line_errors() {
    let dir = scratch("skeins-bad");
    let geese = example("barnacle_geese_v.json");
    let out = dir.join("never.json");
    let cases: [(&[&str], &[&str]); 6] = [
        (&["--formations", "0"], &["--formations", "at least 1"]),
        (
            &["--formations", "101"],
            &["--formations", "101", "at most 50"],
        ),
        (
            &["--formations", "51"],
            &["--formations", "at least 2 birds"],
        ),
        (&["--formation-size", "1"], &["--formation-size", "1"]),
        (
            &["--formations", "3", "--formation-size", "10"],
            &["--formations/--formation-size", "conflict", "10 formations"],
        ),
        (&["--clearance", "-2"], &["--clearance"]),
    ];
    for (flags, needles) in cases {
        let mut args = vec!["animate", s(&geese), "--birds", "100", "-o", s(&out)];
        args.extend_from_slice(flags);
        assert_usage_error(&run(&args), needles);
        assert!(!out.exists());
    }
    // Consistent flags are accepted.
    let o = run(&[
        "animate",
        s(&geese),
        "--birds",
        "100",
        "--formations",
        "10",
        "--formation-size",
        "10",
        "--no-initiation",
        "--seconds",
        "1",
        "-q",
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn the_follow_camera_frames_the_whole_sky_of_formations() {
    use formation::export::pictures::Film;
    use formation::export::RenderOptions;
    let mut c = config(200, 0, 4.0);
    c.initiation = false;
    let (a, _) = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap();
    let opts = RenderOptions {
        width: 1280,
        height: 720,
        ..RenderOptions::default()
    };
    let film = Film::with_options(&a, 25.0, &opts);
    assert!(film.len() > 50);
    for (k, v) in film.views.iter().enumerate() {
        let st = film.states(k);
        assert!(
            v.scale() >= 3.0 - 1e-9,
            "frame {k}: {} px per wingspan",
            v.scale()
        );
        for b in st {
            let (x, y) = v.to_pixel(b.x, b.y, 1280, 720);
            assert!(
                (0.0..1280.0).contains(&x) && (0.0..720.0).contains(&y),
                "frame {k}: a bird at ({x:.0}, {y:.0}) is outside the picture"
            );
        }
    }
    // One formation of the same flock is not framed whole: its birds stay at least 12 px.
    let one = a.formation(0).unwrap();
    let film = Film::with_options(&one, 25.0, &opts);
    assert!(film.views.iter().all(|v| v.scale() >= 12.0 - 1e-9));
}

#[test]
fn a_take_off_that_never_converges_is_flown_again_then_reported() {
    // 6 s of flight are too short for any formation to form: every formation tries
    // TAKEOFF_TRIES take-offs (fresh steady flights and starts), then the run fails naming one.
    let mut c = config(60, 0, 2.0);
    c.initiate.max_time = 6.0;
    // Low enough to climb to in the time the limit leaves after the hold and the last run (a
    // cruise altitude out of the climb's reach is refused up front, exit 2).
    c.initiate.cruise_altitude = 1.0;
    let e = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap_err();
    let msg = e.to_string();
    assert_eq!(e.exit_code(), 1);
    assert!(msg.starts_with("formation 0 ("), "{msg}");
    assert!(
        msg.contains(&format!("in {} take-offs", formation::skein::TAKEOFF_TRIES)),
        "{msg}"
    );
    // A normal run flies each formation's take-off once or a few times.
    let (_, report) = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&config(60, 0, 2.0))
        .unwrap();
    let sk = report.skein.unwrap();
    assert!(sk
        .formations
        .iter()
        .all(|f| (1..=formation::skein::TAKEOFF_TRIES).contains(&f.takeoff_tries)));
}

#[test]
fn a_flock_taken_apart_gives_each_formation_as_it_reads_alone() {
    // `into_formations` (which consumes the flock frame by frame, so a flock's take-off from a
    // steady file never holds its frames twice) gives exactly what `formation(k)` copies out.
    let mut c = config(200, 0, 2.0);
    c.initiation = false;
    let (a, _) = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap();
    let k = a.formation_count();
    assert!(k > 1, "{k} formations");
    let each: Vec<_> = (0..k).map(|f| a.formation(f).unwrap()).collect();
    let apart = a.clone().into_formations();
    assert_eq!(apart.len(), k);
    for (f, (x, y)) in each.iter().zip(&apart).enumerate() {
        assert_eq!(x, y, "formation {f}");
        assert!(!x.frames.is_empty());
    }
    // A flock of one formation is itself.
    let one = each[0].clone();
    assert_eq!(one.clone().into_formations(), vec![one]);
}

/// Per formation at frame `k`: mean position (x, y, z) and mean heading (radians, clockwise from
/// north).
fn formation_means(a: &Animation, k: usize) -> Vec<[f64; 4]> {
    let fr = &a.frames[k];
    a.formations
        .as_ref()
        .unwrap()
        .iter()
        .map(|fm| {
            let n = fm.birds.len() as f64;
            let mut m = [0.0; 4];
            let (mut hs, mut hc) = (0.0, 0.0);
            for &i in &fm.birds {
                m[0] += fr.x[i] / n;
                m[1] += fr.y[i] / n;
                m[2] += fr.z[i] / n;
                hs += fr.heading[i].sin();
                hc += fr.heading[i].cos();
            }
            m[3] = hs.atan2(hc);
            m
        })
        .collect()
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt(),
    )
}

/// The natural layout of 1000 birds is not a drill pattern: formations' heights spread by at
/// least a wingspan, the distance from each formation to its nearest varies (coefficient of
/// variation at least 0.25), headings spread by at least 1° with every formation within 15° of
/// the course; the grid layout (the earlier lattice) is measured beside it and is the regular
/// one.
#[test]
fn the_natural_layout_scatters_formations_in_height_distance_and_heading() {
    let measure = |layout: formation::skein::SkeinLayout, seed: u64| {
        let mut c = config(1000, seed, 12.0);
        c.initiation = false;
        c.skein.layout = layout;
        let (a, report) = Pipeline::from_path(example("barnacle_geese_v.json"))
            .run(&c)
            .unwrap();
        assert!(report.skein.as_ref().unwrap().min_separation >= 5.0);
        let mut stats = Vec::new();
        for k in (0..a.frames.len()).step_by(90) {
            let m = formation_means(&a, k);
            let heights: Vec<f64> = m.iter().map(|v| v[2]).collect();
            let headings: Vec<f64> = m.iter().map(|v| v[3].to_degrees()).collect();
            let nearest: Vec<f64> = m
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    m.iter()
                        .enumerate()
                        .filter(|&(j, _)| j != i)
                        .map(|(_, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            let (_, h_sd) = mean_sd(&heights);
            let (_, hd_sd) = mean_sd(&headings);
            let worst = headings.iter().fold(0.0f64, |w, h| w.max(h.abs()));
            let (nm, nsd) = mean_sd(&nearest);
            eprintln!(
                "{layout:?} seed {seed} frame {k}: heights sd {h_sd:.2}, headings sd {hd_sd:.2}° \
                 (worst {worst:.2}°), nearest-formation distance CV {:.3} (mean {nm:.1})",
                nsd / nm
            );
            stats.push((h_sd, hd_sd, worst, nsd / nm));
        }
        stats
    };
    let natural = (0..3).flat_map(|seed| measure(formation::skein::SkeinLayout::Natural, seed));
    for (h_sd, hd_sd, worst, cv) in natural {
        assert!(h_sd >= 1.0, "formations' heights sd {h_sd} wingspans");
        assert!(hd_sd >= 1.0, "formations' headings sd {hd_sd}°");
        assert!(worst <= 15.0, "a formation {worst}° off the course");
        assert!(cv >= 0.25, "nearest-formation distance CV {cv}");
    }
    for (h_sd, _, _, cv) in measure(formation::skein::SkeinLayout::Grid, 0) {
        assert!(h_sd < 0.5, "grid heights sd {h_sd}");
        assert!(cv < 0.25, "grid nearest-formation CV {cv}");
    }
}

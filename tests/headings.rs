//! Issue 19, "headings everywhere": every output that depends on the flock's heading is checked
//! at headings other than north. One flight (the same params, seed and take-off) is flown along
//! straight paths heading north, east (90°) and south-west (225°), and along issue 19's path with
//! a 90° turn and a climb (`tests/data/path_turn_climb.json`) turned to start at 225°. The course
//! frame is the same in every run, so each world-frame run is the north run turned and moved:
//! - the charts (power, ξ, savings, take-off paths, shape) show the same in their own frames;
//! - the cameras (follow, ground) frame the flock whatever its heading;
//! - the hand-over from the take-off into the steady flight is the same step, turned.

mod support;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use formation::annotations::{Annotations, Heading};
use formation::export::pictures::Film;
use formation::export::{CameraKind, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::plot::paths::PathsChart;
use formation::plot::power::{PowerChart, PowerMetric, PowerOf};
use formation::plot::savings::SavingsChart;
use formation::plot::shape::ShapeChart;
use formation::plot::xi::XiChart;
use formation::Animation;

use support::{data, scratch};

/// Where every straight path starts (world frame, wingspans).
const START: [f64; 3] = [30.0, -40.0, 10.0];

/// `p` turned clockwise (seen from above) by `h` radians about the origin.
fn turn(p: (f64, f64), h: f64) -> (f64, f64) {
    let (s, c) = h.sin_cos();
    (p.0 * c + p.1 * s, -p.0 * s + p.1 * c)
}

/// A straight path from [`START`] at heading `deg` (clockwise from north), 3000 wingspans long.
fn straight(dir: &Path, deg: f64) -> PathBuf {
    let (dx, dy) = turn((0.0, 3000.0), deg.to_radians());
    let p = dir.join(format!("straight_{deg}.json"));
    let end = [START[0] + dx, START[1] + dy, START[2]];
    std::fs::write(&p, format!("{{\"points\": [{START:?}, {end:?}]}}")).unwrap();
    p
}

/// Issue 19's test path (a straight, a 90° right turn of radius 150, a climb) turned to start
/// at heading `deg`.
fn turning(dir: &Path, deg: f64) -> PathBuf {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("path_turn_climb.json")).unwrap())
            .unwrap();
    let pts: Vec<[f64; 3]> = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let q: Vec<f64> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_f64().unwrap())
                .collect();
            let (x, y) = turn((q[0], q[1]), deg.to_radians());
            [x, y, q[2]]
        })
        .collect();
    let p = dir.join(format!("turning_{deg}.json"));
    std::fs::write(&p, format!("{{\"points\": {pts:?}}}")).unwrap();
    p
}

/// 9 geese of the V example's params: the take-off, then `seconds` of steady flight on `path`.
fn fly(path: &Path, seconds: f64) -> Animation {
    let mut c = Config {
        seed: 5,
        seconds: Some(seconds),
        ..Config::default()
    };
    c.steady.birds = 9;
    c.course.path = Some(path.to_path_buf());
    // The take-off must end before the test path's turn (200 wingspans out): climb at the
    // former 2.5 wingspans/s (a goose's power-limited climb doubles the take-off's length).
    c.initiate.climb_rate = Some(2.5);
    Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap()
        .0
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a.is_nan() && b.is_nan()) || (a - b).abs() <= tol
}

fn assert_all_close(what: &str, a: &[f64], b: &[f64], tol: f64) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            close(*x, *y, tol),
            "{what}[{k}]: {x} against {y} (tolerance {tol})"
        );
    }
}

/// The steady flight's middle frame and a frame halfway through the take-off.
fn frames_to_chart(a: &Animation) -> [usize; 2] {
    let s = a.stage("steady").unwrap();
    let t = a.stage("initiation").unwrap();
    [(s.start + s.end) / 2, (t.start + t.end) / 2]
}

/// Every chart of `a` is the chart of `north` in its own frame; the take-off paths' world
/// panel is the north one turned by `h` about [`START`]. Within what the runs store: positions
/// to 10⁻⁵ wingspans (10⁻⁴ allowed for lengths, which also turn with headings stored to
/// 10⁻⁶ radians over tens of wingspans) and savings to 10⁻⁶ (2·10⁻⁶ allowed).
fn assert_same_charts(north: &Animation, a: &Animation, h: f64, what: &str) {
    let origin = Path::new("flock.json");
    for k in frames_to_chart(north) {
        for metric in [PowerMetric::Xi, PowerMetric::E] {
            let n = PowerChart::from_animation(north, origin, PowerOf::Frame(k), metric).unwrap();
            let c = PowerChart::from_animation(a, origin, PowerOf::Frame(k), metric).unwrap();
            assert_all_close(&format!("{what}: power frame {k}: bars"), &c.x, &n.x, 1e-4);
            assert_all_close(
                &format!("{what}: power frame {k}"),
                &c.values,
                &n.values,
                2e-6,
            );
        }
    }
    let n = PowerChart::from_animation(north, origin, PowerOf::Key(1), PowerMetric::Xi).unwrap();
    let c = PowerChart::from_animation(a, origin, PowerOf::Key(1), PowerMetric::Xi).unwrap();
    assert_eq!(
        (&c.x, &c.values, c.leader),
        (&n.x, &n.values, n.leader),
        "{what}: key 1"
    );

    let n = XiChart::from_animation(north, origin).unwrap();
    let c = XiChart::from_animation(a, origin).unwrap();
    assert_eq!(c.t, n.t, "{what}: ξ chart times");
    assert_eq!(
        (&c.rank, &c.leaders),
        (&n.rank, &n.leaders),
        "{what}: ranks"
    );
    assert_eq!(c.takeoff, n.takeoff);
    for (i, (x, y)) in c.xi.iter().zip(&n.xi).enumerate() {
        assert_all_close(&format!("{what}: ξ of bird {i}"), x, y, 2e-6);
    }

    let n = SavingsChart::from_animation(north, origin).unwrap();
    let c = SavingsChart::from_animation(a, origin).unwrap();
    assert_eq!(c.stats.birds.len(), n.stats.birds.len());
    for (x, y) in c.stats.birds.iter().zip(&n.stats.birds) {
        assert_eq!(
            (x.bird, x.leader, x.formation),
            (y.bird, y.leader, y.formation)
        );
        for (u, v, name) in [
            (x.rank, y.rank, "rank"),
            (x.saving, y.saving, "saving"),
            (x.lateral, y.lateral, "lateral"),
            (x.behind, y.behind, "behind"),
        ] {
            assert!(
                close(u, v, 1e-4),
                "{what}: bird {} {name}: {u} against {v}",
                x.bird
            );
        }
    }
    let flat = |s: &[(f64, f64)]| s.iter().flat_map(|p| [p.0, p.1]).collect::<Vec<f64>>();
    assert_all_close(
        &format!("{what}: saving over time"),
        &flat(&c.stats.saving_over_time),
        &flat(&n.stats.saving_over_time),
        2e-6,
    );

    let n = PathsChart::from_animation(north).unwrap();
    let c = PathsChart::from_animation(a).unwrap();
    assert_eq!(
        (c.leader, &c.rank),
        (n.leader, &n.rank),
        "{what}: paths' leader"
    );
    for i in 0..a.birds {
        assert_all_close(
            &format!("{what}: moving panel, bird {i}"),
            &flat(&c.relative[i]),
            &flat(&n.relative[i]),
            1e-4,
        );
        let turned: Vec<(f64, f64)> = n.world[i]
            .iter()
            .map(|&(x, y)| {
                let (u, v) = turn((x - START[0], y - START[1]), h);
                (u + START[0], v + START[1])
            })
            .collect();
        assert_all_close(
            &format!("{what}: world panel, bird {i}"),
            &flat(&c.world[i]),
            &flat(&turned),
            1e-4,
        );
    }
}

#[test]
fn the_charts_show_the_same_flight_at_any_heading() {
    let dir = scratch("headings-charts");
    let north = fly(&straight(&dir, 0.0), 6.0);
    for deg in [90.0f64, 225.0] {
        let a = fly(&straight(&dir, deg), 6.0);
        // The run really flies that way: the leader's heading in the steady flight.
        let k = frames_to_chart(&a)[0];
        let l = a.leaders()[0];
        let dh = (a.frames[k].heading[l] - north.frames[k].heading[l] - deg.to_radians())
            .rem_euclid(2.0 * PI);
        // Headings are stored to 10⁻⁶ radians.
        assert!(
            dh.min(2.0 * PI - dh) < 1.5e-6,
            "{deg}°: heading off by {dh}"
        );
        assert_same_charts(&north, &a, deg.to_radians(), &format!("{deg}°"));
    }
}

#[test]
fn on_a_turning_path_the_charts_keep_the_formation() {
    let dir = scratch("headings-turn");
    // Long enough to fly the whole turn: 200 wingspans of straight and 236 of arc.
    let straight = fly(&straight(&dir, 225.0), 40.0);
    let turned = fly(&turning(&dir, 225.0), 40.0);
    // Frames well inside the turn: the leader's heading has turned by 30° to 60°.
    let l = turned.leaders()[0];
    let h0 = turned.frames[turned.stage("steady").unwrap().start].heading[l];
    let in_turn: Vec<usize> = (0..turned.frames.len())
        .filter(|&k| {
            let d = (turned.frames[k].heading[l] - h0)
                .rem_euclid(2.0 * PI)
                .to_degrees();
            (30.0..=60.0).contains(&d)
        })
        .collect();
    assert!(in_turn.len() > 50, "{} frames in the turn", in_turn.len());
    let origin = Path::new("flock.json");
    let mut worst = 0.0f64;
    for &k in in_turn.iter().step_by(10) {
        let s = PowerChart::from_animation(&straight, origin, PowerOf::Frame(k), PowerMetric::Xi)
            .unwrap();
        let t = PowerChart::from_animation(&turned, origin, PowerOf::Frame(k), PowerMetric::Xi)
            .unwrap();
        // The savings are the formation's (computed in the formation frame); the bars stand at
        // the birds' slots in the turning formation frame, within a tenth of a wingspan of the
        // straight flight's (0.084 measured): the leader's heading is its velocity's, and in a
        // turn of radius 150 the chord to a bird a few wingspans behind differs from the arc.
        assert_all_close(&format!("turn frame {k}: ξ"), &t.values, &s.values, 1e-9);
        for (a, b) in t.x.iter().zip(&s.x) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(
        worst < 0.15,
        "bars moved by up to {worst} wingspans in the turn"
    );
    // ξ over time and the ranks do not change with the turn.
    let (s, t) = (
        XiChart::from_animation(&straight, origin).unwrap(),
        XiChart::from_animation(&turned, origin).unwrap(),
    );
    assert_eq!((&t.rank, &t.leaders, &t.t), (&s.rank, &s.leaders, &s.t));
    for (i, (x, y)) in t.xi.iter().zip(&s.xi).enumerate() {
        assert_all_close(&format!("turn: ξ of bird {i}"), x, y, 1e-9);
    }
    // The take-off (before the turn) is the straight one's, chart for chart.
    let (s, t) = (
        PathsChart::from_animation(&straight).unwrap(),
        PathsChart::from_animation(&turned).unwrap(),
    );
    assert_eq!(t.leader, s.leader);
    for i in 0..turned.birds {
        for (p, q) in t.relative[i].iter().zip(&s.relative[i]) {
            assert!(
                close(p.0, q.0, 1e-6) && close(p.1, q.1, 1e-6),
                "bird {i}: {p:?} {q:?}"
            );
        }
    }
    // Charts draw: every one renders on a path with a turn.
    let svg = formation::plot::render(&t, formation::io::OutputKind::Svg).unwrap();
    assert!(svg.starts_with(b"<svg"));
}

#[test]
fn the_shape_chart_does_not_depend_on_the_heading_in_the_footage() {
    // A V of 7 birds seen in the image with the flight direction up, right (90°) and 225°.
    let v: Vec<(f64, f64)> = (0..7)
        .map(|i| {
            let rank = ((i + 1) / 2) as f64;
            let side = if i % 2 == 1 { 1.0 } else { -1.0 };
            (side * 1.6 * rank, 1.1 * rank)
        })
        .collect();
    let chart = |deg: f64, heading: Heading| {
        // Image coordinates: x right, y down; the flock flies towards image-up turned
        // clockwise by `deg`, the birds behind the leader lie opposite.
        let frames: Vec<Vec<[f64; 2]>> = (0..3)
            .map(|f| {
                v.iter()
                    .map(|&(lat, back)| {
                        let (x, y) = turn((lat, -back), deg.to_radians());
                        [400.0 + 30.0 * x + f as f64, 300.0 - 30.0 * y]
                    })
                    .collect()
            })
            .collect();
        let ann = Annotations::from_points("memory", heading, 30.0, &frames).unwrap();
        let (p, _) = formation::pipeline::extract_stage(
            &ann,
            &Config::default(),
            &formation::progress::Silent,
        )
        .unwrap();
        ShapeChart::from_params(&p, None, Some(0.3), Path::new("memory")).unwrap()
    };
    let up = chart(0.0, Heading::Up);
    for (deg, h) in [(90.0, Heading::Right), (225.0, Heading::Degrees(225.0))] {
        let c = chart(deg, h);
        assert_eq!(c.frame.leader, up.frame.leader, "{deg}°");
        assert_eq!(c.frame.shape.kind(), up.frame.shape.kind(), "{deg}°");
        for (a, b) in c.frame.positions.iter().zip(&up.frame.positions) {
            assert_eq!(a.id, b.id);
            assert!(
                close(a.x, b.x, 1e-6) && close(a.y, b.y, 1e-6),
                "{deg}°: {a:?} {b:?}"
            );
        }
    }
}

#[test]
fn the_cameras_frame_the_flock_at_any_heading() {
    let dir = scratch("headings-cameras");
    let (w, h) = (480usize, 270usize);
    let inside = |(x, y): (f64, f64)| x > 0.0 && x < w as f64 && y > 0.0 && y < h as f64;
    for path in [
        straight(&dir, 90.0),
        straight(&dir, 225.0),
        turning(&dir, 225.0),
    ] {
        let a = fly(&path, 30.0);
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        // The pictures (5 a second) of `camera`, birds never under `min_bird_px` pixels a
        // wingspan; each picture's birds in pixels.
        let pictures = |camera: CameraKind, min_bird_px: f64| -> Vec<Vec<(f64, f64)>> {
            let opts = RenderOptions {
                width: w as u32,
                height: h as u32,
                camera,
                min_bird_px,
                ..RenderOptions::default()
            };
            let film = Film::with_options(&a, 5.0, &opts);
            (0..film.len())
                .map(|k| film.states(k))
                .zip(&film.views)
                .map(|(st, view)| {
                    st.iter()
                        .filter_map(|b| view.project([b.x, b.y, b.z], w, h))
                        .map(|(x, y, _)| (x, y))
                        .collect()
                })
                .collect()
        };
        // Follow, fitting the whole flock: every bird in every picture.
        for (k, birds) in pictures(CameraKind::Follow, 0.0).iter().enumerate() {
            assert_eq!(birds.len(), a.birds);
            for (i, &p) in birds.iter().enumerate() {
                assert!(inside(p), "{name}: follow picture {k}: bird {i} at {p:?}");
            }
        }
        // Follow at the default minimum size: the leader always in the picture.
        let lead = a.leaders()[0];
        let min = RenderOptions::default().min_bird_px;
        for (k, birds) in pictures(CameraKind::Follow, min).iter().enumerate() {
            let p = birds[lead];
            assert!(inside(p), "{name}: picture {k}: the leader at {p:?}");
        }
        // Ground: the observer under the course sees the flock pass over, whatever its heading.
        let most = pictures(CameraKind::Ground, min)
            .iter()
            .map(|birds| birds.iter().filter(|&&p| inside(p)).count())
            .max()
            .unwrap();
        assert!(
            most >= 7,
            "{name}: ground camera saw at most {most} of 9 birds"
        );
    }
}

#[test]
fn the_hand_over_is_the_same_step_at_any_heading() {
    let dir = scratch("headings-handover");
    let north = fly(&straight(&dir, 0.0), 4.0);
    let e = north.stage("initiation").unwrap().end;
    assert!(e > 1 && e < north.frames.len());
    for deg in [90.0f64, 225.0] {
        let h = deg.to_radians();
        let a = fly(&straight(&dir, deg), 4.0);
        assert_eq!(
            a.stage("initiation").unwrap().end,
            e,
            "{deg}°: the same take-off"
        );
        for k in [e - 2, e - 1, e] {
            let (f0, f1) = (&a.frames[k], &a.frames[k + 1]);
            let (n0, n1) = (&north.frames[k], &north.frames[k + 1]);
            for i in 0..a.birds {
                let step = (f1.x[i] - f0.x[i], f1.y[i] - f0.y[i]);
                let want = turn((n1.x[i] - n0.x[i], n1.y[i] - n0.y[i]), h);
                // Positions are stored to 10⁻⁵ wingspans, headings to 10⁻⁶ radians and
                // speeds to 10⁻⁵ wingspans per second: a step agrees within two positions'
                // rounding, a turn rate within two headings'.
                assert!(
                    close(step.0, want.0, 2.5e-5) && close(step.1, want.1, 2.5e-5),
                    "{deg}°, frame {k}, bird {i}: step {step:?}, north's turned {want:?}"
                );
                let dh = |f: &formation::animation::Frame, g: &formation::animation::Frame| {
                    (g.heading[i] - f.heading[i] + PI).rem_euclid(2.0 * PI) - PI
                };
                assert!(
                    close(dh(f0, f1), dh(n0, n1), 2.5e-6),
                    "{deg}°: turn rate of bird {i}"
                );
                assert!(
                    close(f1.speed[i], n1.speed[i], 1.5e-5),
                    "{deg}°: speed of bird {i}"
                );
                assert!(close(f1.z[i], n1.z[i], 1e-9), "{deg}°: height of bird {i}");
            }
        }
    }
}

//! Issue 19: a directable flock. The flock follows a path (turns as a formation, banks, climbs),
//! too-tight turns are widened and reported, `--loop` cycles seamlessly, bad paths are refused
//! with one line naming the file and the point. Paths are laid at headings other than north.

mod support;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use formation::pipeline::{Config, Pipeline};
use formation::Animation;
use support::{assert_usage_error, data, run, s, scratch};

/// A straight of 200 wingspans, a 90° right turn of radius 150 and a straight of 300 climbing 20
/// wingspans, rotated to start at heading `h0` (radians) from `origin`; returns the control
/// points and a dense exact curve (points and tangent headings).
/// Points of an exact curve with the tangent heading at each.
type Dense = Vec<([f64; 3], f64)>;

fn turn_path(h0: f64, origin: [f64; 3]) -> (Vec<[f64; 3]>, Dense) {
    // Local frame: start heading north; then rotate clockwise by h0.
    let mut local: Vec<([f64; 3], f64)> = Vec::new();
    for k in 0..=400 {
        local.push(([0.0, k as f64 * 0.5, 20.0], 0.0));
    }
    for k in 1..=400 {
        let a = PI - k as f64 * (PI / 2.0) / 400.0;
        local.push((
            [150.0 + 150.0 * a.cos(), 200.0 + 150.0 * a.sin(), 20.0],
            PI / 2.0 - (a - PI / 2.0),
        ));
    }
    for k in 1..=600 {
        let u = k as f64 / 600.0;
        local.push(([150.0 + 300.0 * u, 350.0, 20.0 + 20.0 * u], PI / 2.0));
    }
    let rot = |p: [f64; 3]| {
        let (sn, cs) = h0.sin_cos();
        [
            origin[0] + p[0] * cs + p[1] * sn,
            origin[1] - p[0] * sn + p[1] * cs,
            origin[2] + p[2],
        ]
    };
    let dense: Vec<([f64; 3], f64)> = local.iter().map(|&(p, h)| (rot(p), h + h0)).collect();
    let mut ctrl: Vec<[f64; 3]> = Vec::new();
    for y in [0.0, 50.0, 100.0, 150.0, 200.0] {
        ctrl.push(rot([0.0, y, 20.0]));
    }
    for k in 1..=12 {
        let a = PI - k as f64 * (PI / 2.0) / 12.0;
        ctrl.push(rot([
            150.0 + 150.0 * a.cos(),
            200.0 + 150.0 * a.sin(),
            20.0,
        ]));
    }
    for k in 1..=6 {
        ctrl.push(rot([
            150.0 + 50.0 * k as f64,
            350.0,
            20.0 + 20.0 * k as f64 / 6.0,
        ]));
    }
    (ctrl, dense)
}

fn write_path(dir: &Path, name: &str, points: &[[f64; 3]]) -> PathBuf {
    let p = dir.join(name);
    let text = serde_json::json!({"units": "wingspans", "points": points}).to_string();
    std::fs::write(&p, text).unwrap();
    p
}

fn config(birds: usize, seconds: f64, path: Option<PathBuf>) -> Config {
    let mut c = Config {
        seed: 5,
        seconds: Some(seconds),
        initiation: false,
        ..Config::default()
    };
    c.steady.birds = birds;
    c.course.path = path;
    c
}

fn wrap(a: f64) -> f64 {
    (a + PI).rem_euclid(2.0 * PI) - PI
}

fn min_pair_distance(a: &Animation) -> f64 {
    let mut m = f64::MAX;
    for f in &a.frames {
        for i in 0..a.birds {
            for j in i + 1..a.birds {
                let d = ((f.x[i] - f.x[j]).powi(2)
                    + (f.y[i] - f.y[j]).powi(2)
                    + (f.z[i] - f.z[j]).powi(2))
                .sqrt();
                m = m.min(d);
            }
        }
    }
    m
}

#[test]
fn the_flock_follows_a_turning_climbing_path_at_any_heading() {
    let dir = scratch("paths-follow");
    for h0 in [130f64.to_radians(), -70f64.to_radians()] {
        let (ctrl, dense) = turn_path(h0, [40.0, -25.0, 0.0]);
        let path = write_path(&dir, "turn.json", &ctrl);
        // The path's own turn, banks and speeds, without position keeping (the bank follows the
        // path's turn, not a bird's small moves about its slot).
        let mut c = config(14, 65.0, Some(path));
        c.steady.jostle.scale = 0.0;
        let (a, report) = Pipeline::from_path(data("steady_v9_params.json"))
            .run(&c)
            .unwrap();
        assert!(
            report.course.widened.is_empty(),
            "{:?}",
            report.course.warnings
        );
        let lead = a.leaders()[0];
        let v = c.steady.speed;
        let g = 9.81 / a.wingspan_m;
        let mut turn_frames = 0;
        for (k, f) in a.frames.iter().enumerate() {
            let p = [f.x[lead], f.y[lead], f.z[lead]];
            let (q, h) = dense
                .iter()
                .min_by(|a, b| dist(a.0, p).total_cmp(&dist(b.0, p)))
                .copied()
                .unwrap();
            assert!(
                dist(q, p) < 3.0,
                "h0 {h0}: frame {k}: leader {:.2} from the curve",
                dist(q, p)
            );
            assert!(
                wrap(f.heading[lead] - h).abs() < 10f64.to_radians(),
                "frame {k}: heading {} vs tangent {h}",
                f.heading[lead]
            );
            // Followers behind the leader, along its heading.
            let (sn, cs) = f.heading[lead].sin_cos();
            for i in 0..a.birds {
                if i != lead {
                    let ahead = (f.x[i] - p[0]) * sn + (f.y[i] - p[1]) * cs;
                    assert!(
                        ahead < 0.0,
                        "frame {k}: bird {i} is {ahead:.2} ahead of the leader"
                    );
                }
            }
            // In the middle of the turn: banks and speeds.
            let local = rot_inv(h0, [40.0, -25.0, 0.0], p);
            if local[1] > 230.0 && local[0] < 120.0 && local[0] > 20.0 {
                turn_frames += 1;
                let (fa, fb) = (&a.frames[k - 1], &a.frames[k + 1]);
                let omega = wrap(fb.heading[lead] - fa.heading[lead]) / (fb.t - fa.t);
                let want = v * omega / g;
                let bank = f.bank.as_ref().unwrap()[lead].tan();
                assert!(
                    want > 0.0 && bank / want > 0.5 && bank / want < 2.0,
                    "frame {k}: tan bank {bank} vs Vω/g {want}"
                );
                // Outer (left) birds faster, inner (right) slower: v = V (R + d) / R.
                let right = |i: usize| (f.x[i] - p[0]) * cs - (f.y[i] - p[1]) * sn;
                for i in 0..a.birds {
                    let d_out = -right(i);
                    let expect = v * (150.0 + d_out) / 150.0;
                    assert!(
                        (f.speed[i] - expect).abs() < 0.03 * v,
                        "frame {k}: bird {i} {d_out:.2} outward flies {:.3}, expected {expect:.3}",
                        f.speed[i]
                    );
                    assert!(f.bank.as_ref().unwrap()[i] > 0.0);
                }
            }
            // In the climb: nose up.
            if local[0] > 200.0 && local[0] < 420.0 {
                assert!(f.pitch.as_ref().unwrap()[lead] > 0.02, "frame {k}: pitch");
            }
        }
        assert!(turn_frames > 100, "{turn_frames} frames in the turn");
        assert!(
            min_pair_distance(&a) >= 0.3,
            "closest approach {}",
            min_pair_distance(&a)
        );
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn rot_inv(h0: f64, o: [f64; 3], p: [f64; 3]) -> [f64; 3] {
    let (sn, cs) = h0.sin_cos();
    let (x, y) = (p[0] - o[0], p[1] - o[1]);
    [x * cs - y * sn, x * sn + y * cs, p[2] - o[2]]
}

#[test]
fn a_take_off_starts_at_the_first_point_and_joins_the_path() {
    let dir = scratch("paths-takeoff");
    let (ctrl, dense) = turn_path(200f64.to_radians(), [0.0, 0.0, 0.0]);
    let path = write_path(&dir, "turn.json", &ctrl);
    let mut c = config(9, 25.0, Some(path));
    c.initiation = true;
    let (a, _) = Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap();
    let f0 = &a.frames[0];
    let cx = f0.x.iter().sum::<f64>() / a.birds as f64;
    let cy = f0.y.iter().sum::<f64>() / a.birds as f64;
    // Sitting on the ground: the root at the bird's sitting height.
    let sit = formation::wingbeat::rest::stance(c.wingbeat.species).sit;
    assert!(
        f0.z.iter().all(|&z| (z - sit).abs() < 1e-9),
        "on the ground"
    );
    assert!(
        cx.hypot(cy) < 25.0,
        "start area centre {cx:.1}, {cy:.1} far from the first point"
    );
    let st = a.stage("steady").unwrap().start;
    let lead = a.leaders()[0];
    for f in &a.frames[st..] {
        let p = [f.x[lead], f.y[lead], f.z[lead]];
        let best = dense.iter().map(|q| dist(q.0, p)).fold(f64::MAX, f64::min);
        assert!(best < 3.0, "leader {best:.2} from the path at t {}", f.t);
    }
    // No jump anywhere: every step within what the fastest bird flies in a frame.
    for w in a.frames.windows(2) {
        for i in 0..a.birds {
            let d = dist(
                [w[0].x[i], w[0].y[i], w[0].z[i]],
                [w[1].x[i], w[1].y[i], w[1].z[i]],
            );
            assert!(
                d < 2.0 * c.steady.speed / a.fps,
                "bird {i} jumps {d} at t {}",
                w[1].t
            );
        }
    }
}

#[test]
fn a_too_tight_turn_is_widened_and_reported_once() {
    let dir = scratch("paths-tight");
    // A sharp corner heading west then south.
    let pts = [
        [0.0, 0.0, 10.0],
        [-140.0, 0.0, 10.0],
        [-150.0, 0.0, 10.0],
        [-150.0, -10.0, 10.0],
        [-150.0, -200.0, 10.0],
    ];
    let path = write_path(&dir, "corner.json", &pts);
    let out_json = dir.join("a.json");
    let out = run(&[
        "steady",
        s(&data("steady_v9_params.json")),
        "--birds",
        "14",
        "--frames",
        "900",
        "--path",
        s(&path),
        "-q",
        "-o",
        s(&out_json),
    ]);
    let err = support::stderr(&out);
    assert!(out.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains("too tight") && warnings[0].contains("near point 2"),
        "{err}"
    );
    let a = Animation::read(&out_json).unwrap();
    assert!(a.path.as_ref().unwrap().widened);
    let v = 10.0;
    for f in &a.frames {
        for i in 0..a.birds {
            assert!(
                f.speed[i] >= 0.6 * v - 0.05 && f.speed[i] <= 1.4 * v + 0.05,
                "speed {}",
                f.speed[i]
            );
            assert!(f.bank.as_ref().unwrap()[i].abs() <= 40f64.to_radians() + 1e-9);
        }
    }
    assert!(min_pair_distance(&a) >= 0.3);
}

fn loop_steps(a: &Animation, relative: bool) -> (f64, f64) {
    let lead = a.leaders()[0];
    let step = |f: &formation::animation::Frame, g: &formation::animation::Frame| {
        let mut m: f64 = 0.0;
        for i in 0..a.birds {
            let (ox, oy, oz) = if relative {
                (
                    g.x[lead] - f.x[lead],
                    g.y[lead] - f.y[lead],
                    g.z[lead] - f.z[lead],
                )
            } else {
                (0.0, 0.0, 0.0)
            };
            let d = dist(
                [f.x[i] + ox, f.y[i] + oy, f.z[i] + oz],
                [g.x[i], g.y[i], g.z[i]],
            );
            let dh = wrap(g.heading[i] - f.heading[i]).abs();
            let dv = (g.speed[i] - f.speed[i]).abs();
            let dp =
                wrap(g.wing_phase.as_ref().unwrap()[i] - f.wing_phase.as_ref().unwrap()[i]).abs();
            m = m.max(d + dh + dv + dp);
        }
        m
    };
    let inside = a
        .frames
        .windows(2)
        .map(|w| step(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let wrap_step = step(a.frames.last().unwrap(), &a.frames[0]);
    (inside, wrap_step)
}

#[test]
fn a_loop_wraps_like_any_other_step() {
    let mut c = config(9, 12.0, None);
    c.steady.looped = true;
    let (a, _) = Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap();
    assert!(a.looped);
    let (inside, wrap_step) = loop_steps(&a, true);
    assert!(wrap_step <= inside, "wrap {wrap_step} vs in-loop {inside}");
    // Shapes cycle: the first key shape comes round again.
    assert!(a.key_shapes.len() >= 4);
    // On a closed path the loop closes in the world.
    let dir = scratch("paths-loop");
    let r = 70.0;
    let circle: Vec<[f64; 3]> = (0..=16)
        .map(|k| {
            let t = 2.0 * PI * k as f64 / 16.0;
            [r * t.cos() + 300.0, -r * t.sin(), 25.0]
        })
        .collect();
    let mut c = config(9, 44.0, Some(write_path(&dir, "circle.json", &circle)));
    c.steady.looped = true;
    let (a, rep) = Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap();
    assert_eq!(rep.course.laps, 1);
    assert!((rep.course.speed_factor - 1.0).abs() < 0.05);
    let (inside, wrap_step) = loop_steps(&a, false);
    assert!(
        wrap_step <= inside * 1.0001,
        "wrap {wrap_step} vs in-loop {inside}"
    );
}

#[test]
fn heights_and_lateral_spacing_live_like_the_footage() {
    let (mut spread, mut neigh, mut runs) = (0.0, 0.0, 0.0);
    let mut lateral_moves = 0.0f64;
    for seed in 0..12 {
        let mut c = config(15, 30.0, None);
        c.seed = seed;
        // Key shapes sampled exactly at their frames: key-shape interpolation only.
        c.steady.jostle.scale = 0.0;
        let (a, _) = Pipeline::from_path(data("steady_v9_params.json"))
            .run(&c)
            .unwrap();
        let f = &a.frames[a.frames.len() / 2];
        let m = f.z.iter().sum::<f64>() / 15.0;
        spread += (f.z.iter().map(|z| (z - m).powi(2)).sum::<f64>() / 15.0).sqrt();
        let mut order: Vec<usize> = (0..15).collect();
        order.sort_by(|&i, &j| f.x[i].total_cmp(&f.x[j]));
        neigh += (order
            .windows(2)
            .map(|w| (f.z[w[0]] - f.z[w[1]]).powi(2))
            .sum::<f64>()
            / 14.0)
            .sqrt();
        runs += 1.0;
        // Lateral positions drift between key shapes, and each key shape's E is Munk's for its x.
        let k0 = &a.key_shapes[0];
        for ks in &a.key_shapes[1..] {
            for (b0, b) in k0.birds.iter().zip(&ks.birds) {
                lateral_moves = lateral_moves.max((b.x - b0.x).abs());
            }
            let fr = &a.frames[ks.frame];
            let e: f64 = fr.e.as_ref().unwrap().iter().sum();
            let x: Vec<f64> = ks.birds.iter().map(|b| b.x).collect();
            let munk = formation::aero::AeroOptions::default()
                .munk_total(&x)
                .unwrap();
            // Each bird's e is stored to 10⁻⁶.
            assert!(
                (e - munk).abs() < 1e-6 * munk.abs().max(1.0) + 0.5e-6 * ks.birds.len() as f64,
                "key at {}: Σe {e} vs Munk {munk}",
                ks.frame
            );
            for (i, b) in ks.birds.iter().enumerate() {
                assert!(
                    (fr.x[i] - b.x).abs() < 0.5e-5 + 1e-9,
                    "frame at a key has the key's x"
                );
            }
        }
    }
    let (spread, neigh) = (spread / runs, neigh / runs);
    assert!((spread - 0.14).abs() < 0.04, "height spread {spread}");
    assert!(
        (neigh - 0.06).abs() < 0.025,
        "neighbour height difference {neigh}"
    );
    assert!(
        lateral_moves > 0.02,
        "lateral positions never move ({lateral_moves})"
    );
}

#[test]
fn bad_paths_are_refused_with_the_file_and_the_point() {
    let dir = scratch("paths-bad");
    let params = data("steady_v9_params.json");
    // File name, content, what the one line must say (separated by `|`).
    let cases = [
        ("one.json", r#"{"points": [[0, 0, 5]]}"#, "at least 2"),
        (
            "rep.json",
            r#"{"points": [[0, 0, 5], [0, 10, 5], [0, 10, 5]]}"#,
            "point 2|repeats point 1",
        ),
        (
            "nan.csv",
            "x,y,z\n0,0,5\n0,NaN,5\n",
            "point 1|not a finite number",
        ),
        (
            "units.json",
            r#"{"units": "feet", "points": [[0, 0, 5], [0, 10, 5]]}"#,
            "unknown units",
        ),
        (
            "back.json",
            r#"{"points": [[0, 0, 5], [0, 100, 5], [0.5, 97, 5], [0.5, 300, 5]]}"#,
            "point 1|turns back on itself",
        ),
        ("row.csv", "0,0,5\n0,10\n", "line 2|point 1"),
    ];
    // `steady` on the v9 fixture with `extra` arguments, writing `out`.
    let steady = |extra: &[&str], out: &Path| {
        let mut args = vec!["steady", s(&params), "--birds", "9", "-q", "-o", s(out)];
        args.extend_from_slice(extra);
        run(&args)
    };
    for (name, text, needles) in cases {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        let out_file = dir.join(format!("{name}.out.json"));
        let out = steady(&["--frames", "200", "--path", s(&p)], &out_file);
        let mut needles: Vec<&str> = needles.split('|').collect();
        needles.push(name);
        assert_usage_error(&out, &needles);
        assert!(!out_file.exists(), "{name}: no output after a failure");
    }
    let ok = dir.join("ok.json");
    std::fs::write(&ok, r#"{"points": [[0, 0, 5], [0, 10, 5]]}"#).unwrap();
    let flags = ["--frames", "200", "--path", s(&ok), "--path-units", "feet"];
    let out = steady(&flags, &dir.join("x.json"));
    assert_usage_error(&out, &["unknown units"]);
    // A loop shorter than one key interval.
    let out = steady(&["--frames", "60", "--loop"], &dir.join("y.json"));
    assert_usage_error(
        &out,
        &["--loop", "shorter than one key interval", "--key-every"],
    );
    // A loop cannot begin with a take-off.
    let out = run(&[
        "animate",
        s(&params),
        "--birds",
        "9",
        "--seconds",
        "10",
        "--loop",
        "-q",
        "-o",
        s(&dir.join("z.json")),
    ]);
    assert_usage_error(&out, &["--loop", "take-off"]);
}

#[test]
fn the_pictures_and_the_gltf_of_a_loop_close_the_cycle() {
    let mut c = config(9, 12.0, None);
    c.steady.looped = true;
    let (a, _) = Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap();
    // Pictures: drawn in the flock's moving frame, the last picture leads into the first.
    let film = formation::export::pictures::Film::new(&a, 25.0, 320, 180);
    let n = film.len();
    let states: Vec<_> = (0..n).map(|k| film.states(k)).collect();
    assert_eq!(n, 300, "12 s at 25 fps");
    let step = |p: &[formation::export::sample::BirdState],
                q: &[formation::export::sample::BirdState]| {
        p.iter()
            .zip(q)
            .map(|(a, b)| dist([a.x, a.y, a.z], [b.x, b.y, b.z]))
            .fold(0.0, f64::max)
    };
    let inside = states
        .windows(2)
        .map(|w| step(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let wrap_step = step(&states[n - 1], &states[0]);
    assert!(wrap_step <= inside + 1e-9, "wrap {wrap_step} vs {inside}");
    // glTF: the clip ends on a closing key one frame after the last, the first frame moved by
    // the flock's travel.
    let closed = formation::export::gltf::closed_loop(&a);
    assert_eq!(closed.frames.len(), a.frames.len() + 1);
    let (f0, fc) = (&a.frames[0], closed.frames.last().unwrap());
    assert!((fc.t - a.frames.len() as f64 / a.fps).abs() < 1e-9);
    let travel = fc.y[0] - f0.y[0];
    assert!(
        (travel - c.steady.speed * 12.0).abs() < 0.05,
        "travel {travel}"
    );
    for i in 0..a.birds {
        assert!((fc.y[i] - f0.y[i] - travel).abs() < 1e-9 && (fc.x[i] - f0.x[i]).abs() < 1e-9);
    }
}

#[test]
fn the_camera_follows_a_flock_turning_at_any_heading() {
    let dir = scratch("paths-camera");
    let (ctrl, _) = turn_path(230f64.to_radians(), [-500.0, 800.0, 0.0]);
    let path = write_path(&dir, "turn.json", &ctrl);
    let c = config(14, 60.0, Some(path));
    let (a, _) = Pipeline::from_path(data("steady_v9_params.json"))
        .run(&c)
        .unwrap();
    let (w, h) = (480, 270);
    let film = formation::export::pictures::Film::new(&a, 5.0, w, h);
    let lead = a.leaders()[0];
    for (k, view) in film.views.iter().enumerate() {
        let st = film.states(k);
        let b = &st[lead];
        let (px, py, _) = view.project([b.x, b.y, b.z], w, h).unwrap();
        assert!(
            px > 0.0 && px < w as f64 && py > 0.0 && py < h as f64,
            "picture {k}: the leader at ({px:.0}, {py:.0}) is out of the picture"
        );
        let inside = st
            .iter()
            .filter(|b| {
                let (x, y, _) = view.project([b.x, b.y, b.z], w, h).unwrap();
                x > 0.0 && x < w as f64 && y > 0.0 && y < h as f64
            })
            .count();
        assert!(inside >= 7, "picture {k}: {inside} birds in the picture");
    }
}

#[test]
fn a_sky_of_formations_is_centred_on_the_path() {
    // 60 geese from the 9-goose example fly as several formations; the path is the course of the
    // leader nearest the middle of the flock, so formations fly on both sides of it.
    let dir = scratch("paths_skein");
    let path = write_path(
        &dir,
        "north.json",
        &[[40.0, 0.0, 20.0], [40.0, 2000.0, 20.0]],
    );
    let mut c = config(60, 10.0, Some(path));
    c.initiation = false;
    let (a, _) = Pipeline::from_path(support::example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap();
    let leaders = a.leaders();
    assert!(leaders.len() > 2, "{} formations", leaders.len());
    let f = &a.frames[0];
    let east = leaders.iter().filter(|&&l| f.x[l] > 40.5).count();
    let west = leaders.iter().filter(|&&l| f.x[l] < 39.5).count();
    assert!(
        east.abs_diff(west) <= 1,
        "{east} formations east of the path, {west} west"
    );
    assert!(
        leaders.iter().any(|&l| (f.x[l] - 40.0).abs() < 1e-6),
        "one leader flies on the path"
    );
}

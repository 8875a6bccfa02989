//! Late birds join like real ones: in the steady flight (`--joiners K`) they fly in from one
//! side and take the free end of an arm, closing a 30-wingspan gap in the 5.5 s wild geese
//! took, while the birds already in formation keep their order; a take-off whose start file
//! has birds far to the side brings them in at the tail of an arm too.

mod steady_support;
mod support;

use formation::animation::{EventKind, Frame};
use formation::keyshape::{steady_flight_report, ReorganiseOptions, SteadyOptions};
use formation::progress::Silent;
use formation::rng::seeded;
use formation::Animation;
use support::{bin, code, example_arg, scratch, stderr};

/// Each bird's (lateral offset to the right, distance behind) of the frame's front-most bird
/// `lead` (the flock flies along +y in the steady flight's frame; headings are averaged for a
/// flock that has turned).
fn relative(f: &Frame, lead: usize) -> Vec<(f64, f64)> {
    let n = f.x.len();
    let h = f.heading[lead];
    let (fx, fy) = (h.sin(), h.cos());
    (0..n)
        .map(|i| {
            let (dx, dy) = (f.x[i] - f.x[lead], f.y[i] - f.y[lead]);
            (dx * fy - dy * fx, -(dx * fx + dy * fy))
        })
        .collect()
}

/// The birds on each side of `lead`, ordered from it outwards by lateral distance.
fn arms(rel: &[(f64, f64)], lead: usize) -> [Vec<usize>; 2] {
    let side = |right: bool| {
        let mut v: Vec<usize> = (0..rel.len())
            .filter(|&i| i != lead && (rel[i].0 >= 0.0) == right)
            .collect();
        v.sort_by(|&a, &b| rel[a].0.abs().total_cmp(&rel[b].0.abs()));
        v
    };
    [side(false), side(true)]
}

fn min_distance(f: &Frame) -> f64 {
    let n = f.x.len();
    let mut d = f64::INFINITY;
    for i in 0..n {
        for j in i + 1..n {
            d = d.min((f.x[i] - f.x[j]).hypot(f.y[i] - f.y[j]));
        }
    }
    d
}

fn with_joiners(seed: u64, birds: usize, joiners: usize, fps: f64) -> Animation {
    let opts = SteadyOptions {
        birds,
        frames: (30.0 * fps) as usize,
        fps,
        seed,
        reorganise: ReorganiseOptions {
            joiners,
            ..ReorganiseOptions::default()
        },
        ..SteadyOptions::default()
    };
    steady_flight_report(&steady_support::v9(), &opts, &mut seeded(seed), &Silent)
        .unwrap()
        .0
}

#[test]
fn late_birds_fly_in_from_a_side_and_take_the_free_end_of_an_arm() {
    for (birds, joiners) in [(7, 2), (14, 3)] {
        for seed in 1..=3 {
            let a = with_joiners(seed, birds, joiners, 30.0);
            let join: Vec<_> = a
                .events
                .iter()
                .filter(|e| e.kind == EventKind::Join)
                .collect();
            assert_eq!(join.len(), 1, "seed {seed}: {:?}", a.events);
            let e = join[0];
            assert_eq!(e.birds.len(), joiners);
            assert!(e.duration <= 7.0, "a join of {} s", e.duration);
            // No other manoeuvre before the late birds are in.
            assert!(a
                .events
                .iter()
                .all(|o| o.kind == EventKind::Join || o.t >= e.t + e.duration));
            let fps = a.fps;
            let at = |t: f64| &a.frames[(t * fps).round() as usize];
            let lead = a.leaders()[0];
            let before = relative(at(e.t), lead);
            let after = relative(at(e.t + e.duration), lead);
            let settled = relative(at(e.t + e.duration + 1.0), lead);
            // 30 wingspans to the side at the start, within a wingspan of the slot at the end
            // (the slot itself moves by position keeping), all on one side.
            for &b in &e.birds {
                let gap = (before[b].0 - after[b].0).abs();
                assert!(
                    (gap - 30.0).abs() < 1.5,
                    "seed {seed}: bird {b} starts {gap} wingspans aside"
                );
                let off = (after[b].0 - settled[b].0).hypot(after[b].1 - settled[b].1);
                assert!(off < 1.0, "seed {seed}: bird {b} {off} from its slot");
            }
            // After the join the late birds hold the outermost places of an arm, and every
            // arm keeps the order its birds had before.
            let arms_before = {
                let mut rel = before.clone();
                for &b in &e.birds {
                    rel[b].0 = f64::NAN;
                }
                let arms = arms(&rel, lead);
                arms.map(|v| {
                    v.into_iter()
                        .filter(|b| !e.birds.contains(b))
                        .collect::<Vec<_>>()
                })
            };
            let arms_after = arms(&after, lead);
            // All of them at the tail of one arm, the one on their side.
            let joined: Vec<&Vec<usize>> = arms_after
                .iter()
                .filter(|arm| arm.iter().any(|b| e.birds.contains(b)))
                .collect();
            assert_eq!(joined.len(), 1, "seed {seed}: late birds on both arms");
            for (k, arm) in arms_after.iter().enumerate() {
                let old: Vec<usize> = arm
                    .iter()
                    .copied()
                    .filter(|b| !e.birds.contains(b))
                    .collect();
                assert_eq!(old, arms_before[k], "seed {seed}: arm {k} reordered");
                let first_late = arm.iter().position(|b| e.birds.contains(b));
                if let Some(p) = first_late {
                    assert!(
                        arm[p..].iter().all(|b| e.birds.contains(b)),
                        "seed {seed}: late birds {:?} not at the end of arm {arm:?}",
                        e.birds
                    );
                }
            }
            // Apart and smooth in every frame.
            let mut worst = (f64::INFINITY, 0.0f64, 0.0f64);
            for k in 1..a.frames.len() - 1 {
                let (p, f, q) = (&a.frames[k - 1], &a.frames[k], &a.frames[k + 1]);
                worst.0 = worst.0.min(min_distance(f));
                for i in 0..birds {
                    let ax = (q.x[i] - 2.0 * f.x[i] + p.x[i]) * fps * fps;
                    let ay = (q.y[i] - 2.0 * f.y[i] + p.y[i]) * fps * fps;
                    worst.1 = worst.1.max(ax.hypot(ay));
                    let dh = (q.heading[i] - f.heading[i] + std::f64::consts::PI)
                        .rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI;
                    worst.2 = worst.2.max(dh.abs() * fps);
                }
            }
            assert!(worst.0 >= 0.3, "seed {seed}: birds {} apart", worst.0);
            // The brake: 1.5 × 6.7 wingspans/s over 2 s = 5 wingspans/s² (about 0.8 g for a
            // goose), plus position keeping.
            assert!(worst.1 <= 7.0, "seed {seed}: acceleration {}", worst.1);
            assert!(
                worst.2.to_degrees() <= 45.0,
                "seed {seed}: turn rate {} °/s",
                worst.2.to_degrees()
            );
        }
    }
}

#[test]
fn late_birds_fly_the_same_at_any_frame_rate() {
    let a = with_joiners(5, 7, 2, 30.0);
    let b = with_joiners(5, 7, 2, 60.0);
    assert_eq!(a.events, b.events);
    for (k, f) in a.frames.iter().enumerate() {
        let g = &b.frames[2 * k];
        for i in 0..7 {
            assert!((f.x[i] - g.x[i]).abs() < 1e-6 && (f.y[i] - g.y[i]).abs() < 1e-6);
        }
    }
}

#[test]
fn birds_far_aside_at_the_take_off_join_at_the_tail_keeping_the_order() {
    // Five birds in a V and two 30 wingspans to the right, flying in as the wild geese did
    // (about 5 wingspans/s sideways at a cruise of 8).
    let dir = scratch("joining-start");
    let h = -(5f64.atan2(8.0));
    let start = serde_json::json!({
        "x": [-1.54, -0.77, 0.0, 0.77, 1.54, 30.0, 31.0],
        "y": [-2.48, -1.24, 0.0, -1.24, -2.48, -1.0, -2.5],
        "heading": [0.0, 0.0, 0.0, 0.0, 0.0, h, h],
        "speed": [8.0, 8.0, 8.0, 8.0, 8.0, 9.43, 9.43],
    });
    std::fs::write(dir.join("start.json"), start.to_string()).unwrap();
    for seed in ["1", "2", "3"] {
        let out = bin()
            .current_dir(&dir)
            .args(["animate", &example_arg("barnacle_geese_v.json")])
            .args(["--birds", "7", "--start", "start.json", "--seconds", "2"])
            .args(["--seed", seed, "--quiet", "-o", "a.json"])
            .output()
            .unwrap();
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        let a = Animation::read(&dir.join("a.json")).unwrap();
        let end = a.stages[0].end;
        let lead = 2;
        let rel0 = relative(&a.frames[0], lead);
        let fin = relative(&a.frames[end], lead);
        // The late birds' sideways gap to their place is under a wingspan in under 7 s.
        let joined = a
            .frames
            .iter()
            .position(|f| {
                let r = relative(f, lead);
                [5, 6].iter().all(|&b| (r[b].0 - fin[b].0).abs() < 1.0)
            })
            .unwrap();
        let t = a.frames[joined].t;
        assert!(t < 7.0, "seed {seed}: joined after {t} s");
        // The leader leads, the five keep their arms and order, the two are at the tail of
        // the right arm.
        assert_eq!(
            (0..7)
                .max_by(|&p, &q| fin[q].1.total_cmp(&fin[p].1))
                .unwrap(),
            lead,
            "seed {seed}: the leader changed"
        );
        let [left0, right0] = arms(&rel0[..5], lead);
        let [left, right] = arms(&fin, lead);
        assert_eq!(left, left0, "seed {seed}: left arm");
        assert_eq!(right[..2], right0[..], "seed {seed}: right arm");
        assert_eq!(
            right[2..],
            [5, 6],
            "seed {seed}: late birds not at the tail"
        );
    }
}

/// The joining filmed in the wild (white-fronted geese): a lopsided V of five (three to the
/// right of the leader, one to its left, the last right bird a straggler 2.7 wingspans out) and
/// two late birds 31 and 33 wingspans to the right, flying in at about 4.4 wingspans/s sideways.
/// The real five kept their places (ending 0.39, 1.08 and 2.0 to the right and 1.06 to the
/// left) and the two joined behind the last bird of the right arm (3.7 and 4.8 aside).
#[test]
fn the_filmed_joining_keeps_the_formed_birds_places_and_order() {
    use formation::animation::clearance::Clearance;
    let dir = scratch("joining-filmed");
    let h = -0.45f64;
    let x = [0.0, 0.47, 0.89, 3.6, -0.96, 31.0, 32.9];
    let y = [0.0, -0.97, -1.91, -3.2, -0.94, -13.8, -11.5];
    let start = serde_json::json!({
        "x": x,
        "y": y,
        "heading": [0.0, 0.0, 0.0, 0.0, 0.0, h, h],
        "speed": [10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0],
    });
    std::fs::write(dir.join("start.json"), start.to_string()).unwrap();
    for (seed, fps) in [
        ("0", "30"),
        ("1", "30"),
        ("2", "30"),
        ("0", "24"),
        ("0", "60"),
    ] {
        let out = bin()
            .current_dir(&dir)
            .args(["animate", &example_arg("barnacle_geese_v.json")])
            .args(["--birds", "7", "--start", "start.json", "--seconds", "10"])
            .args(["--seed", seed, "--fps", fps, "--quiet", "-o", "a.json"])
            .output()
            .unwrap();
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        let a = Animation::read(&dir.join("a.json")).unwrap();
        // Which start bird each animated bird is (frame 0 holds the start positions).
        let f0 = &a.frames[0];
        let who: Vec<usize> = (0..7)
            .map(|b| {
                (0..7)
                    .min_by(|&p, &q| {
                        let d = |i: usize| (f0.x[b] - x[i]).hypot(f0.y[b] - y[i]);
                        d(p).total_cmp(&d(q))
                    })
                    .unwrap()
            })
            .collect();
        let lead = who.iter().position(|&i| i == 0).unwrap();
        let end = a.stages[0].end;
        let fin = relative(&a.frames[end], lead);
        let [left, right] = arms(&fin, lead);
        let named = |arm: &[usize]| arm.iter().map(|&b| who[b]).collect::<Vec<_>>();
        let what = format!("seed {seed} at {fps} fps");
        assert_eq!(named(&left), [4], "{what}: left arm");
        assert_eq!(named(&right), [1, 2, 3, 5, 6], "{what}: right arm");
        assert_eq!(
            (0..7)
                .max_by(|&p, &q| fin[q].1.total_cmp(&fin[p].1))
                .unwrap(),
            lead,
            "{what}: the leader changed"
        );
        // The five formed birds end near where they were (within a wingspan aside; the
        // straggler closes in towards its neighbour), the late birds beyond them.
        for (i, real) in [(1, 0.47), (2, 0.89), (4, -0.96)] {
            let b = who.iter().position(|&w| w == i).unwrap();
            assert!(
                (fin[b].0 - real).abs() < 0.5,
                "{what}: bird {i} ends {} aside, {real} at the start",
                fin[b].0
            );
        }
        // The late birds are within a wingspan aside of their places in under 7 s.
        let late: Vec<usize> = [5, 6]
            .iter()
            .map(|&i| who.iter().position(|&w| w == i).unwrap())
            .collect();
        let joined = a
            .frames
            .iter()
            .position(|f| {
                let r = relative(f, lead);
                late.iter().all(|&b| (r[b].0 - fin[b].0).abs() < 1.0)
            })
            .unwrap();
        let t = a.frames[joined].t;
        assert!(t < 7.0, "{what}: joined after {t} s");
        // No clash in any frame of any stage.
        let c = Clearance::of(&a);
        assert_eq!(
            (c.wing, c.body),
            (0, 0),
            "{what}: clashes, closest {:?}",
            c.closest
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

//! Turns tighter than the flock can fly (issue 19, item 2): a turn that widening makes flyable
//! is flown within the birds' bank and speed limits; one that widening cannot make flyable (two
//! legs closer together than the turn's diameter, or the smoothing's work bound reached) is
//! refused with exit 2 and one line naming the path file, the point and the radius to give it,
//! never flown at the bank limit or off the drawn path.

mod support;

use formation::animation::Animation;
use std::path::{Path, PathBuf};
use support::*;

/// Cruise speed of these flights (the CLI's default), wingspans per second.
const SPEED: f64 = 10.0;
/// The default bank limit (`course.max_bank`), degrees, and minimum speed (`course.min_speed`),
/// a fraction of the cruise speed.
const MAX_BANK_DEG: f64 = 40.0;
const MIN_SPEED: f64 = 0.6;

/// Writes a path of `points` (wingspans) as `NAME.json` in `dir`.
fn path_file(dir: &Path, name: &str, points: &[[f64; 3]]) -> PathBuf {
    let p = dir.join(format!("{name}.json"));
    let pts: Vec<String> = points
        .iter()
        .map(|q| format!("[{}, {}, {}]", q[0], q[1], q[2]))
        .collect();
    std::fs::write(&p, format!("{{\"points\": [{}]}}", pts.join(", "))).unwrap();
    p
}

/// `steady` of 9 geese for `seconds` at 30 fps along `path`, into `out`.
fn fly(path: &Path, out: &Path, seconds: &str) -> std::process::Output {
    let params = data("steady_v9_params.json");
    run(&[
        "steady",
        s(&params),
        "--birds",
        "9",
        "--seconds",
        seconds,
        "--fps",
        "30",
        "--path",
        s(path),
        "-o",
        s(out),
        "--quiet",
    ])
}

/// Exit 2, one line naming the file, the point and the radius to give the turn; no output.
fn assert_refused_turn(out: &std::process::Output, path: &Path, point: &str, anim: &Path) {
    let name = path.file_name().unwrap().to_str().unwrap();
    assert_usage_error(
        out,
        &[
            name,
            point,
            "wingspans along the path",
            "radius of at least",
        ],
    );
    assert!(!anim.exists(), "no output after a refusal");
}

/// Flies a path of `points` named `name` and checks it is refused ([`assert_refused_turn`]);
/// returns the message.
fn refusal(name: &str, points: &[[f64; 3]]) -> String {
    let dir = scratch(&format!("turn-{name}"));
    let p = path_file(&dir, name, points);
    let out_file = dir.join("a.json");
    let out = fly(&p, &out_file, "20");
    assert_refused_turn(&out, &p, "point ", &out_file);
    std::fs::remove_dir_all(&dir).unwrap();
    stderr(&out)
}

/// Two legs 10 wingspans apart joined by a square end: the flock needs a turn about 46
/// wingspans across, which smoothing cannot make (on main the hairpin shrank to a 10-wingspan
/// stub and the flock flew straight on past it).
#[test]
fn a_hairpin_narrower_than_the_turn_is_refused_naming_its_point() {
    let hairpin = [
        [0.0, 0.0, 10.0],
        [0.0, 300.0, 10.0],
        [10.0, 300.0, 10.0],
        [10.0, 0.0, 10.0],
    ];
    let err = refusal("hairpin", &hairpin);
    assert!(
        err.contains("point 1 ") || err.contains("point 2 "),
        "the place is the hairpin's end: {err}"
    );
}

/// The fuzzer's path that turns back onto its own leg, shortened so the flock reaches the turn:
/// on main the widening stopped at its round limit with a radius of 13.7 wingspans left, and the
/// flock flew it with banks clamped at the 40° limit where 47° were needed.
#[test]
fn a_turn_back_onto_a_long_leg_is_refused_not_flown_at_the_bank_limit() {
    let back = [
        [0.0, 0.0, 10.0],
        [0.0, 100.0, 10.0],
        [2200.0, 1.0, 15.0],
        [3000.0, 0.0, 10.0],
        [0.0, 0.0, 1.0],
    ];
    refusal("back", &back);
}

/// The fuzzer's own input (a leg 28 000 wingspans long, then back): the smoothing reaches its
/// work bound; refused, in bounded time (about a second in release; the bound is generous).
#[test]
fn the_fuzzers_long_turn_back_is_refused_in_bounded_time() {
    let dir = scratch("turn-back-long");
    let p = data("fuzz/path-slow-232ab045.json");
    let out_file = dir.join("a.json");
    let start = std::time::Instant::now();
    let out = fly(&p, &out_file, "2");
    assert_refused_turn(&out, &p, "point ", &out_file);
    assert!(start.elapsed() < std::time::Duration::from_secs(60));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Largest coordinated-turn bank any bird needs (degrees, from its heading rate over
/// neighbouring frames: tan φ = v ω / g) and the smallest speed of any bird over the cruise
/// speed, over the whole flight.
fn needed_bank_and_slowest(anim: &Animation) -> (f64, f64) {
    let g = 9.81 / anim.wingspan_m;
    let fr = &anim.frames;
    let (mut bank, mut slow) = (0.0f64, f64::INFINITY);
    for k in 1..fr.len() - 1 {
        let dt = fr[k + 1].t - fr[k - 1].t;
        for i in 0..anim.birds {
            let dh = formation::course::spline::wrap(fr[k + 1].heading[i] - fr[k - 1].heading[i]);
            let v = fr[k].speed[i];
            bank = bank.max((v * dh.abs() / dt / g).atan().to_degrees());
            slow = slow.min(v / SPEED);
        }
    }
    (bank, slow)
}

/// Turns that widening can make flyable still fly, with the one warning, and every bird within
/// its limits: two square corners 60 wingspans apart (a U-turn about 60 wingspans across), a
/// sharp 135° corner between long legs (on main flown at a radius of 17 wingspans where the
/// flock needs 23), and a zig-zag of 90° corners 42 wingspans apart (on main flown at a radius
/// of 17 wingspans, a coordinated bank of 42.5° needed past the 40° limit).
#[test]
fn widened_turns_are_flown_within_the_birds_bank_and_speed_limits() {
    let dir = scratch("turn-widened");
    let zigzag: Vec<[f64; 3]> = (0..40)
        .map(|i| [if i % 2 == 0 { 0.0 } else { 30.0 }, 30.0 * i as f64, 10.0])
        .collect();
    let cases: [(&str, Vec<[f64; 3]>); 3] = [
        (
            "u60",
            vec![
                [0.0, 0.0, 10.0],
                [0.0, 300.0, 10.0],
                [60.0, 300.0, 10.0],
                [60.0, 0.0, 10.0],
            ],
        ),
        (
            "corner135",
            vec![[0.0, 0.0, 10.0], [0.0, 300.0, 10.0], [300.0, 0.0, 10.0]],
        ),
        ("zigzag", zigzag),
    ];
    for (name, pts) in cases {
        let p = path_file(&dir, name, &pts);
        let out_file = dir.join(format!("{name}-out.json"));
        let out = fly(&p, &out_file, "55");
        let err = stderr(&out);
        assert_eq!(code(&out), 0, "{name}: {err}");
        assert!(
            err.contains("widened"),
            "{name}: the widening is said: {err}"
        );
        let anim = Animation::read(&out_file).unwrap();
        let (bank, slow) = needed_bank_and_slowest(&anim);
        // 5 % for the finite differences of headings between frames.
        assert!(
            bank <= 1.05 * MAX_BANK_DEG,
            "{name}: a bird needs a bank of {bank:.1}°"
        );
        assert!(
            slow >= MIN_SPEED,
            "{name}: a bird flies at {slow:.3} of cruise"
        );
        assert!(bank > 5.0, "{name}: the flock did turn ({bank:.1}°)");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

//! Inputs that `cargo fuzz` (see `fuzz/`, `docs/reliability.md`) found to crash or exhaust memory,
//! kept as regression tests. Each runs the same code as its fuzz target and must end in a clean
//! error (or success), quickly and without a large allocation.

use formation::export::{sample, write_outputs, RenderOptions};
use formation::extract::params::FormationParams;
use formation::keyshape::{steady_flight, KeyOptions, SteadyOptions};
use formation::progress::Silent;
use formation::rng::stream;
use formation::Animation;

mod support;

/// A fuzz finding of `tests/data/fuzz/`.
fn data(name: &str) -> std::path::PathBuf {
    support::data("fuzz").join(name)
}

/// The `params` target's steady flight: 6 birds, 4 frames, a key shape every 0.05 s.
fn tiny_steady(p: &FormationParams) -> formation::Result<Animation> {
    let opts = SteadyOptions {
        birds: 6,
        frames: 4,
        keys: KeyOptions {
            key_every_s: 0.05,
            ..KeyOptions::default()
        },
        ..SteadyOptions::default()
    };
    steady_flight(p, &opts, &mut stream(0, "steady"), &Silent)
}

/// `sigma_x` = 1.1·10⁹⁴ (finite) made the feasible ξ ranges NaN and `f64::clamp` panicked in
/// `keyshape::keys::draw_target`. Now the params file is refused, naming the field.
#[test]
fn params_with_a_huge_sigma_are_refused() {
    let path = data("params-crash-1739c627.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let p: FormationParams = formation::io::parse_json(&path, &text).unwrap();
    let e = p.validate(&path).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("frames[0].sigma_x"), "{e}");
    // Just inside the bound, the same file runs (or fails cleanly), without panicking.
    let ok = text.replace(
        &text[text.find("\"sigma_x\":").unwrap()..text.find(",\"mu_y\"").unwrap()],
        "\"sigma_x\":99.0",
    );
    let p: FormationParams = formation::io::parse_json(&path, &ok).unwrap();
    p.validate(&path).unwrap();
    let _ = tiny_steady(&p);
}

/// A frame time of 5·10⁷ s: counting the picture frames (1.3·10⁹ at 25 fps) allocated all their
/// times first (10 GB). Now they are counted arithmetically and refused before any allocation.
#[test]
fn an_animation_lasting_years_is_refused_without_allocating() {
    let path = data("animation-oom-86986314.json");
    let a = Animation::read(&path).unwrap();
    sample::check_times(&a, &path).unwrap();
    assert!(sample::output_count(&a, 25.0) > 1_000_000_000);
    let dir = support::scratch("fuzz-years");
    let e = write_outputs(
        &a,
        &[dir.join("a.gif"), dir.join("frames/")],
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("frames at"), "{e}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The small steady flight of the `path` target: 5 birds, 2 s at 10 fps, a key every second.
fn path_flight() -> Animation {
    let p: FormationParams = formation::io::parse_json(
        &support::data("steady_v9_params.json"),
        &std::fs::read_to_string(support::data("steady_v9_params.json")).unwrap(),
    )
    .unwrap();
    let opts = SteadyOptions {
        birds: 5,
        frames: 20,
        fps: 10.0,
        keys: KeyOptions {
            key_every_s: 1.0,
            ..KeyOptions::default()
        },
        ..SteadyOptions::default()
    };
    steady_flight(&p, &opts, &mut stream(0, "steady"), &Silent).unwrap()
}

/// An open path that turns back onto its own leg 28 000 wingspans long (`[30000, 0, 10]` then
/// back to the start): widening smoothed it for all 400 rounds, 13 s in the fuzzer's build (4 s
/// in release; a 49 000-wingspan leg at `--speed 1` took 35 s). The smoothing's work is bounded
/// now (0.5 s of CPU here; the bound is on this thread's CPU time, which a loaded machine does
/// not stretch). Its turn cannot be widened to the flock's radius (it used to fly at 1.04
/// wingspans where the flock needs 23, silently), so it is refused, naming the point and the
/// radius to give.
#[test]
fn a_path_turning_back_onto_a_long_leg_is_refused_in_bounded_time() {
    use formation::course::file;
    let path = data("path-slow-232ab045.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let points = file::parse_str(&path, &text, None, 1.5).unwrap();
    let mut anim = path_flight();
    let mut config = formation::pipeline::Config::default();
    config.course.path = Some(path.clone());
    let start = support::WorkClock::start();
    let err = formation::pipeline::course_stage(&mut anim, Some(&points), &config)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("point 3 ") && err.contains("radius of at least"),
        "{err}"
    );
    assert!(
        start.elapsed() < std::time::Duration::from_secs(10),
        "{:?} of CPU",
        start.elapsed()
    );
}

/// A closed path shaped as a thin spike (`(0,0) → (11,0) → (10,13) → (0,500) → (0,0)`, CRLF and a
/// form feed from the fuzzer): long enough around for the flock's turns, but widening it shrank
/// it towards nothing, and the stretch smoothed around each tight sample grew without bound (a
/// hang in `course::spline::widen`). Now the collapse is detected and the path refused.
#[test]
fn a_closed_spike_path_is_refused_not_widened_forever() {
    use formation::course::file;
    let path = data("path-timeout-f1861c65.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let points = file::parse_str(&path, &text, None, 1.5).unwrap();
    assert!(points.closed);
    let mut anim = path_flight();
    let mut config = formation::pipeline::Config::default();
    config.course.path = Some(path.clone());
    let start = support::WorkClock::start();
    let e = formation::pipeline::course_stage(&mut anim, Some(&points), &config).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("cannot be widened"), "{e}");
    assert!(
        start.elapsed() < std::time::Duration::from_secs(10),
        "{:?} of CPU",
        start.elapsed()
    );
}

/// The refusal of the bird model `name` (in `tests/data/fuzz/`): exit 2 and one line, returned.
fn refused_bird_model(name: &str) -> String {
    let path = data(name);
    let bytes = std::fs::read(&path).unwrap();
    let e =
        formation::export::bird_model::parse(&path, &bytes, formation::wingbeat::Species::Goose)
            .unwrap_err();
    assert_eq!(e.exit_code(), 2);
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1, "{msg}");
    msg
}

/// A bird model (a formation `.glb` with bytes changed by the fuzzer) whose inverse bind matrix
/// of `body` is singular: its inverse was NaN, so the `.glb` export failed with "internal error"
/// (exit 1) and the `.usda` text held NaN. Now the model is refused naming the joint.
#[test]
fn a_bird_model_with_a_singular_bind_matrix_is_refused() {
    let msg = refused_bird_model("bird_model-nan-5da5f56a.glb");
    assert!(msg.contains("cannot be inverted"), "{msg}");
}

/// A bird model (bytes changed by the fuzzer) whose NORMAL accessor has fewer vectors than its
/// POSITION accessor has vertices: building the bird indexed past the normals (a panic). Now the
/// model is refused naming the mesh, the primitive and the counts.
#[test]
fn a_bird_model_with_fewer_normals_than_vertices_is_refused() {
    let msg = refused_bird_model("bird_model-crash-4e3181e8.glb");
    assert!(
        msg.contains("NORMAL has") && msg.contains("vertices"),
        "{msg}"
    );
}

/// A bird model (bytes changed by the fuzzer) with an infinite skin weight: the vertex's
/// normalised weights became NaN and reached the USD text. Now refused naming the vertex.
#[test]
fn a_bird_model_with_an_infinite_skin_weight_is_refused() {
    let msg = refused_bird_model("bird_model-nan-e3e38933.glb");
    assert!(msg.contains("skin weight"), "{msg}");
}

/// A bird model (bytes changed by the fuzzer) whose `upper_arm.R` joint sits 10³⁸ spans of the
/// mesh away: its place was finite, but its offsets composed down the chain and scaled to a
/// wingspan overflowed to `inf` in the USD text (`render -o a.usda` wrote it, exit 0). Now refused
/// naming the joint.
#[test]
fn a_bird_model_with_a_joint_far_from_its_mesh_is_refused() {
    let msg = refused_bird_model("bird_model-nan-3b394836.glb");
    assert!(
        msg.contains("joint \"upper_arm.R\"") && msg.contains("spans"),
        "{msg}"
    );
}

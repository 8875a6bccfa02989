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

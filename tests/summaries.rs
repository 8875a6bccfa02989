//! Every command ends with a summary on stderr saying what it wrote (the file and its size) and,
//! for `solve`, whether it converged, the residual and the evaluations; `--quiet` silences it.

mod support;

use support::{code, data, run, s, scratch, stderr};

/// Runs `args`, checks exit 0, and returns stderr; then checks `--quiet` prints nothing.
fn summary_of(args: &[&str]) -> String {
    let out = run(args);
    assert_eq!(code(&out), 0, "{args:?}: {}", stderr(&out));
    let err = stderr(&out);
    let mut quiet = args.to_vec();
    quiet.push("--quiet");
    let q = run(&quiet);
    assert_eq!(code(&q), 0, "{quiet:?}: {}", stderr(&q));
    assert!(stderr(&q).is_empty(), "{quiet:?} printed {}", stderr(&q));
    err
}

#[test]
fn render_plot_report_and_solve_say_what_they_wrote() {
    let dir = scratch("summaries");
    let anim = data("flock_small.json");

    let glb = dir.join("a.glb");
    let err = summary_of(&["render", s(&anim), "-o", s(&glb)]);
    assert!(
        err.starts_with("render: 5 birds, 50 frames at 20 fps (2.5 s; initiation + steady) from "),
        "{err}"
    );
    assert!(
        err.contains("wrote ") && err.contains("a.glb (") && err.contains("kB)"),
        "{err}"
    );

    let png = dir.join("s.png");
    let err = summary_of(&["plot", "savings", s(&anim), "-o", s(&png)]);
    assert!(
        err.starts_with("plot: each bird's saving against its rank"),
        "{err}"
    );
    assert!(err.contains("s.png ("), "{err}");

    let html = dir.join("r.html");
    let err = summary_of(&["report", s(&anim), "-o", s(&html)]);
    assert!(
        err.starts_with("report: a page on an animation of 5 birds, 50 frames"),
        "{err}"
    );
    assert!(err.contains("r.html ("), "{err}");

    let target = dir.join("t.json");
    std::fs::write(&target, r#"{"x": [-1.0, 0.0, 1.0], "xi": [0.8, 1.0, 1.2]}"#).unwrap();
    let shape = dir.join("s.json");
    let err = summary_of(&["solve", s(&target), "-o", s(&shape)]);
    assert!(
        err.starts_with("solve: 3 birds, converged (residual"),
        "{err}"
    );
    assert!(err.contains("evaluations"), "{err}");
    assert!(err.contains("s.json ("), "{err}");
    assert_eq!(err.lines().count(), 2, "{err}");
}

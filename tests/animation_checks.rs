//! Animation files that contradict themselves are refused with one line naming the field: an
//! unknown species, a negative speed, a negative path length, an `fps` the frame times deny. The
//! same file without the fault renders.

mod support;

use serde_json::Value;
use support::{bin, code, s, scratch, stderr};

/// A change to a valid animation file, and what the refusal must name.
type Case = (Box<dyn Fn(&mut Value)>, &'static str);

#[test]
fn self_contradicting_animation_files_are_refused() {
    let d = scratch("anim-checks");
    let good = d.join("good.json");
    let o = bin()
        .args([
            "animate",
            s(&support::example("barnacle_geese_v.json")),
            "--birds",
            "5",
            "--seconds",
            "2",
            "--quiet",
            "-o",
            s(&good),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let base: Value = serde_json::from_slice(&std::fs::read(&good).unwrap()).unwrap();
    let out = d.join("out.csv");
    let render = |doc: &Value| {
        let p = d.join("case.json");
        std::fs::write(&p, serde_json::to_vec(doc).unwrap()).unwrap();
        let _ = std::fs::remove_file(&out);
        bin()
            .args(["render", s(&p), "-o", s(&out)])
            .output()
            .unwrap()
    };
    let o = render(&base);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let cases: Vec<Case> = vec![
        (
            Box::new(|v| v["species"] = Value::from("dodo")),
            "species: \"dodo\"",
        ),
        (
            Box::new(|v| v["frames"][3]["speed"][1] = Value::from(-2.0)),
            "frames[3].speed[1]",
        ),
        (
            Box::new(|v| {
                v["path"] = serde_json::json!({"source": "p.json", "points": [[0, 0, 10], [0, 50, 10]],
                    "closed": false, "length": -5.0, "widened": false});
            }),
            "path.length",
        ),
        (
            // Frames 1/30 s apart in a file claiming 60 fps.
            Box::new(|v| v["fps"] = Value::from(60.0)),
            "fps: 60 contradicts the frame times, whose median step is 0.033333 s (30.000 frames per second)",
        ),
    ];
    for (change, needle) in cases {
        let mut doc = base.clone();
        change(&mut doc);
        let o = render(&doc);
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "{needle}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert!(!out.exists());
    }
}

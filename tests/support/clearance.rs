//! Shared by the clearance tests: the example footages with their read flags, one `animate` run
//! read back, and the assertion that a clearance count is clear.

use std::path::Path;

use formation::animation::clearance::Clearance;
use formation::animation::Animation;

use super::{example_arg, run, s};

/// (name, input, read flags) of every example footage.
pub fn examples() -> Vec<(&'static str, String, Vec<&'static str>)> {
    vec![
        (
            "barnacle geese V",
            example_arg("barnacle_geese_v.json"),
            vec![],
        ),
        ("snow geese J", example_arg("snow_geese_j.csv"), vec![]),
        (
            "cranes",
            example_arg("cranes_v_dltdv.csv"),
            vec!["--wingspan-px", "22", "--heading", "300"],
        ),
        ("pelicans U", example_arg("pelicans_u_labelme"), vec![]),
    ]
}

/// Runs `animate INPUT -o DIR/a.json --quiet ARGS` (asserting it succeeds) and reads the
/// animation back.
pub fn animate(dir: &Path, input: &str, args: &[&str]) -> Animation {
    let out = dir.join("a.json");
    let mut all = vec!["animate", input, "-o", s(&out), "--quiet"];
    all.extend_from_slice(args);
    let o = run(&all);
    assert!(
        o.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    Animation::read(&out).expect("read the animation back")
}

/// Asserts that `c` counts no wing and no body clash; `what` names the run.
pub fn assert_clear(c: &Clearance, what: &str) {
    assert_eq!(
        (c.wing, c.body),
        (0, 0),
        "{what}: {} wing and {} body clashes in {} frames, closest {:?}",
        c.wing,
        c.body,
        c.frames_with_clash,
        c.closest
    );
}

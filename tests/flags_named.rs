//! Every command run with a bad value of every flag it has: exit 2 and one line that names that
//! flag (library errors name option paths such as `initiate.max_turn_rate`; `src/cli/flags.rs`
//! must turn each into the flag of the command that was run). The flags are read from each
//! command's `--help`, so a new flag without a case here fails the test.

mod support;

use std::collections::BTreeSet;

use support::{bin, data, example_arg, s, scratch};

/// Flags that take no value, or that only print.
const SWITCHES: &[&str] = &[
    "--help",
    "--version",
    "--quiet",
    "--json",
    "--keep-unconverged",
    "--no-initiation",
    "--sun",
    "--loop",
    "--strict",
    "--pretty",
    "--binary-frames",
    "--land",
];

/// The flags `formation ARGS --help` lists.
fn help_flags(args: &[&str]) -> BTreeSet<String> {
    let out = bin().args(args).arg("--help").output().unwrap();
    assert!(out.status.success(), "{args:?} --help");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    text.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = l.strip_prefix("-q, ").unwrap_or(l);
            let l = l.split_once(", ").map_or(
                l,
                |(short, long)| {
                    if short.len() == 2 {
                        long
                    } else {
                        l
                    }
                },
            );
            let flag = l.strip_prefix("--")?.split([' ', '=']).next()?;
            Some(format!("--{flag}"))
        })
        .filter(|f| !SWITCHES.contains(&f.as_str()))
        .collect()
}

struct Command {
    /// Subcommand words.
    name: &'static [&'static str],
    /// A valid invocation (without the flag under test), `OUT` for the scratch directory.
    base: Vec<String>,
    /// (flag, bad value, what the message must contain besides the flag, if not the flag).
    cases: Vec<(&'static str, &'static str, Option<String>)>,
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|x| x.to_string()).collect()
}

fn commands() -> Vec<Command> {
    let geese = example_arg("barnacle_geese_v.json");
    let shape = example_arg("v9_shape.json");
    let target = example_arg("equal_savings_target.json");
    let params = data("steady_v9_params.json").to_string_lossy().into_owned();
    let steady = data("initiate_steady_v9.json")
        .to_string_lossy()
        .into_owned();
    let flock = data("flock_small.json").to_string_lossy().into_owned();
    let read: Vec<(&str, &str, Option<String>)> = vec![
        ("--heading", "sideways", None),
        ("--wingspan-px", "-3", None),
        ("--y-origin", "middle", None),
        // The examples are native annotations: one point per bird, no body parts.
        ("--bodypart", "head", None),
    ];
    let fit: Vec<(&str, &str, Option<String>)> = vec![
        ("--threshold", "-1", None),
        ("--kind", "w", None),
        ("--max-samples", "0", None),
        ("--j-offset", "2", None),
    ];
    let steady_flags: Vec<(&str, &str, Option<String>)> = vec![
        ("--birds", "1", None),
        ("--fps", "0", None),
        ("--key-every", "0", None),
        ("--speed", "0", None),
        ("--epsilon", "2", None),
        ("--c1", "2", None),
        ("--c2", "3", None),
        ("--wingspan-m", "0", None),
        ("--max-jump", "0", None),
        ("--jostle", "-1", None),
        ("--leader-changes", "nan", None),
        ("--swaps", "1e9", None),
        ("--joiners", "99", None),
        ("--core-radius", "nan", None),
        ("--mass-kg", "0", None),
        ("--speed-ms", "-3", None),
        ("--wake", "sideways", None),
        ("--aero-model", "sideways", None),
        ("--formations", "0", None),
        ("--formation-size", "1", None),
        ("--clearance", "-1", None),
        ("--skein-layout", "lattice", None),
    ];
    let course: Vec<(&str, &str, Option<String>)> = vec![
        ("--path", "OUT/no-path.json", Some("no-path.json".into())),
        ("--path-units", "feet", None),
        ("--land-on", "lava", None),
    ];
    let wingbeat: Vec<(&str, &str, Option<String>)> = vec![
        ("--species", "dodo", None),
        ("--phase", "sync", None),
        ("--glide", "soar", None),
        ("--wing-variation", "9", None),
    ];
    let initiate: Vec<(&str, &str, Option<String>)> = vec![
        ("--max-steps", "0", None),
        ("--max-seconds", "-1", None),
        ("--perception", "psychic", None),
        ("--hpr-gamma", "9", None),
        ("--fov", "500", None),
        ("--reference-cone", "0", None),
        ("--alpha", "2", None),
        ("--k", "0", None),
        ("--max-turn-rate", "0", None),
        ("--max-accel", "0", None),
        ("--min-speed", "0", None),
        ("--max-speed", "0.5", None),
        ("--separation", "0", None),
        ("--avoid-distance", "0", None),
        ("--tolerance", "0", None),
        ("--hold", "nan", None),
        ("--takeoff", "0", None),
        ("--ground-seconds", "-1", None),
        ("--cruise-altitude", "1e9", None),
        ("--climb-rate", "0", None),
        // A start file that does not exist is named by its path.
        ("--start", "OUT/no-start.json", Some("no-start.json".into())),
        ("--start-width", "0", None),
        ("--start-depth", "0", None),
        ("--heading-spread", "200", None),
    ];
    let shot: Vec<(&str, &str, Option<String>)> = vec![
        ("--camera", "orbit", None),
        ("--view", "0,0,10,10", None),
        ("--background", "plaid", None),
        ("--min-bird-px", "-1", None),
        ("--gif-tolerance", "-1", None),
    ];
    let scene: Vec<(&str, &str, Option<String>)> = vec![
        ("--keys", "some", None),
        ("--clips", "reel", None),
        ("--bird-model", "OUT/no-bird.glb", None),
        ("--size-variation", "3", None),
        ("--start-frame", "-5", None),
        ("--subframes", "0", None),
        ("--units", "feet", None),
        ("--up", "x", None),
        ("--path-out", "OUT/path.txt", None),
        ("--usd-mode", "pixie", None),
        ("--gltf-mode", "pixie", None),
        ("--joint-map", "OUT/no-map.json", None),
        ("--crowd-pose-error", "0", None),
    ];
    // The savings flags of `report` and `plot savings`.
    let savings: Vec<(&str, &str, Option<String>)> = vec![
        ("--aero-model", "sideways", None),
        ("--wake", "sideways", None),
        ("--core-radius", "nan", None),
        ("--mass-kg", "0", None),
        ("--speed-ms", "-3", None),
    ];
    let seed = ("--seed", "x", None);
    let o = |ext: &'static str| ("-o", ext, None);
    let cat = |parts: Vec<Vec<(&'static str, &'static str, Option<String>)>>| {
        parts.into_iter().flatten().collect::<Vec<_>>()
    };
    vec![
        Command {
            name: &["extract"],
            base: strings(&["extract", &geese, "-o", "OUT/p.json"]),
            cases: cat(vec![
                read.clone(),
                fit.clone(),
                vec![
                    ("--wingspan-m", "0", None),
                    ("--footage-fps", "0", None),
                    o("OUT/p.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["report"],
            base: strings(&["report", &geese, "-o", "OUT/r.html"]),
            cases: cat(vec![
                read.clone(),
                fit.clone(),
                savings.clone(),
                vec![
                    ("--wingspan-m", "-1", None),
                    ("--footage-fps", "nan", None),
                    o("OUT/r.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["track"],
            base: strings(&[
                "track",
                &data("track_frames").to_string_lossy(),
                "-o",
                "OUT/a.json",
            ]),
            cases: vec![
                ("--polarity", "grey", None),
                ("--every", "0", None),
                ("--frames", "3..1", None),
                ("--roi", "0,0,999,10", None),
                ("--fps", "-2", None),
                ("--wingspan-px", "0", None),
                ("--debug-frames", "/dev/null/frames", None),
                ("--review", "OUT/r.txt", None),
                o("OUT/a.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["view"],
            base: strings(&["view", &flock, "-o", "OUT/v.html"]),
            cases: vec![
                ("--start-frame", "-1", None),
                ("--every", "0", None),
                o("OUT/v.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["annotate"],
            base: strings(&[
                "annotate",
                &geese,
                "--images",
                &data("track_frames").to_string_lossy(),
                "-o",
                "OUT/r.html",
            ]),
            cases: cat(vec![
                read.clone(),
                vec![
                    ("--images", "OUT/no-frames", Some("no-frames".into())),
                    o("OUT/r.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["power"],
            base: strings(&["power", &shape]),
            cases: vec![
                ("--core-radius", "nan", None),
                ("--wake", "sideways", None),
                ("--wake-descent", "nan", None),
                ("--aero-model", "sideways", None),
                ("--mass-kg", "0", None),
                ("--speed-ms", "-3", None),
                ("--species", "owl", None),
                ("--wingspan-m", "0", None),
                seed.clone(),
            ],
        },
        Command {
            name: &["solve"],
            base: strings(&["solve", &target, "-o", "OUT/s.json"]),
            cases: vec![
                ("--tolerance", "-1", None),
                ("--core-radius", "nan", None),
                ("--wake", "sideways", None),
                o("OUT/s.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["steady"],
            base: strings(&[
                "steady",
                &params,
                "--birds",
                "9",
                "--frames",
                "30",
                "-o",
                "OUT/s.json",
            ]),
            cases: cat(vec![
                steady_flags.clone(),
                course.clone(),
                wingbeat.clone(),
                scene.clone(),
                vec![
                    ("--cruise-altitude", "1e9", None),
                    ("--frames", "0", None),
                    ("--seconds", "-1", None),
                    ("--report", "OUT/r.txt", None),
                    o("OUT/s.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["initiate"],
            base: strings(&["initiate", &steady, "-o", "OUT/i.json"]),
            cases: cat(vec![
                initiate.clone(),
                course.clone(),
                wingbeat.clone(),
                scene.clone(),
                vec![o("OUT/i.txt"), seed.clone()],
            ]),
        },
        Command {
            name: &["animate"],
            base: strings(&[
                "animate",
                &geese,
                "--birds",
                "9",
                "--seconds",
                "1",
                "-o",
                "OUT/a.json",
            ]),
            cases: cat(vec![
                vec![("--footage-fps", "-5", None)],
                read.clone(),
                steady_flags.clone(),
                course,
                initiate.clone(),
                wingbeat.clone(),
                shot.clone(),
                scene.clone(),
                vec![
                    ("--seconds", "-1", None),
                    ("--shot-seconds", "-1", None),
                    ("--size", "0x0", None),
                    ("--picture-fps", "-3", None),
                    o("OUT/a.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["render"],
            base: strings(&["render", &flock, "-o", "OUT/r.json"]),
            cases: cat(vec![
                shot,
                scene,
                vec![
                    ("--size", "0x0", None),
                    ("--picture-fps", "0", None),
                    ("--fps", "0", None),
                    ("--wingspan-m", "0", None),
                    o("OUT/r.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["plot", "power"],
            base: strings(&["plot", "power", &flock, "-o", "OUT/p.png"]),
            cases: vec![
                ("--key", "5", None),
                ("--frame", "100000", None),
                ("--metric", "watts", None),
                ("--formation", "5", None),
                ("--dpi", "5000", None),
                o("OUT/p.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["plot", "xi"],
            base: strings(&["plot", "xi", &flock, "-o", "OUT/x.png"]),
            cases: vec![
                ("--formation", "5", None),
                ("--dpi", "5000", None),
                o("OUT/x.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["plot", "shape"],
            base: strings(&["plot", "shape", &geese, "-o", "OUT/s.png"]),
            cases: cat(vec![
                read,
                fit,
                vec![
                    ("--frame", "999", None),
                    ("--dpi", "0", None),
                    o("OUT/s.txt"),
                    seed.clone(),
                ],
            ]),
        },
        Command {
            name: &["plot", "savings"],
            base: strings(&["plot", "savings", &flock, "-o", "OUT/s.png"]),
            cases: cat(vec![
                savings,
                vec![("--dpi", "nan", None), o("OUT/s.txt"), seed.clone()],
            ]),
        },
        Command {
            name: &["plot", "paths"],
            base: strings(&["plot", "paths", &flock, "-o", "OUT/p.png"]),
            cases: vec![
                ("--formation", "5", None),
                ("--dpi", "5000", None),
                o("OUT/p.txt"),
                seed.clone(),
            ],
        },
        Command {
            name: &["plot", "wingbeat"],
            base: strings(&["plot", "wingbeat", "-o", "OUT/w.png"]),
            cases: vec![
                ("--species", "dodo", None),
                ("--dpi", "5000", None),
                o("OUT/w.txt"),
                seed,
            ],
        },
    ]
}

#[test]
fn every_flag_of_every_command_is_named_when_its_value_is_bad() {
    let dir = scratch("flags-named");
    let out_dir = s(&dir).to_string();
    let mut failures = Vec::new();
    for cmd in commands() {
        // Every flag the command has is tested.
        let listed = help_flags(cmd.name);
        let covered: BTreeSet<String> = cmd
            .cases
            .iter()
            .map(|(f, _, _)| if *f == "-o" { "--output" } else { f }.to_string())
            .collect();
        for f in listed.difference(&covered) {
            failures.push(format!("{:?}: no bad-value case for {f}", cmd.name));
        }
        for f in covered.difference(&listed) {
            failures.push(format!("{:?}: {f} is not in --help", cmd.name));
        }
        for (flag, value, needle) in &cmd.cases {
            let mut args: Vec<String> = cmd
                .base
                .iter()
                .map(|a| a.replace("OUT", &out_dir))
                .collect();
            if let Some(k) = args.iter().position(|a| a == flag) {
                // Replace a flag the base command has (the output, `annotate --images`)
                // instead of adding a second one.
                args[k + 1] = value.replace("OUT", &out_dir);
            } else {
                args.push(flag.to_string());
                args.push(value.replace("OUT", &out_dir));
            }
            let out = bin().args(&args).arg("--quiet").output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr).into_owned();
            let needle = needle.clone().unwrap_or_else(|| flag.to_string());
            let one_line = err.trim_end().lines().count() == 1;
            if out.status.code() != Some(2) || !one_line || !err.contains(&needle) {
                failures.push(format!(
                    "{:?} {flag} {value}: exit {:?}, expected one line naming {needle:?}: {}",
                    cmd.name,
                    out.status.code(),
                    err.trim_end()
                ));
            }
            // Nothing was written.
            let left: Vec<_> = std::fs::read_dir(&dir)
                .unwrap()
                .filter_map(|e| e.ok())
                .map(|e| e.file_name())
                .collect();
            if !left.is_empty() {
                failures.push(format!("{:?} {flag} {value}: left {left:?}", cmd.name));
                for e in std::fs::read_dir(&dir).unwrap().flatten() {
                    let _ = std::fs::remove_file(e.path());
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

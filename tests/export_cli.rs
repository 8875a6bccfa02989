//! `formation render` through the built binary: outputs, exit codes, one-line messages, and no
//! partial or truncated file after a failure.

mod support;

use support::{assert_usage_error, run as formation, s, scratch as tmpdir};

use std::path::Path;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flock_small.json");

#[test]
fn render_writes_every_output_kind() {
    let d = tmpdir("ok");
    let (gif, frames, glb, csv, json) = (
        d.join("f.gif"),
        d.join("frames"),
        d.join("f.glb"),
        d.join("f.csv"),
        d.join("f.json"),
    );
    let frames_arg = format!("{}/", s(&frames));
    let out = formation(&[
        "render",
        FIXTURE,
        "-o",
        s(&gif),
        "-o",
        &frames_arg,
        "-o",
        s(&glb),
        "-o",
        s(&csv),
        "-o",
        s(&json),
        "--size",
        "320x180",
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty());
    let anim = formation::Animation::read(Path::new(FIXTURE)).unwrap();
    let img = image::open(frames.join("frame_00000.png")).unwrap();
    assert_eq!((img.width(), img.height()), (320, 180));
    assert_eq!(
        std::fs::read_dir(&frames).unwrap().count(),
        anim.frames.len()
    );
    let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
        std::fs::File::open(&gif).unwrap(),
    ))
    .unwrap();
    let n = image::AnimationDecoder::into_frames(dec).count();
    assert_eq!(
        n,
        formation::export::sample::output_times(&anim, 25.0).len()
    );
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
    assert_eq!(rows, 1 + anim.frames.len() * anim.birds);
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
    formation::Animation::read(&json).unwrap();
    // Same input, same bytes.
    let gif2 = d.join("g.gif");
    let out = formation(&["render", FIXTURE, "-o", s(&gif2), "--size", "320x180", "-q"]);
    assert!(out.status.success());
    assert_eq!(std::fs::read(&gif).unwrap(), std::fs::read(&gif2).unwrap());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn fps_and_wingspan_flags_change_the_outputs() {
    let d = tmpdir("flags");
    let frames = format!("{}/", s(&d.join("frames")));
    let json = d.join("a.json");
    let out = formation(&[
        "render",
        FIXTURE,
        "-o",
        &frames,
        "-o",
        s(&json),
        "--picture-fps",
        "10",
        "--size",
        "64x48",
        "--wingspan-m",
        "2.0",
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let anim = formation::Animation::read(Path::new(FIXTURE)).unwrap();
    let expected = formation::export::sample::output_times(&anim, 10.0).len();
    assert_eq!(
        std::fs::read_dir(d.join("frames")).unwrap().count(),
        expected
    );
    assert_eq!(formation::Animation::read(&json).unwrap().wingspan_m, 2.0);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_options_and_paths_exit_2_with_one_line_and_no_file() {
    let d = tmpdir("bad");
    let gif = d.join("out.gif");
    let g = s(&gif);
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["-o".into(), s(&d.join("out.xyz")).into()],
            vec!["out.xyz", ".gif"],
        ),
        (
            vec!["-o".into(), s(&d.join("no/such/dir/out.gif")).into()],
            vec!["does not exist"],
        ),
        (
            vec!["-o".into(), g.into(), "--size".into(), "0x0".into()],
            vec!["--size"],
        ),
        (
            vec!["-o".into(), g.into(), "--size".into(), "100000x500".into()],
            vec!["--size"],
        ),
        (
            vec!["-o".into(), g.into(), "--size".into(), "big".into()],
            vec!["--size"],
        ),
        (
            vec!["-o".into(), g.into(), "--picture-fps".into(), "0".into()],
            vec!["--picture-fps"],
        ),
        (
            vec!["-o".into(), g.into(), "--picture-fps".into(), "NaN".into()],
            vec!["--picture-fps"],
        ),
        (
            vec!["-o".into(), g.into(), "--picture-fps=-5".into()],
            vec!["--picture-fps"],
        ),
        (
            vec!["-o".into(), g.into(), "--picture-fps".into(), "60".into()],
            vec!["--picture-fps", "GIF"],
        ),
        (
            vec!["-o".into(), g.into(), "--wingspan-m".into(), "0".into()],
            vec!["--wingspan-m"],
        ),
        (
            vec!["-o".into(), s(&d.join("missing/flock.usda")).into()],
            vec!["flock.usda", "does not exist"],
        ),
        (
            vec!["-o".into(), g.into(), "--keys".into(), "some".into()],
            vec!["--keys"],
        ),
        (
            vec!["-o".into(), g.into(), "--bird-model".into(), FIXTURE.into()],
            vec!["--bird-model", "not a binary .glb"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["render", FIXTURE];
        args.extend(extra.iter().map(|a| a.as_str()));
        let out = formation(&args);
        assert_usage_error(&out, &needles);
        assert!(!gif.exists(), "{args:?} left {g}");
    }
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        0,
        "no temporaries left"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_bad_second_output_writes_nothing_and_keeps_existing_files() {
    let d = tmpdir("keep");
    let csv = d.join("keep.csv");
    std::fs::write(&csv, "old").unwrap();
    let out = formation(&["render", FIXTURE, "-o", s(&csv), "-o", s(&d.join("x.avi"))]);
    assert_usage_error(&out, &["x.avi"]);
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "old");
    // A frames directory holding someone else's files is refused, not replaced.
    std::fs::create_dir_all(d.join("mine")).unwrap();
    std::fs::write(d.join("mine/notes.txt"), "keep me").unwrap();
    let out = formation(&["render", FIXTURE, "-o", &format!("{}/", s(&d.join("mine")))]);
    assert_usage_error(&out, &["notes.txt"]);
    assert!(d.join("mine/notes.txt").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn malformed_animation_exits_2_naming_the_file() {
    let d = tmpdir("malformed");
    let bad = d.join("bad.json");
    let text =
        std::fs::read_to_string(FIXTURE)
            .unwrap()
            .replacen("\"fps\": 20.0", "\"fps\": -1.0", 1);
    std::fs::write(&bad, text).unwrap();
    let out_gif = d.join("o.gif");
    let out = formation(&["render", s(&bad), "-o", s(&out_gif)]);
    assert_usage_error(&out, &["bad.json", "fps"]);
    assert!(!out_gif.exists());
    // Frame times that do not increase cannot be sampled or keyed.
    let mut anim = formation::Animation::read(Path::new(FIXTURE)).unwrap();
    anim.frames[3].t = anim.frames[2].t;
    let stuck = d.join("stuck.json");
    formation::io::write_json_atomic(&stuck, &anim).unwrap();
    let out = formation(&["render", s(&stuck), "-o", s(&d.join("o.glb"))]);
    assert_usage_error(&out, &["stuck.json", "frames[3].t"]);
    assert!(!d.join("o.glb").exists());
    let out = formation(&["render", s(&d.join("missing.json")), "-o", s(&out_gif)]);
    assert_usage_error(&out, &["missing.json"]);
    std::fs::remove_dir_all(&d).unwrap();
}

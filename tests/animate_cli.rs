//! `formation animate`, the whole chain through the binary: every output opens in an independent
//! reader, equal seeds give equal bytes, and bad flags fail before any work with one line and
//! no file.

mod support;

use support::{assert_usage_text, example_arg as example, run_quiet as run, scratch};

use std::path::Path;

const SMALL: [&str; 6] = ["--seconds", "2", "--size", "160x90", "--picture-fps", "10"];

#[test]
fn every_output_opens_and_matches_the_animation() {
    let dir = scratch("outputs");
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    let mut args = vec![
        "animate".to_string(),
        example("barnacle_geese_v.json"),
        "--birds".into(),
        "11".into(),
    ];
    for o in ["a.json", "a.csv", "a.gif", "a.glb", "frames/"] {
        args.push("-o".into());
        args.push(p(o));
    }
    args.extend(SMALL.iter().map(|s| s.to_string()));
    let argv: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    let (code, err) = run(&argv);
    assert_eq!(code, 0, "{err}");

    let anim = formation::Animation::read(Path::new(&p("a.json"))).unwrap();
    assert_eq!(anim.birds, 11);
    let names: Vec<&str> = anim.stages.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["initiation", "steady"]);
    let steady = anim.stage("steady").unwrap();
    assert_eq!(steady.end - steady.start, 60, "2 s at 30 fps");
    assert_eq!(steady.end, anim.frames.len());
    assert!(anim.frames.iter().all(|f| f.wing_phase.is_some()));
    assert!(!anim.key_shapes.is_empty());
    assert!(anim.key_shapes.iter().all(|k| k.frame >= steady.start));

    // CSV: header and one row per frame and bird.
    let csv = std::fs::read_to_string(p("a.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("frame,t,bird,x,y,z,heading,speed,e,xi"));
    assert_eq!(lines.count(), anim.frames.len() * 11);

    // GIF: decoded by `image`, 160×90, one frame per 1/10 s of animation.
    let file = std::fs::File::open(p("a.gif")).unwrap();
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(file)).unwrap();
    use image::AnimationDecoder;
    let frames = decoder.into_frames().collect_frames().unwrap();
    let duration = anim.frames.last().unwrap().t - anim.frames[0].t;
    let expected = (duration * 10.0).floor() as usize + 1;
    assert!(
        frames.len().abs_diff(expected) <= 1,
        "{} GIF frames for {duration} s at 10 fps",
        frames.len()
    );
    assert_eq!(frames[0].buffer().dimensions(), (160, 90));

    // PNG frames decode.
    let pngs: Vec<_> = std::fs::read_dir(p("frames")).unwrap().collect();
    assert!(pngs.len() > 10);
    let first = image::open(dir.join("frames").join("frame_00000.png")).unwrap();
    assert_eq!((first.width(), first.height()), (160, 90));

    // glb: the binary header.
    let glb = std::fs::read(p("a.glb")).unwrap();
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(u32::from_le_bytes(glb[4..8].try_into().unwrap()), 2);
    assert_eq!(
        u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
        glb.len()
    );
}

#[test]
fn equal_seeds_give_equal_bytes_and_params_input_gives_the_same_flock() {
    let dir = scratch("seeds");
    let p = |n: &str| dir.join(n).to_string_lossy().into_owned();
    let geese = example("barnacle_geese_v.json");
    let go = |seed: &str, input: &str, out: &str| {
        let (code, err) = run(&[
            "animate",
            input,
            "--birds",
            "9",
            "-o",
            &p(&format!("{out}.json")),
            "-o",
            &p(&format!("{out}.gif")),
            "--seed",
            seed,
            "--seconds",
            "1",
            "--size",
            "96x54",
            "--picture-fps",
            "5",
        ]);
        assert_eq!(code, 0, "{err}");
    };
    go("7", &geese, "a");
    go("7", &geese, "b");
    go("8", &geese, "c");
    let read = |n: &str| std::fs::read(p(n)).unwrap();
    assert_eq!(read("a.json"), read("b.json"));
    assert_eq!(read("a.gif"), read("b.gif"));
    assert_ne!(read("a.json"), read("c.json"));
    // extract → params file → animate gives the flock that animate gives from the annotations.
    let (code, err) = run(&["extract", &geese, "-o", &p("params.json"), "--seed", "7"]);
    assert_eq!(code, 0, "{err}");
    go("7", &p("params.json"), "d");
    assert_eq!(read("a.json"), read("d.json"));
}

#[test]
fn steady_only() {
    let dir = scratch("steady-only");
    let out = dir.join("s.json");
    let (code, err) = run(&[
        "animate",
        &example("pelicans_u_labelme"),
        "--birds",
        "20",
        "--no-initiation",
        "--seconds",
        "3",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let anim = formation::Animation::read(&out).unwrap();
    assert_eq!(anim.frames.len(), 90);
    assert_eq!(anim.stages.len(), 1);
    assert_eq!(anim.stages[0].name, "steady");
}

#[test]
fn bad_flags_fail_up_front_with_one_line_and_no_file() {
    let dir = scratch("bad");
    let geese = example("barnacle_geese_v.json");
    let cases: &[(&[&str], &str)] = &[
        (&["-o", "OUT/x.avi"], "x.avi"),
        (&["-o", "OUT/x.gif", "--size", "0x0"], "--size"),
        (&["-o", "OUT/x.gif", "--fps", "0"], "fps"),
        (&["-o", "OUT/x.gif", "--fps", "nan"], "fps"),
        (&["-o", "OUT/x.gif", "--picture-fps", "-3"], "fps"),
        (&["-o", "OUT/x.gif", "--seconds", "-1"], "--seconds"),
        (&["-o", "/nonexistent-dir/x.gif"], "/nonexistent-dir/x.gif"),
        (&["-o", "OUT/x.gif", "--species", "dodo"], "dodo"),
        (&["-o", "OUT/x.gif", "--max-steps", "0"], "max-steps"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["animate", &geese, "--birds", "9"];
        let owned: Vec<String> = extra
            .iter()
            .map(|a| a.replace("OUT", dir.to_str().unwrap()))
            .collect();
        args.extend(owned.iter().map(|s| s.as_str()));
        let (code, err) = run(&args);
        assert_usage_text(&format!("{extra:?}"), code, &err, &[needle]);
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            0,
            "{extra:?} left a file"
        );
    }
    let (code, err) = run(&["animate", &geese, "--birds", "0", "-o", "x.gif"]);
    assert_usage_text("--birds 0", code, &err, &["--birds"]);
}

//! `formation extract` and `formation plot shape` through the binary (issue 3): bad input gets
//! exit 2 and one line naming the file and the frame/row/field, with no output file left behind
//! and an existing one untouched; the examples extract to the shapes they were made with; equal
//! seeds give byte-identical params; charts are written.

mod support;

use support::{assert_usage_error_in, examples_dir as examples, run, scratch as tmpdir};

use std::fs;
use std::path::Path;

/// Runs `extract` on `content` written to `name`; asserts exit 2, a one-line message containing
/// the file name and every `needles`, and that no output was written.
fn bad(name: &str, content: &str, extra: &[&str], needles: &[&str]) {
    let dir = tmpdir(&name.replace(['/', '.'], "_"));
    let input = dir.join(name);
    fs::write(&input, content).unwrap();
    let out = dir.join("params.json");
    let mut args = vec![
        "extract",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    // The message names the file, and says what is wrong with it.
    let mut all = vec![name];
    all.extend_from_slice(needles);
    assert_usage_error_in(name, &o, &all);
    assert!(!out.exists(), "{name}: no output after a failure");
    // Only the input is left: no temporary files either.
    assert_eq!(
        fs::read_dir(&dir).unwrap().count(),
        1,
        "{name}: stray files"
    );
    let _ = fs::remove_dir_all(&dir);
}

const V3: &str = "[[100,100],[60,140],[140,140]]";

#[test]
fn empty_file() {
    bad("empty.json", "", &[], &["empty"]);
    bad("blank.csv", "  \n\n", &[], &["empty"]);
}

#[test]
fn truncated_files() {
    bad(
        "trunc.json",
        r#"{"wingspan_px": 30, "frames": [{"birds": [[1, 2], [3"#,
        &[],
        &["truncated", "line 1"],
    );
    bad(
        "trunc_dlt.csv",
        "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y,pt3_cam1_X,pt3_cam1_Y\n1,2,3,4,5,6\n1,2,3,4,5",
        &["--wingspan-px", "20"],
        &["row 2", "truncated"],
    );
}

#[test]
fn wrong_json_shape() {
    bad(
        "shape.json",
        r#"{"frames": {"birds": []}}"#,
        &[],
        &["frames"],
    );
    bad(
        "bird.json",
        r#"{"wingspan_px": 30, "frames": [{"birds": [[1, 2, 3]]}]}"#,
        &[],
        &["frames[0].birds[0]"],
    );
    bad("array.json", "[1, 2, 3]", &[], &["top level"]);
    bad("other.json", r#"{"hello": 1}"#, &[], &["frames", "shapes"]);
}

#[test]
fn nan_or_text_in_coordinates() {
    bad(
        "nan.csv",
        "frame,bird,x,y\n0,0,1,2\n0,1,NaN,3\n0,2,5,6\n",
        &["--wingspan-px", "10"],
        &["row 2", "field x", "NaN"],
    );
    bad(
        "text.csv",
        "frame,x,y\n0,1,2\n0,4,3\n0,5,oops\n",
        &["--wingspan-px", "10"],
        &["row 3", "field y", "oops"],
    );
    bad(
        "text.json",
        r#"{"wingspan_px": 30, "frames": [{"birds": [[1, 2], ["a", 3], [5, 6]]}]}"#,
        &[],
        &["frames[0].birds[1][0] (x)"],
    );
    bad(
        "text_dlt.csv",
        "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y,pt3_cam1_X,pt3_cam1_Y\n1,2,3,4,5,six\n",
        &["--wingspan-px", "20"],
        &["row 1", "pt3_cam1_Y", "six"],
    );
}

#[test]
fn fewer_than_three_birds() {
    bad(
        "two.json",
        r#"{"wingspan_px": 30, "frames": [{"index": 0, "birds": [[1,2],[3,4],[5,6]]}, {"index": 7, "birds": [[1,2],[3,4]]}]}"#,
        &[],
        &["frame 7", "2 bird(s)", "at least 3"],
    );
}

#[test]
fn duplicate_points() {
    bad(
        "dup.json",
        r#"{"wingspan_px": 30, "frames": [{"birds": [[1,2],[3,4],[1,2]]}]}"#,
        &[],
        &["frame 0", "same point", "frames[0].birds[2]"],
    );
    bad(
        "dupid.csv",
        "frame,bird,x,y\n0,1,1,2\n0,1,3,4\n0,2,5,6\n",
        &["--wingspan-px", "10"],
        &["frame 0", "bird id 1", "twice"],
    );
}

#[test]
fn no_scale_and_bad_scale() {
    bad(
        "noscale.json",
        &format!(r#"{{"frames": [{{"birds": {V3}}}]}}"#),
        &[],
        &["frame 0", "no scale", "--wingspan-px"],
    );
    bad(
        "negscale.json",
        &format!(r#"{{"wingspan_px": -4, "frames": [{{"birds": {V3}}}]}}"#),
        &[],
        &["wingspan_px", "positive"],
    );
    bad(
        "negframe.json",
        &format!(r#"{{"frames": [{{"wingspan_px": 0, "birds": {V3}}}]}}"#),
        &[],
        &["frames[0].wingspan_px", "positive"],
    );
    // A bad flag names the flag.
    let dir = tmpdir("flag");
    let p = dir.join("ok.json");
    fs::write(&p, format!(r#"{{"frames": [{{"birds": {V3}}}]}}"#)).unwrap();
    let o = run(&[
        "extract",
        p.to_str().unwrap(),
        "-o",
        dir.join("o.json").to_str().unwrap(),
        "--wingspan-px",
        "-3",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        err.contains("--wingspan-px") && err.contains("positive"),
        "{err}"
    );
    assert!(!dir.join("o.json").exists());
}

#[test]
fn labelme_directory_without_points() {
    let dir = tmpdir("labelme_empty");
    let lm = dir.join("frames");
    fs::create_dir_all(&lm).unwrap();
    for k in 0..3 {
        fs::write(
            lm.join(format!("f{k}.json")),
            r#"{"version": "5.4.1", "shapes": [{"label": "bird", "points": [[1,2],[3,4],[5,6]], "shape_type": "polygon"}], "imagePath": "a.jpg"}"#,
        )
        .unwrap();
    }
    let out = dir.join("p.json");
    let o = run(&[
        "extract",
        lm.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--wingspan-px",
        "20",
    ]);
    assert_usage_error_in(
        "a labelme directory without points",
        &o,
        &["frames", "point"],
    );
    assert!(!out.exists());
    // And an empty directory.
    let empty = dir.join("none");
    fs::create_dir_all(&empty).unwrap();
    let o = run(&[
        "extract",
        empty.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(err.contains("none") && err.contains(".json"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn failure_keeps_an_existing_output() {
    let dir = tmpdir("keep");
    let input = dir.join("bad.json");
    fs::write(&input, "{").unwrap();
    let out = dir.join("params.json");
    fs::write(&out, "precious").unwrap();
    let o = run(&[
        "extract",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(fs::read_to_string(&out).unwrap(), "precious");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn params_file_is_not_annotations() {
    let dir = tmpdir("params_in");
    let ann = examples().join("barnacle_geese_v.json");
    let p = dir.join("p.json");
    let o = run(&["extract", ann.to_str().unwrap(), "-o", p.to_str().unwrap()]);
    assert!(o.status.success());
    let o = run(&[
        "extract",
        p.to_str().unwrap(),
        "-o",
        dir.join("q.json").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(err.contains("params file"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

fn params(path: &Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

fn kinds(p: &serde_json::Value) -> Vec<String> {
    p["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["shape"]["kind"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn examples_extract_to_their_shapes() {
    let dir = tmpdir("examples");
    let cases: [(&str, &[&str], &str, usize); 4] = [
        ("barnacle_geese_v.json", &[], "v", 9),
        ("snow_geese_j.csv", &[], "j", 16),
        (
            "cranes_v_dltdv.csv",
            &["--wingspan-px", "22", "--heading", "300"],
            "v",
            41,
        ),
        ("pelicans_u_labelme", &[], "u", 12),
    ];
    for (name, extra, kind, birds) in cases {
        let input = examples().join(name);
        let out = dir.join(format!("{name}.json"));
        let mut args = vec![
            "extract",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = run(&args);
        let stdout = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            stdout.contains("mu_x") && stdout.contains("kinds:"),
            "{name}: table: {stdout}"
        );
        let p = params(&out);
        assert_eq!(p["format"], "formation-params/1");
        assert_eq!(p["birds"].as_u64(), Some(birds as u64), "{name}");
        let k = kinds(&p);
        let right = k.iter().filter(|x| x.as_str() == kind).count();
        assert!(right * 10 >= k.len() * 9, "{name}: {k:?}");
        // Every frame lists every bird's position with its deviation.
        for f in p["frames"].as_array().unwrap() {
            assert_eq!(
                f["positions"].as_array().unwrap().len(),
                f["order"].as_array().unwrap().len()
            );
        }
    }
    // The cranes were made with 4 outliers; the snow geese with 1.
    let c = params(&dir.join("cranes_v_dltdv.csv.json"));
    assert!(c["frames"].as_array().unwrap().iter().all(|f| f["outliers"]
        .as_array()
        .unwrap()
        .len()
        == 4));
    let s = params(&dir.join("snow_geese_j.csv.json"));
    assert!(s["frames"].as_array().unwrap().iter().all(|f| f["outliers"]
        .as_array()
        .unwrap()
        .len()
        == 1));
    // Without the flags the DLTdv file has no scale: the message says how to give one.
    let o = run(&[
        "extract",
        examples().join("cranes_v_dltdv.csv").to_str().unwrap(),
        "-o",
        dir.join("x.json").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--wingspan-px"));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn equal_seeds_give_identical_bytes_and_json_goes_to_stdout() {
    let dir = tmpdir("seed");
    let input = examples().join("cranes_v_dltdv.csv");
    let a = dir.join("a.json");
    let b = dir.join("b.json");
    for out in [&a, &b] {
        let o = run(&[
            "--seed",
            "5",
            "extract",
            input.to_str().unwrap(),
            "--wingspan-px",
            "22",
            "--heading",
            "300",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success());
    }
    assert_eq!(fs::read(&a).unwrap(), fs::read(&b).unwrap());
    let o = run(&[
        "--seed",
        "5",
        "extract",
        input.to_str().unwrap(),
        "--wingspan-px",
        "22",
        "--heading",
        "300",
        "--json",
    ]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    assert_eq!(v, params(&a));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn plot_shape_writes_png_and_svg() {
    let dir = tmpdir("plot");
    let p = dir.join("p.json");
    let ann = examples().join("snow_geese_j.csv");
    assert!(
        run(&["extract", ann.to_str().unwrap(), "-o", p.to_str().unwrap()])
            .status
            .success()
    );
    let png = dir.join("fit.png");
    let o = run(&[
        "plot",
        "shape",
        p.to_str().unwrap(),
        "--frame",
        "3",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(&fs::read(&png).unwrap()[..4], b"\x89PNG");
    // Straight from annotations, as SVG.
    let svg = dir.join("fit.svg");
    let o = run(&[
        "plot",
        "shape",
        ann.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = fs::read_to_string(&svg).unwrap();
    assert!(text.contains("<svg") && text.contains("leader"));
    // A frame that does not exist: exit 2, the flag named, no file.
    let none = dir.join("none.png");
    let o = run(&[
        "plot",
        "shape",
        p.to_str().unwrap(),
        "--frame",
        "99",
        "-o",
        none.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--frame"));
    assert!(!none.exists());
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn params_from_path_reads_params_or_extracts_annotations() {
    use formation::annotations::ReadOptions;
    use formation::extract::{params_from_path, ExtractOptions};
    use formation::rng::stream;
    let dir = tmpdir("from_path");
    let ann = examples().join("barnacle_geese_v.json");
    let from_ann = params_from_path(
        &ann,
        &ReadOptions::default(),
        &ExtractOptions::default(),
        &mut stream(0, "extract"),
    )
    .unwrap();
    let p = dir.join("p.json");
    assert!(
        run(&["extract", ann.to_str().unwrap(), "-o", p.to_str().unwrap()])
            .status
            .success()
    );
    let from_params = params_from_path(
        &p,
        &ReadOptions::default(),
        &ExtractOptions::default(),
        &mut stream(9, "x"),
    )
    .unwrap();
    assert_eq!(from_ann.frames.len(), from_params.frames.len());
    assert_eq!(from_ann.frames[0].order, from_params.frames[0].order);
    assert_eq!(
        from_ann.frames[0].shape.kind(),
        from_params.frames[0].shape.kind()
    );
    let _ = fs::remove_dir_all(&dir);
}

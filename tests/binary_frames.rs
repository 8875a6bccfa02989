//! Animation files whose frames are in a binary file beside them (`--binary-frames`): the pair is
//! read back as the same animation in single precision by every command, is deterministic and
//! about 45 % of the text's size, and a frames file that is missing, cut short, foreign or named
//! outside the directory is refused with one line naming it.

mod support;

use serde_json::Value;
use support::{assert_refused, bin, data, s, scratch};

const FIELDS: [&str; 10] = [
    "x",
    "y",
    "z",
    "heading",
    "speed",
    "bank",
    "pitch",
    "e",
    "xi",
    "wing_phase",
];

fn steady(dir: &std::path::Path, out: &str, extra: &[&str]) {
    let params = data("steady_v9_params.json");
    let o = bin()
        .current_dir(dir)
        .args([
            "steady",
            s(&params),
            "--birds",
            "9",
            "--seconds",
            "4",
            "--seed",
            "5",
            "--quiet",
            "-o",
            out,
        ])
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn json(path: &std::path::Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn binary_frames_read_back_as_the_animation_in_single_precision() {
    let dir = scratch("binary_frames_round_trip");
    steady(&dir, "text.json", &[]);
    steady(&dir, "bin.json", &["--binary-frames"]);
    let text = json(&dir.join("text.json"));
    let head = json(&dir.join("bin.json"));
    // Everything but the frames is in the header, as in the text file.
    for (k, v) in text.as_object().unwrap() {
        if k != "frames" {
            assert_eq!(&head[k], v, "{k}");
        }
    }
    assert!(head.get("frames").is_none(), "the header has no frames");
    let ff = &head["frames_file"];
    assert_eq!(ff["format"], "formation-frames/2");
    assert_eq!(ff["path"], "bin.frames");
    let frames = text["frames"].as_array().unwrap();
    assert_eq!(ff["frames"].as_u64().unwrap() as usize, frames.len());
    let fields: Vec<&str> = ff["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let want: Vec<&str> = FIELDS
        .iter()
        .copied()
        .filter(|f| frames[0].get(*f).is_some())
        .collect();
    assert_eq!(fields, want);
    // The documented layout, read here independently of the library.
    let bytes = std::fs::read(dir.join("bin.frames")).unwrap();
    assert_eq!(&bytes[..16], b"formation-frames");
    let birds = 9;
    let record = 8 + fields.len() * birds * 4;
    assert_eq!(bytes.len(), 16 + frames.len() * record + 8);
    // The id at the end is the header's.
    let id = u64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap());
    assert_eq!(ff["id"].as_str().unwrap(), format!("{id:016x}"));
    for (i, f) in frames.iter().enumerate() {
        let r = &bytes[16 + i * record..16 + (i + 1) * record];
        let t = f64::from_le_bytes(r[..8].try_into().unwrap());
        assert_eq!(t, f["t"].as_f64().unwrap(), "frame {i} t");
        for (j, name) in fields.iter().enumerate() {
            for b in 0..birds {
                let at = 8 + (j * birds + b) * 4;
                let got = f32::from_le_bytes(r[at..at + 4].try_into().unwrap());
                let v = f[*name][b].as_f64().unwrap();
                assert_eq!(got, v as f32, "frame {i} {name}[{b}]");
            }
        }
    }
    // The text file is more than twice the pair's size.
    let text_len = std::fs::metadata(dir.join("text.json")).unwrap().len();
    let pair = std::fs::metadata(dir.join("bin.json")).unwrap().len() + bytes.len() as u64;
    assert!(pair * 2 < text_len, "{pair} bytes against {text_len}");
    // Deterministic: the same run writes the same bytes.
    steady(&dir, "again.json", &["--binary-frames"]);
    assert_eq!(std::fs::read(dir.join("again.frames")).unwrap(), bytes);
    // Read back by render: as JSON text, the values of the text file to single precision.
    let o = bin()
        .current_dir(&dir)
        .args(["render", "bin.json", "-o", "back.json", "-o", "back.csv"])
        .args(["--quiet"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = json(&dir.join("back.json"));
    assert!(back.get("frames_file").is_none());
    let back_frames = back["frames"].as_array().unwrap();
    assert_eq!(back_frames.len(), frames.len());
    for (i, (a, b)) in frames.iter().zip(back_frames).enumerate() {
        for name in &fields {
            for k in 0..birds {
                let (x, y) = (a[*name][k].as_f64().unwrap(), b[*name][k].as_f64().unwrap());
                // Single precision, then the file's own rounding (1e-5 for positions).
                let tol = x.abs() * 1.2e-7 + 1.1e-5;
                assert!((x - y).abs() <= tol, "frame {i} {name}[{k}]: {x} vs {y}");
            }
        }
    }
    let csv = std::fs::read_to_string(dir.join("back.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + frames.len() * birds);
    // Nothing else beside the outputs (no temporaries).
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "again.frames",
            "again.json",
            "back.csv",
            "back.json",
            "bin.frames",
            "bin.json",
            "text.json"
        ]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_frames_files_are_refused_naming_them() {
    let dir = scratch("binary_frames_bad");
    steady(&dir, "a.json", &["--binary-frames"]);
    let frames = std::fs::read(dir.join("a.frames")).unwrap();
    let header = std::fs::read_to_string(dir.join("a.json")).unwrap();
    let render = |what: &str, file: &str, needle: &str| {
        let o = bin()
            .current_dir(&dir)
            .args(["render", file, "-o", "out.csv", "--quiet"])
            .output()
            .unwrap();
        assert_refused(&o, needle, what);
        assert!(!dir.join("out.csv").exists(), "{what}: no output");
    };
    // Cut short.
    std::fs::write(dir.join("a.frames"), &frames[..frames.len() - 1]).unwrap();
    render("cut short", "a.json", "a.frames");
    // Foreign first bytes.
    let mut foreign = frames.clone();
    foreign[..16].copy_from_slice(b"not-frames-file!");
    std::fs::write(dir.join("a.frames"), &foreign).unwrap();
    render("foreign", "a.json", "not a frames file");
    // Missing.
    std::fs::remove_file(dir.join("a.frames")).unwrap();
    render("missing", "a.json", "a.frames");
    std::fs::write(dir.join("a.frames"), &frames).unwrap();
    // Named outside the directory, an unknown field, a required field left out, another version,
    // frames of its own too.
    for (what, from, to, needle) in [
        (
            "outside",
            "\"path\":\"a.frames\"",
            "\"path\":\"../a.frames\"",
            "frames_file.path",
        ),
        (
            "unknown field",
            "\"fields\":[\"x\"",
            "\"fields\":[\"w\"",
            "frames_file.fields[0]",
        ),
        (
            "required field",
            "\"fields\":[\"x\",",
            "\"fields\":[",
            "\"x\" is missing",
        ),
        (
            "version",
            "formation-frames/2",
            "formation-frames/9",
            "frames_file.format",
        ),
        (
            "both",
            "\"frames_file\":",
            "\"frames\":[{\"t\":0,\"x\":[0],\"y\":[0],\"z\":[0],\"heading\":[0],\"speed\":[0]}],\"frames_file\":",
            "frames_file",
        ),
    ] {
        assert!(header.contains(from), "{what}: {from} not in the header");
        std::fs::write(dir.join("b.json"), header.replacen(from, to, 1)).unwrap();
        std::fs::copy(dir.join("a.frames"), dir.join("b.frames")).unwrap();
        render(what, "b.json", needle);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Two runs writing the same name at once can leave the animation file of one and the frames file
/// of the other; with equal sizes the pair used to be read as one animation. The id both carry
/// refuses it, naming both files; a first-version pair (no id) is still read.
#[test]
fn a_pair_mixed_from_two_runs_is_refused_naming_both_files() {
    let dir = scratch("binary_frames_mixed");
    steady(&dir, "a.json", &["--binary-frames"]);
    // Another seed: another flight of the same size.
    let params = data("steady_v9_params.json");
    let o = bin()
        .current_dir(&dir)
        .args(["steady", s(&params), "--birds", "9", "--seconds", "4"])
        .args(["--seed", "6", "--quiet", "--binary-frames", "-o", "b.json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let a = std::fs::read(dir.join("a.frames")).unwrap();
    let b = std::fs::read(dir.join("b.frames")).unwrap();
    assert_eq!(a.len(), b.len(), "the two runs' frames files have one size");
    assert_ne!(a, b);
    std::fs::copy(dir.join("b.frames"), dir.join("a.frames")).unwrap();
    let o = bin()
        .current_dir(&dir)
        .args(["render", "a.json", "-o", "out.csv", "--quiet"])
        .output()
        .unwrap();
    assert_refused(&o, "different runs", "mixed pair");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("a.frames") && err.contains("a.json"),
        "names both files: {err}"
    );
    assert!(!dir.join("out.csv").exists());
    // The first version: no id in the header, no id at the end of the frames file.
    std::fs::write(dir.join("a.frames"), &a[..a.len() - 8]).unwrap();
    let head = json(&dir.join("a.json"));
    let mut v1 = head.clone();
    v1["frames_file"]["format"] = "formation-frames/1".into();
    v1["frames_file"].as_object_mut().unwrap().remove("id");
    std::fs::write(dir.join("a.json"), serde_json::to_vec(&v1).unwrap()).unwrap();
    let o = bin()
        .current_dir(&dir)
        .args(["render", "a.json", "-o", "v1.csv", "--quiet"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

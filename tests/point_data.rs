//! Point data for other tools: the CSV's orientation (`qx,qy,qz,qw`) and `pitch`, and
//! `--units m` / `--up y` for the CSV and the animation JSON (which reads back as it was).

mod support;

use formation::animation::axes::{orientation, Units, Up};
use formation::export::{write_outputs, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;
use formation::Animation;
use support::{bin, code, example, s, scratch, stderr};

fn flight() -> Animation {
    let mut c = Config {
        seed: 5,
        seconds: Some(2.0),
        ..Config::default()
    };
    c.steady.birds = 7;
    Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap()
        .0
}

/// The CSV as header and rows of cells.
fn read_csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    // v' = q v q*, with q = [x, y, z, w].
    let [x, y, z, w] = q;
    let t = [
        2.0 * (y * v[2] - z * v[1]),
        2.0 * (z * v[0] - x * v[2]),
        2.0 * (x * v[1] - y * v[0]),
    ];
    [
        v[0] + w * t[0] + (y * t[2] - z * t[1]),
        v[1] + w * t[1] + (z * t[0] - x * t[2]),
        v[2] + w * t[2] + (x * t[1] - y * t[0]),
    ]
}

#[test]
fn the_csv_carries_each_birds_orientation_and_pitch() {
    let dir = scratch("point-q");
    let a = flight();
    let csv = dir.join("f.csv");
    write_outputs(
        &a,
        std::slice::from_ref(&csv),
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap();
    let (header, rows) = read_csv(&csv);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    // The fixed ten first, the new columns last.
    assert_eq!(
        header[..10].join(","),
        "frame,t,bird,x,y,z,heading,speed,e,xi"
    );
    assert_eq!(header[header.len() - 5..].join(","), "qx,qy,qz,qw,pitch");
    let (qx, qy, qz, qw) = (col("qx"), col("qy"), col("qz"), col("qw"));
    let mut turned = 0;
    for r in &rows {
        let num = |i: usize| r[i].parse::<f64>().unwrap();
        // The CSV writes quaternion components and angles to 10⁻⁶ (the animation file's
        // precision), so the unit norm and the axes below hold to a few 10⁻⁶.
        let q = [num(qx), num(qy), num(qz), num(qw)];
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 2.5e-6, "{norm}");
        assert!(q[3] >= 0.0);
        // The bird's forward axis (+y) points along its heading, lifted by its pitch.
        let (h, p) = (num(col("heading")), num(col("pitch")));
        let fwd = rotate(q, [0.0, 1.0, 0.0]);
        let want = [h.sin() * p.cos(), h.cos() * p.cos(), p.sin()];
        for i in 0..3 {
            assert!((fwd[i] - want[i]).abs() < 1e-5, "{fwd:?} {want:?}");
        }
        // Its right wing (+x) drops by the bank.
        let right = rotate(q, [1.0, 0.0, 0.0]);
        let bank = num(col("bank"));
        assert!(
            (right[2] + bank.sin() * p.cos()).abs() < 1e-5,
            "{right:?} {bank}"
        );
        if p.abs() > 1e-6 {
            turned += 1;
        }
    }
    // The take-off climbs nose up: some rows carry a pitch.
    assert!(turned > 0);
}

#[test]
fn metres_and_y_up_for_csv_and_json_and_the_json_reads_back() {
    let dir = scratch("point-units");
    let a = flight();
    let (csv, json, glb) = (dir.join("m.csv"), dir.join("m.json"), dir.join("m.glb"));
    let opts = RenderOptions {
        units: Units::M,
        up: Up::Y,
        ..RenderOptions::default()
    };
    write_outputs(
        &a,
        &[csv.clone(), json.clone(), glb.clone()],
        &opts,
        &Silent,
    )
    .unwrap();
    let (header, rows) = read_csv(&csv);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let ws = a.wingspan_m;
    let mut worst: f64 = 0.0;
    for r in &rows {
        let num = |i: usize| r[i].parse::<f64>().unwrap();
        let (k, b) = (num(0) as usize, num(2) as usize);
        let f = &a.frames[k];
        let want = [f.x[b] * ws, f.z[b] * ws, -f.y[b] * ws];
        let got = [num(col("x")), num(col("y")), num(col("z"))];
        for i in 0..3 {
            worst = worst.max((got[i] - want[i]).abs());
        }
        // Positions and speeds to 10⁻⁵ m (and m/s), angles and quaternions to 10⁻⁶, as the
        // animation file stores them: each cell the value rounded to that step.
        assert!((num(col("speed")) - f.speed[b] * ws).abs() <= 0.5e-5 + 1e-9);
        let q = [
            num(col("qx")),
            num(col("qy")),
            num(col("qz")),
            num(col("qw")),
        ];
        let o = orientation(Up::Y, f.heading[b], num(col("pitch")), num(col("bank")));
        for i in 0..4 {
            // Rounded once in the CSV, and pitch and bank rounded before `o` was made.
            assert!((q[i] - o[i]).abs() <= 1.5e-6, "{q:?} {o:?}");
        }
    }
    assert!(worst <= 0.5e-5 + 1e-9, "{worst}");
    // The JSON says what it is in and reads back in wingspans, z up.
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(
        (doc["units"].as_str(), doc["up"].as_str()),
        (Some("m"), Some("y"))
    );
    let back = Animation::read(&json).unwrap();
    let mut worst: f64 = 0.0;
    for (f, g) in a.frames.iter().zip(&back.frames) {
        for (p, q) in [
            (&f.x, &g.x),
            (&f.y, &g.y),
            (&f.z, &g.z),
            (&f.speed, &g.speed),
        ] {
            for (p, q) in p.iter().zip(q) {
                worst = worst.max((p - q).abs());
            }
        }
    }
    // The file stores positions and speeds to 10⁻⁵ m (and m/s).
    assert!(worst <= 0.5e-5 / a.wingspan_m * (1.0 + 1e-6), "{worst}");
    assert!(back.units.is_default() && back.up.is_default());
    // What was read is exactly the original rounded in metres on the y-up axes and brought back,
    // and its .glb is that animation's .glb.
    let mut expect = a.in_axes(Units::M, Up::Y);
    expect.quantize();
    expect.to_world_axes();
    assert!(
        expect.frames == back.frames,
        "the read frames are the rounded ones"
    );
    let glb = dir.join("expect.glb");
    write_outputs(
        &expect,
        std::slice::from_ref(&glb),
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap();
    let again = dir.join("again.glb");
    write_outputs(
        &back,
        std::slice::from_ref(&again),
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap();
    assert_eq!(std::fs::read(&glb).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn units_and_up_on_the_command_line() {
    let dir = scratch("point-cli");
    let out = dir.join("a.csv");
    let o = bin()
        .args([
            "animate",
            s(&example("barnacle_geese_v.json")),
            "--birds",
            "5",
            "--seconds",
            "1",
            "--quiet",
            "--units",
            "m",
            "--up",
            "y",
            "-o",
            s(&out),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let (header, rows) = read_csv(&out);
    let y = header.iter().position(|h| h == "y").unwrap();
    // Y up in metres: birds sit at the standing height above the field at the start.
    let h: f64 = rows[0][y].parse().unwrap();
    assert!(h > 0.0 && h < 1.0, "{h}");
    for (flag, value) in [("--units", "feet"), ("--up", "x")] {
        let o = bin()
            .args([
                "render",
                s(&dir.join("none.json")),
                flag,
                value,
                "-o",
                s(&dir.join("b.csv")),
            ])
            .output()
            .unwrap();
        assert_eq!(code(&o), 2);
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
    }
}

#[test]
fn the_flown_path_is_written_for_layout_and_reads_back_as_a_path() {
    let dir = scratch("point-path");
    let path = dir.join("course.json");
    // A right-angle corner much tighter than a flock of 9 can turn: it gets widened.
    std::fs::write(
        &path,
        r#"{"units": "wingspans", "points": [[0, 0, 30], [0, 120, 30], [120, 120, 30]]}"#,
    )
    .unwrap();
    let (flown, json, glb, usda) = (
        dir.join("flown.json"),
        dir.join("a.json"),
        dir.join("a.glb"),
        dir.join("a.usda"),
    );
    let o = bin()
        .args([
            "animate",
            s(&example("barnacle_geese_v.json")),
            "--birds",
            "9",
            "--seconds",
            "14",
            "--path",
            s(&path),
            "--quiet",
            "--path-out",
            s(&flown),
            "-o",
            s(&json),
            "-o",
            s(&glb),
            "-o",
            s(&usda),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let a = Animation::read(&json).unwrap();
    let rec = a.path.as_ref().unwrap();
    assert!(rec.widened);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&flown).unwrap()).unwrap();
    assert_eq!(doc["units"], "wingspans");
    let pts: Vec<[f64; 3]> = serde_json::from_value(doc["points"].clone()).unwrap();
    assert_eq!(pts, rec.flown);
    // About a wingspan apart, from the path's first point to its last, and the corner cut: the
    // widened course passes inside the drawn corner at (0, 120).
    // (The last step is what remains of the course: any length up to 1.5.)
    let steps = pts.len() - 1;
    for (k, w) in pts.windows(2).enumerate() {
        let d = ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
        let lo = if k + 1 == steps { 0.0 } else { 0.5 };
        assert!(d > lo && d < 1.5, "step {k} of {steps}: {d}");
    }
    let near = |p: [f64; 3], q: [f64; 3]| (0..3).all(|i| (p[i] - q[i]).abs() < 1e-9);
    assert!(near(pts[0], [0.0, 0.0, 30.0]), "{:?}", pts[0]);
    assert!(near(*pts.last().unwrap(), [120.0, 120.0, 30.0]));
    let corner = pts
        .iter()
        .map(|p| (p[0].powi(2) + (p[1] - 120.0).powi(2)).sqrt())
        .fold(f64::INFINITY, f64::min);
    assert!(corner > 1.0, "{corner}");
    // It reads back as a path.
    let o = bin()
        .args([
            "animate",
            s(&example("barnacle_geese_v.json")),
            "--birds",
            "9",
            "--seconds",
            "4",
            "--path",
            s(&flown),
            "--quiet",
            "-o",
            s(&dir.join("b.json")),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    // The .glb has it as a line strip node, the .usda as a guide curve.
    let bytes = std::fs::read(&glb).unwrap();
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let j: serde_json::Value = serde_json::from_slice(&bytes[20..20 + n]).unwrap();
    let node = j["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["name"] == "flown_path")
        .unwrap();
    let mesh = &j["meshes"][node["mesh"].as_u64().unwrap() as usize];
    assert_eq!(mesh["primitives"][0]["mode"], 3);
    let acc = &j["accessors"][mesh["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize];
    assert_eq!(acc["count"], pts.len());
    let text = std::fs::read_to_string(&usda).unwrap();
    assert!(text.contains("def BasisCurves \"flown_path\""));
    assert!(text.contains(&format!("int[] curveVertexCounts = [{}]", pts.len())));
    // A bad name is refused before any work.
    let o = bin()
        .args([
            "animate",
            s(&example("barnacle_geese_v.json")),
            "--birds",
            "5",
            "--path-out",
            s(&json),
            "-o",
            s(&json),
        ])
        .output()
        .unwrap();
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("--path-out"), "{}", stderr(&o));
}

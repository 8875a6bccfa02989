//! `--size-variation F`: each bird of the .glb and .usda scaled by its own seeded factor, recorded
//! in the metadata; the animation's positions (.json, .csv, the roots' translation keys) unchanged.

mod support;

use std::path::Path;

use serde_json::Value;
use support::glb::split;
use support::{bin, code, data, example_arg, s, scratch, stderr};

fn ok(args: &[&str]) {
    let out = bin().args(args).output().unwrap();
    assert_eq!(code(&out), 0, "{args:?}: {}", stderr(&out));
}

/// Per bird root node: its scale (1 when absent); the scene's recorded list and variation.
fn scales(glb: &Path) -> (Vec<f64>, Vec<f64>, f64) {
    let (j, _) = split(&std::fs::read(glb).unwrap());
    let flock = j["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["name"] == "flock")
        .unwrap();
    let nodes: Vec<f64> = flock["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| &j["nodes"][i.as_u64().unwrap() as usize])
        .filter(|n| n["name"].as_str().unwrap_or("").starts_with("bird_"))
        .map(|n| match n.get("scale") {
            Some(s) => {
                let v: Vec<f64> = s
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                assert!(v[0] == v[1] && v[1] == v[2], "uniform scale: {v:?}");
                v[0]
            }
            None => 1.0,
        })
        .collect();
    let e = &j["scenes"][0]["extras"];
    let recorded = e["bird_scales"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    (nodes, recorded, e["size_variation"].as_f64().unwrap())
}

/// The bytes of every root translation key of the first clip.
fn translations(j: &Value, bin: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let a = &j["animations"][0];
    for c in a["channels"].as_array().unwrap() {
        let node = &j["nodes"][c["target"]["node"].as_u64().unwrap() as usize];
        if c["target"]["path"] == "translation"
            && node["name"].as_str().unwrap().starts_with("bird_")
        {
            let sampler = &a["samplers"][c["sampler"].as_u64().unwrap() as usize];
            let acc = &j["accessors"][sampler["output"].as_u64().unwrap() as usize];
            let view = &j["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
            let o = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let l = view["byteLength"].as_u64().unwrap() as usize;
            out.extend_from_slice(&bin[o..o + l]);
        }
    }
    out
}

#[test]
fn size_variation_scales_each_bird_deterministically_without_moving_it() {
    let dir = scratch("sizes");
    let geese = example_arg("barnacle_geese_v.json");
    let p = |n: &str| dir.join(n);
    let run = |tag: &str, f: Option<&str>| {
        let outs: Vec<String> = ["glb", "usda", "csv", "json"]
            .iter()
            .map(|ext| s(&p(&format!("{tag}.{ext}"))).to_string())
            .collect();
        let mut a = vec![
            "animate",
            &geese,
            "--birds",
            "12",
            "--seconds",
            "2",
            "--seed",
            "5",
            "--quiet",
            "--usd-mode",
            "skel",
        ];
        for o in &outs {
            a.extend(["-o", o.as_str()]);
        }
        if let Some(f) = f {
            a.extend(["--size-variation", f]);
        }
        ok(&a);
    };
    run("a", Some("0.05"));
    run("b", Some("0.05"));
    run("zero", Some("0"));
    run("default", None);
    let read = |n: &str| std::fs::read(p(n)).unwrap();
    for ext in ["glb", "usda", "csv", "json"] {
        assert!(
            read(&format!("a.{ext}")) == read(&format!("b.{ext}")),
            "{ext} not deterministic"
        );
    }
    // Size only: the animation's positions are the same bytes whatever the variation.
    for ext in ["csv", "json"] {
        assert!(
            read(&format!("a.{ext}")) == read(&format!("zero.{ext}")),
            "{ext}"
        );
        assert!(
            read(&format!("a.{ext}")) == read(&format!("default.{ext}")),
            "{ext}"
        );
    }
    let (nodes, recorded, f) = scales(&p("a.glb"));
    assert_eq!(f, 0.05);
    assert_eq!(nodes.len(), 12);
    assert_eq!(recorded.len(), 12);
    for (n, r) in nodes.iter().zip(&recorded) {
        assert!((n - r).abs() < 1e-6, "{n} vs recorded {r}");
        // Within the documented range: 1 ± 3F.
        assert!((0.85..=1.15).contains(n), "{n}");
    }
    let mut distinct = nodes.clone();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    assert_eq!(distinct.len(), 12, "{nodes:?}");
    let mean = nodes.iter().sum::<f64>() / 12.0;
    let sd = (nodes.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 11.0).sqrt();
    assert!(sd > 0.02 && sd < 0.1, "spread {sd} for F = 0.05");
    // The roots' translation keys are the same bytes as without variation.
    let (ja, bin_a) = split(&read("a.glb"));
    let (jz, bin_z) = split(&read("zero.glb"));
    let (ta, tz) = (translations(&ja, &bin_a), translations(&jz, &bin_z));
    assert!(!ta.is_empty() && ta == tz, "root translations changed");
    let (zn, _, zf) = scales(&p("zero.glb"));
    assert!(zn.iter().all(|&v| v == 1.0) && zf == 0.0);
    // The default is the documented 0.04.
    let (dn, _, df) = scales(&p("default.glb"));
    assert_eq!(df, 0.04);
    assert!(dn.iter().any(|&v| v != 1.0));
    // USD: the same scales as xformOp:scale, recorded in customLayerData.
    let usda = String::from_utf8(read("a.usda")).unwrap();
    let usd_scales: Vec<f64> = usda
        .lines()
        .filter_map(|l| l.trim().strip_prefix("float3 xformOp:scale = ("))
        .map(|r| r.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(usd_scales.len(), 12);
    for (u, n) in usd_scales.iter().zip(&nodes) {
        assert!((u - n).abs() < 1e-6, "{u} vs {n}");
    }
    assert!(usda.contains("double[] bird_scales = ["));
    assert!(usda.contains("\"xformOp:translate\", \"xformOp:orient\", \"xformOp:scale\""));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_size_variation_out_of_range_is_refused_naming_the_flag() {
    let dir = scratch("badsize");
    let out = dir.join("out.glb");
    let anim = data("flock_small.json").to_string_lossy().into_owned();
    for bad in ["3", "-0.1", "nan"] {
        let o = bin()
            .args(["render", &anim, "-o", s(&out), "--size-variation", bad])
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            err.contains("--size-variation") && err.contains("0 (every bird the same size) to 0.3"),
            "{err}"
        );
        assert!(!out.exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The numbers of the line `prefix[...]` of `text` (a static array of scalars or tuples).
fn numbers_after(text: &str, prefix: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find_map(|l| l.trim().strip_prefix(prefix))
        .unwrap_or_else(|| panic!("no {prefix}"));
    line.split([',', '(', ')', '[', ']'])
        .filter(|x| !x.trim().is_empty())
        .map(|x| x.trim().parse().unwrap())
        .collect()
}

#[test]
fn the_point_instanced_crowd_scales_its_birds_like_the_rig() {
    let dir = scratch("sizes-crowd");
    let geese = example_arg("barnacle_geese_v.json");
    let p = |n: &str| s(&dir.join(n)).to_string();
    let (glb, usda, json) = (p("c.glb"), p("c.usda"), p("c.json"));
    ok(&[
        "animate",
        &geese,
        "--birds",
        "12",
        "--seconds",
        "2",
        "--seed",
        "5",
        "--quiet",
        "--usd-mode",
        "instancer",
        "--size-variation",
        "0.05",
        "-o",
        &glb,
        "-o",
        &usda,
        "-o",
        &json,
    ]);
    let (nodes, _, _) = scales(Path::new(&glb));
    let text = std::fs::read_to_string(&usda).unwrap();
    // One uniform scale per instance, the glTF birds' own.
    let sc = numbers_after(&text, "float3[] scales = ");
    assert_eq!(sc.len(), 3 * 12);
    for (b, n) in nodes.iter().enumerate() {
        let v = &sc[3 * b..3 * b + 3];
        assert!(
            v.iter().all(|x| (x - n).abs() < 1e-6),
            "bird {b}: {v:?} vs {n}"
        );
    }
    assert!(nodes.iter().any(|&n| n > 1.01) && nodes.iter().any(|&n| n < 0.99));
    let recorded = numbers_after(&text, "double[] bird_scales = ");
    assert_eq!(recorded.len(), 12);
    let pivot = numbers_after(&text, "double size_pivot_m = ")[0];
    assert!(pivot > 0.05 && pivot < 0.2, "{pivot}");
    // Each instance sits (s − 1)·pivot along its bird's vertical from the animation's position:
    // a bigger bird at rest still sits on the ground.
    let anim: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let ws = anim["wingspan_m"].as_f64().unwrap();
    let start = text.find("positions.timeSamples = {").unwrap();
    let lines: Vec<&str> = text[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('}'))
        .collect();
    let frames = anim["frames"].as_array().unwrap();
    assert_eq!(lines.len(), frames.len());
    // Metres about the crowd's translation (the flock's centre at that time).
    let start = text.find("xformOp:translate.timeSamples = {").unwrap();
    let centres: Vec<&str> = text[start..].lines().skip(1).take(frames.len()).collect();
    let mut worst: f64 = 0.0;
    for (k, line) in lines.iter().enumerate() {
        let c = numbers_after(centres[k], &format!("{k}: "));
        let pos: Vec<f64> = numbers_after(line, &format!("{k}: "))
            .iter()
            .enumerate()
            .map(|(i, v)| c[i % 3] + v)
            .collect();
        let f = &frames[k];
        let at = |key: &str, b: usize| f[key][b].as_f64().unwrap();
        for (b, s) in nodes.iter().enumerate() {
            let want = [at("x", b) * ws, at("z", b) * ws, -at("y", b) * ws];
            let d: Vec<f64> = (0..3).map(|i| pos[3 * b + i] - want[i]).collect();
            let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            worst = worst.max((len - (s - 1.0).abs() * pivot).abs());
            if k == 0 {
                // Sitting, level: straight up or down.
                assert!((d[1] - (s - 1.0) * pivot).abs() < 1e-3, "bird {b}: {d:?}");
            }
        }
    }
    assert!(worst < 1e-3, "{worst} m");
    let _ = std::fs::remove_dir_all(&dir);
}

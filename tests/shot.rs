//! The shot's frame conventions: resampling to another frame rate (`render --fps`), sub-frame
//! samples for motion blur (`--subframes`), the first frame's number (`--start-frame`), the
//! whole shot's length (`--shot-seconds`) and a loop's range, checked on the files written.

mod support;

use std::f64::consts::TAU;
use std::path::Path;

use formation::animation::resample::resample;
use formation::export::{write_outputs, RenderOptions};
use formation::pipeline::{Config, Pipeline};
use formation::progress::Silent;
use formation::{Animation, Error};
use serde_json::Value;
use support::{bin, code, example, s, scratch, stderr};

/// The geese example: 9 birds, a take-off and `seconds` of steady flight at `fps`.
fn flight(fps: f64, seconds: f64) -> Animation {
    let mut c = Config {
        seed: 3,
        seconds: Some(seconds),
        ..Config::default()
    };
    c.steady.birds = 9;
    c.steady.fps = fps;
    Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap()
        .0
}

/// A steady loop of 9 birds, `seconds` long at `fps`.
fn looped(fps: f64, seconds: f64) -> Animation {
    let mut c = Config {
        seed: 3,
        seconds: Some(seconds),
        initiation: false,
        ..Config::default()
    };
    c.steady.birds = 9;
    c.steady.fps = fps;
    c.steady.looped = true;
    Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap()
        .0
}

/// The JSON chunk of a `.glb`.
fn glb_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + n]).unwrap()
}

/// Every float of accessor `i` of a `.glb` (float accessors only).
fn glb_floats(path: &Path, json: &Value, i: usize) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = &bytes[28 + n..];
    let a = &json["accessors"][i];
    assert_eq!(a["componentType"], 5126);
    let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let off = v["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = a["count"].as_u64().unwrap() as usize;
    let width = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("{t}"),
    };
    bin[off..off + 4 * width * count]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

/// The key times of the first sampler of the first clip, seconds.
fn first_key_times(path: &Path) -> Vec<f32> {
    let j = glb_json(path);
    let input = j["animations"][0]["samplers"][0]["input"].as_u64().unwrap() as usize;
    glb_floats(path, &j, input)
}

/// The time codes of the first `xformOp:translate.timeSamples` of a `.usda`.
fn usd_time_codes(text: &str) -> Vec<f64> {
    let start = text.find("xformOp:translate.timeSamples = {").unwrap();
    text[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('}'))
        .map(|l| l.trim().split(':').next().unwrap().parse::<f64>().unwrap())
        .collect()
}

fn usd_header(text: &str, key: &str) -> f64 {
    let l = text
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{key} = ")))
        .unwrap();
    l.split('=').nth(1).unwrap().trim().parse().unwrap()
}

/// Largest position difference (wingspans) between two frames.
fn position_gap(a: &formation::animation::Frame, b: &formation::animation::Frame) -> f64 {
    let mut w: f64 = 0.0;
    for (p, q) in [(&a.x, &b.x), (&a.y, &b.y), (&a.z, &b.z)] {
        for (p, q) in p.iter().zip(q) {
            w = w.max((p - q).abs());
        }
    }
    w
}

fn phase_gap(a: f64, b: f64) -> f64 {
    ((a - b + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI).abs()
}

#[test]
fn resampling_to_24_fps_keeps_the_motion_in_seconds() {
    let a = flight(30.0, 4.0);
    let b = resample(&a, 24.0).unwrap();
    assert_eq!(b.fps, 24.0);
    let span = a.frames.last().unwrap().t;
    assert_eq!(b.frames.len(), (span * 24.0 + 1e-6).floor() as usize + 1);
    // Common times (every 1/6 s): the same frames, bit for bit.
    for k in 0..b.frames.len() / 4 {
        let (fa, fb) = (&a.frames[5 * k], &b.frames[4 * k]);
        assert!((fa.t - fb.t).abs() < 1e-12);
        assert!(position_gap(fa, fb) <= 1e-4, "frame {k}");
        assert_eq!(fa.wing_phase, fb.wing_phase);
        assert_eq!(fa.heading, fb.heading);
    }
    // Stages start at the same time to within a frame of the new rate.
    for (sa, sb) in a.stages.iter().zip(&b.stages) {
        assert_eq!(sa.name, sb.name);
        let (ta, tb) = (a.frames[sa.start].t, b.frames[sb.start].t);
        assert!(tb >= ta - 1e-9 && tb - ta < 1.0 / 24.0, "{ta} {tb}");
    }
    // Phase-continuous wingbeats: every sample's phase lies on the forward arc between the
    // phases of the frames around it.
    for fb in &b.frames {
        let k = a.frames.iter().rposition(|f| f.t <= fb.t + 1e-12).unwrap();
        let (Some(p0), Some(pb)) = (&a.frames[k].wing_phase, &fb.wing_phase) else {
            panic!("phases")
        };
        let Some(next) = a.frames.get(k + 1) else {
            continue;
        };
        let p1 = next.wing_phase.as_ref().unwrap();
        for i in 0..a.birds {
            let arc = (p1[i] - p0[i]).rem_euclid(TAU);
            let got = (pb[i] - p0[i]).rem_euclid(TAU);
            assert!(
                got <= arc + 1e-9 || (TAU - got) < 1e-9,
                "bird {i} at {}",
                fb.t
            );
        }
    }
    // Nothing below the ground where the frames are above it (a monotone interpolant).
    let lowest = |an: &Animation| {
        an.frames
            .iter()
            .flat_map(|f| f.z.iter().copied())
            .fold(f64::INFINITY, f64::min)
    };
    assert!(lowest(&b) >= lowest(&a) - 1e-12);
}

#[test]
fn subframe_samples_follow_the_motion_between_frames() {
    // The same flight simulated at 120 fps is the truth between the 30-fps frames: take every
    // fourth of its frames, sample them at 120 fps again and compare.
    let truth = flight(120.0, 3.0);
    let mut coarse = truth.clone();
    coarse.fps = 30.0;
    coarse.frames = truth.frames.iter().step_by(4).cloned().collect();
    for st in &mut coarse.stages {
        st.start = st.start.div_ceil(4);
        st.end = st.end.div_ceil(4);
    }
    coarse.key_shapes.clear();
    let fine = resample(&coarse, 120.0).unwrap();
    let steady = truth.stage("steady").unwrap().start;
    let (mut take_pos, mut take_phase, mut fly_pos, mut fly_phase) = (0f64, 0f64, 0f64, 0f64);
    for (k, (f, g)) in truth.frames.iter().zip(&fine.frames).enumerate() {
        assert!((f.t - g.t).abs() < 1e-9);
        let pos = position_gap(f, g);
        let phase = f
            .wing_phase
            .as_ref()
            .unwrap()
            .iter()
            .zip(g.wing_phase.as_ref().unwrap())
            .map(|(a, b)| phase_gap(*a, *b))
            .fold(0.0, f64::max);
        if k < steady {
            take_pos = take_pos.max(pos);
            take_phase = take_phase.max(phase);
        } else {
            fly_pos = fly_pos.max(pos);
            fly_phase = fly_phase.max(phase);
        }
    }
    // Measured: steady 1.0e-4 wingspans and 0.037 rad; take-off 4.2e-3 and 0.17 rad (the run's
    // first wingbeats).
    assert!(fly_pos < 1e-3 && fly_phase < 0.06, "{fly_pos} {fly_phase}");
    assert!(
        take_pos < 1e-2 && take_phase < 0.3,
        "{take_pos} {take_phase}"
    );
}

#[test]
fn subframes_write_k_samples_a_frame_and_double_nothing() {
    let dir = scratch("shot-subframes");
    let a = flight(30.0, 2.0);
    let n = a.frames.len();
    let opts = RenderOptions {
        subframes: 4,
        start_frame: Some(1001),
        ..RenderOptions::default()
    };
    let (glb, usda) = (dir.join("f.glb"), dir.join("f.usda"));
    write_outputs(&a, &[glb.clone(), usda.clone()], &opts, &Silent).unwrap();
    let times = first_key_times(&glb);
    assert_eq!(times.len(), 4 * (n - 1) + 1);
    assert!(times.windows(2).all(|w| w[1] > w[0]), "keys doubled");
    assert!((times[0] as f64 * 30.0 - 1001.0).abs() < 1e-3);
    assert!((*times.last().unwrap() as f64 * 30.0 - (1001 + n - 1) as f64).abs() < 2e-3);
    let j = glb_json(&glb);
    assert_eq!(j["scenes"][0]["extras"]["frame_start"], 1001);
    assert_eq!(j["scenes"][0]["extras"]["frame_end"], 1001 + n as u64 - 1);
    assert_eq!(j["scenes"][0]["extras"]["fps"], 30.0);
    assert_eq!(j["scenes"][0]["extras"]["subframes"], 4);
    let text = std::fs::read_to_string(&usda).unwrap();
    let codes = usd_time_codes(&text);
    assert_eq!(codes.len(), 4 * (n - 1) + 1);
    for (i, c) in codes.iter().enumerate() {
        assert!((c - (1001.0 + i as f64 / 4.0)).abs() < 1e-9, "{c}");
    }
    assert_eq!(usd_header(&text, "startTimeCode"), 1001.0);
    assert_eq!(usd_header(&text, "endTimeCode"), (1001 + n - 1) as f64);
    assert_eq!(usd_header(&text, "timeCodesPerSecond"), 30.0);
    // At whole frames the samples are the frames: the .glb's translations at every fourth key
    // equal those written without sub-frames.
    let plain = dir.join("p.glb");
    write_outputs(
        &a,
        std::slice::from_ref(&plain),
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap();
    let jp = glb_json(&plain);
    let out = |j: &Value, path: &Path| {
        let s = j["animations"][0]["samplers"][0]["output"]
            .as_u64()
            .unwrap() as usize;
        glb_floats(path, j, s)
    };
    let (fine, coarse) = (out(&j, &glb), out(&jp, &plain));
    assert_eq!(fine.len(), 3 * (4 * (n - 1) + 1));
    for k in 0..n {
        for c in 0..3 {
            assert_eq!(fine[3 * 4 * k + c], coarse[3 * k + c], "frame {k}");
        }
    }
}

#[test]
fn start_frame_numbers_every_output_and_travels_with_the_file() {
    let dir = scratch("shot-start");
    let a = flight(30.0, 1.0);
    let n = a.frames.len();
    let opts = RenderOptions {
        start_frame: Some(1001),
        width: 64,
        height: 36,
        ..RenderOptions::default()
    };
    let outs = ["f.json", "f.csv", "f.glb", "f.usda", "frames/"].map(|f| dir.join(f));
    write_outputs(&a, &outs, &opts, &Silent).unwrap();
    let csv = std::fs::read_to_string(&outs[1]).unwrap();
    let frames: Vec<u64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(frames[0], 1001);
    assert_eq!(*frames.last().unwrap(), 1001 + n as u64 - 1);
    let times = first_key_times(&outs[2]);
    assert!((times[0] as f64 * 30.0 - 1001.0).abs() < 1e-3);
    let text = std::fs::read_to_string(&outs[3]).unwrap();
    assert_eq!(usd_time_codes(&text)[0], 1001.0);
    assert_eq!(usd_header(&text, "startTimeCode"), 1001.0);
    assert!(outs[4].join("frame_01001.png").is_file());
    assert!(!outs[4].join("frame_00000.png").exists());
    // The animation file records it; a render of that file keeps it without the flag.
    let back = Animation::read(&outs[0]).unwrap();
    assert_eq!(back.start_frame, 1001);
    let again = dir.join("g.csv");
    write_outputs(
        &back,
        std::slice::from_ref(&again),
        &RenderOptions::default(),
        &Silent,
    )
    .unwrap();
    let first = std::fs::read_to_string(&again).unwrap();
    assert!(first.lines().nth(1).unwrap().starts_with("1001,"));
}

#[test]
fn shot_seconds_is_the_whole_shot_to_the_frame() {
    for (fps, shot) in [(30.0, 15.0), (24.0, 12.5), (25.0, 13.02)] {
        let mut c = Config {
            seed: 3,
            shot_seconds: Some(shot),
            ..Config::default()
        };
        // The fast climb, a take-off of about 10 s (the shot's length is what is tested).
        c.initiate.climb_rate = Some(2.5);
        c.steady.birds = 9;
        c.steady.fps = fps;
        let a = Pipeline::from_path(example("barnacle_geese_v.json"))
            .run(&c)
            .unwrap()
            .0;
        assert_eq!(
            a.frames.len(),
            (shot * fps).round() as usize,
            "{shot} s at {fps}"
        );
        let steady = a.stage("steady").unwrap();
        assert_eq!(steady.end, a.frames.len());
        assert!(steady.start > 0 && steady.start < steady.end);
        assert!(a.key_shapes.iter().all(|k| k.frame < a.frames.len()));
    }
    // The take-off alone is longer than the shot: refused, naming the option.
    let mut c = Config {
        seed: 3,
        shot_seconds: Some(4.0),
        ..Config::default()
    };
    c.steady.birds = 9;
    let e = Pipeline::from_path(example("barnacle_geese_v.json"))
        .run(&c)
        .unwrap_err();
    assert!(
        matches!(&e, Error::Parameter { name, .. } if name == "shot_seconds"),
        "{e}"
    );
    // A loop has its own length.
    c.initiation = false;
    c.steady.looped = true;
    assert!(c.validate().is_err());
}

#[test]
fn shot_flags_on_the_command_line() {
    let dir = scratch("shot-cli");
    let geese = example("barnacle_geese_v.json");
    let out = dir.join("a.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "animate",
            s(&geese),
            "--birds",
            "9",
            "--climb-rate",
            "2.5",
            "--quiet",
            "-o",
            s(&out),
        ];
        args.extend_from_slice(extra);
        bin().args(&args).output().unwrap()
    };
    for (args, needle) in [
        (
            vec!["--shot-seconds", "2", "--takeoff", "9"],
            "--shot-seconds",
        ),
        (vec!["--start-frame", "-5"], "--start-frame"),
        (vec!["--subframes", "0"], "--subframes"),
    ] {
        let o = run(&args);
        assert_eq!(code(&o), 2, "{args:?}");
        let err = stderr(&o);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!out.exists());
    }
    let o = run(&["--shot-seconds", "14", "--fps", "24"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let a = Animation::read(&out).unwrap();
    assert_eq!(a.frames.len(), 14 * 24);
    // render --fps: the file at another rate; a loop needs a rate that fits its cycle.
    let r = dir.join("r.json");
    let o = bin()
        .args(["render", s(&out), "--fps", "30", "-o", s(&r), "--quiet"])
        .output()
        .unwrap();
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let b = Animation::read(&r).unwrap();
    assert_eq!(b.fps, 30.0);
    assert_eq!(
        b.frames.len(),
        ((14 * 24 - 1) as f64 / 24.0 * 30.0).floor() as usize + 1
    );
}

#[test]
fn a_loop_range_never_repeats_a_frame() {
    let dir = scratch("shot-loop");
    let a = looped(30.0, 4.0);
    let n = a.frames.len();
    assert_eq!(n, 120);
    let (glb, usda, csv) = (dir.join("l.glb"), dir.join("l.usda"), dir.join("l.csv"));
    let opts = RenderOptions {
        start_frame: Some(1001),
        ..RenderOptions::default()
    };
    write_outputs(
        &a,
        &[glb.clone(), usda.clone(), csv.clone()],
        &opts,
        &Silent,
    )
    .unwrap();
    let j = glb_json(&glb);
    // The range is the loop's 120 frames; the closing key (the first again) lies past it.
    assert_eq!(j["scenes"][0]["extras"]["frame_start"], 1001);
    assert_eq!(j["scenes"][0]["extras"]["frame_end"], 1001 + 119);
    assert_eq!(first_key_times(&glb).len(), n + 1);
    let text = std::fs::read_to_string(&usda).unwrap();
    assert_eq!(usd_header(&text, "endTimeCode"), 1120.0);
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    assert_eq!(rows, n * a.birds);
    // With sub-frames the closing sample is the last, still past the range.
    let sub = dir.join("s.glb");
    let opts = RenderOptions {
        subframes: 2,
        ..RenderOptions::default()
    };
    write_outputs(&a, std::slice::from_ref(&sub), &opts, &Silent).unwrap();
    assert_eq!(first_key_times(&sub).len(), 2 * n + 1);
    assert_eq!(glb_json(&sub)["scenes"][0]["extras"]["frame_end"], 119);
    // Resampled, a loop stays a loop when its cycle is a whole number of frames.
    let b = resample(&a, 24.0).unwrap();
    assert!(b.looped);
    assert_eq!(b.frames.len(), 96);
    let e = resample(&a, 25.3).unwrap_err();
    assert!(e.to_string().contains("whole number of frames"), "{e}");
}

//! Library-level tests of the outputs: every output opens in an independent reader, the camera
//! keeps every bird inside the picture, and equal inputs give byte-identical files.

use std::path::{Path, PathBuf};
use std::process::Command;

use formation::export::synthetic::{synthetic_flock, SyntheticParams};
use formation::export::{plan_outputs, write_outputs, Film, RenderOptions};
use formation::progress::Silent;
use formation::Animation;

mod support;

use support::scratch;

/// A short synthetic flock: 14 birds converging into a V, then cruising.
fn flock(seconds: f64, fps: f64) -> Animation {
    let p = SyntheticParams {
        seconds,
        fps,
        initiation_s: seconds / 3.0,
        ..SyntheticParams::default()
    };
    synthetic_flock(&mut formation::rng::seeded(7), &p)
}

fn small() -> RenderOptions {
    RenderOptions {
        width: 240,
        height: 136,
        ..RenderOptions::default()
    }
}

#[test]
fn every_output_opens_in_an_independent_reader() {
    let anim = flock(3.0, 20.0);
    let d = scratch("all");
    let outs: Vec<PathBuf> = ["a.gif", "frames/", "a.glb", "a.csv", "a.json"]
        .iter()
        .map(|n| d.join(n))
        .collect();
    write_outputs(&anim, &outs, &small(), &Silent).unwrap();

    // GIF: frame count at 25 fps and size, through image's decoder.
    let f = std::fs::File::open(d.join("a.gif")).unwrap();
    let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(f)).unwrap();
    let frames = image::AnimationDecoder::into_frames(dec)
        .collect_frames()
        .unwrap();
    let expected = formation::export::sample::output_times(&anim, 25.0).len();
    assert_eq!(frames.len(), expected);
    assert_eq!(
        expected,
        1 + ((anim.frames.last().unwrap().t) * 25.0).floor() as usize
    );
    for fr in &frames {
        assert_eq!(fr.buffer().dimensions(), (240, 136));
        assert_eq!(fr.delay().numer_denom_ms(), (40, 1));
    }
    // The GIF loops forever: NETSCAPE2.0 extension with loop count 0.
    let bytes = std::fs::read(d.join("a.gif")).unwrap();
    let pos = bytes
        .windows(11)
        .position(|w| w == b"NETSCAPE2.0")
        .expect("loop extension");
    assert_eq!(&bytes[pos + 11..pos + 15], &[3, 1, 0, 0]);

    // PNG frames: one per animation frame, each decodes at the right size.
    let mut names: Vec<String> = std::fs::read_dir(d.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), anim.frames.len());
    assert_eq!(names[0], "frame_00000.png");
    let img = image::open(d.join("frames").join(&names[7])).unwrap();
    assert_eq!((img.width(), img.height()), (240, 136));
    assert!(matches!(img, image::DynamicImage::ImageRgb8(_)));

    // CSV: SPEC columns, one row per frame and bird, e/xi empty during initiation only.
    let text = std::fs::read_to_string(d.join("a.csv")).unwrap();
    let mut rd = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(
        &header[..10],
        &["frame", "t", "bird", "x", "y", "z", "heading", "speed", "e", "xi"]
    );
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), anim.frames.len() * anim.birds);
    let steady = anim.stage("steady").unwrap().start;
    assert_eq!(&rows[0][9], "");
    let r = &rows[steady * anim.birds + 3];
    assert_eq!(r[0].parse::<usize>().unwrap(), steady);
    assert_eq!(r[2].parse::<usize>().unwrap(), 3);
    // Each number exactly the value at the animation file's precision (10⁻⁵ wingspans for
    // positions, 10⁻⁶ for savings).
    use formation::animation::precision::{to, POSITION, SAVING};
    assert_eq!(
        r[3].parse::<f64>().unwrap(),
        to(anim.frames[steady].x[3], POSITION)
    );
    assert_eq!(
        r[9].parse::<f64>().unwrap(),
        to(anim.frames[steady].xi.as_ref().unwrap()[3], SAVING)
    );

    // JSON round-trips and validates against SPEC §4.4, at the file's precision: positions to
    // 10⁻⁵ wingspans, headings to 10⁻⁶ radians (this animation was not rounded by a run).
    let back = Animation::read(&d.join("a.json")).unwrap();
    assert_eq!(
        (back.birds, back.frames.len()),
        (anim.birds, anim.frames.len())
    );
    assert_eq!(
        (&back.stages, back.key_shapes.len()),
        (&anim.stages, anim.key_shapes.len())
    );
    for (a, b) in anim.frames.iter().zip(&back.frames) {
        for (u, v, step) in [
            (&a.x, &b.x, 1e-5),
            (&a.y, &b.y, 1e-5),
            (&a.heading, &b.heading, 1e-6),
        ] {
            assert!(u
                .iter()
                .zip(v)
                .all(|(p, q)| (p - q).abs() <= 0.5 * step * (1.0 + 1e-9)));
        }
        assert_eq!(a.xi.is_some(), b.xi.is_some());
    }

    // GLB: a glTF container whose JSON chunk parses with gltf-json and references the binary.
    let glb = std::fs::read(d.join("a.glb")).unwrap();
    assert_eq!(&glb[0..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
        glb.len()
    );
    let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    assert_eq!(jlen % 4, 0);
    let root = gltf_json::Root::from_slice(&glb[20..20 + jlen]).unwrap();
    // One clip over every stage (the default); per bird: root translation and rotation, body
    // (bank), tail and the four wing joints (the goose's legs are not skinned: no channels).
    // Nodes: per bird a root, nine joints and a skinned mesh node; plus `flock`.
    assert_eq!(root.animations.len(), 1);
    for a in &root.animations {
        assert_eq!(a.channels.len(), anim.birds * 8);
    }
    assert_eq!(root.nodes.len(), anim.birds * 11 + 1);
    assert_eq!(root.skins.len(), anim.birds);
    let bin_len = u32::from_le_bytes(glb[20 + jlen..24 + jlen].try_into().unwrap()) as u64;
    assert_eq!(root.buffers[0].byte_length.0, bin_len);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn equal_inputs_give_byte_identical_outputs_whatever_the_thread_count() {
    let d = scratch("det");
    let mut names = vec!["a.gif", "a.glb", "a.csv", "a.json"];
    // Video too when ffmpeg is there (CI installs it): its encoders' output depends on their
    // thread count, which must therefore not follow the machine's cores.
    let ffmpeg = Command::new(formation::export::pictures::ffmpeg_program())
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if ffmpeg {
        names.extend(["a.mp4", "a.webm"]);
    } else {
        eprintln!("video skipped: no ffmpeg (apt-get install ffmpeg)");
    }
    for (run, threads) in [(0, 1), (1, 3)] {
        let anim = flock(2.0, 20.0);
        let outs: Vec<PathBuf> = names.iter().map(|n| d.join(format!("{run}{n}"))).collect();
        let opts = RenderOptions { threads, ..small() };
        write_outputs(&anim, &outs, &opts, &Silent).unwrap();
    }
    for n in names {
        let a = std::fs::read(d.join(format!("0{n}"))).unwrap();
        let b = std::fs::read(d.join(format!("1{n}"))).unwrap();
        assert!(a == b, "{n} differs between runs");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn camera_keeps_every_bird_inside_the_picture() {
    let anim = flock(8.0, 30.0);
    for (w, h) in [(960, 540), (200, 400), (300, 300)] {
        // min_bird_px 0: the whole flock is always framed (the default zooms in on the lead
        // birds of a flock too large for 12 px birds; tested below).
        let opts = RenderOptions {
            width: w as u32,
            height: h as u32,
            min_bird_px: 0.0,
            ..RenderOptions::default()
        };
        let film = Film::with_options(&anim, 25.0, &opts);
        let margin = 0.07 * w.min(h) as f64;
        for (k, view) in film.views.iter().enumerate() {
            let states = film.states(k);
            for (i, b) in states.iter().enumerate() {
                let (px, py) = view.to_pixel(b.x, b.y, w, h);
                let r = formation::export::silhouette::radius(film.species) * view.scale();
                let inside = px - r >= margin - 1e-6
                    && px + r <= w as f64 - margin + 1e-6
                    && py - r >= margin - 1e-6
                    && py + r <= h as f64 - margin + 1e-6;
                assert!(
                    inside,
                    "{w}x{h} frame {k} bird {i} at ({px:.1}, {py:.1}) r {r:.1}"
                );
            }
        }
        // Smooth: the zoom never changes by more than 3 % between frames.
        for v in film.views.windows(2) {
            assert!((v[1].scale() / v[0].scale() - 1.0).abs() < 0.03);
        }
    }
}

#[test]
fn the_drawn_birds_are_inside_the_picture_and_dark_against_the_sky() {
    // Every frame: the darkest pixels (birds) never touch the border strip.
    let anim = flock(3.0, 20.0);
    let film = Film::new(&anim, 10.0, 320, 180);
    let mut canvas = formation::export::raster::Canvas::new(320, 180);
    let mut mask = formation::export::raster::Mask::new();
    for k in 0..film.len() {
        film.draw(k, &mut canvas, &mut mask, false);
        let mut dark = 0;
        for y in 0..180 {
            for x in 0..320 {
                let p = canvas.pixel(x, y);
                if p[0] < 90 && p[2] < 110 {
                    dark += 1;
                    assert!(
                        (5..315).contains(&x) && (5..175).contains(&y),
                        "frame {k}: bird pixel at ({x},{y})"
                    );
                }
            }
        }
        assert!(dark > 14 * 10, "frame {k}: only {dark} bird pixels");
    }
}

#[test]
fn bad_outputs_are_rejected_before_any_work() {
    let d = scratch("bad");
    let anim = flock(1.0, 10.0);
    let good = d.join("ok.csv");
    for bad in [
        d.join("a.txt"),
        d.join("missing/a.gif"),
        d.join("ok.csv"), // duplicate
    ] {
        let e = write_outputs(&anim, &[good.clone(), bad.clone()], &small(), &Silent).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
        assert!(
            !good.exists(),
            "nothing written when {} is bad",
            bad.display()
        );
    }
    // A directory holding other files is never replaced.
    std::fs::create_dir_all(d.join("keep")).unwrap();
    std::fs::write(d.join("keep/notes.txt"), "mine").unwrap();
    let e = plan_outputs(&[d.join("keep/")]).unwrap_err();
    assert!(e.to_string().contains("notes.txt"), "{e}");
    for opts in [
        RenderOptions {
            width: 0,
            height: 0,
            ..small()
        },
        RenderOptions {
            width: 100_000,
            ..small()
        },
        RenderOptions {
            fps: Some(f64::NAN),
            ..small()
        },
        RenderOptions {
            fps: Some(0.0),
            ..small()
        },
        RenderOptions {
            fps: Some(60.0),
            ..small()
        }, // too fast for a GIF
        RenderOptions {
            wingspan_m: Some(-1.0),
            ..small()
        },
    ] {
        let out = d.join("x.gif");
        let e = write_outputs(&anim, std::slice::from_ref(&out), &opts, &Silent).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(!out.exists());
    }
    // No temporaries left behind by the probes.
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "{left:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Regenerates `tests/data/flock_small.json` (run with `--ignored` after changing the generator).
#[test]
#[ignore]
fn regenerate_fixture() {
    let p = SyntheticParams {
        birds: 5,
        seconds: 2.5,
        fps: 20.0,
        initiation_s: 0.8,
        ..SyntheticParams::default()
    };
    let anim = synthetic_flock(&mut formation::rng::seeded(1), &p);
    let path = support::data("flock_small.json");
    formation::io::write_json_atomic(&path, &anim).unwrap();
}

/// Writes the benchmark's 14-bird, 20 s, 30 fps synthetic flock to `$FORMATION_DEMO_OUT` (for
/// looking at renders by hand: `formation render $FORMATION_DEMO_OUT -o flock.gif`).
#[test]
#[ignore]
fn write_demo_animation() {
    let Ok(path) = std::env::var("FORMATION_DEMO_OUT") else {
        return;
    };
    let anim = synthetic_flock(&mut formation::rng::seeded(0), &SyntheticParams::default());
    formation::io::write_json_atomic(Path::new(&path), &anim).unwrap();
}

/// Decodes frame `$FORMATION_GIF_FRAME` of `$FORMATION_GIF` into `$FORMATION_GIF.png`, to look
/// at what the fixed palette makes of a picture.
#[test]
#[ignore]
fn dump_gif_frame() {
    let (Ok(path), Ok(k)) = (
        std::env::var("FORMATION_GIF"),
        std::env::var("FORMATION_GIF_FRAME"),
    ) else {
        return;
    };
    let f = std::fs::File::open(&path).unwrap();
    let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(f)).unwrap();
    let k: usize = k.parse().unwrap();
    let frame = image::AnimationDecoder::into_frames(dec)
        .nth(k)
        .unwrap()
        .unwrap();
    frame.into_buffer().save(format!("{path}.png")).unwrap();
}

#[test]
fn gif_frames_decode_to_the_drawn_pictures_within_the_tolerance() {
    // Frames after the first store only pixels that changed by more than the tolerance; decoding
    // must rebuild every picture: each pixel is either the palette colour of the drawn picture
    // or within the tolerance of its true colour. With tolerance 0 it is the former or exactly
    // its true colour (a palette colour shown there that the true colour has come to equal: the
    // GIF's sky scrolls by whole pixels, so a colour can step onto one).
    let anim = flock(2.0, 20.0);
    for tol in [0.0, 10.0] {
        let d = scratch(&format!("exact{tol}"));
        let gif = d.join("a.gif");
        let opts = RenderOptions {
            gif_tolerance: tol,
            ..small()
        };
        write_outputs(&anim, std::slice::from_ref(&gif), &opts, &Silent).unwrap();
        let dec = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(
            std::fs::File::open(&gif).unwrap(),
        ))
        .unwrap();
        let frames = image::AnimationDecoder::into_frames(dec)
            .collect_frames()
            .unwrap();
        let film = Film::with_options(&anim, 25.0, &opts);
        assert_eq!(frames.len(), film.len());
        let palette = film.palette();
        let mut lookup = formation::export::palette::Lookup::new(&palette);
        let mut canvas = formation::export::raster::Canvas::new(240, 136);
        let mut mask = formation::export::raster::Mask::new();
        let mut idx = Vec::new();
        let mut lagging = 0usize;
        for k in [0, 1, 2, 17, film.len() - 1] {
            film.draw(k, &mut canvas, &mut mask, true);
            // Each pixel's own index: the sky dithered at its place on the screen, the plumage
            // (held exactly by the palette) not.
            let plumage = formation::export::silhouette::plumage(film.species);
            let plain = [plumage.body, plumage.arm, plumage.hand, plumage.head];
            idx.clear();
            for (i, p) in canvas.rgba.chunks_exact(4).enumerate() {
                let rgb = [p[0], p[1], p[2]];
                idx.push(if plain.contains(&rgb) {
                    lookup.index(rgb)
                } else {
                    lookup.index_dithered(rgb, i % canvas.width, i / canvas.width)
                });
            }
            let g = frames[k].buffer().as_raw();
            for (i, &p) in idx.iter().enumerate() {
                let want = palette.colours[p as usize];
                let got = &g[i * 4..i * 4 + 3];
                if got == want {
                    continue;
                }
                let truth = &canvas.rgba[i * 4..i * 4 + 3];
                let err = (0..3)
                    .map(|c| (got[c] as i32 - truth[c] as i32).abs())
                    .max()
                    .unwrap();
                assert!(
                    err <= tol as i32,
                    "tolerance {tol} frame {k} pixel {i}: {got:?} vs drawn {truth:?}"
                );
                lagging += (err > 0) as usize;
            }
        }
        if tol == 0.0 {
            assert_eq!(lagging, 0);
        }
        std::fs::remove_dir_all(&d).unwrap();
    }
}

#[test]
fn glb_follows_the_rules_the_khronos_validator_checks() {
    // CI runs the real validator (.ci/validate-gltf.js); this catches regressions in cargo test.
    let anim = flock(2.0, 20.0);
    let glb = formation::export::gltf::glb_bytes(&anim, 1.5).unwrap();
    let jlen = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let root = gltf_json::Root::from_slice(&glb[20..20 + jlen]).unwrap();
    let bin = &glb[28 + jlen..];
    assert_eq!(bin.len() % 4, 0);
    for v in &root.buffer_views {
        assert_eq!(v.byte_offset.map_or(0, |o| o.0) % 4, 0);
        assert!(v.byte_offset.map_or(0, |o| o.0) + v.byte_length.0 <= bin.len() as u64);
    }
    let floats = |a: &gltf_json::Accessor| -> Vec<f32> {
        let v = &root.buffer_views[a.buffer_view.unwrap().value()];
        let o = v.byte_offset.map_or(0, |o| o.0) as usize;
        bin[o..o + v.byte_length.0 as usize]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect()
    };
    for m in &root.meshes {
        for p in &m.primitives {
            for (sem, acc) in &p.attributes {
                let a = &root.accessors[acc.value()];
                if matches!(
                    sem,
                    gltf_json::validation::Checked::Valid(gltf_json::mesh::Semantic::Positions)
                ) {
                    assert!(a.min.is_some() && a.max.is_some(), "POSITION needs min/max");
                }
                if matches!(
                    sem,
                    gltf_json::validation::Checked::Valid(gltf_json::mesh::Semantic::Normals)
                ) {
                    for n in floats(a).chunks_exact(3) {
                        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                        assert!((l - 1.0).abs() < 1e-4);
                    }
                }
            }
        }
    }
    let anim_json = &root.animations[0];
    for s in &anim_json.samplers {
        let input = &root.accessors[s.input.value()];
        assert!(
            input.min.is_some() && input.max.is_some(),
            "sampler input needs min/max"
        );
        let t = floats(input);
        assert!(t.windows(2).all(|w| w[1] > w[0]), "times strictly increase");
        let out = &root.accessors[s.output.value()];
        if out.type_ == gltf_json::validation::Checked::Valid(gltf_json::accessor::Type::Vec4) {
            let q = floats(out);
            for (k, e) in q.chunks_exact(4).enumerate() {
                let l = (e.iter().map(|v| v * v).sum::<f32>()).sqrt();
                assert!((l - 1.0).abs() < 1e-5, "unit quaternions");
                if k > 0 {
                    let p = &q[(k - 1) * 4..k * 4];
                    let dot: f32 = p.iter().zip(e).map(|(a, b)| a * b).sum();
                    assert!(dot >= 0.0, "consecutive keys in one hemisphere");
                }
            }
        }
    }
    // Positions in metres on glTF's axes: a bird flying north moves along −Z.
    let first = &root.accessors[anim_json.samplers[0].output.value()];
    let tr = floats(first);
    let n = tr.len() / 3;
    assert!(tr[3 * (n - 1) + 2] < tr[2] - 10.0, "north is −Z");
    let y0 = anim.frames[0].y[0] as f32 * 1.5;
    assert!((tr[2] + y0).abs() < 1e-3);
}

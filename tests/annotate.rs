//! `formation annotate`: the review page of `track` for annotations made elsewhere. The birds
//! `track` finds in `tests/data/track_frames/` are written as a long CSV (y down, matched to the
//! images by frame index) and as a DLTdv CSV (y up from the bottom edge); each page embeds the
//! three frames and holds the same birds at the same pixels (y down), with confidence 1; the
//! page's "Save" name comes from the annotations. Bad input exits 2 with one line.

mod support;

use serde_json::Value;
use support::{data, run_quiet, s, scratch};

/// The JSON the page embeds (its `<script type="application/json" id="data">`).
fn page_data(html: &str) -> Value {
    let start = html.find(r#"id="data">"#).unwrap() + r#"id="data">"#.len();
    let end = start + html[start..].find("</script>").unwrap();
    serde_json::from_str(&html[start..end].replace("<\\/", "</")).unwrap()
}

#[test]
fn annotations_from_elsewhere_get_the_review_page() {
    let dir = scratch("annotate");
    let frames = data("track_frames");
    let tracked = dir.join("a.json");
    let (code, err) = run_quiet(&["track", s(&frames), "-o", s(&tracked)]);
    assert_eq!(code, 0, "{err}");
    let t: Value = serde_json::from_slice(&std::fs::read(&tracked).unwrap()).unwrap();
    let height = t["image_size"][1].as_f64().unwrap();
    let mut long = String::from("frame,bird,x,y\n");
    let mut dltdv = String::new();
    let marks: Vec<Vec<(u64, f64, f64)>> = t["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f["birds"]
                .as_array()
                .unwrap()
                .iter()
                .map(|b| {
                    (
                        b["id"].as_u64().unwrap(),
                        b["x"].as_f64().unwrap(),
                        b["y"].as_f64().unwrap(),
                    )
                })
                .collect()
        })
        .collect();
    let ids = marks[0].iter().map(|m| m.0).max().unwrap() as usize + 1;
    dltdv += &(0..ids)
        .map(|i| format!("pt{0}_cam1_X,pt{0}_cam1_Y", i + 1))
        .collect::<Vec<_>>()
        .join(",");
    dltdv.push('\n');
    for (k, f) in marks.iter().enumerate() {
        let mut row = vec!["NaN".to_string(); 2 * ids];
        for &(id, x, y) in f {
            long += &format!("{k},{id},{x},{y}\n");
            row[2 * id as usize] = x.to_string();
            row[2 * id as usize + 1] = (height - y).to_string();
        }
        dltdv += &row.join(",");
        dltdv.push('\n');
    }
    for (name, text) in [("marks.csv", long), ("marks_dltdv.csv", dltdv)] {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let page = dir.join(format!("{name}.html"));
        let (code, err) = run_quiet(&[
            "annotate",
            s(&file),
            "--images",
            s(&frames),
            "--wingspan-px",
            "12",
            "--heading",
            "right",
            "-o",
            s(&page),
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        let html = std::fs::read_to_string(&page).unwrap();
        let d = page_data(&html);
        let stem = name.trim_end_matches(".csv");
        assert_eq!(d["name"], format!("{stem}_reviewed.json").as_str());
        assert_eq!(d["images"].as_object().unwrap().len(), 3, "{name}");
        assert!(d["images"]["0"]
            .as_str()
            .unwrap()
            .starts_with("data:image/jpeg;base64,"));
        let a = &d["annotations"];
        assert_eq!(a["image_size"][1].as_f64(), Some(height), "{name}");
        for (k, f) in marks.iter().enumerate() {
            let fr = &a["frames"][k];
            assert_eq!(fr["image"], format!("f{k}.png").as_str(), "{name}");
            assert_eq!(fr["heading"].as_f64(), Some(90.0), "{name}");
            assert_eq!(fr["wingspan_px"].as_f64(), Some(12.0), "{name}");
            let birds = fr["birds"].as_array().unwrap();
            assert_eq!(birds.len(), f.len(), "{name}: frame {k}");
            for &(id, x, y) in f {
                let b = birds
                    .iter()
                    .find(|b| b["id"].as_u64() == Some(id))
                    .unwrap_or_else(|| panic!("{name}: frame {k}: no bird {id}"));
                assert!((b["x"].as_f64().unwrap() - x).abs() < 0.01, "{name}");
                assert!(
                    (b["y"].as_f64().unwrap() - y).abs() < 0.01,
                    "{name}: y down"
                );
                assert_eq!(b["confidence"].as_f64(), Some(1.0));
            }
        }
    }
}

#[test]
fn annotate_refuses_what_it_cannot_show() {
    let dir = scratch("annotate_bad");
    let frames = data("track_frames");
    let csv = dir.join("m.csv");
    // Frame 7 has no image among the three.
    let rows = "0,0,10,10\n0,1,20,10\n0,2,30,10\n7,0,12,10\n7,1,22,10\n7,2,32,10\n";
    std::fs::write(&csv, format!("frame,bird,x,y\n{rows}")).unwrap();
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let page = dir.join("r.html");
    // 3-D tracks (a long CSV with z) have no pixels on the images.
    let xyz = dir.join("xyz.csv");
    std::fs::write(
        &xyz,
        "frame,bird,x,y,z\n0,0,0,0,10\n0,1,-1.5,-1.5,10.2\n0,2,1.5,-1.5,9.9\n1,0,0,1,10\n1,1,-1.5,-0.5,10.2\n1,2,1.5,-0.5,9.9\n",
    )
    .unwrap();
    for (args, needle) in [
        (
            vec![
                "annotate",
                s(&xyz),
                "--images",
                s(&frames),
                "--wingspan-px",
                "1.5",
            ],
            "frame 0: 3-D positions",
        ),
        (
            vec![
                "annotate",
                s(&csv),
                "--images",
                s(&frames),
                "--wingspan-px",
                "12",
            ],
            "frame 7: no image",
        ),
        (
            vec![
                "annotate",
                s(&csv),
                "--images",
                s(&empty),
                "--wingspan-px",
                "12",
            ],
            "no image",
        ),
    ] {
        let mut a = args.clone();
        a.extend(["-o", s(&page)]);
        let (code, err) = run_quiet(&a);
        assert_eq!(code, 2, "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{err}");
        assert!(!page.exists());
    }
}

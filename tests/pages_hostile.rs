//! The pages formation writes keep their script elements whatever the names in them: a
//! directory named `<!--<script>` (which merged the review page's two scripts into one whose code
//! never ran), a source and a save name holding `</script>`, `<!--` and `-->`. Each page is split
//! as an HTML parser splits it (`formation::embed::script_texts`, the standard's script-data
//! states) and must have as many scripts as it has `<script` tags, the data script parsing back
//! to the annotations written.

mod support;

use formation::embed::script_texts;
use serde_json::Value;
use support::{data, run_quiet, s, scratch};

const HOSTILE: &str = "<!--<script>";

/// Every `<script` start tag written gives one element, and the data element holds JSON.
fn intact(html: &str) -> Vec<String> {
    let written = html.to_ascii_lowercase().matches("<script").count();
    let scripts = script_texts(html);
    assert_eq!(scripts.len(), written, "the page parses into other scripts");
    for t in &scripts {
        let l = t.to_ascii_lowercase();
        assert!(!l.contains("<!--") && !l.contains("<script") && !l.contains("</script"));
    }
    scripts
}

fn data_of(html: &str) -> Value {
    let scripts = intact(html);
    serde_json::from_str(&scripts[0]).expect("the data script is JSON")
}

#[test]
fn review_annotate_and_report_pages_survive_hostile_names() {
    let dir = scratch("pages-hostile");
    // Frames in a directory named like the start of a comment and a script.
    let frames = dir.join(HOSTILE);
    std::fs::create_dir_all(&frames).unwrap();
    for f in ["f0.png", "f1.png", "f2.png"] {
        std::fs::copy(data("track_frames").join(f), frames.join(f)).unwrap();
    }
    let out = dir.join("a.json");
    let page = dir.join("review.html");
    let (code, err) = run_quiet(&["track", s(&frames), "-o", s(&out), "--review", s(&page)]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    let d = data_of(&html);
    assert_eq!(d["annotations"]["source"].as_str(), Some(s(&frames)));
    let written: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(d["annotations"], written);
    assert!(!html.contains("<title>formation review: <!--"));

    // Annotations from elsewhere with a hostile source, saved under a hostile name.
    let mut ann = written.clone();
    ann["source"] = Value::from("</script><script>alert(1)</script><!--<script>-->");
    let src = dir.join("--><!--<script>.json");
    std::fs::write(&src, serde_json::to_string(&ann).unwrap()).unwrap();
    let page2 = dir.join("annotate.html");
    let (code, err) = run_quiet(&["annotate", s(&src), "--images", s(&frames), "-o", s(&page2)]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&page2).unwrap();
    let d = data_of(&html);
    assert_eq!(d["annotations"]["source"], ann["source"]);
    assert_eq!(d["name"].as_str(), Some("--><!--<script>_reviewed.json"));

    // The report of an animation in the hostile directory.
    let anim = frames.join(HOSTILE.to_string() + ".json");
    std::fs::copy(support::example("barnacle_geese_v.json"), &anim).unwrap();
    let report = dir.join("report.html");
    let (code, err) = run_quiet(&["report", s(&anim), "-o", s(&report)]);
    if code == 0 {
        intact(&std::fs::read_to_string(&report).unwrap());
    } else {
        // Not an animation the report reads: the page is not the subject here.
        assert_eq!(code, 2, "{err}");
    }

    // An animation in the hostile directory, under a hostile name: its report and its 3-D
    // player keep every script element; the player's metadata (the title is the file name)
    // parses back.
    let anim = frames.join("a<!--<script>.json");
    std::fs::copy(data("flock_small.json"), &anim).unwrap();
    let report = dir.join("report-anim.html");
    let (code, err) = run_quiet(&["report", s(&anim), "-o", s(&report)]);
    assert_eq!(code, 0, "{err}");
    intact(&std::fs::read_to_string(&report).unwrap());
    let player = dir.join("view.html");
    let (code, err) = run_quiet(&["view", s(&anim), "-o", s(&player)]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&player).unwrap();
    let scripts = intact(&html);
    let meta: Value = serde_json::from_str(&scripts[0]).expect("the player's metadata is JSON");
    assert_eq!(meta["title"].as_str(), Some("a<!--<script>.json"));
    assert!(!html.contains("<title>formation view: <!--"));
    let _ = std::fs::remove_dir_all(&dir);
}

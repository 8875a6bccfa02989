//! Fuzz target: the data embedded in the review page (`track --review`, `annotate`). The bytes
//! give the source, the save name and an image name (split at zero bytes); the page must parse
//! (as the HTML standard's tokenizer splits scripts) into the two script elements written, the
//! first holding JSON that reads back to the same names.
#![no_main]

use std::collections::BTreeMap;

use formation::track::detect::Blob;
use formation::track::{review, Polarity, Tracked, TrackedBird, TrackedFrame};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let mut parts = text.split('\0');
    let source = parts.next().unwrap_or("").to_string();
    let save_as = parts.next().unwrap_or("a.json").to_string();
    let image = parts.next().map(str::to_string);
    let blob = Blob { x: 1.0, y: 2.0, area: 4, span: 3.0, axis: 0.0, snr: 9.0, split: false };
    let tracked = Tracked {
        source: source.clone(),
        width: 8,
        height: 6,
        fps: Some(25.0),
        polarity: Polarity::Dark,
        frames: vec![TrackedFrame {
            index: 0,
            image: image.clone(),
            wingspan_px: 3.0,
            heading_deg: 90.0,
            birds: vec![TrackedBird { id: 0, x: 1.0, y: 2.0, confidence: 0.5, blob }],
        }],
        decoded: None,
        warnings: Vec::new(),
    };
    let page = review::page(&tracked, &BTreeMap::new(), &save_as);
    let scripts = formation::embed::script_texts(&page);
    assert_eq!(scripts.len(), 2, "the page parses into {} scripts", scripts.len());
    let v: serde_json::Value = serde_json::from_str(&scripts[0]).expect("data is JSON");
    assert_eq!(v["name"].as_str(), Some(save_as.as_str()));
    assert_eq!(v["annotations"]["source"].as_str(), Some(source.as_str()));
    if let Some(i) = image {
        assert_eq!(v["annotations"]["frames"][0]["image"].as_str(), Some(i.as_str()));
    }
});

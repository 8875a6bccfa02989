//! Property tests over the annotation readers (issue 3): no byte string makes them panic, and
//! whatever they accept, `extract` handles without panicking. Inputs are arbitrary bytes, alone or
//! after a prefix that steers them into each format's parser.

use std::path::Path;

use formation::annotations::{parse_str, Heading, ReadOptions};
use formation::extract::{extract, ExtractOptions};
use formation::rng::stream;
use proptest::prelude::*;

const PREFIXES: [&str; 7] = [
    "",
    "{\"wingspan_px\": 20, \"frames\": [",
    "{\"frames\": [{\"birds\": [[",
    "frame,bird,x,y\n",
    "frame,x,y,wingspan_px\n0,1,2,3\n",
    "pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,pt2_cam1_Y,pt3_cam1_X,pt3_cam1_Y\n",
    "{\"shapes\": [{\"label\": \"1\", \"shape_type\": \"point\", \"points\": [[",
];

fn try_all(text: &str) {
    let opts = [
        ReadOptions::default(),
        ReadOptions {
            wingspan_px: Some(17.0),
            heading: Some(Heading::Degrees(33.0)),
            ..ReadOptions::default()
        },
    ];
    for o in &opts {
        if let Ok(ann) = parse_str(Path::new("fuzz"), text, o) {
            let _ = extract(&ann, &ExtractOptions::default(), &mut stream(0, "fuzz"));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn arbitrary_bytes_never_panic(p in 0usize..PREFIXES.len(), bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = format!("{}{}", PREFIXES[p], String::from_utf8_lossy(&bytes));
        try_all(&text);
    }

    #[test]
    fn number_soup_never_panics(p in 0usize..PREFIXES.len(), nums in proptest::collection::vec(prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        (-2000i32..2000).prop_map(|v| v.to_string()),
        Just("NaN".to_string()), Just("".to_string()), Just("1e308".to_string()), Just("-0".to_string()),
    ], 0..60), sep in prop_oneof![Just(","), Just("\n"), Just("],["), Just("]}, {\"birds\": [[")]) {
        let text = format!("{}{}", PREFIXES[p], nums.join(sep));
        try_all(&text);
    }

    #[test]
    fn well_formed_native_files_with_wild_numbers(pts in proptest::collection::vec((-1e12f64..1e12, -1e12f64..1e12), 0..12), scale in -5.0f64..1e6) {
        let birds: Vec<String> = pts.iter().map(|(x, y)| format!("[{x}, {y}]")).collect();
        let text = format!("{{\"wingspan_px\": {scale}, \"frames\": [{{\"birds\": [{}]}}, {{\"birds\": [{}]}}]}}", birds.join(","), birds.join(","));
        try_all(&text);
    }
}

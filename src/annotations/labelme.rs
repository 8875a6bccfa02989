//! Labelme JSON (one file per frame, or a directory of them), pixels with y down.
//!
//! Every shape with `"shape_type": "point"` is a bird. Its id is the shape's `group_id` when set,
//! else its `label` when that is a whole number; otherwise birds carry no id. A `line` shape
//! labelled `wingspan` (drawn tip to tip across one bird's wings) gives the frame's scale; several
//! such lines are averaged. Top-level `"heading"` and `"wingspan_px"` keys, if someone adds them,
//! are read too. In a directory, files ending in `.json` are read in name order; a frame's index
//! is the last number in its file name when every name has a distinct one, else its position.
//! Files with no point at all (frames not annotated yet) are skipped.

use std::path::Path;

use serde_json::Value;

use super::native::{heading, id, number, short};
use super::{Format, RawAnnotations, RawBird, RawFrame};
use crate::error::{Error, Result};

struct LabelmeFrame {
    image: Option<String>,
    wingspan_px: Option<f64>,
    heading: Option<super::Heading>,
    file_scale: Option<f64>,
    birds: Vec<RawBird>,
}

fn parse_frame(path: &Path, text: &str) -> Result<LabelmeFrame> {
    let v: Value = crate::io::parse_json(path, text)?;
    let obj = v
        .as_object()
        .ok_or_else(|| Error::format(path, "top level: expected a Labelme JSON object"))?;
    let shapes = obj
        .get("shapes")
        .and_then(|s| s.as_array())
        .ok_or_else(|| {
            Error::format(path, "shapes: expected an array (is this a Labelme file?)")
        })?;
    let mut birds = Vec::new();
    let mut spans = Vec::new();
    for (k, s) in shapes.iter().enumerate() {
        let at = format!("shapes[{k}]");
        let so = s.as_object().ok_or_else(|| {
            Error::format(
                path,
                format!("{at}: expected an object, found {}", short(s)),
            )
        })?;
        let kind = so
            .get("shape_type")
            .and_then(|t| t.as_str())
            .unwrap_or("polygon");
        let label = so.get("label").and_then(|l| l.as_str()).unwrap_or("");
        let pts = || {
            so.get("points").and_then(|p| p.as_array()).ok_or_else(|| {
                Error::format(path, format!("{at}.points: expected an array of [x, y]"))
            })
        };
        let point = |j: usize, p: &Value| -> Result<(f64, f64)> {
            match p.as_array() {
                Some(a) if a.len() == 2 => Ok((
                    number(path, &format!("{at}.points[{j}][0] (x)"), &a[0])?,
                    number(path, &format!("{at}.points[{j}][1] (y)"), &a[1])?,
                )),
                _ => Err(Error::format(
                    path,
                    format!("{at}.points[{j}]: expected [x, y], found {}", short(p)),
                )),
            }
        };
        match kind {
            "point" => {
                let p = pts()?;
                let first = p.first().ok_or_else(|| {
                    Error::format(path, format!("{at}.points: a point shape needs one [x, y]"))
                })?;
                let (x, y) = point(0, first)?;
                let bird_id = match so.get("group_id") {
                    None | Some(Value::Null) => label.trim().parse::<usize>().ok(),
                    Some(g) => Some(id(path, &format!("{at}.group_id"), g)?),
                };
                birds.push(RawBird {
                    z: None,
                    id: bird_id,
                    x,
                    y,
                    at: format!("{at} (label \"{label}\")"),
                });
            }
            "line" if label.trim().eq_ignore_ascii_case("wingspan") => {
                let p = pts()?;
                if p.len() != 2 {
                    return Err(Error::format(
                        path,
                        format!(
                            "{at}: a wingspan line needs exactly 2 points, found {}",
                            p.len()
                        ),
                    ));
                }
                let (a, b) = (point(0, &p[0])?, point(1, &p[1])?);
                spans.push(((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt());
            }
            _ => {}
        }
    }
    let wingspan_px = if spans.is_empty() {
        None
    } else {
        Some(spans.iter().sum::<f64>() / spans.len() as f64)
    };
    Ok(LabelmeFrame {
        image: obj
            .get("imagePath")
            .and_then(|s| s.as_str())
            .map(str::to_string),
        wingspan_px,
        heading: match obj.get("heading") {
            None | Some(Value::Null) => None,
            Some(h) => Some(heading(path, "heading", h)?),
        },
        file_scale: match obj.get("wingspan_px") {
            None | Some(Value::Null) => None,
            Some(w) => Some(number(path, "wingspan_px", w)?),
        },
        birds,
    })
}

pub(crate) fn parse_file(path: &Path, text: &str) -> Result<RawAnnotations> {
    let f = parse_frame(path, text)?;
    if f.birds.is_empty() {
        return Err(Error::format(
            path,
            "shapes: no \"point\" shape; mark each bird with Labelme's point tool",
        ));
    }
    Ok(RawAnnotations {
        fps: None,
        format: Format::Labelme,
        source: None,
        heading: f.heading,
        wingspan_px: f.file_scale,
        y_up: false,
        is_csv: false,
        frames: vec![RawFrame {
            index: 0,
            image: f.image,
            wingspan_px: f.wingspan_px,
            at: "shapes (wingspan line)".into(),
            birds: f.birds,
        }],
    })
}

/// The last run of digits in a file stem.
fn trailing_number(name: &str) -> Option<i64> {
    let stem = name.rsplit_once('.').map(|p| p.0).unwrap_or(name);
    let digits: String = stem
        .chars()
        .rev()
        .skip_while(|c| !c.is_ascii_digit())
        .take_while(|c| c.is_ascii_digit())
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    digits.parse().ok()
}

pub(crate) fn read_dir(dir: &Path) -> Result<RawAnnotations> {
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(Error::format(
            dir,
            "directory has no .json files; expected one Labelme file per frame",
        ));
    }
    // Refuse before reading: the frame limit, and one budget for the whole directory (each file
    // alone is also bounded by `io::read_text`).
    let max_frames = crate::limits::MAX_ANNOTATED_FRAMES;
    if files.len() > max_frames {
        return Err(Error::format(
            dir,
            format!(
                "{} .json files, at most {max_frames} annotated frames; annotate a subset (a few dozen frames are plenty)",
                files.len()
            ),
        ));
    }
    let total: u64 = files
        .iter()
        .filter_map(|p| std::fs::metadata(p).ok())
        .map(|m| m.len())
        .sum();
    if total > crate::io::MAX_INPUT_BYTES {
        return Err(Error::format(
            dir,
            format!(
                "its .json files hold {total} bytes, more than the {} byte limit of one input",
                crate::io::MAX_INPUT_BYTES
            ),
        ));
    }
    let names: Vec<String> = files
        .iter()
        .map(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        })
        .collect();
    let mut numbers: Vec<Option<i64>> = names.iter().map(|n| trailing_number(n)).collect();
    {
        let mut seen: Vec<i64> = numbers.iter().flatten().copied().collect();
        seen.sort_unstable();
        seen.dedup();
        if seen.len() != files.len() {
            numbers = vec![None; files.len()];
        }
    }
    let mut frames = Vec::new();
    let mut heading = None;
    let mut scale = None;
    for (k, p) in files.iter().enumerate() {
        let text = crate::io::read_text(p)?;
        let f = parse_frame(p, &text)?;
        if f.birds.is_empty() {
            continue;
        }
        heading = heading.or(f.heading);
        scale = scale.or(f.file_scale);
        let index = numbers[k].unwrap_or(k as i64);
        frames.push(RawFrame {
            index,
            image: f.image.or_else(|| Some(names[k].clone())),
            wingspan_px: f.wingspan_px,
            at: format!("{}: wingspan line", names[k]),
            birds: f
                .birds
                .into_iter()
                .map(|mut b| {
                    b.at = format!("{} {}", names[k], b.at);
                    b
                })
                .collect(),
        });
    }
    if frames.is_empty() {
        return Err(Error::format(
            dir,
            format!(
                "none of the {} Labelme files has a \"point\" shape; mark each bird with the point tool",
                files.len()
            ),
        ));
    }
    Ok(RawAnnotations {
        fps: None,
        format: Format::LabelmeDir,
        source: dir.file_name().map(|n| n.to_string_lossy().into_owned()),
        heading,
        wingspan_px: scale,
        y_up: false,
        is_csv: false,
        frames,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = r#"{"shapes": [
        {"label": "bird", "group_id": 4, "shape_type": "point", "points": [[10, 20]]},
        {"label": "bird", "group_id": 2, "shape_type": "point", "points": [[30, 40]]},
        {"label": "bird", "group_id": 9, "shape_type": "point", "points": [[50, 45]]},
        {"label": "wingspan", "shape_type": "line", "points": [[0, 0], [30, 40]]},
        {"label": "tree", "shape_type": "polygon", "points": [[0, 0], [1, 1], [2, 0]]}
    ], "imagePath": "f.jpg"}"#;

    #[test]
    fn group_ids_and_wingspan_line() {
        let raw = parse_file(Path::new("f.json"), FILE).unwrap();
        let f = &raw.frames[0];
        assert_eq!(
            f.birds.iter().map(|b| b.id).collect::<Vec<_>>(),
            vec![Some(4), Some(2), Some(9)]
        );
        assert_eq!(f.wingspan_px, Some(50.0));
        assert_eq!(f.image.as_deref(), Some("f.jpg"));
    }

    #[test]
    fn frame_numbers_come_from_file_names() {
        assert_eq!(trailing_number("frame_0012.json"), Some(12));
        assert_eq!(trailing_number("clip3_f7.json"), Some(7));
        assert_eq!(trailing_number("a.json"), None);
    }
}

//! The two CSV inputs of docs/formats.md §4.1, in pixels.
//!
//! - Long CSV: header with `frame`, `x`, `y` and optionally `bird` (ids) and `wingspan_px`
//!   (per-row scale, constant within a frame); other columns are ignored. One row per bird per
//!   frame; y grows downward unless `read.y_origin` is bottom.
//! - DLTdv digitizer CSV: header `pt1_cam1_X,pt1_cam1_Y,pt2_cam1_X,...`, one row per frame, `NaN`
//!   (or an empty field) where a bird is not marked. DLTdv measures y from the image's bottom
//!   edge, so y grows upward unless `read.y_origin` is top. With several cameras the lowest-numbered
//!   camera is read. Bird `ptN` gets id N − 1; rows with no mark at all are skipped (frames not
//!   digitised).
//!
//! Both accept leading `# key: value` comment lines for `source`, `heading`, `wingspan_px`.

use std::path::Path;

use super::{Format, Heading, RawAnnotations, RawBird, RawFrame};
use crate::error::{Error, Result};

/// Leading `# key: value` lines.
struct Meta {
    source: Option<String>,
    heading: Option<Heading>,
    wingspan_px: Option<f64>,
}

fn meta(path: &Path, text: &str) -> Result<Meta> {
    let mut m = Meta {
        source: None,
        heading: None,
        wingspan_px: None,
    };
    for (ln, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let Some(c) = t.strip_prefix('#') else { break };
        let Some((k, v)) = c.split_once(':') else {
            continue;
        };
        let (k, v) = (k.trim().to_ascii_lowercase(), v.trim());
        let at = format!("line {} ({k})", ln + 1);
        match k.as_str() {
            "source" => m.source = Some(v.to_string()),
            "heading" => {
                m.heading =
                    Some(Heading::parse(v).map_err(|e| Error::format(path, format!("{at}: {e}")))?)
            }
            "wingspan_px" => {
                m.wingspan_px = Some(v.parse::<f64>().map_err(|_| {
                    Error::format(path, format!("{at}: `{v}` is not a number of pixels"))
                })?)
            }
            _ => {}
        }
    }
    Ok(m)
}

/// Header fields of the first non-comment line.
fn header(text: &str) -> Option<Vec<String>> {
    let line = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))?;
    Some(
        line.split(',')
            .map(|f| f.trim().trim_matches('"').to_string())
            .collect(),
    )
}

/// `ptN_camM_X` → (N, M, is_x).
fn dlt_column(name: &str) -> Option<(usize, usize, bool)> {
    let lower = name.to_ascii_lowercase();
    let rest = lower.strip_prefix("pt")?;
    let (n, rest) = rest.split_once("_cam")?;
    let (m, axis) = rest.split_once('_')?;
    let is_x = match axis {
        "x" => true,
        "y" => false,
        _ => return None,
    };
    Some((n.parse().ok()?, m.parse().ok()?, is_x))
}

/// `ptN_X` / `ptN_Y` / `ptN_Z` (DLTdv `xyzpts`, 3-D world coordinates) → (N, axis 0..3).
fn xyz_column(name: &str) -> Option<(usize, usize)> {
    let lower = name.to_ascii_lowercase();
    let (n, axis) = lower.strip_prefix("pt")?.split_once('_')?;
    let axis = match axis {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        _ => return None,
    };
    Some((n.parse().ok()?, axis))
}

pub(crate) fn detect_csv(path: &Path, text: &str) -> Result<Format> {
    let h = header(text)
        .ok_or_else(|| Error::format(path, "no header line; expected CSV annotations"))?;
    if !h.is_empty() && h.iter().all(|c| dlt_column(c).is_some()) {
        return Ok(Format::Dltdv);
    }
    if !h.is_empty() && h.iter().all(|c| xyz_column(c).is_some()) {
        return Ok(Format::Dltdv);
    }
    let has = |n: &str| h.iter().any(|c| c.eq_ignore_ascii_case(n));
    if has("frame") && has("x") && has("y") {
        return Ok(Format::LongCsv);
    }
    Err(Error::format(
        path,
        format!(
            "line 1: header `{}` is neither a long CSV (frame,bird,x,y) nor DLTdv (pt1_cam1_X,pt1_cam1_Y,...); not JSON either",
            h.join(",").chars().take(60).collect::<String>()
        ),
    ))
}

fn reader(text: &str) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes())
}

fn csv_error(path: &Path, e: &csv::Error) -> Error {
    let line = e.position().map(|p| p.line()).unwrap_or(0);
    Error::format(path, format!("line {line}: unreadable CSV: {e}"))
}

fn is_nan_text(s: &str) -> bool {
    s.is_empty() || s.eq_ignore_ascii_case("nan")
}

pub(crate) fn parse(path: &Path, text: &str, format: Format) -> Result<RawAnnotations> {
    let m = meta(path, text)?;
    let mut rdr = reader(text);
    let hdr: Vec<String> = rdr
        .headers()
        .map_err(|e| csv_error(path, &e))?
        .iter()
        .map(str::to_string)
        .collect();
    let frames = if format == Format::Dltdv && hdr.iter().all(|c| xyz_column(c).is_some()) {
        parse_xyzpts(path, &mut rdr, &hdr)?
    } else if format == Format::Dltdv {
        parse_dltdv(path, &mut rdr, &hdr)?
    } else {
        parse_long(path, &mut rdr, &hdr)?
    };
    Ok(RawAnnotations {
        fps: None,
        format,
        source: m.source,
        heading: m.heading,
        wingspan_px: m.wingspan_px,
        // 3-D points (DLTdv xyzpts, a long CSV with `z`) are world coordinates with z up:
        // seen from above, y grows upward.
        y_up: format == Format::Dltdv
            || frames.iter().any(|f| f.birds.iter().any(|b| b.z.is_some())),
        is_csv: true,
        frames,
    })
}

fn parse_long(path: &Path, rdr: &mut csv::Reader<&[u8]>, hdr: &[String]) -> Result<Vec<RawFrame>> {
    let col = |n: &str| hdr.iter().position(|c| c.eq_ignore_ascii_case(n));
    let (Some(cf), Some(cx), Some(cy)) = (col("frame"), col("x"), col("y")) else {
        return Err(Error::format(path, "header: needs columns frame, x, y"));
    };
    let (cb, cw, cz) = (col("bird"), col("wingspan_px"), col("z"));
    let mut frames: Vec<RawFrame> = Vec::new();
    // Frame index → position in `frames` (a linear search made reading quadratic in frames).
    let mut frame_pos: std::collections::HashMap<i64, usize> = std::collections::HashMap::new();
    let mut rec = csv::StringRecord::new();
    let mut row = 0usize;
    loop {
        match rdr.read_record(&mut rec) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(path, &e)),
        }
        row += 1;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        let at = format!("row {row} (line {line})");
        let field = |c: usize, name: &str| {
            rec.get(c).ok_or_else(|| {
                Error::format(
                    path,
                    format!(
                        "{at}: field {name} missing (row has {} fields, header {})",
                        rec.len(),
                        hdr.len()
                    ),
                )
            })
        };
        let fnum = |c: usize, name: &str| -> Result<f64> {
            let s = field(c, name)?;
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(_) => Err(Error::format(
                    path,
                    format!("{at}, field {name}: `{s}` is not a finite number; leave out birds that are not marked"),
                )),
                Err(_) => Err(Error::format(
                    path,
                    format!("{at}, field {name}: `{s}` is not a number"),
                )),
            }
        };
        let fs = field(cf, "frame")?;
        let index: i64 = fs.parse().map_err(|_| {
            Error::format(
                path,
                format!("{at}, field frame: `{fs}` is not an integer frame number"),
            )
        })?;
        let id = match cb {
            Some(c) => {
                let s = field(c, "bird")?;
                if s.is_empty() {
                    None
                } else {
                    Some(s.parse::<usize>().map_err(|_| {
                        Error::format(
                            path,
                            format!("{at}, field bird: `{s}` is not a non-negative integer id"),
                        )
                    })?)
                }
            }
            None => None,
        };
        let x = fnum(cx, "x")?;
        let y = fnum(cy, "y")?;
        let z = match cz {
            Some(c) => Some(fnum(c, "z")?),
            None => None,
        };
        let w = match cw {
            Some(c) if !field(c, "wingspan_px")?.is_empty() => Some(fnum(c, "wingspan_px")?),
            _ => None,
        };
        let pos = match frame_pos.get(&index) {
            Some(&p) => p,
            None => {
                frame_pos.insert(index, frames.len());
                frames.push(RawFrame {
                    index,
                    image: None,
                    wingspan_px: None,
                    at: format!("{at}, field wingspan_px"),
                    birds: Vec::new(),
                });
                frames.len() - 1
            }
        };
        let f = &mut frames[pos];
        if let Some(w) = w {
            match f.wingspan_px {
                Some(prev) if prev != w => {
                    return Err(Error::format(
                        path,
                        format!("{at}, field wingspan_px: {w} differs from {prev} given earlier for frame {index}"),
                    ))
                }
                _ => {
                    f.wingspan_px = Some(w);
                    f.at = format!("{at}, field wingspan_px");
                }
            }
        }
        f.birds.push(RawBird { id, x, y, z, at });
    }
    if frames.is_empty() {
        return Err(Error::format(path, "no data rows after the header"));
    }
    Ok(frames)
}

fn parse_dltdv(path: &Path, rdr: &mut csv::Reader<&[u8]>, hdr: &[String]) -> Result<Vec<RawFrame>> {
    let cols: Vec<(usize, usize, bool)> = hdr.iter().filter_map(|c| dlt_column(c)).collect();
    let cam = cols.iter().map(|c| c.1).min().unwrap_or(1);
    // (point number, x column, y column) of the chosen camera.
    let mut points: Vec<(usize, Option<usize>, Option<usize>)> = Vec::new();
    // Point number → position in `points` (a linear search made a wide header quadratic).
    let mut point_pos: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (ci, &(n, m, is_x)) in cols.iter().enumerate() {
        if m != cam {
            continue;
        }
        let p = match point_pos.get(&n) {
            Some(&p) => p,
            None => {
                if points.len() == crate::limits::MAX_ANNOTATED_BIRDS {
                    return Err(Error::format(
                        path,
                        format!(
                            "header: more than {} points per camera, at most {} birds per frame",
                            crate::limits::MAX_ANNOTATED_BIRDS,
                            crate::limits::MAX_ANNOTATED_BIRDS
                        ),
                    ));
                }
                point_pos.insert(n, points.len());
                points.push((n, None, None));
                points.len() - 1
            }
        };
        if is_x {
            points[p].1 = Some(ci);
        } else {
            points[p].2 = Some(ci);
        }
    }
    for p in &points {
        if p.1.is_none() || p.2.is_none() || p.0 == 0 {
            return Err(Error::format(
                path,
                format!("header: point pt{}_cam{cam} needs both an _X and a _Y column (points count from 1)", p.0),
            ));
        }
    }
    points.sort_by_key(|p| p.0);
    let mut frames = Vec::new();
    let mut rec = csv::StringRecord::new();
    let mut row = 0usize;
    loop {
        match rdr.read_record(&mut rec) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(path, &e)),
        }
        row += 1;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        if rec.len() != hdr.len() {
            return Err(Error::format(
                path,
                format!(
                    "row {row} (line {line}): {} fields, the header has {} (truncated row?)",
                    rec.len(),
                    hdr.len()
                ),
            ));
        }
        let mut birds = Vec::new();
        for &(n, cx, cy) in &points {
            let (cx, cy) = (cx.unwrap_or(0), cy.unwrap_or(0));
            let (sx, sy) = (rec.get(cx).unwrap_or(""), rec.get(cy).unwrap_or(""));
            let num = |s: &str, name: &str| -> Result<Option<f64>> {
                if is_nan_text(s) {
                    return Ok(None);
                }
                match s.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Some(v)),
                    _ => Err(Error::format(
                        path,
                        format!("row {row} (line {line}), field {name}: `{s}` is not a number (use NaN for an unmarked bird)"),
                    )),
                }
            };
            let hx = hdr.get(cx).map(String::as_str).unwrap_or("X");
            let hy = hdr.get(cy).map(String::as_str).unwrap_or("Y");
            match (num(sx, hx)?, num(sy, hy)?) {
                (Some(x), Some(y)) => birds.push(RawBird {
                    z: None,
                    id: Some(n - 1),
                    x,
                    y,
                    at: format!("row {row} (line {line}), pt{n}"),
                }),
                (None, None) => {}
                _ => {
                    return Err(Error::format(
                        path,
                        format!("row {row} (line {line}), pt{n}: only one of X and Y is marked"),
                    ))
                }
            }
        }
        if birds.is_empty() {
            continue;
        }
        frames.push(RawFrame {
            index: row as i64 - 1,
            image: None,
            wingspan_px: None,
            at: format!("row {row}"),
            birds,
        });
    }
    if frames.is_empty() {
        return Err(Error::format(path, "no row with a marked bird"));
    }
    Ok(frames)
}

/// DLTdv `xyzpts`: `ptN_X,ptN_Y,ptN_Z` per point, one row per frame, 3-D world coordinates
/// of the calibration frame with Z up (X, Y the horizontal plane, Y grows upward as seen from
/// above, as DLTdv's y does).
fn parse_xyzpts(
    path: &Path,
    rdr: &mut csv::Reader<&[u8]>,
    hdr: &[String],
) -> Result<Vec<RawFrame>> {
    // (point number, [X, Y, Z] columns).
    let mut points: Vec<(usize, [Option<usize>; 3])> = Vec::new();
    let mut point_pos: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (ci, c) in hdr.iter().enumerate() {
        let Some((n, axis)) = xyz_column(c) else {
            continue;
        };
        let p = match point_pos.get(&n) {
            Some(&p) => p,
            None => {
                if points.len() == crate::limits::MAX_ANNOTATED_BIRDS {
                    return Err(Error::format(
                        path,
                        format!(
                            "header: more than {} points, at most {} birds per frame",
                            crate::limits::MAX_ANNOTATED_BIRDS,
                            crate::limits::MAX_ANNOTATED_BIRDS
                        ),
                    ));
                }
                point_pos.insert(n, points.len());
                points.push((n, [None; 3]));
                points.len() - 1
            }
        };
        points[p].1[axis] = Some(ci);
    }
    for p in &points {
        if p.1.iter().any(Option::is_none) || p.0 == 0 {
            return Err(Error::format(
                path,
                format!(
                    "header: point pt{} needs _X, _Y and _Z columns (points count from 1)",
                    p.0
                ),
            ));
        }
    }
    points.sort_by_key(|p| p.0);
    let mut frames = Vec::new();
    let mut rec = csv::StringRecord::new();
    let mut row = 0usize;
    loop {
        match rdr.read_record(&mut rec) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(path, &e)),
        }
        row += 1;
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        if rec.len() != hdr.len() {
            return Err(Error::format(
                path,
                format!(
                    "row {row} (line {line}): {} fields, the header has {} (truncated row?)",
                    rec.len(),
                    hdr.len()
                ),
            ));
        }
        let mut birds = Vec::new();
        for &(n, cols) in &points {
            let mut v = [None; 3];
            for (k, c) in cols.iter().enumerate() {
                let c = c.unwrap_or(0);
                let s = rec.get(c).unwrap_or("");
                if is_nan_text(s) {
                    continue;
                }
                match s.parse::<f64>() {
                    Ok(x) if x.is_finite() => v[k] = Some(x),
                    _ => {
                        let name = hdr.get(c).map(String::as_str).unwrap_or("?");
                        return Err(Error::format(
                            path,
                            format!("row {row} (line {line}), field {name}: `{s}` is not a number (use NaN for an unmarked bird)"),
                        ));
                    }
                }
            }
            match v {
                [Some(x), Some(y), Some(z)] => birds.push(RawBird {
                    id: Some(n - 1),
                    x,
                    y,
                    z: Some(z),
                    at: format!("row {row} (line {line}), pt{n}"),
                }),
                [None, None, None] => {}
                _ => {
                    return Err(Error::format(
                        path,
                        format!(
                            "row {row} (line {line}), pt{n}: only some of X, Y and Z are given"
                        ),
                    ))
                }
            }
        }
        if birds.is_empty() {
            continue;
        }
        frames.push(RawFrame {
            index: row as i64 - 1,
            image: None,
            wingspan_px: None,
            at: format!("row {row}"),
            birds,
        });
    }
    if frames.is_empty() {
        return Err(Error::format(path, "no row with a marked bird"));
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_csv_with_metadata_and_per_frame_scale() {
        let text = "# source: test clip\n# heading: 45\nframe,bird,x,y,wingspan_px,note\n0,1,1,2,30,a\n0,2,3,4,30,b\n1,1,5,6,31,c\n";
        let raw = parse(Path::new("t.csv"), text, Format::LongCsv).unwrap();
        assert_eq!(raw.source.as_deref(), Some("test clip"));
        assert_eq!(raw.heading, Some(Heading::Degrees(45.0)));
        assert_eq!(raw.frames.len(), 2);
        assert_eq!(raw.frames[1].wingspan_px, Some(31.0));
        assert_eq!(raw.frames[0].birds[1].id, Some(2));
        assert!(!raw.y_up);
    }

    #[test]
    fn dltdv_picks_the_first_camera_and_skips_empty_rows() {
        let text = "pt1_cam1_X,pt1_cam1_Y,pt1_cam2_X,pt1_cam2_Y,pt2_cam1_X,pt2_cam1_Y\nNaN,NaN,1,1,NaN,NaN\n1,2,9,9,3,4\n";
        assert_eq!(detect_csv(Path::new("d.csv"), text).unwrap(), Format::Dltdv);
        let raw = parse(Path::new("d.csv"), text, Format::Dltdv).unwrap();
        assert_eq!(raw.frames.len(), 1);
        assert_eq!(raw.frames[0].index, 1);
        let b = &raw.frames[0].birds;
        assert_eq!((b[0].id, b[0].x, b[0].y), (Some(0), 1.0, 2.0));
        assert_eq!((b[1].id, b[1].x), (Some(1), 3.0));
        assert!(raw.y_up);
    }

    #[test]
    fn conflicting_frame_scales_are_an_error() {
        let text = "frame,x,y,wingspan_px\n0,1,2,30\n0,3,4,31\n";
        let e = parse(Path::new("t.csv"), text, Format::LongCsv)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 2") && e.contains("wingspan_px"), "{e}");
    }
}

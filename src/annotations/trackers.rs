//! Tracks written by the multi-animal trackers biologists use, read as annotations (pixels, y
//! down, ids from the tracker's identities). Each is told apart by content (see
//! [`detect`]); the layouts are described in `docs/formats.md`.
//!
//! - **SLEAP analysis CSV**: header `track,frame_idx,instance.score,NODE.x,NODE.y,NODE.score,...`
//!   (older exports lack `instance.score`); one row per animal per frame; the first node's x, y
//!   is the bird; `track` names the identity (`track_3`, or empty for untracked instances,
//!   which then get ids by assignment).
//! - **DeepLabCut multi-animal CSV**: four header rows `scorer`, `individuals`, `bodyparts`,
//!   `coords` (x, y, likelihood per individual and body part); one row per frame, its first cell
//!   the frame number (or an image path, then the row's position); the first body part listed
//!   is the bird; empty or NaN cells are birds not found. The identity is the individual's
//!   position in the `individuals` row.
//! - **MOTChallenge / CVAT MOT text**: no header; `frame,id,left,top,width,height,...` per line
//!   (frames from 1); the bird is the box centre; id −1 (detections not linked into tracks)
//!   leaves ids to the assignment.
//! - **idtracker.ai `trajectories.csv`**: header `time,x1,y1,x2,y2,...` (`time` optional), one
//!   row per frame from frame 0, NaN where an animal is not seen; animal N gets id N − 1.

use std::collections::HashMap;
use std::path::Path;

use super::{Format, RawAnnotations, RawBird, RawFrame};
use crate::error::{Error, Result};

fn fields(line: &str) -> Vec<&str> {
    line.split(',')
        .map(|f| f.trim().trim_matches('"'))
        .collect()
}

fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

/// Which tracker wrote `text`, if any.
pub(crate) fn detect(text: &str) -> Option<Format> {
    let mut it = lines(text);
    let (_, first) = it.next()?;
    let h = fields(first);
    let low: Vec<String> = h.iter().map(|c| c.to_ascii_lowercase()).collect();
    if low.first().map(String::as_str) == Some("scorer") {
        let next: Vec<String> = it
            .take(3)
            .map(|(_, l)| {
                fields(l)
                    .first()
                    .map(|c| c.to_ascii_lowercase())
                    .unwrap_or_default()
            })
            .collect();
        if next.first().map(String::as_str) == Some("individuals") {
            return Some(Format::Dlc);
        }
        return None;
    }
    if low.iter().any(|c| c == "frame_idx") && low.iter().any(|c| c.ends_with(".x")) {
        return Some(Format::Sleap);
    }
    let xy = |c: &str, p: char| {
        c.strip_prefix(p)
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    if low.iter().any(|c| xy(c, 'x'))
        && low
            .iter()
            .all(|c| c == "time" || c == "frame" || xy(c, 'x') || xy(c, 'y'))
    {
        return Some(Format::IdTracker);
    }
    // MOT: no header, at least 6 numbers per line, an integer frame and id.
    if h.len() >= 6
        && h.iter().all(|c| c.parse::<f64>().is_ok())
        && h[0].parse::<i64>().is_ok()
        && h[1].parse::<i64>().is_ok()
    {
        return Some(Format::Mot);
    }
    None
}

fn num(path: &Path, at: &str, name: &str, s: &str) -> Result<Option<f64>> {
    if s.is_empty() || s.eq_ignore_ascii_case("nan") {
        return Ok(None);
    }
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(Some(v)),
        _ => Err(Error::format(
            path,
            format!("{at}, field {name}: `{s}` is not a number"),
        )),
    }
}

/// `read.bodypart` naming a node the file of SLEAP's (CSV or HDF5) at `path` lacks, listing its
/// nodes.
pub(super) fn no_node<S: AsRef<str>>(path: &Path, b: &str, nodes: &[S]) -> Error {
    let names: Vec<&str> = nodes.iter().map(AsRef::as_ref).collect();
    Error::parameter(
        "read.bodypart",
        format!(
            "{}: no node \"{b}\"; its nodes are {}",
            path.display(),
            names.join(", ")
        ),
    )
}

fn get<'a>(path: &Path, at: &str, row: &[&'a str], c: usize, name: &str) -> Result<&'a str> {
    row.get(c).copied().ok_or_else(|| {
        Error::format(
            path,
            format!("{at}: field {name} missing (row has {} fields)", row.len()),
        )
    })
}

/// Frames in order of first appearance, keyed by index.
#[derive(Default)]
pub(crate) struct Frames {
    frames: Vec<RawFrame>,
    pos: HashMap<i64, usize>,
}

impl Frames {
    pub(crate) fn push(&mut self, index: i64, bird: RawBird) {
        let p = *self.pos.entry(index).or_insert_with(|| {
            self.frames.push(RawFrame {
                index,
                image: None,
                wingspan_px: None,
                at: format!("frame {index}"),
                birds: Vec::new(),
            });
            self.frames.len() - 1
        });
        self.frames[p].birds.push(bird);
    }

    pub(crate) fn done(self, path: &Path, format: Format) -> Result<RawAnnotations> {
        if self.frames.is_empty() {
            return Err(Error::format(path, "no bird in any row"));
        }
        let total: usize = self.frames.iter().map(|f| f.birds.len()).sum();
        if total > crate::limits::MAX_BIRD_FRAMES {
            return Err(Error::format(path, "too many marks"));
        }
        Ok(RawAnnotations {
            fps: None,
            format,
            source: None,
            heading: None,
            wingspan_px: None,
            y_up: false,
            is_csv: true,
            frames: self.frames,
        })
    }
}

/// Parses a tracker file of the detected `format`.
pub(crate) fn parse(
    path: &Path,
    text: &str,
    format: Format,
    bodypart: Option<&str>,
) -> Result<RawAnnotations> {
    match format {
        Format::Sleap => sleap(path, text, bodypart),
        Format::Dlc => dlc(path, text, bodypart),
        Format::Mot => mot(path, text),
        Format::IdTracker => idtracker(path, text),
        _ => Err(Error::Internal(format!(
            "{} is not a tracker format",
            format.name()
        ))),
    }
}

/// An id from a track name: its trailing number (`track_3` → 3), else its order of first
/// appearance among names without one.
pub(crate) fn track_id(name: &str, named: &mut HashMap<String, usize>) -> usize {
    let digits: String = name
        .chars()
        .rev()
        .take_while(|c| c.is_ascii_digit())
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    if let Ok(n) = digits.parse::<usize>() {
        if n < 1_000_000 {
            return n;
        }
    }
    let k = named.len();
    1_000_000 + *named.entry(name.to_string()).or_insert(k)
}

fn sleap(path: &Path, text: &str, bodypart: Option<&str>) -> Result<RawAnnotations> {
    let mut it = lines(text);
    let (_, head) = it.next().ok_or_else(|| Error::format(path, "empty file"))?;
    let h: Vec<String> = fields(head)
        .iter()
        .map(|c| c.to_ascii_lowercase())
        .collect();
    let col = |n: &str| h.iter().position(|c| c == n);
    let cf = col("frame_idx").ok_or_else(|| Error::format(path, "header: no frame_idx"))?;
    let ct = col("track");
    let cx = match bodypart {
        None => h
            .iter()
            .position(|c| c.ends_with(".x"))
            .ok_or_else(|| Error::format(path, "header: no NODE.x column"))?,
        Some(b) => col(&format!("{}.x", b.to_ascii_lowercase())).ok_or_else(|| {
            let nodes: Vec<&str> = h.iter().filter_map(|c| c.strip_suffix(".x")).collect();
            no_node(path, b, &nodes)
        })?,
    };
    let node = h[cx].trim_end_matches(".x").to_string();
    let cy = col(&format!("{node}.y"))
        .ok_or_else(|| Error::format(path, format!("header: {node}.x without {node}.y")))?;
    let mut out = Frames::default();
    let mut named = HashMap::new();
    for (row, (line, l)) in it.enumerate() {
        let r = fields(l);
        let at = format!("row {} (line {line})", row + 1);
        let fs = get(path, &at, &r, cf, "frame_idx")?;
        let index: i64 = fs.parse().map_err(|_| {
            Error::format(
                path,
                format!("{at}, field frame_idx: `{fs}` is not a frame number"),
            )
        })?;
        let x = num(
            path,
            &at,
            &format!("{node}.x"),
            get(path, &at, &r, cx, "x")?,
        )?;
        let y = num(
            path,
            &at,
            &format!("{node}.y"),
            get(path, &at, &r, cy, "y")?,
        )?;
        let id = match ct.map(|c| get(path, &at, &r, c, "track")).transpose()? {
            Some(t) if !t.is_empty() && !t.eq_ignore_ascii_case("nan") => {
                Some(track_id(t, &mut named))
            }
            _ => None,
        };
        match (x, y) {
            (Some(x), Some(y)) => out.push(
                index,
                RawBird {
                    id,
                    x,
                    y,
                    z: None,
                    at,
                },
            ),
            (None, None) => {}
            _ => {
                return Err(Error::format(
                    path,
                    format!("{at}: {node}.x and {node}.y must both be given or both be empty"),
                ))
            }
        }
    }
    out.done(path, Format::Sleap)
}

fn dlc(path: &Path, text: &str, bodypart: Option<&str>) -> Result<RawAnnotations> {
    let mut it = lines(text);
    let mut head: Vec<Vec<String>> = Vec::new();
    for name in ["scorer", "individuals", "bodyparts", "coords"] {
        let (line, l) = it
            .next()
            .ok_or_else(|| Error::format(path, format!("header: no `{name}` row")))?;
        let r: Vec<String> = fields(l).iter().map(|c| c.to_string()).collect();
        if !r.first().is_some_and(|c| c.eq_ignore_ascii_case(name)) {
            return Err(Error::format(
                path,
                format!("line {line}: expected the `{name}` header row of a DeepLabCut multi-animal CSV"),
            ));
        }
        head.push(r);
    }
    let (inds, parts, coords) = (&head[1], &head[2], &head[3]);
    let part = match bodypart {
        None => parts
            .get(1)
            .cloned()
            .ok_or_else(|| Error::format(path, "header: no body part"))?,
        Some(b) => parts
            .iter()
            .skip(1)
            .find(|p| p.eq_ignore_ascii_case(b))
            .cloned()
            .ok_or_else(|| {
                let mut known: Vec<&str> = Vec::new();
                for p in parts.iter().skip(1) {
                    if !known.contains(&p.as_str()) {
                        known.push(p);
                    }
                }
                Error::parameter(
                    "read.bodypart",
                    format!(
                        "{}: no body part \"{b}\"; its body parts are {}",
                        path.display(),
                        known.join(", ")
                    ),
                )
            })?,
    };
    // Each individual's x and y columns for the first body part.
    let mut order: Vec<String> = Vec::new();
    let mut cols: Vec<(usize, Option<usize>, Option<usize>)> = Vec::new();
    for (c, coord) in coords.iter().enumerate().skip(1) {
        let (Some(ind), Some(p)) = (inds.get(c), parts.get(c)) else {
            continue;
        };
        if *p != part || ind.eq_ignore_ascii_case("single") {
            continue;
        }
        let k = match order.iter().position(|o| o == ind) {
            Some(k) => k,
            None => {
                order.push(ind.clone());
                cols.push((order.len() - 1, None, None));
                order.len() - 1
            }
        };
        match coord.to_ascii_lowercase().as_str() {
            "x" => cols[k].1 = Some(c),
            "y" => cols[k].2 = Some(c),
            _ => {}
        }
    }
    if let Some((k, _, _)) = cols.iter().find(|c| c.1.is_none() || c.2.is_none()) {
        return Err(Error::format(
            path,
            format!(
                "header: individual {} has no x or no y column for {part}",
                order[*k]
            ),
        ));
    }
    if cols.is_empty() {
        return Err(Error::format(path, "header: no individual"));
    }
    let mut out = Frames::default();
    for (row, (line, l)) in it.enumerate() {
        let r = fields(l);
        let at = format!("row {} (line {line})", row + 1);
        let index = r
            .first()
            .and_then(|c| c.parse::<i64>().ok())
            .unwrap_or(row as i64);
        for &(k, cx, cy) in &cols {
            let (cx, cy) = (cx.unwrap_or(0), cy.unwrap_or(0));
            let name = &order[k];
            let x = num(
                path,
                &at,
                &format!("{name} {part} x"),
                r.get(cx).copied().unwrap_or(""),
            )?;
            let y = num(
                path,
                &at,
                &format!("{name} {part} y"),
                r.get(cy).copied().unwrap_or(""),
            )?;
            match (x, y) {
                (Some(x), Some(y)) => out.push(
                    index,
                    RawBird {
                        z: None,
                        id: Some(k),
                        x,
                        y,
                        at: format!("{at}, {name}"),
                    },
                ),
                (None, None) => {}
                _ => {
                    return Err(Error::format(
                        path,
                        format!("{at}: {name} {part} has only one of x and y"),
                    ))
                }
            }
        }
    }
    out.done(path, Format::Dlc)
}

fn mot(path: &Path, text: &str) -> Result<RawAnnotations> {
    let mut out = Frames::default();
    for (row, (line, l)) in lines(text).enumerate() {
        let r = fields(l);
        let at = format!("row {} (line {line})", row + 1);
        if r.len() < 6 {
            return Err(Error::format(
                path,
                format!(
                    "{at}: {} fields, a MOT line has at least 6 (frame,id,left,top,width,height)",
                    r.len()
                ),
            ));
        }
        let frame: i64 = r[0].parse().map_err(|_| {
            Error::format(
                path,
                format!("{at}, field frame: `{}` is not a frame number", r[0]),
            )
        })?;
        let id: i64 = r[1]
            .parse::<f64>()
            .ok()
            .filter(|v| v.fract() == 0.0 && v.abs() < 1e9)
            .map(|v| v as i64)
            .ok_or_else(|| {
                Error::format(
                    path,
                    format!("{at}, field id: `{}` is not an integer", r[1]),
                )
            })?;
        let mut v = [0.0; 4];
        for (i, name) in ["left", "top", "width", "height"].iter().enumerate() {
            v[i] = num(path, &at, name, r[2 + i])?
                .ok_or_else(|| Error::format(path, format!("{at}, field {name}: empty")))?;
        }
        if v[2] < 0.0 || v[3] < 0.0 {
            return Err(Error::format(path, format!("{at}: a box of negative size")));
        }
        out.push(
            frame,
            RawBird {
                z: None,
                id: (id >= 0).then_some(id as usize),
                x: v[0] + 0.5 * v[2],
                y: v[1] + 0.5 * v[3],
                at,
            },
        );
    }
    out.done(path, Format::Mot)
}

fn idtracker(path: &Path, text: &str) -> Result<RawAnnotations> {
    let mut it = lines(text);
    let (_, head) = it.next().ok_or_else(|| Error::format(path, "empty file"))?;
    let h: Vec<String> = fields(head)
        .iter()
        .map(|c| c.to_ascii_lowercase())
        .collect();
    let mut animals: Vec<(usize, usize, usize)> = Vec::new();
    for (c, name) in h.iter().enumerate() {
        if let Some(n) = name.strip_prefix('x').and_then(|n| n.parse::<usize>().ok()) {
            let cy = h
                .iter()
                .position(|o| *o == format!("y{n}"))
                .ok_or_else(|| Error::format(path, format!("header: x{n} without y{n}")))?;
            if n == 0 {
                return Err(Error::format(
                    path,
                    "header: animals count from 1 (x1, y1, ...)",
                ));
            }
            animals.push((n - 1, c, cy));
        }
    }
    let cf = h.iter().position(|c| c == "frame");
    let mut out = Frames::default();
    for (row, (line, l)) in it.enumerate() {
        let r = fields(l);
        let at = format!("row {} (line {line})", row + 1);
        let index = match cf {
            Some(c) => {
                let s = get(path, &at, &r, c, "frame")?;
                s.parse::<i64>().map_err(|_| {
                    Error::format(
                        path,
                        format!("{at}, field frame: `{s}` is not a frame number"),
                    )
                })?
            }
            None => row as i64,
        };
        for &(id, cx, cy) in &animals {
            let x = num(path, &at, &h[cx], get(path, &at, &r, cx, &h[cx])?)?;
            let y = num(path, &at, &h[cy], get(path, &at, &r, cy, &h[cy])?)?;
            match (x, y) {
                (Some(x), Some(y)) => out.push(
                    index,
                    RawBird {
                        z: None,
                        id: Some(id),
                        x,
                        y,
                        at: format!("{at}, animal {}", id + 1),
                    },
                ),
                (None, None) => {}
                _ => {
                    return Err(Error::format(
                        path,
                        format!("{at}: animal {} has only one of x and y", id + 1),
                    ))
                }
            }
        }
    }
    out.done(path, Format::IdTracker)
}

//! Reading a course file: the leader's path in the world frame (docs/formats.md §2: `x` east,
//! `y` north, `z` up) as JSON `{"units": "wingspans" | "m", "points": [[x, y, z], ...]}` or as a
//! CSV of `x,y,z` rows (an optional header line `x,y,z`; units from [`CourseOptions::units`]).
//! Gives the control points in wingspans. Every problem is one line naming the file and the point.
//!
//! [`CourseOptions::units`]: super::CourseOptions::units

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Largest number of control points of a path.
pub const MAX_POINTS: usize = 100_000;

/// Longest path, wingspans (along the straight legs between its points; 150 km for 1.5 m birds):
/// the course is sampled every [`super::spline::SAMPLE_SPACING`] wingspans in at most
/// [`super::spline::MAX_SAMPLES`] samples, and a longer path would be sampled more coarsely,
/// losing its turns (a flight longer than the path flies straight on past an open path's end, or
/// repeats a closed one).
pub const MAX_LENGTH: f64 = 100_000.0;

/// Two control points closer than this are the same point, wingspans (1.5 cm for a goose): one
/// threshold for repeated points and for a closed path's last point returning to its first
/// (a millionth of a wingspan before, so points a hair farther apart counted as distinct).
pub const REPEAT_DISTANCE: f64 = 0.01;

/// Units of a path's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PathUnits {
    /// Wingspans (the animation's own unit).
    Wingspans,
    /// Metres, divided by the wingspan in metres.
    M,
}

impl PathUnits {
    /// The word a file or flag uses.
    pub fn word(self) -> &'static str {
        match self {
            PathUnits::Wingspans => "wingspans",
            PathUnits::M => "m",
        }
    }

    /// Parses the word of a file or flag (`wingspans` or `m`).
    pub fn parse(word: &str) -> Option<PathUnits> {
        match word {
            "wingspans" => Some(PathUnits::Wingspans),
            "m" => Some(PathUnits::M),
            _ => None,
        }
    }
}

/// A path's control points, wingspans, world frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PathPoints {
    /// Control points, wingspans.
    pub points: Vec<[f64; 3]>,
    /// The last point repeats the first: the path is a closed loop (the repeat is dropped).
    pub closed: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonPath {
    units: Option<String>,
    points: JsonPoints,
}

/// The `points` array, read point by point into `[x, y, z]`: a point of another length is named
/// by its index, and reading stops after [`MAX_POINTS`] + 1 points, so memory stays a small
/// multiple of the points kept (a `Vec` per point took 8 bytes of memory per byte of file).
struct JsonPoints(Vec<[f64; 3]>);

impl<'de> Deserialize<'de> for JsonPoints {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = JsonPoints;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of [x, y, z] points")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<JsonPoints, A::Error> {
                use serde::de::Error as _;
                let mut pts = Vec::new();
                while let Some(p) = seq.next_element::<Point>()? {
                    let i = pts.len();
                    if i == MAX_POINTS {
                        return Err(A::Error::custom(format!(
                            "points: more than {MAX_POINTS} points"
                        )));
                    }
                    match p.0 {
                        Some(xyz) => pts.push(xyz),
                        None => {
                            return Err(A::Error::custom(format!(
                                "points[{i}]: {} numbers, expected [x, y, z]",
                                p.1
                            )))
                        }
                    }
                }
                Ok(JsonPoints(pts))
            }
        }
        d.deserialize_seq(Visit)
    }
}

/// One point of the `points` array, read without a heap allocation: `Some([x, y, z])`, or `None`
/// and how many numbers a point of another length held.
struct Point(Option<[f64; 3]>, usize);

impl<'de> Deserialize<'de> for Point {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Point;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a point [x, y, z]")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<Point, A::Error> {
                let mut xyz = [0.0; 3];
                let mut n = 0usize;
                while let Some(v) = seq.next_element::<f64>()? {
                    if n < 3 {
                        xyz[n] = v;
                    }
                    n += 1;
                }
                Ok(Point((n == 3).then_some(xyz), n))
            }
        }
        d.deserialize_seq(Visit)
    }
}

/// Reads `path` (JSON by content, else CSV) through [`crate::io::read_text`] (size bounds,
/// binary refusal) and parses it with [`parse_str`].
pub fn read(path: &Path, units: Option<PathUnits>, wingspan_m: f64) -> Result<PathPoints> {
    let text = crate::io::read_text(path)?;
    parse_str(path, &text, units, wingspan_m)
}

/// Parses the text of a path file (JSON by content, else CSV); `path` is only named in messages.
/// `units` is the flag's choice (`None`: the file's, or wingspans), `wingspan_m` converts metres.
pub fn parse_str(
    path: &Path,
    text: &str,
    units: Option<PathUnits>,
    wingspan_m: f64,
) -> Result<PathPoints> {
    // A byte-order mark (some spreadsheet and Windows editors write one) is not content.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let (raw, file_units) = if text.trim_start().starts_with('{') {
        let j: JsonPath = crate::io::parse_json(path, text)?;
        let u = match &j.units {
            None => None,
            Some(w) => Some(PathUnits::parse(w).ok_or_else(|| {
                Error::format(
                    path,
                    format!("units: unknown units \"{w}\"; use \"wingspans\" or \"m\""),
                )
            })?),
        };
        (j.points.0, u)
    } else {
        (read_csv(path, text)?, None)
    };
    let units = match (units, file_units) {
        (Some(a), Some(b)) if a != b => {
            return Err(Error::format(
                path,
                format!(
                    "units: the file says \"{}\" but \"{}\" was asked for; give one",
                    b.word(),
                    a.word()
                ),
            ))
        }
        (Some(a), _) => a,
        (None, Some(b)) => b,
        (None, None) => PathUnits::Wingspans,
    };
    let scale = match units {
        PathUnits::Wingspans => 1.0,
        PathUnits::M => 1.0 / wingspan_m,
    };
    check(path, raw, scale)
}

fn read_csv(path: &Path, text: &str) -> Result<Vec<[f64; 3]>> {
    let mut pts = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if pts.is_empty() && cells.iter().any(|c| c.parse::<f64>().is_err()) {
            if cells == ["x", "y", "z"] {
                continue;
            }
            if ln == 0 {
                return Err(Error::format(
                    path,
                    format!("line 1: expected the header x,y,z or three numbers, found \"{line}\""),
                ));
            }
        }
        if cells.len() != 3 {
            return Err(Error::format(
                path,
                format!(
                    "line {}: {} cells, expected x,y,z (point {})",
                    ln + 1,
                    cells.len(),
                    pts.len()
                ),
            ));
        }
        if pts.len() == MAX_POINTS {
            return Err(Error::format(
                path,
                format!("line {}: more than {MAX_POINTS} points", ln + 1),
            ));
        }
        let mut p = [0.0; 3];
        for (k, c) in cells.iter().enumerate() {
            p[k] = c.parse::<f64>().map_err(|_| {
                Error::format(
                    path,
                    format!(
                        "line {}: point {}: \"{c}\" is not a number",
                        ln + 1,
                        pts.len()
                    ),
                )
            })?;
        }
        pts.push(p);
    }
    Ok(pts)
}

/// Converts to wingspans and checks: finite, at least two distinct points, no point repeating
/// the one before, at most [`MAX_POINTS`]; a last point equal to the first closes the path.
fn check(path: &Path, raw: Vec<[f64; 3]>, scale: f64) -> Result<PathPoints> {
    if raw.len() > MAX_POINTS {
        return Err(Error::format(
            path,
            format!("points: {} points, at most {MAX_POINTS}", raw.len()),
        ));
    }
    let bound = crate::limits::MAX_COORDINATE / 10.0;
    let mut points = Vec::with_capacity(raw.len());
    for (i, p) in raw.iter().enumerate() {
        if let Some(k) = p.iter().position(|v| !v.is_finite()) {
            return Err(Error::format(
                path,
                format!("point {i}: {} is not a finite number", ["x", "y", "z"][k]),
            ));
        }
        let q = [p[0] * scale, p[1] * scale, p[2] * scale];
        if let Some(k) = q.iter().position(|v| v.abs() > bound) {
            return Err(Error::format(
                path,
                format!(
                    "point {i}: {} = {:.3e} wingspans is beyond ±{bound:e} wingspans",
                    ["x", "y", "z"][k],
                    q[k]
                ),
            ));
        }
        points.push(q);
    }
    if points.len() < 2 {
        return Err(Error::format(
            path,
            format!("points: {} point(s); a path needs at least 2", points.len()),
        ));
    }
    for i in 1..points.len() {
        if dist(points[i], points[i - 1]) < REPEAT_DISTANCE {
            return Err(Error::format(
                path,
                format!(
                    "point {i}: repeats point {} ({}): closer than {REPEAT_DISTANCE} wingspans to it; remove it",
                    i - 1,
                    show(points[i])
                ),
            ));
        }
    }
    let n = points.len();
    let closed = n >= 4 && dist(points[0], points[n - 1]) < REPEAT_DISTANCE;
    let mut length = 0.0;
    for i in 1..n {
        length += dist(points[i], points[i - 1]);
        if length > MAX_LENGTH {
            return Err(Error::format(
                path,
                format!(
                    "point {i}: the path is {length:.0} wingspans long by here, longer than the {MAX_LENGTH:.0} wingspans a path may be; cut it to the part the flock flies"
                ),
            ));
        }
    }
    if closed {
        points.pop();
    } else if n == 3 && dist(points[0], points[2]) < REPEAT_DISTANCE {
        return Err(Error::format(
            path,
            "point 2: returns to point 0; a closed path needs at least 3 distinct points",
        ));
    }
    Ok(PathPoints { points, closed })
}

/// Distance of two points, wingspans.
pub fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A point as `(x, y, z)` with one decimal, for messages.
pub fn show(p: [f64; 3]) -> String {
    format!("{:.1}, {:.1}, {:.1}", p[0], p[1], p[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("formation-course-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn json_and_csv_read_alike_and_metres_convert() {
        let j = write(
            "a.json",
            r#"{"units": "m", "points": [[0, 0, 15], [0, 150, 15], [150, 300, 30]]}"#,
        );
        let c = write("a.csv", "x,y,z\n0,0,15\n0,150,15\n150,300,30\n");
        let a = read(&j, None, 1.5).unwrap();
        let b = read(&c, Some(PathUnits::M), 1.5).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.points[2], [100.0, 200.0, 20.0]);
        assert!(!a.closed);
        let e = read(&j, Some(PathUnits::Wingspans), 1.5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("units"), "{e}");
    }

    #[test]
    fn bad_paths_name_the_point() {
        for (text, want) in [
            (r#"{"points": [[0, 0, 0]]}"#, "at least 2"),
            (
                r#"{"points": [[0, 0, 0], [0, 0, 0]]}"#,
                "point 1: repeats point 0",
            ),
            (
                r#"{"units": "feet", "points": [[0, 0, 0], [1, 0, 0]]}"#,
                "unknown units",
            ),
            (r#"{"points": [[0, 0, 0], [1, 0]]}"#, "points[1]"),
        ] {
            let e = read(&write("b.json", text), None, 1.5)
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{e}");
            assert_eq!(e.lines().count(), 1);
        }
        let e = read(&write("b.csv", "0,0,0\n1,NaN,0\n"), None, 1.5)
            .unwrap_err()
            .to_string();
        assert!(e.contains("point 1: y is not a finite number"), "{e}");
    }

    #[test]
    fn a_repeated_first_point_closes_the_path() {
        let p = read(
            &write("c.csv", "0,0,0\n10,0,0\n10,10,0\n0,10,0\n0,0,0\n"),
            None,
            1.5,
        )
        .unwrap();
        assert!(p.closed);
        assert_eq!(p.points.len(), 4);
    }
}

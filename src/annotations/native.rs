//! The native annotation JSON (docs/formats.md §4.1): `{"source", "heading", "wingspan_px", "frames":
//! [{"index", "image", "wingspan_px", "birds": [[x, y], ...]}]}` in pixels. A bird may also be an
//! object `{"id": 3, "x": .., "y": ..}`, which carries its identity across frames.

use std::path::Path;

use serde_json::Value;

use super::{Format, Heading, RawAnnotations, RawBird, RawFrame};
use crate::error::{Error, Result};

/// Reads a number field, naming it when it is not a finite number.
pub(crate) fn number(path: &Path, at: &str, v: &Value) -> Result<f64> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        _ => Err(Error::format(
            path,
            format!("{at}: expected a number, found {}", short(v)),
        )),
    }
}

/// A short rendering of a JSON value for messages.
pub(crate) fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s
    }
}

/// Reads an id: a non-negative integer.
pub(crate) fn id(path: &Path, at: &str, v: &Value) -> Result<usize> {
    v.as_u64()
        .and_then(|u| usize::try_from(u).ok())
        .ok_or_else(|| {
            Error::format(
                path,
                format!(
                    "{at}: expected a non-negative integer id, found {}",
                    short(v)
                ),
            )
        })
}

/// Parses a heading value: a string or degrees.
pub(crate) fn heading(path: &Path, at: &str, v: &Value) -> Result<Heading> {
    match v {
        Value::String(s) => {
            Heading::parse(s).map_err(|m| Error::format(path, format!("{at}: {m}")))
        }
        Value::Number(_) => Ok(Heading::Degrees(number(path, at, v)?)),
        _ => Err(Error::format(
            path,
            format!(
                "{at}: expected \"up\", \"down\", \"left\", \"right\" or degrees, found {}",
                short(v)
            ),
        )),
    }
}

/// Refuses native annotations beyond the size limits before they are parsed into memory: the
/// frames are counted and each frame's birds are counted while skipped, so a frame of 10⁷ birds
/// is refused in the memory of its text, not of its parsed tree. A file whose structure is wrong
/// passes here and gets the exact message from [`parse`].
pub(crate) fn check_counts(path: &Path, text: &str) -> Result<()> {
    use crate::limits::{MAX_ANNOTATED_BIRDS, MAX_ANNOTATED_FRAMES};
    use serde::de::{Deserializer, IgnoredAny, SeqAccess, Visitor};
    const TOO_MANY: &str = "formation: too many birds in one frame";

    struct Birds;
    impl<'de> serde::Deserialize<'de> for Birds {
        fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Birds, D::Error> {
            struct Count;
            impl<'de> Visitor<'de> for Count {
                type Value = Birds;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("an array of birds")
                }
                fn visit_seq<A: SeqAccess<'de>>(
                    self,
                    mut seq: A,
                ) -> std::result::Result<Birds, A::Error> {
                    let mut n = 0usize;
                    while seq.next_element::<IgnoredAny>()?.is_some() {
                        n += 1;
                        if n > MAX_ANNOTATED_BIRDS {
                            return Err(serde::de::Error::custom(TOO_MANY));
                        }
                    }
                    Ok(Birds)
                }
            }
            d.deserialize_seq(Count)
        }
    }
    #[derive(serde::Deserialize)]
    struct Frame {
        #[serde(default)]
        #[allow(dead_code)]
        birds: Option<Birds>,
    }
    /// The number of frames; fails with `TOO_MANY k` at the first frame `k` over the limit.
    struct Frames(usize);
    impl<'de> serde::Deserialize<'de> for Frames {
        fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Frames, D::Error> {
            struct Each;
            impl<'de> Visitor<'de> for Each {
                type Value = Frames;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("an array of frames")
                }
                fn visit_seq<A: SeqAccess<'de>>(
                    self,
                    mut seq: A,
                ) -> std::result::Result<Frames, A::Error> {
                    let mut k = 0usize;
                    loop {
                        match seq.next_element::<Frame>() {
                            Ok(Some(_)) => k += 1,
                            Ok(None) => return Ok(Frames(k)),
                            Err(e) if e.to_string().starts_with(TOO_MANY) => {
                                return Err(serde::de::Error::custom(format!("{TOO_MANY} {k}")))
                            }
                            Err(e) => return Err(e),
                        }
                    }
                }
            }
            d.deserialize_seq(Each)
        }
    }
    #[derive(serde::Deserialize)]
    struct File {
        frames: Frames,
    }
    match serde_json::from_str::<File>(text) {
        Err(e) if e.to_string().starts_with(TOO_MANY) => {
            let k = e.to_string()[TOO_MANY.len()..]
                .split_whitespace()
                .next()
                .unwrap_or("?")
                .to_string();
            Err(Error::format(
                path,
                format!(
                    "frames[{k}]: more than {MAX_ANNOTATED_BIRDS} birds marked, at most {MAX_ANNOTATED_BIRDS} per frame"
                ),
            ))
        }
        Ok(f) if f.frames.0 > MAX_ANNOTATED_FRAMES => Err(Error::format(
            path,
            format!(
                "{} annotated frames, at most {MAX_ANNOTATED_FRAMES}; annotate a subset (a few dozen frames are plenty)",
                f.frames.0
            ),
        )),
        _ => Ok(()),
    }
}

pub(crate) fn parse(path: &Path, text: &str) -> Result<RawAnnotations> {
    let v: Value = crate::io::parse_json(path, text)?;
    let obj = v
        .as_object()
        .ok_or_else(|| Error::format(path, "top level: expected a JSON object"))?;
    let source = match obj.get("source") {
        None | Some(Value::Null) => None,
        Some(Value::String(s)) => Some(s.clone()),
        Some(other) => {
            return Err(Error::format(
                path,
                format!("source: expected text, found {}", short(other)),
            ))
        }
    };
    let heading = match obj.get("heading") {
        None | Some(Value::Null) => None,
        Some(h) => Some(heading(path, "heading", h)?),
    };
    let wingspan_px = match obj.get("wingspan_px") {
        None | Some(Value::Null) => None,
        Some(w) => Some(number(path, "wingspan_px", w)?),
    };
    let fps = match obj.get("fps") {
        None | Some(Value::Null) => None,
        Some(f) => {
            let f = number(path, "fps", f)?;
            if !(f.is_finite() && f > 0.0 && f <= 100_000.0) {
                return Err(Error::format(
                    path,
                    format!(
                        "fps: {f}: must be a positive number of frames per second, at most 100000"
                    ),
                ));
            }
            Some(f)
        }
    };
    let frames_v = obj
        .get("frames")
        .and_then(|f| f.as_array())
        .ok_or_else(|| Error::format(path, "frames: expected an array of frames"))?;
    if frames_v.is_empty() {
        return Err(Error::format(
            path,
            "frames: the array is empty, no frame to read",
        ));
    }
    let mut frames = Vec::with_capacity(frames_v.len());
    for (k, fv) in frames_v.iter().enumerate() {
        let at = format!("frames[{k}]");
        let fo = fv.as_object().ok_or_else(|| {
            Error::format(path, format!("{at}: expected an object with \"birds\""))
        })?;
        let index = match fo.get("index") {
            None | Some(Value::Null) => k as i64,
            Some(i) => i.as_i64().ok_or_else(|| {
                Error::format(
                    path,
                    format!("{at}.index: expected an integer, found {}", short(i)),
                )
            })?,
        };
        let image = match fo.get("image") {
            Some(Value::String(s)) => Some(s.clone()),
            _ => None,
        };
        let fw = match fo.get("wingspan_px") {
            None | Some(Value::Null) => None,
            Some(w) => Some(number(path, &format!("{at}.wingspan_px"), w)?),
        };
        let birds_v = fo.get("birds").and_then(|b| b.as_array()).ok_or_else(|| {
            Error::format(
                path,
                format!("{at}.birds: expected an array of [x, y] points"),
            )
        })?;
        let mut birds = Vec::with_capacity(birds_v.len());
        for (j, bv) in birds_v.iter().enumerate() {
            let bat = format!("{at}.birds[{j}]");
            let bird = match bv {
                Value::Array(a) if a.len() == 2 => RawBird {
                    z: None,
                    id: None,
                    x: number(path, &format!("{bat}[0] (x)"), &a[0])?,
                    y: number(path, &format!("{bat}[1] (y)"), &a[1])?,
                    at: bat,
                },
                Value::Object(o) => {
                    let get = |name: &str| {
                        o.get(name).ok_or_else(|| {
                            Error::format(path, format!("{bat}: missing field \"{name}\""))
                        })
                    };
                    RawBird {
                        id: match o.get("id") {
                            None | Some(Value::Null) => None,
                            Some(i) => Some(id(path, &format!("{bat}.id"), i)?),
                        },
                        x: number(path, &format!("{bat}.x"), get("x")?)?,
                        y: number(path, &format!("{bat}.y"), get("y")?)?,
                        z: match o.get("z") {
                            None | Some(Value::Null) => None,
                            Some(z) => Some(number(path, &format!("{bat}.z"), z)?),
                        },
                        at: bat,
                    }
                }
                other => {
                    return Err(Error::format(
                        path,
                        format!(
                            "{bat}: expected [x, y] or {{\"id\", \"x\", \"y\"}}, found {}",
                            short(other)
                        ),
                    ))
                }
            };
            birds.push(bird);
        }
        frames.push(RawFrame {
            index,
            image,
            wingspan_px: fw,
            at: format!("{at}.wingspan_px"),
            birds,
        });
    }
    Ok(RawAnnotations {
        format: Format::Native,
        source,
        heading,
        wingspan_px,
        fps,
        y_up: false,
        is_csv: false,
        frames,
    })
}

//! The one place that tells formation's own files apart by content: the format tags of the
//! params and animation files, and what any other JSON document looks like (a shape, a target,
//! annotations). Every reader that must say "this is not the file you meant" asks here, so the
//! messages agree. Annotation formats (native, Labelme, CSV) are told apart by
//! [`crate::annotations::detect`], which asks here first.

use serde_json::Value;

/// Format tag of params files (docs/formats.md §4.2).
pub const PARAMS_FORMAT: &str = "formation-params/1";

/// Format tag of animation files (docs/formats.md §4.4).
pub const ANIMATION_FORMAT: &str = "formation-animation/1";

/// What a JSON document is, judged by its `"format"` tag and its top-level fields.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Kind {
    /// `"format": "formation-params/1"`.
    Params,
    /// `"format": "formation-animation/1"`.
    Animation,
    /// Another `"format"` tag (e.g. an older version).
    OtherFormat(String),
    /// No tag, a `"birds"` array: a shape (docs/formats.md §4.3).
    Shape,
    /// No tag, `"x"` and `"xi"`: a target of `solve`.
    Target,
    /// No tag, `"shapes"`: Labelme annotations.
    Labelme,
    /// No tag, `"frames"`: native annotations.
    NativeAnnotations,
    /// Not a JSON object, or none of the above.
    Unknown,
}

impl Kind {
    /// How messages name the kind: `a "formation-params/1" file`, `a shape file`.
    pub fn describe(&self) -> String {
        match self {
            Kind::Params => format!("a \"{PARAMS_FORMAT}\" file"),
            Kind::Animation => format!("a \"{ANIMATION_FORMAT}\" file"),
            Kind::OtherFormat(t) => format!("a \"{t}\" file"),
            Kind::Shape => "a shape file".into(),
            Kind::Target => "a target file".into(),
            Kind::Labelme => "Labelme annotations".into(),
            Kind::NativeAnnotations => "annotations".into(),
            Kind::Unknown => "no \"format\" field".into(),
        }
    }
}

/// The kind of a parsed JSON document.
pub fn json_kind(v: &Value) -> Kind {
    let Some(obj) = v.as_object() else {
        return Kind::Unknown;
    };
    match obj.get("format").and_then(|f| f.as_str()) {
        Some(PARAMS_FORMAT) => Kind::Params,
        Some(ANIMATION_FORMAT) => Kind::Animation,
        Some(t) => Kind::OtherFormat(t.to_string()),
        None if obj.contains_key("shapes") => Kind::Labelme,
        None if obj.contains_key("frames") => Kind::NativeAnnotations,
        None if obj.get("birds").is_some_and(|b| b.is_array()) => Kind::Shape,
        None if obj.contains_key("x") && obj.contains_key("xi") => Kind::Target,
        None => Kind::Unknown,
    }
}

/// The kind of a text, `None` when it is not JSON (a CSV file, say). Cheap for texts that cannot
/// be one of formation's tagged files.
pub fn text_kind(text: &str) -> Option<Kind> {
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if !(t.starts_with('{') || t.starts_with('[')) {
        return None;
    }
    serde_json::from_str::<Value>(t).ok().map(|v| json_kind(&v))
}

/// What the file or directory at `path` holds: a directory is Labelme annotations (a JSON file
/// per frame), a file is judged by [`text_kind`] ([`Kind::Unknown`] for text that is not JSON,
/// e.g. CSV annotations).
pub fn path_kind(path: &std::path::Path) -> crate::error::Result<Kind> {
    if path.is_dir() {
        return Ok(Kind::Labelme);
    }
    Ok(stream_kind(path)?.unwrap_or(Kind::Unknown))
}

/// [`text_kind`] of the file at `path`, judged while it is read ([`crate::io::TextInput`]): only
/// the top-level fields that tell the kinds apart are kept, so sniffing a large animation takes
/// no more memory than a chunk of it. Errors of reading (not text, too big) are errors; text
/// that is not JSON is `None`.
pub fn stream_kind(path: &std::path::Path) -> crate::error::Result<Option<Kind>> {
    let mut input = crate::io::TextInput::open(path)?;
    let head =
        serde_json::from_reader::<_, Head>(std::io::BufReader::with_capacity(1 << 16, &mut input));
    if let Some(e) = input.error() {
        return Err(e);
    }
    Ok(head.ok().and_then(|h| h.kind))
}

/// The top-level facts [`json_kind`] looks at, gathered without keeping the values.
struct Head {
    /// `None` for a document that is neither an object nor an array.
    kind: Option<Kind>,
}

impl<'de> serde::Deserialize<'de> for Head {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Head, D::Error> {
        d.deserialize_any(HeadVisitor)
    }
}

struct HeadVisitor;

/// Skips any value, telling whether it was an array.
struct IsArray(bool);

impl<'de> serde::Deserialize<'de> for IsArray {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<IsArray, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = IsArray;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("any value")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<IsArray, A::Error> {
                while a.next_element::<serde::de::IgnoredAny>()?.is_some() {}
                Ok(IsArray(true))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<IsArray, A::Error> {
                while a
                    .next_entry::<serde::de::IgnoredAny, serde::de::IgnoredAny>()?
                    .is_some()
                {}
                Ok(IsArray(false))
            }
            fn visit_bool<E>(self, _: bool) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
            fn visit_i64<E>(self, _: i64) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
            fn visit_u64<E>(self, _: u64) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
            fn visit_f64<E>(self, _: f64) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
            fn visit_str<E>(self, _: &str) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
            fn visit_unit<E>(self) -> Result<IsArray, E> {
                Ok(IsArray(false))
            }
        }
        d.deserialize_any(V)
    }
}

/// A string value, or `None` for any other value (skipped).
struct MaybeStr(Option<String>);

impl<'de> serde::Deserialize<'de> for MaybeStr {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<MaybeStr, D::Error> {
        match serde_json::Value::deserialize(d)? {
            // Small in any real file; a huge non-string value is rare and only costs its parse.
            Value::String(s) => Ok(MaybeStr(Some(s))),
            _ => Ok(MaybeStr(None)),
        }
    }
}

impl<'de> serde::de::Visitor<'de> for HeadVisitor {
    type Value = Head;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON document")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut a: A) -> Result<Head, A::Error> {
        let mut format: Option<Option<String>> = None;
        let (mut shapes, mut frames, mut birds, mut x, mut xi) =
            (false, false, false, false, false);
        while let Some(key) = a.next_key::<String>()? {
            match key.as_str() {
                "format" => format = Some(a.next_value::<MaybeStr>()?.0),
                "birds" => birds = a.next_value::<IsArray>()?.0,
                other => {
                    match other {
                        "shapes" => shapes = true,
                        "frames" => frames = true,
                        "x" => x = true,
                        "xi" => xi = true,
                        _ => {}
                    }
                    a.next_value::<serde::de::IgnoredAny>()?;
                }
            }
        }
        let kind = match format.flatten().as_deref() {
            Some(PARAMS_FORMAT) => Kind::Params,
            Some(ANIMATION_FORMAT) => Kind::Animation,
            Some(t) => Kind::OtherFormat(t.to_string()),
            None if shapes => Kind::Labelme,
            None if frames => Kind::NativeAnnotations,
            None if birds => Kind::Shape,
            None if x && xi => Kind::Target,
            None => Kind::Unknown,
        };
        Ok(Head { kind: Some(kind) })
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> Result<Head, A::Error> {
        while a.next_element::<serde::de::IgnoredAny>()?.is_some() {}
        Ok(Head {
            kind: Some(Kind::Unknown),
        })
    }
    fn visit_bool<E>(self, _: bool) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
    fn visit_i64<E>(self, _: i64) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
    fn visit_u64<E>(self, _: u64) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
    fn visit_f64<E>(self, _: f64) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
    fn visit_str<E>(self, _: &str) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
    fn visit_unit<E>(self) -> Result<Head, E> {
        Ok(Head { kind: None })
    }
}

/// Whether `text` is a params file (`"format": "formation-params/1"`); cheap for annotations,
/// which never carry the tag.
pub fn is_params(text: &str) -> bool {
    text.contains(PARAMS_FORMAT) && text_kind(text) == Some(Kind::Params)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds() {
        let k = |s: &str| text_kind(s);
        assert_eq!(k(r#"{"format": "formation-params/1"}"#), Some(Kind::Params));
        assert_eq!(
            k("\u{feff} {\"format\": \"formation-animation/1\"}"),
            Some(Kind::Animation)
        );
        assert_eq!(
            k(r#"{"format": "formation-animation/0"}"#),
            Some(Kind::OtherFormat("formation-animation/0".into()))
        );
        assert_eq!(k(r#"{"birds": [{"x": 0, "y": 0}]}"#), Some(Kind::Shape));
        assert_eq!(k(r#"{"x": [0], "xi": [1]}"#), Some(Kind::Target));
        assert_eq!(k(r#"{"shapes": []}"#), Some(Kind::Labelme));
        assert_eq!(k(r#"{"frames": []}"#), Some(Kind::NativeAnnotations));
        assert_eq!(k("frame,bird,x,y\n"), None);
        assert_eq!(k("{ truncated"), None);
    }

    #[test]
    fn params_files_are_told_from_annotations() {
        assert!(is_params(
            r#"{"format": "formation-params/1", "frames": []}"#
        ));
        assert!(!is_params(
            r#"{"frames": [], "source": "formation-params/1"}"#
        ));
        assert!(!is_params("frame,x,y\n"));
    }
}

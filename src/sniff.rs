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
    let text = crate::io::read_text(path)?;
    Ok(text_kind(&text).unwrap_or(Kind::Unknown))
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

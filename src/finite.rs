//! No NaN or infinity in an output file. `serde_json` silently writes a non-finite
//! number as `null`, and CSV/glTF would carry `NaN`/`inf`; every writer therefore checks first.
//! [`check_serialize`] walks any `Serialize` value the way a serializer would and reports the
//! first non-finite number by its path (`frames[12].x[3]`), which the writers turn into
//! [`crate::Error::Internal`] (a non-finite result is the tool's failure, exit 1).

use std::fmt;

use serde::ser::{self, Serialize};

use crate::error::{Error, Result};

/// Checks that every floating-point number inside `value` is finite; `what` names the output in
/// the error (e.g. the file being written).
pub fn check_serialize<T: Serialize + ?Sized>(what: &str, value: &T) -> Result<()> {
    let mut c = Checker { path: Vec::new() };
    match value.serialize(&mut c) {
        Ok(()) => Ok(()),
        Err(NonFinite(msg)) => Err(Error::Internal(format!(
            "{what}: refusing to write a non-finite number at {msg}"
        ))),
    }
}

/// Pretty JSON text of `value` for stdout (the commands' JSON output), refusing non-finite numbers like
/// [`crate::io::write_json_atomic`] does for files.
pub fn to_json_pretty<T: Serialize + ?Sized>(what: &str, value: &T) -> Result<String> {
    check_serialize(what, value)?;
    serde_json::to_string_pretty(value)
        .map_err(|e| Error::Internal(format!("serialising {what}: {e}")))
}

/// Checks a slice of numbers, naming `field` and the index of the first non-finite one.
pub fn check_slice(what: &str, field: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::Internal(format!(
            "{what}: refusing to write a non-finite number at {field}[{i}] ({})",
            values[i]
        ))),
    }
}

#[derive(Debug)]
struct NonFinite(String);

impl fmt::Display for NonFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NonFinite {}

impl ser::Error for NonFinite {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        NonFinite(msg.to_string())
    }
}

enum Seg {
    Field(&'static str),
    Key(String),
    Index(usize),
}

struct Checker {
    path: Vec<Seg>,
}

impl Checker {
    fn path_string(&self) -> String {
        let mut s = String::new();
        for seg in &self.path {
            match seg {
                Seg::Field(f) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(f);
                }
                Seg::Key(k) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                Seg::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        if s.is_empty() {
            s.push_str("the top level");
        }
        s
    }

    fn float(&self, v: f64) -> Result<(), NonFinite> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(NonFinite(format!("{} ({v})", self.path_string())))
        }
    }
}

type R = Result<(), NonFinite>;

impl<'a> ser::Serializer for &'a mut Checker {
    type Ok = ();
    type Error = NonFinite;
    type SerializeSeq = Seq<'a>;
    type SerializeTuple = Seq<'a>;
    type SerializeTupleStruct = Seq<'a>;
    type SerializeTupleVariant = Seq<'a>;
    type SerializeMap = Map<'a>;
    type SerializeStruct = Self;
    type SerializeStructVariant = Self;

    fn serialize_bool(self, _: bool) -> R {
        Ok(())
    }
    fn serialize_i8(self, _: i8) -> R {
        Ok(())
    }
    fn serialize_i16(self, _: i16) -> R {
        Ok(())
    }
    fn serialize_i32(self, _: i32) -> R {
        Ok(())
    }
    fn serialize_i64(self, _: i64) -> R {
        Ok(())
    }
    fn serialize_u8(self, _: u8) -> R {
        Ok(())
    }
    fn serialize_u16(self, _: u16) -> R {
        Ok(())
    }
    fn serialize_u32(self, _: u32) -> R {
        Ok(())
    }
    fn serialize_u64(self, _: u64) -> R {
        Ok(())
    }
    fn serialize_f32(self, v: f32) -> R {
        self.float(v as f64)
    }
    fn serialize_f64(self, v: f64) -> R {
        self.float(v)
    }
    fn serialize_char(self, _: char) -> R {
        Ok(())
    }
    fn serialize_str(self, _: &str) -> R {
        Ok(())
    }
    fn serialize_bytes(self, _: &[u8]) -> R {
        Ok(())
    }
    fn serialize_none(self) -> R {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> R {
        v.serialize(self)
    }
    fn serialize_unit(self) -> R {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> R {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, v: &T) -> R {
        v.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        v: &T,
    ) -> R {
        self.path.push(Seg::Field(variant));
        v.serialize(&mut *self)?;
        self.path.pop();
        Ok(())
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq { c: self, i: 0 })
    }
    fn serialize_tuple(self, _: usize) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq { c: self, i: 0 })
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq { c: self, i: 0 })
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Seq<'a>, NonFinite> {
        Ok(Seq { c: self, i: 0 })
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Map<'a>, NonFinite> {
        Ok(Map { c: self })
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self, NonFinite> {
        Ok(self)
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self, NonFinite> {
        Ok(self)
    }
}

struct Seq<'a> {
    c: &'a mut Checker,
    i: usize,
}

impl Seq<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        self.c.path.push(Seg::Index(self.i));
        v.serialize(&mut *self.c)?;
        self.c.path.pop();
        self.i += 1;
        Ok(())
    }
}

impl ser::SerializeSeq for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        self.element(v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTuple for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        self.element(v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTupleStruct for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        self.element(v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeTupleVariant for Seq<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        self.element(v)
    }
    fn end(self) -> R {
        Ok(())
    }
}

struct Map<'a> {
    c: &'a mut Checker,
}

impl ser::SerializeMap for Map<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> R {
        // Keys are rendered for the path only (strings as they are, anything else as JSON).
        let name = serde_json::to_value(key)
            .ok()
            .map(|v| match v {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            })
            .unwrap_or_else(|| "?".to_string());
        self.c.path.push(Seg::Key(name));
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> R {
        v.serialize(&mut *self.c)?;
        self.c.path.pop();
        Ok(())
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeStruct for &mut Checker {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, v: &T) -> R {
        self.path.push(Seg::Field(key));
        v.serialize(&mut **self)?;
        self.path.pop();
        Ok(())
    }
    fn end(self) -> R {
        Ok(())
    }
}

impl ser::SerializeStructVariant for &mut Checker {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, v: &T) -> R {
        self.path.push(Seg::Field(key));
        v.serialize(&mut **self)?;
        self.path.pop();
        Ok(())
    }
    fn end(self) -> R {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(serde::Serialize)]
    struct Inner {
        v: Vec<f64>,
        o: Option<f64>,
    }

    #[derive(serde::Serialize)]
    struct Outer {
        name: String,
        frames: Vec<Inner>,
        pairs: Vec<[f64; 2]>,
        map: BTreeMap<String, f64>,
    }

    fn outer() -> Outer {
        Outer {
            name: "x".into(),
            frames: vec![
                Inner {
                    v: vec![1.0, 2.0],
                    o: None,
                },
                Inner {
                    v: vec![3.0, 4.0],
                    o: Some(5.0),
                },
            ],
            pairs: vec![[0.0, 1.0]],
            map: BTreeMap::from([("a".to_string(), 1.0)]),
        }
    }

    #[test]
    fn finite_values_pass() {
        check_serialize("out.json", &outer()).unwrap();
    }

    #[test]
    fn first_non_finite_is_named_by_its_path() {
        let mut o = outer();
        o.frames[1].v[1] = f64::NAN;
        let e = check_serialize("out.json", &o).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert_eq!(
            e.to_string(),
            "internal error: out.json: refusing to write a non-finite number at frames[1].v[1] (NaN)"
        );
        let mut o = outer();
        o.frames[1].o = Some(f64::INFINITY);
        let e = check_serialize("out.json", &o).unwrap_err().to_string();
        assert!(e.ends_with("at frames[1].o (inf)"), "{e}");
        let mut o = outer();
        o.pairs[0][1] = f64::NEG_INFINITY;
        let e = check_serialize("out.json", &o).unwrap_err().to_string();
        assert!(e.ends_with("at pairs[0][1] (-inf)"), "{e}");
        let mut o = outer();
        o.map.insert("b".into(), f64::NAN);
        let e = check_serialize("out.json", &o).unwrap_err().to_string();
        assert!(e.ends_with("at map.b (NaN)"), "{e}");
    }

    #[test]
    fn slices_name_the_index() {
        check_slice("f.csv", "x", &[1.0, 2.0]).unwrap();
        let e = check_slice("f.csv", "x", &[1.0, f64::NAN]).unwrap_err();
        assert!(e.to_string().contains("x[1] (NaN)"));
    }
}

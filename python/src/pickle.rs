//! The pickled form of `Params`, `Animation` and `Annotations` (their `__reduce__`), so that
//! `pickle`, `copy`, `multiprocessing`, joblib and Dask can move them between processes.
//!
//! The round trip is exact: `Params` and `Annotations` go as their JSON (serde_json with
//! `float_roundtrip` writes the shortest text that reads back as the same `f64`). An
//! `Animation` does not go as its JSON file, which rounds the frames to the file's precision
//! (1e-5 wingspans, 1e-6 radians; an animation read from a file in metres, or resampled, holds
//! finer values): it goes as a JSON header (everything but the frames, and the run's options
//! that `Animation.write` uses) followed by the frames' raw little-endian `f64` bits, 8 bytes a
//! value (a NaN keeps its bits, −0 its sign), written and read without a text parser.
//!
//! Layout of an animation's state: [`ANIMATION_TAG`], then three sections, each a little-endian
//! `u64` byte count and its bytes: the animation JSON without frames, the options JSON, the
//! frames. The frames section is a `u64` frame count, then per frame `t` (`f64`) and, for each
//! of `x y z heading speed bank pitch e xi wing_phase` in that order, a `u64` value count
//! (`u64::MAX` for an optional field the frame does not have) and that many `f64`.

use formation::animation::{Animation, Frame};
use formation::pipeline::Config;

/// The first bytes of a pickled animation's state (a version for later layouts).
pub const ANIMATION_TAG: &[u8] = b"formation-animation-state/1\n";

/// Marks an optional per-bird field a frame does not have.
const ABSENT: u64 = u64::MAX;

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_values(out: &mut Vec<u8>, v: Option<&[f64]>) {
    match v {
        None => put_u64(out, ABSENT),
        Some(v) => {
            put_u64(out, v.len() as u64);
            out.reserve(v.len() * 8);
            for x in v {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
}

fn put_section(out: &mut Vec<u8>, bytes: &[u8]) {
    put_u64(out, bytes.len() as u64);
    out.extend_from_slice(bytes);
}

/// The state of an animation and the options it was made with.
pub fn animation_state(anim: &Animation, config: &Config) -> Result<Vec<u8>, String> {
    let header = serde_json::to_vec(&anim.with_frames(Vec::new())).map_err(|e| e.to_string())?;
    let options = serde_json::to_vec(config).map_err(|e| e.to_string())?;
    let values: usize = anim
        .frames
        .first()
        .map_or(0, |_| anim.frames.len() * (8 + 10 * (8 + 8 * anim.birds)));
    let mut frames = Vec::with_capacity(8 + values);
    put_u64(&mut frames, anim.frames.len() as u64);
    for f in &anim.frames {
        frames.extend_from_slice(&f.t.to_le_bytes());
        for v in [&f.x, &f.y, &f.z, &f.heading, &f.speed] {
            put_values(&mut frames, Some(v));
        }
        for v in [&f.bank, &f.pitch, &f.e, &f.xi, &f.wing_phase] {
            put_values(&mut frames, v.as_deref());
        }
    }
    let mut out =
        Vec::with_capacity(ANIMATION_TAG.len() + header.len() + options.len() + frames.len() + 24);
    out.extend_from_slice(ANIMATION_TAG);
    put_section(&mut out, &header);
    put_section(&mut out, &options);
    put_section(&mut out, &frames);
    Ok(out)
}

/// Reads a state back; `Err` says what is wrong with it (a truncated or foreign byte string).
struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if n > self.bytes.len() {
            return Err(format!(
                "truncated: {n} bytes wanted, {} left",
                self.bytes.len()
            ));
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }

    fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }

    fn section(&mut self) -> Result<&'a [u8], String> {
        let n = self.u64()?;
        let n = usize::try_from(n).map_err(|_| format!("a section of {n} bytes"))?;
        self.take(n)
    }

    fn values(&mut self) -> Result<Option<Vec<f64>>, String> {
        let n = self.u64()?;
        if n == ABSENT {
            return Ok(None);
        }
        let n = usize::try_from(n)
            .ok()
            .filter(|&n| n <= self.bytes.len() / 8)
            .ok_or_else(|| format!("truncated: {n} values, {} bytes left", self.bytes.len()))?;
        let b = self.take(n * 8)?;
        Ok(Some(
            b.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect(),
        ))
    }

    fn required(&mut self, field: &str) -> Result<Vec<f64>, String> {
        self.values()?
            .ok_or_else(|| format!("frame without its `{field}` values"))
    }
}

/// The animation and options of a state written by [`animation_state`].
pub fn animation_from_state(bytes: &[u8]) -> Result<(Animation, Config), String> {
    let rest = bytes
        .strip_prefix(ANIMATION_TAG)
        .ok_or("not the pickled state of a formation.Animation of this version")?;
    let mut r = Reader { bytes: rest };
    let header = r.section()?;
    let options = r.section()?;
    let frames = r.section()?;
    if !r.bytes.is_empty() {
        return Err(format!("{} bytes after the frames", r.bytes.len()));
    }
    let anim: Animation = serde_json::from_slice(header).map_err(|e| format!("header: {e}"))?;
    let config: Config = serde_json::from_slice(options).map_err(|e| format!("options: {e}"))?;
    let mut r = Reader { bytes: frames };
    let n = r.u64()?;
    let n = usize::try_from(n)
        .ok()
        .filter(|&n| n <= r.bytes.len() / 8)
        .ok_or_else(|| format!("truncated: {n} frames"))?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let t = r.f64()?;
        out.push(Frame {
            t,
            x: r.required("x")?,
            y: r.required("y")?,
            z: r.required("z")?,
            heading: r.required("heading")?,
            speed: r.required("speed")?,
            bank: r.values()?,
            pitch: r.values()?,
            e: r.values()?,
            xi: r.values()?,
            wing_phase: r.values()?,
        });
    }
    if !r.bytes.is_empty() {
        return Err(format!("{} bytes after the last frame", r.bytes.len()));
    }
    Ok((anim.with_frames(out), config))
}

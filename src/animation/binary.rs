//! Frames in a binary file beside the animation file: the animation JSON keeps everything but
//! its frames (stages, key shapes, formations, the savings model, ...) and names the binary file
//! that holds them in single precision, about 40 bytes a bird-frame against about 90 as JSON text.
//!
//! Layout (little-endian): the 16 bytes `formation-frames`, then one record per frame: `t` as a
//! 64-bit float, then for each field the file's `fields` list names, in that order, one 32-bit
//! float per bird. A frame without an optional field (`bank`, `pitch`, `e`, `xi`,
//! `wing_phase`) holds NaN for each of its birds. The values are the animation file's (rounded
//! to its precision, in its units and up axis) in single precision. Last, the pair's id: 8 bytes,
//! the [`FramesHash`] of everything before them, which the animation file's `frames_file.id`
//! repeats, so that an animation file and a frames file of different runs (two runs writing the
//! same name at once, or a file copied over from another run) are refused as a pair rather than
//! read as one animation. The id depends only on the bytes, so equal runs still write equal
//! files. Files of the first version (`formation-frames/1`, no id) are still read.
//! docs/formats.md has the reading recipe for NumPy.

use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{precision, Animation, Frame};
use crate::error::{Error, Result};

/// The frames file's format tag, in the animation file's `frames_file.format`.
pub const FRAMES_FORMAT: &str = "formation-frames/2";

/// The first version's tag: no id, no trailer; still read.
pub const FRAMES_FORMAT_V1: &str = "formation-frames/1";

/// Bytes of the id at the end of a frames file of [`FRAMES_FORMAT`].
const ID_BYTES: u64 = 8;

/// The first bytes of a frames file.
pub const MAGIC: &[u8; 16] = b"formation-frames";

/// What the animation file says of its frames file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramesFile {
    /// Always [`FRAMES_FORMAT`].
    pub format: String,
    /// The frames file's name, in the animation file's directory.
    pub path: String,
    /// Number of frames (records).
    pub frames: usize,
    /// The fields of each record after `t`, in order (names of [`Frame::FIELDS`], the first
    /// [`Frame::REQUIRED`] among them).
    pub fields: Vec<String>,
    /// The pair's id, 16 lowercase hexadecimal digits: the frames file's last 8 bytes (a
    /// little-endian [`FramesHash`] of the bytes before them). Absent in the first version.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
}

/// A 64-bit hash of a byte stream, the id of a frames file: words of 8 bytes each go through a
/// multiply–xorshift step (a bijection of the state, so any one word changed changes the
/// hash), the length and a final mix close it. Not cryptographic: it tells apart the files of
/// different runs (2⁻⁶⁴ to miss), not a forger. The same for any split of the same bytes into
/// [`FramesHash::update`] calls; about 2 GB/s.
#[derive(Debug, Clone)]
pub struct FramesHash {
    state: u64,
    tail: [u8; 8],
    tail_len: usize,
    len: u64,
}

impl Default for FramesHash {
    fn default() -> Self {
        FramesHash {
            state: u64::from_le_bytes(*b"frames/2"),
            tail: [0; 8],
            tail_len: 0,
            len: 0,
        }
    }
}

impl FramesHash {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;

    fn mix(state: u64, word: u64) -> u64 {
        let x = (state ^ word).wrapping_mul(Self::K);
        x ^ (x >> 32)
    }

    /// Adds `bytes` to the stream.
    pub fn update(&mut self, mut bytes: &[u8]) {
        self.len += bytes.len() as u64;
        if self.tail_len > 0 {
            let take = (8 - self.tail_len).min(bytes.len());
            self.tail[self.tail_len..self.tail_len + take].copy_from_slice(&bytes[..take]);
            self.tail_len += take;
            bytes = &bytes[take..];
            if self.tail_len < 8 {
                return;
            }
            self.state = Self::mix(self.state, u64::from_le_bytes(self.tail));
            self.tail_len = 0;
        }
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            let w: [u8; 8] = w.try_into().unwrap_or_default();
            self.state = Self::mix(self.state, u64::from_le_bytes(w));
        }
        let rest = words.remainder();
        self.tail[..rest.len()].copy_from_slice(rest);
        self.tail_len = rest.len();
    }

    /// The hash of the bytes so far.
    pub fn finish(&self) -> u64 {
        let mut s = self.state;
        if self.tail_len > 0 {
            let mut last = [0u8; 8];
            last[..self.tail_len].copy_from_slice(&self.tail[..self.tail_len]);
            s = Self::mix(s, u64::from_le_bytes(last));
        }
        s = Self::mix(s, self.len);
        // splitmix64's finaliser: every bit of the state reaches every bit of the id.
        s = (s ^ (s >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        s = (s ^ (s >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        s ^ (s >> 31)
    }
}

/// A writer that hashes what goes through it.
struct Hashing<'a, W: Write> {
    inner: &'a mut W,
    hash: FramesHash,
}

impl<W: Write> Write for Hashing<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hash.update(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// The frames file written beside the animation file `json`: its name with the extension
/// `.frames` (`flock.json` → `flock.frames`).
pub fn frames_path(json: &Path) -> PathBuf {
    json.with_extension("frames")
}

/// Bytes of one record of `birds` birds and `fields` fields.
fn record_bytes(birds: usize, fields: usize) -> Option<u64> {
    (birds as u64)
        .checked_mul(fields as u64)?
        .checked_mul(4)?
        .checked_add(8)
}

/// Writes `anim`'s frames to `out` (buffered: records are written a field at a time), the file
/// that will be `frames_target` (see the module's layout), then the id, and returns what the
/// animation file says of them (`path` = the target's file name, `id` the file's).
/// A value that is not finite is an error naming its frame, bird and field. Nothing is moved into
/// place: the caller commits both files together.
pub fn write_frames(
    anim: &Animation,
    out: &mut impl Write,
    frames_target: &Path,
) -> std::io::Result<FramesFile> {
    let mut out = Hashing {
        inner: out,
        hash: FramesHash::default(),
    };
    let present: Vec<usize> = (0..Frame::FIELDS.len())
        .filter(|&k| k < Frame::REQUIRED || anim.frames.iter().any(|f| f.values(k).is_some()))
        .collect();
    out.write_all(MAGIC)?;
    let mut record = Vec::with_capacity(anim.birds * 4);
    for (i, f) in anim.frames.iter().enumerate() {
        out.write_all(&f.t.to_le_bytes())?;
        for &k in &present {
            record.clear();
            let (name, steps) = Frame::FIELDS[k];
            match f.values(k) {
                Some(v) => {
                    for (b, &x) in v.iter().enumerate() {
                        if !x.is_finite() {
                            return Err(std::io::Error::new(
                                std::io::ErrorKind::InvalidData,
                                format!("frame {i}, bird {b}: {name} is not a finite number"),
                            ));
                        }
                        record.extend_from_slice(&(precision::to(x, steps) as f32).to_le_bytes());
                    }
                }
                None => {
                    for _ in 0..anim.birds {
                        record.extend_from_slice(&f32::NAN.to_le_bytes());
                    }
                }
            }
            out.write_all(&record)?;
        }
    }
    let id = out.hash.finish();
    out.inner.write_all(&id.to_le_bytes())?;
    out.flush()?;
    Ok(FramesFile {
        format: FRAMES_FORMAT.to_string(),
        path: frames_target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        frames: anim.frames.len(),
        fields: present
            .iter()
            .map(|&k| Frame::FIELDS[k].0.to_string())
            .collect(),
        id: Some(format!("{id:016x}")),
    })
}

/// Reads the frames file `anim.frames_file` names (beside `origin`, the animation file) into
/// `anim.frames`. Errors name the frames file and what is wrong with it (missing, its size against
/// the records the animation file announces, its first bytes) or the animation file's
/// `frames_file` field at fault.
pub fn read_frames(anim: &mut Animation, origin: &Path) -> Result<()> {
    let Some(ff) = &anim.frames_file else {
        return Ok(());
    };
    let name = Path::new(&ff.path);
    // A bare file name is its own last component: no directory, no `..`, not absolute.
    let plain = name.file_name() == Some(name.as_os_str());
    if !plain {
        return Err(Error::format(
            origin,
            format!(
                "frames_file.path: \"{}\" must be a file name in the animation file's directory",
                ff.path
            ),
        ));
    }
    let path = origin
        .parent()
        .map_or_else(|| name.to_path_buf(), |d| d.join(name));
    let file = std::fs::File::open(&path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            Error::format(
                &path,
                format!(
                    "missing: {} keeps its frames in this file; keep the two files together",
                    origin.display()
                ),
            )
        } else {
            Error::io(&path, e)
        }
    })?;
    let size = file.metadata().map_err(|e| Error::io(&path, e))?.len();
    read_frames_from(
        anim,
        origin,
        &path,
        BufReader::with_capacity(1 << 20, file),
        size,
    )
}

/// [`read_frames`] from `input`, the `size` bytes of the frames file `path`.
pub fn read_frames_from(
    anim: &mut Animation,
    origin: &Path,
    path: &Path,
    mut input: impl Read,
    size: u64,
) -> Result<()> {
    let Some(ff) = anim.frames_file.take() else {
        return Ok(());
    };
    let bad = |msg: String| Err(Error::format(origin, msg));
    // The id the animation file announces: `None` for the first version, which has none.
    let id = if ff.format == FRAMES_FORMAT {
        let Some(text) = &ff.id else {
            return bad(format!(
                "frames_file.id: missing (a \"{FRAMES_FORMAT}\" file names the id of its frames file)"
            ));
        };
        match u64::from_str_radix(text, 16) {
            Ok(v) if text.len() == 16 && text.bytes().all(|b| b.is_ascii_hexdigit()) => Some(v),
            _ => {
                return bad(format!(
                    "frames_file.id: \"{text}\" is not 16 hexadecimal digits"
                ))
            }
        }
    } else if ff.format == FRAMES_FORMAT_V1 {
        if ff.id.is_some() {
            return bad(format!(
                "frames_file.id: a \"{FRAMES_FORMAT_V1}\" file has no id; the format is \"{FRAMES_FORMAT}\""
            ));
        }
        None
    } else {
        return bad(format!(
            "frames_file.format: expected \"{FRAMES_FORMAT}\" (or \"{FRAMES_FORMAT_V1}\"), found \"{}\"",
            ff.format
        ));
    };
    if !anim.frames.is_empty() {
        return bad(
            "frames_file: the file has frames of its own too; give either \"frames\" or \"frames_file\""
                .into(),
        );
    }
    let mut order = Vec::with_capacity(ff.fields.len().min(Frame::FIELDS.len()));
    for (i, f) in ff.fields.iter().enumerate() {
        let Some(k) = Frame::FIELDS.iter().position(|(g, _)| g == f) else {
            let names: Vec<&str> = Frame::FIELDS.iter().map(|(g, _)| *g).collect();
            return bad(format!(
                "frames_file.fields[{i}]: unknown field \"{f}\" (expected some of {})",
                names.join(", ")
            ));
        };
        if order.contains(&k) {
            return bad(format!("frames_file.fields[{i}]: \"{f}\" is listed twice"));
        }
        order.push(k);
    }
    if let Some(k) = (0..Frame::REQUIRED).find(|k| !order.contains(k)) {
        return bad(format!(
            "frames_file.fields: \"{}\" is missing (every frame has x, y, z, heading and speed)",
            Frame::FIELDS[k].0
        ));
    }
    if anim.birds == 0 {
        return bad("birds: must be at least 1".into());
    }
    crate::limits::check_animation_size(&origin.display().to_string(), anim.birds, ff.frames)?;
    let expected = record_bytes(anim.birds, order.len())
        .and_then(|r| r.checked_mul(ff.frames as u64))
        .and_then(|b| b.checked_add(MAGIC.len() as u64))
        .and_then(|b| b.checked_add(if id.is_some() { ID_BYTES } else { 0 }));
    if expected != Some(size) {
        return Err(Error::format(
            path,
            format!(
                "{size} bytes, but {} announces {} frames of {} birds and {} fields ({} bytes); the two files do not belong together, or this one was cut short",
                origin.display(),
                ff.frames,
                anim.birds,
                order.len(),
                expected.map_or_else(|| "too many".to_string(), |b| b.to_string())
            ),
        ));
    }
    let io = |e| Error::io(path, e);
    let mut hash = FramesHash::default();
    let mut magic = [0u8; 16];
    input.read_exact(&mut magic).map_err(io)?;
    hash.update(&magic);
    if &magic != MAGIC {
        return Err(Error::format(
            path,
            "not a frames file (its first bytes are not \"formation-frames\")",
        ));
    }
    let n = anim.birds;
    let mut bytes = vec![0u8; n * 4];
    let mut frames = Vec::with_capacity(ff.frames);
    for _ in 0..ff.frames {
        let mut t = [0u8; 8];
        input.read_exact(&mut t).map_err(io)?;
        hash.update(&t);
        let mut f = Frame {
            t: f64::from_le_bytes(t),
            ..Frame::default()
        };
        for &k in &order {
            input.read_exact(&mut bytes).map_err(io)?;
            hash.update(&bytes);
            let v: Vec<f64> = bytes
                .chunks_exact(4)
                .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
                .collect();
            // An optional field all NaN is one this frame does not have.
            let absent = k >= Frame::REQUIRED && v.iter().all(|x| x.is_nan());
            f.set_values(k, (!absent).then_some(v));
        }
        frames.push(f);
    }
    if let Some(want) = id {
        let mut last = [0u8; 8];
        input.read_exact(&mut last).map_err(io)?;
        let stored = u64::from_le_bytes(last);
        if stored != hash.finish() {
            return Err(Error::format(
                path,
                "damaged: its bytes do not match the id at its end; write the animation again",
            ));
        }
        if stored != want {
            return Err(Error::format(
                path,
                format!(
                    "its id {stored:016x} is not the {want:016x} that {} names: the two files come from different runs (written at once, or one copied over); write the animation again",
                    origin.display()
                ),
            ));
        }
    }
    anim.frames = frames;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_frames() -> Animation {
        let mut a = Animation::new(3, 30.0, 1.5, 2);
        for (i, t) in [0.0, 1.0 / 30.0].into_iter().enumerate() {
            let k = i as f64;
            a.frames.push(Frame {
                t,
                x: vec![-0.5 + k, 1_234.567_891],
                y: vec![2.0, -3.25 - k],
                z: vec![10.0, 10.000_01],
                heading: vec![0.001, -0.002],
                speed: vec![10.0, 9.5],
                bank: Some(vec![0.1, -0.1]),
                pitch: None,
                e: (i == 1).then(|| vec![0.25, 0.5]),
                xi: None,
                wing_phase: Some(vec![1.0, 6.0]),
            });
        }
        a
    }

    #[test]
    fn frames_read_back_in_single_precision_with_absent_fields_absent() {
        let dir = std::env::temp_dir().join(format!("formation-binary-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let json = dir.join("a.json");
        let target = frames_path(&json);
        let a = two_frames();
        let mut file = std::fs::File::create(&target).unwrap();
        let ff = write_frames(&a, &mut file, &target).unwrap();
        drop(file);
        assert_eq!(ff.path, "a.frames");
        assert_eq!(
            ff.fields,
            ["x", "y", "z", "heading", "speed", "bank", "e", "wing_phase"]
        );
        assert_eq!(
            std::fs::metadata(&target).unwrap().len(),
            16 + 2 * (8 + 8 * 2 * 4) + 8
        );
        let mut b = a.with_frames(Vec::new());
        b.frames_file = Some(ff.clone());
        read_frames(&mut b, &json).unwrap();
        assert_eq!(b.frames.len(), 2);
        for (fa, fb) in a.frames.iter().zip(&b.frames) {
            assert_eq!(fa.t, fb.t);
            for (k, &(name, steps)) in Frame::FIELDS.iter().enumerate() {
                match (fa.values(k), fb.values(k)) {
                    (None, None) => {}
                    (Some(va), Some(vb)) => {
                        for (x, y) in va.iter().zip(vb) {
                            let want = f64::from(precision::to(*x, steps) as f32);
                            assert_eq!(want, *y, "field {name}");
                        }
                    }
                    other => panic!("field {name}: {other:?}"),
                }
            }
        }
        // Cut short, or named outside the directory: refused, naming the file.
        let bytes = std::fs::read(&target).unwrap();
        std::fs::write(&target, &bytes[..bytes.len() - 4]).unwrap();
        let mut c = a.with_frames(Vec::new());
        c.frames_file = Some(ff.clone());
        let e = read_frames(&mut c, &json).unwrap_err().to_string();
        assert!(e.contains("a.frames") && e.contains("cut short"), "{e}");
        let mut d = a.with_frames(Vec::new());
        d.frames_file = Some(FramesFile {
            path: "../a.frames".into(),
            ..ff
        });
        let e = read_frames(&mut d, &json).unwrap_err().to_string();
        assert!(e.contains("frames_file.path"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Writes `a`'s frames to memory: the bytes and what the animation file says of them.
    fn in_memory(a: &Animation) -> (Vec<u8>, FramesFile) {
        let mut bytes = Vec::new();
        let ff = write_frames(a, &mut bytes, Path::new("a.frames")).unwrap();
        (bytes, ff)
    }

    fn read_back(a: &Animation, ff: &FramesFile, bytes: &[u8]) -> Result<Animation> {
        let mut b = a.with_frames(Vec::new());
        b.frames_file = Some(ff.clone());
        read_frames_from(
            &mut b,
            Path::new("a.json"),
            Path::new("a.frames"),
            bytes,
            bytes.len() as u64,
        )?;
        Ok(b)
    }

    #[test]
    fn the_hash_does_not_depend_on_how_the_bytes_are_split() {
        let bytes: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
        let mut whole = FramesHash::default();
        whole.update(&bytes);
        for split in [1, 3, 8, 13, 999] {
            let mut h = FramesHash::default();
            for c in bytes.chunks(split) {
                h.update(c);
            }
            assert_eq!(h.finish(), whole.finish(), "chunks of {split}");
        }
        // One byte changed, or one more zero byte, changes it.
        let mut other = bytes.clone();
        other[500] ^= 1;
        let mut h = FramesHash::default();
        h.update(&other);
        assert_ne!(h.finish(), whole.finish());
        let mut h = FramesHash::default();
        h.update(&bytes);
        h.update(&[0]);
        assert_ne!(h.finish(), whole.finish());
    }

    #[test]
    fn a_frames_file_of_another_run_is_refused_naming_both_files() {
        let a = two_frames();
        let (bytes, ff) = in_memory(&a);
        assert_eq!(ff.format, FRAMES_FORMAT);
        let id = ff.id.clone().unwrap();
        assert_eq!(id.len(), 16);
        assert_eq!(
            u64::from_le_bytes(bytes[bytes.len() - 8..].try_into().unwrap()),
            u64::from_str_radix(&id, 16).unwrap()
        );
        assert!(read_back(&a, &ff, &bytes).is_ok());
        // Another run of the same size: same header, other frames.
        let mut other = a.clone();
        other.frames[1].x[0] += 0.5;
        let (other_bytes, other_ff) = in_memory(&other);
        assert_eq!(other_bytes.len(), bytes.len());
        assert_ne!(other_ff.id, ff.id);
        let e = read_back(&a, &ff, &other_bytes).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let e = e.to_string();
        assert!(
            e.starts_with("a.frames: ") && e.contains("a.json") && e.contains("different runs"),
            "{e}"
        );
        // A byte changed inside the records: damaged.
        let mut damaged = bytes.clone();
        damaged[30] ^= 0x40;
        let e = read_back(&a, &ff, &damaged).unwrap_err().to_string();
        assert!(e.starts_with("a.frames: damaged"), "{e}");
        // A bad id in the animation file.
        for bad in ["12", "zzzzzzzzzzzzzzzz", "+123456789abcdef"] {
            let f = FramesFile {
                id: Some(bad.into()),
                ..ff.clone()
            };
            let e = read_back(&a, &f, &bytes).unwrap_err().to_string();
            assert!(e.contains("frames_file.id"), "{bad}: {e}");
        }
        let f = FramesFile {
            id: None,
            ..ff.clone()
        };
        let e = read_back(&a, &f, &bytes).unwrap_err().to_string();
        assert!(e.contains("frames_file.id: missing"), "{e}");
    }

    #[test]
    fn first_version_files_without_an_id_are_still_read() {
        let a = two_frames();
        let (bytes, ff) = in_memory(&a);
        let v1 = FramesFile {
            format: FRAMES_FORMAT_V1.into(),
            id: None,
            ..ff.clone()
        };
        let b = read_back(&a, &v1, &bytes[..bytes.len() - 8]).unwrap();
        let c = read_back(&a, &ff, &bytes).unwrap();
        assert_eq!(b.frames, c.frames);
        // With the trailer, a first-version file is the wrong size.
        assert!(read_back(&a, &v1, &bytes).is_err());
    }
}

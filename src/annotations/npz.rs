//! TRex's tracks: one NumPy `.npz` archive per individual (`VIDEO_fish0.npz`, `VIDEO_fish1.npz`,
//! …), each a zip of `.npy` arrays of equal length, one element per frame the individual was
//! tracked in (see `docs/formats.md`). Read here without Python: the zip's central directory,
//! its members stored or deflated (`np.savez` and `np.savez_compressed`), and the `.npy`
//! headers of one-dimensional numeric arrays.
//!
//! The bird is `X#wcentroid`, `Y#wcentroid` (TRex's default body centre), else the first of
//! `X#centroid`, `X` (the head), `X#pcentroid` with its `Y`; `frame` numbers the rows (else their
//! order), rows with `missing` ≠ 0 or non-finite positions are left out, and `time` gives the
//! frame rate. Positions are TRex's (centimetres when its `cm_per_pixel` is set, y down), so the
//! wingspan (`read.wingspan_px`) is given in the same unit. The id is the number that ends the file
//! name (`fish3` → 3).

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use super::{Format, RawAnnotations, RawBird, RawFrame};
use crate::error::{Error, Result};

/// The first bytes of a zip archive (a local file header).
pub(crate) const ZIP_MAGIC: &[u8; 4] = b"PK\x03\x04";

/// Largest total of decompressed bytes of one archive (a decompression bomb stops here).
const MAX_MEMBER_BYTES: u64 = 1 << 30;

/// Whether `path` is a zip archive (by its first bytes).
pub(crate) fn is_zip(path: &Path) -> bool {
    let mut head = [0u8; 4];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && &head == ZIP_MAGIC
}

/// Whether the directory holds `.npz` files.
pub(crate) fn dir_has_npz(dir: &Path) -> bool {
    std::fs::read_dir(dir)
        .map(|it| it.flatten().any(|e| is_npz_name(&e.path())))
        .unwrap_or(false)
}

fn is_npz_name(p: &Path) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case("npz")) && p.is_file()
}

/// The stem without its trailing number (`video_fish12` → `video_fish`) and the number.
fn split_number(stem: &str) -> (&str, Option<usize>) {
    let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (head, tail) = stem.split_at(stem.len() - digits);
    (head, tail.parse().ok())
}

/// The individuals' files: every `.npz` of a directory, or the files beside `path` whose names
/// differ from its name only in the trailing number (`video_fish0.npz` → `video_fish*.npz`).
fn individual_files(path: &Path) -> Result<Vec<PathBuf>> {
    let (dir, prefix) = if path.is_dir() {
        (path.to_path_buf(), None)
    } else {
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let (head, number) = split_number(stem);
        let dir = path
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let dir = if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir
        };
        match number {
            Some(_) => (dir, Some(head.to_string())),
            None => return Ok(vec![path.to_path_buf()]),
        }
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| Error::io(&dir, e))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| is_npz_name(p))
        .filter(|p| match &prefix {
            None => true,
            Some(h) => p
                .file_stem()
                .and_then(|s| s.to_str())
                .is_some_and(|s| split_number(s).0 == h && split_number(s).1.is_some()),
        })
        .collect();
    if files.is_empty() {
        return Err(Error::format(
            path,
            "no .npz files (TRex writes one per individual)",
        ));
    }
    files.sort_by_key(|p| {
        let stem = p
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("")
            .to_string();
        (split_number(&stem).1.unwrap_or(usize::MAX), stem)
    });
    Ok(files)
}

/// Where an individual is seen: (frame, x, y, row of its arrays).
type Seen = Vec<(i64, f64, f64, usize)>;

/// One individual's tracks: its id, its file and where it is seen.
type Track = (usize, PathBuf, Seen);

/// Reads TRex's tracks from one individual's `.npz` (and its siblings) or a directory of them.
pub(crate) fn read(path: &Path) -> Result<RawAnnotations> {
    let mut tracks: Vec<Track> = Vec::new();
    let mut rates: Vec<f64> = Vec::new();
    for (order, file) in individual_files(path)?.into_iter().enumerate() {
        let bytes = crate::io::read_bytes(&file)?;
        let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let id = split_number(stem).1.unwrap_or(order);
        if let Some((_, other, _)) = tracks.iter().find(|t| t.0 == id) {
            return Err(Error::format(
                &file,
                format!("individual {id} again (also {})", other.display()),
            ));
        }
        let (rows, rate) = individual(&file, &bytes)?;
        rates.extend(rate);
        tracks.push((id, file, rows));
    }
    assemble(path, tracks, rates)
}

/// One individual's archive from bytes (`path` only names it in messages), as bird 0.
pub(crate) fn read_one(path: &Path, bytes: &[u8]) -> Result<RawAnnotations> {
    let (rows, rate) = individual(path, bytes)?;
    assemble(
        path,
        vec![(0, path.to_path_buf(), rows)],
        rate.into_iter().collect(),
    )
}

/// The frames of every individual's tracks, in frame order; the median of their frame rates.
fn assemble(path: &Path, tracks: Vec<Track>, mut rates: Vec<f64>) -> Result<RawAnnotations> {
    let mut frames: Vec<RawFrame> = Vec::new();
    let mut at_index: HashMap<i64, usize> = HashMap::new();
    for (id, file, rows) in tracks {
        for (index, x, y, row) in rows {
            let p = *at_index.entry(index).or_insert_with(|| {
                frames.push(RawFrame {
                    index,
                    image: None,
                    wingspan_px: None,
                    at: format!("frame {index}"),
                    birds: Vec::new(),
                });
                frames.len() - 1
            });
            frames[p].birds.push(RawBird {
                z: None,
                id: Some(id),
                x,
                y,
                at: format!("{}, row {row}", file.display()),
            });
        }
    }
    if frames.is_empty() {
        return Err(Error::format(path, "no individual is seen in any frame"));
    }
    let total: usize = frames.iter().map(|f| f.birds.len()).sum();
    if total > crate::limits::MAX_BIRD_FRAMES {
        return Err(Error::format(path, "too many marks"));
    }
    frames.sort_by_key(|f| f.index);
    rates.sort_by(f64::total_cmp);
    Ok(RawAnnotations {
        format: Format::Trex,
        source: None,
        heading: None,
        wingspan_px: None,
        fps: rates.get(rates.len() / 2).copied(),
        y_up: false,
        is_csv: true,
        frames,
    })
}

/// One individual's archive: its (frame, x, y, row) where it is seen, and the frame rate its
/// `frame` and `time` arrays give.
pub(crate) fn individual(file: &Path, bytes: &[u8]) -> Result<(Seen, Option<f64>)> {
    let arrays = arrays(file, bytes)?;
    let (xs, ys) = ["#wcentroid", "#centroid", "", "#pcentroid"]
        .iter()
        .find_map(|s| Some((arrays.get(&format!("X{s}"))?, arrays.get(&format!("Y{s}"))?)))
        .ok_or_else(|| {
            let mut names: Vec<&str> = arrays.keys().map(String::as_str).collect();
            names.sort_unstable();
            Error::format(
                file,
                format!(
                    "no positions: expected arrays X#wcentroid and Y#wcentroid (or X and Y); the archive holds {}",
                    if names.is_empty() { "none".to_string() } else { names.join(", ") }
                ),
            )
        })?;
    let n = xs.len();
    let mut names: Vec<&String> = arrays.keys().collect();
    names.sort_unstable();
    for name in names {
        let len = arrays[name].len();
        if len != n {
            return Err(Error::format(
                file,
                format!("array {name} has {len} rows, the positions have {n}"),
            ));
        }
    }
    let frame = arrays.get("frame");
    let missing = arrays.get("missing");
    let mut rows = Vec::new();
    for row in 0..n {
        let index = match frame {
            Some(f) => {
                let v = f[row];
                if !v.is_finite() || v.fract() != 0.0 || v.abs() > 1e15 {
                    return Err(Error::format(
                        file,
                        format!("row {row}: frame {v} is not a frame number"),
                    ));
                }
                v as i64
            }
            None => row as i64,
        };
        if missing.is_some_and(|m| m[row] != 0.0) {
            continue;
        }
        let (x, y) = (xs[row], ys[row]);
        if x.is_finite() && y.is_finite() {
            rows.push((index, x, y, row));
        }
    }
    let rate = frame.zip(arrays.get("time")).and_then(|(f, t)| rate(f, t));
    Ok((rows, rate))
}

/// Frames per second from an individual's frame numbers and times (first to last), when both
/// span more than one frame.
fn rate(frame: &[f64], time: &[f64]) -> Option<f64> {
    let ok: Vec<(f64, f64)> = frame
        .iter()
        .zip(time)
        .filter(|(f, t)| f.is_finite() && t.is_finite())
        .map(|(&f, &t)| (f, t))
        .collect();
    let (&(f0, t0), &(f1, t1)) = (ok.first()?, ok.last()?);
    let r = (f1 - f0) / (t1 - t0);
    (f1 > f0 && r.is_finite() && r > 0.0 && r <= 100_000.0).then_some(r)
}

/// The archive's arrays by name (without `.npy`).
fn arrays(path: &Path, bytes: &[u8]) -> Result<HashMap<String, Vec<f64>>> {
    let mut out = HashMap::new();
    for (name, data) in members(path, bytes)? {
        let Some(key) = name.strip_suffix(".npy") else {
            continue;
        };
        out.insert(key.to_string(), npy(path, &name, &data)?);
    }
    Ok(out)
}

fn u16_at(b: &[u8], i: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(i..i + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], i: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(i..i + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], i: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(i..i + 8)?.try_into().ok()?))
}

/// The members of a zip archive, decompressed: (name, bytes).
fn members(path: &Path, b: &[u8]) -> Result<Vec<(String, Vec<u8>)>> {
    let bad =
        |what: &str| Error::format(path, format!("not a readable .npz (zip) archive: {what}"));
    // The end of central directory record: 22 bytes plus a comment of up to 65 535.
    let from = b.len().saturating_sub(22 + 65_535);
    let eocd = (from..b.len().saturating_sub(21))
        .rev()
        .find(|&i| u32_at(b, i) == Some(0x0605_4b50))
        .ok_or_else(|| bad("no end of central directory (truncated?)"))?;
    let count = u16_at(b, eocd + 10).ok_or_else(|| bad("short end record"))? as usize;
    let mut at = u32_at(b, eocd + 16).ok_or_else(|| bad("short end record"))? as usize;
    if count == 0xFFFF || at == 0xFFFF_FFFF {
        return Err(bad("a zip64 archive of that many arrays is not supported"));
    }
    let mut out = Vec::with_capacity(count);
    let mut total = 0u64;
    for k in 0..count {
        let entry = |what: &str| bad(&format!("central directory entry {k}: {what}"));
        if u32_at(b, at) != Some(0x0201_4b50) {
            return Err(entry("bad signature"));
        }
        let method = u16_at(b, at + 10).ok_or_else(|| entry("short"))?;
        let crc = u32_at(b, at + 16).ok_or_else(|| entry("short"))?;
        let mut packed = u64::from(u32_at(b, at + 20).ok_or_else(|| entry("short"))?);
        let mut size = u64::from(u32_at(b, at + 24).ok_or_else(|| entry("short"))?);
        let name_len = u16_at(b, at + 28).ok_or_else(|| entry("short"))? as usize;
        let extra_len = u16_at(b, at + 30).ok_or_else(|| entry("short"))? as usize;
        let comment_len = u16_at(b, at + 32).ok_or_else(|| entry("short"))? as usize;
        let mut local = u64::from(u32_at(b, at + 42).ok_or_else(|| entry("short"))?);
        let name_bytes = b
            .get(at + 46..at + 46 + name_len)
            .ok_or_else(|| entry("name past the end"))?;
        let name = String::from_utf8_lossy(name_bytes).into_owned();
        // Zip64 sizes and offset (numpy writes them for large arrays), in this order, each only
        // where the 32-bit field is saturated.
        let extra = b
            .get(at + 46 + name_len..at + 46 + name_len + extra_len)
            .ok_or_else(|| entry("extra field past the end"))?;
        let mut e = 0;
        while e + 4 <= extra.len() {
            let (id, len) = (
                u16_at(extra, e).unwrap_or(0),
                u16_at(extra, e + 2).unwrap_or(0) as usize,
            );
            if id == 1 {
                let mut f = e + 4;
                for v in [&mut size, &mut packed, &mut local] {
                    if *v == 0xFFFF_FFFF {
                        *v = u64_at(extra, f).ok_or_else(|| entry("short zip64 field"))?;
                        f += 8;
                    }
                }
            }
            e += 4 + len;
        }
        at += 46 + name_len + extra_len + comment_len;
        total += size;
        if total > MAX_MEMBER_BYTES {
            return Err(bad("more than 1 GiB of arrays"));
        }
        let l = usize::try_from(local).map_err(|_| entry("offset"))?;
        if u32_at(b, l) != Some(0x0403_4b50) {
            return Err(entry("its local header is missing"));
        }
        let start = l
            + 30
            + u16_at(b, l + 26).ok_or_else(|| entry("short local header"))? as usize
            + u16_at(b, l + 28).ok_or_else(|| entry("short local header"))? as usize;
        let data = usize::try_from(packed)
            .ok()
            .and_then(|p| b.get(start..start.checked_add(p)?))
            .ok_or_else(|| entry(&format!("{name}: data past the end (truncated?)")))?;
        let bytes = match method {
            0 => data.to_vec(),
            8 => {
                let mut v = Vec::with_capacity(size.min(MAX_MEMBER_BYTES) as usize);
                flate2::read::DeflateDecoder::new(data)
                    .take(size + 1)
                    .read_to_end(&mut v)
                    .map_err(|e| entry(&format!("{name}: damaged compressed data ({e})")))?;
                v
            }
            m => {
                return Err(entry(&format!(
                    "{name}: compression method {m} (stored or deflated only)"
                )))
            }
        };
        if bytes.len() as u64 != size {
            return Err(entry(&format!(
                "{name}: {} bytes where the directory says {size}",
                bytes.len()
            )));
        }
        let mut c = flate2::Crc::new();
        c.update(&bytes);
        if c.sum() != crc {
            return Err(entry(&format!("{name}: checksum mismatch (damaged)")));
        }
        out.push((name, bytes));
    }
    Ok(out)
}

/// A one-dimensional numeric `.npy` array as floats (booleans as 0/1).
fn npy(path: &Path, name: &str, b: &[u8]) -> Result<Vec<f64>> {
    let bad = |what: String| Error::format(path, format!("array {name}: {what}"));
    if b.get(..6) != Some(b"\x93NUMPY".as_slice()) {
        return Err(bad("not a .npy array (no \\x93NUMPY magic)".into()));
    }
    let major = b.get(6).copied().unwrap_or(0);
    let (len, start) = match major {
        1 => (u16_at(b, 8).map(usize::from), 10),
        2 | 3 => (u32_at(b, 8).map(|v| v as usize), 12),
        v => return Err(bad(format!(".npy format version {v}"))),
    };
    let len = len.ok_or_else(|| bad("short header".into()))?;
    let header = b
        .get(start..start + len)
        .map(String::from_utf8_lossy)
        .ok_or_else(|| bad("header past the end".into()))?;
    let field = |key: &str| -> Option<String> {
        let i = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[i..].trim_start().strip_prefix(':')?.trim_start();
        Some(rest.to_string())
    };
    let descr = field("descr")
        .and_then(|r| {
            r.strip_prefix('\'')
                .and_then(|r| r.split('\'').next())
                .map(str::to_string)
        })
        .ok_or_else(|| bad(format!("no dtype in its header {header:?}")))?;
    // `fortran_order` does not matter: only one-dimensional arrays are read.
    let shape: Vec<usize> = field("shape")
        .and_then(|r| {
            r.strip_prefix('(')
                .and_then(|r| r.split(')').next())
                .map(str::to_string)
        })
        .ok_or_else(|| bad(format!("no shape in its header {header:?}")))?
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad(format!("shape in {header:?}")))?;
    let n = match shape.as_slice() {
        [n] => *n,
        [n, 1] | [1, n] => *n,
        s => return Err(bad(format!("shape {s:?}: one value per frame expected"))),
    };
    let (order, kind) = descr.split_at(1.min(descr.len()));
    let big = order == ">";
    let data = &b[start + len..];
    let (width, conv): (usize, fn(&[u8]) -> f64) = match kind {
        "f8" => (8, |c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8]))),
        "f4" => (4, |c| {
            f64::from(f32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
        }),
        "i8" => (8, |c| {
            i64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f64
        }),
        "u8" => (8, |c| {
            u64::from_le_bytes(c.try_into().unwrap_or([0; 8])) as f64
        }),
        "i4" => (4, |c| {
            f64::from(i32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
        }),
        "u4" => (4, |c| {
            f64::from(u32::from_le_bytes(c.try_into().unwrap_or([0; 4])))
        }),
        "i2" => (2, |c| {
            f64::from(i16::from_le_bytes(c.try_into().unwrap_or([0; 2])))
        }),
        "u2" => (2, |c| {
            f64::from(u16::from_le_bytes(c.try_into().unwrap_or([0; 2])))
        }),
        "i1" => (1, |c| f64::from(c[0] as i8)),
        "u1" | "b1" => (1, |c| f64::from(c[0])),
        _ => return Err(bad(format!("dtype {descr} (numbers or booleans expected)"))),
    };
    let need = n
        .checked_mul(width)
        .filter(|&v| v <= data.len())
        .ok_or_else(|| {
            bad(format!(
                "{n} values of {width} bytes, {} bytes there (truncated?)",
                data.len()
            ))
        })?;
    Ok(data[..need]
        .chunks_exact(width)
        .map(|c| {
            if big {
                let mut r = c.to_vec();
                r.reverse();
                conv(&r)
            } else {
                conv(c)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trailing_numbers_split_off() {
        assert_eq!(split_number("video_fish12"), ("video_fish", Some(12)));
        assert_eq!(split_number("tracks"), ("tracks", None));
    }
}

//! SLEAP's analysis HDF5 (what `sleap-convert` writes as its analysis format): datasets
//! `tracks` (tracks × 2 × nodes × frames, floats, NaN where a node was not found; SLEAP stores
//! its frames × nodes × 2 × tracks array transposed), `track_names` and `node_names` (byte
//! strings), the others (`track_occupancy`, scores, paths) unused. Read by content: the HDF5 signature.

use std::collections::HashMap;
use std::path::Path;

use super::trackers::{track_id, Frames};
use super::{Format, RawAnnotations, RawBird};
use crate::error::{Error, Result};

/// The first bytes of an HDF5 file (superblock at offset 0, as h5py writes it).
pub(crate) const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";

/// Whether `bytes` start with the HDF5 signature.
pub(crate) fn is_hdf5(bytes: &[u8]) -> bool {
    bytes.starts_with(SIGNATURE)
}

/// Whether the file at `path` starts with the HDF5 signature (false when unreadable: the
/// reader that follows names the problem).
pub(crate) fn file_is_hdf5(path: &Path) -> bool {
    use std::io::Read;
    // Only regular files: looking into a pipe or a FIFO would take its first bytes from the
    // reader that follows.
    if !path.is_file() {
        return false;
    }
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && is_hdf5(&head)
}

/// Most values of `tracks` read (4 tracks' x and y of 2 nodes over a million frames is 16 M).
const MAX_VALUES: u64 = 64_000_000;

/// Most bytes one dataset (or one of its chunks) may take in memory: `tracks` at
/// [`MAX_VALUES`] doubles; a damaged file can declare any size.
const MAX_BYTES: u64 = MAX_VALUES * 8;

/// The shape of dataset `name`, refused (before any data is read) when it, its element or its
/// chunks would take more than [`MAX_BYTES`].
fn guarded_shape(path: &Path, name: &str, ds: &hdf5_pure::Dataset) -> Result<Vec<u64>> {
    let what = format!("dataset {name}");
    let shape = ds.shape().map_err(|e| h5err(path, &what, e))?;
    let elem = ds.element_size().map_err(|e| h5err(path, &what, e))?;
    let bytes = |dims: &[u64]| {
        dims.iter()
            .try_fold(elem.max(1), |acc, &d| acc.checked_mul(d.max(1)))
            .filter(|&b| b <= MAX_BYTES)
    };
    let too_big = || {
        Error::format(
            path,
            format!(
                "{what}: shape {shape:?} of {elem}-byte elements is larger than {MAX_BYTES} bytes"
            ),
        )
    };
    bytes(&shape).ok_or_else(too_big)?;
    if let Ok(hdf5_pure::Layout::Chunked { chunk_shape, .. }) = ds.layout() {
        bytes(&chunk_shape).ok_or_else(too_big)?;
    }
    Ok(shape)
}

fn h5err(path: &Path, what: &str, e: impl std::fmt::Display) -> Error {
    Error::format(
        path,
        format!("{what}: {e} (is this SLEAP's analysis HDF5, as sleap-convert writes it?)"),
    )
}

/// Parses the bytes of an analysis HDF5 file; `bodypart` names the node (default the first).
pub(crate) fn parse(path: &Path, bytes: Vec<u8>, bodypart: Option<&str>) -> Result<RawAnnotations> {
    let file = hdf5_pure::File::from_bytes(bytes).map_err(|e| h5err(path, "HDF5", e))?;
    let ds = file
        .dataset("tracks")
        .map_err(|e| h5err(path, "dataset tracks", e))?;
    let shape = guarded_shape(path, "tracks", &ds)?;
    let [nt, two, nn, nf] = shape[..] else {
        return Err(Error::format(
            path,
            format!(
                "dataset tracks: shape {shape:?}, expected 4 dimensions (tracks, 2, nodes, frames)"
            ),
        ));
    };
    if two != 2 || nt == 0 || nn == 0 || nf == 0 {
        return Err(Error::format(
            path,
            format!(
                "dataset tracks: shape {shape:?}, expected (tracks, 2, nodes, frames), none empty"
            ),
        ));
    }
    let total = nt
        .checked_mul(2)
        .and_then(|v| v.checked_mul(nn))
        .and_then(|v| v.checked_mul(nf))
        .filter(|&v| v <= MAX_VALUES)
        .ok_or_else(|| {
            Error::format(
                path,
                format!("dataset tracks: shape {shape:?} holds more than {MAX_VALUES} values"),
            )
        })?;
    let strings = |name: &str, n: u64| -> Result<Option<Vec<String>>> {
        let Ok(d) = file.dataset(name) else {
            return Ok(None);
        };
        let shape = guarded_shape(path, name, &d)?;
        if shape != [n] {
            return Err(Error::format(
                path,
                format!("dataset {name}: shape {shape:?}, expected [{n}] (one name per entry of tracks)"),
            ));
        }
        let v = d
            .read_string()
            .map_err(|e| h5err(path, &format!("dataset {name}"), e))?;
        if v.len() as u64 != n {
            return Err(Error::format(
                path,
                format!("dataset {name}: {} names, dataset tracks has {n}", v.len()),
            ));
        }
        Ok(Some(v))
    };
    let nodes = strings("node_names", nn)?;
    let names = strings("track_names", nt)?;
    let node = match (bodypart, &nodes) {
        (None, _) => 0,
        (Some(b), Some(nodes)) => nodes
            .iter()
            .position(|n| n.eq_ignore_ascii_case(b))
            .ok_or_else(|| super::trackers::no_node(path, b, nodes))?,
        (Some(b), None) => {
            return Err(Error::parameter(
                "read.bodypart",
                format!(
                    "{}: no node_names dataset to find \"{b}\" in",
                    path.display()
                ),
            ))
        }
    } as u64;
    let v = ds
        .read_f64()
        .map_err(|e| h5err(path, "dataset tracks", e))?;
    if v.len() as u64 != total {
        return Err(Error::format(
            path,
            format!("dataset tracks: {} values for shape {shape:?}", v.len()),
        ));
    }
    let node_name = nodes
        .as_ref()
        .map_or_else(|| format!("node {node}"), |n| n[node as usize].clone());
    let mut named = HashMap::new();
    let ids: Vec<usize> = (0..nt as usize)
        .map(|t| match &names {
            Some(n) => track_id(&n[t], &mut named),
            None => t,
        })
        .collect();
    let at = |t: u64, c: u64, f: u64| v[(((t * 2 + c) * nn + node) * nf + f) as usize];
    let mut out = Frames::default();
    for f in 0..nf {
        for t in 0..nt {
            let (x, y) = (at(t, 0, f), at(t, 1, f));
            let place = format!("frame {f}, track {t} ({node_name})");
            match (x.is_finite(), y.is_finite()) {
                (true, true) => out.push(
                    f as i64,
                    RawBird {
                        id: Some(ids[t as usize]),
                        x,
                        y,
                        z: None,
                        at: place,
                    },
                ),
                (false, false) => {}
                _ => {
                    return Err(Error::format(
                        path,
                        format!(
                            "dataset tracks, {place}: x and y must both be numbers or both NaN"
                        ),
                    ))
                }
            }
        }
    }
    out.done(path, Format::SleapH5)
}

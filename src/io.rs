//! File input and output shared by every stage: reading JSON with messages that name the file and
//! the line, and writing outputs atomically (a temporary file beside the target, then a rename), so
//! that a failed or interrupted run leaves no partial file and never truncates an existing one.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::error::{Error, Result};

/// Upper bound on the size of any input file we read fully into memory, bytes: 2 GiB, enough for
/// the largest animation file `formation` writes (10⁷ bird-frames of pretty JSON, about 2 GB; see
/// [`crate::limits::MAX_BIRD_FRAMES`]).
pub const MAX_INPUT_BYTES: u64 = 2 * 1024 * 1024 * 1024;

/// Reads a whole file as bytes, with the path in the error and a size limit.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    let meta = fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::format(path, "is a directory, expected a file"));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(Error::format(
            path,
            format!(
                "file is {} bytes, more than the {} byte limit",
                meta.len(),
                MAX_INPUT_BYTES
            ),
        ));
    }
    fs::read(path).map_err(|e| Error::io(path, e))
}

/// Reads a whole file as UTF-8 text.
pub fn read_text(path: &Path) -> Result<String> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| {
        Error::format(
            path,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// Parses JSON text into `T`, turning serde's message into one line naming the file, line and column.
pub fn parse_json<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    if text.trim().is_empty() {
        return Err(Error::format(path, "file is empty, expected JSON"));
    }
    serde_json::from_str(text).map_err(|e| json_error(path, &e))
}

/// Reads and parses a JSON file.
pub fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text = read_text(path)?;
    parse_json(path, &text)
}

/// One-line description of a serde_json error with its position.
pub fn json_error(path: &Path, e: &serde_json::Error) -> Error {
    let what = match e.classify() {
        serde_json::error::Category::Eof => "truncated JSON".to_string(),
        serde_json::error::Category::Syntax => "invalid JSON".to_string(),
        serde_json::error::Category::Data => "unexpected JSON structure".to_string(),
        serde_json::error::Category::Io => "read error".to_string(),
    };
    // serde_json's Display already appends "at line L column C"; strip it so we can place it first.
    let msg = e.to_string();
    let msg = match msg.rfind(" at line ") {
        Some(pos) => msg[..pos].to_string(),
        None => msg,
    };
    Error::format(
        path,
        format!("line {}, column {}: {what}: {msg}", e.line(), e.column()),
    )
}

/// Checks that a value is finite, naming the field when it is not.
pub fn check_finite(name: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::parameter(
            name,
            format!("must be a finite number, got {v}"),
        ))
    }
}

/// Kind of output, chosen by the `-o` path's extension (or a trailing `/` / existing directory).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// `.json`
    Json,
    /// `.csv`
    Csv,
    /// `.gif`
    Gif,
    /// `.png`
    Png,
    /// `.svg`
    Svg,
    /// `.glb`
    Glb,
    /// `.usda` (text USD)
    Usda,
    /// A directory of numbered PNG frames.
    Directory,
}

impl OutputKind {
    /// Classifies an output path. Unknown extensions are an error naming the path and the choices.
    pub fn from_path(path: &Path, allowed: &[OutputKind]) -> Result<OutputKind> {
        let s = path.to_string_lossy();
        let kind = if s.ends_with('/') || s.ends_with(std::path::MAIN_SEPARATOR) || path.is_dir() {
            Some(OutputKind::Directory)
        } else {
            match path
                .extension()
                .and_then(|e| e.to_str())
                .map(|e| e.to_ascii_lowercase())
                .as_deref()
            {
                Some("json") => Some(OutputKind::Json),
                Some("csv") => Some(OutputKind::Csv),
                Some("gif") => Some(OutputKind::Gif),
                Some("png") => Some(OutputKind::Png),
                Some("svg") => Some(OutputKind::Svg),
                Some("glb") => Some(OutputKind::Glb),
                Some("usda") => Some(OutputKind::Usda),
                _ => None,
            }
        };
        match kind {
            Some(k) if allowed.contains(&k) => Ok(k),
            _ => Err(Error::parameter(
                "-o",
                format!(
                    "{}: cannot tell the output format from this name; use one of: {}",
                    path.display(),
                    allowed
                        .iter()
                        .map(|k| k.describe())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )),
        }
    }

    fn describe(self) -> &'static str {
        match self {
            OutputKind::Json => ".json",
            OutputKind::Csv => ".csv",
            OutputKind::Gif => ".gif",
            OutputKind::Png => ".png",
            OutputKind::Svg => ".svg",
            OutputKind::Glb => ".glb",
            OutputKind::Usda => ".usda",
            OutputKind::Directory => "a directory (DIR/)",
        }
    }
}

/// A file being written atomically: data goes to a temporary file in the target's directory and
/// only [`AtomicFile::commit`] moves it into place. Dropping it uncommitted removes the temporary.
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    writer: Option<BufWriter<fs::File>>,
}

/// Temporary path beside `target` (same directory, so the final rename is atomic).
fn temp_path_for(target: &Path) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".to_string());
    let dir = target.parent().filter(|p| !p.as_os_str().is_empty());
    let tmp_name = format!(".{name}.tmp-formation-{}", std::process::id());
    match dir {
        Some(d) => d.join(tmp_name),
        None => PathBuf::from(tmp_name),
    }
}

impl AtomicFile {
    /// Creates the temporary file for `target`. Fails (naming `target`) if its directory is missing
    /// or not writable.
    pub fn create(target: &Path) -> Result<AtomicFile> {
        if target.is_dir() {
            return Err(Error::format(
                target,
                "is a directory, expected a file name",
            ));
        }
        let tmp = temp_path_for(target);
        // Created and registered under the lock, so a signal cannot leave it unregistered.
        let file = with_temps(|v| {
            let f = fs::File::create(&tmp)?;
            v.push(tmp.clone());
            Ok(f)
        })
        .map_err(|e| Error::io(target, e))?;
        Ok(AtomicFile {
            target: target.to_path_buf(),
            tmp,
            writer: Some(BufWriter::new(file)),
        })
    }

    /// The buffered writer of the temporary file.
    pub fn writer(&mut self) -> &mut BufWriter<fs::File> {
        self.writer.as_mut().expect("writer present until commit")
    }

    /// Flushes, syncs and renames the temporary file onto the target. On any failure the
    /// temporary is removed and the target left as it was.
    pub fn commit(mut self) -> Result<()> {
        let writer = self.writer.take().expect("writer present until commit");
        let tmp = self.tmp.clone();
        let result = (|| {
            let file = writer.into_inner().map_err(|e| e.into_error())?;
            file.sync_all()?;
            drop(file);
            with_temps(|v| {
                fs::rename(&tmp, &self.target)?;
                v.retain(|q| q != &tmp);
                Ok(())
            })
        })();
        result.map_err(|e| {
            let _ = with_temps(|v| {
                let _ = fs::remove_file(&tmp);
                v.retain(|q| q != &tmp);
                Ok(())
            });
            Error::io(&self.target, e)
        })
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.writer().flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.writer.is_some() {
            self.writer = None;
            let _ = with_temps(|v| {
                let _ = fs::remove_file(&self.tmp);
                v.retain(|q| q != &self.tmp);
                Ok(())
            });
        }
    }
}

/// Writes `bytes` to `target` atomically.
pub fn write_bytes_atomic(target: &Path, bytes: &[u8]) -> Result<()> {
    let mut f = AtomicFile::create(target)?;
    f.writer()
        .write_all(bytes)
        .map_err(|e| Error::io(target, e))?;
    f.commit()
}

/// Serialises `value` as pretty JSON (with a trailing newline) to `target` atomically. A
/// non-finite number anywhere in `value` (which JSON cannot hold; serde_json would write `null`)
/// is refused with [`Error::Internal`] naming its path, before the file is created. The JSON is
/// streamed into the temporary file, not built in memory.
pub fn write_json_atomic<T: Serialize>(target: &Path, value: &T) -> Result<()> {
    crate::finite::check_serialize(&target.display().to_string(), value)?;
    let mut f = AtomicFile::create(target)?;
    serde_json::to_writer_pretty(f.writer(), value).map_err(|e| {
        if e.is_io() {
            Error::io(target, e.into())
        } else {
            Error::Internal(format!("serialising {}: {e}", target.display()))
        }
    })?;
    f.writer()
        .write_all(b"\n")
        .map_err(|e| Error::io(target, e))?;
    f.commit()
}

/// A directory being filled atomically: files go into a temporary sibling directory that
/// [`AtomicDir::commit`] renames onto the target (replacing an existing directory of ours only
/// after the new one is complete).
pub struct AtomicDir {
    target: PathBuf,
    tmp: PathBuf,
    committed: bool,
}

impl AtomicDir {
    /// Creates the temporary directory for `target`.
    pub fn create(target: &Path) -> Result<AtomicDir> {
        let trimmed = PathBuf::from(target.to_string_lossy().trim_end_matches('/'));
        if trimmed.exists() && !trimmed.is_dir() {
            return Err(Error::format(&trimmed, "exists and is not a directory"));
        }
        let tmp = temp_path_for(&trimmed);
        with_temps(|v| {
            let _ = fs::remove_dir_all(&tmp);
            fs::create_dir(&tmp)?;
            v.push(tmp.clone());
            Ok(())
        })
        .map_err(|e| Error::io(&trimmed, e))?;
        Ok(AtomicDir {
            target: trimmed,
            tmp,
            committed: false,
        })
    }

    /// Path of a file inside the temporary directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.tmp.join(name)
    }

    /// Moves the finished directory into place. An existing target directory is replaced.
    pub fn commit(mut self) -> Result<()> {
        // Under the lock: a signal waits until the old directory is replaced (or restored).
        with_temps(|v| {
            if self.target.is_dir() {
                let old = temp_path_for(&self.target).with_extension("old");
                let _ = fs::remove_dir_all(&old);
                fs::rename(&self.target, &old)?;
                if let Err(e) = fs::rename(&self.tmp, &self.target) {
                    let _ = fs::rename(&old, &self.target);
                    return Err(e);
                }
                let _ = fs::remove_dir_all(&old);
            } else {
                fs::rename(&self.tmp, &self.target)?;
            }
            v.retain(|q| q != &self.tmp);
            Ok(())
        })
        .map_err(|e| Error::io(&self.target, e))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for AtomicDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = with_temps(|v| {
                let _ = fs::remove_dir_all(&self.tmp);
                v.retain(|q| q != &self.tmp);
                Ok(())
            });
        }
    }
}

// Temporaries still open, so that a signal handler in the binary can remove them before exiting.
// Creating, committing and removing a temporary all happen under this lock, so the handler sees
// every temporary that exists and never runs in the middle of a commit's renames.
static OPEN_TEMPS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn with_temps<R>(f: impl FnOnce(&mut Vec<PathBuf>) -> std::io::Result<R>) -> std::io::Result<R> {
    let mut guard = OPEN_TEMPS.lock().unwrap_or_else(|p| p.into_inner());
    f(&mut guard)
}

/// Removes every temporary file or directory still open (called on Ctrl-C / SIGTERM, right
/// before the process exits). The list stays locked afterwards: no temporary can be created or
/// committed any more, so nothing new appears between the cleanup and the exit.
pub fn remove_open_temporaries() {
    let guard = OPEN_TEMPS.lock().unwrap_or_else(|p| p.into_inner());
    for p in guard.iter() {
        // Worker threads may still be adding frames to a temporary directory: retry.
        for _ in 0..50 {
            let gone = if p.is_dir() {
                fs::remove_dir_all(p).is_ok() || !p.exists()
            } else {
                fs::remove_file(p).is_ok() || !p.exists()
            };
            if gone {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }
    std::mem::forget(guard);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uncommitted_file_leaves_nothing_and_keeps_existing() {
        let dir = std::env::temp_dir().join(format!("formation-io-test-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.json");
        fs::write(&target, b"old").unwrap();
        {
            let mut f = AtomicFile::create(&target).unwrap();
            f.writer().write_all(b"new partial").unwrap();
            // dropped without commit
        }
        assert_eq!(fs::read(&target).unwrap(), b"old");
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
        write_bytes_atomic(&target, b"new").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unknown_extension_is_rejected() {
        let e = OutputKind::from_path(Path::new("a.xyz"), &[OutputKind::Json]).unwrap_err();
        assert!(e.to_string().contains("a.xyz"));
        assert_eq!(e.exit_code(), 2);
    }
}

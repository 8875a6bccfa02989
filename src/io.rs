//! File input and output shared by every stage: reading JSON with messages that name the file and
//! the line, and writing outputs atomically (a temporary file beside the target, then a rename), so
//! that a failed or interrupted run leaves no partial file and never truncates an existing one.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::error::{Error, Result};

/// Upper bound on the size of any input file, bytes: 6 GiB, enough for the largest animation
/// file `formation` writes ([`crate::limits::MAX_BIRD_FRAMES`] bird-frames: up to 2.5 GB compact
/// for a wide sky of formations, whose coordinates have more digits, and 5.0 GB with `pretty`).
/// Animation files are parsed as they are read (their text is never held whole); other inputs
/// are small in practice and read whole.
pub const MAX_INPUT_BYTES: u64 = 6 * 1024 * 1024 * 1024;

/// Opens an input for reading, refusing directories and regular files over the size limit up
/// front. Devices, FIFOs and process substitutions (`<(…)`) are read too, through a bounded
/// reader: their size is only known once read. Also gives the size of a regular file, so that
/// its whole text is read into one allocation of that size (no doubling: reading a 28 MB file
/// took a 32 MiB buffer beside the 16 MiB one it grew from).
fn open_input(path: &Path) -> Result<(std::io::Take<fs::File>, u64, usize)> {
    let meta = fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::format(path, "is a directory, expected a file"));
    }
    let limit = if meta.is_file() {
        MAX_INPUT_BYTES
    } else {
        MAX_STREAM_BYTES
    };
    if meta.len() > limit {
        return Err(too_big(path, Some(meta.len()), limit));
    }
    let file = fs::File::open(path).map_err(|e| Error::io(path, e))?;
    // One byte more than the file, so that reaching its end needs no reallocation either.
    let hint = if meta.is_file() {
        usize::try_from(meta.len()).map_or(0, |n| n.saturating_add(1))
    } else {
        0
    };
    Ok((std::io::Read::take(file, limit + 1), limit, hint))
}

fn too_big(path: &Path, len: Option<u64>, limit: u64) -> Error {
    match len {
        Some(n) => Error::format(
            path,
            format!("input is {n} bytes, more than the {limit} byte limit"),
        ),
        None if limit < MAX_INPUT_BYTES => Error::format(
            path,
            format!(
                "more than {limit} bytes from a pipe or device (the limit for inputs that are \
                 not regular files); give the file itself"
            ),
        ),
        None => Error::format(path, format!("input is more than the {limit} byte limit")),
    }
}

/// Size of the chunks inputs are read in, bytes.
const READ_CHUNK: usize = 1 << 20;

/// Upper bound on what is read from an input that is not a regular file (a pipe, a FIFO, a
/// device, a process substitution `<(…)`), bytes: 256 MiB. Its size is only known once read, so
/// the bound is also the memory an endless stream can take before it is refused.
pub const MAX_STREAM_BYTES: u64 = 256 * 1024 * 1024;

/// Reads a whole file as bytes, with the path in the error and a size limit that also holds for
/// devices and pipes (`/dev/zero` is refused after 2 GiB, not read until memory runs out).
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    let (mut reader, limit, hint) = open_input(path)?;
    let mut buf = Vec::with_capacity(hint);
    std::io::Read::read_to_end(&mut reader, &mut buf).map_err(|e| Error::io(path, e))?;
    if buf.len() as u64 > limit {
        return Err(too_big(path, None, limit));
    }
    Ok(buf)
}

/// Reads a whole file as UTF-8 text. The text is checked while it is read, so binary data (a NUL
/// byte, bytes that are not UTF-8: `/dev/zero`, `/dev/urandom`, an image given by mistake) is
/// refused after the first chunk rather than after reading it all.
pub fn read_text(path: &Path) -> Result<String> {
    let (mut reader, limit, hint) = open_input(path)?;
    let mut buf: Vec<u8> = Vec::with_capacity(hint);
    let mut chunk = vec![0u8; READ_CHUNK];
    // Bytes of `buf` known to be complete, valid UTF-8.
    let mut valid = 0usize;
    loop {
        let n = match std::io::Read::read(&mut reader, &mut chunk) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Error::io(path, e)),
        };
        if (buf.len() + n) as u64 > limit {
            return Err(too_big(path, None, limit));
        }
        if buf.is_empty() {
            if let Some(e) = utf16_text(path, &chunk[..n]) {
                return Err(e);
            }
        }
        if let Some(k) = chunk[..n].iter().position(|&b| b == 0) {
            return Err(Error::format(
                path,
                format!(
                    "binary data (a NUL byte at offset {}), expected a text file",
                    buf.len() + k
                ),
            ));
        }
        buf.extend_from_slice(&chunk[..n]);
        match std::str::from_utf8(&buf[valid..]) {
            Ok(_) => valid = buf.len(),
            // A character cut by the chunk boundary: check it with the next chunk.
            Err(e) if e.error_len().is_none() => valid += e.valid_up_to(),
            Err(e) => return Err(not_utf8(path, valid + e.valid_up_to())),
        }
    }
    if valid < buf.len() {
        return Err(not_utf8(path, valid));
    }
    String::from_utf8(buf).map_err(|e| not_utf8(path, e.utf8_error().valid_up_to()))
}

/// An error naming UTF-16 text (as Windows tools such as PowerShell's `>` and Excel's "Unicode
/// text" write it) when `head`, the file's first bytes, starts with a UTF-16 byte-order mark or
/// has the zero high bytes of ASCII in UTF-16; `None` otherwise.
fn utf16_text(path: &Path, head: &[u8]) -> Option<Error> {
    let order = match head {
        [0xFF, 0xFE, ..] => Some("little-endian"),
        [0xFE, 0xFF, ..] => Some("big-endian"),
        _ => {
            // Without a mark: ASCII characters with a zero byte beside each one.
            let pairs: Vec<&[u8]> = head.chunks_exact(2).take(64).collect();
            let ascii = |b: u8| b == b'\t' || b == b'\n' || b == b'\r' || (0x20..0x7F).contains(&b);
            if pairs.len() >= 2 && pairs.iter().all(|p| p[1] == 0 && ascii(p[0])) {
                Some("little-endian")
            } else if pairs.len() >= 2 && pairs.iter().all(|p| p[0] == 0 && ascii(p[1])) {
                Some("big-endian")
            } else {
                None
            }
        }
    }?;
    Some(Error::format(
        path,
        format!(
            "UTF-16 text ({order}), expected UTF-8; save it as UTF-8 (e.g. `iconv -f UTF-16 -t UTF-8`)"
        ),
    ))
}

fn not_utf8(path: &Path, offset: usize) -> Error {
    Error::format(
        path,
        format!("not UTF-8 text (invalid byte at offset {offset})"),
    )
}

/// Parses JSON text into `T`, turning serde's message into one line naming the file, line and column.
/// A leading byte-order mark (written by some Windows editors) is skipped.
pub fn parse_json<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
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

/// An input read as UTF-8 text in chunks, with the checks of [`read_text`] made as the bytes go
/// by (the size limit, UTF-16, NUL bytes, UTF-8 across chunk boundaries, a leading byte-order
/// mark skipped), for parsers that stream: memory stays at one chunk whatever the file's size.
/// A failed check ends the reading with an I/O error; [`TextInput::error`] then holds the
/// message naming the file.
pub struct TextInput<R = std::io::Take<fs::File>> {
    reader: R,
    path: PathBuf,
    limit: u64,
    /// Bytes read from the file so far.
    read: u64,
    /// Bytes checked and ready to be served: `buf[pos..end]`; `buf[end..]` is the start of a
    /// character cut by the chunk boundary, kept for the next chunk.
    buf: Vec<u8>,
    pos: usize,
    end: usize,
    started: bool,
    done: bool,
    /// Some byte other than JSON whitespace was seen.
    content: bool,
    error: Option<Error>,
}

impl TextInput {
    /// Opens `path` for streaming (directories and files over the size limit refused at once).
    pub fn open(path: &Path) -> Result<TextInput> {
        let (reader, limit, _) = open_input(path)?;
        Ok(TextInput::new(path, reader, limit))
    }
}

impl<R: std::io::Read> TextInput<R> {
    /// Streams `reader`, named `path` in messages, refusing more than `limit` bytes.
    pub fn new(path: &Path, reader: R, limit: u64) -> TextInput<R> {
        TextInput {
            reader,
            path: path.to_path_buf(),
            limit,
            read: 0,
            buf: Vec::new(),
            pos: 0,
            end: 0,
            started: false,
            done: false,
            content: false,
            error: None,
        }
    }

    /// The check that stopped the reading, if one did.
    pub fn error(&mut self) -> Option<Error> {
        self.error.take()
    }

    /// Whether everything read so far was whitespace (an empty file, for its message).
    pub fn blank(&self) -> bool {
        !self.content
    }

    fn fail(&mut self, e: Error) -> std::io::Error {
        let text = e.to_string();
        self.error = Some(e);
        self.done = true;
        std::io::Error::new(std::io::ErrorKind::InvalidData, text)
    }

    /// Reads and checks the next chunk; false at the end of the input.
    fn refill(&mut self) -> std::io::Result<bool> {
        // The cut character's bytes move to the front.
        let carry = self.buf.len() - self.end;
        self.buf.copy_within(self.end.., 0);
        self.buf.resize(carry + READ_CHUNK, 0);
        let n = loop {
            match std::io::Read::read(&mut self.reader, &mut self.buf[carry..]) {
                Ok(n) => break n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    let path = self.path.clone();
                    return Err(self.fail(Error::io(&path, e)));
                }
            }
        };
        self.buf.truncate(carry + n);
        let offset = self.read - carry as u64;
        self.read += n as u64;
        if self.read > self.limit {
            let e = too_big(&self.path, None, self.limit);
            return Err(self.fail(e));
        }
        self.pos = 0;
        if n == 0 {
            self.end = 0;
            if carry > 0 {
                let e = not_utf8(&self.path, offset as usize);
                return Err(self.fail(e));
            }
            self.buf.clear();
            return Ok(false);
        }
        if !self.started {
            self.started = true;
            if let Some(e) = utf16_text(&self.path, &self.buf) {
                return Err(self.fail(e));
            }
            if self.buf.starts_with("\u{feff}".as_bytes()) {
                self.pos = 3;
            }
        }
        if let Some(k) = self.buf.iter().position(|&b| b == 0) {
            let e = Error::format(
                &self.path,
                format!(
                    "binary data (a NUL byte at offset {}), expected a text file",
                    offset + k as u64
                ),
            );
            return Err(self.fail(e));
        }
        self.end = match std::str::from_utf8(&self.buf) {
            Ok(_) => self.buf.len(),
            Err(e) if e.error_len().is_none() => e.valid_up_to(),
            Err(e) => {
                let e = not_utf8(&self.path, offset as usize + e.valid_up_to());
                return Err(self.fail(e));
            }
        };
        if !self.content {
            self.content = self.buf[self.pos..self.end]
                .iter()
                .any(|b| !matches!(b, b' ' | b'\t' | b'\n' | b'\r'));
        }
        Ok(true)
    }
}

impl<R: std::io::Read> std::io::Read for TextInput<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        while self.pos == self.end {
            if self.done || !self.refill()? {
                self.done = true;
                return Ok(0);
            }
        }
        let n = out.len().min(self.end - self.pos);
        if n == 1 {
            out[0] = self.buf[self.pos];
        } else {
            out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        }
        self.pos += n;
        Ok(n)
    }
}

/// Parses the JSON file at `path` into `T` while reading it ([`TextInput`]): the text is never
/// held whole, so a large file takes the memory of what it parses into, not twice that. Errors
/// as [`read_json`]'s.
pub fn read_json_streaming<T: DeserializeOwned>(path: &Path) -> Result<T> {
    parse_json_streaming(TextInput::open(path)?)
}

/// [`read_json_streaming`] of any input (the fuzz targets stream bytes held in memory).
pub fn parse_json_streaming<T: DeserializeOwned, R: std::io::Read>(
    mut input: TextInput<R>,
) -> Result<T> {
    let path = input.path.clone();
    let path = path.as_path();
    // Through a `BufReader`: the standard library reads its bytes one by one without a call each
    // (serde_json's reader asks byte by byte; three times faster than asking the input).
    let parsed = serde_json::from_reader(std::io::BufReader::with_capacity(1 << 16, &mut input));
    match parsed {
        Ok(v) => Ok(v),
        Err(e) => Err(match input.error() {
            Some(read) => read,
            None if e.is_eof() && input.blank() => {
                Error::format(path, "file is empty, expected JSON")
            }
            None => json_error(path, &e),
        }),
    }
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

/// Kind of output, chosen by the output path's extension (or a trailing `/` / existing directory).
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
    /// `.mp4` (H.264 video through the system ffmpeg)
    Mp4,
    /// `.webm` (VP9 video through the system ffmpeg)
    Webm,
    /// `.html` (the self-contained page of `report`)
    Html,
}

impl OutputKind {
    /// Classifies an output path (an animation's or a chart's `output`). Unknown extensions are an
    /// error naming the path and the choices.
    pub fn from_path(path: &Path, allowed: &[OutputKind]) -> Result<OutputKind> {
        Self::for_flag("output", path, allowed)
    }

    /// Classifies an output path named `flag` in errors (e.g. `report`).
    /// The format follows the name: a trailing `/` asks for a frames directory, a known extension
    /// for that format (an existing directory of that name is refused, not filled with frames),
    /// and an existing directory without an extension is a frames directory.
    pub fn for_flag(flag: &str, path: &Path, allowed: &[OutputKind]) -> Result<OutputKind> {
        let s = path.to_string_lossy();
        let by_extension = match path
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
            Some("mp4") => Some(OutputKind::Mp4),
            Some("webm") => Some(OutputKind::Webm),
            Some("usda") => Some(OutputKind::Usda),
            Some("html") | Some("htm") => Some(OutputKind::Html),
            _ => None,
        };
        let kind = if s.ends_with('/') || s.ends_with(std::path::MAIN_SEPARATOR) {
            Some(OutputKind::Directory)
        } else if let Some(k) = by_extension {
            // A pipe, socket or device under that name would be replaced by a regular file
            // (outputs are written to a temporary and renamed): refused instead.
            if std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
                return Err(Error::parameter(
                    flag,
                    format!(
                        "{}: exists and is not a regular file (a pipe, socket or device), which \
                         the {} output would replace; remove it or choose another name",
                        path.display(),
                        k.describe()
                    ),
                ));
            }
            if path.is_dir() {
                return Err(Error::parameter(
                    flag,
                    format!(
                        "{}: is an existing directory, so it cannot be written as a {} file; \
                         remove it or choose another name",
                        path.display(),
                        k.describe()
                    ),
                ));
            }
            Some(k)
        } else if path.is_dir() {
            Some(OutputKind::Directory)
        } else {
            None
        };
        match kind {
            Some(k) if allowed.contains(&k) => Ok(k),
            _ => Err(Error::parameter(
                flag,
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
            OutputKind::Mp4 => ".mp4",
            OutputKind::Webm => ".webm",
            OutputKind::Html => ".html",
        }
    }
}

/// Every temporary `formation` creates is named `.formation-PID-RANDOM.tmp` (a file),
/// `.formation-PID-RANDOM.tmpdir` (a directory of frames) or `.formation-PID-RANDOM.old` (an
/// output being replaced), in the target's own directory so that the final rename is atomic. The
/// name does not depend on the target's (a legal 255-byte output name still works), RANDOM is
/// drawn from the operating system and the temporary is created exclusively (`O_EXCL`, which never
/// follows a symbolic link), so nothing planted at a predictable path can redirect a write.
const TEMP_PREFIX: &str = ".formation-";

/// Length of the random part of a temporary's name.
const TEMP_RANDOM_LEN: usize = 12;

/// `frames/` → `frames`: a frames directory is named with a trailing slash on the command line.
fn without_trailing_slash(target: &Path) -> PathBuf {
    PathBuf::from(target.to_string_lossy().trim_end_matches('/'))
}

/// The directory a target lives in (`.` for a bare file name).
fn dir_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Runs `make` with a builder of our temporaries' names: `.formation-PID-RANDOM{suffix}`.
fn with_temp_builder<T>(
    suffix: &str,
    make: impl FnOnce(&tempfile::Builder) -> std::io::Result<T>,
) -> std::io::Result<T> {
    let prefix = format!("{TEMP_PREFIX}{}-", std::process::id());
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(suffix).rand_bytes(TEMP_RANDOM_LEN);
    make(&b).map_err(without_temp_path)
}

/// tempfile's errors append "at path …" naming the temporary; the user named the output, and
/// messages name that, so keep the operating system's own error only.
fn without_temp_path(e: std::io::Error) -> std::io::Error {
    let text = e.to_string();
    match text.find(" at path \"") {
        Some(cut) if e.get_ref().is_some() => std::io::Error::new(e.kind(), &text[..cut]),
        _ => e,
    }
}

/// Creates a new temporary file in `dir`, exclusively, with an unpredictable name.
fn create_temp_file(dir: &Path) -> std::io::Result<(fs::File, PathBuf)> {
    // Outputs get the permissions any new file gets (0666 less the umask), not a temporary's 0600.
    let named = with_temp_builder(".tmp", |b| {
        use std::os::unix::fs::PermissionsExt;
        b.clone()
            .permissions(fs::Permissions::from_mode(0o666))
            .tempfile_in(dir)
    })?;
    let (file, path) = named.into_parts();
    let path = path.keep().map_err(|e| e.error)?;
    Ok((file, path))
}

/// Creates a new temporary directory in `dir`, exclusively, with an unpredictable name.
fn create_temp_dir(dir: &Path) -> std::io::Result<PathBuf> {
    Ok(with_temp_builder(".tmpdir", |b| b.tempdir_in(dir))?.keep())
}

/// A fresh, unused name for the backup of an output being replaced (nothing is left there).
fn backup_name(dir: &Path) -> std::io::Result<PathBuf> {
    // Reserve the name exclusively, then free it: the rename onto it happens under the registry
    // lock right after; had something appeared there meanwhile, a file rename would replace that
    // entry itself (rename never follows a link) and a directory rename would fail.
    let named = with_temp_builder(".old", |b| b.tempfile_in(dir))?;
    let path = named.path().to_path_buf();
    named.close()?;
    Ok(path)
}

/// The PID in a temporary's name of ours, if `name` is one.
fn temp_owner_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(TEMP_PREFIX)?;
    let (pid, rest) = rest.split_once('-')?;
    let (random, suffix) = rest.split_once('.')?;
    let pid: u32 = pid.parse().ok()?;
    let ours = random.len() == TEMP_RANDOM_LEN
        && random.bytes().all(|b| b.is_ascii_alphanumeric())
        && matches!(suffix, "tmp" | "tmpdir" | "old");
    ours.then_some(pid)
}

/// Removes the temporaries of earlier `formation` runs that died without cleaning up (SIGKILL, a
/// power cut) from `dir`: only entries named exactly as ours, whose process no longer runs,
/// owned by the same user as `witness` (a temporary we just created), and never a symbolic link.
/// Linux only (process liveness is read from `/proc`); elsewhere nothing is removed.
fn remove_stale_temporaries(dir: &Path, witness: &Path) {
    use std::os::unix::fs::MetadataExt;
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let Ok(me) = fs::symlink_metadata(witness) else {
        return;
    };
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temp_owner_pid) else {
            continue;
        };
        if pid == std::process::id() || proc.join(pid.to_string()).exists() {
            continue;
        }
        let path = entry.path();
        let Ok(meta) = fs::symlink_metadata(&path) else {
            continue;
        };
        if meta.file_type().is_symlink() || meta.uid() != me.uid() {
            continue;
        }
        // remove_dir_all never follows links inside the directory.
        let _ = if meta.is_dir() {
            fs::remove_dir_all(&path)
        } else {
            fs::remove_file(&path)
        };
    }
}

/// Registers a new temporary (created by `create` under the registry lock, so that a signal
/// cannot leave it unregistered) and, the first time a directory is used, removes stale
/// temporaries of dead runs from it.
fn new_temporary<T>(
    dir: &Path,
    create: impl FnOnce(&Path) -> std::io::Result<(T, PathBuf)>,
) -> std::io::Result<(T, PathBuf)> {
    let (value, path, first_use) = with_registry(|r| -> std::io::Result<_> {
        let (value, path) = create(dir)?;
        r.open.push(path.clone());
        let first_use = r.cleaned_dirs.insert(dir.to_path_buf());
        Ok((value, path, first_use))
    })?;
    if first_use {
        remove_stale_temporaries(dir, &path);
    }
    Ok((value, path))
}

/// A finished temporary waiting to be moved onto its target.
#[derive(Debug)]
struct Pending {
    tmp: PathBuf,
    target: PathBuf,
}

/// Moves `p.tmp` onto `p.target`. An existing target is kept as a backup (returned) when
/// `keep_backup` is set or when it is a directory (a directory cannot be renamed over); files are
/// replaced by one atomic rename, so a reader sees either the old or the new file, never neither.
fn put_in_place(p: &Pending, keep_backup: bool) -> std::io::Result<Option<PathBuf>> {
    let existing = fs::symlink_metadata(&p.target).ok();
    let is_dir = existing.as_ref().is_some_and(|m| m.is_dir());
    if existing.is_none() || !(keep_backup || is_dir) {
        fs::rename(&p.tmp, &p.target)?;
        return Ok(None);
    }
    let backup = backup_name(&dir_of(&p.target))?;
    if is_dir {
        fs::rename(&p.target, &backup)?;
    } else {
        // A hard link keeps the old file under the backup name while the rename below replaces
        // the target atomically (link() never follows a symbolic link on Linux).
        fs::hard_link(&p.target, &backup)?;
    }
    if let Err(e) = fs::rename(&p.tmp, &p.target) {
        if is_dir {
            let _ = fs::rename(&backup, &p.target);
        } else {
            let _ = fs::remove_file(&backup);
        }
        return Err(e);
    }
    Ok(Some(backup))
}

/// Removes a file or directory, whichever it is (never following a link).
fn remove_any(path: &Path) {
    match fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => {
            let _ = fs::remove_dir_all(path);
        }
        Ok(_) => {
            let _ = fs::remove_file(path);
        }
        Err(_) => {}
    }
}

/// Moves every pending temporary onto its target, or none: if one rename fails, the targets
/// already replaced get their old content back and the remaining temporaries are removed.
fn commit_all(registry: &mut Registry, pending: Vec<Pending>) -> Result<()> {
    let keep_backups = pending.len() > 1;
    let mut done: Vec<(usize, Option<PathBuf>)> = Vec::new();
    let mut failure = None;
    for (k, p) in pending.iter().enumerate() {
        match put_in_place(p, keep_backups) {
            Ok(backup) => done.push((k, backup)),
            Err(e) => {
                failure = Some((k, e));
                break;
            }
        }
    }
    if let Some((k, e)) = failure {
        for (i, backup) in done.into_iter().rev() {
            let target = &pending[i].target;
            match backup {
                Some(b) => {
                    if fs::symlink_metadata(target).is_ok_and(|m| m.is_dir()) {
                        let _ = fs::remove_dir_all(target);
                    }
                    let _ = fs::rename(&b, target);
                }
                None => remove_any(target),
            }
        }
        discard_queued(registry, &pending);
        return Err(Error::io(&pending[k].target, e));
    }
    for (_, backup) in done {
        if let Some(b) = backup {
            remove_any(&b);
        }
    }
    registry.forget(pending.iter().map(|p| &p.tmp));
    Ok(())
}

/// Removes queued temporaries that will not be committed, and forgets them.
fn discard_queued(registry: &mut Registry, pending: &[Pending]) {
    for p in pending {
        remove_any(&p.tmp);
    }
    registry.forget(pending.iter().map(|p| &p.tmp));
}

/// Hands a finished temporary to the open [`OutputBatch`], or moves it into place at once when
/// there is none.
fn finish(tmp: PathBuf, target: PathBuf) -> Result<()> {
    with_registry(|r| {
        let p = Pending { tmp, target };
        match r.batch.as_mut() {
            Some(queue) => {
                let id = output_identity(&p.target);
                if queue.iter().any(|q| output_identity(&q.target) == id) {
                    // Two outputs of one run on the same file: the second would silently replace
                    // the first. Callers check this up front; this is the last line of defence.
                    remove_any(&p.tmp);
                    r.forget(std::iter::once(&p.tmp));
                    return Err(Error::format(
                        &p.target,
                        "is given as two outputs of this command; name each output once",
                    ));
                }
                queue.push(p);
                Ok(())
            }
            None => commit_all(r, vec![p]),
        }
    })
}

/// Whether `a` and `b` name one existing file: the same device and inode on Unix (whatever the
/// spelling, `..` or links), the same canonical path elsewhere. A name that does not exist is
/// no file's.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (fs::metadata(a), fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (fs::canonicalize(a), fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// What makes two output names the same file: the canonical directory and the file name
/// (`a.json`, `./a.json` and `../d/a.json` from inside `d` are one output).
pub fn output_identity(target: &Path) -> PathBuf {
    let trimmed = without_trailing_slash(target);
    match (fs::canonicalize(dir_of(&trimmed)), trimmed.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => trimmed,
    }
}

/// Checks that the directory an output goes into exists, naming `flag` when it does not, so that
/// a run fails before any work rather than after the other outputs are written.
pub fn check_output_dir(flag: &str, target: &Path) -> Result<()> {
    let trimmed = without_trailing_slash(target);
    let parent = dir_of(&trimmed);
    if parent.is_dir() {
        Ok(())
    } else {
        Err(Error::parameter(
            flag,
            format!(
                "{}: directory {} does not exist; create it first",
                target.display(),
                parent.display()
            ),
        ))
    }
}

/// A file being written atomically: data goes to a temporary file in the target's directory and
/// only [`AtomicFile::commit`] moves it into place (or queues it in the open [`OutputBatch`]).
/// Dropping it uncommitted removes the temporary.
pub struct AtomicFile {
    target: PathBuf,
    tmp: PathBuf,
    writer: Option<BufWriter<fs::File>>,
}

impl AtomicFile {
    /// Creates the temporary file for `target`. Fails (naming `target`) if its directory is missing
    /// or not writable, or if `target` is a directory.
    pub fn create(target: &Path) -> Result<AtomicFile> {
        set_current_output(target);
        if target.is_dir() {
            return Err(Error::format(
                target,
                "is a directory, expected a file name",
            ));
        }
        let (file, tmp) =
            new_temporary(&dir_of(target), create_temp_file).map_err(|e| Error::io(target, e))?;
        Ok(AtomicFile {
            target: target.to_path_buf(),
            tmp,
            writer: Some(BufWriter::new(file)),
        })
    }

    /// Path of the temporary file, for a writer that opens it by name (the system ffmpeg);
    /// [`AtomicFile::commit`] still renames it into place.
    pub fn temp_path(&self) -> &Path {
        &self.tmp
    }

    /// The buffered writer of the temporary file.
    pub fn writer(&mut self) -> &mut BufWriter<fs::File> {
        self.writer.as_mut().expect("writer present until commit")
    }

    /// Flushes and syncs the temporary file, then renames it onto the target (at once, or when
    /// the open [`OutputBatch`] commits). On any failure the temporary is removed and the target
    /// left as it was.
    pub fn commit(mut self) -> Result<()> {
        let writer = self.writer.take().expect("writer present until commit");
        let synced = writer
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| file.sync_all());
        if let Err(e) = synced {
            discard(&self.tmp);
            return Err(Error::io(&self.target, e));
        }
        finish(self.tmp.clone(), self.target.clone())
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
        if self.writer.take().is_some() {
            discard(&self.tmp);
        }
    }
}

/// Removes an unfinished temporary and forgets it.
fn discard(tmp: &Path) {
    let _ = with_registry(|r| -> std::io::Result<()> {
        remove_any(tmp);
        r.forget(std::iter::once(tmp));
        Ok(())
    });
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
    write_json_atomic_as(target, value, true)
}

/// [`write_json_atomic`], indented (`pretty`) or compact (one line, no spaces: about a third
/// smaller for animations).
pub fn write_json_atomic_as<T: Serialize>(target: &Path, value: &T, pretty: bool) -> Result<()> {
    crate::finite::check_serialize(&target.display().to_string(), value)?;
    let mut f = AtomicFile::create(target)?;
    let written = if pretty {
        serde_json::to_writer_pretty(f.writer(), value)
    } else {
        serde_json::to_writer(f.writer(), value)
    };
    written.map_err(|e| {
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
/// [`AtomicDir::commit`] renames onto the target (replacing an existing directory only after the
/// new one is complete), at once or when the open [`OutputBatch`] commits.
pub struct AtomicDir {
    target: PathBuf,
    tmp: PathBuf,
    committed: bool,
}

impl AtomicDir {
    /// Creates the temporary directory for `target`.
    pub fn create(target: &Path) -> Result<AtomicDir> {
        set_current_output(target);
        let trimmed = without_trailing_slash(target);
        if fs::symlink_metadata(&trimmed).is_ok_and(|m| !m.is_dir()) {
            return Err(Error::format(&trimmed, "exists and is not a directory"));
        }
        let ((), tmp) = new_temporary(&dir_of(&trimmed), |d| Ok(((), create_temp_dir(d)?)))
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
        self.committed = true;
        finish(self.tmp.clone(), self.target.clone())
    }
}

impl Drop for AtomicDir {
    fn drop(&mut self) {
        if !self.committed {
            discard(&self.tmp);
        }
    }
}

/// All outputs of one run, committed together or not at all (a failed run leaves no
/// output). While a batch is open, [`AtomicFile::commit`] and [`AtomicDir::commit`] only queue
/// their temporaries; [`OutputBatch::commit`] moves them all into place, restoring the earlier
/// targets if one rename fails; dropping the batch uncommitted removes every queued temporary.
/// The binary opens one batch around each command.
#[must_use = "an output batch that is dropped discards every output queued in it"]
pub struct OutputBatch {
    committed: bool,
}

impl OutputBatch {
    /// Opens the batch. Fails if one is already open (batches do not nest).
    pub fn begin() -> Result<OutputBatch> {
        with_registry(|r| -> std::io::Result<_> {
            if r.batch.is_some() {
                return Ok(false);
            }
            r.batch = Some(Vec::new());
            Ok(true)
        })
        .map_err(|e| Error::Internal(e.to_string()))
        .and_then(|opened| {
            if opened {
                Ok(OutputBatch { committed: false })
            } else {
                Err(Error::Internal("an output batch is already open".into()))
            }
        })
    }

    /// Moves every queued output into place, all or none.
    pub fn commit(mut self) -> Result<()> {
        self.committed = true;
        with_registry(|r| {
            let pending = r.batch.take().unwrap_or_default();
            commit_all(r, pending)
        })
    }
}

impl Drop for OutputBatch {
    fn drop(&mut self) {
        if !self.committed {
            let _ = with_registry(|r| -> std::io::Result<()> {
                let pending = r.batch.take().unwrap_or_default();
                discard_queued(r, &pending);
                Ok(())
            });
        }
    }
}

/// Temporaries still open (so that a signal handler in the binary can remove them before
/// exiting), the queue of the open [`OutputBatch`], and the directories already cleaned of stale
/// temporaries. Creating, committing and removing a temporary all happen under this lock, so
/// the handler sees every temporary that exists and never runs in the middle of a commit.
#[derive(Default)]
struct Registry {
    open: Vec<PathBuf>,
    batch: Option<Vec<Pending>>,
    cleaned_dirs: std::collections::BTreeSet<PathBuf>,
}

impl Registry {
    fn forget<'a, P: AsRef<Path> + ?Sized + 'a>(&mut self, paths: impl Iterator<Item = &'a P>) {
        for p in paths {
            self.open.retain(|q| q.as_path() != p.as_ref());
        }
    }
}

static REGISTRY: std::sync::Mutex<Option<Registry>> = std::sync::Mutex::new(None);

/// Runs `f` on the registry of open temporaries, locked (a poisoned lock is taken over: the
/// registry is a list of paths, consistent after any panic).
fn with_registry<R>(f: impl FnOnce(&mut Registry) -> R) -> R {
    let mut guard = REGISTRY.lock().unwrap_or_else(|p| p.into_inner());
    f(guard.get_or_insert_with(Registry::default))
}

/// The output being written now (set by the writers), named when memory runs out.
static CURRENT_OUTPUT: std::sync::Mutex<Option<PathBuf>> = std::sync::Mutex::new(None);

/// Records `path` as the output being written, for [`out_of_memory`]'s message (the input
/// recorded before is done with).
pub fn set_current_output(path: &Path) {
    let mut g = CURRENT_OUTPUT.lock().unwrap_or_else(|p| p.into_inner());
    *g = Some(path.to_path_buf());
    drop(g);
    let mut i = CURRENT_INPUT.lock().unwrap_or_else(|p| p.into_inner());
    *i = None;
}

/// The input being worked on now (an image being decoded and searched), named when memory runs
/// out before any output is being written.
static CURRENT_INPUT: std::sync::Mutex<Option<PathBuf>> = std::sync::Mutex::new(None);

/// Records `path` as the input being worked on, for [`out_of_memory`]'s message, until an
/// output is being written.
pub fn set_current_input(path: &Path) {
    let mut g = CURRENT_INPUT.lock().unwrap_or_else(|p| p.into_inner());
    *g = Some(path.to_path_buf());
}

/// What the binary does when an allocation of `bytes` fails (its allocator calls this instead of
/// aborting): removes the run's temporaries (the outputs it replaces are untouched until the
/// final rename, so they stay as they were), writes one line on stderr naming the output being
/// written and the size, and ends the process with exit code 2. Nothing here allocates except
/// the removal of a temporary directory; locks are only tried, so an allocation that failed while
/// one was held cannot deadlock.
pub fn out_of_memory(bytes: usize) -> ! {
    if let Ok(mut guard) = REGISTRY.try_lock() {
        if let Some(r) = guard.as_mut() {
            for p in r.open.iter() {
                remove_any(p);
            }
        }
        // Keep it locked: nothing is created or committed between the cleanup and the exit.
        std::mem::forget(guard);
    }
    let mut line = [0u8; 1024];
    let len = {
        let mut w: &mut [u8] = &mut line;
        let output = CURRENT_OUTPUT.try_lock().ok();
        let what = output.as_ref().and_then(|g| g.as_deref());
        let input = CURRENT_INPUT.try_lock().ok();
        let input = input.as_ref().and_then(|g| g.as_deref());
        let _ = match (input, what) {
            (Some(p), _) => writeln!(
                w,
                "error: {}: out of memory while working on this input: {bytes} more bytes could not be allocated; give a smaller one or raise the memory limit; no output written",
                p.display()
            ),
            (None, what) => match what {
            Some(p) => writeln!(
                w,
                "error: {}: out of memory: {bytes} more bytes could not be allocated; lower the picture size, the frame rate, the flock or the length, or raise the memory limit; no output written",
                p.display()
            ),
            None => writeln!(
                w,
                "error: out of memory: {bytes} more bytes could not be allocated; lower the flock, the length or the picture size, or raise the memory limit; no output written"
            ),
            },
        };
        1024 - w.len()
    };
    let _ = std::io::Write::write_all(&mut std::io::stderr(), &line[..len]);
    std::process::exit(2)
}

/// Removes every temporary file or directory still open (called on a terminating signal, right
/// before the process exits). The registry stays locked afterwards: no temporary can be created
/// or committed any more, so nothing new appears between the cleanup and the exit.
pub fn remove_open_temporaries() {
    let mut guard = REGISTRY.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(r) = guard.as_mut() {
        for p in r.open.iter() {
            // Worker threads may still be adding frames to a temporary directory: retry.
            for _ in 0..50 {
                remove_any(p);
                if fs::symlink_metadata(p).is_err() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
        }
    }
    std::mem::forget(guard);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf16_text_is_named_with_or_without_a_mark() {
        let p = Path::new("a.json");
        let le: Vec<u8> = "{\"frames\": []}"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        let be: Vec<u8> = "x,y\n1,2\n"
            .encode_utf16()
            .flat_map(|u| u.to_be_bytes())
            .collect();
        let marked = [&[0xFF, 0xFE][..], &le].concat();
        for (head, order) in [(&marked, "little"), (&le, "little"), (&be, "big")] {
            let e = utf16_text(p, head).expect("UTF-16").to_string();
            assert!(e.contains("UTF-16 text") && e.contains(order), "{e}");
        }
        // UTF-8 text, binary data and a lone zero are not UTF-16 text.
        for head in [
            &b"{\"frames\": []}"[..],
            &[0x89, b'P', b'N', b'G', 0, 0][..],
            &[0u8][..],
        ] {
            assert!(utf16_text(p, head).is_none(), "{head:?}");
        }
    }

    #[test]
    fn uncommitted_file_leaves_nothing_and_keeps_existing() {
        let dir = std::env::temp_dir().join(format!("formation-io-test-{}", std::process::id()));
        // Empty: a run that died here with the same PID (PIDs wrap) may have left files.
        let _ = fs::remove_dir_all(&dir);
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

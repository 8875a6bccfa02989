//! Where frames come from: a video decoded by the system `ffmpeg` into raw grey frames over a
//! pipe, a directory of images (PNG or JPEG, in name order), or a glob of image files
//! (`*`, `?` in the last path component, e.g. `clip/frame_*.png`).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use super::detect::Gray;
use crate::error::{Error, Result};

/// Image file extensions read from directories and globs.
pub const IMAGE_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// A source of frames.
pub enum Input {
    /// A video file (its size and rate come with its frames, [`VideoFrames::start`]).
    Video {
        /// The file.
        path: PathBuf,
        /// Frame width, pixels (0 until decoding starts).
        width: usize,
        /// Frame height, pixels (0 until decoding starts).
        height: usize,
        /// Frames per second (`None` until decoding starts, or when the video does not say).
        fps: Option<f64>,
    },
    /// Image files in order.
    Images(Vec<PathBuf>),
}

fn is_image(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .map(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        .unwrap_or(false)
}

/// Matches a file name against a glob of `*` (any run) and `?` (any one character).
pub fn glob_match(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    let (mut i, mut j, mut star, mut mark) = (0usize, 0usize, None::<usize>, 0usize);
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// Opens `input`: a directory, a glob, an image file or a video.
pub fn open(input: &Path) -> Result<Input> {
    let text = input.to_string_lossy();
    if input.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(input)
            .map_err(|e| Error::io(input, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file() && is_image(p))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::format(
                input,
                "the directory holds no image (.png, .jpg, .jpeg); give a directory of frames, a glob such as 'frames/*.png', or a video",
            ));
        }
        return Ok(Input::Images(files));
    }
    if !input.exists() && (text.contains('*') || text.contains('?')) {
        let dir = input
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let pattern = input
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if dir.to_string_lossy().contains(['*', '?']) {
            return Err(Error::format(
                input,
                "a glob may only use * and ? in the file name, not in directories",
            ));
        }
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(|e| Error::io(dir, e))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.is_file()
                    && p.file_name()
                        .map(|n| glob_match(&pattern, &n.to_string_lossy()))
                        .unwrap_or(false)
            })
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::format(input, "no file matches this pattern"));
        }
        return Ok(Input::Images(files));
    }
    if !input.exists() {
        return Err(Error::format(input, "no such file or directory"));
    }
    if is_image(input) {
        return Ok(Input::Images(vec![input.to_path_buf()]));
    }
    probe(input)
}

/// A video: the one `ffmpeg` that decodes it also tells its size and rate (no separate probe,
/// so a pipe or a FIFO is read once, and the size is that of the frames ffmpeg hands over, after
/// it turned them by the video's rotation metadata).
fn probe(path: &Path) -> Result<Input> {
    Ok(Input::Video {
        path: path.to_path_buf(),
        width: 0,
        height: 0,
        fps: None,
    })
}

/// Frames of a video in order, read from ffmpeg's pipe as YUV4MPEG (grey): a header line with
/// the frame size and rate, then `FRAME` lines each followed by the pixels. ffmpeg's messages
/// are collected beside it; decoder errors in them are counted ([`VideoFrames::finish`]).
pub struct VideoFrames {
    child: Child,
    out: std::io::BufReader<std::process::ChildStdout>,
    errors: Option<std::thread::JoinHandle<String>>,
    path: PathBuf,
    /// Frame width, pixels (as decoded and turned upright).
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Frames per second, when the video says.
    pub fps: Option<f64>,
}

fn read_line(r: &mut impl std::io::BufRead, max: usize) -> std::io::Result<Vec<u8>> {
    let mut line = Vec::new();
    let mut byte = [0u8; 1];
    loop {
        match r.read(&mut byte) {
            Ok(0) => return Ok(line),
            Ok(_) if byte[0] == b'\n' => return Ok(line),
            Ok(_) => {
                line.push(byte[0]);
                if line.len() > max {
                    return Ok(line);
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

impl VideoFrames {
    /// Starts decoding `path` and reads the stream's header (frame size and rate).
    pub fn start(path: &Path) -> Result<VideoFrames> {
        let mut child = Command::new(crate::export::pictures::ffmpeg_program())
            .args(["-hide_banner", "-nostdin", "-loglevel", "error", "-i"])
            .arg(path)
            .args([
                "-map",
                "0:v:0",
                "-f",
                "yuv4mpegpipe",
                "-pix_fmt",
                "gray",
                "pipe:1",
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                Error::format(
                    path,
                    format!("videos are decoded by ffmpeg, which did not run ({e}); install ffmpeg, or give a directory of image frames"),
                )
            })?;
        // ffmpeg's messages are drained beside the frames, so that many of them cannot fill
        // the pipe and stall it.
        let errors = child.stderr.take().map(|mut e| {
            std::thread::spawn(move || {
                let mut text = String::new();
                let mut buf = Vec::new();
                let _ = e.read_to_end(&mut buf);
                text.push_str(&String::from_utf8_lossy(&buf));
                text
            })
        });
        let Some(stdout) = child.stdout.take() else {
            return Err(Error::Internal("ffmpeg's output pipe".into()));
        };
        let mut v = VideoFrames {
            child,
            out: std::io::BufReader::with_capacity(1 << 20, stdout),
            errors,
            path: path.to_path_buf(),
            width: 0,
            height: 0,
            fps: None,
        };
        let header = match read_line(&mut v.out, 4096) {
            Ok(h) => h,
            Err(e) => {
                v.stop();
                return Err(Error::io(path, e));
            }
        };
        let header = String::from_utf8_lossy(&header).into_owned();
        if !header.starts_with("YUV4MPEG2 ") {
            let why = v.stop_with_messages();
            let why = why.lines().last().unwrap_or("").trim().to_string();
            return Err(Error::format(
                path,
                format!(
                    "ffmpeg cannot decode this as a video{}; give a video, a directory of images or a glob",
                    if why.is_empty() { String::new() } else { format!(" ({why})") }
                ),
            ));
        }
        for field in header.split_whitespace().skip(1) {
            let (tag, value) = field.split_at(1);
            match tag {
                "W" => v.width = value.parse().unwrap_or(0),
                "H" => v.height = value.parse().unwrap_or(0),
                "F" => {
                    let (a, b) = value.split_once(':').unwrap_or((value, "1"));
                    if let (Ok(a), Ok(b)) = (a.parse::<f64>(), b.parse::<f64>()) {
                        let f = a / b;
                        if f.is_finite() && f > 0.0 && f <= crate::limits::MAX_FPS {
                            v.fps = Some(f);
                        }
                    }
                }
                _ => {}
            }
        }
        let (w, h) = (v.width, v.height);
        if w == 0 || h == 0 || (w as u64) * (h as u64) > crate::limits::MAX_FRAME_PIXELS {
            v.stop();
            return Err(Error::format(
                path,
                format!("{w}x{h} frames: outside 1 pixel to 8K UHD"),
            ));
        }
        Ok(v)
    }

    /// The next frame, `None` at the end.
    pub fn next_frame(&mut self) -> Result<Option<Gray>> {
        let line = read_line(&mut self.out, 4096).map_err(|e| Error::io(&self.path, e))?;
        if line.is_empty() {
            return Ok(None);
        }
        if !line.starts_with(b"FRAME") {
            return Err(Error::format(
                &self.path,
                "ffmpeg's frames went out of step; the video is damaged",
            ));
        }
        let n = self.width * self.height;
        let mut data = vec![0u8; n];
        let mut got = 0;
        while got < n {
            match self.out.read(&mut data[got..]) {
                Ok(0) => break,
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::io(&self.path, e)),
            }
        }
        if got < n {
            return Err(Error::format(
                &self.path,
                "ffmpeg stopped in the middle of a frame; the video is truncated or damaged",
            ));
        }
        Ok(Some(Gray {
            width: self.width,
            height: self.height,
            data,
        }))
    }

    /// Waits for ffmpeg after `frames` decoded frames. An error when it gave none; otherwise a
    /// warning (returned) when it reported decoder errors: the video is damaged or cut short,
    /// and frames may be missing.
    pub fn finish(mut self, frames: usize) -> Result<Option<String>> {
        let status = self.child.wait().map_err(|e| Error::io(&self.path, e))?;
        let err = self
            .errors
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
        if frames == 0 {
            let why = lines.last().map(|l| l.trim()).unwrap_or("no frame");
            return Err(Error::format(
                &self.path,
                format!("ffmpeg cannot decode this video ({why})"),
            ));
        }
        if lines.is_empty() && status.success() {
            return Ok(None);
        }
        Ok(Some(format!(
            "{}: ffmpeg decoded {frames} frames and reported {} error{} (first: {}); the video is damaged or cut short and frames may be missing; repair or re-encode it (ffmpeg -i IN -c:v ffv1 OUT.mkv) to see what is left",
            self.path.display(),
            lines.len().max(1),
            if lines.len() == 1 { "" } else { "s" },
            lines.first().map(|l| l.trim()).unwrap_or("exit status")
        )))
    }

    fn stop_with_messages(mut self) -> String {
        let _ = self.child.kill();
        let _ = self.child.wait();
        self.errors
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default()
    }

    /// Stops decoding early.
    pub fn stop(self) {
        let _ = self.stop_with_messages();
    }
}

/// Reads one image file as grey.
pub fn read_image(path: &Path) -> Result<Gray> {
    use image::ImageDecoder as _;
    crate::io::set_current_input(path);
    let bytes = crate::io::read_bytes(path)?;
    let undecodable = |e: image::ImageError| {
        Error::format(
            path,
            format!("cannot decode this image ({e}); give PNG or JPEG frames"),
        )
    };
    // The size from the header, checked before any pixel is decoded: a small file can announce
    // a picture of gigabytes, whose allocation would end the run without naming the image.
    let decoder = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| Error::io(path, e))?
        .into_decoder()
        .map_err(undecodable)?;
    let (w, h) = decoder.dimensions();
    let (w, h) = (w as usize, h as usize);
    if (w as u64) * (h as u64) > crate::limits::MAX_FRAME_PIXELS {
        return Err(Error::format(
            path,
            format!("{w}x{h} is larger than 8K UHD"),
        ));
    }
    // The decoded picture and its grey copy must fit in the memory left.
    let need = decoder
        .total_bytes()
        .saturating_add((w as u64) * (h as u64));
    if crate::limits::memory_budget().is_some_and(|m| need > m) {
        return Err(Error::format(
            path,
            format!(
                "{w}x{h}: decoding it needs {} MB, more than the memory left; give smaller frames or raise the memory limit",
                need.div_ceil(1_000_000)
            ),
        ));
    }
    let img = image::DynamicImage::from_decoder(decoder).map_err(undecodable)?;
    let g = img.to_luma8();
    Ok(Gray {
        width: w,
        height: h,
        data: g.into_raw(),
    })
}

#[cfg(test)]
mod tests {
    use super::glob_match;

    #[test]
    fn globs_match_like_a_shell() {
        assert!(glob_match("frame_*.png", "frame_0001.png"));
        assert!(glob_match("f??.png", "f01.png"));
        assert!(!glob_match("f??.png", "f001.png"));
        assert!(!glob_match("*.png", "a.jpg"));
        assert!(glob_match("*", "anything"));
    }
}

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
    /// A video file, with its size and frame rate as `ffprobe` reports them.
    Video {
        /// The file.
        path: PathBuf,
        /// Frame width, pixels.
        width: usize,
        /// Frame height, pixels.
        height: usize,
        /// Frames per second (`None` when the container does not say).
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

/// The `ffprobe` beside the `ffmpeg` in use.
fn ffprobe_program() -> PathBuf {
    let ff = crate::export::pictures::ffmpeg_program();
    match ff.file_name().and_then(|n| n.to_str()) {
        Some(n) if n.contains("ffmpeg") => ff.with_file_name(n.replacen("ffmpeg", "ffprobe", 1)),
        _ => PathBuf::from("ffprobe"),
    }
}

fn probe(path: &Path) -> Result<Input> {
    let out = Command::new(ffprobe_program())
        .args(["-v", "error", "-select_streams", "v:0"])
        .args(["-show_entries", "stream=width,height,avg_frame_rate,r_frame_rate"])
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(path)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| {
            Error::format(
                path,
                format!("videos are decoded by ffmpeg/ffprobe, which did not run ({e}); install ffmpeg, or give a directory of image frames"),
            )
        })?;
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{name}=")))
            .map(|v| v.trim().to_string())
    };
    let width = field("width").and_then(|v| v.parse::<usize>().ok());
    let height = field("height").and_then(|v| v.parse::<usize>().ok());
    let (Some(width), Some(height)) = (width, height) else {
        let why = String::from_utf8_lossy(&out.stderr);
        let why = why.lines().last().unwrap_or("").trim().to_string();
        return Err(Error::format(
            path,
            format!(
                "ffmpeg cannot decode this as a video{}; give a video, a directory of images or a glob",
                if why.is_empty() { String::new() } else { format!(" ({why})") }
            ),
        ));
    };
    if width == 0
        || height == 0
        || (width as u64) * (height as u64) > crate::limits::MAX_FRAME_PIXELS
    {
        return Err(Error::format(
            path,
            format!("{width}x{height} frames: outside 1 pixel to 8K UHD"),
        ));
    }
    let rate = |s: Option<String>| -> Option<f64> {
        let s = s?;
        let (a, b) = s.split_once('/').unwrap_or((&s, "1"));
        let (a, b) = (a.parse::<f64>().ok()?, b.parse::<f64>().ok()?);
        let f = a / b;
        (f.is_finite() && f > 0.0 && f <= crate::limits::MAX_FPS).then_some(f)
    };
    let fps = rate(field("avg_frame_rate")).or(rate(field("r_frame_rate")));
    Ok(Input::Video {
        path: path.to_path_buf(),
        width,
        height,
        fps,
    })
}

/// Frames of a video in order, read from ffmpeg's pipe.
pub struct VideoFrames {
    child: Child,
    path: PathBuf,
    width: usize,
    height: usize,
}

impl VideoFrames {
    /// Starts decoding `path` (`width × height` frames).
    pub fn start(path: &Path, width: usize, height: usize) -> Result<VideoFrames> {
        let child = Command::new(crate::export::pictures::ffmpeg_program())
            .args(["-hide_banner", "-nostdin", "-loglevel", "error", "-i"])
            .arg(path)
            .args([
                "-map", "0:v:0", "-f", "rawvideo", "-pix_fmt", "gray", "pipe:1",
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| Error::format(path, format!("ffmpeg did not start: {e}")))?;
        Ok(VideoFrames {
            child,
            path: path.to_path_buf(),
            width,
            height,
        })
    }

    /// The next frame, `None` at the end.
    pub fn next_frame(&mut self) -> Result<Option<Gray>> {
        let n = self.width * self.height;
        let mut data = vec![0u8; n];
        let Some(out) = self.child.stdout.as_mut() else {
            return Ok(None);
        };
        let mut got = 0;
        while got < n {
            match out.read(&mut data[got..]) {
                Ok(0) => break,
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::io(&self.path, e)),
            }
        }
        if got == 0 {
            return Ok(None);
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

    /// Waits for ffmpeg; an error when it failed before giving any frame is the caller's to
    /// judge (`frames` read so far).
    pub fn finish(mut self, frames: usize) -> Result<()> {
        drop(self.child.stdout.take());
        let mut err = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut err);
        }
        let status = self.child.wait().map_err(|e| Error::io(&self.path, e))?;
        if frames == 0 && !status.success() {
            let why = err.lines().last().unwrap_or("").trim().to_string();
            return Err(Error::format(
                &self.path,
                format!("ffmpeg cannot decode this video ({why})"),
            ));
        }
        Ok(())
    }

    /// Stops decoding early.
    pub fn stop(mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
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

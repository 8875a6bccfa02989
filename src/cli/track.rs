//! `formation track INPUT -o annotations.json`: find and track the birds of a video, a
//! directory of images or a glob ([`formation::track`]), and write the native annotations with
//! the footage's `fps`, per-frame wingspan and heading, and a confidence per bird.

use std::path::PathBuf;

use clap::Args;
use formation::io::{write_bytes_atomic, OutputKind};
use formation::track::{review, track_path, Polarity, TrackOptions};
use formation::{Error, Result};

use super::Global;

/// Arguments of `formation track`.
#[derive(Debug, Args)]
pub struct TrackArgs {
    /// A video (decoded by ffmpeg), a directory of PNG/JPEG frames, or a glob such as
    /// 'clip/frame_*.png'.
    pub input: PathBuf,
    /// Output annotations (.json, the native format `formation extract` reads).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Also write a review page (.html): the frames with the birds drawn, to correct them in a
    /// browser and save the corrected annotations.
    #[arg(long, value_name = "PAGE.html")]
    pub review: Option<PathBuf>,
    /// Birds darker than the sky (dark), brighter (bright), or decided on the first frame (auto).
    #[arg(long, default_value = "auto", value_name = "auto|dark|bright")]
    pub polarity: String,
    /// Annotate every K-th frame (1 = every frame).
    #[arg(
        long,
        default_value = "1",
        value_name = "K",
        allow_hyphen_values = true
    )]
    pub every: String,
    /// Frames to read, 0-based, B excluded: A..B, or A.. to the end.
    #[arg(long, value_name = "A..B", allow_hyphen_values = true)]
    pub frames: Option<String>,
    /// Region to search, pixels: x,y,w,h (default: the whole frame).
    #[arg(long, value_name = "X,Y,W,H", allow_hyphen_values = true)]
    pub roi: Option<String>,
    /// Frames per second of the footage (default: the video's; image frames have none).
    #[arg(long, value_name = "F", allow_hyphen_values = true)]
    pub fps: Option<String>,
    /// The birds' wingspan on screen, pixels, when known: sets the detection's scale and the
    /// wingspan written (default: measured from the birds that last).
    #[arg(long, value_name = "PX", allow_hyphen_values = true)]
    pub wingspan_px: Option<String>,
    /// Write every processed frame into DIR as a PNG with the detections, tracks and background
    /// drawn, to see why a bird was missed.
    #[arg(long, value_name = "DIR")]
    pub debug_frames: Option<PathBuf>,
}

fn bad(name: &str, message: String) -> Error {
    Error::parameter(name, message)
}

/// The options the flags give.
pub fn options(a: &TrackArgs) -> Result<TrackOptions> {
    let polarity: Polarity = a.polarity.parse().map_err(|m| bad("track.polarity", m))?;
    let every: usize = a.every.trim().parse().map_err(|_| {
        bad(
            "track.every",
            format!("`{}` is not a whole number of frames; give K >= 1", a.every),
        )
    })?;
    let frames = match &a.frames {
        None => (0, None),
        Some(s) => {
            let msg = || {
                bad(
                    "track.frames",
                    format!("`{s}` is not a frame range; give A..B (B excluded) or A.., 0-based"),
                )
            };
            let (x, y) = s.trim().split_once("..").ok_or_else(msg)?;
            let x: usize = x.trim().parse().map_err(|_| msg())?;
            let y = match y.trim() {
                "" => None,
                y => Some(y.parse::<usize>().map_err(|_| msg())?),
            };
            (x, y)
        }
    };
    let roi = match &a.roi {
        None => None,
        Some(s) => {
            let v: Vec<usize> = s
                .split(',')
                .map(|p| p.trim().parse::<usize>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| {
                    bad(
                        "track.roi",
                        format!("`{s}` is not a region; give x,y,w,h in whole pixels"),
                    )
                })?;
            let [x, y, w, h] = v[..] else {
                return Err(bad(
                    "track.roi",
                    format!("`{s}` has {} numbers; give x,y,w,h", v.len()),
                ));
            };
            Some([x, y, w, h])
        }
    };
    let fps = match &a.fps {
        None => None,
        Some(s) => Some(s.trim().parse::<f64>().map_err(|_| {
            bad(
                "track.fps",
                format!("`{s}` is not a frame rate; give frames per second, e.g. 25"),
            )
        })?),
    };
    let wingspan_px = match &a.wingspan_px {
        None => None,
        Some(s) => Some(s.trim().parse::<f64>().map_err(|_| {
            bad(
                "track.wingspan_px",
                format!(
                    "`{s}` is not a number of pixels; give a bird's wingspan on screen, e.g. 26"
                ),
            )
        })?),
    };
    let opts = TrackOptions {
        polarity,
        every,
        frames,
        roi,
        fps,
        wingspan_px,
        debug_frames: a.debug_frames.clone(),
    };
    opts.validate()?;
    Ok(opts)
}

/// Runs `formation track`.
pub fn run(args: TrackArgs, g: Global) -> Result<()> {
    OutputKind::for_flag("-o", &args.output, &[OutputKind::Json])?;
    if let Some(r) = &args.review {
        OutputKind::for_flag("--review", r, &[OutputKind::Html])?;
    }
    let opts = options(&args)?;
    formation::io::check_output_dir("-o", &args.output)?;
    if let Some(d) = &args.debug_frames {
        std::fs::create_dir_all(d).map_err(|e| {
            Error::parameter(
                "track.debug_frames",
                format!("cannot make the directory {} ({e}); give a directory to write the debug frames into", d.display()),
            )
        })?;
    }
    if let Some(r) = &args.review {
        formation::io::check_output_dir("--review", r)?;
    }
    let progress = super::progress::TermProgress::new(g.quiet);
    let mut jpegs = std::collections::BTreeMap::new();
    let mut failed: Option<Error> = None;
    let tracked = track_path(&args.input, &opts, &progress, |k, frame| {
        if args.review.is_none() || failed.is_some() {
            return;
        }
        if jpegs.len() == review::MAX_FRAMES {
            failed = Some(Error::parameter(
                "review",
                format!(
                    "a review page holds at most {} frames; choose fewer with --every or --frames",
                    review::MAX_FRAMES
                ),
            ));
            return;
        }
        match review::frame_jpeg(frame) {
            Ok(j) => {
                jpegs.insert(k, j);
            }
            Err(e) => failed = Some(e),
        }
    })?;
    if let Some(e) = failed {
        return Err(e);
    }
    let warnings: Vec<&str> = tracked.warnings.iter().map(String::as_str).collect();
    super::warn_lines(super::flags::Cmd::Track, g, &warnings)?;
    let text = tracked.to_native();
    write_bytes_atomic(&args.output, text.as_bytes())?;
    if let Some(r) = &args.review {
        let name = args
            .output
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "annotations.json".into());
        write_bytes_atomic(r, review::page(&tracked, &jpegs, &name).as_bytes())?;
    }
    if !g.quiet {
        let decoded = tracked
            .decoded
            .map(|n| format!(" of {n} decoded"))
            .unwrap_or_default();
        eprintln!(
            "{}: {} frames tracked{decoded}, {} tracks, wingspan {:.1} px, heading {:.1} deg",
            args.input.display(),
            tracked.frames.len(),
            tracked.track_count(),
            tracked.wingspan_px(),
            tracked.heading_deg()
        );
    }
    Ok(())
}

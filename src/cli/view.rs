//! `formation view ANIMATION -o player.html`: the library's self-contained 3-D player page
//! ([`formation::player`]) of an animation file, written atomically.

use std::path::PathBuf;

use clap::Args;
use formation::io::{write_bytes_atomic, OutputKind};
use formation::player::{page, PlayerOptions, MAX_EVERY};
use formation::sniff::Kind;
use formation::{Animation, Error, Result};

use super::Global;

/// Arguments of `formation view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// An animation file (.json, with its binary frames file if it has one).
    pub input: PathBuf,
    /// Output page (.html): one file that plays offline in any browser with WebGL 2.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Number of the animation's first frame on the page's timeline (e.g. 1001; default: the
    /// animation file's, else 0).
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = parse_start_frame)]
    pub start_frame: Option<u64>,
    /// Keep every K-th frame in the page (1 = all, the default); the player interpolates between
    /// the kept frames, so positions stay smooth but wingbeats faster than fps/(2K) alias. For
    /// very large flocks: the page holds 32 bytes a bird and kept frame.
    #[arg(long, value_name = "K", default_value_t = 1, allow_negative_numbers = true, value_parser = parse_every)]
    pub every: usize,
}

fn parse_start_frame(s: &str) -> std::result::Result<u64, String> {
    let max = formation::export::MAX_START_FRAME;
    match s.trim().parse::<i64>() {
        Ok(v) if (0..=max as i64).contains(&v) => Ok(v as u64),
        _ => Err(format!(
            "the first frame is a whole number from 0 to {max} (studios use 0, 1, 101 or 1001)"
        )),
    }
}

fn parse_every(s: &str) -> std::result::Result<usize, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if (1..=MAX_EVERY as i64).contains(&v) => Ok(v as usize),
        _ => Err(format!(
            "keep every K-th frame with K a whole number from 1 (every frame) to {MAX_EVERY}"
        )),
    }
}

/// Runs `formation view`.
pub fn run(args: ViewArgs, g: Global) -> Result<()> {
    OutputKind::for_flag("-o", &args.output, &[OutputKind::Html])?;
    formation::io::check_output_dir("-o", &args.output)?;
    let kind = formation::sniff::path_kind(&args.input)?;
    if kind != Kind::Animation {
        return Err(Error::format(
            &args.input,
            "not an animation file (view plays what steady, initiate, animate or render --json write)",
        ));
    }
    let anim = Animation::read(&args.input)?;
    let title = args
        .input
        .file_name()
        .map_or_else(|| "animation".into(), |n| n.to_string_lossy().into_owned());
    let html = page(
        &anim,
        &PlayerOptions {
            title,
            start_frame: args.start_frame,
            every: args.every,
        },
    )?;
    write_bytes_atomic(&args.output, html.as_bytes())?;
    let what = format!(
        "a 3-D player of {} birds, {} frames ({})",
        anim.birds,
        anim.frames.len().div_ceil(args.every),
        super::summary::human_size(&(html.len() as u64))
    );
    super::summary::chart(g, "view", &what, &args.input, &args.output);
    Ok(())
}

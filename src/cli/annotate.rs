//! `formation annotate ANNOTATIONS --images FRAMES -o review.html`: the review page of
//! `formation track` for annotations made elsewhere (any format `extract` reads: a tracker's
//! file, DLTdv, Labelme, long CSV, native JSON) over the footage's frames, to check and correct
//! them in a browser and save the corrected native JSON.

use std::path::PathBuf;

use clap::Args;
use formation::annotations;
use formation::io::{write_bytes_atomic, OutputKind};
use formation::track::{review, source};
use formation::{Error, Result};

use super::extract::ReadArgs;
use super::Global;

/// Arguments of `formation annotate`.
#[derive(Debug, Args)]
pub struct AnnotateArgs {
    /// Annotations in any format `extract` reads.
    pub annotations: PathBuf,
    /// The footage's frames: a directory of PNG/JPEG images or a glob such as
    /// 'clip/frame_*.png', in frame order (a frame shows the image its annotation names, else the
    /// image at its frame index from 0).
    #[arg(long, value_name = "DIR|GLOB")]
    pub images: PathBuf,
    /// The review page to write (.html).
    #[arg(short = 'o', long = "output", value_name = "PAGE.html")]
    pub output: PathBuf,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// Runs `formation annotate`.
pub fn run(args: AnnotateArgs, g: Global) -> Result<()> {
    OutputKind::for_flag("-o", &args.output, &[OutputKind::Html])?;
    formation::io::check_output_dir("-o", &args.output)?;
    let ann = annotations::read(&args.annotations, &args.read.options())?;
    // 3-D tracks are world positions, not pixels of the images, and the page saves 2-D birds.
    if let Some(f) = ann
        .frames
        .iter()
        .find(|f| f.birds.iter().any(|b| b.height.is_some()))
    {
        return Err(Error::format(
            &args.annotations,
            format!(
                "frame {}: 3-D positions (with heights), which are not pixels of the images and which the page would drop on saving; review the 2-D tracks they were made from",
                f.index
            ),
        ));
    }
    let images = match source::open(&args.images) {
        Ok(source::Input::Images(files)) => files,
        Ok(source::Input::Video { .. }) => {
            return Err(Error::parameter(
                "annotate.images",
                format!(
                    "{}: a video; give its frames as images (e.g. ffmpeg -i VIDEO frames/%05d.png)",
                    args.images.display()
                ),
            ))
        }
        Err(e) => return Err(e),
    };
    let name = args
        .annotations
        .file_stem()
        .map(|n| format!("{}_reviewed.json", n.to_string_lossy()))
        .unwrap_or_else(|| "annotations.json".into());
    let page = review::annotations_page(&ann, &images, &name)?;
    write_bytes_atomic(&args.output, page.as_bytes())?;
    if !g.quiet {
        let birds: usize = ann.frames.iter().map(|f| f.birds.len()).sum();
        eprintln!(
            "wrote {} ({:.1} MB): {} frames, {birds} marks over {} images; Save downloads {name}",
            args.output.display(),
            page.len() as f64 / 1e6,
            ann.frames.len(),
            images.len()
        );
    }
    Ok(())
}

//! `formation report INPUT -o report.html`: reads annotations (extracted on the
//! fly), a params file or an animation, and writes the library's self-contained page
//! ([`formation::report`]) atomically.

use std::path::PathBuf;

use clap::Args;
use formation::extract::FormationParams;
use formation::io::{write_bytes_atomic, OutputKind};
use formation::report::{report, Subject};
use formation::sniff::Kind;
use formation::{Animation, Result};

use super::extract::ExtractionArgs;
use super::Global;

/// Arguments of `formation report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Annotations (any format), a params file written by `formation extract`, or an animation
    /// file.
    pub input: PathBuf,
    /// Output page (.html).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    #[command(flatten)]
    pub extraction: ExtractionArgs,
    #[command(flatten)]
    pub savings: super::wake::SavingsFlags,
}

/// Runs `formation report`.
pub fn run(args: ReportArgs, g: Global) -> Result<()> {
    OutputKind::for_flag("-o", &args.output, &[OutputKind::Html])?;
    let extract = args.extraction.options();
    extract.validate()?;
    // The savings flags are checked before any work.
    let footage_aero = args.savings.aero(None)?;
    formation::io::check_output_dir("-o", &args.output)?;
    let kind = formation::sniff::path_kind(&args.input)?;
    let (params, animation, threshold): (Option<FormationParams>, Option<Animation>, _) = match kind
    {
        Kind::Animation => {
            let mut a = Animation::read(&args.input)?;
            args.savings.apply(&mut a)?;
            (None, Some(a), None)
        }
        Kind::Params => (Some(FormationParams::read(&args.input)?), None, None),
        _ => {
            let (_, p, _) = super::extract::read_and_extract(
                &args.input,
                &args.extraction.read,
                extract,
                g,
                super::flags::Cmd::Report,
            )?;
            (Some(p), None, Some(extract.inlier_threshold))
        }
    };
    if let Some(p) = &params {
        super::warn_params(g, p)?;
    }
    let page = report(&Subject {
        origin: &args.input,
        params: params.as_ref(),
        threshold,
        animation: animation.as_ref(),
        aero: footage_aero,
    })?;
    write_bytes_atomic(&args.output, page.as_bytes())?;
    let what = match (&params, &animation) {
        (Some(p), _) => format!(
            "a page on {} annotated frames (shape {}, fits, spacing, savings by {})",
            p.frames.len(),
            super::summary::dominant(p),
            footage_aero.unwrap_or_default().record()
        ),
        (None, Some(a)) => format!(
            "a page on an animation of {} birds, {} frames (savings by {}, take-off, steady flight){}",
            a.birds,
            a.frames.len(),
            a.savings_model
                .as_ref()
                .map_or("Hummel's model".to_string(), |m| m.to_string()),
            super::summary::clearance_text(a)
        ),
        (None, None) => "a page".to_string(),
    };
    super::summary::chart(g, "report", &what, &args.input, &args.output);
    Ok(())
}

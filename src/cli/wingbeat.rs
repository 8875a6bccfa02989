//! `formation plot wingbeat`: one wingbeat's joint angles over its phase.

use std::path::PathBuf;

use clap::Args;
use formation::plot::wingbeat::WingbeatChart;
use formation::wingbeat::{Glide, PhaseMode, Species, WingbeatOptions};
use formation::Result;

use super::Global;

/// Arguments of `formation plot wingbeat`.
#[derive(Debug, Args)]
pub struct PlotWingbeatArgs {
    /// Species preset: goose, crane or pelican.
    #[arg(long, default_value_t = Species::default().to_string())]
    pub species: String,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot wingbeat`.
pub fn run_plot_wingbeat(args: PlotWingbeatArgs, _g: Global) -> Result<()> {
    let species: Species = args.species.parse()?;
    super::chart::save(&WingbeatChart::new(species), &args.output)
}

/// Wingbeat flags shared by `steady`, `initiate` and `animate` (the wing phases written into the
/// animation file and drawn by the renderers; the `wingbeat` section of the library's `Config`,
/// defaults from `WingbeatOptions::default()`). Names are parsed by the library, whose messages
/// list the valid ones.
#[derive(Debug, Clone, Args)]
pub struct WingbeatFlags {
    /// Species preset of the wingbeat (frequency, amplitudes, downstroke fraction): goose, crane
    /// or pelican.
    #[arg(long, default_value_t = WingbeatOptions::default().species.to_string())]
    pub species: String,
    /// Phase relation between birds: `locked` (followers flap with a lag that tracks their
    /// streamwise distance to the bird ahead, Portugal et al. 2014) or `independent`.
    #[arg(long, default_value_t = WingbeatOptions::default().phase_mode.to_string(), value_name = "locked|independent")]
    pub phase: String,
    /// Gliding: `off` (continuous flapping), `bouts` (flap-gliding) or `always`.
    #[arg(long, default_value_t = WingbeatOptions::default().glide.to_string(), value_name = "off|bouts|always")]
    pub glide: String,
    /// Scale of the per-bird and per-wingbeat variation: 0 = identical birds, 1 = the species' own.
    #[arg(long = "wing-variation", default_value_t = WingbeatOptions::default().variation, allow_negative_numbers = true)]
    pub variation: f64,
}

impl WingbeatFlags {
    /// The library options (names parsed here; numbers validated by the library).
    pub fn options(&self) -> Result<WingbeatOptions> {
        Ok(WingbeatOptions {
            species: self.species.parse::<Species>()?,
            phase_mode: self.phase.parse::<PhaseMode>()?,
            glide: self.glide.parse::<Glide>()?,
            variation: self.variation,
            ..WingbeatOptions::default()
        })
    }
}

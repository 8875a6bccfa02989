//! `formation initiate` and `formation plot paths` (issue 5): flags → [`InitiateOptions`], run the
//! §6 simulation into the first key shape of a steady-flight file, write the combined animation.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use formation::animation::Animation;
use formation::initiate::{
    self, GroundStart, InitiateOptions, PerceptionMode, Start, StartRegion, StartState,
    HPR_GAMMA_DEFAULT,
};
use formation::io::OutputKind;
use formation::{Error, Result};

use super::progress::TermProgress;
use super::Global;

/// Occlusion model of the perception.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PerceptionArg {
    /// Hidden Point Removal (the paper's; radius R = max distance · 10^γ).
    Hpr,
    /// Birds as discs of half a wingspan occluding one another.
    Exact,
}

/// Arguments of `formation initiate`.
#[derive(Debug, Args)]
pub struct InitiateArgs {
    /// A steady-flight animation file (its first key shape is the target).
    pub steady: PathBuf,
    /// Outputs by extension: .json (the animation file), .csv, and also .gif, DIR/, .glb; may be
    /// repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    #[command(flatten)]
    pub initiate: InitiateFlags,
    #[command(flatten)]
    pub wingbeat: super::wingbeat::WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
    /// Print the run's statistics as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Initiation flags shared by `initiate` and `animate`.
#[derive(Debug, Clone, Args)]
pub struct InitiateFlags {
    /// Frame limit of the take-off at the output --fps (the time limit is also at most 300 s of
    /// flight); no convergence within it fails with exit 1.
    #[arg(long, default_value_t = InitiateOptions::default().max_steps)]
    pub max_steps: usize,
    /// Take-off duration, seconds: a longer take-off than the flock's natural one stretches the
    /// departures; a shorter one is not possible yet (warned) [default: the natural one, about
    /// 7 + 1.1 × birds seconds: 17 s for 9 birds, 22 s for 14, 52 s for 41; `--json` reports it].
    #[arg(long, allow_negative_numbers = true)]
    pub takeoff: Option<f64>,
    /// Cruise altitude of the steady flight above the ground (`z`), wingspans.
    #[arg(long, allow_negative_numbers = true, default_value_t = InitiateOptions::default().cruise_altitude)]
    pub cruise_altitude: f64,
    /// Largest climb rate after lift-off, wingspans per second.
    #[arg(long, allow_negative_numbers = true, default_value_t = InitiateOptions::default().climb_rate)]
    pub climb_rate: f64,
    /// Occlusion model.
    #[arg(long, value_enum, default_value_t = PerceptionArg::Hpr)]
    pub perception: PerceptionArg,
    /// HPR radius exponent γ: R = (distance of the farthest bird) · 10^γ.
    #[arg(long, allow_negative_numbers = true, default_value_t = HPR_GAMMA_DEFAULT)]
    pub hpr_gamma: f64,
    /// Visual field per eye, degrees from straight ahead (paper: 90); widened when the key shape
    /// needs it for a bird to see its reference from its slot (docs/initiation.md).
    #[arg(long, allow_negative_numbers = true, default_value_t = 90.0)]
    pub fov: f64,
    /// Cone per eye in which the closest visible bird is the preferred reference, degrees
    /// (paper: 0.35π = 63).
    #[arg(long, allow_negative_numbers = true, default_value_t = 63.0)]
    pub reference_cone: f64,
    /// α of eq. (6) (heading gain).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.2)]
    pub alpha: f64,
    /// |K| of eq. (5) (speed gain).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.06)]
    pub k: f64,
    /// Maximum turn rate, degrees per second.
    #[arg(long, allow_negative_numbers = true, default_value_t = 90.0)]
    pub max_turn_rate: f64,
    /// Maximum acceleration, wingspans per second squared [default: 4].
    #[arg(long, allow_negative_numbers = true)]
    pub max_accel: Option<f64>,
    /// Minimum flight speed, fraction of the cruise speed [default: 0.5].
    #[arg(long, allow_negative_numbers = true)]
    pub min_speed: Option<f64>,
    /// Maximum flight speed, fraction of the cruise speed [default: 1.6].
    #[arg(long, allow_negative_numbers = true)]
    pub max_speed: Option<f64>,
    /// Separation drive distance, wingspans [default: 10, as in the paper].
    #[arg(long, allow_negative_numbers = true)]
    pub separation: Option<f64>,
    /// Collision avoidance: predicted closest approach that triggers evasion, wingspans
    /// [default: 0.8].
    #[arg(long, allow_negative_numbers = true)]
    pub avoid_distance: Option<f64>,
    /// Convergence: every bird within this distance of its slot, wingspans [default: 0.1].
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Convergence: for this long, seconds (also the hand-over blend window) [default: 1].
    #[arg(long, allow_negative_numbers = true)]
    pub hold: Option<f64>,
    /// Start: `ground` (at rest in a take-off area, leaving one after another, climbing to the
    /// cruise altitude), `air` (the paper's: scattered in the air at the cruise altitude), or a
    /// start file: JSON {"x": [...], "y": [...], "heading": [...], "speed": [...]} (world frame,
    /// wingspans, radians clockwise from north, wingspans per second; heading and speed optional).
    #[arg(long, default_value = "ground")]
    pub start: String,
    /// Width of the take-off area (ground) or start region (air) across the cruise heading,
    /// wingspans [default: ground 4.5√N (with the depth, about 10 square wingspans per bird);
    /// air 30, or 6√N for large flocks].
    #[arg(long, allow_negative_numbers = true)]
    pub start_width: Option<f64>,
    /// Depth of the take-off area or start region along the cruise heading, wingspans
    /// [default: ground 2.2√N; air the width].
    #[arg(long, allow_negative_numbers = true)]
    pub start_depth: Option<f64>,
    /// Start headings are uniform within this many degrees of the cruise heading [default: 5
    /// on the ground, 180 (any) in the air].
    #[arg(long)]
    pub heading_spread: Option<f64>,
}

impl InitiateFlags {
    /// The library options these flags describe (validated by the library).
    pub fn options(&self, seed: u64, birds: usize) -> Result<InitiateOptions> {
        let mut o = InitiateOptions {
            seed,
            max_steps: self.max_steps,
            alpha: self.alpha,
            k: self.k,
            max_turn_rate: self.max_turn_rate.to_radians(),
            ..Default::default()
        };
        o.perception.fov_per_eye = self.fov.to_radians();
        o.perception.reference_cone = self.reference_cone.to_radians();
        o.perception.mode = match self.perception {
            PerceptionArg::Hpr => PerceptionMode::Hpr {
                gamma: self.hpr_gamma,
            },
            PerceptionArg::Exact => PerceptionMode::Exact,
        };
        let set = |field: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *field = v;
            }
        };
        set(&mut o.max_accel, self.max_accel);
        set(&mut o.min_speed, self.min_speed);
        set(&mut o.max_speed, self.max_speed);
        set(&mut o.separation_distance, self.separation);
        set(&mut o.avoid_distance, self.avoid_distance);
        set(&mut o.tolerance, self.tolerance);
        set(&mut o.hold, self.hold);
        o.takeoff = self.takeoff;
        if let Some(t) = self.takeoff {
            let natural = formation::initiate::TakeoffPlan::natural_seconds(birds);
            if t.is_finite() && t > 0.0 && t < 0.8 * natural {
                eprintln!(
                    "warning: --takeoff {t}: {birds} birds need about {natural:.0} s to form with these rules (docs/initiation.md); the take-off will last about that long"
                );
            }
        }
        o.cruise_altitude = self.cruise_altitude;
        o.climb_rate = self.climb_rate;
        if let Some(h) = self.heading_spread {
            if !(h.is_finite() && (0.0..=180.0).contains(&h)) {
                return Err(Error::parameter(
                    "--heading-spread",
                    format!("must be in [0, 180] degrees, got {h}"),
                ));
            }
        }
        o.start = match self.start.as_str() {
            "ground" => {
                let d = GroundStart::default();
                Start::Ground(GroundStart {
                    width: self.start_width,
                    depth: self.start_depth,
                    heading_spread: self
                        .heading_spread
                        .map_or(d.heading_spread, f64::to_radians),
                    ..d
                })
            }
            "air" => Start::Random(StartRegion {
                width: self.start_width,
                depth: self.start_depth,
                heading_spread: self
                    .heading_spread
                    .map_or(std::f64::consts::PI, f64::to_radians),
                ..Default::default()
            }),
            path => {
                for (flag, given) in [
                    ("--start-width", self.start_width.is_some()),
                    ("--start-depth", self.start_depth.is_some()),
                    ("--heading-spread", self.heading_spread.is_some()),
                ] {
                    if given {
                        return Err(Error::parameter(
                            flag,
                            "does not apply to a start file (--start FILE); give --start ground or air",
                        ));
                    }
                }
                Start::Given(StartState::read(std::path::Path::new(path), birds)?)
            }
        };
        o.validate()?;
        formation::initiate::check_size(birds, 0, self.max_steps)?;
        Ok(o)
    }
}

/// Runs `formation initiate`.
pub fn run(args: InitiateArgs, g: Global) -> Result<()> {
    let wing = args.wingbeat.options()?;
    formation::export::plan_outputs(&args.output)?;
    let steady = Animation::read(&args.steady)?;
    if steady.formations.is_none() {
        initiate::check_steady(&steady, &args.steady)?;
    }
    let opts = args.initiate.options(g.seed, steady.birds)?;
    let mut rng = formation::rng::stream(g.seed, "initiate");
    let progress = TermProgress::new(g.quiet);
    let (mut anim, stats) = if steady.formations.is_some() {
        // A flock of several formations takes off formation by formation (issue 13).
        let config = formation::pipeline::Config {
            seed: g.seed,
            initiate: opts,
            ..Default::default()
        };
        formation::pipeline::initiate_stage(&steady, &config, &progress)?
    } else {
        initiate::initiate(&steady, &opts, &mut rng, &progress)?
    };
    // Savings (e, ξ) in the take-off frames too.
    formation::aero::fill_frame_savings(&mut anim, &Default::default());
    formation::wingbeat::assign_phases(&mut anim, &wing)?;
    super::write_animation(&anim, &args.output, &args.scene.options(), g)?;
    if args.json {
        let text = formation::finite::to_json_pretty("statistics", &stats)?;
        super::stdout::println(&text)?;
    }
    Ok(())
}

/// Arguments of `formation plot paths`.
#[derive(Debug, Args)]
pub struct PlotPathsArgs {
    /// An animation file with an initiation stage.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    #[command(flatten)]
    pub formation: super::steady::FormationArg,
}

/// Runs `formation plot paths`.
pub fn run_plot_paths(args: PlotPathsArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let (a, which) = args
        .formation
        .pick(Animation::read(&args.input)?, &args.input)?;
    let mut chart = formation::plot::paths::PathsChart::from_animation(&a)
        .map_err(|e| Error::format(&args.input, e.to_string()))?;
    chart.title.push_str(which.as_deref().unwrap_or(""));
    formation::plot::save(&chart, &args.output)
}

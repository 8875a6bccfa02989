//! `formation steady`, `formation plot power` and `formation plot xi`: flags into
//! [`SteadyOptions`], the library's Algorithm 1, and the animation written as JSON or long CSV.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use formation::animation::Animation;
use formation::extract::params::FormationParams;
use formation::io::{write_json_atomic, OutputKind};
use formation::keyshape::{JostleOptions, KeyOptions, SteadyOptions};
use formation::pipeline::{flock_steady_stage, Config, SteadyOutcome};
use formation::plot::power::{PowerChart, PowerMetric, PowerOf};
use formation::plot::xi::XiChart;
use formation::skein::SkeinOptions;
use formation::{Error, Result};

use super::progress::TermProgress;
use super::Global;

/// Arguments of `formation steady`.
#[derive(Debug, Args)]
pub struct SteadyArgs {
    /// A params file written by `formation extract`.
    pub params: PathBuf,
    /// Number of birds to animate (N ≥ 2).
    #[arg(long)]
    pub birds: usize,
    /// Number of frames (F ≥ 1); or give --seconds.
    #[arg(long, conflicts_with = "seconds")]
    pub frames: Option<usize>,
    /// Length of the steady flight, seconds (frames = seconds × --fps); or give --frames.
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Outputs by extension: .json (the animation file), .csv, and also .gif, DIR/, .glb; may be
    /// repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    #[command(flatten)]
    pub steady: SteadyFlags,
    #[command(flatten)]
    pub path: super::course::PathFlags,
    #[command(flatten)]
    pub land: super::course::LandFlags,
    /// Height of the flight above the ground without a path, wingspans (without it the flight
    /// keeps the course frame's height, ready for `formation initiate`, which climbs to its own
    /// --cruise-altitude and adds this).
    #[arg(long = "cruise-altitude", allow_negative_numbers = true)]
    pub cruise_altitude: Option<f64>,
    #[command(flatten)]
    pub skein: SkeinFlags,
    #[command(flatten)]
    pub wingbeat: super::wingbeat::WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
    /// Also write the run's report (correspondence, ranges, solve statistics) as JSON here.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Steady-flight flags shared by `steady` and `animate` (the `steady` section of the library's
/// `Config`; defaults from `SteadyOptions::default()`).
#[derive(Debug, Clone, Args)]
pub struct SteadyFlags {
    /// Frames per second of the animation.
    #[arg(long, default_value_t = SteadyOptions::default().fps, allow_negative_numbers = true)]
    pub fps: f64,
    /// Time between key shapes, seconds.
    #[arg(long = "key-every", default_value_t = KeyOptions::default().key_every_s, allow_negative_numbers = true)]
    pub key_every: f64,
    /// Cruise speed of the flock, wingspans per second.
    #[arg(long, default_value_t = SteadyOptions::default().speed, allow_negative_numbers = true)]
    pub speed: f64,
    /// ε of eq. (2): widening of each bird's ξ range, in [0, 0.5].
    #[arg(long, default_value_t = KeyOptions::default().epsilon, allow_negative_numbers = true)]
    pub epsilon: f64,
    /// C1 of eq. (2): smallest step ratio of ξ between key shapes, in [0.5, 1].
    #[arg(long, default_value_t = KeyOptions::default().c1, allow_negative_numbers = true)]
    pub c1: f64,
    /// C2 of eq. (2): largest step ratio of ξ between key shapes, in [1, 2].
    #[arg(long, default_value_t = KeyOptions::default().c2, allow_negative_numbers = true)]
    pub c2: f64,
    /// Wingspan of one bird, metres (recorded in the animation; used by the .glb export).
    #[arg(long = "wingspan-m", default_value_t = SteadyOptions::default().wingspan_m, allow_negative_numbers = true)]
    pub wingspan_m: f64,
    /// Largest move of a bird between consecutive key shapes, wingspans.
    #[arg(long = "max-jump", default_value_t = KeyOptions::default().max_jump, allow_negative_numbers = true)]
    pub max_jump: f64,
    /// Scale of each bird's small, frequent moves about its slot: 1 = as measured in the
    /// footage (or the field-data default without footage timing), 0 = key-shape interpolation
    /// only; in [0, 10].
    #[arg(long, value_name = "S", default_value_t = JostleOptions::default().scale, allow_negative_numbers = true)]
    pub jostle: f64,
    /// Leader changes per minute of steady flight: the leader drops back into the first slot of
    /// an arm and that arm's first bird takes the lead, in a manoeuvre of a few seconds; 0 =
    /// never. Default: 1 with position keeping on (--jostle above 0), else 0.
    #[arg(
        long = "leader-changes",
        value_name = "R",
        allow_negative_numbers = true
    )]
    pub leader_changes: Option<f64>,
    /// Swaps of two neighbours along an arm per minute of steady flight; 0 = never. Default: 2
    /// with position keeping on, else 0.
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub swaps: Option<f64>,
    /// Late birds: K of the birds fly in from one side, about 30 wingspans out, and join at the
    /// free end of an arm in about 5.5 s, as in footage of wild geese; the others keep their
    /// order. Needs a flight without the take-off (--no-initiation for animate).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub joiners: usize,
    /// A seamless cycle: the last key shape is the first and the wingbeats make whole cycles, so
    /// the GIF, the glTF clip or a game's background flock loops without a jump (in the flock's
    /// moving frame; in the world on a closed --path). No take-off.
    #[arg(long = "loop")]
    pub looped: bool,
    /// Vortex core radius of Hummel's model, wingspans (docs/model.md).
    #[arg(long = "core-radius", value_name = "R", default_value_t = formation::aero::AeroOptions::default().core_radius, allow_negative_numbers = true)]
    pub core_radius: f64,
    /// Wake model of the savings: planar (Hummel's, heights ignored) or 3d (each bird's height
    /// in every frame; the key shapes are still solved in the plane).
    #[arg(long, value_enum, default_value_t = super::wake::WakeArg::Planar)]
    pub wake: super::wake::WakeArg,
    /// Model of the frames' savings: hummel (horseshoes with a core, the default) or lissaman
    /// (elliptic lifting lines, the kind the field studies used); the key shapes are solved with
    /// Hummel's model either way (docs/model.md).
    #[arg(long = "aero-model", value_enum, value_name = "MODEL", default_value_t = super::wake::ModelArg::Hummel)]
    pub aero_model: super::wake::ModelArg,
    /// Body mass of a bird, kg, for its power curve (savings of total power; default: the
    /// species' typical mass scaled to --wingspan-m).
    #[arg(long = "mass-kg", value_name = "KG", allow_negative_numbers = true)]
    pub mass_kg: Option<f64>,
    /// Airspeed, m/s, at which savings of total power are evaluated (default: each bird's own
    /// speed).
    #[arg(long = "speed-ms", value_name = "M/S", allow_negative_numbers = true)]
    pub speed_ms: Option<f64>,
}

impl SteadyFlags {
    /// The library options for `birds` birds (frames and seed are set by the caller's
    /// [`Config`]; validated there).
    pub fn options(&self, birds: usize) -> SteadyOptions {
        SteadyOptions {
            birds,
            fps: self.fps,
            speed: self.speed,
            wingspan_m: self.wingspan_m,
            keys: KeyOptions {
                epsilon: self.epsilon,
                c1: self.c1,
                c2: self.c2,
                key_every_s: self.key_every,
                max_jump: self.max_jump,
                ..KeyOptions::default()
            },
            jostle: JostleOptions {
                scale: self.jostle,
                ..JostleOptions::default()
            },
            reorganise: formation::keyshape::ReorganiseOptions {
                leader_changes: self.leader_changes,
                swaps: self.swaps,
                joiners: self.joiners,
                ..formation::keyshape::ReorganiseOptions::default()
            },
            looped: self.looped,
            aero: formation::aero::AeroOptions {
                core_radius: self.core_radius,
                wake: self.wake.into(),
                model: self.aero_model.into(),
                ..formation::aero::AeroOptions::default()
            },
            flight: formation::animation::FlightSettings {
                mass_kg: self.mass_kg,
                speed_ms: self.speed_ms,
            },
            ..SteadyOptions::default()
        }
    }
}

/// Flags of flocks of several formations, shared by `steady` and `animate` (the `skein` section
/// of the library's `Config`).
#[derive(Debug, Clone, Args)]
pub struct SkeinFlags {
    /// Number of formations (skeins) the flock flies as (default: formations of about the
    /// footage's size; one formation up to twice its birds). 1 = one formation of all birds.
    #[arg(long, value_name = "K")]
    pub formations: Option<usize>,
    /// Typical number of birds of a formation instead of the footage's (at least 2).
    #[arg(long = "formation-size", value_name = "M")]
    pub formation_size: Option<usize>,
    /// Smallest distance between birds of different formations, wingspans.
    #[arg(long, default_value_t = SkeinOptions::default().clearance, allow_negative_numbers = true)]
    pub clearance: f64,
    /// How the formations are arranged: natural (scattered at irregular distances, heights and
    /// headings, as skeins of a migrating flock), grid (lanes, one formation behind the other)
    /// or compound (one large V of formations, as large shorebird flocks fly).
    #[arg(long = "skein-layout", value_name = "LAYOUT", default_value = "natural",
          value_parser = clap::builder::TypedValueParser::map(
              clap::builder::PossibleValuesParser::new(["natural", "grid", "compound"]),
              |s| s.parse::<formation::skein::SkeinLayout>().unwrap_or_default()))]
    pub skein_layout: formation::skein::SkeinLayout,
}

impl SkeinFlags {
    /// The library options.
    pub fn options(&self) -> SkeinOptions {
        SkeinOptions {
            formations: self.formations,
            formation_size: self.formation_size,
            clearance: self.clearance,
            layout: self.skein_layout,
            ..SkeinOptions::default()
        }
    }
}

/// Runs `formation steady`.
pub fn run(args: SteadyArgs, g: Global) -> Result<()> {
    if args.frames.is_none() && args.seconds.is_none() {
        return Err(Error::parameter(
            "--frames",
            "give the length of the steady flight: --frames F or --seconds S",
        ));
    }
    let mut config = Config {
        seed: g.seed,
        seconds: args.seconds,
        steady: SteadyOptions {
            frames: args.frames.unwrap_or(SteadyOptions::default().frames),
            ..args.steady.options(args.birds)
        },
        wingbeat: args.wingbeat.options()?,
        initiation: false,
        course: formation::course::CourseOptions {
            cruise_altitude: args.cruise_altitude,
            ..args.path.options()
        },
        skein: args.skein.options(),
        ..Config::default()
    };
    super::savings::apply_species(&mut config.steady, &args.wingbeat.species);
    args.land.apply(&mut config);
    config.steady_options()?;
    config.wingbeat.validate()?;
    config.course.validate()?;
    if config.land {
        config.landing.validate()?;
        if config.steady.looped {
            return Err(Error::parameter(
                "land",
                "a loop cycles for ever and cannot end in a landing; give one of --land and --loop",
            ));
        }
    }
    let plan = formation::export::plan_outputs(&args.output)?;
    super::course::check_path_kept(&args.path, &args.output, &args.scene.options())?;
    if let Some(r) = &args.report {
        formation::export::plan_report(r, &plan)?;
    }
    let path = config.course.load(config.steady.wingspan_m)?;
    let params = FormationParams::read(&args.params)?;
    super::warn_params(g, &params)?;
    let progress = TermProgress::new(g.quiet);
    let long = formation::pipeline::landing_config(&config, path.as_ref());
    let (mut anim, outcome) = flock_steady_stage(&params, &long, &progress)?;
    formation::pipeline::land_stage(&mut anim, &config, path.as_ref())?;
    let course = formation::pipeline::course_stage(&mut anim, path.as_ref(), &config)?;
    super::course::warn(super::flags::Cmd::Steady, g, &course)?;
    formation::pipeline::finish(&mut anim, &config)?;
    // A real species is named in the animation (its family's rig draws it).
    if let Some(b) = formation::aero::species::lookup(&args.wingbeat.species) {
        anim.species = Some(b.name.to_string());
    }
    super::check_bird_model(
        super::flags::Cmd::Steady,
        g,
        &args.scene.options(),
        formation::wingbeat::WingbeatOptions::for_animation(&anim).species,
    )?;
    super::write_animation(&anim, &args.output, &args.scene.options(), g)?;
    if let Some(r) = &args.report {
        write_json_atomic(r, &outcome)?;
    }
    if !g.quiet {
        let text = match &outcome {
            SteadyOutcome::One(report) => {
                let k = &report.keys;
                format!(
                    "{}\nkey shapes: {} ({} draws, {} redraws, {} damped, {} held, {} kept the previous lateral positions, min λ {:.3}), max key residual {:.1e}, max jump {:.2} wingspans",
                    super::summary::animation_text("steady", &anim, Some(&params)),
                    k.keys, k.draws, k.redraws, k.damped, k.held, k.lateral_held, k.min_damping, k.max_residual, k.max_jump
                )
            }
            SteadyOutcome::Flock(f) => format!(
                "{}\n{}",
                super::summary::animation_text("steady", &anim, Some(&params)),
                flock_summary(f)
            ),
        };
        let mut files = formation::export::written_files(&args.output, &args.scene.options());
        files.extend(args.report.iter().cloned());
        super::summary::defer(text, &files);
    }
    Ok(())
}

/// One line about a flock of several formations: how many, their sizes, lanes, separation.
pub fn flock_summary(f: &formation::skein::SkeinReport) -> String {
    let lo = f.sizes.iter().min().copied().unwrap_or(0);
    let hi = f.sizes.iter().max().copied().unwrap_or(0);
    format!(
        "flock: {} birds in {} formations of {lo} to {hi} birds, {} lanes; birds of different formations at least {:.1} wingspans apart (clearance {})",
        f.sizes.iter().sum::<usize>(),
        f.sizes.len(),
        f.lanes,
        f.min_separation,
        f.clearance
    )
}

/// What `plot power` shows.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MetricArg {
    /// Relative power reduction ξ_i = e_i / E.
    Xi,
    /// Power reduction e_i.
    E,
}

impl From<PowerMetric> for MetricArg {
    fn from(m: PowerMetric) -> MetricArg {
        match m {
            PowerMetric::Xi => MetricArg::Xi,
            PowerMetric::E => MetricArg::E,
        }
    }
}

impl From<MetricArg> for PowerMetric {
    fn from(m: MetricArg) -> PowerMetric {
        match m {
            MetricArg::Xi => PowerMetric::Xi,
            MetricArg::E => PowerMetric::E,
        }
    }
}

/// Arguments of `formation plot power`.
#[derive(Debug, Args)]
pub struct PlotPowerArgs {
    /// A shape file (docs/formats.md) or an animation file.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Key shape of the animation to plot (index into key_shapes; default 0).
    #[arg(long, conflicts_with = "frame")]
    pub key: Option<usize>,
    /// Frame of the animation to plot instead of a key shape.
    #[arg(long)]
    pub frame: Option<usize>,
    /// Quantity to plot.
    #[arg(long, value_enum, default_value_t = MetricArg::from(PowerMetric::default()))]
    pub metric: MetricArg,
    #[command(flatten)]
    pub formation: FormationArg,
}

/// `--formation K` of the charts of one formation.
#[derive(Debug, Clone, Args)]
pub struct FormationArg {
    /// Formation of a flock of several formations to chart (index into the file's formations;
    /// default 0).
    #[arg(long, value_name = "K")]
    pub formation: Option<usize>,
}

impl FormationArg {
    /// The formation asked for of `anim` (read from `origin`) as an animation of its own, and
    /// the words a chart's title adds (`None` for a flock of one formation).
    pub fn pick(&self, anim: Animation, origin: &Path) -> Result<(Animation, Option<String>)> {
        formation::plot::one_formation(anim, self.formation, origin)
    }
}

/// Runs `formation plot power`.
pub fn run_plot_power(args: PlotPowerArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let metric = PowerMetric::from(args.metric);
    let of = match (args.frame, args.key) {
        (Some(k), _) => Some(PowerOf::Frame(k)),
        (None, k) => k.map(PowerOf::Key),
    };
    let chart = PowerChart::from_file(&args.input, args.formation.formation, of, metric)?;
    super::chart::save(&chart, &args.output)
}

/// Arguments of `formation plot xi`.
#[derive(Debug, Args)]
pub struct PlotXiArgs {
    /// An animation file.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    #[command(flatten)]
    pub formation: FormationArg,
}

/// Runs `formation plot xi`.
pub fn run_plot_xi(args: PlotXiArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let (anim, which) = args
        .formation
        .pick(Animation::read(&args.input)?, &args.input)?;
    let mut chart = XiChart::from_animation(&anim, &args.input)?;
    chart.title.push_str(which.as_deref().unwrap_or(""));
    super::chart::save(&chart, &args.output)
}

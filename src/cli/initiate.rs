//! `formation initiate` and `formation plot paths`: flags → [`InitiateOptions`], run the
//! §6 simulation into the first key shape of a steady-flight file, write the combined animation.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use formation::animation::wing::Species;
use formation::animation::Animation;
use formation::initiate::{
    self, Cruise, GroundStart, InitiateOptions, PerceptionMode, Start, StartChoice, StartRegion,
    TakeoffPlan, HPR_GAMMA_DEFAULT,
};
use formation::io::OutputKind;
use formation::{Error, Result};

use super::flags::Cmd;
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
    pub path: super::course::PathFlags,
    #[command(flatten)]
    pub land: super::course::LandFlags,
    #[command(flatten)]
    pub wingbeat: super::wingbeat::WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
    /// Print the run's statistics as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The library's defaults, for the flags' `default_value_t`.
fn d() -> InitiateOptions {
    InitiateOptions::default()
}

/// The help of `--start-width`, with the library's rules for its default.
fn start_width_help() -> String {
    format!(
        "Width of the take-off area (ground) or start region (air) across the cruise heading, wingspans [default: ground from the flock size and --takeoff, {} times the depth; air {}√N, at least {}]",
        initiate::GROUND_ASPECT,
        initiate::AIR_WIDTH_PER_ROOT_BIRD,
        initiate::AIR_MIN_WIDTH
    )
}

/// The help of `--start-depth`, with the library's rules for its default.
fn start_depth_help() -> String {
    format!(
        "Depth of the take-off area or start region along the cruise heading, wingspans [default: ground from the flock size and --takeoff, at most {}; air half the width, {} to {}]",
        initiate::GROUND_MAX_DEPTH,
        initiate::AIR_DEPTH_RANGE.0,
        initiate::AIR_DEPTH_RANGE.1
    )
}

/// The help of `--climb-rate`, with the species' power-limited climbs at their typical wingspans.
fn climb_rate_help() -> String {
    let w = |sp: Species| {
        let b = formation::aero::flight::Morphology::of(sp).span_m;
        Cruise::power_climb(sp, b, None)
    };
    format!(
        "Largest climb rate after lift-off, wingspans per second, scaled by the take-off's drive [default: the species' power-limited climb: goose {:.2}, crane {:.2}, pelican {:.2} at their typical wingspans]",
        w(Species::Goose),
        w(Species::Crane),
        w(Species::Pelican)
    )
}

/// The help of `--takeoff`, with the library's natural and shortest take-offs for two flock sizes
/// of geese.
fn takeoff_help() -> String {
    let o = InitiateOptions::default();
    let nat = |n| TakeoffPlan::natural_form_seconds(n, &o);
    let short = |n| TakeoffPlan::shortest_form_seconds(n, &o);
    let long = |n| TakeoffPlan::longest_form_seconds(n, &o);
    format!(
        "Time until the V has formed, seconds from the start of the take-off (the birds' sitting included): the birds start closer or farther apart and drive harder or softer to form in about this time, and climb to the cruise altitude at their own pace meanwhile (harder for a fast formation); outside what the flock can fly a warning gives the range it can [default: the natural one, for geese {:.1} s for 14 birds and {:.1} s for 100; from about {:.1} to {:.1} s for 14 birds; the summary says when the V formed, `--json` reports it as formed_seconds]",
        nat(14),
        nat(100),
        short(14),
        long(14)
    )
}

/// The help of `--heading-spread`, with the library's defaults for each start.
fn heading_spread_help() -> String {
    format!(
        "Start headings are uniform within this many degrees of the cruise heading [default: ground {}, air {}]",
        deg(GroundStart::default().heading_spread),
        deg(StartRegion::default().heading_spread)
    )
}

/// An angle of the library's defaults (radians) as the degrees a flag shows.
fn deg(rad: f64) -> f64 {
    initiate::display_degrees(rad)
}

/// The radians of a flag given in degrees: the library's own value when the flag shows its
/// default, so that the default options are exactly the library's.
fn rad(degrees: f64, default: f64) -> f64 {
    if degrees == deg(default) {
        default
    } else {
        degrees.to_radians()
    }
}

/// Initiation flags shared by `initiate` and `animate`; every default is the library's
/// ([`InitiateOptions::default`]), every check the library's ([`InitiateOptions::validate`]).
#[derive(Debug, Clone, Args)]
pub struct InitiateFlags {
    /// Frame limit of the take-off at the animation's frame rate; no convergence within it (or
    /// within --max-seconds) fails with exit 1.
    #[arg(long, default_value_t = d().max_steps)]
    pub max_steps: usize,
    /// Time limit of the take-off, seconds of flight; no convergence within it (or within
    /// --max-steps frames) fails with exit 1.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().max_time)]
    pub max_seconds: f64,
    /// Take-off duration, seconds: the birds start closer or farther apart and drive harder or
    /// softer to form in about this time.
    #[arg(long, allow_negative_numbers = true, help = takeoff_help())]
    pub takeoff: Option<f64>,
    /// Seconds the birds sit on the ground, wings folded, before the first one starts its run
    /// (ground start).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().ground_seconds)]
    pub ground_seconds: f64,
    /// Cruise altitude of the steady flight above the ground (`z`), wingspans.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().cruise_altitude)]
    pub cruise_altitude: f64,
    /// Largest climb rate after lift-off, wingspans per second (scaled by the take-off's drive).
    #[arg(long, allow_negative_numbers = true, help = climb_rate_help())]
    pub climb_rate: Option<f64>,
    /// Occlusion model.
    #[arg(long, value_enum, default_value_t = PerceptionArg::of(&d().perception.mode))]
    pub perception: PerceptionArg,
    /// HPR radius exponent γ: R = (distance of the farthest bird) · 10^γ.
    #[arg(long, allow_negative_numbers = true, default_value_t = HPR_GAMMA_DEFAULT)]
    pub hpr_gamma: f64,
    /// Visual field per eye, degrees from straight ahead (paper: 90); widened when the key shape
    /// needs it for a bird to see its reference from its slot (docs/initiation.md).
    #[arg(long, allow_negative_numbers = true, default_value_t = deg(d().perception.fov_per_eye))]
    pub fov: f64,
    /// Cone per eye in which the closest visible bird is the preferred reference, degrees
    /// (paper: 0.35π).
    #[arg(long, allow_negative_numbers = true, default_value_t = deg(d().perception.reference_cone))]
    pub reference_cone: f64,
    /// α of eq. (6) (heading gain).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().alpha)]
    pub alpha: f64,
    /// |K| of eq. (5) (speed gain).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().k)]
    pub k: f64,
    /// Maximum turn rate, degrees per second.
    #[arg(long, allow_negative_numbers = true, default_value_t = deg(d().max_turn_rate))]
    pub max_turn_rate: f64,
    /// Maximum acceleration, wingspans per second squared.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().max_accel)]
    pub max_accel: f64,
    /// Minimum flight speed, fraction of the cruise speed.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().min_speed)]
    pub min_speed: f64,
    /// Maximum flight speed, fraction of the cruise speed.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().max_speed)]
    pub max_speed: f64,
    /// Separation drive distance, wingspans (paper: 10).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().separation_distance)]
    pub separation: f64,
    /// Collision avoidance: predicted closest approach that triggers evasion, wingspans (birds
    /// settling into neighbouring slots keep half their slots' distance instead).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().avoid_distance)]
    pub avoid_distance: f64,
    /// Convergence: every bird within this distance of its slot, wingspans.
    #[arg(long, allow_negative_numbers = true, default_value_t = d().tolerance)]
    pub tolerance: f64,
    /// Convergence: for this long, seconds (also the hand-over blend window).
    #[arg(long, allow_negative_numbers = true, default_value_t = d().hold)]
    pub hold: f64,
    /// Start: `ground` (at rest in a take-off area, leaving one after another, climbing to the
    /// cruise altitude), `air` (the paper's: scattered in the air at the cruise altitude), or a
    /// start file: JSON {"x": [...], "y": [...], "heading": [...], "speed": [...]} (world frame,
    /// wingspans, radians clockwise from north, wingspans per second; heading and speed optional).
    #[arg(long, default_value = d().start.word(), value_parser = super::start::parse_start)]
    pub start: String,
    /// Width of the take-off area (ground) or start region (air) across the cruise heading,
    /// wingspans.
    #[arg(long, allow_negative_numbers = true, help = start_width_help())]
    pub start_width: Option<f64>,
    /// Depth of the take-off area or start region along the cruise heading, wingspans.
    #[arg(long, allow_negative_numbers = true, help = start_depth_help())]
    pub start_depth: Option<f64>,
    /// Start headings are uniform within this many degrees of the cruise heading.
    #[arg(long, allow_negative_numbers = true, help = heading_spread_help())]
    pub heading_spread: Option<f64>,
}

impl PerceptionArg {
    /// The flag value of a perception mode.
    fn of(mode: &PerceptionMode) -> PerceptionArg {
        match mode {
            PerceptionMode::Hpr { .. } => PerceptionArg::Hpr,
            PerceptionMode::Exact => PerceptionArg::Exact,
        }
    }
}

impl InitiateFlags {
    /// The library options these flags describe, checked by the library
    /// ([`InitiateOptions::validate`]; its errors name option paths, which the command line
    /// turns into these flags). A take-off duration the rules cannot reach for birds of `cruise`
    /// (their climb) is warned about.
    pub fn options(&self, seed: u64, birds: usize, cruise: &Cruise) -> Result<InitiateOptions> {
        let def = InitiateOptions::default();
        let mut o = InitiateOptions {
            seed,
            max_steps: self.max_steps,
            max_time: self.max_seconds,
            takeoff: self.takeoff,
            ground_seconds: self.ground_seconds,
            cruise_altitude: self.cruise_altitude,
            climb_rate: self.climb_rate,
            alpha: self.alpha,
            k: self.k,
            max_turn_rate: rad(self.max_turn_rate, def.max_turn_rate),
            max_accel: self.max_accel,
            min_speed: self.min_speed,
            max_speed: self.max_speed,
            separation_distance: self.separation,
            avoid_distance: self.avoid_distance,
            tolerance: self.tolerance,
            hold: self.hold,
            ..def.clone()
        };
        o.perception.fov_per_eye = rad(self.fov, def.perception.fov_per_eye);
        o.perception.reference_cone = rad(self.reference_cone, def.perception.reference_cone);
        o.perception.mode = match self.perception {
            PerceptionArg::Hpr => PerceptionMode::Hpr {
                gamma: self.hpr_gamma,
            },
            PerceptionArg::Exact => PerceptionMode::Exact,
        };
        o.start = Start::from_choice(
            &StartChoice {
                kind: self.start.clone(),
                width: self.start_width,
                depth: self.start_depth,
                heading_spread_deg: self.heading_spread,
            },
            birds,
        )?;
        o.validate()?;
        initiate::check_size(birds, 0, o.max_steps)?;
        if let Some(w) = TakeoffPlan::warning(birds, &o, cruise) {
            super::stdout::warning(&super::flags::rewrite(Cmd::Initiate, &w));
        }
        Ok(o)
    }
}

/// Runs `formation initiate`.
pub fn run(args: InitiateArgs, g: Global) -> Result<()> {
    let wing = args.wingbeat.options()?;
    formation::export::plan_outputs(&args.output)?;
    super::course::check_path_kept(&args.path, &args.output, &args.scene.options())?;
    let steady = Animation::read(&args.steady)?;
    if steady.formations.is_none() {
        initiate::check_steady(&steady, &args.steady)?;
    }
    // The climb after lift-off is the power-limited climb of the species the output is made
    // of (its wingbeats), unless --climb-rate gives one.
    let mass = steady.flight.and_then(|f| f.mass_kg);
    let cruise = Cruise::of_birds(0.0, 1.0, wing.species, steady.wingspan_m, mass);
    let mut opts = args.initiate.options(g.seed, steady.birds, &cruise)?;
    opts.climb_rate = Some(opts.climb_rate_for(&cruise));
    // The take-off climbs to the path's first point, then the course step maps the
    // whole flight onto the path.
    let mut course = super::course::course_config(&args.path, &steady, &args.steady, &mut opts)?;
    args.land.apply(&mut course.0);
    if course.0.land {
        course.0.landing.validate()?;
        if steady.looped {
            return Err(Error::parameter(
                "land",
                format!(
                    "{}: this steady flight is a loop, which cycles for ever and cannot end in a landing; make it without --loop",
                    args.steady.display()
                ),
            ));
        }
    }
    let mut rng = formation::rng::stream(g.seed, formation::rng::Stream::Initiate);
    let progress = TermProgress::new(g.quiet);
    let (mut anim, stats) = if steady.formations.is_some() {
        // A flock of several formations takes off formation by formation.
        let config = formation::pipeline::Config {
            seed: g.seed,
            initiate: opts,
            ..Default::default()
        };
        formation::pipeline::initiate_stage(steady, &config, &progress)?
    } else {
        initiate::initiate(&steady, &opts, &mut rng, &progress)?
    };
    formation::pipeline::land_stage(&mut anim, &course.0, course.1.as_ref())?;
    // Savings (e, ξ) in the take-off frames too.
    let aero = anim
        .savings_model
        .as_ref()
        .map(formation::aero::AeroOptions::from_record)
        .unwrap_or_default();
    formation::aero::fill_frame_savings(&mut anim, &aero);
    let report = formation::pipeline::course_stage(&mut anim, course.1.as_ref(), &course.0)?;
    super::course::warn(super::flags::Cmd::Initiate, g, &report)?;
    formation::wingbeat::rest::stand_on_ground(&mut anim, wing.species);
    formation::initiate::landing::flare_pitch(&mut anim, formation::initiate::landing::FLARE_PITCH);
    formation::wingbeat::assign_phases(&mut anim, &wing)?;
    anim.quantize();
    super::check_bird_model(
        super::flags::Cmd::Initiate,
        g,
        &args.scene.options(),
        formation::wingbeat::WingbeatOptions::for_animation(&anim).species,
    )?;
    super::write_animation(&anim, &args.output, &args.scene.options(), g)?;
    if args.json {
        let text = formation::finite::to_json_pretty("statistics", &stats)?;
        super::stdout::println(&text)?;
    }
    let written = formation::export::written_files(&args.output, &args.scene.options());
    super::summary::initiate(g, &anim, &stats, &written);
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
    super::chart::save(&chart, &args.output)
}

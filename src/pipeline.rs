//! The whole chain in one call: annotations (a file in any docs/formats.md §4.1 format, or points in memory)
//! or formation parameters → §4 extraction → §5 steady flight → §6 initiation → wingbeats, giving
//! an [`Animation`] and a [`Report`] of what each stage did. `formation animate`, the benches, the
//! tests and the fuzz targets all run this; so can a game engine, a DCC plug-in or a notebook.
//!
//! ```no_run
//! use formation::pipeline::{Config, Pipeline};
//! let mut config = Config::default();
//! config.steady.birds = 14;
//! config.seconds = Some(10.0);
//! let (animation, report) = Pipeline::from_path("examples_data/barnacle_geese_v.json")
//!     .run(&config)?;
//! # Ok::<(), formation::Error>(())
//! ```
//!
//! Every option lives in one [`Config`] section, one per stage, each `Default` and serde-ready, so
//! a whole run can be written to and read from JSON. Errors name the option by its path in the
//! config (`steady.fps`, `initiate.max_turn_rate`); the command line maps those paths to its own
//! flags. Each stage draws from its own random stream ([`Stream`]) derived from [`Config::seed`],
//! so `animate` gives exactly what `extract`, `steady` and `initiate` give when run one after the
//! other with the same seed.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::animation::Animation;
use crate::annotations::{Annotations, ReadOptions};
use crate::course::{CourseOptions, CourseReport, PathPoints};
use crate::error::{Error, Result};
use crate::export::RenderOptions;
use crate::extract::{self, ExtractOptions, FormationParams, FrameReport};
use crate::initiate::landing::{self, LandingOptions, LandingStats};
use crate::initiate::{self, InitiateOptions, InitiateStats};
use crate::keyshape::{steady_flight_report, SteadyOptions, SteadyReport};
use crate::progress::{Progress, Silent};
use crate::rng::{stream, Stream};
use crate::skein::{self, FlockOptions, SkeinOptions, SkeinReport};
use crate::wingbeat::{self, WingbeatOptions};

/// Default length of the steady flight, seconds ([`Config::seconds`]).
pub const DEFAULT_SECONDS: f64 = 20.0;

/// Every option of a run, one section per stage. The sections are the stages' own options
/// structs; [`Pipeline::run`] sets the derived fields (`steady.frames` from [`Config::seconds`],
/// `steady.seed` and `initiate.seed` from [`Config::seed`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// Seed of every random stream; equal seeds and inputs give byte-identical animations.
    pub seed: u64,
    /// Length of the steady flight, seconds: `steady.frames` = round(seconds · `steady.fps`).
    /// `None`: `steady.frames` as given.
    pub seconds: Option<f64>,
    /// Length of the whole shot, seconds, take-off included (`None`: the take-off's own length
    /// plus [`Config::seconds`]). The steady flight takes what the take-off leaves: the
    /// animation has exactly round(shot_seconds · `steady.fps`) frames. Replaces `seconds`.
    pub shot_seconds: Option<f64>,
    /// Fly the §6 take-off before the steady flight; `false`: the steady flight alone.
    pub initiation: bool,
    /// End the flight with a landing (docs/landing.md); with an open path, where the path ends.
    pub land: bool,
    /// How the flock lands (used when [`Config::land`]).
    pub landing: LandingOptions,
    /// How annotation files are read (ignored for params and for annotations in memory).
    pub read: ReadOptions,
    /// §4 parameter extraction (ignored when the input is formation parameters).
    pub extract: ExtractOptions,
    /// §5 steady flight: birds, frame rate, key shapes, speed.
    pub steady: SteadyOptions,
    /// §6 initiation.
    pub initiate: InitiateOptions,
    /// Wingbeats.
    pub wingbeat: WingbeatOptions,
    /// The course: the path the flock follows, turn and bank limits.
    pub course: CourseOptions,
    /// Large flocks as several formations (skeins): how many, how big, how far apart.
    pub skein: SkeinOptions,
    /// Pictures and exports (used by [`crate::export::write_outputs`], not by [`Pipeline::run`]).
    pub render: RenderOptions,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            seed: 0,
            seconds: Some(DEFAULT_SECONDS),
            shot_seconds: None,
            initiation: true,
            land: false,
            landing: LandingOptions::default(),
            read: ReadOptions::default(),
            extract: ExtractOptions::default(),
            steady: SteadyOptions::default(),
            initiate: InitiateOptions::default(),
            wingbeat: WingbeatOptions::default(),
            course: CourseOptions::default(),
            skein: SkeinOptions::default(),
            render: RenderOptions::default(),
        }
    }
}

impl Config {
    /// The number of steady-flight frames: round(`seconds` · `steady.fps`), or `steady.frames`
    /// without `seconds`. An unusable `steady.fps` is left to [`SteadyOptions::validate`] to
    /// report (the count is then 1).
    pub fn frames(&self) -> Result<usize> {
        // A whole shot of S seconds has round(S · fps) frames; its steady flight is made that
        // long and cut where the shot ends (after the take-off's frames).
        let (seconds, name) = match (self.shot_seconds, self.seconds) {
            (Some(s), _) => (s, "shot_seconds"),
            (None, Some(s)) => (s, "seconds"),
            (None, None) => return Ok(self.steady.frames),
        };
        if !(seconds.is_finite() && seconds > 0.0) {
            return Err(Error::parameter(
                name,
                format!("must be a positive number of seconds, got {seconds}"),
            ));
        }
        let fps = self.steady.fps;
        if !(fps.is_finite() && fps > 0.0) {
            return Ok(1);
        }
        let frames = (seconds * fps).round();
        if !(1.0..=crate::limits::MAX_FRAMES as f64).contains(&frames) {
            return Err(Error::parameter(
                name,
                format!(
                    "{seconds} s at {fps} fps is {frames} frames; give between 1 and {} frames",
                    crate::limits::MAX_FRAMES
                ),
            ));
        }
        Ok(frames as usize)
    }

    /// The steady-flight options with the derived fields set. A flock that may fly as several
    /// formations is checked with its largest possible formation (the flock as a whole only
    /// against [`crate::limits::MAX_BIRDS`] and the bird-frame limit).
    pub fn steady_options(&self) -> Result<SteadyOptions> {
        let mut steady = SteadyOptions {
            frames: self.frames()?,
            seed: self.seed,
            ..self.steady.clone()
        };
        // A start file whose birds already fly a formation: its arms are the key shapes'.
        if let (true, initiate::Start::Given(s)) = (self.initiation, &self.initiate.start) {
            steady.given = s.joining(0.0).map(|j| j.given_arms());
        }
        let n = steady.birds;
        if self.skein.formations == Some(1) || n <= crate::limits::MAX_FORMATION_BIRDS {
            steady.validate()?;
        } else {
            if n > crate::limits::MAX_BIRDS {
                return Err(Error::parameter(
                    "steady.birds",
                    format!("{n}: at most {} birds", crate::limits::MAX_BIRDS),
                ));
            }
            crate::limits::check_animation_size("steady.frames", n, steady.frames)?;
            SteadyOptions {
                birds: crate::limits::MAX_FORMATION_BIRDS,
                frames: 1,
                ..steady.clone()
            }
            .validate()?;
        }
        self.skein.validate(n)?;
        Ok(steady)
    }

    /// Birds of the largest formation that takes off, which sets the take-off's length and
    /// memory bound: the flock; with several formations (`skein.formations`, or
    /// `skein.formation_size`), the largest one's size; 2 without a take-off (its options are
    /// still checked, but no take-off frames are needed).
    pub fn takeoff_birds(&self) -> usize {
        let birds = self.steady.birds;
        if !self.initiation {
            return 2;
        }
        let k = match (self.skein.formations, self.skein.formation_size) {
            (Some(k), _) => k,
            (None, Some(m)) => skein::formation_count(birds, m, None, Some(m)),
            (None, None) => 1,
        };
        if k > 1 && 2 * k <= birds {
            skein::sizes::size_bounds(birds, k).1
        } else {
            birds
        }
    }

    /// The initiation options with the seed set.
    pub fn initiate_options(&self) -> Result<InitiateOptions> {
        let o = InitiateOptions {
            seed: self.seed,
            ..self.initiate.clone()
        };
        o.validate()?;
        // The memory bound of the take-off's frames matters only when it is flown (a large
        // flock's steady flight alone may hold more birds than a take-off of max_steps could).
        if self.initiation {
            initiate::check_size(self.steady.birds, 0, o.max_steps)?;
        }
        Ok(o)
    }

    /// Checks every section before any work, in the order the stages run; the error names the
    /// option's path (`steady.fps`).
    pub fn validate(&self) -> Result<()> {
        self.steady_options()?;
        // Checked with or without the take-off, so that a config is valid or not as a whole.
        self.initiate_options()?;
        self.wingbeat.validate()?;
        self.course.validate()?;
        if self.land {
            self.landing.validate()?;
            if self.steady.looped {
                return Err(Error::parameter(
                    "land",
                    "a loop cycles for ever and cannot end in a landing; fly without steady.loop, or without the landing",
                ));
            }
            if self.shot_seconds.is_some() && self.course.path.is_some() {
                return Err(Error::parameter(
                    "shot_seconds",
                    "a landing on a path ends where the path ends, so the path sets the shot's length; give no shot length, or no path",
                ));
            }
        }
        if self.steady.looped && self.initiation {
            return Err(Error::parameter(
                "steady.loop",
                "a loop is a steady flight alone and cannot begin with a take-off; fly it without the take-off (initiation false)",
            ));
        }
        if let Some(shot) = self.shot_seconds {
            if self.steady.looped {
                return Err(Error::parameter(
                    "shot_seconds",
                    "a loop lasts its own cycle; give the loop's length with seconds instead",
                ));
            }
            if let (true, Some(takeoff)) = (self.initiation, self.initiate.takeoff) {
                if takeoff >= shot {
                    return Err(Error::parameter(
                        "shot_seconds",
                        format!("{shot} s is not longer than the {takeoff} s take-off asked for; give a longer shot, a shorter take-off, or no take-off"),
                    ));
                }
            }
        }
        if self.steady.reorganise.joiners > 0 && self.initiation {
            return Err(Error::parameter(
                "steady.reorganise.joiners",
                "late birds join a formation already flying: they cannot take off with the flock; fly it without the take-off (initiation false), or give a start file with birds to the side",
            ));
        }
        self.render.validate()?;
        self.extract.validate()
    }
}

/// What each stage did.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Model-selection scores of every annotated frame (empty when the input was parameters).
    pub extract: Vec<FrameReport>,
    /// The formation parameters the steady flight was made from (read or extracted), with
    /// their summary and warnings.
    pub params: FormationParams,
    /// Algorithm 1's correspondence, ranges and key-shape statistics.
    pub steady: SteadyReport,
    /// The initiation's statistics (`None` without initiation); for a flock of several
    /// formations the whole flock's (see [`skein::flock_stats`]).
    pub initiate: Option<InitiateStats>,
    /// What the course step did (turns widened, laps of a loop, warnings to show).
    pub course: CourseReport,
    /// Each formation's reports and the arrangement, when the flock flew as several formations
    /// (then `steady` is formation 0's).
    pub skein: Option<SkeinReport>,
    /// What the landing did (`None` without one).
    pub landing: Option<LandingStats>,
}

/// What a pipeline starts from.
#[derive(Debug, Clone)]
enum Input {
    /// A file or directory: params written by `extract`, or annotations in any format.
    Path(PathBuf),
    /// Annotations already read or built in memory.
    Annotations(Annotations),
    /// Formation parameters already extracted.
    Params(FormationParams),
}

/// The input of a run; [`Pipeline::run`] takes it through every stage.
#[derive(Debug, Clone)]
pub struct Pipeline {
    input: Input,
}

impl Pipeline {
    /// Starts from a file: a params file (told apart by content) or annotations in any docs/formats.md §4.1
    /// format, read with [`Config::read`] when the pipeline runs.
    pub fn from_path(path: impl Into<PathBuf>) -> Pipeline {
        Pipeline {
            input: Input::Path(path.into()),
        }
    }

    /// Starts from annotations (e.g. [`Annotations::from_points`]).
    pub fn from_annotations(annotations: Annotations) -> Pipeline {
        Pipeline {
            input: Input::Annotations(annotations),
        }
    }

    /// Starts from formation parameters (skips extraction).
    pub fn from_params(params: FormationParams) -> Pipeline {
        Pipeline {
            input: Input::Params(params),
        }
    }

    /// The file or name that messages about the input mention.
    pub fn origin(&self) -> &Path {
        match &self.input {
            Input::Path(p) => p,
            Input::Annotations(a) => &a.path,
            Input::Params(_) => Path::new("formation parameters"),
        }
    }

    /// Runs every stage silently.
    pub fn run(&self, config: &Config) -> Result<(Animation, Report)> {
        self.run_with(config, &Silent)
    }

    /// Runs every stage, reporting progress to `progress`. Every option is checked before any
    /// work.
    pub fn run_with(
        &self,
        config: &Config,
        progress: &dyn Progress,
    ) -> Result<(Animation, Report)> {
        config.validate()?;
        let path = config.course.load(config.steady.wingspan_m)?;
        let (params, extract_report) = self.params(config, progress)?;
        let sizes = config
            .skein
            .sizes(config.steady.birds, params.birds, config.seed)?;
        if sizes.len() > 1 {
            return flock_run(
                &params,
                &sizes,
                extract_report,
                config,
                path.as_ref(),
                progress,
            );
        }
        let long = landing_config(config, path.as_ref());
        let (steady, steady_report) = steady_stage(&params, &long, progress)?;
        let (mut anim, initiate_report) = if config.initiation {
            initiate::check_steady(&steady, self.origin())?;
            let config = takeoff_config(config, path.as_ref())?;
            let (anim, stats) = initiate_stage(steady, &config, progress)?;
            (anim, Some(stats))
        } else {
            (steady, None)
        };
        let landing = land_stage(&mut anim, config, path.as_ref())?;
        // Savings (e, ξ) in the take-off frames too.
        crate::aero::fill_frame_savings(&mut anim, &config.steady_options()?.aero);
        let course = course_stage(&mut anim, path.as_ref(), config)?;
        fit_shot(&mut anim, config)?;
        finish(&mut anim, config)?;
        Ok((
            anim,
            Report {
                extract: extract_report,
                params,
                steady: steady_report,
                initiate: initiate_report,
                course,
                skein: None,
                landing,
            },
        ))
    }

    /// The formation parameters of the input: read, or extracted with the `extract` stream.
    pub fn params(
        &self,
        config: &Config,
        progress: &dyn Progress,
    ) -> Result<(FormationParams, Vec<FrameReport>)> {
        match &self.input {
            Input::Params(p) => {
                p.validate(self.origin())?;
                Ok((p.clone(), Vec::new()))
            }
            Input::Annotations(a) => extract_stage(a, config, progress),
            Input::Path(path) => {
                if let Some(p) = FormationParams::read_if_params(path)? {
                    return Ok((p, Vec::new()));
                }
                let ann = crate::annotations::read(path, &config.read)?;
                extract_stage(&ann, config, progress)
            }
        }
    }
}

/// §4 extraction of `ann` with the config's `extract` section and the seed's `extract` stream.
pub fn extract_stage(
    ann: &Annotations,
    config: &Config,
    progress: &dyn Progress,
) -> Result<(FormationParams, Vec<FrameReport>)> {
    extract::extract_with_report(
        ann,
        &config.extract,
        &mut stream(config.seed, Stream::Extract),
        progress,
    )
}

/// §5 steady flight from `params` with the config's `steady` section (frames from `seconds`) and
/// the seed's `steady` stream.
pub fn steady_stage(
    params: &FormationParams,
    config: &Config,
    progress: &dyn Progress,
) -> Result<(Animation, SteadyReport)> {
    steady_flight_report(
        params,
        &config.steady_options()?,
        &mut stream(config.seed, Stream::Steady),
        progress,
    )
}

/// The config of a take-off onto `path`: the take-off climbs to the height of the path's first
/// point (`initiate.cruise_altitude`), so that the course step joins it to the path.
pub fn takeoff_config(config: &Config, path: Option<&PathPoints>) -> Result<Config> {
    let mut c = config.clone();
    if let Some(p) = path {
        let origin = config.course.path.clone().unwrap_or_default();
        c.initiate.cruise_altitude = crate::course::takeoff_altitude(p, &origin)?;
    }
    Ok(c)
}

/// The config and the loaded path of a take-off flown on its own onto `course`'s path, ahead of
/// the steady flight `steady` (read from `origin`), as `formation initiate` does: the course step
/// needs the steady flight's cruise speed and wingspan, and the take-off climbs to the path's
/// first point (set in `initiate.cruise_altitude`, and in the config). A steady flight already
/// on a path is refused.
pub fn takeoff_course(
    course: CourseOptions,
    steady: &Animation,
    origin: &Path,
    initiate: &mut InitiateOptions,
) -> Result<(Config, Option<PathPoints>)> {
    let mut config = Config {
        course,
        ..Config::default()
    };
    config.steady.wingspan_m = steady.wingspan_m;
    let leader = steady.leaders().first().copied().unwrap_or(0);
    if let Some(f) = steady.frames.first() {
        config.steady.speed = f.speed.get(leader).copied().unwrap_or(config.steady.speed);
    }
    if steady.path.is_some() && config.course.path.is_some() {
        return Err(Error::format(
            origin,
            "path: this steady flight already follows a path; give the take-off the steady flight made without one, and the path here",
        ));
    }
    let path = config.course.load(steady.wingspan_m)?;
    if let Some(p) = &path {
        let file = config.course.path.clone().unwrap_or_default();
        initiate.cruise_altitude = crate::course::takeoff_altitude(p, &file)?;
    }
    config.initiate.cruise_altitude = initiate.cruise_altitude;
    Ok((config, path))
}

/// The course step: maps `anim`, made in the course frame by the stages before, onto
/// `path` (loaded with [`CourseOptions::load`]) or, without one, sets the cruise altitude of a
/// flight without a take-off; fills banks and pitches. A take-off is recognised by the
/// animation's `initiation` stage.
pub fn course_stage(
    anim: &mut Animation,
    path: Option<&PathPoints>,
    config: &Config,
) -> Result<CourseReport> {
    let grounded = anim.stage("initiation").is_some() || anim.stage("landing").is_some();
    let takeoff_altitude = grounded.then(|| match path {
        Some(p) => p.points[0][2],
        None => config.initiate.cruise_altitude,
    });
    let flight = crate::course::Flight {
        speed: config.steady.speed,
        takeoff_altitude,
        looped: anim.looped,
    };
    crate::course::apply(anim, path, &config.course, flight)
}

/// Cuts `anim` to the shot's length when [`Config::shot_seconds`] is set: exactly
/// round(shot_seconds · fps) frames, the steady flight taking what the take-off leaves; an error
/// names `shot_seconds` when the take-off alone is as long as the shot. A landing has already
/// been fitted into the shot ([`land_stage`]).
pub fn fit_shot(anim: &mut Animation, config: &Config) -> Result<()> {
    let Some(shot) = config.shot_seconds else {
        return Ok(());
    };
    if anim.stage("landing").is_some() {
        return Ok(());
    }
    let frames = (shot * anim.fps).round() as usize;
    let takeoff = anim
        .stages
        .iter()
        .filter(|s| s.name != crate::animation::StageName::Steady)
        .map(|s| s.end)
        .max()
        .unwrap_or(0);
    if takeoff >= frames {
        return Err(Error::parameter(
            "shot_seconds",
            format!(
                "{shot} s is shorter than the take-off alone ({:.2} s, {takeoff} frames at {} fps); give a longer shot, a shorter take-off, or no take-off",
                takeoff as f64 / anim.fps,
                anim.fps
            ),
        ));
    }
    anim.truncate(frames);
    Ok(())
}

/// The last steps of every run, after the course and the shot's length: birds on the ground
/// stand or sit, birds in their flare pitch up, the wingbeats, and the values rounded to the
/// animation file's precision ([`Animation::quantize`]).
pub fn finish(anim: &mut Animation, config: &Config) -> Result<()> {
    // What the flock's making freed goes back before the wingbeats' tables are made.
    crate::memory::release_free();
    wingbeat::rest::stand_on_ground(anim, config.wingbeat.species);
    landing::flare_pitch(anim, landing::FLARE_PITCH);
    wingbeat::assign_phases(anim, &config.wingbeat)?;
    anim.quantize();
    Ok(())
}

/// The config whose steady flight is long enough for a landing at the end of an open path: its
/// `seconds` at least the path's length at cruise speed plus a margin (the landing then cuts the
/// flight where it must start, [`land_stage`]). Any other config as it is.
pub fn landing_config(config: &Config, path: Option<&PathPoints>) -> Config {
    let mut c = config.clone();
    if let (true, Some(p), None) = (config.land, path, config.shot_seconds) {
        if !p.closed && config.steady.speed > 0.0 {
            let dense = crate::course::spline::spline_points(&p.points, false);
            let len: f64 = dense
                .windows(2)
                .map(|w| crate::course::file::dist(w[0], w[1]))
                .sum();
            let need = len / config.steady.speed + LANDING_MARGIN_S;
            c.seconds = Some(c.seconds.unwrap_or(0.0).max(need));
        }
    }
    c
}

/// Seconds of steady flight added beyond an open path's length at cruise speed, so that the
/// flight reaches the place where its landing must start.
const LANDING_MARGIN_S: f64 = 3.0;

/// The course-frame cruise altitude of `anim`'s flight: the path's first point, the take-off's
/// cruise altitude, or for a steady flight alone `course.cruise_altitude` (default: the
/// take-off's default cruise altitude).
fn course_altitude(config: &Config, path: Option<&PathPoints>, takeoff: bool) -> f64 {
    match path {
        Some(p) => p.points[0][2],
        None if takeoff => config.initiate.cruise_altitude,
        None => config
            .course
            .cruise_altitude
            .unwrap_or(InitiateOptions::default().cruise_altitude),
    }
}

/// The landing stage, when [`Config::land`]: appends a `landing` stage to `anim` (course frame,
/// before [`course_stage`]). A steady flight alone is first raised to its cruise altitude. On an
/// open path the flight is cut where the landing must start for the flock's front to come to
/// rest at the path's end; with [`Config::shot_seconds`] the steady flight is cut so that the
/// landing ends the shot.
pub fn land_stage(
    anim: &mut Animation,
    config: &Config,
    path: Option<&PathPoints>,
) -> Result<Option<LandingStats>> {
    if !config.land {
        return Ok(None);
    }
    config.landing.validate()?;
    let takeoff = anim.stage("initiation").is_some();
    if let Some(p) = path {
        let origin = config.course.path.clone().unwrap_or_default();
        crate::course::takeoff_altitude(p, &origin)?;
    }
    let altitude = course_altitude(config, path, takeoff);
    if !takeoff {
        for f in &mut anim.frames {
            for z in &mut f.z {
                *z += altitude;
            }
        }
    }
    let speed = config.steady.speed;
    let world_height = match path {
        Some(p) if !p.closed => p.points.last().map_or(altitude, |q| q[2]),
        _ => altitude,
    }
    .max(1.0);
    let site = landing::Site {
        speed,
        altitude,
        world_height,
        along_scale: path.map_or(1.0, |_| config.course.min_speed),
    };
    let fps = anim.fps;
    match (path, config.shot_seconds) {
        (Some(p), _) if !p.closed => {
            let flight = crate::course::Flight {
                speed,
                takeoff_altitude: Some(altitude),
                looped: false,
            };
            let length =
                crate::course::apply(&mut anim.clone(), Some(p), &config.course, flight)?.length;
            let s0 = crate::course::start_along(anim, takeoff);
            let front = |f: &crate::animation::Frame| f.y.iter().copied().fold(f64::MIN, f64::max);
            // The landing's reach depends a little on the birds' state where it starts: find
            // the start frame, then refine it from the reach planned there.
            let mut reach = landing::front_distance(anim, &config.landing, &site)?;
            let mut target = s0 + length - reach - speed / fps;
            let mut k = anim.frames.iter().rposition(|f| front(f) <= target);
            for _ in 0..3 {
                let Some(at) = k else { break };
                reach =
                    landing::front_distance_from(anim, &anim.frames[at], &config.landing, &site)?;
                target = s0 + length - reach - speed / fps;
                k = anim.frames.iter().rposition(|f| front(f) <= target);
            }
            let first_steady = anim.stage("steady").map_or(0, |s| s.start);
            let origin = config.course.path.clone().unwrap_or_default();
            let last = anim.frames.last().map_or(f64::MIN, front);
            match k {
                Some(k) if k >= first_steady && k + 1 < anim.frames.len() => {
                    anim.truncate(k + 1)
                }
                Some(k) if k + 1 == anim.frames.len() && last + speed / fps < target => {
                    return Err(Error::format(
                        &origin,
                        format!(
                            "the flight ends {:.0} wingspans before it must start landing to come to rest at the path's end; make the steady flight longer or the path shorter",
                            target - last
                        ),
                    ));
                }
                Some(k) if k >= first_steady => {}
                _ => {
                    return Err(Error::format(
                        &origin,
                        format!(
                            "the path ({length:.0} wingspans) is too short to take off, reach the formation and land ({reach:.0} wingspans from the start of the landing to rest); make it longer"
                        ),
                    ))
                }
            }
            landing::land(anim, &config.landing, &site, None).map(Some)
        }
        (_, Some(shot)) => {
            let total = (shot * fps).round() as usize;
            // The landing's own length, planned from the end of the flight as it is; the
            // flight is cut so that the landing ends the shot.
            let mut probe = anim.clone();
            let stats = landing::land(&mut probe, &config.landing, &site, None)?;
            let need =
                ((stats.seconds + config.landing.rest_seconds.min(0.5)) * fps).ceil() as usize + 1;
            let first_steady = anim.stage("steady").map_or(0, |s| s.start);
            let keep = total.saturating_sub(need);
            if keep <= first_steady {
                return Err(Error::parameter(
                    "shot_seconds",
                    format!(
                        "{shot} s is shorter than the take-off ({:.1} s) and the landing ({:.1} s); give a longer shot",
                        first_steady as f64 / fps,
                        need as f64 / fps
                    ),
                ));
            }
            anim.truncate(keep);
            landing::land(anim, &config.landing, &site, Some(total)).map(Some)
        }
        _ => landing::land(anim, &config.landing, &site, None).map(Some),
    }
}

/// The whole run of a flock of several formations of `sizes` birds: steady flights, take-offs
/// (when `config.initiation`), arrangement, savings and wingbeats.
fn flock_run(
    params: &FormationParams,
    sizes: &[usize],
    extract: Vec<FrameReport>,
    config: &Config,
    path: Option<&PathPoints>,
    progress: &dyn Progress,
) -> Result<(Animation, Report)> {
    let long = landing_config(config, path);
    let steady = long.steady_options()?;
    let initiate = config
        .initiation
        .then(|| takeoff_config(config, path)?.initiate_options())
        .transpose()?;
    let (mut anim, mut report) = skein::fly(
        params,
        sizes,
        &FlockOptions {
            steady: &steady,
            initiate: initiate.as_ref(),
            skein: &config.skein,
            seed: config.seed,
        },
        progress,
    )?;
    let landing = land_stage(&mut anim, config, path)?;
    let course = course_stage(&mut anim, path, config)?;
    fit_shot(&mut anim, config)?;
    finish(&mut anim, config)?;
    // The closest approach of the animation as written (its positions rounded to the file's
    // precision, moved along a path).
    report.min_separation = skein::min_separation(&anim);
    let first = report
        .formations
        .first()
        .and_then(|f| f.steady.clone())
        .ok_or_else(|| Error::Internal("a flock without formations".into()))?;
    Ok((
        anim,
        Report {
            extract,
            params: params.clone(),
            steady: first,
            initiate: skein::flock_stats(&report),
            course,
            skein: Some(report),
            landing,
        },
    ))
}

/// The steady flight of `params` for the config: one formation ([`steady_stage`]) or, for a
/// large flock, several ([`skein::fly`] without take-off); the report is then the flock's.
pub fn flock_steady_stage(
    params: &FormationParams,
    config: &Config,
    progress: &dyn Progress,
) -> Result<(Animation, SteadyOutcome)> {
    let sizes = config
        .skein
        .sizes(config.steady.birds, params.birds, config.seed)?;
    if sizes.len() == 1 {
        let (a, r) = steady_stage(params, config, progress)?;
        return Ok((a, SteadyOutcome::One(Box::new(r))));
    }
    let steady = config.steady_options()?;
    let (a, r) = skein::fly(
        params,
        &sizes,
        &FlockOptions {
            steady: &steady,
            initiate: None,
            skein: &config.skein,
            seed: config.seed,
        },
        progress,
    )?;
    Ok((a, SteadyOutcome::Flock(Box::new(r))))
}

/// The report of [`flock_steady_stage`].
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum SteadyOutcome {
    /// One formation: Algorithm 1's report.
    One(Box<SteadyReport>),
    /// Several formations: each one's report and the arrangement.
    Flock(Box<SkeinReport>),
}

/// §6 initiation into the first key shape of `steady` with the config's `initiate` section and
/// the seed's `initiate` stream. The flock size is the steady flight's. A steady flight of
/// several formations takes off formation by formation ([`skein::initiate_flock`]).
pub fn initiate_stage(
    steady: Animation,
    config: &Config,
    progress: &dyn Progress,
) -> Result<(Animation, InitiateStats)> {
    // The climb after lift-off: the option, or the power-limited climb of the species the
    // wingbeats will be of (the steady flight does not name it yet).
    let cruise = initiate::Cruise::of_birds(
        0.0,
        1.0,
        config.wingbeat.species,
        steady.wingspan_m,
        steady.flight.and_then(|f| f.mass_kg),
    );
    let opts = InitiateOptions {
        seed: config.seed,
        climb_rate: Some(config.initiate.climb_rate_for(&cruise)),
        ..config.initiate.clone()
    };
    opts.validate()?;
    initiate::check_size(steady.birds, 0, opts.max_steps)?;
    if steady.formations.is_some() {
        let (anim, report) = skein::initiate_flock(
            steady,
            &FlockOptions {
                steady: &config.steady,
                initiate: Some(&opts),
                skein: &config.skein,
                seed: config.seed,
            },
            progress,
        )?;
        let stats = skein::flock_stats(&report)
            .ok_or_else(|| Error::Internal("a take-off without statistics".into()))?;
        return Ok((anim, stats));
    }
    initiate::initiate(
        &steady,
        &opts,
        &mut stream(config.seed, Stream::Initiate),
        progress,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geese() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples_data/barnacle_geese_v.json")
    }

    fn small() -> Config {
        let mut c = Config {
            seed: 3,
            seconds: Some(1.0),
            ..Config::default()
        };
        c.steady.birds = 7;
        c
    }

    #[test]
    fn every_input_gives_the_same_animation() {
        let config = small();
        let (a, rep) = Pipeline::from_path(geese()).run(&config).unwrap();
        assert_eq!(rep.extract.len(), 20);
        let ann = crate::annotations::read(&geese(), &config.read).unwrap();
        let (b, _) = Pipeline::from_annotations(ann.clone())
            .run(&config)
            .unwrap();
        assert_eq!(a, b);
        let (params, _) = extract_stage(&ann, &config, &Silent).unwrap();
        let (c, rep) = Pipeline::from_params(params).run(&config).unwrap();
        assert_eq!(a, c);
        assert!(rep.extract.is_empty());
        assert_eq!(a.birds, 7);
        assert_eq!(a.stage("steady").map(|s| s.end - s.start), Some(30));
        assert!(rep.initiate.is_some_and(|s| s.converged));
    }

    #[test]
    fn points_in_memory_are_annotations() {
        let frames: Vec<Vec<[f64; 2]>> = (0..2)
            .map(|f| {
                (0..7)
                    .map(|i| {
                        let rank = ((i + 1) / 2) as f64;
                        let side = if i % 2 == 1 { 1.0 } else { -1.0 };
                        [100.0 + side * 30.0 * rank + f as f64, 50.0 + 20.0 * rank]
                    })
                    .collect()
            })
            .collect();
        let ann =
            Annotations::from_points("memory", crate::annotations::Heading::Up, 32.0, &frames)
                .unwrap();
        assert_eq!(ann.bird_count(), 7);
        let (p, _) = extract_stage(&ann, &small(), &Silent).unwrap();
        assert!(p
            .frames
            .iter()
            .all(|f| f.shape.kind() == "v" && f.outliers.is_empty()));
        let mut bad = frames.clone();
        bad[1][3] = [f64::NAN, 0.0];
        let e = Annotations::from_points("memory", crate::annotations::Heading::Up, 32.0, &bad)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "memory: frames[1][3]: not a finite number");
    }

    #[test]
    fn config_round_trips_through_json_and_rejects_typos() {
        let mut c = small();
        c.initiate.perception.mode = crate::initiate::PerceptionMode::Exact;
        c.wingbeat.species = crate::wingbeat::Species::Crane;
        let text = serde_json::to_string(&c).unwrap();
        let back: Config = serde_json::from_str(&text).unwrap();
        assert_eq!(back, c);
        let partial: Config = serde_json::from_str(r#"{"steady": {"birds": 12}}"#).unwrap();
        assert_eq!(partial.steady.birds, 12);
        assert_eq!(partial.steady.fps, SteadyOptions::default().fps);
        assert!(serde_json::from_str::<Config>(r#"{"steady": {"bird": 12}}"#).is_err());
    }

    #[test]
    fn errors_name_option_paths() {
        let mut c = small();
        c.seconds = Some(-1.0);
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("seconds: "));
        let mut c = small();
        c.steady.fps = 0.0;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("steady.fps: "));
        let mut c = small();
        c.initiate.max_turn_rate = -1.0;
        let e = c.validate().unwrap_err().to_string();
        assert!(e.starts_with("initiate.max_turn_rate: "), "{e}");
        let mut c = small();
        c.wingbeat.variation = 9.0;
        let e = c.validate().unwrap_err().to_string();
        assert!(e.starts_with("wingbeat.variation: "), "{e}");
    }
}

//! `formation steady`, `formation plot power` and `formation plot xi` (issue 4): flags into
//! [`SteadyOptions`], the library's Algorithm 1, and the animation written as JSON or long CSV.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use formation::aero::power_reduction;
use formation::animation::Animation;
use formation::extract::params::FormationParams;
use formation::io::{write_json_atomic, OutputKind};
use formation::keyshape::{steady_flight_report, SteadyOptions};
use formation::plot::power::{PowerChart, PowerMetric};
use formation::plot::xi::XiChart;
use formation::shape::Shape;
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
    /// Number of frames (F ≥ 1).
    #[arg(long)]
    pub frames: usize,
    /// Outputs by extension: .json (the animation file), .csv, and also .gif, DIR/, .glb; may be
    /// repeated.
    #[arg(short = 'o', long = "output", required = true)]
    pub output: Vec<PathBuf>,
    #[command(flatten)]
    pub steady: SteadyFlags,
    #[command(flatten)]
    pub wingbeat: super::wingbeat::WingbeatFlags,
    #[command(flatten)]
    pub scene: super::render::SceneArgs,
    /// Also write the run's report (correspondence, ranges, solve statistics) as JSON here.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Steady-flight flags shared by `steady` and `animate`.
#[derive(Debug, Clone, Args)]
pub struct SteadyFlags {
    /// Frames per second of the animation.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub fps: f64,
    /// Time between key shapes, seconds.
    #[arg(
        long = "key-every",
        default_value_t = 3.0,
        allow_negative_numbers = true
    )]
    pub key_every: f64,
    /// Cruise speed of the flock, wingspans per second.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub speed: f64,
    /// ε of eq. (2): widening of each bird's ξ range, in [0, 0.5].
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    pub epsilon: f64,
    /// C1 of eq. (2): smallest step ratio of ξ between key shapes, in [0.5, 1].
    #[arg(long, default_value_t = 0.85, allow_negative_numbers = true)]
    pub c1: f64,
    /// C2 of eq. (2): largest step ratio of ξ between key shapes, in [1, 2].
    #[arg(long, default_value_t = 1.15, allow_negative_numbers = true)]
    pub c2: f64,
    /// Wingspan of one bird, metres (recorded in the animation; used by the .glb export).
    #[arg(
        long = "wingspan-m",
        default_value_t = 1.5,
        allow_negative_numbers = true
    )]
    pub wingspan_m: f64,
    /// Largest move of a bird between consecutive key shapes, wingspans.
    #[arg(
        long = "max-jump",
        default_value_t = 0.5,
        allow_negative_numbers = true
    )]
    pub max_jump: f64,
}

impl SteadyFlags {
    /// The validated library options for `birds` birds and `frames` frames.
    pub fn options(&self, birds: usize, frames: usize, seed: u64) -> Result<SteadyOptions> {
        let opts = SteadyOptions {
            birds,
            frames,
            fps: self.fps,
            key_every_s: self.key_every,
            speed: self.speed,
            epsilon: self.epsilon,
            c1: self.c1,
            c2: self.c2,
            wingspan_m: self.wingspan_m,
            seed,
            max_jump: self.max_jump,
            ..SteadyOptions::default()
        };
        opts.validate()?;
        Ok(opts)
    }
}

/// Runs `formation steady`.
pub fn run(args: SteadyArgs, g: Global) -> Result<()> {
    let opts = args.steady.options(args.birds, args.frames, g.seed)?;
    let wing = args.wingbeat.options()?;
    let plan = formation::export::plan_outputs(&args.output)?;
    if let Some(r) = &args.report {
        OutputKind::for_flag("--report", r, &[OutputKind::Json])?;
        formation::io::check_output_dir("--report", r)?;
        let id = formation::io::output_identity(r);
        if plan
            .iter()
            .any(|o| formation::io::output_identity(&o.path) == id)
        {
            return Err(formation::Error::parameter(
                "--report",
                format!(
                    "{}: is also given to -o; the report needs a file of its own",
                    r.display()
                ),
            ));
        }
    }
    let params = read_params(&args.params)?;
    let mut rng = formation::rng::stream(g.seed, "steady");
    let progress = TermProgress::new(g.quiet);
    let (mut anim, report) = steady_flight_report(&params, &opts, &mut rng, &progress)?;
    formation::wingbeat::assign_phases(&mut anim, &wing)?;
    super::write_animation(&anim, &args.output, &args.scene.options(), g)?;
    if let Some(r) = &args.report {
        write_json_atomic(r, &report)?;
    }
    if !g.quiet {
        let k = &report.keys;
        eprintln!(
            "steady: {} key shapes ({} draws, {} redraws, {} damped, {} held, min λ {:.3}), max key residual {:.1e}, max jump {:.2} wingspans",
            k.keys, k.draws, k.redraws, k.damped, k.held, k.min_damping, k.max_residual, k.max_jump
        );
    }
    Ok(())
}

/// Reads a params file, telling other `formation` files apart before serde's field errors.
pub fn read_params(path: &Path) -> Result<FormationParams> {
    let value: serde_json::Value = formation::io::read_json(path)?;
    let tag = value.get("format").and_then(|f| f.as_str());
    if tag != Some(formation::extract::params::PARAMS_FORMAT) {
        let found = match tag {
            Some(t) => format!("a \"{t}\" file"),
            None if value.get("birds").is_some_and(|b| b.is_array()) => "a shape file".into(),
            None => "no \"format\" field".into(),
        };
        return Err(Error::format(
            path,
            format!(
                "not a formation params file ({found}, expected \"format\": \"{}\"); write one with `formation extract ANNOTATIONS -o params.json`",
                formation::extract::params::PARAMS_FORMAT
            ),
        ));
    }
    FormationParams::read(path)
}

/// What `plot power` shows.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum MetricArg {
    /// Relative power reduction ξ_i = e_i / E.
    Xi,
    /// Power reduction e_i.
    E,
}

/// Arguments of `formation plot power`.
#[derive(Debug, Args)]
pub struct PlotPowerArgs {
    /// A shape file (SPEC §4.3) or an animation file.
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
    #[arg(long, value_enum, default_value_t = MetricArg::Xi)]
    pub metric: MetricArg,
}

/// Runs `formation plot power`.
pub fn run_plot_power(args: PlotPowerArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let metric = match args.metric {
        MetricArg::Xi => PowerMetric::Xi,
        MetricArg::E => PowerMetric::E,
    };
    let name = args
        .input
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let value: serde_json::Value = formation::io::read_json(&args.input)?;
    let is_animation = value.get("format").and_then(|f| f.as_str())
        == Some(formation::animation::ANIMATION_FORMAT);
    let chart = if is_animation {
        let anim = Animation::read(&args.input)?;
        let (x, e, xi, what) = match args.frame {
            Some(k) => {
                let fr = anim.frames.get(k).ok_or_else(|| {
                    Error::parameter(
                        "--frame",
                        format!(
                            "{k}: {} has {} frames (0..{})",
                            args.input.display(),
                            anim.frames.len(),
                            anim.frames.len().saturating_sub(1)
                        ),
                    )
                })?;
                let (e, xi) = match (&fr.e, &fr.xi) {
                    (Some(e), Some(xi)) => (e.clone(), xi.clone()),
                    _ => {
                        // World → formation frame for a flock heading +y: y behind = −north.
                        let back: Vec<f64> = fr.y.iter().map(|v| -v).collect();
                        let p = power_reduction(&fr.x, &back)?;
                        (p.e, p.xi)
                    }
                };
                (fr.x.clone(), e, xi, format!("frame {k}"))
            }
            None => {
                let k = args.key.unwrap_or(0);
                let ks = anim.key_shapes.get(k).ok_or_else(|| {
                    Error::parameter(
                        "--key",
                        format!(
                            "{k}: {} has {} key shape(s); use --frame for an animation without key shapes",
                            args.input.display(),
                            anim.key_shapes.len()
                        ),
                    )
                })?;
                let x: Vec<f64> = ks.birds.iter().map(|b| b.x).collect();
                let y: Vec<f64> = ks.birds.iter().map(|b| b.y).collect();
                let p = power_reduction(&x, &y)?;
                (x, p.e, p.xi, format!("key shape {k} (frame {})", ks.frame))
            }
        };
        let leader = if args.frame.is_none() {
            anim.key_shapes
                .get(args.key.unwrap_or(0))
                .and_then(|ks| {
                    ks.birds
                        .iter()
                        .enumerate()
                        .min_by(|a, b| a.1.y.total_cmp(&b.1.y))
                })
                .map(|(i, _)| i)
        } else {
            None
        };
        PowerChart {
            title: format!("{name}: {what}"),
            values: match metric {
                PowerMetric::Xi => xi,
                PowerMetric::E => e,
            },
            x,
            metric,
            ranges: anim.xi_ranges.clone(),
            leader,
        }
    } else {
        if args.key.is_some() || args.frame.is_some() {
            return Err(Error::parameter(
                "--key/--frame",
                format!(
                    "{} is a shape file, which has no key shapes or frames",
                    args.input.display()
                ),
            ));
        }
        let shape: Shape = formation::io::parse_json(
            &args.input,
            &serde_json::to_string(&value).map_err(|e| Error::Internal(e.to_string()))?,
        )?;
        shape.validate(&args.input, 2)?;
        let p = power_reduction(&shape.xs(), &shape.ys())?;
        PowerChart {
            title: format!("{name}: E = {:.4}", p.total),
            x: shape.xs(),
            values: match metric {
                PowerMetric::Xi => p.xi,
                PowerMetric::E => p.e,
            },
            metric,
            ranges: None,
            leader: shape.leader(),
        }
    };
    formation::plot::save(&chart, &args.output)
}

/// Arguments of `formation plot xi`.
#[derive(Debug, Args)]
pub struct PlotXiArgs {
    /// An animation file.
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
}

/// Runs `formation plot xi`.
pub fn run_plot_xi(args: PlotXiArgs, _g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let anim = Animation::read(&args.input)?;
    let n = anim.birds;
    let mut xi = vec![Vec::with_capacity(anim.frames.len()); n];
    let mut any = false;
    for fr in &anim.frames {
        let values = match &fr.xi {
            Some(v) => Some(v.clone()),
            None => {
                let back: Vec<f64> = fr.y.iter().map(|v| -v).collect();
                power_reduction(&fr.x, &back).ok().map(|p| p.xi)
            }
        };
        any |= values.is_some();
        for (i, series) in xi.iter_mut().enumerate() {
            series.push(
                values
                    .as_ref()
                    .and_then(|v| v.get(i).copied())
                    .unwrap_or(f64::NAN),
            );
        }
    }
    if !any {
        return Err(Error::format(
            &args.input,
            "no frame has a defined ξ (every frame has two birds wing to wing)",
        ));
    }
    let lateral = anim
        .key_shapes
        .first()
        .map(|k| k.birds.iter().map(|b| b.x).collect())
        .or_else(|| anim.frames.first().map(|f| f.x.clone()))
        .unwrap_or_default();
    let name = args
        .input
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let chart = XiChart {
        title: format!("{name}: ξ of {n} birds over time"),
        t: anim.frames.iter().map(|f| f.t).collect(),
        xi,
        lateral,
        key_times: anim
            .key_shapes
            .iter()
            .filter_map(|k| anim.frames.get(k.frame).map(|f| f.t))
            .collect(),
    };
    formation::plot::save(&chart, &args.output)
}

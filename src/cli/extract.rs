//! `formation extract` and `formation plot shape`: flags → [`ReadOptions`] and
//! [`ExtractOptions`], the per-frame summary table on stdout, the params file through an atomic
//! write.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use formation::annotations::{self, Heading, ReadOptions, YOrigin};
use formation::extract::{ExtractOptions, FormationParams, FrameReport, ShapeKind};
use formation::io::{write_json_atomic, OutputKind};
use formation::pipeline::{extract_stage, Config};
use formation::{Error, Result};

use super::Global;

/// How to read annotations (shared by `extract` and `plot shape`).
#[derive(Debug, Args, Clone)]
pub struct ReadArgs {
    /// Flight direction in the image: up, down, left, right, or degrees clockwise from image-up
    /// (overrides the file's `heading`; default up).
    #[arg(long, allow_hyphen_values = true, value_name = "DIR|DEG")]
    pub heading: Option<Heading>,
    /// Wingspan in pixels, for every frame (overrides the file's `wingspan_px`).
    #[arg(long = "wingspan-px", value_name = "PX", allow_hyphen_values = true)]
    pub wingspan_px: Option<f64>,
    /// Where pixel y = 0 is in CSV input: top (long CSV default) or bottom (DLTdv default).
    #[arg(long = "y-origin", value_name = "top|bottom")]
    pub y_origin: Option<YOrigin>,
    /// The body part (DeepLabCut) or node (SLEAP) that gives each bird's position in a tracker's
    /// file (default: the first the file lists).
    #[arg(long, value_name = "NAME")]
    pub bodypart: Option<String>,
}

/// Fitting options (shared by `extract` and `plot shape`).
#[derive(Debug, Args, Clone)]
pub struct FitArgs {
    /// Inlier threshold: birds farther than this from the fitted curve are outliers, wingspans.
    #[arg(long, default_value_t = ExtractOptions::default().inlier_threshold, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Fit only this shape family: v, u, j or line (default: chosen per frame).
    #[arg(long)]
    pub kind: Option<ShapeKind>,
    /// Most RANSAC samples per model and frame (all subsets are tried when there are fewer).
    #[arg(long = "max-samples", default_value_t = ExtractOptions::default().max_samples)]
    pub max_samples: usize,
    /// A parabola is a J when its vertex is more than this fraction of the flock's half-width
    /// from its centre.
    #[arg(long = "j-offset", default_value_t = ExtractOptions::default().j_offset, allow_hyphen_values = true)]
    pub j_offset: f64,
}

/// The bird's size in metres (shared by `extract` and `report`).
#[derive(Debug, Args, Clone)]
pub struct SizeArgs {
    /// Wingspan of one bird, metres: the wingtip spacings are also given in metres (default:
    /// unknown, wingspans only).
    #[arg(long = "wingspan-m", value_name = "M", allow_hyphen_values = true)]
    pub wingspan_m: Option<f64>,
}

/// The footage's timing (shared by `extract`, `report` and `animate`).
#[derive(Debug, Args, Clone)]
pub struct TimingArgs {
    /// Frames per second of the footage: frame times are frame index / F, for the birds'
    /// position-keeping statistics (default: the annotations' top-level "fps"; without either,
    /// the steady flight uses the field-data default).
    #[arg(long = "footage-fps", value_name = "F", allow_hyphen_values = true)]
    pub footage_fps: Option<f64>,
}

impl ReadArgs {
    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            heading: self.heading,
            wingspan_px: self.wingspan_px,
            y_origin: self.y_origin,
            bodypart: self.bodypart.clone(),
        }
    }
}

impl FitArgs {
    /// The library options for these flags.
    pub fn options(&self) -> ExtractOptions {
        ExtractOptions {
            inlier_threshold: self.threshold,
            max_samples: self.max_samples,
            j_offset: self.j_offset,
            kind: self.kind,
            ..ExtractOptions::default()
        }
    }
}

/// Arguments of `formation extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// Annotations: native JSON, long CSV, DLTdv CSV, Labelme JSON file or directory.
    pub annotations: PathBuf,
    /// Output params file (.json).
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Print the params as JSON on stdout instead of the summary table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub extraction: ExtractionArgs,
}

/// Reading, fitting and the bird's size: every flag of §4 extraction (shared by `extract` and
/// `report`).
#[derive(Debug, Args, Clone)]
pub struct ExtractionArgs {
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub timing: TimingArgs,
}

impl ExtractionArgs {
    /// The extraction options for these flags.
    pub fn options(&self) -> ExtractOptions {
        ExtractOptions {
            wingspan_m: self.size.wingspan_m,
            footage_fps: self.timing.footage_fps,
            ..self.fit.options()
        }
    }
}

/// Reads annotations and extracts, with the seed's `extract` stream. The warnings in the
/// params name `cmd`'s flags.
pub fn read_and_extract(
    path: &Path,
    read: &ReadArgs,
    extract: ExtractOptions,
    g: Global,
    cmd: super::flags::Cmd,
) -> Result<(annotations::Annotations, FormationParams, Vec<FrameReport>)> {
    let config = Config {
        seed: g.seed,
        read: read.options(),
        extract,
        ..Config::default()
    };
    config.extract.validate()?;
    let ann = annotations::read(path, &config.read)?;
    let progress = super::progress::TermProgress::new(g.quiet);
    let (mut params, reports) = extract_stage(&ann, &config, &progress)?;
    if let Some(s) = &mut params.summary {
        for w in &mut s.warnings {
            w.message = super::flags::rewrite(cmd, &w.message);
        }
    }
    Ok((ann, params, reports))
}

/// Runs `formation extract`.
pub fn run(args: ExtractArgs, g: Global) -> Result<()> {
    if args.output.is_none() && !args.json {
        return Err(Error::parameter(
            "-o",
            "give an output file (-o params.json) or --json to print the params on stdout",
        ));
    }
    if let Some(o) = &args.output {
        OutputKind::from_path(o, &[OutputKind::Json])?;
    }
    let (ann, params, reports) = read_and_extract(
        &args.annotations,
        &args.extraction.read,
        args.extraction.options(),
        g,
        super::flags::Cmd::Extract,
    )?;
    super::warn_params(g, &params)?;
    if let Some(o) = &args.output {
        write_json_atomic(o, &params)?;
    }
    if args.json {
        let s = formation::finite::to_json_pretty("params", &params)?;
        super::stdout::println(&s)?;
    } else if !g.quiet {
        super::stdout::print(&summary_table(
            &ann,
            &params,
            &reports,
            args.output.as_deref(),
        ))?;
    }
    Ok(())
}

fn id_list(ids: &[usize]) -> String {
    if ids.is_empty() {
        return "-".into();
    }
    let mut ids = ids.to_vec();
    ids.sort_unstable();
    let s: Vec<String> = ids.iter().map(|i| i.to_string()).collect();
    let s = s.join(",");
    if s.len() > 18 {
        format!("{}…", &s[..s[..17].rfind(',').unwrap_or(17)])
    } else {
        s
    }
}

/// The per-frame summary table.
pub fn summary_table(
    ann: &annotations::Annotations,
    p: &FormationParams,
    reports: &[FrameReport],
    out: Option<&Path>,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: {} ({}), {} frames, {} birds, ids {}",
        ann.path.display(),
        p.source,
        ann.format.name(),
        p.frames.len(),
        p.birds,
        if ann.ids_given {
            "from the file"
        } else {
            "assigned (lateral order in frame 0, then matched)"
        }
    );
    s.push_str(
        " frame birds  kind leader   mu_x sigma_x   mu_y sigma_y  inl  outliers           next best (ΔS)   apex° (left+right)  depth    WTS\n",
    );
    for (f, r) in p.frames.iter().zip(reports) {
        let next = r
            .margin()
            .map(|(k, d)| format!("{} (+{:.1})", k.name(), d))
            .unwrap_or_else(|| "-".into());
        let _ = writeln!(
            s,
            "{:>6} {:>5} {:>5} {:>6} {:>6.3} {:>7.3} {:>6.3} {:>7.3} {:>4}  {:<18} {:<14} {:>19} {:>6} {:>6}",
            f.index,
            f.order.len(),
            f.shape.kind(),
            f.leader,
            f.mu_x,
            f.sigma_x,
            f.mu_y,
            f.sigma_y,
            f.inliers.len(),
            id_list(&f.outliers),
            next,
            f.geometry.map(|g| apex_text(&g)).unwrap_or_else(|| "-".into()),
            f.geometry.map(|g| format!("{:.2}", g.depth)).unwrap_or_else(|| "-".into()),
            f.geometry
                .map(|g| format!("{:+.2}", g.wingtip_spacing))
                .unwrap_or_else(|| "-".into()),
        );
    }
    let kinds: Vec<String> = p
        .kind_counts()
        .iter()
        .map(|(k, c)| format!("{k} in {c}/{}", p.frames.len()))
        .collect();
    let n_out: usize = p.frames.iter().map(|f| f.outliers.len()).sum();
    let _ = write!(
        s,
        "kinds: {}; {} outlier marks; ΔS = criterion gap to the next best family (larger = clearer)",
        kinds.join(", "),
        n_out
    );
    s.push('\n');
    if let Some(sum) = &p.summary {
        s.push_str(&overall_text(&sum.geometry, sum.wingspan_m.is_some()));
    }
    if let Some(ci) = &p.ci {
        s.push_str(&ci_text(ci));
    }
    s.push_str("angles from the flight axis behind the leader (90° = line abreast); depth = farthest inlier behind the leader; WTS = mean wingtip spacing of lateral neighbours (μ_x − 1), wingspans\n");
    if let Some(o) = out {
        let _ = writeln!(s, "wrote {}", o.display());
    }
    s
}

/// The line of 95 % bootstrap intervals.
pub fn ci_text(ci: &formation::extract::bootstrap::Intervals) -> String {
    let r = |v: Option<[f64; 2]>, prec: usize, unit: &str| {
        v.map(|[lo, hi]| format!("{lo:.prec$} to {hi:.prec$}{unit}"))
    };
    let parts: Vec<String> = [
        r(ci.apex_deg, 1, "°").map(|t| format!("apex angle {t}")),
        r(ci.lateral, 2, "")
            .zip(r(ci.behind, 2, " wingspans"))
            .map(|(a, b)| format!("nearest bird ahead {a} to the side and {b} in front")),
        r(ci.depth, 2, " wingspans").map(|t| format!("depth {t}")),
        r(ci.wts, 3, " wingspans").map(|t| format!("mean wingtip spacing {t}")),
    ]
    .into_iter()
    .flatten()
    .collect();
    if parts.is_empty() {
        return String::new();
    }
    format!(
        "95 % intervals of the medians (bootstrap over frames and birds): {}\n",
        parts.join("; ")
    )
}

/// `54.1 (27.0+27.1)`, `61.0 (right)` for one arm, `-` for none.
fn apex_text(g: &formation::extract::geometry::FrameGeometry) -> String {
    match (g.arm_left_deg, g.arm_right_deg) {
        (Some(l), Some(r)) => format!("{:.1} ({l:.1}+{r:.1})", l + r),
        (Some(l), None) => format!("{l:.1} (left)"),
        (None, Some(r)) => format!("{r:.1} (right)"),
        (None, None) => "-".into(),
    }
}

/// The `overall:` line of the summary table.
pub fn overall_text(g: &formation::extract::geometry::GeometrySummary, metres: bool) -> String {
    use formation::extract::geometry::Stat;
    let st = |s: &Option<Stat>, unit: &str, prec: usize| match s {
        Some(s) => format!(
            "{:.prec$}{unit} (median of {} frames, {:.prec$} to {:.prec$})",
            s.median, s.frames, s.min, s.max
        ),
        None => "-".into(),
    };
    let mut s = String::from("overall: ");
    match (&g.apex_deg, &g.arm_left_deg, &g.arm_right_deg) {
        (Some(_), Some(l), Some(r)) => {
            let _ = write!(
                s,
                "apex angle {}, left arm {:.1}°, right arm {:.1}°; ",
                st(&g.apex_deg, "°", 1),
                l.median,
                r.median
            );
        }
        (_, l, r) => {
            let _ = write!(
                s,
                "no apex (one arm): left arm {}, right arm {}; ",
                st(l, "°", 1),
                st(r, "°", 1)
            );
        }
    }
    let _ = write!(s, "depth {}; ", st(&g.depth, " wingspans", 2));
    let _ = write!(
        s,
        "mean wingtip spacing {}",
        st(&g.wingtip_spacing, " wingspans", 2)
    );
    if metres {
        let _ = write!(s, " = {}", st(&g.wingtip_spacing_m, " m", 2));
    }
    s.push('\n');
    s
}

/// Arguments of `formation plot shape`.
#[derive(Debug, Args)]
pub struct PlotShapeArgs {
    /// A params file written by `formation extract`, or annotations (extracted on the fly).
    pub input: PathBuf,
    /// Output chart (.png or .svg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Frame index to draw (as in the table's `frame` column; default: the first frame).
    #[arg(long, allow_hyphen_values = true)]
    pub frame: Option<i64>,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub fit: FitArgs,
}

/// Runs `formation plot shape`.
pub fn run_plot_shape(args: PlotShapeArgs, g: Global) -> Result<()> {
    OutputKind::from_path(&args.output, &[OutputKind::Png, OutputKind::Svg])?;
    let (params, threshold) = if let Some(p) = FormationParams::read_if_params(&args.input)? {
        (p, None)
    } else {
        let (_, p, _) = read_and_extract(
            &args.input,
            &args.read,
            args.fit.options(),
            g,
            super::flags::Cmd::PlotShape,
        )?;
        super::warn_params(g, &p)?;
        (p, Some(args.fit.threshold))
    };
    let chart = formation::plot::shape::ShapeChart::from_params(
        &params,
        args.frame,
        threshold,
        &args.input,
    )?;
    super::chart::save(&chart, &args.output)
}

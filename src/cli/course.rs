//! Course flags shared by `steady`, `initiate` and `animate`: the path the flock
//! follows and its units (the `course` section of the library's `Config`), and the warnings the
//! course step reports; `--land` and `--land-on`, the landing at the course's end.

use std::path::PathBuf;

use clap::Args;
use formation::course::{CourseOptions, CourseReport, PathUnits};
use formation::initiate::landing::Surface;

/// `--path` and `--path-units`.
#[derive(Debug, Clone, Args)]
pub struct PathFlags {
    /// The leader's path, world frame (x east, y north, z up): JSON {"units": "wingspans" | "m",
    /// "points": [[x, y, z], ...]} or CSV x,y,z; the formation turns, banks and climbs along it
    /// (docs/paths.md). A last point equal to the first closes the path.
    #[arg(long)]
    pub path: Option<PathBuf>,
    /// Units of the path's coordinates: wingspans or m (when not given: the file's "units", else
    /// wingspans).
    #[arg(long = "path-units", value_name = "UNITS", value_parser = parse_units)]
    pub path_units: Option<PathUnits>,
}

fn parse_units(s: &str) -> Result<PathUnits, String> {
    PathUnits::parse(s).ok_or_else(|| format!("unknown units \"{s}\"; use wingspans or m"))
}

impl PathFlags {
    /// The course options with this path (other fields default).
    pub fn options(&self) -> CourseOptions {
        CourseOptions {
            path: self.path.clone(),
            units: self.path_units,
            ..CourseOptions::default()
        }
    }
}

/// Refuses a run that would write over its own `--path` file (`--path-out`, an `-o` output or
/// a frames file naming it), naming both.
pub fn check_path_kept(
    flags: &PathFlags,
    outputs: &[PathBuf],
    opts: &formation::export::RenderOptions,
) -> formation::Result<()> {
    match &flags.path {
        Some(p) => formation::export::check_written(outputs, opts, &[("course.path", p)]),
        None => formation::export::check_written(outputs, opts, &[]),
    }
}

/// Prints the course step's warnings on stderr, one line each (with `--strict`, the first is
/// the error instead).
pub fn warn(
    cmd: super::flags::Cmd,
    g: super::Global,
    report: &CourseReport,
) -> formation::Result<()> {
    let lines: Vec<&str> = report.warnings.iter().map(String::as_str).collect();
    super::warn_lines(cmd, g, &lines)
}

/// For `initiate --path`: the config the course step needs (the steady file's cruise speed and
/// wingspan, the take-off's altitude) and the loaded path; sets the take-off's cruise altitude
/// to the path's first point. A steady file already on a path is refused.
pub fn course_config(
    flags: &PathFlags,
    steady: &formation::Animation,
    origin: &std::path::Path,
    opts: &mut formation::initiate::InitiateOptions,
) -> formation::Result<(
    formation::pipeline::Config,
    Option<formation::course::PathPoints>,
)> {
    formation::pipeline::takeoff_course(flags.options(), steady, origin, opts)
}

/// `--land` and `--land-on`, shared by `steady`, `initiate` and `animate`.
#[derive(Debug, Clone, Args)]
pub struct LandFlags {
    /// End the flight with a landing: the formation loosens, glides down, flares, touches down
    /// bird after bird and stops, wings folded (docs/landing.md); with --path, where the path
    /// ends.
    #[arg(long)]
    pub land: bool,
    /// Where to land: ground (a few running steps, then sitting) or water (the body settles at
    /// the waterline); implies --land.
    #[arg(long = "land-on", value_name = "SURFACE", value_parser = parse_surface)]
    pub land_on: Option<Surface>,
}

fn parse_surface(s: &str) -> Result<Surface, String> {
    Surface::parse(s).map_err(|_| format!("unknown surface \"{s}\"; use ground or water"))
}

impl LandFlags {
    /// Sets `config.land` and `config.landing` from the flags.
    pub fn apply(&self, config: &mut formation::pipeline::Config) {
        config.land = self.land || self.land_on.is_some();
        if let Some(s) = self.land_on {
            config.landing.surface = s;
        }
    }
}

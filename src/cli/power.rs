//! `formation power SHAPE [--json]`: e_i, ξ_i and E of a shape (SPEC §4.3).

use std::path::PathBuf;

use clap::Args;
use formation::{aero, Error, Result, Shape};
use serde::Serialize;

use super::Global;

/// Arguments of `formation power`.
#[derive(Debug, Args)]
pub struct PowerArgs {
    /// Shape file: {"birds": [{"x": .., "y": ..}, ...]} in the formation frame, wingspans.
    pub shape: PathBuf,
    /// Print JSON ({"total": E, "birds": [{"x","y","e","xi"}]}) instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct PowerJson {
    total: f64,
    birds: Vec<BirdJson>,
}

#[derive(Serialize)]
struct BirdJson {
    x: f64,
    y: f64,
    e: f64,
    xi: f64,
}

/// Runs `formation power`.
pub fn run(args: PowerArgs, _g: Global) -> Result<()> {
    let shape: Shape = formation::io::read_json(&args.shape)?;
    shape.validate(&args.shape, 2)?;
    let (x, y) = (shape.xs(), shape.ys());
    let pr = aero::power_reduction(&x, &y).map_err(|e| in_file(&args.shape, e))?;
    let mut out = String::new();
    if args.json {
        let doc = PowerJson {
            total: pr.total,
            birds: shape
                .birds
                .iter()
                .zip(pr.e.iter().zip(&pr.xi))
                .map(|(b, (&e, &xi))| BirdJson {
                    x: b.x,
                    y: b.y,
                    e,
                    xi,
                })
                .collect(),
        };
        out = formation::finite::to_json_pretty("power", &doc)?;
        out.push('\n');
    } else {
        let leader = shape.leader().unwrap_or(0);
        out.push_str(&format!(
            "{:>5} {:>10} {:>10} {:>12} {:>9}\n",
            "bird", "x", "y", "e", "xi"
        ));
        for (i, b) in shape.birds.iter().enumerate() {
            out.push_str(&format!(
                "{:>5} {:>10.4} {:>10.4} {:>12.6} {:>9.5}{}\n",
                i,
                b.x,
                b.y,
                pr.e[i],
                pr.xi[i],
                if i == leader { "  leader" } else { "" }
            ));
        }
        out.push_str(&format!(
            "total E = {:.6} over {} birds (wingspans; drag ratio C omitted)\n",
            pr.total,
            shape.len()
        ));
    }
    super::stdout::print(&out)
}

/// Prefixes a model error with the file it came from.
pub fn in_file(path: &std::path::Path, e: Error) -> Error {
    match e {
        Error::Downwash { .. } | Error::Parameter { .. } | Error::Unreachable(_) => {
            Error::format(path, e.to_string())
        }
        other => other,
    }
}

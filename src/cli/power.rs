//! `formation power SHAPE [--json]`: e_i, ξ_i and E of a shape (docs/formats.md).

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
    /// Print JSON ({"total": E, "flock_saving": E/N, "birds": [{"x","y","e","xi","saving"}]})
    /// instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Vortex core radius of Hummel's model, wingspans (docs/model.md).
    #[arg(long, allow_negative_numbers = true, default_value_t = formation::aero::AeroOptions::default().core_radius)]
    pub core_radius: f64,
}

#[derive(Serialize)]
struct PowerJson {
    total: f64,
    flock_saving: f64,
    birds: Vec<BirdJson>,
}

#[derive(Serialize)]
struct BirdJson {
    x: f64,
    y: f64,
    e: f64,
    xi: f64,
    saving: f64,
}

/// Runs `formation power`.
pub fn run(args: PowerArgs, _g: Global) -> Result<()> {
    let text = formation::io::read_text(&args.shape)?;
    match formation::sniff::text_kind(&text) {
        None | Some(formation::sniff::Kind::Shape | formation::sniff::Kind::Unknown) => {}
        Some(kind) => {
            return Err(Error::format(
                &args.shape,
                format!(
                    "this is {}, not a shape; `formation power` reads {{\"birds\": [{{\"x\": .., \"y\": ..}}, ...]}}{}",
                    kind.describe(),
                    if kind == formation::sniff::Kind::Animation {
                        " (an animation's key shapes are charted by `formation plot power`)"
                    } else {
                        ""
                    }
                ),
            ))
        }
    }
    let shape: Shape = formation::io::parse_json(&args.shape, &text)?;
    shape.validate(&args.shape, 2)?;
    let (x, y) = (shape.xs(), shape.ys());
    let model = aero::AeroOptions {
        core_radius: args.core_radius,
        ..aero::AeroOptions::default()
    };
    model.validate().map_err(|e| match e {
        Error::Parameter { message, .. } => Error::parameter("--core-radius", message),
        other => other,
    })?;
    let pr = model
        .power_reduction(&x, &y)
        .map_err(|e| in_file(&args.shape, e))?;
    let flock_saving = pr.total / shape.len() as f64;
    let mut out = String::new();
    if args.json {
        let doc = PowerJson {
            total: pr.total,
            flock_saving,
            birds: shape
                .birds
                .iter()
                .zip(pr.e.iter().zip(&pr.xi))
                .map(|(b, (&e, &xi))| BirdJson {
                    x: b.x,
                    y: b.y,
                    e,
                    xi,
                    saving: e,
                })
                .collect(),
        };
        out = formation::finite::to_json_pretty("power", &doc)?;
        out.push('\n');
    } else {
        let leader = shape.leader().unwrap_or(0);
        out.push_str(&format!(
            "{:>5} {:>10} {:>10} {:>9} {:>9}\n",
            "bird", "x", "y", "saving", "xi"
        ));
        for (i, b) in shape.birds.iter().enumerate() {
            out.push_str(&format!(
                "{:>5} {:>10.4} {:>10.4} {:>8.2}% {:>9.5}{}\n",
                i,
                b.x,
                b.y,
                100.0 * pr.e[i],
                pr.xi[i],
                if i == leader { "  leader" } else { "" }
            ));
        }
        out.push_str(&format!(
            "flock saving {:.2}% (mean over {} birds; E = {:.6})\n",
            100.0 * flock_saving,
            shape.len(),
            pr.total
        ));
        out.push_str(
            "saving = e, the share of a bird's solo induced power (the power that holds it up) that the\n\
             others save it (negative: it flies in downwash); total power falls by about C × saving,\n\
             C = induced / total power (0.3-0.5 in cruise); x, y in wingspans, y behind the leader\n",
        );
    }
    super::stdout::print(&out)
}

/// Prefixes a model error with the file it came from.
pub fn in_file(path: &std::path::Path, e: Error) -> Error {
    match e {
        Error::Collision { .. } | Error::Parameter { .. } | Error::Unreachable(_) => {
            Error::format(path, e.to_string())
        }
        other => other,
    }
}

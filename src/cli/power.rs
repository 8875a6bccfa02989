//! `formation power SHAPE [--json]`: e_i, ξ_i and E of a shape (docs/formats.md).

use std::path::PathBuf;

use clap::Args;
use formation::{aero, Error, Result, Shape};
use serde::Serialize;

use super::wake::{ModelArg, WakeArg};
use super::Global;

/// Arguments of `formation power`.
#[derive(Debug, Args)]
pub struct PowerArgs {
    /// Shape file: {"birds": [{"x": .., "y": ..}, ...]} in the formation frame, wingspans.
    pub shape: PathBuf,
    /// Print JSON ({"total": E, "flock_saving": E/N, "flock_saving_total", "flight": {..},
    /// "birds": [{"x","y","e","xi","saving","saving_total"}]}) instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Vortex core radius of Hummel's model, wingspans (docs/model.md).
    #[arg(long, allow_negative_numbers = true, default_value_t = formation::aero::AeroOptions::default().core_radius)]
    pub core_radius: f64,
    /// Wake model: planar (Hummel's, heights ignored) or 3d (uses each bird's "z", wingspans,
    /// up; docs/model.md).
    #[arg(long, value_enum, default_value_t = WakeArg::Planar)]
    pub wake: WakeArg,
    /// With --wake 3d: slope at which the trailing vortices sink behind each bird, wingspans per
    /// wingspan (0 = level; about 0.01 for a goose; docs/model.md).
    #[arg(
        long,
        value_name = "SLOPE",
        allow_negative_numbers = true,
        default_value_t = 0.0
    )]
    pub wake_descent: f64,
    /// Model of the savings: hummel (Hummel's horseshoes with a vortex core) or lissaman
    /// (elliptically loaded lifting lines, the kind Hainsworth and Cutts & Speakman used; no
    /// core); docs/model.md.
    #[arg(long = "aero-model", value_enum, value_name = "MODEL", default_value_t = ModelArg::Hummel)]
    pub aero_model: ModelArg,
    #[command(flatten)]
    pub flight: FlightArgs,
}

/// The bird whose power curve turns savings of induced power into savings of total power.
#[derive(Debug, Args, Clone)]
pub struct FlightArgs {
    /// Species whose size and cruise airspeed set the power curve: a real species
    /// (barnacle-goose, greylag-goose, canada-goose, white-fronted-goose, pink-footed-goose,
    /// common-crane, white-pelican, northern-bald-ibis; docs/species.md) or a family's typical
    /// bird (goose, crane or pelican; docs/model.md).
    #[arg(long, value_name = "NAME", default_value = "goose")]
    pub species: String,
    /// Body mass, kg (default: the species' typical mass, scaled to --wingspan-m).
    #[arg(long = "mass-kg", value_name = "KG", allow_negative_numbers = true)]
    pub mass_kg: Option<f64>,
    /// Airspeed, m/s (default: a real species' cruise airspeed, a family's minimum-power speed).
    #[arg(long = "speed-ms", value_name = "M/S", allow_negative_numbers = true)]
    pub speed_ms: Option<f64>,
    /// Wingspan, m (default: the species' typical span).
    #[arg(long = "wingspan-m", value_name = "M", allow_negative_numbers = true)]
    pub wingspan_m: Option<f64>,
}

/// The power curve and airspeed the flags give.
pub struct Flight {
    /// The name given: a real species or the family.
    pub name: &'static str,
    pub curve: aero::flight::PowerCurve,
    pub speed_ms: f64,
}

impl Flight {
    /// Share of total power that is induced power at the airspeed.
    pub fn induced_share(&self) -> f64 {
        self.curve.induced_share(self.speed_ms)
    }
}

impl FlightArgs {
    /// Checks the flags and builds the curve; errors name the flag.
    pub fn flight(&self) -> Result<Flight> {
        let species: formation::animation::wing::Species = self
            .species
            .parse()
            .map_err(|e: Error| reflag(e, "--species"))?;
        let real = aero::species::lookup(&self.species);
        let preset = real.map_or(aero::flight::Morphology::of(species), |b| b.morphology());
        let mut bird = match self.wingspan_m {
            Some(b) => {
                let least = formation::limits::MIN_WINGSPAN_M;
                if !(b.is_finite() && b >= least && b <= 100.0) {
                    return Err(Error::parameter(
                        "--wingspan-m",
                        format!("{b}: must be in [{least}, 100] metres"),
                    ));
                }
                preset.scaled_to(b)
            }
            None => preset,
        };
        if let Some(m) = self.mass_kg {
            bird.mass_kg = m;
        }
        bird.validate().map_err(|e| reflag(e, "--mass-kg"))?;
        let curve = aero::flight::PowerCurve::new(bird);
        let speed_ms = match self.speed_ms {
            Some(v) => {
                aero::flight::validate_speed(v).map_err(|e| reflag(e, "--speed-ms"))?;
                v
            }
            None => real.map_or(curve.minimum_power_speed(), |b| b.cruise_ms),
        };
        Ok(Flight {
            name: real.map_or(species.name(), |b| b.name),
            curve,
            speed_ms,
        })
    }
}

/// Renames a parameter error to the flag it came from.
fn reflag(e: Error, flag: &str) -> Error {
    match e {
        Error::Parameter { message, .. } => Error::parameter(flag, message),
        other => other,
    }
}

/// Core radii the saving's sensitivity is shown over, wingspans: from a tight core to one of a
/// third of the vortex span.
const CORES: [f64; 5] = [0.02, 0.04, 0.08, 0.16, 0.32];

#[derive(Serialize)]
struct CoreJson {
    core_radius: f64,
    flock_saving: f64,
    flock_saving_total: f64,
}

/// One entry of the band over models, wakes and cores.
#[derive(Serialize)]
struct BandJson {
    model: &'static str,
    wake: &'static str,
    /// Absent for the lifting-line model, which has no core.
    #[serde(skip_serializing_if = "Option::is_none")]
    core_radius: Option<f64>,
    flock_saving: f64,
    flock_saving_total: f64,
}

/// The model that gave the main numbers.
#[derive(Serialize)]
struct ModelJson {
    name: &'static str,
    wake: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    core_radius: Option<f64>,
}

#[derive(Serialize)]
struct FlightJson {
    species: String,
    mass_kg: f64,
    wingspan_m: f64,
    wing_area_m2: f64,
    speed_ms: f64,
    induced_share: f64,
    method: &'static str,
}

/// The flock saving's lowest and highest over the band (and the chosen model), fractions of
/// induced and of total power.
#[derive(Serialize)]
struct RangeJson {
    induced: [f64; 2],
    total: [f64; 2],
}

#[derive(Serialize)]
struct PowerJson {
    total: f64,
    saving_range: RangeJson,
    flock_saving: f64,
    flock_saving_total: f64,
    model: ModelJson,
    flight: FlightJson,
    sensitivity: Vec<CoreJson>,
    band: Vec<BandJson>,
    birds: Vec<BirdJson>,
}

#[derive(Serialize)]
struct BirdJson {
    x: f64,
    y: f64,
    #[serde(skip_serializing_if = "is_zero")]
    z: f64,
    e: f64,
    xi: f64,
    saving: f64,
    saving_total: f64,
}

/// True for 0: a height left out of the JSON (planar shapes print as before).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
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
    let (x, y, z) = (shape.xs(), shape.ys(), shape.zs());
    let flight = args.flight.flight()?;
    let share = flight.induced_share();
    let model = aero::AeroOptions {
        core_radius: args.core_radius,
        wake: args.wake.into(),
        wake_descent: args.wake_descent,
        model: args.aero_model.into(),
        ..aero::AeroOptions::default()
    };
    model.validate().map_err(|e| match e {
        Error::Parameter { name, message } if name == "aero.wake_descent" => Error::parameter(
            "--wake-descent",
            message.replace("the wake \"3d\"", "--wake 3d"),
        ),
        Error::Parameter { message, .. } => Error::parameter("--core-radius", message),
        other => other,
    })?;
    let pr = model
        .power_reduction_3d(&x, &y, &z)
        .map_err(|e| in_file(&args.shape, e))?;
    let flock_saving = pr.total / shape.len() as f64;
    // How much the number depends on the core radius (the model's one free length).
    // (The lifting-line model has no core: no entries.)
    let cores: &[f64] = if model.model.is_hummel() { &CORES } else { &[] };
    let sensitivity: Vec<CoreJson> = cores
        .iter()
        .filter_map(|&c| {
            let m = aero::AeroOptions {
                core_radius: c,
                ..model
            };
            let p = m.power_reduction_3d(&x, &y, &z).ok()?;
            let f = p.total / shape.len() as f64;
            Some(CoreJson {
                core_radius: c,
                flock_saving: f,
                flock_saving_total: f * share,
            })
        })
        .collect();
    // The band over both models, both wakes and (Hummel's) cores: how much the number depends
    // on modelling choices no measurement fixes.
    let mut band: Vec<BandJson> = Vec::new();
    for m in [aero::AeroModel::Hummel, aero::AeroModel::Lissaman] {
        for w in [aero::Wake::Planar, aero::Wake::ThreeD] {
            let cores: &[f64] = if m.is_hummel() { &CORES } else { &[0.0] };
            for &c in cores {
                let o = aero::AeroOptions {
                    core_radius: if m.is_hummel() { c } else { model.core_radius },
                    wake: w,
                    wake_descent: if w == aero::Wake::ThreeD {
                        model.wake_descent
                    } else {
                        0.0
                    },
                    model: m,
                    ..model
                };
                let Ok(p) = o.power_reduction_3d(&x, &y, &z) else {
                    continue;
                };
                let f = p.total / shape.len() as f64;
                band.push(BandJson {
                    model: m.name(),
                    wake: w.name(),
                    core_radius: m.is_hummel().then_some(c),
                    flock_saving: f,
                    flock_saving_total: f * share,
                });
            }
        }
    }
    let core_used = model.model.is_hummel().then_some(model.core_radius);
    // The range leads: the band's lowest and highest, the chosen model's value included.
    let (lo, hi) = band
        .iter()
        .map(|b| b.flock_saving)
        .fold((flock_saving, flock_saving), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    let mut out = String::new();
    if args.json {
        let doc = PowerJson {
            total: pr.total,
            saving_range: RangeJson {
                induced: [lo, hi],
                total: [lo * share, hi * share],
            },
            flock_saving,
            flock_saving_total: flock_saving * share,
            model: ModelJson {
                name: model.model.name(),
                wake: model.wake.name(),
                core_radius: core_used,
            },
            flight: FlightJson {
                species: flight.name.to_string(),
                mass_kg: flight.curve.bird.mass_kg,
                wingspan_m: flight.curve.bird.span_m,
                wing_area_m2: flight.curve.bird.wing_area_m2,
                speed_ms: flight.speed_ms,
                induced_share: share,
                method: "Pennycuick 2008",
            },
            sensitivity,
            band,
            birds: shape
                .birds
                .iter()
                .zip(pr.e.iter().zip(&pr.xi))
                .map(|(b, (&e, &xi))| BirdJson {
                    x: b.x,
                    y: b.y,
                    z: b.z,
                    e,
                    xi,
                    saving: e,
                    saving_total: e * share,
                })
                .collect(),
        };
        out = formation::finite::to_json_pretty("power", &doc)?;
        out.push('\n');
    } else {
        let leader = shape.leader().unwrap_or(0);
        out.push_str(&format!(
            "{}\n",
            super::savings::range_line(lo, hi, share, flock_saving, &super::savings::label(&model))
        ));
        out.push_str(&format!(
            "{:>5} {:>10} {:>10} {:>9} {:>9} {:>9}\n",
            "bird", "x", "y", "induced", "total", "xi"
        ));
        for (i, b) in shape.birds.iter().enumerate() {
            out.push_str(&format!(
                "{:>5} {:>10.4} {:>10.4} {:>8.2}% {:>8.2}% {:>9.5}{}\n",
                i,
                b.x,
                b.y,
                100.0 * pr.e[i],
                100.0 * pr.e[i] * share,
                pr.xi[i],
                if i == leader {
                    "  leader"
                } else if pr.e[i] > 1.0 {
                    "  e > 1"
                } else {
                    ""
                }
            ));
        }
        if pr.e.iter().any(|&e| e > 1.0) {
            out.push_str(super::savings::E_ABOVE_ONE);
            out.push('\n');
        }
        out.push_str(&format!(
            "flock saving {:.2}% of induced power, {:.2}% of total power (mean over {} birds; E = {:.6})\n",
            100.0 * flock_saving,
            100.0 * flock_saving * share,
            shape.len(),
            pr.total
        ));
        if let (Some(lo), Some(hi)) = (
            sensitivity.iter().map(|c| c.flock_saving).reduce(f64::min),
            sensitivity.iter().map(|c| c.flock_saving).reduce(f64::max),
        ) {
            out.push_str(&format!(
                "with a vortex core of {} to {} wingspans: flock saving {:.1} to {:.1}% of induced power ({})\n",
                CORES[0],
                CORES[CORES.len() - 1],
                100.0 * lo,
                100.0 * hi,
                sensitivity
                    .iter()
                    .map(|c| format!("{}: {:.1}%", c.core_radius, 100.0 * c.flock_saving))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if let (Some(lo), Some(hi)) = (
            band.iter().map(|c| c.flock_saving).reduce(f64::min),
            band.iter().map(|c| c.flock_saving).reduce(f64::max),
        ) {
            out.push_str(&format!(
                "over both models (hummel, lissaman), both wakes (planar, 3d) and the cores above: flock saving {:.1} to {:.1}% of induced power, {:.1} to {:.1}% of total power\n",
                100.0 * lo,
                100.0 * hi,
                100.0 * lo * share,
                100.0 * hi * share
            ));
        }
        let bird = &flight.curve.bird;
        out.push_str(&format!(
            "model: {}{}, {}; power curve after Pennycuick (2008) for a {} of {:.2} kg, {:.2} m span at {:.1} m/s: induced power is {:.0}% of the total\n",
            model.model.describe(),
            match model.wake {
                aero::Wake::Planar => String::new(),
                aero::Wake::ThreeD if model.wake_descent == 0.0 => {
                    " in 3-D (each bird's height z)".to_string()
                }
                aero::Wake::ThreeD => format!(
                    " in 3-D (each bird's height z; trailing vortices sinking {} wingspans per wingspan)",
                    model.wake_descent
                ),
            },
            match core_used {
                Some(c) => format!("core {c} wingspans"),
                None => "no core (a continuous vortex sheet; --core-radius is not used)".into(),
            },
            flight.name,
            bird.mass_kg,
            bird.span_m,
            flight.speed_ms,
            100.0 * share
        ));
        out.push_str(
            "induced = e, the share of a bird's solo induced power (the power that holds it up) that the\n\
             others save it (negative: it flies in downwash); total = e × induced share, the share of its\n\
             mechanical power; model estimates, not measurements; x, y in wingspans, y behind the leader\n",
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

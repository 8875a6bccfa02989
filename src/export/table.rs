//! CSV export in the long format of docs/formats.md §4.4, one row per frame and bird: first
//! exactly the ten fixed columns `frame,t,bird,x,y,z,heading,speed,e,xi` (world frame,
//! wingspans, radians, wingspans per second, seconds), then the analysis columns (never
//! renamed, only added to):
//!
//! | column | meaning |
//! |---|---|
//! | `stage` | the stage the frame belongs to (`initiation`, `steady`, another stage's name, or `none`) |
//! | `formation` | index of the bird's formation (0 for a flock of one formation) |
//! | `rank` | place in its formation from the front at this frame, 0 = the leader |
//! | `leader` | 1 for the formation's leader, else 0 |
//! | `lateral`, `behind` | formation frame relative to the leader's heading, wingspans |
//! | `wing_phase` | radians in [0, 2π), 0 = start of the downstroke |
//! | `bank` | radians, right wing down positive (0 when the file carries none: level) |
//! | `saving_total` | `e` as a fraction of the bird's total mechanical power: `e` × the induced share of its power curve at its airspeed (empty where `e` is) |
//! | `qx`, `qy`, `qz`, `qw` | the bird's orientation as a unit quaternion (heading, pitch and bank; [`axes::orientation`]) |
//! | `pitch` | radians, nose up positive (0 when the file carries none) |
//!
//! `render.units` (`wingspans` or `m`) and `render.up` (`z` or `y`, see [`axes`]) set the units
//! of `x`, `y`, `z`, `speed`, `lateral` and `behind` and the axes of `x`, `y`, `z` and of the
//! quaternion, for tools that want metres and Y up (Houdini, Unreal).
//!
//! `e` (the saving), `xi` and `wing_phase` are numbers in every frame of a file written by this
//! tool; they are empty only for a hand-made animation file without them. Numbers use the
//! shortest decimal of the value rounded to the precision the animation file stores it at
//! (positions, lengths and speeds to 10⁻⁵, angles, quaternion components and savings to 10⁻⁶,
//! times to 10⁻⁶ s): no float noise and no `-0`. `docs/formats.md` documents every column.

use std::io::Write;

use crate::animation::axes::{self, Units, Up};
use crate::animation::precision::{ANGLE, POSITION, SAVING, SPEED};
use crate::animation::Animation;

/// Steps per second of the `t` column: frame times are written to the microsecond.
const TIME: f64 = 1e6;

/// The header line, without newline.
pub const CSV_HEADER: &str =
    "frame,t,bird,x,y,z,heading,speed,e,xi,stage,formation,rank,leader,lateral,behind,wing_phase,bank,saving_total,qx,qy,qz,qw,pitch";

/// A number as a CSV cell, rounded to `1 / steps` (`steps` a power of ten, the precision the
/// animation file stores such a value at, [`precision`]) and written as the shortest decimal of
/// the rounded value: no float noise (`0.10500000000000001`), no `-0`, no exponent.
#[derive(Clone, Copy)]
struct Num(f64, f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write_decimal(f, self.0, self.1)
    }
}

/// Writes `x` rounded to `1 / steps` (`steps` = 10^d, d ≤ 9) as a plain decimal with trailing
/// zeros dropped: the text reads back to exactly [`crate::animation::precision::to`]`(x, steps)`. Values too
/// large to round that way (and non-finite ones, refused before any output is written) are
/// written as Rust's shortest round-trip form; zero of either sign as `0`.
pub fn write_decimal<W: std::fmt::Write + ?Sized>(
    f: &mut W,
    x: f64,
    steps: f64,
) -> std::fmt::Result {
    let digits = steps.log10().round().clamp(0.0, 9.0) as u32;
    let scale = 10u64.pow(digits);
    let n = (x * scale as f64).round();
    if !(n.is_finite() && n.abs() < 9e15) {
        return if x == 0.0 {
            f.write_str("0")
        } else {
            write!(f, "{x}")
        };
    }
    let n = n as i64;
    if n == 0 {
        return f.write_str("0");
    }
    let sign = if n < 0 { "-" } else { "" };
    let (int, mut frac, mut width) = (n.unsigned_abs() / scale, n.unsigned_abs() % scale, digits);
    if frac == 0 {
        return write!(f, "{sign}{int}");
    }
    while frac % 10 == 0 {
        frac /= 10;
        width -= 1;
    }
    write!(f, "{sign}{int}.{frac:0width$}", width = width as usize)
}

/// An optional number as a CSV cell: [`Num`], or nothing (written without a `String`).
struct Cell(Option<f64>, f64);

impl std::fmt::Display for Cell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(x) => write_decimal(f, x, self.1),
            None => Ok(()),
        }
    }
}

/// The stage word of every frame (`none` outside every stage).
fn stage_words(anim: &Animation) -> Vec<&str> {
    let mut w = vec!["none"; anim.frames.len()];
    for s in &anim.stages {
        for k in s.start..s.end.min(w.len()) {
            w[k] = s.name.as_str();
        }
    }
    w
}

/// Writes the CSV text of `anim` to `w` (wingspans, `z` up).
pub fn write_csv<W: Write>(anim: &Animation, w: &mut W) -> std::io::Result<()> {
    write_csv_in(anim, Units::Wingspans, Up::Z, anim.wingspan_m, w)
}

/// Writes the CSV text of `anim` to `w` in `units` (metres: birds `wingspan_m` wide) on the
/// `up` axes.
pub fn write_csv_in<W: Write>(
    anim: &Animation,
    units: Units,
    up: Up,
    wingspan_m: f64,
    w: &mut W,
) -> std::io::Result<()> {
    writeln!(w, "{CSV_HEADER}")?;
    let stages = stage_words(anim);
    let of = anim.formation_of_birds();
    let leaders = anim.leaders();
    let curve = crate::aero::flight::curve_of(anim);
    let scale = match units {
        Units::Wingspans => 1.0,
        Units::M => wingspan_m,
    };
    for (k, f) in anim.frames.iter().enumerate() {
        let rel = anim.relative_with(k, &of, &leaders);
        for (b, r) in rel.iter().enumerate() {
            let v = |a: &Vec<f64>| a.get(b).copied().unwrap_or(f64::NAN);
            let o = |a: &Option<Vec<f64>>, steps: f64| {
                Cell(a.as_ref().and_then(|a| a.get(b)).copied(), steps)
            };
            let or0 =
                |a: &Option<Vec<f64>>| a.as_ref().and_then(|a| a.get(b)).copied().unwrap_or(0.0);
            let bank = or0(&f.bank);
            let pitch = or0(&f.pitch);
            let total = Cell(
                f.e.as_ref().and_then(|a| a.get(b)).map(|e| {
                    let v = anim.flight.and_then(|f| f.speed_ms).unwrap_or_else(|| {
                        crate::aero::flight::airspeed_ms(&curve, v(&f.speed), anim.wingspan_m)
                    });
                    e * curve.induced_share(v)
                }),
                SAVING,
            );
            let p = up
                .from_world([v(&f.x), v(&f.y), v(&f.z)])
                .map(|c| c * scale);
            let q = axes::orientation(up, v(&f.heading), pitch, bank);
            writeln!(
                w,
                "{},{},{b},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{total},{},{},{},{},{}",
                anim.start_frame + k as u64,
                Num(f.t, TIME),
                Num(p[0], POSITION),
                Num(p[1], POSITION),
                Num(p[2], POSITION),
                Num(v(&f.heading), ANGLE),
                Num(v(&f.speed) * scale, SPEED),
                o(&f.e, SAVING),
                o(&f.xi, SAVING),
                stages[k],
                r.formation,
                r.rank,
                u8::from(r.leader),
                Num(r.lateral * scale, POSITION),
                Num(r.behind * scale, POSITION),
                o(&f.wing_phase, ANGLE),
                Num(bank, ANGLE),
                Num(q[0], ANGLE),
                Num(q[1], ANGLE),
                Num(q[2], ANGLE),
                Num(q[3], ANGLE),
                Num(pitch, ANGLE),
            )?;
        }
    }
    Ok(())
}

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
//!
//! `e` (the saving), `xi` and `wing_phase` are numbers in every frame of a file written by this
//! tool; they are empty only for a hand-made animation file without them. Numbers use the
//! shortest text that reads back to the same `f64`. `docs/formats.md` documents every column.

use std::io::Write;

use crate::animation::Animation;

/// The header line, without newline.
pub const CSV_HEADER: &str =
    "frame,t,bird,x,y,z,heading,speed,e,xi,stage,formation,rank,leader,lateral,behind,wing_phase,bank,saving_total";

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

/// Writes the CSV text of `anim` to `w`.
pub fn write_csv<W: Write>(anim: &Animation, w: &mut W) -> std::io::Result<()> {
    writeln!(w, "{CSV_HEADER}")?;
    let stages = stage_words(anim);
    let of = anim.formation_of_birds();
    let leaders = anim.leaders();
    let curve = crate::aero::flight::curve_of(anim);
    for (k, f) in anim.frames.iter().enumerate() {
        let rel = anim.relative_with(k, &of, &leaders);
        for (b, r) in rel.iter().enumerate() {
            let v = |a: &Vec<f64>| a.get(b).copied().unwrap_or(f64::NAN);
            let o = |a: &Option<Vec<f64>>| match a.as_ref().and_then(|a| a.get(b)) {
                Some(x) => format!("{x}"),
                None => String::new(),
            };
            let bank = f
                .bank
                .as_ref()
                .and_then(|a| a.get(b))
                .copied()
                .unwrap_or(0.0);
            let total = match f.e.as_ref().and_then(|a| a.get(b)) {
                Some(e) => {
                    let v = anim.flight.and_then(|f| f.speed_ms).unwrap_or_else(|| {
                        crate::aero::flight::airspeed_ms(&curve, v(&f.speed), anim.wingspan_m)
                    });
                    format!("{}", e * curve.induced_share(v))
                }
                None => String::new(),
            };
            writeln!(
                w,
                "{k},{},{b},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{bank},{total}",
                f.t,
                v(&f.x),
                v(&f.y),
                v(&f.z),
                v(&f.heading),
                v(&f.speed),
                o(&f.e),
                o(&f.xi),
                stages[k],
                r.formation,
                r.rank,
                u8::from(r.leader),
                r.lateral,
                r.behind,
                o(&f.wing_phase),
            )?;
        }
    }
    Ok(())
}

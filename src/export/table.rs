//! CSV export in SPEC §4.4's long format, one row per frame and bird, exactly the SPEC's columns
//! `frame,t,bird,x,y,z,heading,speed,e,xi` (world frame, wingspans, radians, wingspans per
//! second, seconds). `e` (the saving) and `xi` are numbers in every frame of a file written by this tool (the take-off included; empty only for a hand-made animation file without them).
//! Numbers use the shortest text that reads back to the same `f64`. The wing phases are in the
//! JSON animation file and drive the glTF wing nodes.

use std::io::Write;

use crate::animation::Animation;

/// The header line, without newline.
pub const CSV_HEADER: &str = "frame,t,bird,x,y,z,heading,speed,e,xi";

/// Writes the CSV text of `anim` to `w`.
pub fn write_csv<W: Write>(anim: &Animation, w: &mut W) -> std::io::Result<()> {
    writeln!(w, "{CSV_HEADER}")?;
    for (k, f) in anim.frames.iter().enumerate() {
        for b in 0..anim.birds {
            let v = |a: &Vec<f64>| a.get(b).copied().unwrap_or(f64::NAN);
            let o = |a: &Option<Vec<f64>>| match a.as_ref().and_then(|a| a.get(b)) {
                Some(x) => format!("{x}"),
                None => String::new(),
            };
            writeln!(
                w,
                "{k},{},{b},{},{},{},{},{},{},{}",
                f.t,
                v(&f.x),
                v(&f.y),
                v(&f.z),
                v(&f.heading),
                v(&f.speed),
                o(&f.e),
                o(&f.xi)
            )?;
        }
    }
    Ok(())
}

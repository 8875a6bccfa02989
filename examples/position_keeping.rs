//! Position keeping of a steady flight (the figures of docs/jostle.md): the 0.5 s and 3 s moves
//! and per-bird spread, lateral and fore-aft, as `extract` measures footage; the closest two
//! birds and the largest acceleration of any bird.
//!
//! `cargo run --release --example position_keeping -- steady.json [FROM_SECONDS]`

use formation::animation::Animation;
use formation::keyshape::jostle::measure_animation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: position_keeping ANIMATION.json [FROM_SECONDS]")?;
    let from: f64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(0.0);
    let anim = Animation::read(std::path::Path::new(&path))?;
    let (lat, fa) = measure_animation(&anim, from).ok_or("the flight is too short")?;
    for (name, a) in [("lateral", lat), ("fore-aft", fa)] {
        println!(
            "{name}: move 0.5 s median {:.4} p90 {:.4}, 3 s median {}, spread {:.4}, time scale {:.3} s",
            a.move_median,
            a.move_p90,
            a.move_long_median.map_or("-".into(), |m| format!("{m:.4}")),
            a.spread,
            a.time_scale
        );
    }
    let mut closest = f64::INFINITY;
    for f in &anim.frames {
        for i in 0..f.x.len() {
            for j in i + 1..f.x.len() {
                closest = closest.min((f.x[i] - f.x[j]).hypot(f.y[i] - f.y[j]));
            }
        }
    }
    let mut accel: f64 = 0.0;
    for w in anim.frames.windows(3) {
        let h = w[1].t - w[0].t;
        for i in 0..w[0].x.len() {
            let ax = (w[2].x[i] - 2.0 * w[1].x[i] + w[0].x[i]) / (h * h);
            let ay = (w[2].y[i] - 2.0 * w[1].y[i] + w[0].y[i]) / (h * h);
            accel = accel.max(ax.hypot(ay));
        }
    }
    println!("closest pair {closest:.3} wingspans; largest acceleration {accel:.3} wingspans/s²");
    Ok(())
}

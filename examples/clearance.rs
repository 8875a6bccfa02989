//! Counts wing and body clashes per stage of an animation file (the clearance test of
//! `docs/formats.md`): `cargo run --release --example clearance -- ANIMATION.json`.
use formation::animation::clearance::Clearance;
use formation::animation::Animation;

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: clearance ANIMATION.json");
    let anim = Animation::read(std::path::Path::new(&path)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let mut all = Clearance::default();
    for (name, c) in Clearance::by_stage(&anim) {
        println!(
            "{name}: {} frames, {} wing, {} body clashes in {} frames; closest {}",
            c.frames,
            c.wing,
            c.body,
            c.frames_with_clash,
            c.closest.map_or("-".into(), |c| format!(
                "{:.3} (frame {}, birds {} and {})",
                c.distance, c.frame, c.birds.0, c.birds.1
            ))
        );
        all.add(&c);
    }
    println!("all: {} wing, {} body", all.wing, all.body);
    std::process::exit(i32::from(all.clashes() > 0));
}

//! One frame of reference: recomputing an animation's savings with the model it was made with
//! (what `power`, `report` and `plot` do with `--wake`, `--core-radius` or the band) reproduces
//! the values the steady flight stored, in the course frame, with position keeping on (the
//! leader's heading wanders; the course does not).

use formation::aero::{recompute_frame_savings, AeroOptions, Wake};
use formation::extract::params::FormationParams;
use formation::keyshape::{steady_flight_report, SteadyOptions};
use formation::progress::Silent;
use formation::rng::seeded;

fn params() -> FormationParams {
    let p =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/steady_v9_params.json");
    FormationParams::read(&p).unwrap()
}

#[test]
fn recomputed_savings_reproduce_the_stored_ones_in_the_course_frame() {
    for wake in [Wake::Planar, Wake::ThreeD] {
        let aero = AeroOptions {
            wake,
            ..AeroOptions::default()
        };
        let opts = SteadyOptions {
            birds: 9,
            frames: 60,
            seed: 7,
            aero,
            ..SteadyOptions::default()
        };
        let (anim, _) = steady_flight_report(&params(), &opts, &mut seeded(7), &Silent).unwrap();
        // Position keeping turns the leader: its heading is not the course's.
        let turn = anim
            .frames
            .iter()
            .flat_map(|f| f.heading.iter())
            .fold(0.0f64, |m, h| m.max(h.abs()));
        assert!(turn > 1e-4, "{turn}");
        let mut again = anim.clone();
        recompute_frame_savings(&mut again, &aero);
        let mut worst = 0.0f64;
        for (a, b) in anim.frames.iter().zip(&again.frames) {
            for (x, y) in a.e.as_ref().unwrap().iter().zip(b.e.as_ref().unwrap()) {
                worst = worst.max((x - y).abs());
            }
        }
        assert!(worst < 1e-9, "{wake:?}: {worst}");
    }
}

//! Measures how far an animated GIF strays from the PNG frames of the same film
//! ([`formation::export::fidelity`]): `cargo run --release --example gif_error -- flock.gif
//! frames/ [EVERY]` renders nothing itself; write the two with
//! `formation render A.json -o flock.gif -o frames/`. Prints the low-frequency error and the
//! seam of every EVERY-th frame (default 25) that is worse than 1 level, then the worst.
use formation::export::fidelity::{decode_gif, frame_error, FrameError};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: gif_error FLOCK.gif FRAMES_DIR [EVERY]");
        std::process::exit(2);
    }
    let every: usize = args
        .get(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(25)
        .max(1);
    let dir = std::path::PathBuf::from(&args[1]);
    let mut worst = FrameError::default();
    let mut worst_at = (0, 0);
    let file = std::fs::File::open(&args[0]).expect("the GIF");
    let (_, _, n) = decode_gif(std::io::BufReader::new(file), |k, shown, w| {
        if k % every != 0 {
            return Ok(());
        }
        let png = dir.join(formation::export::pictures::frame_name(k));
        let truth = image::open(&png)
            .unwrap_or_else(|e| panic!("{}: {e}", png.display()))
            .to_rgba8();
        let e = frame_error(shown, truth.as_raw(), w);
        if e.low_frequency > 1.0 || e.seam > 1.0 {
            println!(
                "frame {k}: low-frequency {:.2}, seam {:.2}",
                e.low_frequency, e.seam
            );
        }
        if e.low_frequency > worst.low_frequency {
            worst_at.0 = k;
        }
        if e.seam > worst.seam {
            worst_at.1 = k;
        }
        worst = worst.max(e);
        Ok(())
    })
    .expect("a GIF");
    println!(
        "{n} frames, every {every}th compared: worst low-frequency error {:.2} levels (frame {}), worst seam {:.2} (frame {})",
        worst.low_frequency, worst_at.0, worst.seam, worst_at.1
    );
}

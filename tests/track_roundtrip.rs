//! Footage in, on a round trip: flocks drawn by formation's own renderer (sky, clouds, sun, the
//! three species, birds from 8 to 60 px across, noise and blur) are tracked, and the tracks are
//! compared with the animation that drew them: detection precision and recall, centroid error in
//! wingspans, id switches, the measured wingspan and heading, and `extract`'s shape on the tracked
//! points against the true ones.

mod track_support;

use formation::track::{Polarity, TrackOptions, Tracked, Tracking};
use track_support::{fixed, shoot, v_flock, Shot};

fn track(shot: &Shot, opts: &TrackOptions) -> Tracked {
    let mut t = Tracking::new(opts).unwrap();
    for (k, g) in shot.frames.iter().enumerate() {
        t.push(k, None, g, std::path::Path::new("shot")).unwrap();
    }
    t.finish("shot", Some(25.0)).unwrap()
}

#[derive(Debug, Default)]
struct Score {
    truths: usize,
    found: usize,
    detections: usize,
    sq_err_ws: f64,
    switches: usize,
    worst_span: f64,
    worst_heading: f64,
    along: f64,
    across: f64,
}

fn score(shot: &Shot, tr: &Tracked) -> Score {
    let mut s = Score::default();
    let mut last_id: Vec<Option<usize>> = vec![None; shot.truth[0].len()];
    for (k, f) in tr.frames.iter().enumerate() {
        let truth = &shot.truth[k];
        let ws = shot.span[k];
        s.truths += truth.len();
        s.detections += f.birds.len();
        let cost = |i: usize, j: usize| {
            let (b, t) = (&f.birds[j], truth[i]);
            (b.x - t.0).powi(2) + (b.y - t.1).powi(2)
        };
        if f.birds.len() >= truth.len() {
            let a = formation::annotations::hungarian(truth.len(), f.birds.len(), cost);
            for (i, &j) in a.iter().enumerate() {
                let d2 = cost(i, j);
                if d2.sqrt() <= 0.5 * ws {
                    let hh = shot.heading.to_radians();
                    let (ex, ey) = (f.birds[j].x - truth[i].0, f.birds[j].y - truth[i].1);
                    s.along += (ex * hh.sin() - ey * hh.cos()) / ws;
                    s.across += (ex * hh.cos() + ey * hh.sin()) / ws;
                    s.found += 1;
                    s.sq_err_ws += d2 / (ws * ws);
                    let id = f.birds[j].id;
                    if last_id[i].is_some_and(|l| l != id) {
                        s.switches += 1;
                    }
                    last_id[i] = Some(id);
                }
            }
        } else {
            let a =
                formation::annotations::hungarian(f.birds.len(), truth.len(), |j, i| cost(i, j));
            for (j, &i) in a.iter().enumerate() {
                let d2 = cost(i, j);
                if d2.sqrt() <= 0.5 * ws {
                    let hh = shot.heading.to_radians();
                    let (ex, ey) = (f.birds[j].x - truth[i].0, f.birds[j].y - truth[i].1);
                    s.along += (ex * hh.sin() - ey * hh.cos()) / ws;
                    s.across += (ex * hh.cos() + ey * hh.sin()) / ws;
                    s.found += 1;
                    s.sq_err_ws += d2 / (ws * ws);
                    let id = f.birds[j].id;
                    if last_id[i].is_some_and(|l| l != id) {
                        s.switches += 1;
                    }
                    last_id[i] = Some(id);
                }
            }
        }
        if (f.wingspan_px / ws - 1.0).abs() > s.worst_span.abs() {
            s.worst_span = f.wingspan_px / ws - 1.0;
        }
        let dh = ((f.heading_deg - shot.heading + 540.0) % 360.0 - 180.0).abs();
        s.worst_heading = s.worst_heading.max(dh);
    }
    s
}

fn check(name: &str, s: &Score) {
    let recall = s.found as f64 / s.truths as f64;
    let precision = s.found as f64 / s.detections as f64;
    let rms = (s.sq_err_ws / s.found as f64).sqrt();
    let switches = s.switches as f64 * 100.0 / s.truths as f64;
    eprintln!(
        "{name}: recall {recall:.4} precision {precision:.4} rms {rms:.4} ws, switches {switches:.2}/100, span {:.3}, heading {:.2} deg",
        s.worst_span, s.worst_heading
    );
    assert!(recall >= 0.98, "{name}: recall {recall}");
    assert!(precision >= 0.98, "{name}: precision {precision}");
    // The silhouette's centre of mass lies a little behind the point the renderer places the
    // bird at (0.02-0.05 wingspans, by species); a shift common to all birds moves no distance
    // between them, so the error about it is bounded tighter too.
    let (ma, mc) = (s.along / s.found as f64, s.across / s.found as f64);
    let spread = (rms * rms - ma * ma - mc * mc).max(0.0).sqrt();
    eprintln!(
        "{name}: common shift along {ma:.4} across {mc:.4}, RMS about it {spread:.4} wingspans"
    );
    assert!(
        spread <= 0.03,
        "{name}: centroid RMS about the common shift {spread} wingspans"
    );
    assert!(rms <= 0.05, "{name}: centroid RMS {rms} wingspans");
    assert!(
        switches <= 1.0,
        "{name}: {switches} id switches per 100 bird-frames"
    );
    assert!(
        s.worst_span.abs() <= 0.10,
        "{name}: wingspan off by {}",
        s.worst_span
    );
    assert!(
        s.worst_heading <= 5.0,
        "{name}: heading off by {} deg",
        s.worst_heading
    );
}

#[test]
fn flocks_of_every_species_and_size_are_tracked() {
    // (species, pixels per wingspan, heading, birds, noise σ)
    let cases = [
        ("goose", 12.0, 70.0, 9, 3.0),
        ("crane", 20.0, 30.0, 7, 4.0),
        ("pelican", 30.0, 300.0, 7, 3.0),
        ("goose", 45.0, 95.0, 5, 2.0),
    ];
    for (i, &(species, px, heading, n, noise)) in cases.iter().enumerate() {
        // Long enough to cross a good part of the picture, short enough to stay in it.
        let frames = 24;
        let a = v_flock(n, heading, frames, species, (0.0, 0.0));
        let opts = fixed(&a, px, i % 2 == 0);
        let shot = shoot(&a, &opts, noise);
        if std::env::var_os("FORMATION_TRACK_DUMP").is_some() {
            let g = &shot.frames[frames / 2];
            image::GrayImage::from_raw(g.width as u32, g.height as u32, g.data.clone())
                .unwrap()
                .save(format!("/tmp/track_{species}_{px}.png"))
                .unwrap();
        }
        for t in &shot.truth {
            assert_eq!(t.len(), n, "{species} {px}: every bird in the picture");
        }
        let tr = track(&shot, &TrackOptions::default());
        if std::env::var_os("FORMATION_TRACK_DUMP").is_some() {
            let f = &tr.frames[frames / 2];
            for b in &f.birds {
                eprintln!(
                    "  {:.1},{:.1} area {} span {:.1} snr {:.1}",
                    b.x, b.y, b.blob.area, b.blob.span, b.blob.snr
                );
            }
            eprintln!("  truth {:?}", shot.truth[frames / 2]);
        }
        assert_eq!(tr.polarity, Polarity::Dark);
        check(&format!("{species} {px} px"), &score(&shot, &tr));
    }
}

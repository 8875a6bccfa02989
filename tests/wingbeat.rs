//! Invariants of the wingbeat stage (issue 7): Wu & Popović's g1, g2 and h, the downstroke ratio,
//! C1 blending between wingbeats, seeded determinism, spatial phase locking, accelerating and
//! gliding birds, the renderers' replay of the stored phases, and `formation plot wingbeat`.

mod support;

use support::{bin, scratch};

use std::f64::consts::{PI, TAU};

use formation::animation::{Animation, Frame};
use formation::wingbeat::{
    assign_phases, bird_ahead, g1, g2, pose, probe, AheadIndex, Flapper, Glide, PhaseMap,
    PhaseMode, Species, WingbeatOptions,
};
use proptest::prelude::*;

fn wrap_pi(a: f64) -> f64 {
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// A flock flying north in a V (leader at the front), `speed(t)` wingspans/s, at `fps`.
fn v_flock(birds: usize, seconds: f64, fps: f64, speed: impl Fn(f64) -> f64) -> Animation {
    let mut a = Animation::new(7, fps, 1.6, birds);
    let frames = (seconds * fps) as usize;
    let mut travelled = 0.0;
    for k in 0..frames {
        let t = k as f64 / fps;
        if k > 0 {
            travelled += speed(t) / fps;
        }
        let mut f = Frame {
            t,
            ..Frame::default()
        };
        for i in 0..birds {
            // Bird 0 leads; odd birds on the right arm, even birds on the left.
            let rank = i.div_ceil(2) as f64;
            let side = if i % 2 == 1 { 1.0 } else { -1.0 };
            f.x.push(side * 0.85 * rank);
            f.y.push(travelled - 0.6 * rank);
            f.z.push(0.0);
            f.heading.push(0.0);
            f.speed.push(speed(t));
        }
        a.frames.push(f);
    }
    a
}

fn phases(a: &Animation) -> Vec<Vec<f64>> {
    a.frames
        .iter()
        .map(|f| f.wing_phase.clone().expect("phases assigned"))
        .collect()
}

proptest! {
    #[test]
    fn g1_starts_at_the_upstroke_value_and_reaches_the_downstroke_value_at_pi(
        d in -1.5f64..1.5, u in -1.5f64..1.5,
    ) {
        prop_assert!((g1(d, u, 0.0) - u).abs() < 1e-12);
        prop_assert!((g1(d, u, PI) - d).abs() < 1e-12);
        prop_assert!((g1(d, u, TAU) - u).abs() < 1e-12);
    }

    #[test]
    fn g2_is_held_on_the_downstroke(d in -1.5f64..1.5, u in -1.5f64..1.5, phi in 0.0f64..PI) {
        prop_assert_eq!(g2(d, u, phi), d);
        // ...and moves on the upstroke, peaking at mid-upstroke.
        prop_assert!((g2(d, u, 1.5 * PI) - u).abs() < 1e-12);
    }

    #[test]
    fn h_meets_its_four_conditions_and_is_monotone(u in 0.05f64..0.95) {
        let h = PhaseMap::new(u);
        prop_assert!(h.eval(0.0).abs() < 1e-12);
        prop_assert!((h.eval(TAU * u) - PI).abs() < 1e-9);
        // h(2π) = 2π: the limit from below (h is taken modulo 2π, h(2π) wraps to h(0) = 0).
        prop_assert!((h.eval(TAU - 1e-12) - TAU).abs() < 1e-9);
        let eps = 1e-7;
        let slope0 = (h.eval(eps) - h.eval(0.0)) / eps;
        let slope_end = (h.eval(TAU - 1e-12) - h.eval(TAU - eps)) / (eps - 1e-12);
        prop_assert!((slope0 - 1.0).abs() < 1e-5, "h'(0) = {}", slope0);
        prop_assert!((slope_end - 1.0).abs() < 1e-4, "h'(2π) = {}", slope_end);
        prop_assert!((h.derivative(0.0) - 1.0).abs() < 1e-12);
        let mut prev = -1.0;
        for k in 0..2000 {
            let p = TAU * k as f64 / 2000.0;
            let v = h.eval(p);
            prop_assert!(v > prev, "h not increasing at {}", p);
            prop_assert!(h.derivative(p) > 0.0);
            prev = v;
        }
        // Stroke midpoints at uπ and (1 + u)π (what lets one offset align g2 with g1).
        prop_assert!((h.eval(PI * u) - 0.5 * PI).abs() < 1e-9);
        prop_assert!((h.eval(PI * (1.0 + u)) - 1.5 * PI).abs() < 1e-9);
    }

    #[test]
    fn downstroke_to_upstroke_ratio_is_u_over_one_minus_u(ua in 0.35f64..0.7, ub in 0.35f64..0.7) {
        let mut preset = Species::Goose.preset();
        preset.timing.u_alpha = ua;
        preset.timing.u_beta = ub;
        // The dihedral is highest at φ = 0 and lowest at the end of the downstroke.
        let m = 20_000;
        let (mut kmin, mut vmin) = (0, f64::INFINITY);
        for k in 0..m {
            let v = pose(&preset.strokes, &preset.timing, TAU * k as f64 / m as f64).dihedral;
            if v < vmin {
                (kmin, vmin) = (k, v);
            }
        }
        let down = kmin as f64 / m as f64;
        let ratio = down / (1.0 - down);
        prop_assert!((ratio - ua / (1.0 - ua)).abs() < 2e-3 * (1.0 + ratio), "{} vs {}", ratio, ua / (1.0 - ua));
        // The g2 DOFs are held over a downstroke of fraction u_β, centred on the g1 downstroke.
        let delta = (ua - ub) * PI;
        let held = |phi: f64| pose(&preset.strokes, &preset.timing, phi).sweep;
        let d = preset.strokes.sweep.down;
        for k in 1..100 {
            let phi = delta + TAU * ub * k as f64 / 100.0;
            prop_assert!((held(phi) - d).abs() < 1e-12);
        }
        prop_assert!((held(delta + TAU * ub + 0.2) - d).abs() > 1e-4);
        // Mid-upstroke of g2 (sweep extreme) coincides with the g1 mid-upstroke.
        let mid = (1.0 + ua) * PI;
        prop_assert!((held(mid) - preset.strokes.sweep.up).abs() < 1e-9);
    }
}

#[test]
fn blending_is_continuous_in_value_and_slope_and_confined_to_mid_upstroke() {
    let amps = [1.0, 1.5, 0.6, 1.2];
    let freqs = [3.0, 3.6, 2.7, 3.1];
    let timing = Species::Goose.preset().timing;
    let get = |s: f64| probe::blended(Species::Goose, &amps, &freqs, s);
    let comps = |s: f64| {
        let (p, f) = get(s);
        [
            p.dihedral,
            p.hand_dihedral,
            p.tail_bend,
            p.sweep,
            p.arm_twist,
            p.hand_twist,
            p.spread,
            f,
        ]
    };
    let h = 1e-5;
    let step = 1e-3;
    let (mut max_jump, mut max_slope_jump) = (0.0f64, 0.0f64);
    let mut s = 0.3;
    while s < 3.0 * TAU {
        let (a, b, c) = (comps(s - h), comps(s), comps(s + h));
        let (a2, c2) = (comps(s + step - h), comps(s + step + h));
        for q in 0..8 {
            max_jump = max_jump.max((comps(s + step)[q] - b[q]).abs() / step);
            let slope_here = (c[q] - a[q]) / (2.0 * h);
            let slope_next = (c2[q] - a2[q]) / (2.0 * h);
            max_slope_jump = max_slope_jump.max((slope_next - slope_here).abs());
        }
        s += step;
    }
    // Bounded difference quotients: no jump in value (a jump would give ~|Δ|/1e-3 ≫ 10)...
    assert!(max_jump < 10.0, "value jumps: {max_jump}");
    // ...and no jump in slope (slopes change by at most a few 1e-2 per 1e-3 of phase).
    assert!(max_slope_jump < 0.1, "slope jumps: {max_slope_jump}");

    // Outside the blending window the wingbeat is exactly its own: parameters change only around
    // mid-upstroke.
    let mut preset = Species::Goose.preset();
    let b = timing.blend_half_width();
    for k in 0..50 {
        let phi = (timing.mid_upstroke() + b + 1e-9) + (TAU - 2.0 * b - 2e-9) * k as f64 / 49.0;
        let (p, f) = get(TAU + phi); // inside wingbeat 1 or 2's own part
        let n = ((TAU + phi - timing.mid_upstroke()) / TAU).floor() as usize + 1;
        let amp = amps[n];
        let mean = 0.5 * (preset.strokes.dihedral.up + preset.strokes.dihedral.down);
        let half = 0.5 * (preset.strokes.dihedral.up - preset.strokes.dihedral.down) * amp;
        preset.strokes.dihedral.down = mean - half;
        preset.strokes.dihedral.up = mean + half;
        let own = pose(&preset.strokes, &preset.timing, phi);
        assert!((p.dihedral - own.dihedral).abs() < 1e-12, "k={k}");
        assert_eq!(f, freqs[n]);
        preset = Species::Goose.preset();
    }
}

#[test]
fn equal_seeds_give_equal_phases_and_different_seeds_differ() {
    let opts = WingbeatOptions::default();
    let mut a = v_flock(9, 4.0, 30.0, |_| 10.0);
    let mut b = a.clone();
    assign_phases(&mut a, &opts).unwrap();
    assign_phases(&mut b, &opts).unwrap();
    assert_eq!(phases(&a), phases(&b));
    let mut c = v_flock(9, 4.0, 30.0, |_| 10.0);
    c.seed = 8;
    assign_phases(&mut c, &opts).unwrap();
    assert_ne!(phases(&a), phases(&c));
    for f in &a.frames {
        for &p in f.wing_phase.as_ref().unwrap() {
            assert!((0.0..TAU).contains(&p));
        }
    }
    assert_eq!(a.species.as_deref(), Some("goose"));
}

fn locked_phase_errors(variation: f64) -> Vec<f64> {
    let speed = 10.0;
    let mut a = v_flock(7, 20.0, 30.0, |_| speed);
    let opts = WingbeatOptions {
        variation,
        ..WingbeatOptions::default()
    };
    assign_phases(&mut a, &opts).unwrap();
    let ph = phases(&a);
    let last = a.frames.len() - 1;
    let frame = &a.frames[last];
    let mut errs = Vec::new();
    for i in 1..7 {
        let (j, dy) = bird_ahead(frame, i).expect("every follower has a bird ahead");
        // The bird ahead on the same arm: the leader for birds 1 and 2, else two ranks earlier.
        assert_eq!(j, i.saturating_sub(2));
        assert!((dy - 0.6).abs() < 1e-9);
        // The bird ahead's wingbeat frequency, measured over the last second.
        let fps = a.fps as usize;
        let mut adv = 0.0;
        for k in last - fps..last {
            adv += (ph[k + 1][j] - ph[k][j]).rem_euclid(TAU);
        }
        let f = adv / TAU;
        let expected = TAU * f * dy / speed;
        errs.push(wrap_pi(ph[last][j] - ph[last][i] - expected).abs());
    }
    errs
}

#[test]
fn locked_followers_lag_by_their_streamwise_distance() {
    for e in locked_phase_errors(0.0) {
        assert!(e < 0.01, "phase error {e} rad");
    }
    // With per-bird and per-wingbeat variation, the lock still holds to within a few degrees.
    for e in locked_phase_errors(1.0) {
        assert!(e < 0.12, "phase error {e} rad");
    }
}

#[test]
fn independent_birds_are_not_locked() {
    let mut a = v_flock(7, 20.0, 30.0, |_| 10.0);
    let opts = WingbeatOptions {
        phase_mode: PhaseMode::Independent,
        ..WingbeatOptions::default()
    };
    assign_phases(&mut a, &opts).unwrap();
    let ph = phases(&a);
    let last = ph.len() - 1;
    let f = Species::Goose.preset().frequency_hz;
    let worst = (1..7)
        .map(|i: usize| {
            let j = i.saturating_sub(2);
            wrap_pi(ph[last][j] - ph[last][i] - TAU * f * 0.6 / 10.0).abs()
        })
        .fold(0.0, f64::max);
    assert!(
        worst > 0.3,
        "independent birds happen to be locked: {worst}"
    );
}

#[test]
fn accelerating_birds_beat_faster_and_deeper() {
    // Speed ramps from 2 to 12 wingspans/s (1.6 m span: 1.6 m/s² … well above the goose's
    // reference) over the first 6 s, then cruises.
    let ramp = |t: f64| if t < 6.0 { 2.0 + t * 10.0 / 6.0 } else { 12.0 };
    let opts = WingbeatOptions {
        phase_mode: PhaseMode::Independent,
        variation: 0.0,
        ..WingbeatOptions::default()
    };
    let mut a = v_flock(1, 12.0, 30.0, ramp);
    assign_phases(&mut a, &opts).unwrap();
    let flapper = Flapper::from_animation(&a);
    let ph = phases(&a);
    let rate = |from: usize, to: usize| {
        (from..to)
            .map(|k| (ph[k + 1][0] - ph[k][0]).rem_euclid(TAU))
            .sum::<f64>()
            / TAU
            / ((to - from) as f64 / 30.0)
    };
    let peak = |from: usize, to: usize| {
        (from..to)
            .map(|k| flapper.pose(k, 0).dihedral)
            .fold(f64::MIN, f64::max)
    };
    let f0 = Species::Goose.preset().frequency_hz;
    assert!(rate(30, 150) > 1.15 * f0, "accelerating: {}", rate(30, 150));
    assert!(
        (rate(240, 350) - f0).abs() < 0.02 * f0,
        "cruising: {}",
        rate(240, 350)
    );
    assert!(peak(30, 150) > peak(240, 350) + 0.05);
}

#[test]
fn gliding_holds_the_wings_and_bouts_alternate() {
    let mut a = v_flock(3, 8.0, 30.0, |_| 10.0);
    let opts = WingbeatOptions {
        glide: Glide::Always,
        ..WingbeatOptions::default()
    };
    assign_phases(&mut a, &opts).unwrap();
    let fl = Flapper::from_animation(&a);
    for k in 0..a.frames.len() {
        let p = fl.pose(k, 1);
        assert!((p.spread - 1.0).abs() < 1e-12);
        assert!((p.dihedral - fl.pose(0, 1).dihedral).abs() < 1e-12);
    }

    let mut b = v_flock(3, 20.0, 30.0, |_| 10.0);
    let opts = WingbeatOptions {
        species: Species::Pelican,
        glide: Glide::Bouts,
        ..WingbeatOptions::default()
    };
    assign_phases(&mut b, &opts).unwrap();
    let fl = Flapper::from_animation(&b);
    let moving: Vec<bool> = (1..b.frames.len())
        .map(|k| (fl.pose(k, 0).dihedral - fl.pose(k - 1, 0).dihedral).abs() > 1e-9)
        .collect();
    let flapping = moving.iter().filter(|&&m| m).count();
    assert!(flapping > moving.len() / 3 && flapping < moving.len() * 9 / 10);
}

#[test]
fn renderers_rebuild_the_same_wingbeats_from_the_file() {
    for opts in [
        WingbeatOptions::default(),
        WingbeatOptions {
            species: Species::Crane,
            phase_mode: PhaseMode::Independent,
            glide: Glide::Bouts,
            ..WingbeatOptions::default()
        },
    ] {
        let plain = v_flock(5, 6.0, 30.0, |t| 4.0 + t);
        let mut a = plain.clone();
        assign_phases(&mut a, &opts).unwrap();
        // Replayed from the stored phases, as `render` does...
        let stored = Flapper::from_animation(&a);
        // ...and computed without stored phases, with the same options: identical.
        let computed = Flapper::with_options(&plain, &opts);
        assert_eq!(probe::unwrapped(&stored), probe::unwrapped(&computed));
        for k in 0..a.frames.len() {
            for i in 0..5 {
                assert_eq!(stored.pose(k, i), computed.pose(k, i));
                assert_eq!(
                    stored.phase(k, i),
                    a.frames[k].wing_phase.as_ref().unwrap()[i]
                );
            }
        }
        // Through a JSON file the phases are rounded to the file's 10⁻⁶ radians; the wingbeats
        // move by no more than that.
        let json = serde_json::to_string(&a).unwrap();
        let back: Animation = serde_json::from_str(&json).unwrap();
        let from_file = Flapper::from_animation(&back);
        for k in 0..a.frames.len() {
            for i in 0..5 {
                let (p, q) = (from_file.pose(k, i), computed.pose(k, i));
                for (x, y) in [
                    (p.dihedral, q.dihedral),
                    (p.hand_dihedral, q.hand_dihedral),
                    (p.sweep, q.sweep),
                    (p.arm_twist, q.arm_twist),
                    (p.hand_twist, q.hand_twist),
                    (p.spread, q.spread),
                    (p.tail_bend, q.tail_bend),
                ] {
                    assert!((x - y).abs() < 1e-6, "frame {k} bird {i}: {x} vs {y}");
                }
            }
        }
    }
}

#[test]
fn poses_move_smoothly_from_frame_to_frame() {
    let mut a = v_flock(5, 10.0, 60.0, |t| 3.0 + t);
    assign_phases(&mut a, &WingbeatOptions::default()).unwrap();
    let fl = Flapper::from_animation(&a);
    // At 60 fps and ≤ 3.6 Hz a frame is ≤ 0.06 of a period (0.38 rad of phase); the dihedral's
    // slope is at most (u^u − u^d)/2 · max h' ≈ 1.05 rad per rad of phase, so < 0.5 rad per frame.
    for i in 0..5 {
        for k in 1..a.frames.len() {
            let d = (fl.pose(k, i).dihedral - fl.pose(k - 1, i).dihedral).abs();
            assert!(d < 0.5, "bird {i} frame {k}: {d}");
        }
    }
    assert_eq!(fl.pose(10_000, 0), formation::wingbeat::WingPose::EXTENDED);
}

#[test]
fn options_parse_and_reject_unknown_names() {
    assert_eq!("pelican".parse::<Species>().unwrap(), Species::Pelican);
    assert_eq!("Crane".parse::<Species>().unwrap(), Species::Crane);
    let e = "heron".parse::<Species>().unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(e.to_string().contains("wingbeat.species"));
    assert_eq!(
        "independent".parse::<PhaseMode>().unwrap(),
        PhaseMode::Independent
    );
    assert!("sync".parse::<PhaseMode>().is_err());
    assert_eq!("bouts".parse::<Glide>().unwrap(), Glide::Bouts);
    assert!("soar".parse::<Glide>().is_err());
    let bad = WingbeatOptions {
        variation: f64::NAN,
        ..WingbeatOptions::default()
    };
    let mut a = v_flock(2, 1.0, 30.0, |_| 10.0);
    assert!(assign_phases(&mut a, &bad).is_err());
    assert!(a.frames[0].wing_phase.is_none());
}

#[test]
fn plot_wingbeat_writes_png_and_svg() {
    let dir = scratch("plot-wingbeat");
    for (species, name) in [("goose", "g.png"), ("pelican", "p.svg")] {
        let out = dir.join(name);
        let st = bin()
            .args(["plot", "wingbeat", "--species", species, "-o"])
            .arg(&out)
            .status()
            .unwrap();
        assert!(st.success());
        let bytes = std::fs::read(&out).unwrap();
        if name.ends_with(".png") {
            assert_eq!(&bytes[1..4], b"PNG");
        } else {
            assert!(String::from_utf8_lossy(&bytes).contains("<svg"));
        }
    }
    let out = dir.join("bad.png");
    let o = bin()
        .args(["plot", "wingbeat", "--species", "heron", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("heron"));
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

proptest! {
    #[test]
    fn the_grid_finds_the_same_bird_ahead(
        pts in proptest::collection::vec((-20.0f64..20.0, -20.0f64..20.0, -0.5f64..0.5), 1..150),
    ) {
        let mut f = Frame::default();
        for &(x, y, h) in &pts {
            f.x.push(x);
            f.y.push(y);
            f.z.push(0.0);
            f.heading.push(h);
            f.speed.push(10.0);
        }
        let index = AheadIndex::new(&f);
        for i in 0..pts.len() {
            prop_assert_eq!(index.ahead(&f, i), bird_ahead(&f, i));
        }
    }
}

#[test]
fn files_without_wingbeat_record_use_their_species_and_bad_files_are_rejected() {
    let mut a = v_flock(3, 2.0, 30.0, |_| 10.0);
    a.species = Some("pelican".into());
    assert_eq!(WingbeatOptions::for_animation(&a).species, Species::Pelican);
    // Without stored phases the flapper computes them as assign_phases would.
    let computed = Flapper::from_animation(&a);
    let mut b = a.clone();
    assign_phases(
        &mut b,
        &WingbeatOptions {
            species: Species::Pelican,
            ..WingbeatOptions::default()
        },
    )
    .unwrap();
    assert_eq!(
        computed.phase(30, 2),
        b.frames[30].wing_phase.as_ref().unwrap()[2]
    );

    // One bird too few in a frame: an error naming the frame and field, not a panic.
    let mut bad = v_flock(3, 1.0, 30.0, |_| 10.0);
    bad.frames[5].speed.pop();
    let e = assign_phases(&mut bad, &WingbeatOptions::default()).unwrap_err();
    assert!(e.to_string().contains("frames[5].speed"), "{e}");
    // The flapper never panics on it either.
    let f = Flapper::from_animation(&bad);
    let _ = f.pose(5, 2);
    let _ = f.pose_at(5.5, 2);
}

/// A line of birds, each `lateral` wingspans to the side of and 1.2 wingspans behind the one
/// ahead, flying straight at 10 wingspans/s for 20 s at 30 fps.
fn line_flock(birds: usize, lateral: impl Fn(usize, f64) -> f64) -> Animation {
    let (fps, speed) = (30.0, 10.0);
    let mut a = Animation::new(7, fps, 1.6, birds);
    for k in 0..600 {
        let t = k as f64 / fps;
        let mut f = Frame {
            t,
            ..Frame::default()
        };
        for i in 0..birds {
            f.x.push(lateral(i, t));
            f.y.push(speed * t - 1.2 * i as f64);
            f.z.push(0.0);
            f.heading.push(0.0);
            f.speed.push(speed);
        }
        a.frames.push(f);
    }
    a
}

/// Bird `i`'s phase relative to the spatial-phasing target behind bird `i − 1` at frame `k`
/// (0: spatial phase, ±π: spatial antiphase).
fn offset_from_spatial_phase(a: &Animation, k: usize, i: usize) -> f64 {
    let ph = phases(a);
    let f = Species::Goose.preset().frequency_hz;
    let mut adv = 0.0;
    for m in k - 30..k {
        adv += (ph[m + 1][i - 1] - ph[m][i - 1]).rem_euclid(TAU);
    }
    let f_ahead = adv / TAU;
    assert!(
        (f_ahead - f).abs() < 0.1 * f,
        "bird ahead beats at {f_ahead} Hz"
    );
    wrap_pi(ph[k][i - 1] - TAU * f_ahead * 1.2 / 10.0 - ph[k][i])
}

#[test]
fn birds_directly_behind_flap_in_antiphase_and_birds_in_upwash_in_phase() {
    let opts = WingbeatOptions {
        variation: 0.0,
        ..WingbeatOptions::default()
    };
    // A column: each bird 0.2 wingspans aside of the one ahead, in its downwash.
    let mut column = line_flock(4, |i, _| 0.2 * i as f64);
    assign_phases(&mut column, &opts).unwrap();
    // An echelon: each bird 0.85 wingspans aside, in the upwash of the one ahead.
    let mut echelon = line_flock(4, |i, _| 0.85 * i as f64);
    assign_phases(&mut echelon, &opts).unwrap();
    for i in 1..4 {
        let anti = offset_from_spatial_phase(&column, 599, i);
        assert!(
            PI - anti.abs() < 0.02,
            "bird {i} behind: {anti} rad from spatial phase"
        );
        let upwash = offset_from_spatial_phase(&echelon, 599, i);
        assert!(upwash.abs() < 0.02, "bird {i} in upwash: {upwash} rad");
    }
    // A bird that drifts from 1 wingspan aside to directly behind over 10 s and back changes
    // rule once each way (hysteresis: no flicker at the boundary), and holds each rule.
    let drift = |i: usize, t: f64| {
        if i == 0 {
            0.0
        } else {
            let u = (t / 10.0).min(2.0 - t / 10.0).clamp(0.0, 1.0);
            1.0 - u
        }
    };
    let mut mover = line_flock(2, drift);
    assign_phases(&mut mover, &opts).unwrap();
    let states: Vec<bool> = (60..600)
        .map(|k| offset_from_spatial_phase(&mover, k, 1).abs() > PI / 2.0)
        .collect();
    let switches = states.windows(2).filter(|w| w[0] != w[1]).count();
    assert_eq!(switches, 2, "rule switches: {switches}");
    assert!(offset_from_spatial_phase(&mover, 290, 1).abs() > PI - 0.1);
    assert!(offset_from_spatial_phase(&mover, 90, 1).abs() < 0.1);
}

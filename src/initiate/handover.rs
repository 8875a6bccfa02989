//! The hand-over from the take-off to the steady flight: the steady frames moved in space and
//! time so that position, heading, speed and bank continue without a jump.

use super::*;

/// Joins a converged run to the steady flight: birds are renumbered by their final slot, the last
/// `hold` seconds of the initiation are blended (smoothstep) into the backward extrapolation of the
/// steady flight's first frame, and the steady frames are translated (horizontally, and up to the
/// cruise altitude) and delayed to follow on. Every frame gets a `bank`: the simulation's in the
/// initiation, the coordinated-turn bank of the steady flight's own turns after it.
pub fn hand_over(
    steady: &Animation,
    run: &InitiationRun,
    opts: &InitiateOptions,
) -> Result<(Animation, InitiateStats)> {
    hand_over_owned(steady.clone(), run, opts)
}

/// [`hand_over`] of a steady flight given up to it: its frames become the animation's steady
/// frames in place instead of being copied (the flock's memory once, not twice, for large flocks).
pub fn hand_over_owned(
    mut steady: Animation,
    run: &InitiationRun,
    opts: &InitiateOptions,
) -> Result<(Animation, InitiateStats)> {
    let n = steady.birds;
    let fps = steady.fps;
    let f0 = steady
        .frames
        .first()
        .cloned()
        .ok_or_else(|| Error::Internal("steady flight without frames".into()))?;
    let f0 = &f0;
    // Bird b of the simulation becomes animation bird perm[b] (its slot = the key shape's bird).
    let mut perm = vec![usize::MAX; n];
    let mut used = vec![false; n];
    for (b, s) in run.slot.iter().enumerate() {
        match s {
            Some(s) if *s < n && !used[*s] => {
                perm[b] = *s;
                used[*s] = true;
            }
            _ => {
                return Err(Error::Internal(
                    "hand-over of a flock whose slots are not one-to-one".into(),
                ))
            }
        }
    }
    let last = run.pos.len() - 1;
    let alt = opts.cruise_altitude;
    let g = GRAVITY_M_S2 / steady.wingspan_m;
    let steady_bank = steady_banks(&steady, g, opts.max_roll_rate, opts.roll_lag);
    let step_of = |s: usize| perception::direction(f0.heading[s]) * (f0.speed[s] / fps);
    let s0 = |s: usize| DVec2::new(f0.x[s], f0.y[s]);
    // Translation of the steady flight: least squares over birds of the one-step continuation.
    let mut shift = DVec2::ZERO;
    for (b, &s) in perm.iter().enumerate() {
        shift += run.pos[last][b] + step_of(s) - s0(s);
    }
    shift /= n as f64;
    let window = ((opts.hold * fps).round() as usize).clamp(1, last.max(1));
    let steady_frames = std::mem::take(&mut steady.frames);
    let mut frames: Vec<Frame> = Vec::with_capacity(run.pos.len() + steady_frames.len());
    let wing_rate: Option<Vec<f64>> = match (
        steady_frames.first().and_then(|f| f.wing_phase.as_ref()),
        steady_frames.get(1).and_then(|f| f.wing_phase.as_ref()),
    ) {
        (Some(a), Some(b)) => Some(
            a.iter()
                .zip(b)
                .map(|(a, b)| (b - a).rem_euclid(2.0 * PI))
                .collect(),
        ),
        _ => None,
    };
    for t in 0..=last {
        let mut fr = Frame {
            t: t as f64 / fps,
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            heading: vec![0.0; n],
            speed: vec![0.0; n],
            bank: Some(vec![0.0; n]),
            ..Default::default()
        };
        // Blend weight: 0 before the window, smoothstep up to 1 at the last initiation frame.
        let w = if t + window <= last {
            0.0
        } else {
            let u = (t + window - last) as f64 / window as f64;
            u * u * (3.0 - 2.0 * u)
        };
        for (b, &s) in perm.iter().enumerate() {
            let back = (last + 1 - t) as f64;
            let ideal = s0(s) + shift - step_of(s) * back;
            let p = run.pos[t][b].lerp(ideal, w);
            let h = run.heading[t][b];
            let h = sim::wrap_angle(h + w * sim::wrap_angle(f0.heading[s] - h));
            let v = run.speed[t][b] * (1.0 - w) + f0.speed[s] * w;
            fr.x[s] = p.x;
            fr.y[s] = p.y;
            fr.z[s] = run.z[t][b] * (1.0 - w) + (f0.z[s] + alt) * w;
            fr.heading[s] = h;
            fr.speed[s] = v;
            if let Some(bank) = fr.bank.as_mut() {
                bank[s] = run.bank[t][b] * (1.0 - w) + steady_bank[0][s] * w;
            }
        }
        if let (Some(rate), Some(ph0)) = (&wing_rate, f0.wing_phase.as_ref()) {
            let back = (last + 1 - t) as f64;
            fr.wing_phase = Some(
                (0..n)
                    .map(|s| (ph0[s] - rate[s] * back).rem_euclid(2.0 * PI))
                    .collect(),
            );
        }
        frames.push(fr);
    }
    let offset = frames.len();
    let t_start = offset as f64 / fps;
    let t0 = f0.t;
    let steady_len = steady_frames.len();
    for (mut g, bank) in steady_frames.into_iter().zip(steady_bank) {
        g.t = t_start + (g.t - t0);
        for s in 0..n {
            if let (Some(x), Some(y)) = (g.x.get_mut(s), g.y.get_mut(s)) {
                *x += shift.x;
                *y += shift.y;
            }
            if let Some(z) = g.z.get_mut(s) {
                *z += alt;
            }
        }
        g.bank = Some(bank);
        frames.push(g);
    }
    let mut out = Animation::new(opts.seed, fps, steady.wingspan_m, n);
    out.species = steady.species.clone();
    out.flight = steady.flight;
    out.savings_model = steady.savings_model.clone();
    out.stages.push(Stage {
        name: "initiation".into(),
        start: 0,
        end: offset,
    });
    if steady.stages.is_empty() {
        out.stages.push(Stage {
            name: "steady".into(),
            start: offset,
            end: offset + steady_len,
        });
    }
    for st in &steady.stages {
        out.stages.push(Stage {
            name: st.name.clone(),
            start: st.start + offset,
            end: st.end + offset,
        });
    }
    out.key_shapes = steady
        .key_shapes
        .iter()
        .map(|k| {
            let mut k = k.clone();
            k.frame += offset;
            k
        })
        .collect();
    out.events = steady
        .events
        .iter()
        .map(|e| {
            let mut e = e.clone();
            e.t = t_start + (e.t - t0);
            e
        })
        .collect();
    // The steady flight's feasible ξ ranges stay with its key shapes (plot power draws them).
    out.xi_ranges = steady.xi_ranges.clone();
    out.frames = frames;
    // Closest approach (3-D) in the written initiation frames (after the blend).
    let mut stats = run.stats.clone();
    stats.min_distance = out.frames[..offset]
        .iter()
        .map(|f| {
            let pts: Vec<DVec3> = (0..n).map(|i| DVec3::new(f.x[i], f.y[i], f.z[i])).collect();
            sim::min_pair_distance(&pts)
        })
        .fold(stats.min_distance, f64::min);
    Ok((out, stats))
}

/// The bank of every bird in every steady frame: the coordinated-turn bank tan φ = v ω / g of the
/// steady flight's own turns (ω from the headings of neighbouring frames, g in wingspans/s²),
/// followed with the roll lag and roll-rate limit from a level start. Straight flight gives 0.
pub fn steady_banks(
    steady: &Animation,
    g: f64,
    max_roll_rate: f64,
    roll_lag: f64,
) -> Vec<Vec<f64>> {
    let n = steady.birds;
    let fr = &steady.frames;
    let mut out = Vec::with_capacity(fr.len());
    let mut phi = vec![0.0; n];
    for k in 0..fr.len() {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(fr.len() - 1));
        let dt = fr[b].t - fr[a].t;
        for (s, phi) in phi.iter_mut().enumerate() {
            let w = if dt > 0.0 {
                sim::wrap_angle(fr[b].heading[s] - fr[a].heading[s]) / dt
            } else {
                0.0
            };
            let target = (fr[k].speed[s] * w / g).atan();
            if k == 0 {
                *phi = 0.0;
            } else {
                let h = fr[k].t - fr[k - 1].t;
                let rate = ((target - *phi) / roll_lag).clamp(-max_roll_rate, max_roll_rate);
                // An exact step to the target when the lag would overshoot it.
                let next = *phi + rate * h;
                *phi = if (next - target) * (*phi - target) < 0.0 {
                    target
                } else {
                    next
                };
            }
        }
        out.push(phi.clone());
    }
    out
}

//! What an animation says about the flock, for summaries, `plot savings` and
//! `formation report`: its stages' lengths, how much the flock saves over time and in steady
//! flight, and each bird's saving against its place in its formation.
//!
//! Savings are e_i (docs/formats.md §3: the fraction of bird i's solo induced power that the others save
//! it), as recorded in the frames; the flock's saving at a frame is their mean over the birds
//! (E/N). Frames without `e` are skipped.

use super::Animation;

/// One bird over the steady flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BirdStats {
    /// The animation's bird index.
    pub bird: usize,
    /// Its formation.
    pub formation: usize,
    /// Whether it leads its formation.
    pub leader: bool,
    /// Mean rank over the steady frames (0 = the leader).
    pub rank: f64,
    /// Mean saving e_i over the steady frames (fraction of solo induced power).
    pub saving: f64,
    /// Mean offset to the right of the leader, wingspans.
    pub lateral: f64,
    /// Mean distance behind the leader, wingspans.
    pub behind: f64,
}

/// Summary statistics of an animation.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimationStats {
    /// Number of formations.
    pub formations: usize,
    /// Length of the `initiation` stage, seconds.
    pub takeoff_s: Option<f64>,
    /// Length of the `steady` stage, seconds.
    pub steady_s: Option<f64>,
    /// Length of the `landing` stage, seconds.
    pub landing_s: Option<f64>,
    /// Mean flock saving (E/N) over the steady frames.
    pub steady_saving: Option<f64>,
    /// `(t, E/N)` at every frame with savings.
    pub saving_over_time: Vec<(f64, f64)>,
    /// Each bird over the steady flight (the whole animation when it has no steady stage);
    /// empty without savings.
    pub birds: Vec<BirdStats>,
}

impl AnimationStats {
    /// The statistics of `anim`.
    pub fn of(anim: &Animation) -> AnimationStats {
        let secs = |name: &str| {
            anim.stage(name)
                .map(|s| (s.end - s.start) as f64 / anim.fps)
        };
        let saving_over_time: Vec<(f64, f64)> = anim
            .frames
            .iter()
            .filter_map(|f| {
                let e = f.e.as_ref()?;
                (!e.is_empty()).then(|| (f.t, e.iter().sum::<f64>() / e.len() as f64))
            })
            .collect();
        let range = anim
            .stage("steady")
            .map(|s| s.start..s.end)
            .unwrap_or(0..anim.frames.len());
        let of = anim.formation_of_birds();
        let leaders = anim.leaders();
        let n = anim.birds;
        let mut acc = vec![(0.0, 0.0, 0.0, 0.0); n];
        let mut frames = 0usize;
        let mut flock = 0.0;
        for k in range {
            let Some(e) = anim.frames[k].e.as_ref() else {
                continue;
            };
            frames += 1;
            flock += e.iter().sum::<f64>() / n as f64;
            for (i, r) in anim.relative_with(k, &of, &leaders).iter().enumerate() {
                acc[i].0 += r.rank as f64;
                acc[i].1 += e[i];
                acc[i].2 += r.lateral;
                acc[i].3 += r.behind;
            }
        }
        let birds = if frames == 0 {
            Vec::new()
        } else {
            let m = frames as f64;
            (0..n)
                .map(|i| BirdStats {
                    bird: i,
                    formation: of[i],
                    leader: leaders.get(of[i]) == Some(&i),
                    rank: acc[i].0 / m,
                    saving: acc[i].1 / m,
                    lateral: acc[i].2 / m,
                    behind: acc[i].3 / m,
                })
                .collect()
        };
        AnimationStats {
            formations: leaders.len().max(1),
            takeoff_s: secs("initiation"),
            steady_s: secs("steady"),
            landing_s: secs("landing"),
            steady_saving: (frames > 0 && anim.stage("steady").is_some())
                .then(|| flock / frames as f64),
            saving_over_time,
            birds,
        }
    }
}

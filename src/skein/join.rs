//! The flock's one animation, made a formation at a time: each formation's frames are appended
//! to the flock's as soon as the formation is finished (its take-off handed over) and dropped, so
//! the flock's motion is never held twice, once in the formations' many small vectors and once
//! joined. The formations' places in the arrangement, known only once every formation is
//! finished, are added at the end.

use std::ops::Range;

use super::FormationReport;
use crate::animation::{Animation, FormationRecord, Frame, Stage};
use crate::error::{Error, Result};

/// The flock's animation being joined.
pub(super) struct Joiner {
    /// Birds of the whole flock.
    birds: usize,
    /// Everything but the frames, from the first formation.
    out: Option<Animation>,
    frames: Vec<Frame>,
    records: Vec<FormationRecord>,
    ranges: Vec<Range<usize>>,
    xi_ranges: Option<Vec<[f64; 2]>>,
}

impl Joiner {
    /// A flock of `birds` birds in all, no formation yet.
    pub fn new(birds: usize) -> Joiner {
        Joiner {
            birds,
            out: None,
            frames: Vec::new(),
            records: Vec::new(),
            ranges: Vec::new(),
            xi_ranges: Some(Vec::new()),
        }
    }

    /// Frames of the flock (0 before the first formation).
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Appends the next formation, its birds numbered after those of the formations before it;
    /// its frames are moved out of `a` (the rest of `a` is kept as it was).
    pub fn push(&mut self, a: &mut Animation) -> Result<()> {
        let n = self.birds;
        let base = self.ranges.last().map_or(0, |r| r.end);
        let out = self.out.get_or_insert_with(|| {
            let mut out = Animation::new(a.seed, a.fps, a.wingspan_m, n);
            out.species = a.species.clone();
            out.flight = a.flight;
            out.savings_model = a.savings_model.clone();
            out.wingbeat = a.wingbeat.clone();
            out.stages = a.stages.clone();
            out
        });
        if !self.ranges.is_empty() && a.frames.len() != self.frames.len() {
            return Err(Error::Internal("formations of different lengths".into()));
        }
        let leader = a.leaders().first().copied().unwrap_or(0);
        self.records.push(FormationRecord {
            birds: (base..base + a.birds).collect(),
            leader: base + leader,
            key_shapes: a.key_shapes.clone(),
            xi_ranges: a.xi_ranges.clone(),
            steady_start: out.stage("steady").map(|s: &Stage| s.start),
        });
        out.events.extend(a.events.iter().map(|e| {
            let mut e = e.clone();
            e.birds.iter_mut().for_each(|b| *b += base);
            e
        }));
        self.xi_ranges = match (self.xi_ranges.take(), &a.xi_ranges) {
            (Some(mut all), Some(own)) => {
                all.extend_from_slice(own);
                Some(all)
            }
            _ => None,
        };
        let parts = std::mem::take(&mut a.frames);
        if self.ranges.is_empty() {
            // Room for the whole flock, filled as the other formations follow.
            self.frames = parts
                .into_iter()
                .map(|f| {
                    f.map_values(|v| {
                        let mut w = Vec::with_capacity(n);
                        w.extend_from_slice(v);
                        w
                    })
                })
                .collect();
        } else {
            for (dst, f) in self.frames.iter_mut().zip(parts) {
                dst.x.extend_from_slice(&f.x);
                dst.y.extend_from_slice(&f.y);
                dst.z.extend_from_slice(&f.z);
                dst.heading.extend_from_slice(&f.heading);
                dst.speed.extend_from_slice(&f.speed);
                // A value some formation does not carry is not carried by the flock.
                for (d, s) in [
                    (&mut dst.bank, &f.bank),
                    (&mut dst.pitch, &f.pitch),
                    (&mut dst.e, &f.e),
                    (&mut dst.xi, &f.xi),
                    (&mut dst.wing_phase, &f.wing_phase),
                ] {
                    match (d.as_mut(), s) {
                        (Some(d), Some(s)) => d.extend_from_slice(s),
                        _ => *d = None,
                    }
                }
            }
        }
        self.ranges.push(base..base + a.birds);
        Ok(())
    }

    /// The joined animation, every formation moved by its placement (`reports`, in the order
    /// the formations were pushed).
    pub fn finish(self, reports: &[FormationReport]) -> Result<Animation> {
        let mut out = self
            .out
            .ok_or_else(|| Error::Internal("a flock without formations".into()))?;
        let mut frames = self.frames;
        // Height offsets: from the start without a take-off, reached over the first seconds of
        // the steady flight after one.
        let climb = out
            .stage("initiation")
            .and_then(|_| out.stage("steady"))
            .and_then(|s| frames.get(s.start))
            .map(|f| f.t);
        for f in &mut frames {
            let share = climb.map_or(1.0, |t0| super::natural::height_ramp(f.t - t0));
            for (r, rep) in self.ranges.iter().zip(reports) {
                let dz = share * rep.placement.height;
                if dz != 0.0 {
                    f.z[r.clone()].iter_mut().for_each(|z| *z += dz);
                }
            }
            // `x + 0.0` as the values were always joined (it makes a -0.0 +0.0).
            for v in [&mut f.z, &mut f.heading, &mut f.speed] {
                v.iter_mut().for_each(|x| *x += 0.0);
            }
            for (r, rep) in self.ranges.iter().zip(reports) {
                let [dx, dy] = rep.placement.offset;
                f.x[r.clone()].iter_mut().for_each(|x| *x += dx);
                f.y[r.clone()].iter_mut().for_each(|y| *y += dy);
            }
        }
        out.events.sort_by(|a, b| a.t.total_cmp(&b.t));
        out.xi_ranges = self.xi_ranges;
        out.frames = frames;
        out.formations = Some(self.records);
        Ok(out)
    }
}

//! Heights measured in 3-D tracks: the spread of the birds' heights, the height difference of
//! lateral neighbours and the height of each bird above the bird ahead of it, wingspans.

use super::params::{FrameParams, MeasuredHeights};
use crate::annotations::Annotations;

/// The heights of `ann` over the extracted `frames` (in the same order); `None` when the
/// annotations carry no heights.
pub fn measure(ann: &Annotations, frames: &[FrameParams]) -> Option<MeasuredHeights> {
    let (mut var_sum, mut nvar) = (0.0, 0usize);
    let (mut nb_sum, mut nnb) = (0.0, 0usize);
    let mut ahead = Vec::new();
    for (f, p) in ann.frames.iter().zip(frames) {
        let h = |id: usize| -> Option<f64> {
            f.birds.iter().find(|b| b.id == id).and_then(|b| b.height)
        };
        let hs: Vec<f64> = p.order.iter().filter_map(|&id| h(id)).collect();
        if hs.len() != p.order.len() || hs.len() < 2 {
            continue;
        }
        let n = hs.len() as f64;
        let mean = hs.iter().sum::<f64>() / n;
        var_sum += hs.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        nvar += 1;
        for w in hs.windows(2) {
            nb_sum += (w[1] - w[0]).powi(2);
            nnb += 1;
        }
        // The bird ahead: the lateral neighbour toward the leader.
        let Some(li) = p.order.iter().position(|&id| id == p.leader) else {
            continue;
        };
        for (i, v) in hs.iter().enumerate() {
            if i < li {
                ahead.push(v - hs[i + 1]);
            } else if i > li {
                ahead.push(v - hs[i - 1]);
            }
        }
    }
    if nvar == 0 || nnb == 0 || ahead.is_empty() {
        return None;
    }
    let am = ahead.iter().sum::<f64>() / ahead.len() as f64;
    let asd = (ahead.iter().map(|v| (v - am).powi(2)).sum::<f64>() / ahead.len() as f64).sqrt();
    Some(MeasuredHeights {
        frames: nvar,
        spread: (var_sum / nvar as f64).sqrt(),
        neighbour: (nb_sum / nnb as f64).sqrt(),
        ahead_mean: am,
        ahead_sd: asd,
    })
}

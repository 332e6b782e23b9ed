//! The three-dimensional pruning heuristic (003): the world is static, so the distance between
//! two features must stay the same from one stop to the next. A pair whose distance changed by
//! more than its ranges' errors allow is inconsistent; the feature in the most inconsistent
//! pairs is dropped, and again, until no inconsistent pair is left.
//!
//! How much the ranges' errors allow is measured against the pairs themselves: the stereo
//! model's errors are scaled by how far the typical feature's changes exceed what the model
//! predicts (a robust variance factor: on a noisy, soft image sub-pixel matching is worse than
//! the model's nominal figure, and good pairs would otherwise look inconsistent).

use super::rig::Rig;
use super::solve::Pair;

/// How far a pair's distance may change: `sigmas` of the four ranges' errors together, and
/// never less than `floor_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    pub sigmas: f64,
    pub floor_m: f64,
}

/// The median of a standard normal's absolute value.
const HALF_NORMAL_MEDIAN: f64 = 0.674_489_75;

/// What pruning did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pruned {
    pub dropped: usize,
    /// The factor (at least 1) the stereo model's standard deviations were scaled by.
    pub scale: f64,
}

/// Clears the `active` flag of the features pruning drops. `scratch` keeps the pairs' verdicts
/// between calls.
pub fn prune(
    rig: &Rig,
    pairs: &[Pair],
    active: &mut [bool],
    tol: Tolerance,
    scratch: &mut Vec<bool>,
) -> Pruned {
    let n = pairs.len();
    let sd: Vec<[f64; 2]> = pairs.iter().map(|p| [rig.range_sd(p.old), rig.range_sd(p.new)]).collect();
    let pair_sd = |i: usize, j: usize| {
        (sd[i][0].powi(2) + sd[i][1].powi(2) + sd[j][0].powi(2) + sd[j][1].powi(2)).sqrt()
    };
    let change = |i: usize, j: usize| {
        let (a, b) = (&pairs[i], &pairs[j]);
        (distance(a.old, b.old) - distance(a.new, b.new)).abs()
    };
    // Each feature's median normalised change against the others: for a good feature it is
    // the model's error scale (most of its partners are good too), for a blunder far more; the
    // median over the features is a good one's while blunders are fewer than half.
    let mut own: Vec<f64> = Vec::with_capacity(n);
    let mut medians: Vec<f64> = Vec::with_capacity(n);
    for i in (0..n).filter(|&i| active[i]) {
        own.clear();
        own.extend((0..n).filter(|&j| j != i && active[j]).map(|j| change(i, j) / pair_sd(i, j)));
        if !own.is_empty() {
            let mid = own.len() / 2;
            medians.push(*own.select_nth_unstable_by(mid, f64::total_cmp).1);
        }
    }
    let scale = if medians.is_empty() {
        1.0
    } else {
        let mid = medians.len() / 2;
        (*medians.select_nth_unstable_by(mid, f64::total_cmp).1 / HALF_NORMAL_MEDIAN).max(1.0)
    };
    scratch.clear();
    scratch.resize(n * n, false);
    let mut count = vec![0usize; n];
    for i in 0..n {
        for j in i + 1..n {
            if !(active[i] && active[j]) {
                continue;
            }
            if change(i, j) > (tol.sigmas * scale * pair_sd(i, j)).max(tol.floor_m) {
                scratch[i * n + j] = true;
                scratch[j * n + i] = true;
                count[i] += 1;
                count[j] += 1;
            }
        }
    }
    let mut dropped = 0;
    while let Some(worst) =
        (0..n).filter(|&i| active[i] && count[i] > 0).max_by_key(|&i| (count[i], std::cmp::Reverse(i)))
    {
        active[worst] = false;
        dropped += 1;
        count[worst] = 0;
        for j in 0..n {
            if scratch[worst * n + j] {
                scratch[j * n + worst] = false;
                count[j] -= 1;
            }
        }
    }
    Pruned { dropped, scale }
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_feature_that_moved_against_the_others_is_dropped() {
        let rig = super::super::rig::example();
        // The robot moved 0.5 m forward: every point is 0.5 m nearer, except one false match.
        let mut pairs: Vec<Pair> = (0..12)
            .map(|i| {
                let old = [3.0 + 0.2 * i as f64, -1.0 + 0.17 * i as f64, 0.5 + 0.1 * i as f64];
                Pair { old, new: [old[0] - 0.5, old[1], old[2]], old_cov: [0.0; 3], new_cov: [0.0; 3] }
            })
            .collect();
        pairs[5].new[0] += 0.3;
        let mut active = vec![true; pairs.len()];
        let tol = Tolerance { sigmas: 4.0, floor_m: 0.03 };
        let p = prune(&rig, &pairs, &mut active, tol, &mut Vec::new());
        assert_eq!(p.dropped, 1);
        assert!(!active[5] && active.iter().filter(|a| **a).count() == 11);
        assert_eq!(p.scale, 1.0, "exact points: the model's errors stand");
    }
}

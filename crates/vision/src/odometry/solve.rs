//! The motion between two stops by weighted least squares (003 "Motion Solving"): the planar
//! motion `T` (the new pose in the old robot frame) that minimises the weighted squared
//! differences `(x_old - T(x_new))²` over the features seen at both stops, each weighed by the
//! inverse of its stereo covariance at both stops (near features count more than far ones), with
//! the predicted motion as a heavily weighted extra term, the paper's "reasonableness limit".
//! Gauss-Newton from the prediction; then Gennery's editing: the feature with the largest
//! residual is dropped and the motion solved again until every residual is plausible.

use super::rig::Sym2;

/// A planar motion: where the robot's new pose lies in its old frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    pub x_m: f64,
    pub y_m: f64,
    pub heading_rad: f64,
}

impl Motion {
    /// A point of the new robot frame in the old one.
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.heading_rad.sin_cos();
        [c * p[0] - s * p[1] + self.x_m, s * p[0] + c * p[1] + self.y_m]
    }

    /// A point of the old robot frame (3-D, z kept) in the new one.
    pub fn inverse_apply(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.heading_rad.sin_cos();
        let (dx, dy) = (p[0] - self.x_m, p[1] - self.y_m);
        [c * dx + s * dy, -s * dx + c * dy, p[2]]
    }
}

/// One feature at both stops: robot-frame points and their ground-plane covariances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair {
    pub old: [f64; 3],
    pub new: [f64; 3],
    pub old_cov: Sym2,
    pub new_cov: Sym2,
}

/// The prediction and how far it may be off (one standard deviation each).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prior {
    pub motion: Motion,
    pub sd: [f64; 3],
}

/// The solved motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    pub motion: Motion,
    /// Covariance of (x, y, heading).
    pub covariance: [[f64; 3]; 3],
    /// Features whose residual was implausible, dropped one by one.
    pub edited: usize,
    /// Features the solution rests on.
    pub used: usize,
    /// Root mean square of the used features' normalised residuals.
    pub rms: f64,
}

/// Too few features left to solve on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TooFew {
    pub left: usize,
    pub needed: usize,
}

/// Solves for the motion on the pairs whose `active` flag is set, clearing the flags of those
/// Gennery's editing drops (a normalised squared residual above `edit_chi2`).
pub fn solve(
    pairs: &[Pair],
    active: &mut [bool],
    prior: &Prior,
    edit_chi2: f64,
    min_points: usize,
) -> Result<Solution, TooFew> {
    let mut motion = prior.motion;
    let mut edited = 0;
    loop {
        let left = active.iter().filter(|a| **a).count();
        if left < min_points {
            return Err(TooFew { left, needed: min_points });
        }
        let h = gauss_newton(pairs, active, prior, &mut motion);
        let worst = (0..pairs.len())
            .filter(|&i| active[i])
            .map(|i| (i, residual(&pairs[i], &motion).1))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((i, chi2)) if chi2 > edit_chi2 => {
                active[i] = false;
                edited += 1;
            }
            _ => {
                let sum: f64 =
                    (0..pairs.len()).filter(|&i| active[i]).map(|i| residual(&pairs[i], &motion).1).sum();
                let covariance = inverse3(h).ok_or(TooFew { left, needed: min_points })?;
                return Ok(Solution {
                    motion,
                    covariance,
                    edited,
                    used: left,
                    rms: (sum / left as f64).sqrt(),
                });
            }
        }
    }
}

/// How far `motion` lies from the prediction: its squared distance in the prediction's standard
/// deviations (the heading's difference wrapped), a chi-square with three degrees of freedom
/// while the prediction's margins hold.
pub fn departure(motion: &Motion, prior: &Prior) -> f64 {
    let p = &prior.motion;
    let dh = (motion.heading_rad - p.heading_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
        - std::f64::consts::PI;
    let d = [motion.x_m - p.x_m, motion.y_m - p.y_m, dh];
    (0..3).map(|k| (d[k] / prior.sd[k]).powi(2)).sum()
}

/// Iterates from `motion` to the weighted least-squares motion; returns the normal matrix.
fn gauss_newton(pairs: &[Pair], active: &[bool], prior: &Prior, motion: &mut Motion) -> [[f64; 3]; 3] {
    let mut h = [[0.0; 3]; 3];
    for _ in 0..20 {
        h = [[0.0; 3]; 3];
        let mut g = [0.0; 3];
        let m = [motion.x_m, motion.y_m, motion.heading_rad];
        let p = [prior.motion.x_m, prior.motion.y_m, prior.motion.heading_rad];
        for k in 0..3 {
            h[k][k] = prior.sd[k].powi(-2);
            g[k] = h[k][k] * (m[k] - p[k]);
        }
        for (pair, _) in pairs.iter().zip(active).filter(|(_, a)| **a) {
            let (r, w, rb) = weighted(pair, motion);
            // d r / d (x, y, heading).
            let j = [[-1.0, 0.0, rb[1]], [0.0, -1.0, -rb[0]]];
            for a in 0..3 {
                let wj = [w[0] * j[0][a] + w[1] * j[1][a], w[1] * j[0][a] + w[2] * j[1][a]];
                for b in 0..3 {
                    h[a][b] += wj[0] * j[0][b] + wj[1] * j[1][b];
                }
                g[a] += wj[0] * r[0] + wj[1] * r[1];
            }
        }
        let Some(step) = solve3(h, g) else { break };
        motion.x_m -= step[0];
        motion.y_m -= step[1];
        motion.heading_rad -= step[2];
        if step[0].hypot(step[1]) < 1e-7 && step[2].abs() < 1e-8 {
            break;
        }
    }
    h
}

/// The pair's residual `old - T(new)`, its weight (the inverse of the residual's covariance)
/// and the new point turned into the old frame's axes.
fn weighted(pair: &Pair, motion: &Motion) -> ([f64; 2], Sym2, [f64; 2]) {
    let (s, c) = motion.heading_rad.sin_cos();
    let rb = [c * pair.new[0] - s * pair.new[1], s * pair.new[0] + c * pair.new[1]];
    let r = [pair.old[0] - rb[0] - motion.x_m, pair.old[1] - rb[1] - motion.y_m];
    // R Σ Rᵀ for the new point's covariance, added to the old point's.
    let [a, b, d] = pair.new_cov;
    let turned = [
        c * c * a - 2.0 * s * c * b + s * s * d,
        s * c * (a - d) + (c * c - s * s) * b,
        s * s * a + 2.0 * s * c * b + c * c * d,
    ];
    let cov = [pair.old_cov[0] + turned[0], pair.old_cov[1] + turned[1], pair.old_cov[2] + turned[2]];
    let det = cov[0] * cov[2] - cov[1] * cov[1];
    let w = if det > 0.0 { [cov[2] / det, -cov[1] / det, cov[0] / det] } else { [0.0; 3] };
    (r, w, rb)
}

/// The pair's residual and its normalised square (a chi-square with two degrees of freedom).
pub fn residual(pair: &Pair, motion: &Motion) -> ([f64; 2], f64) {
    let (r, w, _) = weighted(pair, motion);
    (r, r[0] * (w[0] * r[0] + w[1] * r[1]) + r[1] * (w[1] * r[0] + w[2] * r[1]))
}

/// `h x = g` for a symmetric positive definite 3x3 `h` (Cholesky); `None` if it is not.
pub(super) fn solve3(h: [[f64; 3]; 3], g: [f64; 3]) -> Option<[f64; 3]> {
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = h[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0; 3];
    for i in 0..3 {
        y[i] = (g[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        x[i] = (y[i] - (i + 1..3).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    Some(x)
}

/// The inverse of a symmetric positive definite 3x3 matrix, column by column.
pub(super) fn inverse3(h: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let cols = [solve3(h, [1.0, 0.0, 0.0])?, solve3(h, [0.0, 1.0, 0.0])?, solve3(h, [0.0, 0.0, 1.0])?];
    Some(std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(truth: &Motion, blunders: &[usize]) -> Vec<Pair> {
        let cov = [1e-4, 0.0, 1e-4];
        (0..20)
            .map(|i| {
                let new = [2.0 + 0.3 * i as f64, -2.0 + 0.21 * i as f64 % 4.0, 1.0];
                let [x, y] = truth.apply([new[0], new[1]]);
                let shift = if blunders.contains(&i) { 0.4 } else { 0.0 };
                Pair { old: [x + shift, y, 1.0], new, old_cov: cov, new_cov: cov }
            })
            .collect()
    }

    #[test]
    fn exact_pairs_give_the_motion_and_blunders_are_edited_out() {
        let truth = Motion { x_m: 0.4, y_m: -0.05, heading_rad: 0.08 };
        let prior =
            Prior { motion: Motion { x_m: 0.35, y_m: 0.0, heading_rad: 0.05 }, sd: [0.05, 0.05, 0.05] };
        let clean = pairs(&truth, &[]);
        let mut active = vec![true; clean.len()];
        let s = solve(&clean, &mut active, &prior, 13.8, 6).expect("solves");
        // The prior pulls a little; twenty points at 1 cm outweigh it by far.
        assert!((s.motion.x_m - 0.4).abs() < 1e-3 && (s.motion.heading_rad - 0.08).abs() < 1e-3, "{s:?}");
        assert_eq!((s.edited, s.used), (0, 20));

        let dirty = pairs(&truth, &[3, 11]);
        let mut active = vec![true; dirty.len()];
        let s = solve(&dirty, &mut active, &prior, 13.8, 6).expect("solves");
        assert_eq!(s.edited, 2, "{s:?}");
        assert!(!active[3] && !active[11]);
        assert!((s.motion.x_m - 0.4).abs() < 1e-3 && (s.motion.y_m + 0.05).abs() < 3e-3, "{s:?}");

        // The reasonableness limit's measure: in the prediction's sds, the heading wrapped.
        let near = Motion { x_m: 0.35 + 0.05, y_m: 0.1, heading_rad: std::f64::consts::TAU };
        assert!((departure(&near, &prior) - 6.0).abs() < 1e-9, "{}", departure(&near, &prior));

        let mut few = vec![false; dirty.len()];
        few[..4].fill(true);
        assert_eq!(solve(&dirty, &mut few, &prior, 13.8, 6), Err(TooFew { left: 4, needed: 6 }));
    }
}

//! Pose refinement for plan-level servoing (000 §5.6, after Kumar's 3D pose refinement): the
//! robot's pose `(x, y, heading)` and the camera mount's pitch that best project the matched
//! landmark vertices onto where correlation found them, by Gauss-Newton from the expected pose,
//! with the expected pose as a weak prior (a vertex row says little about the distance along the
//! hall) and the mount's surveyed pitch as another, look-alikes left out first (`consensus.rs`) and
//! matches that disagree with the rest dropped, worst first. The pitch is an unknown because it
//! moves every row alike (000 §5.5 Fig. 10): 3 mrad is 1.7 px at 554 px focal length, which a level
//! camera model reads as the vertices a third of a metre nearer or further at 8 m. The mount's yaw
//! needs no unknown of its own: it turns every column alike, as the heading does, and the position
//! is unaffected.

use harvey_msgs::Pose2;

use crate::servo::consensus::agreeing;
use crate::servo::linalg::{N, inverse, sandwich, solve_n};

/// The camera: pinhole at the robot's centre, looking along its heading, level as far as the
/// robot knows (the pitch is [`RefineParams::pitch_sd_rad`]'s unknown).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeCamera {
    pub focal_px: f64,
    /// Image centre (pixels).
    pub centre_px: [f64; 2],
    pub height_m: f64,
}

impl PinholeCamera {
    /// Where the world point `p` appears from `pose` through a level camera, or `None` behind it.
    pub fn project(&self, pose: Pose2, p: [f64; 3]) -> Option<[f64; 2]> {
        self.project_tilted(pose, 0.0, p)
    }

    /// …through a camera tilted `pitch_rad` down on its mount (small angles, as the renderer
    /// tilts it: every row's ray turned by the same angle).
    pub fn project_tilted(&self, pose: Pose2, pitch_rad: f64, p: [f64; 3]) -> Option<[f64; 2]> {
        let (dx, dy) = (p[0] - pose.x_m, p[1] - pose.y_m);
        let (c, s) = (pose.heading_rad.cos(), pose.heading_rad.sin());
        let (ahead, left) = (dx * c + dy * s, -dx * s + dy * c);
        (ahead > 0.05).then(|| {
            let f = self.focal_px;
            let down = ((self.height_m - p[2]) / ahead).atan() - pitch_rad;
            [self.centre_px[0] - f * left / ahead, self.centre_px[1] + f * down.tan()]
        })
    }
}

/// A landmark vertex and where it was found in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexMatch {
    pub world_m: [f64; 3],
    pub image_px: [f64; 2],
}

/// Settings: the priors' standard deviations and the outlier gate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineParams {
    /// How well the expected pose is known: along x and y (m) and in heading (rad).
    pub prior_sd: [f64; 3],
    /// How well the mount's pitch is known about level (rad): the world's `[survey]
    /// calibration_sd_rad`. Zero holds the camera level.
    pub pitch_sd_rad: f64,
    /// A match's image position is good to this (pixels)…
    pub image_sd_px: f64,
    /// …and its vertex's mapped place to this (m: the world's `[survey] position_sd_m`). It
    /// does not weight the matches (a near vertex carries the depth), but it is in
    /// [`Refined::map_position_sd_m`].
    pub map_sd_m: f64,
    /// …and one further than this from its projection is dropped.
    pub gate_px: f64,
}

/// The refined pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    pub pose: Pose2,
    /// The mount's pitch the matches say (rad, down positive).
    pub pitch_rad: f64,
    /// Root-mean-square image residual of the matches kept (pixels).
    pub rms_px: f64,
    /// Indices of the matches kept.
    pub kept: Vec<usize>,
    /// How well the matches and the prior fix the position: the root of the position
    /// covariance's trace (m), for image rows good to `image_sd_px`. Vertices all at one depth
    /// leave sideways and turned hard to tell apart, and this large.
    pub position_sd_m: f64,
    /// The same with each vertex's map error in as well (`RefineParams::map_sd_m`, moving it up
    /// to `focal * map_sd / depth` pixels): how far the fix may be from the truth, which no
    /// image residual shows.
    pub map_position_sd_m: f64,
}

impl Refined {
    /// How far the fix moved the pose from `expected`, squared, in the prior's standard
    /// deviations (`prior_sd`: x and y in m, heading in rad): chi-square with three degrees of
    /// freedom for a fix that agrees with its prior.
    pub fn surprise(&self, expected: Pose2, prior_sd: [f64; 3]) -> f64 {
        surprise(self.pose, expected, prior_sd)
    }
}

/// A fix that moves the pose further from the expected one than this (chi-square, three degrees
/// of freedom, 0.999) says more about false matches than about the robot: refused.
pub const SURPRISE_LIMIT: f64 = 16.27;

/// How far `pose` lies from `expected`, squared, in the prior's standard deviations.
pub fn surprise(pose: Pose2, expected: Pose2, prior_sd: [f64; 3]) -> f64 {
    let shift = [
        pose.x_m - expected.x_m,
        pose.y_m - expected.y_m,
        harvey_geometry::wrap(pose.heading_rad - expected.heading_rad),
    ];
    shift.iter().zip(prior_sd).map(|(d, sd)| (d / sd.max(HELD_SD)).powi(2)).sum()
}

/// The smallest prior standard deviation used, so that a pitch held level keeps the normal
/// equations well scaled.
pub const HELD_SD: f64 = 1e-6;

/// Gauss-Newton on `(x, y, heading, pitch)`; `None` with fewer than two matches left.
pub fn refine(
    cam: &PinholeCamera,
    expected: Pose2,
    matches: &[VertexMatch],
    p: &RefineParams,
) -> Option<Refined> {
    // From the largest set that agrees with the pose some pair of them gives: a vertex taken for
    // a look-alike elsewhere in the image can pull an all-in first solution further from the
    // truth than the good matches lie, and dropping the worst from there may keep the wrong ones.
    let mut kept = agreeing(cam, expected, matches, p);
    loop {
        if kept.len() < 2 {
            return None;
        }
        let (pose, pitch_rad, normal) = solve(cam, expected, matches, &kept, p)?;
        let residual = |i: usize| residual_px(cam, pose, pitch_rad, &matches[i]);
        let (worst, r) = kept.iter().map(|&i| (i, residual(i))).max_by(|a, b| a.1.total_cmp(&b.1))?;
        if r > p.gate_px {
            kept.retain(|&i| i != worst);
            continue;
        }
        let rms = (kept.iter().map(|&i| residual(i).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
        let position_sd = |c: Option<[[f64; N]; N]>| c.map_or(f64::INFINITY, |c| (c[0][0] + c[1][1]).sqrt());
        let position_sd_m = position_sd(inverse(normal.information));
        let map_position_sd_m = position_sd(sandwich(normal.information, normal.spread));
        return Some(Refined { pose, pitch_rad, rms_px: rms, kept, position_sd_m, map_position_sd_m });
    }
}

/// How far `m` lies from where it projects from `pose` with the mount pitched `pitch_rad` (px).
pub(super) fn residual_px(cam: &PinholeCamera, pose: Pose2, pitch_rad: f64, m: &VertexMatch) -> f64 {
    cam.project_tilted(pose, pitch_rad, m.world_m)
        .map_or(f64::INFINITY, |q| (q[0] - m.image_px[0]).hypot(q[1] - m.image_px[1]))
}

/// The pose and pitch that best fit the matches `kept` with the priors.
pub(super) fn fit(
    cam: &PinholeCamera,
    expected: Pose2,
    m: &[VertexMatch],
    kept: &[usize],
    p: &RefineParams,
) -> Option<(Pose2, f64)> {
    solve(cam, expected, m, kept, p).map(|(pose, pitch, _)| (pose, pitch))
}

/// The normal equations at the solution: `information = Jᵀ W J` (the inverse of the covariance
/// for the image noise alone) and `spread = Jᵀ W R W J`, with `R` the image noise and the map
/// error together.
struct Normal {
    information: [[f64; N]; N],
    spread: [[f64; N]; N],
}

/// The weighted least-squares pose and pitch of the matches `kept` with the priors, by
/// Gauss-Newton, and the normal equations at it.
fn solve(
    cam: &PinholeCamera,
    expected: Pose2,
    m: &[VertexMatch],
    kept: &[usize],
    p: &RefineParams,
) -> Option<(Pose2, f64, Normal)> {
    let prior = [expected.x_m, expected.y_m, expected.heading_rad, 0.0];
    let prior_sd = [p.prior_sd[0], p.prior_sd[1], p.prior_sd[2], p.pitch_sd_rad].map(|sd| sd.max(HELD_SD));
    let mut v = prior;
    let mut normal = Normal { information: [[0.0; N]; N], spread: [[0.0; N]; N] };
    for _ in 0..20 {
        // Normal equations A d = b from the image rows and columns and the priors; `spread`
        // beside them with each row's variance (`var`) as the image noise and map error give it.
        let (mut a, mut b, mut spread) = ([[0.0f64; N]; N], [0.0f64; N], [[0.0f64; N]; N]);
        let mut add = |j: [f64; N], r: f64, w: f64, var: f64| {
            for ((row, spread_row), &jr) in a.iter_mut().zip(spread.iter_mut()).zip(&j) {
                for ((cell, spread_cell), &jc) in row.iter_mut().zip(spread_row.iter_mut()).zip(&j) {
                    *cell += w * jr * jc;
                    *spread_cell += w * w * var * jr * jc;
                }
            }
            for (bi, &ji) in b.iter_mut().zip(&j) {
                *bi += w * ji * r;
            }
        };
        let image_var = p.image_sd_px * p.image_sd_px;
        for &i in kept {
            let (at, jacobian, var) = image_rows(cam, v, m[i].world_m, p)?;
            for axis in 0..2 {
                add(jacobian[axis], m[i].image_px[axis] - at[axis], 1.0 / image_var, var);
            }
        }
        for k in 0..N {
            let mut j = [0.0; N];
            j[k] = 1.0;
            let var = prior_sd[k] * prior_sd[k];
            add(j, prior[k] - v[k], 1.0 / var, var);
        }
        normal = Normal { information: a, spread };
        let d = solve_n(a, b)?;
        for k in 0..N {
            v[k] += d[k];
        }
        if d.iter().all(|x| x.abs() < 1e-7) {
            break;
        }
    }
    Some((Pose2 { x_m: v[0], y_m: v[1], heading_rad: v[2] }, v[3], normal))
}

/// Where world point `w` appears from `(x, y, heading, pitch)` = `v`, the image column's and
/// row's derivatives by each of them (forward differences), and either's variance: the image
/// noise and the map error at the point's depth.
pub fn image_rows(
    cam: &PinholeCamera,
    v: [f64; N],
    w: [f64; 3],
    p: &RefineParams,
) -> Option<([f64; 2], [[f64; N]; 2], f64)> {
    let project =
        |v: [f64; N]| cam.project_tilted(Pose2 { x_m: v[0], y_m: v[1], heading_rad: v[2] }, v[3], w);
    let at = project(v)?;
    let (dx, dy) = (w[0] - v[0], w[1] - v[1]);
    let depth = (dx * v[2].cos() + dy * v[2].sin()).max(0.05);
    let var = p.image_sd_px * p.image_sd_px + (cam.focal_px * p.map_sd_m / depth).powi(2);
    let mut jacobian = [[0.0; N]; 2];
    for (axis, row) in jacobian.iter_mut().enumerate() {
        for (k, jk) in row.iter_mut().enumerate() {
            let mut h = v;
            h[k] += 1e-6;
            *jk = (project(h)?[axis] - at[axis]) / 1e-6;
        }
    }
    Some((at, jacobian, var))
}

#[cfg(test)]
#[path = "pose_tests.rs"]
pub(crate) mod tests;

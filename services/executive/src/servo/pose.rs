//! Pose refinement for plan-level servoing (000 §5.6, after Kumar's 3D pose refinement): the
//! robot's pose `(x, y, heading)` that best projects the matched landmark vertices onto where
//! correlation found them, by Gauss-Newton from the expected pose, with the expected pose as a
//! weak prior (a vertex row says little about the distance along the hall) and matches that
//! disagree with the rest dropped, worst first.

use harvey_msgs::Pose2;

/// The camera: pinhole at the robot's centre, level, looking along its heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeCamera {
    pub focal_px: f64,
    /// Image centre (pixels).
    pub centre_px: [f64; 2],
    pub height_m: f64,
}

impl PinholeCamera {
    /// Where the world point `p` appears from `pose`, or `None` behind the camera.
    pub fn project(&self, pose: Pose2, p: [f64; 3]) -> Option<[f64; 2]> {
        let (dx, dy) = (p[0] - pose.x_m, p[1] - pose.y_m);
        let (c, s) = (pose.heading_rad.cos(), pose.heading_rad.sin());
        let (ahead, left) = (dx * c + dy * s, -dx * s + dy * c);
        (ahead > 0.05).then(|| {
            let f = self.focal_px;
            [self.centre_px[0] - f * left / ahead, self.centre_px[1] - f * (p[2] - self.height_m) / ahead]
        })
    }
}

/// A landmark vertex and where it was found in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexMatch {
    pub world_m: [f64; 3],
    pub image_px: [f64; 2],
}

/// Settings: the prior's standard deviations and the outlier gate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineParams {
    /// How well the expected pose is known: along x and y (m) and in heading (rad).
    pub prior_sd: [f64; 3],
    /// A match's image position is good to this (pixels)…
    pub image_sd_px: f64,
    /// …and one further than this from its projection is dropped.
    pub gate_px: f64,
}

/// The refined pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    pub pose: Pose2,
    /// Root-mean-square image residual of the matches kept (pixels).
    pub rms_px: f64,
    /// Indices of the matches kept.
    pub kept: Vec<usize>,
    /// How well the matches and the prior fix the position: the root of the position
    /// covariance's trace (m), for image rows good to `image_sd_px`. Vertices all at one depth
    /// leave sideways and turned hard to tell apart, and this large.
    pub position_sd_m: f64,
}

/// Gauss-Newton on `(x, y, heading)`; `None` with fewer than two matches left.
pub fn refine(
    cam: &PinholeCamera,
    expected: Pose2,
    matches: &[VertexMatch],
    p: &RefineParams,
) -> Option<Refined> {
    let mut kept: Vec<usize> = (0..matches.len()).collect();
    loop {
        if kept.len() < 2 {
            return None;
        }
        let (pose, information) = solve(cam, expected, matches, &kept, p)?;
        let residual = |i: usize| {
            cam.project(pose, matches[i].world_m).map_or(f64::INFINITY, |q| {
                (q[0] - matches[i].image_px[0]).hypot(q[1] - matches[i].image_px[1])
            })
        };
        let (worst, r) = kept.iter().map(|&i| (i, residual(i))).max_by(|a, b| a.1.total_cmp(&b.1))?;
        if r > p.gate_px {
            kept.retain(|&i| i != worst);
            continue;
        }
        let rms = (kept.iter().map(|&i| residual(i).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
        let variance = |k: usize| {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            solve3(information, e).map_or(f64::INFINITY, |c| c[k])
        };
        let position_sd_m = (variance(0) + variance(1)).sqrt();
        return Some(Refined { pose, rms_px: rms, kept, position_sd_m });
    }
}

/// The weighted least-squares pose of the matches `kept` with the prior, by Gauss-Newton, and
/// the information matrix at it (the inverse of its covariance).
fn solve(
    cam: &PinholeCamera,
    expected: Pose2,
    m: &[VertexMatch],
    kept: &[usize],
    p: &RefineParams,
) -> Option<(Pose2, [[f64; 3]; 3])> {
    let as_pose = |v: [f64; 3]| Pose2 { x_m: v[0], y_m: v[1], heading_rad: v[2] };
    let prior = [expected.x_m, expected.y_m, expected.heading_rad];
    let mut v = prior;
    let mut information = [[0.0f64; 3]; 3];
    for _ in 0..20 {
        // Normal equations A d = b from the image rows and the prior.
        let (mut a, mut b) = ([[0.0f64; 3]; 3], [0.0f64; 3]);
        let mut add = |j: [f64; 3], r: f64, w: f64| {
            for (row, &jr) in a.iter_mut().zip(&j) {
                for (cell, &jc) in row.iter_mut().zip(&j) {
                    *cell += w * jr * jc;
                }
            }
            for (bi, &ji) in b.iter_mut().zip(&j) {
                *bi += w * ji * r;
            }
        };
        let w_img = 1.0 / (p.image_sd_px * p.image_sd_px);
        for &i in kept {
            let at = cam.project(as_pose(v), m[i].world_m)?;
            for (axis, &now) in at.iter().enumerate() {
                let mut j = [0.0; 3];
                for (k, jk) in j.iter_mut().enumerate() {
                    let mut h = v;
                    h[k] += 1e-6;
                    *jk = (cam.project(as_pose(h), m[i].world_m)?[axis] - now) / 1e-6;
                }
                add(j, m[i].image_px[axis] - now, w_img);
            }
        }
        for k in 0..3 {
            let mut j = [0.0; 3];
            j[k] = 1.0;
            add(j, prior[k] - v[k], 1.0 / (p.prior_sd[k] * p.prior_sd[k]));
        }
        information = a;
        let d = solve3(a, b)?;
        for k in 0..3 {
            v[k] += d[k];
        }
        if d.iter().all(|x| x.abs() < 1e-7) {
            break;
        }
    }
    Some((as_pose(v), information))
}

/// `A x = b` for a 3x3 system (Cramer's rule); `None` when singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = a;
        for r in 0..3 {
            m[r][k] = b[r];
        }
        *xk = det(m) / d;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    use harvey_geometry::INCH;

    fn cam() -> PinholeCamera {
        PinholeCamera { focal_px: 554.0, centre_px: [320.0, 240.0], height_m: 1.2 }
    }

    /// Vertices down a hallway: a notice board, a door and a sign at 7 to 16 m.
    fn vertices() -> Vec<[f64; 3]> {
        vec![
            [6.9, 1.0, 1.8],
            [8.1, 1.0, 1.8],
            [6.9, 1.0, 1.1],
            [9.0, -1.0, 2.1],
            [8.1, -1.0, 2.1],
            [16.0, 0.2, 2.3],
            [16.0, -0.2, 2.3],
            [16.0, 0.2, 2.1],
        ]
    }

    #[test]
    fn an_expected_pose_inches_off_is_refined_to_the_true_one_despite_an_outlier() {
        let truth = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.01 };
        let params = RefineParams { prior_sd: [0.3, 0.3, 0.1], image_sd_px: 0.5, gate_px: 3.0 };
        let mut matches: Vec<VertexMatch> = vertices()
            .into_iter()
            .enumerate()
            .map(|(k, w)| {
                let q = cam().project(truth, w).expect("in front");
                // Correlation's error: a few tenths of a pixel.
                let e = 0.3 * ((k as f64) * 2.1).sin();
                VertexMatch { world_m: w, image_px: [q[0] + e, q[1] - e] }
            })
            .collect();
        matches[3].image_px[0] += 12.0; // a false match
        for dy_in in [-6.0, -3.0, 3.0, 6.0] {
            let expected = Pose2 { y_m: dy_in * INCH, heading_rad: 0.0, ..truth };
            let r = refine(&cam(), expected, &matches, &params).expect("refines");
            let err = (r.pose.x_m - truth.x_m).hypot(r.pose.y_m - truth.y_m);
            assert!(err < 1.0 * INCH, "expected {dy_in} in off: refined {} in off", err / INCH);
            assert!((r.pose.heading_rad - truth.heading_rad).abs() < 0.002);
            assert!(!r.kept.contains(&3) && r.kept.len() == 7 && r.rms_px < 1.0, "{r:?}");
        }
        // Nothing to go on: no answer.
        assert!(refine(&cam(), truth, &matches[..1], &params).is_none());
    }

    #[test]
    fn vertices_all_at_one_depth_fix_the_position_loosely() {
        let params = RefineParams { prior_sd: [0.3, 0.3, 0.1], image_sd_px: 0.5, gate_px: 3.0 };
        let at = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        let exact = |w: &[[f64; 3]]| -> Vec<VertexMatch> {
            w.iter()
                .map(|&w| VertexMatch { world_m: w, image_px: cam().project(at, w).expect("in front") })
                .collect()
        };
        // The end wall's six, 4.5 m off; then three of them with three nearer ones on a side wall.
        let wall = [
            [4.5, 0.2, 2.3],
            [4.5, -0.2, 2.3],
            [4.5, 0.2, 2.1],
            [4.5, -0.2, 2.1],
            [4.5, 1.0, 0.1],
            [4.5, -1.0, 0.1],
        ];
        let mixed = [wall[0], wall[1], wall[4], [2.0, -1.0, 1.5], [2.5, -1.0, 0.9], [3.0, -1.0, 1.5]];
        let flat = refine(&cam(), at, &exact(&wall), &params).expect("refines");
        let deep = refine(&cam(), at, &exact(&mixed), &params).expect("refines");
        assert!(
            flat.position_sd_m > 0.04 && deep.position_sd_m < 0.02,
            "{} against {}",
            flat.position_sd_m,
            deep.position_sd_m
        );
    }
}

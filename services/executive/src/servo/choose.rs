//! Which landmark vertices to ask for when more are in view than a fix can ask for: landmarks
//! chosen for "what kind of information they offer the servoing procedure" (000 §5.1), greedily,
//! each next the one that most shrinks the fix's expected position spread.

use harvey_msgs::Pose2;

use crate::servo::linalg::{Matrix, N, inverse};
use crate::servo::pose::{HELD_SD, PinholeCamera, RefineParams, image_rows};

/// At most `max` of `candidates` (`(index, vertex in the world)`), as indices: from the priors
/// alone, each next the vertex whose two image coordinates, seen from `pose` with the image
/// noise and the map's error at its depth, leave the smallest position variance (x plus y, the
/// heading and the mount's pitch solved for beside them); ties to the earlier candidate.
pub fn most_telling(
    cam: &PinholeCamera,
    pose: Pose2,
    params: &RefineParams,
    candidates: &[(usize, [f64; 3])],
    max: usize,
) -> Vec<usize> {
    let at = [pose.x_m, pose.y_m, pose.heading_rad, 0.0];
    let prior = [params.prior_sd[0], params.prior_sd[1], params.prior_sd[2], params.pitch_sd_rad];
    let mut information: Matrix = [[0.0; N]; N];
    for (k, sd) in prior.iter().enumerate() {
        information[k][k] = 1.0 / sd.max(HELD_SD).powi(2);
    }
    // Each candidate's information, `Jᵀ J / var` over its column and row.
    let mut left: Vec<(usize, Matrix)> = candidates
        .iter()
        .filter_map(|&(i, w)| {
            let (_, j, var) = image_rows(cam, at, w, params)?;
            let mut m = [[0.0; N]; N];
            for (r, row) in m.iter_mut().enumerate() {
                for (c, cell) in row.iter_mut().enumerate() {
                    *cell = (j[0][r] * j[0][c] + j[1][r] * j[1][c]) / var;
                }
            }
            Some((i, m))
        })
        .collect();
    let position_var = |a: &Matrix, b: &Matrix| {
        let mut sum = *a;
        for (row, brow) in sum.iter_mut().zip(b) {
            for (cell, bc) in row.iter_mut().zip(brow) {
                *cell += bc;
            }
        }
        inverse(sum).map_or(f64::INFINITY, |c| c[0][0] + c[1][1])
    };
    let mut chosen = Vec::new();
    while chosen.len() < max && !left.is_empty() {
        let mut best = (0, f64::INFINITY);
        for (k, (_, m)) in left.iter().enumerate() {
            let v = position_var(&information, m);
            if v < best.1 {
                best = (k, v);
            }
        }
        let (i, m) = left.remove(best.0);
        for (row, mrow) in information.iter_mut().zip(&m) {
            for (cell, mc) in row.iter_mut().zip(mrow) {
                *cell += mc;
            }
        }
        chosen.push(i);
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> PinholeCamera {
        PinholeCamera { focal_px: 554.0, centre_px: [320.0, 240.0], height_m: 1.0 }
    }

    fn params() -> RefineParams {
        RefineParams {
            prior_sd: [0.3, 0.3, 0.05],
            pitch_sd_rad: 0.003,
            image_sd_px: 0.5,
            map_sd_m: 0.01,
            gate_px: 3.0,
        }
    }

    #[test]
    fn far_and_wide_beats_a_near_cluster_in_one_spot() {
        let pose = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        // Four vertices bunched 3 m ahead on the left wall, one low near one on the right, one
        // far on the end wall: of three, the cluster gives one and the two others are taken.
        let candidates = [
            (0, [3.0, 1.0, 1.5]),
            (1, [3.05, 1.0, 1.5]),
            (2, [3.0, 1.0, 1.45]),
            (3, [3.05, 1.0, 1.45]),
            (4, [4.0, -1.0, 0.1]),
            (5, [12.0, 0.2, 2.0]),
        ];
        let mut chosen = most_telling(&cam(), pose, &params(), &candidates, 3);
        chosen.sort_unstable();
        assert_eq!(chosen.len(), 3);
        assert_eq!(chosen.iter().filter(|&&i| i < 4).count(), 1, "{chosen:?}");
        assert!(chosen.contains(&4) && chosen.contains(&5), "{chosen:?}");
    }

    #[test]
    fn every_candidate_is_taken_when_there_is_room_and_none_behind_the_camera() {
        let pose = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
        let candidates = [(7, [3.0, 1.0, 1.5]), (9, [-3.0, 0.0, 1.0]), (11, [5.0, -1.0, 0.1])];
        let mut chosen = most_telling(&cam(), pose, &params(), &candidates, 16);
        chosen.sort_unstable();
        assert_eq!(chosen, [7, 11]);
    }
}

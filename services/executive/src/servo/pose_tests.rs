//! Pose refinement on made-up matches: outliers, one depth, a tilted mount, the map's error.

use super::*;

use harvey_geometry::INCH;

pub(crate) fn cam() -> PinholeCamera {
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

/// A loose prior, a level camera known to be level, a map taken as exact.
pub(crate) fn params() -> RefineParams {
    RefineParams {
        prior_sd: [0.3, 0.3, 0.1],
        pitch_sd_rad: 0.0,
        image_sd_px: 0.5,
        map_sd_m: 0.0,
        gate_px: 3.0,
    }
}

#[test]
fn an_expected_pose_inches_off_is_refined_to_the_true_one_despite_an_outlier() {
    let truth = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.01 };
    let params = params();
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
    let params = params();
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

#[test]
fn a_mount_tilted_a_few_milliradians_is_solved_for_not_read_as_distance() {
    let truth = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
    let tilt = 0.004;
    let matches: Vec<VertexMatch> = vertices()
        .into_iter()
        .map(|w| VertexMatch {
            world_m: w,
            image_px: cam().project_tilted(truth, tilt, w).expect("in front"),
        })
        .collect();
    let expected = Pose2 { x_m: 0.1, y_m: 0.05, ..truth };
    let error = |pitch_sd_rad: f64| {
        let params = RefineParams {
            prior_sd: [0.3, 0.3, 0.1],
            pitch_sd_rad,
            image_sd_px: 0.5,
            map_sd_m: 0.0,
            gate_px: 30.0,
        };
        let r = refine(&cam(), expected, &matches, &params).expect("refines");
        ((r.pose.x_m - truth.x_m).hypot(r.pose.y_m - truth.y_m), r.pitch_rad, r.rms_px)
    };
    let (level, _, level_rms) = error(0.0);
    let (solved, pitch, rms) = error(0.003);
    assert!(level > 2.0 * INCH, "a level model reads the tilt as {} in", level / INCH);
    assert!(solved < 0.5 * INCH && (pitch - tilt).abs() < 0.001, "{} in, pitch {pitch}", solved / INCH);
    assert!(rms < 0.2 && level_rms > rms, "rms {rms} px against {level_rms} px level");
}

#[test]
fn the_map_s_error_widens_the_fix_s_spread_and_a_far_jump_is_surprising() {
    let at = Pose2 { x_m: 0.0, y_m: 0.0, heading_rad: 0.0 };
    let matches: Vec<VertexMatch> = vertices()
        .into_iter()
        .map(|w| VertexMatch { world_m: w, image_px: cam().project(at, w).expect("in front") })
        .collect();
    let exact = refine(&cam(), at, &matches, &params()).expect("refines");
    let surveyed =
        refine(&cam(), at, &matches, &RefineParams { map_sd_m: 0.01, ..params() }).expect("refines");
    assert!((exact.map_position_sd_m - exact.position_sd_m).abs() < 1e-9, "{exact:?}");
    assert!(surveyed.map_position_sd_m > 1.5 * surveyed.position_sd_m, "{surveyed:?}");
    assert_eq!(surveyed.pose, exact.pose, "the map's error does not weight the matches");
    // Expected 0.3 m and 0.1 rad off (one sd each): surprise 2; three sd off: 18.
    let shifted = |k: f64| Pose2 { x_m: 0.3 * k, heading_rad: 0.1 * k, ..at };
    assert!((exact.surprise(shifted(1.0), [0.3, 0.3, 0.1]) - 2.0).abs() < 0.01);
    assert!(exact.surprise(shifted(3.0), [0.3, 0.3, 0.1]) > 16.27);
}

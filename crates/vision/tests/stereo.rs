//! Two-camera stereo on rendered frames (003): parallel cameras 0.3 m apart in the hallway; the
//! depths of matched interesting points agree with ray-cast truth, matches keep to the near/far
//! limits, and a right camera two rows out of alignment is still matched within its band.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_vision::moravec::MoravecParams;
use harvey_vision::stereo::{Stereo, StereoParams};
use harvey_vision::{Gray, Rect};
use harvey_world::{Pose2, World};

mod common;

const W: u32 = 640;
const H: u32 = 480;

fn hallway() -> World {
    harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
}

fn render(w: &World, pose: Pose2) -> Vec<u8> {
    let mut r = Renderer::new(w, W, H, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(w, pose, &mut px).expect("renders");
    px
}

fn params(w: &World, band_rows: usize) -> StereoParams {
    StereoParams {
        focal_px: w.camera.focal_for(W) as f32,
        baseline_m: 0.3,
        band_rows,
        near_m: 1.5,
        far_m: 12.0,
        patch: 9,
        min_score: 0.98,
        min_margin: 0.0,
        moravec: MoravecParams { window: 5, threshold: 3000, suppress_radius: 4, max_corners: 150 },
    }
}

#[test]
fn stereo_depths_agree_with_the_truth_within_the_near_far_limits() {
    let w = hallway();
    let left_pose = Pose2::new(2.0, 0.15, 0.1);
    let (c, s) = (left_pose.heading_rad.cos(), left_pose.heading_rad.sin());
    // The right camera 0.3 m to the right (minus y in the camera's own frame).
    let right_pose = Pose2 { x_m: left_pose.x_m + 0.3 * s, y_m: left_pose.y_m - 0.3 * c, ..left_pose };
    let (l, r) = (render(&w, left_pose), render(&w, right_pose));
    let (lg, rg) =
        (Gray::new(&l, 640, 480, 640).expect("left"), Gray::new(&r, 640, 480, 640).expect("right"));
    let p = params(&w, 1);
    let mut st = Stereo::default();
    let found = st.match_points(&lg, &rg, Rect::new(0, 0, 640, 480), &p).expect("matches").to_vec();
    let mut errors: Vec<f64> = found
        .iter()
        .map(|m| {
            assert!((1.5..=12.0).contains(&m.depth_m), "{m:?}");
            let (t, _) = common::feature(&w, [W, H], left_pose, m.left);
            (f64::from(m.depth_m) - t).abs() / t
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    let median = errors[errors.len() / 2];
    let good = errors.iter().filter(|e| **e < 0.05).count();
    println!("{} matches, median depth error {:.2} %, {good} within 5 %", found.len(), 100.0 * median);
    assert!(found.len() >= 30, "{} matches", found.len());
    assert!(median < 0.02, "median error {median}");
    assert!(good as f64 >= 0.9 * found.len() as f64, "{good} of {}", found.len());

    // Two rows of vertical misalignment: a band of 3 rows still finds the points, 2 rows down.
    let shifted: Vec<u8> = (0..480)
        .flat_map(|y: usize| {
            let src = y.saturating_sub(2);
            r[src * 640..(src + 1) * 640].to_vec()
        })
        .collect();
    let sg = Gray::new(&shifted, 640, 480, 640).expect("shifted");
    let banded =
        st.match_points(&lg, &sg, Rect::new(0, 0, 640, 480), &params(&w, 3)).expect("matches").to_vec();
    let mut offsets: Vec<f32> = banded.iter().map(|m| m.row_offset).collect();
    offsets.sort_by(f32::total_cmp);
    let on_two = offsets.iter().filter(|o| (**o - 2.0).abs() < 0.5).count();
    println!(
        "band search: {on_two} of {} matches 2 rows down, median offset {}",
        banded.len(),
        offsets[offsets.len() / 2]
    );
    // Points on vertical edges slide along them (the aperture problem): most, not all, land
    // on the right row.
    assert!((offsets[offsets.len() / 2] - 2.0).abs() < 0.25);
    assert!(
        banded.len() >= 30 && on_two as f64 >= 0.75 * banded.len() as f64,
        "{on_two} of {}",
        banded.len()
    );
}

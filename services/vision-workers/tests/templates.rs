//! Landmark matching on rendered frames: a template ray-traced from the expected pose is found by
//! reflectance-normalised correlation within 1 px of where the landmark truly projects, when the
//! expected pose is right or 3 inches off, under sensor noise and uneven lighting.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::Encoding;
use harvey_render::{Effects, Renderer};
use harvey_vision::nc::{Correlator, Template};
use harvey_vision::{Gray, Rect};
use harvey_vision_workers::templates;
use harvey_world::{Pose2, World};

fn hallway() -> World {
    harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads")
}

/// A 640x480 frame from the true pose, with 3 grey levels of noise and 30 % vignetting.
fn frame(w: &World, pose: Pose2, seed: u64) -> Vec<u8> {
    let mut r = Renderer::new(w, 640, 480, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    r.render(w, pose, &mut px).expect("renders");
    Effects::noisy(0.3, 3.0, seed).apply(640, 480, 1, seed, &mut px);
    px
}

#[test]
fn a_ray_traced_template_is_found_within_a_pixel_of_the_true_projection() {
    let w = hallway();
    let sign = w.landmark("office-sign").expect("the office sign");
    // The sign's lower-left corner: a vertex where regions of different reflectance meet.
    let corner = [sign.position_m[0] - 0.2, sign.position_m[1], sign.position_m[2] - 0.15];
    let mut worst: f64 = 0.0;
    for (k, truth) in [(8.0, 0.0, 0.3), (7.0, -0.3, 0.45), (9.0, 0.2, 0.5), (6.5, 0.1, 0.25)]
        .map(|(x, y, th)| Pose2::new(x, y, th))
        .into_iter()
        .enumerate()
    {
        let img = frame(&w, truth, k as u64 + 1);
        let gray = Gray::new(&img, 640, 480, 640).expect("frame");
        let [tu, tv] = w.camera.project(640, 480, truth, corner).expect("in view");
        // Expected poses: right, and 3 or 6 inches to the side (000 Table 1).
        for dy in [0.0, 0.0762, -0.1524] {
            let expected = Pose2 { y_m: truth.y_m + dy, ..truth };
            let t = templates::build(&w, expected, corner, 640, 480, 24).expect("template in view");
            // Look in a window 64 px round the expectation.
            let [eu, ev] = t.projection;
            let win = Rect::new(
                (eu - 32.0) as usize,
                (ev - 32.0) as usize,
                (eu + 32.0) as usize,
                (ev + 32.0) as usize,
            );
            let mut c = Correlator::default();
            let m = c.best(&gray, win, &Template::new(&t.pixels).expect("template")).expect("correlates");
            // The match places the template; the corner sits where it sat in the template.
            let found = [
                m.centre[0] as f64 - t.pixels.width as f64 / 2.0 + (eu - t.origin[0] as f64),
                m.centre[1] as f64 - t.pixels.height as f64 / 2.0 + (ev - t.origin[1] as f64),
            ];
            let err = (found[0] - tu).hypot(found[1] - tv);
            println!("pose {k} offset {dy:+.3} m: score {:.4}, error {err:.2} px", m.score);
            assert!(m.score > 0.99, "pose {k}, offset {dy}: score {}", m.score);
            // Six inches off, a sign seen this obliquely (77 degrees from its normal at pose 2)
            // changes shape enough to pull the peak: printed, not asserted; plan-level servoing
            // re-renders the template from the refined pose.
            if dy.abs() < 0.1 {
                worst = worst.max(err);
            }
        }
    }
    assert!(worst <= 1.0, "worst error {worst:.2} px");
}

#[test]
fn selected_vertices_are_found_where_they_project() {
    // Landmark selection (000 §5.2) then matching (000 §5.4), from the pose the frame was taken at.
    let w = hallway();
    let truth = Pose2::new(8.0, 0.0, 0.3);
    let img = frame(&w, truth, 9);
    let gray = Gray::new(&img, 640, 480, 640).expect("frame");
    let chosen = harvey_world::selection::select(&w, truth, [640, 480], 40.0, 12.0, 0.15);
    assert!(chosen.len() >= 4, "{chosen:?}");
    let mut c = Correlator::default();
    for v in chosen.iter().take(8) {
        let t = templates::build(&w, truth, v.point_m, 640, 480, 24).expect("template");
        let [eu, ev] = t.projection;
        let win =
            Rect::new((eu - 32.0) as usize, (ev - 32.0) as usize, (eu + 32.0) as usize, (ev + 32.0) as usize);
        let m = c.best(&gray, win, &Template::new(&t.pixels).expect("template")).expect("correlates");
        let found = [
            m.centre[0] as f64 - 12.0 + (eu - t.origin[0] as f64),
            m.centre[1] as f64 - 12.0 + (ev - t.origin[1] as f64),
        ];
        let err = (found[0] - eu).hypot(found[1] - ev);
        assert!(err <= 1.0 && m.score > 0.99, "vertex {:?}: error {err:.2} px, score {}", v.point_m, m.score);
    }
}

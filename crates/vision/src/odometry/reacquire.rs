//! Reacquiring a feature on the time axis (003 "Constraints on Correspondence"): the motion
//! estimate with its margins of error defines a box in the new left image in which the feature
//! should appear. The box is the hull of the feature's projections under the prediction pushed
//! to its margins in x, y and heading, with the feature's range pushed to its own; a feature
//! whose predicted position has left the image has drifted out of view.

use super::rig::Rig;
use super::solve::{Motion, Prior};
use crate::image::Rect;

/// The window to search for the patch (`half` pixels either side of its centre) of the feature
/// at `point` (old robot frame), in a `size` image; `None` once it has left the view.
pub fn predicted_box(
    rig: &Rig,
    point: [f64; 3],
    prior: &Prior,
    sigmas: f64,
    size: [usize; 2],
    half: usize,
) -> Option<Rect> {
    let (w, h) = (size[0] as f64, size[1] as f64);
    let margin = half as f64;
    let centre = rig.project(prior.motion.inverse_apply(point))?;
    if !(margin..w - margin).contains(&centre[0]) || !(margin..h - margin).contains(&centre[1]) {
        return None;
    }
    // The point slid along its ray from the left camera by its range's error.
    let eye = [0.0, rig.baseline_m / 2.0, rig.height_m];
    let ray = [point[0] - eye[0], point[1] - eye[1], point[2] - eye[2]];
    let length = (ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2]).sqrt();
    let slide = (sigmas * rig.range_sd(point) / length).min(0.5);
    let mut hull = [centre[0], centre[1], centre[0], centre[1]];
    for scale in [1.0 - slide, 1.0 + slide] {
        let p = [eye[0] + ray[0] * scale, eye[1] + ray[1] * scale, eye[2] + ray[2] * scale];
        for corner in 0..8 {
            let sign = |bit: usize| if corner & (1 << bit) == 0 { -sigmas } else { sigmas };
            let m = Motion {
                x_m: prior.motion.x_m + sign(0) * prior.sd[0],
                y_m: prior.motion.y_m + sign(1) * prior.sd[1],
                heading_rad: prior.motion.heading_rad + sign(2) * prior.sd[2],
            };
            let Some([u, v]) = rig.project(m.inverse_apply(p)) else { continue };
            hull = [hull[0].min(u), hull[1].min(v), hull[2].max(u), hull[3].max(v)];
        }
    }
    let clip = |v: f64, max: f64| v.clamp(0.0, max) as usize;
    let r = Rect::new(
        clip((hull[0] - margin - 1.0).floor(), w),
        clip((hull[1] - margin - 1.0).floor(), h),
        clip((hull[2] + margin + 2.0).ceil(), w),
        clip((hull[3] + margin + 2.0).ceil(), h),
    );
    (r.width() > 2 * half && r.height() > 2 * half).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig() -> Rig {
        super::super::rig::example()
    }

    #[test]
    fn the_box_holds_the_feature_under_any_motion_within_the_margins() {
        let r = rig();
        let prior = Prior { motion: Motion { x_m: 0.4, y_m: 0.0, heading_rad: 0.0 }, sd: [0.03, 0.03, 0.01] };
        let point = [4.0, 0.8, 1.5];
        let b = predicted_box(&r, point, &prior, 3.0, [640, 480], 5).expect("in view");
        for (dx, dy, dh) in [(0.09, 0.0, 0.0), (-0.09, 0.09, 0.0), (0.0, -0.09, 0.03), (0.05, 0.05, -0.03)] {
            let m = Motion { x_m: 0.4 + dx, y_m: dy, heading_rad: dh };
            let [u, v] = r.project(m.inverse_apply(point)).expect("in front");
            assert!(b.contains(u as usize, v as usize), "{u}, {v} outside {b}");
        }
        // 3 sd of heading (0.03 rad) is 17 px either way at this focal length, 3 sd of sideways
        // travel (0.09 m at 4 m) 12 px, with the patch and the range's slide some 80 px in all.
        assert!((60..100).contains(&b.width()), "{b}");
        // Behind the robot after the step, or beside the view: drifted out.
        assert!(predicted_box(&r, [0.2, 0.0, 1.0], &prior, 3.0, [640, 480], 5).is_none());
        assert!(predicted_box(&r, [2.0, 3.0, 1.0], &prior, 3.0, [640, 480], 5).is_none());
    }
}

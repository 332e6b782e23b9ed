//! The camera's calibration (001 §6.3): the 4x3 matrix that takes a point in the robot frame
//! (x forward, y left, z up, metres) to image coordinates, for any image size. The renderer and
//! the Expecter use the same model, so what is drawn is where it is expected.

use crate::{Camera, Pose2};

impl Camera {
    /// Focal length in pixels for an image `width_px` wide (square pixels).
    pub fn focal_for(&self, width_px: u32) -> f64 {
        self.focal_px * f64::from(width_px) / f64::from(self.width_px)
    }

    /// The 4x3 calibration matrix `C` for a `width_px x height_px` image: for a robot-frame
    /// point, `[x y z 1] C = [a b c]` and the image point is `(a / c, b / c)`, in pixels from the
    /// image's top-left corner (pixel `(u, v)` covers `[u, u + 1) x [v, v + 1)`).
    pub fn calibration(&self, width_px: u32, height_px: u32) -> [[f64; 3]; 4] {
        let f = self.focal_for(width_px);
        let (cx, cy) = (f64::from(width_px) / 2.0, f64::from(height_px) / 2.0);
        // u = cx - f y / x, v = cy + f (h - z) / x: the camera sits at height h looking forward.
        [[cx, cy, 1.0], [-f, 0.0, 0.0], [0.0, -f, 0.0], [0.0, f * self.height_m, 0.0]]
    }

    /// Where a world point appears for a robot at `pose`; `None` behind the camera.
    pub fn project(&self, width_px: u32, height_px: u32, pose: Pose2, world_m: [f64; 3]) -> Option<[f64; 2]> {
        let (s, c) = pose.heading_rad.sin_cos();
        project_with(&self.calibration(width_px, height_px), [pose.x_m, pose.y_m, c, s], world_m)
    }
}

/// [`Camera::project`] with the calibration `m` and the pose's heading as `[x, y, cos, sin]`
/// worked out beforehand: for loops that project many points from many poses (inlined across
/// crates: the Expecter calls it some 200 times a window).
#[inline]
pub fn project_with(m: &[[f64; 3]; 4], pose: [f64; 4], world_m: [f64; 3]) -> Option<[f64; 2]> {
    let [x, y, c, s] = pose;
    let (dx, dy) = (world_m[0] - x, world_m[1] - y);
    let robot = [dx * c + dy * s, -dx * s + dy * c, world_m[2], 1.0];
    // Written out (a sum over an iterator stayed a call in the Expecter's hot loop), with the
    // same terms in the same order: the same bits.
    let row = |j: usize| robot[0] * m[0][j] + robot[1] * m[1][j] + robot[2] * m[2][j] + robot[3] * m[3][j];
    let (a, b, w) = (row(0), row(1), row(2));
    (w > 1e-9).then(|| [a / w, b / w])
}

#[cfg(test)]
mod tests {
    use crate::{Pose2, load_str};

    #[test]
    fn points_project_through_the_calibration() {
        let w = load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
        let cam = &w.camera;
        // Straight ahead at camera height: the image centre.
        assert_eq!(cam.project(640, 480, Pose2::default(), [5.0, 0.0, cam.height_m]), Some([320.0, 240.0]));
        // 1 m left at 2 m, on the floor: left of centre and below it, scaled by f / 2.
        let [u, v] = cam.project(640, 480, Pose2::default(), [2.0, 1.0, 0.0]).expect("in front");
        assert!((u - (320.0 - 554.0 / 2.0)).abs() < 1e-9 && (v - (240.0 + 554.0 * 1.2 / 2.0)).abs() < 1e-9);
        // Turning the robot left by 90 degrees brings a point on +y to the centre column.
        let [u, _] = cam
            .project(640, 480, Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2), [0.0, 3.0, 1.2])
            .expect("ahead");
        assert!((u - 320.0).abs() < 1e-9);
        assert!(cam.project(640, 480, Pose2::default(), [-1.0, 0.0, 1.0]).is_none(), "behind");
        // Half the width, half the focal length: the same ray lands on the same relative spot.
        let [u2, _] = cam.project(320, 240, Pose2::default(), [2.0, 1.0, 0.0]).expect("in front");
        assert!((u2 - (160.0 - 277.0 / 2.0)).abs() < 1e-9);
    }
}

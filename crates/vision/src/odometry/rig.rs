//! The stereo rig's geometry (003): two parallel cameras at the robot's centre, the left one
//! `baseline / 2` to the robot's left, both at the camera height looking along the robot's x;
//! a matched point's position in the robot frame (x forward, y left, z up) from its left-image
//! position and disparity, its projection back into the left image, and how uncertain its
//! ground-plane position is from the matching's pixel errors.

/// The rig's calibration and how well points are matched on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rig {
    pub focal_px: f64,
    /// The image centre (principal point), pixels from the top-left corner.
    pub centre_px: [f64; 2],
    pub baseline_m: f64,
    pub height_m: f64,
    /// Standard deviation of a disparity, pixels (the two matches' errors together).
    pub disparity_sd_px: f64,
    /// Standard deviation of a point's position across the image, pixels.
    pub position_sd_px: f64,
}

/// A 2x2 symmetric matrix `[xx, xy, yy]`.
pub type Sym2 = [f64; 3];

impl Rig {
    /// The robot-frame point seen at `left` (pixel centres at +0.5) with `disparity_px`; `None`
    /// for a disparity that is not positive and finite.
    pub fn triangulate(&self, left: [f32; 2], disparity_px: f32) -> Option<[f64; 3]> {
        let d = f64::from(disparity_px);
        if !(d.is_finite() && d > 0.0) {
            return None;
        }
        let x = self.focal_px * self.baseline_m / d;
        let y = (self.centre_px[0] - f64::from(left[0])) * x / self.focal_px + self.baseline_m / 2.0;
        let z = self.height_m - (f64::from(left[1]) - self.centre_px[1]) * x / self.focal_px;
        Some([x, y, z])
    }

    /// Where the robot-frame point `p` appears in the left image; `None` behind the camera.
    pub fn project(&self, p: [f64; 3]) -> Option<[f64; 2]> {
        if p[0] <= 1e-6 {
            return None;
        }
        let u = self.centre_px[0] - self.focal_px * (p[1] - self.baseline_m / 2.0) / p[0];
        let v = self.centre_px[1] + self.focal_px * (self.height_m - p[2]) / p[0];
        Some([u, v])
    }

    /// The covariance of the ground-plane position `(x, y)` of a point triangulated at `p`:
    /// the disparity's error moves it along the ray by `x² σd / (f b)`, the position's error
    /// across the ray by `x σu / f` (so near points weigh more than far ones, 003's weights).
    pub fn covariance(&self, p: [f64; 3]) -> Sym2 {
        let (f, b) = (self.focal_px, self.baseline_m);
        let x = p[0];
        let lateral = p[1] - b / 2.0;
        // d(x, y) / d(disparity) and d(x, y) / d(u).
        let dd = [-x * x / (f * b), -lateral * x / (f * b)];
        let du = [0.0, -x / f];
        let (sd, su) = (self.disparity_sd_px.powi(2), self.position_sd_px.powi(2));
        [
            dd[0] * dd[0] * sd + du[0] * du[0] * su,
            dd[0] * dd[1] * sd + du[0] * du[1] * su,
            dd[1] * dd[1] * sd + du[1] * du[1] * su,
        ]
    }

    /// The standard deviation of the point's distance from the rig, metres (along its ray).
    pub fn range_sd(&self, p: [f64; 3]) -> f64 {
        p[0] * p[0] * self.disparity_sd_px / (self.focal_px * self.baseline_m)
    }
}

/// The unit tests' rig: 003's 25 cm on the hallway camera (554 px at 640x480, 1.2 m up).
#[cfg(test)]
pub(super) fn example() -> Rig {
    Rig {
        focal_px: 554.0,
        centre_px: [320.0, 240.0],
        baseline_m: 0.25,
        height_m: 1.2,
        disparity_sd_px: 0.3,
        position_sd_px: 0.3,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig() -> Rig {
        example()
    }

    #[test]
    fn points_triangulate_and_project_back() {
        let r = rig();
        let p = [3.0, 0.7, 0.4];
        let [u, v] = r.project(p).expect("in front");
        // The right camera is `b` further right: its image of the point is `f b / x` further left.
        let d = r.focal_px * r.baseline_m / p[0];
        let back = r.triangulate([u as f32, v as f32], d as f32).expect("positive disparity");
        for k in 0..3 {
            assert!((back[k] - p[k]).abs() < 1e-4, "{back:?} vs {p:?}");
        }
        assert!(r.triangulate([u as f32, v as f32], 0.0).is_none());
        assert!(r.project([-1.0, 0.0, 1.0]).is_none());
    }

    #[test]
    fn far_points_are_less_certain_along_their_ray() {
        let r = rig();
        let near = r.covariance([2.0, r.baseline_m / 2.0, 1.0]);
        let far = r.covariance([6.0, r.baseline_m / 2.0, 1.0]);
        // Straight ahead of the left camera: x² σd / (f b) along, x σu / f across.
        assert!((near[0].sqrt() - 4.0 * 0.3 / (554.0 * 0.25)).abs() < 1e-12);
        assert!((near[2].sqrt() - 2.0 * 0.3 / 554.0).abs() < 1e-12);
        assert!(near[1].abs() < 1e-15);
        assert!((far[0] / near[0] - 81.0).abs() < 1e-9, "range variance grows as x⁴");
        assert!((r.range_sd([6.0, 0.0, 1.0]) - 36.0 * 0.3 / (554.0 * 0.25)).abs() < 1e-12);
    }
}

//! The visual odometry's settings the tests and the bench share (003's constraints where the
//! paper gives them).

use harvey_vision::moravec::MoravecParams;
use harvey_vision::odometry::{OdometryParams, Rig, Solver, Tolerance};
use harvey_vision::stereo::StereoParams;
use harvey_world::World;

/// The odometry's settings for a `width x height` pair `baseline_m` wide in `w`: 003's
/// constraints where the paper gives them.
pub fn params(w: &World, width: u32, height: u32, baseline_m: f64, solver: Solver) -> OdometryParams {
    let rig = Rig {
        focal_px: w.camera.focal_for(width),
        centre_px: [f64::from(width) / 2.0, f64::from(height) / 2.0],
        baseline_m,
        height_m: w.camera.height_m,
        disparity_sd_px: 0.3,
        position_sd_px: 0.3,
    };
    OdometryParams {
        rig,
        stereo: StereoParams {
            focal_px: rig.focal_px as f32,
            baseline_m: baseline_m as f32,
            // 003 searched a band of 5-10 % of the image height for its uncalibrated cameras; this
            // rig is calibrated to 3 mrad (the world's `[survey]`), under 2 px at this focal
            // length. The paper's band (12 rows each way) let points on edges slide along them:
            // on the harsh day its median disparity error was 5 px, with this band 2 px.
            // Near limit 1.5 m and far limit "infinity" (far beyond any wall here), as 003's.
            band_rows: 2,
            near_m: 1.5,
            far_m: 1000.0,
            patch: 11,
            min_score: 0.9,
            min_margin: 0.0,
            moravec: MoravecParams { window: 5, threshold: 3000, suppress_radius: 6, max_corners: 150 },
        },
        track_min_score: 0.8,
        box_sigmas: 3.0,
        rigidity: Tolerance { sigmas: 4.0, floor_m: 0.03 },
        edit_chi2: 13.8,
        min_features: 8,
        // A chi-square with three degrees of freedom, p = 0.001.
        plausible_chi2: 16.3,
        spacing_px: 8.0,
        // An edge's patch has a ratio near 0 (a corner's near 1): a tenth keeps corners of two
        // edges of quite different contrast and leaves edges in any direction out.
        min_turn: 0.1,
        solver,
    }
}

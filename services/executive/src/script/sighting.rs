//! What one look at a servoed leg's landmark says (000 §5.5): the landmark's place relative to
//! the intended line from where the robot should be, its bearing error, and its distance from
//! the image row; the gates that refuse a sighting no believable pose explains (002 §5.2); and
//! the mount measured from the first look.

use harvey_msgs::Pose2;

use super::leg::ServoSetup;
use crate::servo::ServoParams;

/// A sighting the gates let through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Sighted {
    /// The landmark in the frame of the intended line at the expected position (m: ahead, left),
    /// its distance ahead measured from the image row where the row can tell.
    pub landmark: [f64; 2],
    /// The image column's offset left of the centre (pixels).
    pub x_left: f64,
    /// The servo's parameters with the measured mount yaw.
    pub params: ServoParams,
    /// The measured distance ahead less the expected one (m), where the row could tell.
    pub range_error_m: Option<f64>,
}

/// A sighting refused as a false match: its bearing error (radians) and, when the distance
/// gave it away, the range error (m).
pub(crate) type Refused = (f64, Option<f64>);

/// The look's image position `[u, v]` read from `expected` (where the robot should be, heading
/// along the line), with the mount `(yaw, pitch)` and the estimated offset from the line:
/// refused beyond the heading gate (widened by the offset's angle) or the range gate.
pub(crate) fn sighting(
    s: &ServoSetup,
    expected: Pose2,
    mount_rad: (f64, f64),
    offset_m: f64,
    [u, v]: [f64; 2],
) -> Result<Sighted, Refused> {
    let (c, sn) = (expected.heading_rad.cos(), expected.heading_rad.sin());
    let (dx, dy) = (s.point[0] - expected.x_m, s.point[1] - expected.y_m);
    let mut landmark = [dx * c + dy * sn, -dx * sn + dy * c];
    // Its distance from the row it is seen in, where it stands well above or below the camera.
    let (dz, rise) = (s.point[2] - s.camera_height_m, f64::from(s.height_px) / 2.0 - v);
    // The row as a level camera would have seen it.
    let rise = s.params.focal_px * ((rise / s.params.focal_px).atan() - mount_rad.1).tan();
    let params = ServoParams { misalignment_rad: mount_rad.0, ..s.params };
    let x_left = f64::from(s.width_px) / 2.0 - u;
    let bearing_error =
        landmark[1].atan2(landmark[0]) - ((x_left / params.focal_px).atan() + params.misalignment_rad);
    if bearing_error.abs() > s.gate_rad + offset_m.abs() / landmark[0].max(1.0) {
        return Err((bearing_error, None));
    }
    let mut range_error_m = None;
    if dz.abs() > 0.2 && rise * dz > 0.0 && rise.abs() > 2.0 {
        let measured = dz * params.focal_px / rise;
        if (measured - landmark[0]).abs() > s.gate_range * landmark[0] {
            return Err((bearing_error, Some(measured - landmark[0])));
        }
        range_error_m = Some(measured - landmark[0]);
        landmark[0] = measured;
    }
    Ok(Sighted { landmark, x_left, params, range_error_m })
}

/// The mount's (yaw, pitch) from the landmark seen at image `[u, v]` by a robot standing at
/// `at` on the line, heading along it: the difference between where the point should appear to a
/// true camera and where it does.
pub(crate) fn measure_mount(s: &ServoSetup, at: Pose2, [u, v]: [f64; 2]) -> (f64, f64) {
    let f = s.params.focal_px;
    let (c, sn) = (at.heading_rad.cos(), at.heading_rad.sin());
    let (dx, dy) = (s.point[0] - at.x_m, s.point[1] - at.y_m);
    let (ahead, left) = (dx * c + dy * sn, -dx * sn + dy * c);
    let (x_left, rise) = (f64::from(s.width_px) / 2.0 - u, f64::from(s.height_px) / 2.0 - v);
    let yaw = left.atan2(ahead) - (x_left / f).atan();
    let pitch = (rise / f).atan() - (s.point[2] - s.camera_height_m).atan2(ahead);
    (yaw, pitch)
}

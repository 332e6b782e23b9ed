//! `/camera/camera_info` from a camera frame's header alone (its stamp and size) and the run's
//! world: the recorder derives it from the recorded frame, the Foxglove bridge from the header
//! read in place, without encoding the pixels, and both by [`camera_info`], so the bytes agree.

use harvey_cdr::{CameraInfo, CdrError, frames};
use harvey_msgs::FrameHeader;
use harvey_world::World;

/// The calibration of the frame `h` heads: the world's pinhole camera scaled to the frame's
/// width, stamped with the frame, in the camera's optical frame.
pub fn camera_info(h: &FrameHeader, world: &World) -> CameraInfo {
    let (w, ht) = (h.width_px, h.height_px);
    // Harvey's pixel (u, v) covers [u, u + 1); ROS puts its centre at (u, v).
    CameraInfo {
        stamp_ns: h.stamp_ns,
        frame_id: frames::CAMERA.into(),
        width_px: w,
        height_px: ht,
        focal_px: world.camera.focal_for(w),
        centre_px: [f64::from(w) / 2.0 - 0.5, f64::from(ht) / 2.0 - 0.5],
    }
}

/// Refuses a frame the recorded `sensor_msgs/Image` could not be decoded from
/// (`harvey_cdr::decode_image`): an encoding neither mono8 nor rgb8, or `pixel_bytes` other than
/// the header's rows of its stride. Such a frame brings no calibration, read in place or recorded.
pub fn check_frame(h: &FrameHeader, pixel_bytes: usize) -> Result<(), CdrError> {
    let what = if h.encoding().is_none() {
        format!("frame encoding {} is not mono8 or rgb8", h.encoding)
    } else if pixel_bytes != h.payload_len() {
        format!("{pixel_bytes} pixel bytes for a {}x{} frame", h.width_px, h.height_px)
    } else {
        return Ok(());
    };
    Err(CdrError::Invalid { at: 0, what })
}

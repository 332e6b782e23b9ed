//! Where a leg's look searches (002 §5.1's Expecter window, issue 13): the image rectangle round
//! the landmark point's predicted position that a sighting the leg would accept can fall in. Its
//! width is the bearing gate either way (widened by the offset from the line, as the gate is),
//! its height the range gate's change of the point's row, each plus half the template and a
//! margin. A correlation over the whole frame could return another surface's better match far
//! outside it, which the gate then refuses, and with it the look; searched here, the landmark's
//! own match is the answer or there is none.

use harvey_msgs::Pose2;

use super::leg::ServoSetup;

/// Pixels added round the gates' extent: the template's placement is found to a pixel or two.
const MARGIN_PX: f64 = 4.0;

/// How far (either way, yaw and pitch) the first look allows the camera's mount to be from
/// its configured angles, before the look measures it: a degree, beyond the errors a mount
/// has (000 §5.5 Fig. 10 studies 1 and 10 mrad; the harsh condition's sd is 10 mrad).
const MOUNT_TOLERANCE_RAD: f64 = std::f64::consts::PI / 180.0;

/// The window `[u0, v0, u1, v1]` (pixels) to look for `s`'s point in, from `expected`, with the
/// mount's `(yaw, pitch)` and the leg's estimated offset from its line; `None` (the whole frame)
/// when the point is behind the camera or the window would not hold the template.
pub fn look_window(
    s: &ServoSetup,
    expected: Pose2,
    mount_rad: (f64, f64),
    offset_m: f64,
    template_px: u32,
) -> Option<[f32; 4]> {
    let f = s.params.focal_px;
    let [ahead, left] = expected.inverse().apply([s.point[0], s.point[1]]);
    if ahead < 0.5 {
        return None;
    }
    let (w, h) = (f64::from(s.width_px), f64::from(s.height_px));
    let half_template = f64::from(template_px) / 2.0;
    // Columns: the bearing gate either way of the predicted bearing, as `Leg::on_seen` applies it.
    let bearing = left.atan2(ahead) - mount_rad.0;
    let gate = s.gate_rad + offset_m.abs() / ahead.max(1.0);
    let u_at = |b: f64| w / 2.0 - f * b.clamp(-1.4, 1.4).tan();
    let (u0, u1) = (u_at(bearing + gate), u_at(bearing - gate));
    // Rows: the point's height over the camera seen at the range gate's nearest and farthest.
    let dz = s.point[2] - s.camera_height_m;
    let v_at = |d: f64| h / 2.0 - f * ((dz / d).atan() + mount_rad.1).tan();
    let (near, far) = (ahead * (1.0 - s.gate_range).max(0.1), ahead * (1.0 + s.gate_range));
    let (va, vb) = (v_at(near), v_at(far));
    let pad = half_template + MARGIN_PX;
    let window = [
        (u0.min(u1) - pad).max(0.0),
        (va.min(vb) - pad).max(0.0),
        (u0.max(u1) + pad).min(w),
        (va.max(vb) + pad).min(h),
    ];
    let holds = |lo: f64, hi: f64| hi - lo > 2.0 * half_template + 1.0;
    (holds(window[0], window[2]) && holds(window[1], window[3])).then(|| window.map(|x| x.round() as f32))
}

/// The first look's window, before the mount is measured, from the leg's start, where the
/// robot stands on its line heading along it (no motion to gate yet; the mount measured from
/// this look takes that for granted too, so a start off the line or its heading is outside what
/// the look can tell either way): where the point appears
/// for every mount within [`MOUNT_TOLERANCE_RAD`] of `mount_rad` (the union of the two extreme
/// mounts' windows: the columns move with the yaw, the rows with the pitch, each one way). A
/// search of the whole frame can lock on another surface's better match (the hall's corner
/// beside the exit sign under harsh light), and the mount measured from it sends every later
/// look astray.
pub fn first_look_window(
    s: &ServoSetup,
    expected: Pose2,
    mount_rad: (f64, f64),
    template_px: u32,
) -> Option<[f32; 4]> {
    let (t, still) = (MOUNT_TOLERANCE_RAD, ServoSetup { gate_rad: 0.0, gate_range: 0.0, ..*s });
    let low = look_window(&still, expected, (mount_rad.0 - t, mount_rad.1 - t), 0.0, template_px);
    let high = look_window(&still, expected, (mount_rad.0 + t, mount_rad.1 + t), 0.0, template_px);
    match (low, high) {
        (Some(a), Some(b)) => Some([a[0].min(b[0]), a[1].min(b[1]), a[2].max(b[2]), a[3].max(b[3])]),
        // At the image's edge one extreme's window may not hold the template: the other's.
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::leg::Tracking;
    use crate::servo::ServoParams;

    /// The exit sign's corner 12 m down the hall, 1 m up over a camera at 1.2 m (the
    /// `hallway-40ft` mission's), a 640x480 camera of focal 554 px, gates of 3 degrees and 10 %.
    fn sign() -> ServoSetup {
        ServoSetup {
            landmark_index: 0,
            point: [12.0, 0.2, 2.2],
            offset: [0.0; 3],
            params: ServoParams { focal_px: 554.0, misalignment_rad: 0.0, aim_m: 0.6 },
            width_px: 640,
            height_px: 480,
            camera_height_m: 1.2,
            tracking: Tracking::Whole,
            calibrate: true,
            gate_rad: 3f64.to_radians(),
            gate_range: 0.1,
        }
    }

    #[test]
    fn the_window_spans_the_gates_round_the_predicted_position() {
        let s = sign();
        let [u0, v0, u1, v1] = look_window(&s, Pose2::default(), (0.0, 0.0), 0.0, 16).expect("in view");
        // Predicted at u = 320 - 554 * 0.2 / 12 = 310.8, v = 240 - 554 * 1.0 / 12 = 193.8.
        let (u, v) = (320.0 - 554.0 * (0.2f64 / 12.0).atan().tan(), 240.0 - 554.0 / 12.0);
        assert!(f64::from(u0) < u && u < f64::from(u1) && f64::from(v0) < v && v < f64::from(v1));
        // 3 degrees either way is 29 px, plus 12 px of template and margin.
        let half_width = f64::from(u1 - u0) / 2.0;
        assert!((half_width - 41.0).abs() < 2.0, "{half_width}");
        // The sign 10 degrees off (the false matches `hallway-40ft` dim seed 2 returned) is outside.
        let off = 320.0 - 554.0 * ((0.2f64 / 12.0).atan() - 10f64.to_radians()).tan();
        assert!(off > f64::from(u1), "{off} in [{u0}, {u1}]");
        // The mount's yaw moves the window the other way; a wider offset from the line widens it.
        let [m0, _, m1, _] = look_window(&s, Pose2::default(), (0.01, 0.0), 0.0, 16).expect("in view");
        assert!(m0 > u0 && m1 > u1);
        let [w0, _, w1, _] = look_window(&s, Pose2::default(), (0.0, 0.0), 0.3, 16).expect("in view");
        assert!(w1 - w0 > u1 - u0);
    }

    #[test]
    fn behind_the_camera_or_off_the_image_it_is_the_whole_frame() {
        let s = sign();
        let turned = Pose2 { heading_rad: std::f64::consts::PI, ..Pose2::default() };
        assert_eq!(look_window(&s, turned, (0.0, 0.0), 0.0, 16), None);
        // Facing 60 degrees off, the predicted column is off the image: nothing fits the template.
        let askew = Pose2 { heading_rad: 60f64.to_radians(), ..Pose2::default() };
        assert_eq!(look_window(&s, askew, (0.0, 0.0), 0.0, 16), None);
    }

    #[test]
    fn the_first_look_covers_any_mount_within_a_degree_and_no_more() {
        let s = sign();
        let first = first_look_window(&s, Pose2::default(), (0.0, 0.0), 16).expect("in view");
        // Where the point appears for a mount (yaw left, pitch down), seen from the start.
        let seen = |(yaw, pitch): (f64, f64)| {
            let u = 320.0 - 554.0 * ((0.2f64 / 12.0).atan() - yaw).tan();
            let v = 240.0 - 554.0 * ((1.0f64 / 12.0).atan() + pitch).tan();
            (u, v)
        };
        let holds = |(u, v): (f64, f64)| {
            (f64::from(first[0])..=f64::from(first[2])).contains(&u)
                && (f64::from(first[1])..=f64::from(first[3])).contains(&v)
        };
        // Every mount within the tolerance (a harsh day's 5 mrad left and 12 mrad up included)
        // puts the point inside it, with room for the template's half (8 px) beyond.
        for mount in [(0.0, 0.0), (0.0175, 0.0175), (-0.0175, -0.0175), (0.0175, -0.0175), (0.0045, -0.012)] {
            let (u, v) = seen(mount);
            assert!(holds((u - 8.0, v - 8.0)) && holds((u + 8.0, v + 8.0)), "{mount:?}: {u} {v} {first:?}");
        }
        // Three degrees of yaw (the tracking gate's) or of pitch is outside, and so is the side
        // wall's corner 1.2 m right of the sign.
        assert!(!holds(seen((0.052, 0.0))) && !holds(seen((-0.052, 0.0))) && !holds(seen((0.0, 0.052))));
        let corner = 320.0 - 554.0 * ((0.2f64 - 1.2) / 12.0).atan().tan();
        assert!(corner > f64::from(first[2]), "{corner} in {first:?}");
    }
}

//! The deriver's tests: the static transforms and map come first, the transform chain puts the
//! robot where the executive believes it is, and a continued recording gets only what it lacks.

use std::collections::BTreeSet;

use harvey_cdr::{MarkerArray, MarkerKind, TfMessage, decode, encode, frames};
use harvey_msgs::{Header, MissionStatus, Odometry, Pose2, UncertaintyMap, topics};

use super::*;

fn world() -> World {
    let text = include_str!("../../../../worlds/hallway.toml");
    harvey_world::load_str(text, "hallway.toml").expect("the hallway world loads")
}

fn odometry(stamp_ns: u64, p: Pose2) -> Vec<u8> {
    encode(
        &Odometry { header: Header::new(1, stamp_ns), world_from_robot: p, ..Default::default() },
        Vec::new(),
    )
}

fn status(stamp_ns: u64, estimated: Pose2) -> Vec<u8> {
    encode(&MissionStatus { header: Header::new(1, stamp_ns), estimated, ..Default::default() }, Vec::new())
}

/// Applies a planar transform's x, y and yaw to a point.
fn apply(t: &Transform, [x, y]: [f64; 2]) -> ([f64; 2], f64) {
    let [_, _, z, w] = t.rotation.0;
    let yaw = 2.0 * z.atan2(w);
    let (s, c) = yaw.sin_cos();
    ([t.translation.0[0] + c * x - s * y, t.translation.0[1] + s * x + c * y], yaw)
}

#[test]
fn the_first_message_brings_the_camera_mount_and_the_map() {
    let world = world();
    let mut d = Deriver::new(Some(&world));
    let mut out = Vec::new();
    d.derive("/odometry", 5, &odometry(5, world.start), &mut out).expect("derives");
    let topics: Vec<&str> = out.iter().map(|m| m.topic).collect();
    assert_eq!(topics, [TF_STATIC, MAP_MARKERS, TF, TF]);
    let stat = decode::<TfMessage>(&out[0].data).expect("tf_static");
    let camera = &stat.0[0];
    assert_eq!((camera.parent.as_str(), camera.child.as_str()), (frames::BASE_LINK, frames::CAMERA));
    assert_eq!(camera.translation.0, [0.0, 0.0, world.camera.height_m]);
    let map = decode::<MarkerArray>(&out[1].data).expect("map");
    assert_eq!(map.0.len(), world.walls.len() + 2 * world.landmarks.len());
    assert!(map.0.iter().all(|m| m.frame_id == frames::WORLD && m.stamp_ns == 0));
    assert_eq!(out[1].stamp_ns, 5, "logged with the message that brought it");
    let labels: Vec<&str> =
        map.0.iter().filter(|m| m.kind == MarkerKind::TextViewFacing).map(|m| m.text.as_str()).collect();
    assert_eq!(labels.len(), world.landmarks.len());
    assert!(labels.contains(&world.landmarks[0].name.as_str()));
    // Only once.
    out.clear();
    d.derive("/odometry", 6, &odometry(6, world.start), &mut out).expect("derives");
    assert_eq!(out.iter().map(|m| m.topic).collect::<Vec<_>>(), [TF]);
    assert_eq!(out[0].seq, 2, "numbered per topic");
}

#[test]
fn world_to_odom_to_base_link_puts_the_robot_at_its_estimate() {
    let mut d = Deriver::new(None);
    let mut out = Vec::new();
    let odo = Pose2 { x_m: 3.0, y_m: 1.0, heading_rad: 0.3 };
    let est = Pose2 { x_m: 3.2, y_m: 0.7, heading_rad: 0.25 };
    d.derive(topics::ODOMETRY.name, 10, &odometry(10, odo), &mut out).expect("odometry");
    d.derive(topics::EXECUTIVE_STATUS.name, 10, &status(10, est), &mut out).expect("status");
    let odom_base = decode::<TfMessage>(&out[1].data).expect("tf").0.remove(0);
    let world_odom = decode::<TfMessage>(&out[2].data).expect("tf").0.remove(0);
    assert_eq!((world_odom.parent.as_str(), world_odom.child.as_str()), (frames::WORLD, frames::ODOM));
    assert_eq!((odom_base.parent.as_str(), odom_base.child.as_str()), (frames::ODOM, frames::BASE_LINK));
    let (in_odom, yaw_b) = apply(&odom_base, [0.0, 0.0]);
    let (in_world, yaw_c) = apply(&world_odom, in_odom);
    assert!((in_world[0] - est.x_m).abs() < 1e-12 && (in_world[1] - est.y_m).abs() < 1e-12, "{in_world:?}");
    assert!((yaw_b + yaw_c - est.heading_rad).abs() < 1e-12);
    // A status whose tick's odometry the recording lacks brings no transform.
    out.clear();
    d.derive(topics::EXECUTIVE_STATUS.name, 20, &status(20, est), &mut out).expect("status");
    assert!(out.is_empty(), "{out:?}");
    // Taken the other way round (a live observer), the pair brings the same transform.
    let mut e = Deriver::new(None);
    let mut other = Vec::new();
    e.derive(topics::EXECUTIVE_STATUS.name, 10, &status(10, est), &mut other).expect("status");
    e.derive(topics::ODOMETRY.name, 10, &odometry(10, odo), &mut other).expect("odometry");
    let world_odom_again = other.iter().rev().find(|m| m.topic == TF).expect("tf");
    assert_eq!(decode::<TfMessage>(&world_odom_again.data).expect("tf").0.remove(0), world_odom);
}

#[test]
fn derived_topics_and_unknown_topics_derive_nothing_but_the_statics() {
    let mut d = Deriver::new(None);
    let mut out = Vec::new();
    d.derive("/tf", 1, &[0, 1, 0, 0], &mut out).expect("ignored");
    assert!(out.is_empty(), "a derived topic is not a source, not even of the statics");
    d.derive("/something/else", 1, &[], &mut out).expect("ignored");
    assert_eq!(out.iter().map(|m| m.topic).collect::<Vec<_>>(), [TF_STATIC]);
    let map = UncertaintyMap { vertex_count: 3, lost: 1, ..Default::default() };
    out.clear();
    d.derive("ums/map", 2, &encode(&map, Vec::new()), &mut out).expect("map");
    let polygon = decode::<MarkerArray>(&out[0].data).expect("polygon");
    assert_eq!(polygon.0[0].points.len(), 4, "closed");
    assert!(d.derive("ums/map", 3, &[0, 1, 0, 0, 1], &mut out).is_err(), "garbled bytes are an error");
}

#[test]
fn a_continued_recording_gets_only_the_derived_messages_it_lacks() {
    let mut d = Deriver::new(None);
    let mut derived = Vec::new();
    for t in [10, 20, 30] {
        d.derive(topics::ODOMETRY.name, t, &odometry(t, Pose2::default()), &mut derived).expect("derives");
    }
    let present: BTreeSet<_> =
        derived[..3].iter().map(|m| (m.topic.to_owned(), m.stamp_ns, m.seq as u32)).collect();
    let lacking = missing(derived.clone(), &present);
    assert_eq!(lacking, derived[3..].to_vec());
}

#[test]
fn each_frame_brings_its_calibration_with_the_world_and_none_without() {
    let world = world();
    let h = harvey_msgs::FrameHeader::new(3, 7, 320, 240, harvey_msgs::Encoding::Mono8);
    let frame = harvey_cdr::encode_image(&h, &vec![0u8; 320 * 240], Vec::new());
    let mut out = Vec::new();
    Deriver::new(None).derive(topics::CAMERA_FRAME.name, 7, &frame, &mut out).expect("derives");
    assert!(out.iter().all(|m| m.topic != CAMERA_INFO), "no calibration without the world");
    out.clear();
    let mut d = Deriver::new(Some(&world));
    d.derive(topics::CAMERA_FRAME.name, 7, &frame, &mut out).expect("derives");
    let info = out.iter().find(|m| m.topic == CAMERA_INFO).expect("a calibration");
    let info = decode::<harvey_cdr::CameraInfo>(&info.data).expect("camera info");
    assert_eq!(
        (info.width_px, info.height_px, info.stamp_ns, info.frame_id.as_str()),
        (320, 240, 7, frames::CAMERA)
    );
    assert_eq!(info.focal_px, world.camera.focal_for(320), "the focal length scales with the frame");
    assert_eq!(info.centre_px, [159.5, 119.5]);
}

#[test]
fn a_frame_header_read_in_place_derives_what_the_recorded_frame_derives() {
    let world = world();
    let h = harvey_msgs::FrameHeader::new(4, 1_250_000_000, 640, 480, harvey_msgs::Encoding::Rgb8);
    let pixels = vec![7u8; h.payload_len()];
    let frame = harvey_cdr::encode_image(&h, &pixels, Vec::new());
    for w in [None, Some(&world)] {
        let (mut recorded, mut in_place) = (Vec::new(), Vec::new());
        let (mut r, mut p) = (Deriver::new(w), Deriver::new(w));
        for _ in 0..2 {
            r.derive(topics::CAMERA_FRAME.name, h.stamp_ns, &frame, &mut recorded).expect("recorded");
            p.derive_frame(&h, pixels.len(), &mut in_place).expect("in place");
        }
        assert_eq!(in_place, recorded, "the same messages, numbered alike, byte for byte");
    }
    let mut d = Deriver::new(Some(&world));
    let mut out = Vec::new();
    assert!(d.derive_frame(&h, pixels.len() - 1, &mut out).is_err(), "pixels the header does not describe");
    let unset = harvey_msgs::FrameHeader { encoding: 0, ..h };
    assert!(d.derive_frame(&unset, pixels.len(), &mut out).is_err(), "an encoding the image cannot name");
    assert!(out.iter().all(|m| m.topic != CAMERA_INFO), "neither brings a calibration");
}

//! The CDR layouts' tests: messages as ROS 2 lays them out, images and stereo pairs, and
//! images that cannot be what they say.

use super::*;
use crate::{decode, encode, full_text};
use harvey_msgs::{Encoding, MAX_FEATURES};

fn round_trip<T: Ros2Msg + PartialEq + core::fmt::Debug>(v: T) {
    let bytes = encode(&v, Vec::new());
    assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
    assert_eq!(decode::<T>(&bytes).expect("decodes"), v);
    assert!(decode::<T>(&bytes[..bytes.len() - 1]).is_err(), "truncated must fail");
}

#[test]
fn every_message_round_trips() {
    let h = Header::new(42, 3_000_000_123);
    let pose = Pose2 { x_m: 1.5, y_m: -2.0, heading_rad: 0.25 };
    let cmd = MotionCommand { header: h, kind: 1, distance_m: 2.0, command_id: 9, ..Default::default() };
    round_trip(TruePose { header: h, world_from_robot: pose });
    round_trip(SonarRaw { header: h, bank: 2, echo_mask: 0x7f, range_m: [1.25; 8] });
    round_trip(SonarRing { header: h, range_m: [2.0; 24], valid_mask: 5, ..Default::default() });
    round_trip(EncodersRaw { header: h, x_m: 1.0, y_m: 2.0, heading_rad: 3.0, moving: 1, command_id: 4 });
    round_trip(cmd);
    round_trip(Odometry {
        header: h,
        world_from_robot: pose,
        travelled_m: 1.0,
        command: cmd,
        moving: 1,
        ..Default::default()
    });
    let mut features = [Feature::default(); MAX_FEATURES];
    features[3] = Feature { x_px: 10.5, y_px: 4.0, score: 0.9, kind: 1 };
    round_trip(Detections { header: h, frame_seq: 7, count: 4, features, ..Default::default() });
    let mut items = [VisionItem::default(); harvey_msgs::MAX_VISION_ITEMS];
    items[31] = VisionItem { values: [1.0, -2.0, 3.5, 0.0, 5.0, 6.0] };
    round_trip(VisionResult {
        header: h,
        frame_seq: 9,
        request_id: 3,
        status: 1,
        count: 32,
        items,
        ..Default::default()
    });
    round_trip(VisionRequest {
        header: h,
        request_id: 4,
        algorithm: 3,
        expected: pose,
        window_px: [1.0, 2.0, 3.0, 4.0],
        params: [8.0, 0.0, 8.0, 10.0, f32::INFINITY, -1.0, 0.0, 0.5],
        ..Default::default()
    });
    round_trip(UncertaintyMap {
        header: h,
        centre: pose,
        vertex_count: 4,
        area_m2: 0.5,
        ..Default::default()
    });
    round_trip(LandmarkSighting {
        header: h,
        frame_seq: 3,
        landmark_index: 2,
        kind: 2,
        a: 0.1,
        a_sd: 0.01,
        b: 4.0,
        b_sd: 0.1,
    });
    round_trip(Expectation {
        header: h,
        landmark_index: 1,
        class: 1,
        window_px: [1.0, 2.0, 30.0, 40.0],
        width_px: 640,
        height_px: 480,
        contrast: [0.5, -0.25, 0.0, 0.125],
    });
    round_trip(MissionStatus { header: h, state: 1, goal: pose, maps_seen: 3, ..Default::default() });
}

#[test]
fn header_is_a_std_header_then_seq() {
    let bytes = encode(&Header::new(7, 2_500_000_000), Vec::new());
    // sec=2, nanosec=5e8, frame_id "" (len 1 + NUL), pad to 8, seq.
    let expected: Vec<u8> = [
        &[0, 1, 0, 0][..],
        &2i32.to_le_bytes(),
        &500_000_000u32.to_le_bytes(),
        &1u32.to_le_bytes(),
        &[0, 0, 0, 0],
        &7u64.to_le_bytes(),
    ]
    .concat();
    assert_eq!(bytes, expected);
}

#[test]
fn schemas_append_dependencies_once_in_sorted_order() {
    let text = full_text(Odometry::DEF);
    let sections: Vec<&str> = text.lines().filter_map(|l| l.strip_prefix("MSG: ")).collect();
    assert_eq!(
        sections,
        ["harvey_msgs/MotionCommand", "std_msgs/Header", "builtin_interfaces/Time", "harvey_msgs/Pose2"]
    );
    assert!(text.contains("\n\n================================================================================\nMSG: std_msgs/Header\n"));
    assert_eq!(Odometry::DEF.schema_name(), "harvey_msgs/msg/Odometry");
}

#[test]
fn images_follow_sensor_msgs_layout() {
    let h = FrameHeader::new(1, 1_000_000_005, 2, 2, Encoding::Mono8);
    let bytes = encode_image(&h, &[1, 2, 3, 4], Vec::new());
    let mut r = CdrReader::new(&bytes).expect("header");
    assert_eq!((r.prim::<i32>().expect("sec"), r.prim::<u32>().expect("ns")), (1, 5));
    assert_eq!(r.string().expect("frame_id"), "camera");
    assert_eq!((r.prim::<u32>().expect("h"), r.prim::<u32>().expect("w")), (2, 2));
    assert_eq!(r.string().expect("encoding"), "mono8");
    assert_eq!(r.prim::<u8>().expect("bigendian"), 0);
    assert_eq!(r.prim::<u32>().expect("step"), 2);
    assert_eq!(r.byte_seq().expect("data"), &[1, 2, 3, 4]);
    assert_eq!(r.remaining(), 0);
    assert_eq!(image_def().schema_name(), "sensor_msgs/msg/Image");
    let (back, px) = decode_image(&bytes).expect("decodes");
    assert_eq!(
        (back.stamp_ns, back.width_px, back.height_px, px),
        (1_000_000_005, 2, 2, &[1u8, 2, 3, 4][..])
    );
    assert!(decode_image(&bytes[..bytes.len() - 1]).is_err());
}

#[test]
fn a_stereo_pair_is_one_stacked_image_read_back_as_a_pair() {
    let h = FrameHeader::stereo(3, 7, 2, 1, Encoding::Mono8);
    let bytes = encode_image(&h, &[1, 2, 3, 4], Vec::new());
    let mut r = CdrReader::new(&bytes).expect("header");
    let _stamp = (r.prim::<i32>().expect("sec"), r.prim::<u32>().expect("ns"));
    assert_eq!(r.string().expect("frame_id"), frames::STEREO_PAIR);
    assert_eq!((r.prim::<u32>().expect("h"), r.prim::<u32>().expect("w")), (2, 1 + 1));
    let (back, px) = decode_image(&bytes).expect("decodes");
    assert_eq!((back.views(), back.height_px, px), (2, 1, &[1u8, 2, 3, 4][..]));
    // A pair of an odd number of rows is not two images.
    let mut w = CdrWriter::start(Vec::new());
    write_std_header(7, frames::STEREO_PAIR, &mut w);
    w.prim(3u32);
    w.prim(2u32);
    w.string("mono8");
    w.prim(0u8);
    w.prim(2u32);
    w.byte_seq(&[0; 6]);
    let relabelled = w.finish();
    let e = decode_image(&relabelled).expect_err("three rows for a pair");
    assert!(e.to_string().contains("stereo pair of 3 rows"), "{e}");
}

/// A 2x2 rgb8 image's CDR with rows of `step` bytes.
fn rgb8_2x2(step: u32) -> Vec<u8> {
    let mut w = CdrWriter::start(Vec::new());
    write_std_header(7, "camera", &mut w);
    w.prim(2u32);
    w.prim(2u32);
    w.string("rgb8");
    w.prim(0u8);
    w.prim(step);
    w.byte_seq(&vec![0; 2 * step as usize]);
    w.finish()
}

#[test]
fn an_image_whose_rows_are_shorter_than_its_pixels_is_refused() {
    // Two rgb8 pixels a row (6 bytes) in rows of 2 bytes: a reader taking each row's pixels
    // would run past the data.
    let e = decode_image(&rgb8_2x2(2)).expect_err("rows too short");
    assert!(e.to_string().contains("row step of 2 bytes for 2 rgb8 pixels (6 bytes)"), "{e}");
    // Rows longer than their pixels (padding) are an image.
    let padded = rgb8_2x2(8);
    let (h, px) = decode_image(&padded).expect("padded rows");
    assert_eq!((h.stride_bytes, px.len()), (8, 16));
}

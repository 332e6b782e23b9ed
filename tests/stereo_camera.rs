//! The stereo camera across processes (003): `harvey-camera --stereo` renders both images of one
//! instant into one loaned frame, read here in place; the vision workers answer a standing
//! stereo odometry request sent over the bus with the motion between frames (none: the camera
//! stands still) and the obstacle points; the recorder writes the pairs as `sensor_msgs/Image`
//! that reads back as pairs, and the results beside them.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::{VisionAlgorithm, VisionRequest, VisionResult, VisionStatus, topics};

fn start(name: &str, args: &[&str], prefix: &str) -> Child {
    Command::new(common::bin(name))
        .args(args)
        .current_dir(common::repo())
        .env(harvey_bus::PREFIX_ENV, prefix)
        .stdout(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("{name} starts: {e}"))
}

fn stop(mut child: Child, name: &str) {
    common::signal(&child, libc::SIGTERM);
    let status = common::wait_exit(&mut child, Duration::from_secs(20));
    assert!(status.success(), "{name} exited with {status}");
}

#[test]
fn a_stereo_camera_feeds_the_odometry_request_and_is_recorded_as_pairs() {
    let prefix = common::unique_prefix("stereo");
    let dir = common::scratch("stereo");
    let mcap = dir.join("run.mcap");
    let rrd = dir.join("run.rrd");
    let world = "worlds/room.toml";
    let recorder = start(
        "harvey-recorder",
        &["--output", mcap.to_str().expect("utf8"), "--rrd", rrd.to_str().expect("utf8"), "--world", world],
        &prefix,
    );
    let workers = start(
        "harvey-vision-workers",
        &["--world", world, "--odometry", "missions/odometry/003.toml"],
        &prefix,
    );
    let camera = start(
        "harvey-camera",
        &["--world", world, "--stereo", "--pose", "0.8,3.0,2.0", "--rate-hz", "5"],
        &prefix,
    );

    let bus = Bus::join_with_prefix("stereo-test", &prefix).expect("bus");
    let frames = bus.frame_subscriber(topics::CAMERA_FRAME).expect("frames");
    let requests = bus.publisher(topics::VISION_REQUESTS).expect("requests");
    let results = bus.subscriber(topics::VISION_RESULTS).expect("results");
    let waiter = Waiter::new().expect("waiter");
    let _f = waiter.attach(&frames).expect("attach");
    let _r = waiter.attach(&results).expect("attach");

    // The frame in place: both images, the left one first, from two places.
    let frame = loop {
        assert_eq!(waiter.wait(Some(Duration::from_secs(30))).expect("wait"), Wake::Ready, "no frame");
        if let Some(f) = frames.latest().expect("receive") {
            break f;
        }
    };
    let h = *frame.header();
    assert_eq!((h.views(), h.width_px, h.height_px), (2, 640, 480));
    assert_eq!(frame.pixels().len(), 2 * 640 * 480);
    assert_ne!(h.view(frame.pixels(), 0), h.view(frame.pixels(), 1), "two cameras, two images");
    drop(frame);

    // A standing odometry request: the camera stands still, so the predicted motion is none.
    let ask = VisionRequest {
        request_id: 9,
        algorithm: VisionAlgorithm::StereoOdometry as u32,
        standing: 1,
        ..Default::default()
    };
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut answers: Vec<VisionResult> = Vec::new();
    while answers.len() < 4 {
        assert!(Instant::now() < deadline, "{} answers in 60 s", answers.len());
        if answers.is_empty() {
            requests.send(&ask).expect("send");
        }
        waiter.wait(Some(Duration::from_millis(500))).expect("wait");
        frames.latest().expect("drain frames");
        results.drain(|r| answers.push(*r)).expect("results");
    }
    let status = |r: &VisionResult| VisionStatus::from_raw(r.status);
    assert!(
        answers.iter().all(|r| r.request_id == 9 && status(r) == Some(VisionStatus::Found)),
        "{answers:?}"
    );
    assert_eq!(answers[0].items[0].values, [0.0; 6], "the first frame starts the odometry");
    for r in &answers[1..] {
        let [dx, dy, dh, ..] = r.items[0].values;
        assert!(dx.hypot(dy) < 0.01 && dh.abs() < 0.002, "standing still, moved {:?}", r.items[0].values);
        assert!(r.items[1].values[1] >= 20.0, "solved on {} features", r.items[1].values[1]);
        assert!(r.count > 2, "obstacle points: the room's furniture");
    }

    stop(camera, "camera");
    stop(workers, "vision workers");
    stop(recorder, "recorder");
    drop((_f, _r));
    drop((frames, requests, results, bus));

    // The recording: the pairs as stacked images named as pairs, read back as pairs.
    let rec = harvey_recording::Recording::open(&mcap).expect("opens");
    let (mut pairs, mut solved) = (0, 0);
    for m in rec.messages().expect("messages") {
        let m = m.expect("reads");
        match m.topic().trim_start_matches('/') {
            "camera/frame" => {
                let (h, pixels) = harvey_cdr::decode_image(m.data()).expect("an image");
                assert_eq!((h.views(), h.height_px, pixels.len()), (2, 480, 2 * 640 * 480));
                pairs += 1;
            }
            "vision/results" => {
                let r: VisionResult = harvey_cdr::decode(m.data()).expect("a result");
                solved += usize::from(r.algorithm == VisionAlgorithm::StereoOdometry as u32);
            }
            _ => {}
        }
    }
    assert!(pairs >= 4 && solved >= 4, "{pairs} pairs, {solved} odometry results recorded");
    assert!(std::fs::metadata(&rrd).expect("the Rerun file").len() > 100_000, "both images drawn");
    harvey_bus::retire_domain(&prefix).expect("domain retires");
}

//! The stereo visual odometry request on stereo frames rendered as the camera service renders
//! them (the room, the world as built for the seed, the mount misaligned, the conditions'
//! camera): the motion between two stops within 003's bar, the box in the way found among the
//! obstacle points, both solvers; and every bad input refused with its status.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::{Encoding, FrameHeader, Pose2, VisionAlgorithm, VisionRequest, VisionResult, VisionStatus};
use harvey_render::{Effects, Renderer, Shooter, mount_error};
use harvey_vision_workers::dispatch::Dispatcher;
use harvey_vision_workers::odometry_config::OdometryConfig;
use harvey_world::World;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// `worlds/NAME.toml` with `conditions/CONDITION.toml`'s `[camera]` merged in, as `harvey
/// sweep` merges it.
fn world(name: &str, condition: &str) -> World {
    let text = std::fs::read_to_string(format!("{ROOT}/worlds/{name}.toml")).expect("reads");
    let mut world: toml::Table = toml::from_str(&text).expect("parses");
    if condition != "nominal" {
        let over = std::fs::read_to_string(format!("{ROOT}/conditions/{condition}.toml")).expect("reads");
        let over: toml::Table = toml::from_str(&over).expect("parses");
        let camera = world.get_mut("camera").and_then(|c| c.as_table_mut()).expect("a camera");
        camera.extend(over["camera"].as_table().expect("a camera").clone());
    }
    harvey_world::load_str(&toml::to_string(&world).expect("prints"), name).expect("loads")
}

fn config() -> OdometryConfig {
    OdometryConfig::load(std::path::Path::new(&format!("{ROOT}/missions/odometry/003.toml"))).expect("loads")
}

/// The camera service's `--stereo` frames of `w` for `seed`.
fn camera(w: &World, seed: u64, stereo: bool) -> (World, Shooter) {
    let built = w.as_built(seed);
    let (yaw, pitch) = mount_error(&w.camera, seed);
    let renderer = Renderer::new(&built, 640, 480, Encoding::Mono8).misaligned(yaw, pitch);
    let effects = Effects::from_camera(&w.camera, seed);
    let baseline_m = stereo.then(|| w.camera.stereo_baseline_m.expect("a stereo rig"));
    (built, Shooter { renderer, effects, baseline_m })
}

fn shoot(built: &World, s: &mut Shooter, pose: Pose2, seq: u64) -> (FrameHeader, Vec<u8>) {
    let stamp = seq * 3_000_000_000;
    let mut px = vec![0u8; s.frame_bytes()];
    s.take(built, pose, seq, stamp, &mut px).expect("renders");
    (s.header(seq, stamp), px)
}

fn request(predicted: Pose2, params: [f32; 2]) -> VisionRequest {
    let mut r = VisionRequest {
        request_id: 7,
        algorithm: VisionAlgorithm::StereoOdometry as u32,
        standing: 1,
        expected: predicted,
        ..Default::default()
    };
    r.params[..2].copy_from_slice(&params);
    r
}

fn status(r: &VisionResult) -> VisionStatus {
    VisionStatus::from_raw(r.status).expect("a known status")
}

/// The room's first stop and the next, 0.45 m on with a small turn, as the planner predicts it.
const A: Pose2 = Pose2::new(0.8, 3.0, 0.04);
const B: Pose2 = Pose2::new(1.25, 3.02, -0.02);

#[test]
fn two_stops_in_the_room_give_the_motion_and_the_box_in_the_way() {
    let truth = A.relative(&B);
    // The prediction is off by 3 cm and 1 degree, as a planner's would be.
    let predicted = Pose2::new(truth.x_m + 0.03, truth.y_m - 0.02, truth.heading_rad + 0.017);
    for condition in ["nominal", "dim", "harsh"] {
        for lucas in [0.0, 1.0] {
            for seed in 1..=4 {
                let w = world("room", condition);
                let (built, mut cam) = camera(&w, seed, true);
                let mut d = Dispatcher::new(w.clone()).with_odometry(Some(config()));
                let (h, px) = shoot(&built, &mut cam, A, 1);
                let first = d.answer(&h, &px, &request(predicted, [0.0, lucas]));
                assert_eq!(status(&first), VisionStatus::Found, "{condition} seed {seed}: started");
                assert_eq!(first.items[0].values, [0.0; 6], "no motion at the first stop");
                assert!(first.items[1].values[0] >= 20.0, "{condition} seed {seed}: {:?}", first.items[1]);
                let (h, px) = shoot(&built, &mut cam, B, 2);
                let r = d.answer(&h, &px, &request(predicted, [0.0, lucas]));
                let label = format!("{condition} seed {seed} lucas {lucas}");
                assert_eq!(status(&r), VisionStatus::Found, "{label}: {:?}", r.items[1]);
                assert_eq!((r.frame_seq, r.header.stamp_ns), (2, 6_000_000_000));
                let [dx, dy, dh, sx, sy, sh] = r.items[0].values.map(f64::from);
                let error = (dx - truth.x_m).hypot(dy - truth.y_m);
                println!(
                    "{label}: step error {:.1} mm, heading {:.2} deg, sd {sx:.3} {sy:.3} {sh:.4}, counts {:?}",
                    error * 1e3,
                    (dh - truth.heading_rad).to_degrees(),
                    r.items[1].values
                );
                // 003's bar for a step (issue 18): 5 cm; the heading within half a degree.
                assert!(error < 0.05, "{label}: step off by {error:.3} m");
                assert!((dh - truth.heading_rad).abs() < 0.5f64.to_radians(), "{label}: heading");
                assert!(sx > 0.0 && sy > 0.0 && sh > 0.0, "{label}: the solution's uncertainty");
                // The box's face is 1.75 m ahead (x 3.0 in the room, within 0.3 m of the line):
                // points of it are among the obstacles, 0.1-0.8 m up.
                let points = &r.items[2..r.count as usize];
                let on_box = points
                    .iter()
                    .filter(|p| {
                        let [x, y, z] = [p.values[0], p.values[1], p.values[2]].map(f64::from);
                        let world_at = B.apply([x, y]);
                        (world_at[0] - 3.0).abs() < 0.12 && (world_at[1] - 3.0).abs() < 0.35 && z <= 0.85
                    })
                    .count();
                assert!(on_box >= 2, "{label}: {on_box} points on the box of {}", points.len());
                assert!(points.windows(2).all(|p| p[0].values[0].hypot(p[0].values[1])
                    <= p[1].values[0].hypot(p[1].values[1])), "nearest first");
            }
        }
    }
}

#[test]
fn bad_input_is_refused_with_its_status_and_a_blank_wall_gives_no_motion() {
    let w = world("room", "nominal");
    let (built, mut pair) = camera(&w, 1, true);
    let (h, px) = shoot(&built, &mut pair, A, 1);
    let ask = request(Pose2::new(0.4, 0.0, 0.0), [0.0, 0.0]);
    let answer =
        |d: &mut Dispatcher, h: &FrameHeader, px: &[u8], r: &VisionRequest| status(&d.answer(h, px, r));
    // Without settings, or in a world without a stereo rig: a bad parameter.
    assert_eq!(answer(&mut Dispatcher::new(w.clone()), &h, &px, &ask), VisionStatus::BadParameter);
    let hallway = world("hallway", "nominal");
    assert!(hallway.camera.stereo_baseline_m.is_none());
    let mut d = Dispatcher::new(hallway).with_odometry(Some(config()));
    assert_eq!(answer(&mut d, &h, &px, &ask), VisionStatus::BadParameter);
    // An unknown solver or mode, or a prediction that is not finite.
    let mut d = Dispatcher::new(w.clone()).with_odometry(Some(config()));
    for (i, v) in [(0, 2.0), (1, 2.0), (2, -0.1)] {
        let mut bad = ask;
        bad.params[i] = v;
        assert_eq!(answer(&mut d, &h, &px, &bad), VisionStatus::BadParameter, "params[{i}] = {v}");
    }
    let nan = request(Pose2::new(f64::NAN, 0.0, 0.0), [0.0, 0.0]);
    assert_eq!(answer(&mut d, &h, &px, &nan), VisionStatus::BadParameter);
    // One camera's frame, or a pair short of its right image: a bad frame.
    let (mono_world, mut mono) = camera(&w, 1, false);
    let (mh, mpx) = shoot(&mono_world, &mut mono, A, 1);
    assert_eq!(answer(&mut d, &mh, &mpx, &ask), VisionStatus::BadFrame);
    assert_eq!(answer(&mut d, &h, &px[..px.len() - 1], &ask), VisionStatus::BadFrame);
    let rgb = FrameHeader { encoding: Encoding::Rgb8 as u32, ..h };
    assert_eq!(answer(&mut d, &rgb, &px, &ask), VisionStatus::BadFrame);
    // A blank wall: nothing to range, then nothing to solve on (the executive stops and looks).
    let blank = vec![120u8; px.len()];
    let started = d.answer(&h, &blank, &ask);
    assert_eq!((status(&started), started.items[1].values[0]), (VisionStatus::Found, 0.0));
    let (h2, _) = shoot(&built, &mut pair, B, 2);
    let r = d.answer(&h2, &blank, &ask);
    assert_eq!(status(&r), VisionStatus::NotFound);
    assert_eq!(r.items[0].values, [0.0; 6], "no motion");
    // The odometry starts afresh from the blank stop, so the next pair has nothing to be solved
    // against either; the one after is solved again.
    let (h3, px3) = shoot(&built, &mut pair, A, 3);
    assert_eq!(answer(&mut d, &h3, &px3, &ask), VisionStatus::NotFound);
    let (h4, px4) = shoot(&built, &mut pair, B, 4);
    let back = d.answer(&h4, &px4, &request(A.relative(&B), [0.0, 0.0]));
    assert_eq!(status(&back), VisionStatus::Found, "solved again: {:?}", back.items[1]);
}

#[test]
fn the_shipped_settings_load_and_a_bad_one_is_named_with_its_line() {
    let c = config();
    assert_eq!((c.near_m, c.band_rows, c.patch), (1.5, 2, 11), "003's near limit");
    let text = std::fs::read_to_string(format!("{ROOT}/missions/odometry/003.toml")).expect("reads");
    let bad = text.replace("near_m = 1.5", "near_m = -1.5");
    let e = OdometryConfig::parse(&bad, "003.toml").expect_err("negative").to_string();
    let line = text.lines().position(|l| l.starts_with("near_m")).expect("a line") + 1;
    assert!(e.starts_with(&format!("003.toml:{line}: key `odometry.near_m`")), "{e}");
    let even = text.replace("patch = 11", "patch = 10");
    let e = OdometryConfig::parse(&even, "003.toml").expect_err("even").to_string();
    assert!(e.contains("odometry.patch") && e.contains("even"), "{e}");
    let unknown = text.replace("near_m = 1.5", "near_m = 1.5\nnear_limit = 2");
    let e = OdometryConfig::parse(&unknown, "003.toml").expect_err("unknown").to_string();
    assert!(e.contains("near_limit"), "{e}");
    let e = OdometryConfig::parse("[other]\nx = 1\n", "x.toml").expect_err("none").to_string();
    assert_eq!(e, "x.toml: no [odometry] table");
}

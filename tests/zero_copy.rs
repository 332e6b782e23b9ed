//! Zero copy, proven across processes: the camera process renders into a loaned shared-memory
//! slice; this process receives the frame, finds its pixels inside a /dev/shm mapping of its own
//! address space, and checks them against a local render of the same view (both views of a
//! stereo pair).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::process::{Command, Stdio};
use std::time::Duration;

use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::{Encoding, topics};
use harvey_render::{Renderer, checksum};

/// Address ranges of this process's mappings of shared-memory files.
fn shm_mappings() -> Vec<(usize, usize, String)> {
    let maps = std::fs::read_to_string("/proc/self/maps").expect("maps");
    maps.lines()
        .filter(|l| l.contains("/dev/shm/"))
        .filter_map(|l| {
            let (range, rest) = l.split_once(' ')?;
            let (a, b) = range.split_once('-')?;
            let path = rest.split_whitespace().last()?.to_owned();
            Some((usize::from_str_radix(a, 16).ok()?, usize::from_str_radix(b, 16).ok()?, path))
        })
        .collect()
}

fn check(width: u32, height: u32, encoding: Encoding, stereo: bool) {
    let prefix = common::unique_prefix("zc");
    let world_name = if stereo { "worlds/room.toml" } else { "worlds/hallway.toml" };
    let world_path = common::repo().join(world_name);
    let pose = if stereo { [1.0, 3.0, 2.0] } else { [5.0, 0.1, 3.0f64] };
    let mut camera = Command::new(common::bin("harvey-camera"))
        .args([
            "--world",
            world_path.to_str().expect("utf8"),
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
        ])
        .args([
            "--encoding",
            encoding.ros_name(),
            "--rate-hz",
            "30",
            "--pose",
            &format!("{},{},{}", pose[0], pose[1], pose[2]),
        ])
        .args(stereo.then_some("--stereo"))
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .stdout(Stdio::null())
        .spawn()
        .expect("camera starts");

    let bus = Bus::join_with_prefix("zero-copy-test", &prefix).expect("bus");
    let frames = bus.frame_subscriber(topics::CAMERA_FRAME).expect("subscriber");
    let waiter = Waiter::new().expect("waiter");
    let _a = waiter.attach(&frames).expect("attach");
    let frame = loop {
        assert_eq!(
            waiter.wait(Some(Duration::from_secs(20))).expect("wait"),
            Wake::Ready,
            "no frame within 20 s"
        );
        if let Some(f) = frames.latest().expect("receive") {
            break f;
        }
    };

    let h = *frame.header();
    assert_eq!((h.width_px, h.height_px, h.encoding()), (width, height, Some(encoding)));
    let views = if stereo { 2 } else { 1 };
    assert_eq!(h.views(), views);
    let pixels = frame.pixels();
    assert_eq!(pixels.len(), (views * width * height * encoding.bytes_per_pixel()) as usize);
    let (start, end) = (pixels.as_ptr() as usize, pixels.as_ptr() as usize + pixels.len());
    let maps = shm_mappings();
    let inside = maps.iter().find(|(a, b, _)| *a <= start && end <= *b);
    assert!(inside.is_some(), "payload {start:#x}..{end:#x} lies in no /dev/shm mapping: {maps:?}");
    let (_, _, file) = inside.expect("checked");
    assert!(file.contains(&prefix), "mapping {file} is not of this test's bus domain {prefix}");

    // What the camera renders (its default seed, 1): the world as built, through its misaligned
    // mount, with the world's imaging effects for this frame.
    let world = harvey_world::World::load(&world_path).expect("world").as_built(1);
    // A stereo pair is two renders from either side of the mount (the left one first), each
    // with the effects (the right one's noise drawn as another frame).
    let (yaw, pitch) = harvey_render::mount_error(&world.camera, 1);
    let mut renderer = Renderer::new(&world, width, height, encoding).misaligned(yaw, pitch);
    let n = renderer.frame_bytes();
    let mut expected = vec![0u8; n * views as usize];
    let from = harvey_world::Pose2::from_degrees(pose[0], pose[1], pose[2]);
    let bpp = encoding.bytes_per_pixel() as usize;
    let sides: &[(f64, u64)] = match world.camera.stereo_baseline_m.filter(|_| stereo) {
        Some(b) => &[(b / 2.0, h.seq), (-b / 2.0, h.seq ^ (1 << 63))],
        None => &[(0.0, h.seq)],
    };
    for (view, (side, noise_seq)) in expected.chunks_exact_mut(n).zip(sides) {
        renderer.render(&world, from.sideways(*side), view).expect("render");
        let effects = harvey_render::Effects::from_camera(&world.camera, 1);
        effects.apply_at(width as usize, height as usize, bpp, *noise_seq, h.stamp_ns, view);
    }
    assert_eq!(checksum(pixels), checksum(&expected), "frame content differs from the render");

    drop(frame);
    common::signal(&camera, libc::SIGTERM);
    let status = common::wait_exit(&mut camera, Duration::from_secs(10));
    assert!(status.success(), "camera exited with {status}");
    drop(_a);
    drop(frames);
    drop(bus);
    harvey_bus::retire_domain(&prefix).expect("domain retires");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
}

#[test]
fn vga_mono8_frames_are_read_in_place() {
    check(640, 480, Encoding::Mono8, false);
}

#[test]
fn stereo_pairs_are_read_in_place() {
    check(640, 480, Encoding::Mono8, true);
}

#[test]
fn full_hd_rgb8_frames_are_read_in_place() {
    check(1920, 1080, Encoding::Rgb8, false);
}

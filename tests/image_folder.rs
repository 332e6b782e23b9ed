//! The camera's folder source across processes: PNG and JPEG images are played in name order as
//! frames in shared memory, pixel for pixel (PNG) or within JPEG's loss; a folder of mixed sizes
//! is an error naming the file.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::process::{Command, Stdio};
use std::time::Duration;

use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::{Encoding, topics};

fn gradient(w: u32, h: u32, k: u32) -> image::RgbImage {
    image::RgbImage::from_fn(w, h, |x, y| image::Rgb([(x * 4 + k) as u8, (y * 3) as u8, (k * 40) as u8]))
}

#[test]
fn a_folder_of_images_plays_as_frames_in_name_order() {
    let dir = common::scratch("folder");
    let images: Vec<image::RgbImage> = (0..3).map(|k| gradient(64, 48, k)).collect();
    for (k, img) in images.iter().enumerate() {
        img.save(dir.join(format!("frame{k}.png"))).expect("png");
    }
    std::fs::write(dir.join("notes.txt"), "not an image").expect("txt");
    let prefix = common::unique_prefix("img");
    let bus = Bus::join_with_prefix("folder-test", &prefix).expect("bus");
    let frames = bus.frame_subscriber(topics::CAMERA_FRAME).expect("sub");
    let waiter = Waiter::new().expect("waiter");
    let _a = waiter.attach(&frames).expect("attach");
    let mut camera = Command::new(common::bin("harvey-camera"))
        .args(["--images", dir.to_str().expect("utf8"), "--rate-hz", "20", "--frames", "3"])
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .spawn()
        .expect("camera");
    let mut got = Vec::new();
    while got.len() < 3 {
        assert_eq!(
            waiter.wait(Some(Duration::from_secs(20))).expect("wait"),
            Wake::Ready,
            "only {} frames",
            got.len()
        );
        while let Some(f) = frames.take().expect("take") {
            got.push((*f.header(), f.pixels().to_vec()));
        }
    }
    for (k, (h, px)) in got.iter().enumerate() {
        assert_eq!(
            (h.seq, h.width_px, h.height_px, h.encoding()),
            (k as u64 + 1, 64, 48, Some(Encoding::Rgb8))
        );
        assert_eq!(px, images[k].as_raw(), "frame {k} differs from frame{k}.png");
    }
    assert!(common::wait_exit(&mut camera, Duration::from_secs(10)).success());
    drop(_a);
    drop(waiter);
    drop((frames, bus));
    harvey_bus::retire_domain(&prefix).expect("retire");
}

#[test]
fn a_folder_with_a_wrong_sized_image_is_an_error_naming_it() {
    let dir = common::scratch("folder-bad");
    gradient(64, 48, 0).save(dir.join("a.png")).expect("png");
    image::DynamicImage::ImageRgb8(gradient(32, 48, 1)).to_luma8().save(dir.join("b.jpg")).expect("jpg");
    let prefix = common::unique_prefix("imgbad");
    let out = Command::new(common::bin("harvey-camera"))
        .args(["--images", dir.to_str().expect("utf8"), "--rate-hz", "50", "--frames", "5"])
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .stderr(Stdio::piped())
        .output()
        .expect("camera runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("b.jpg: 32x48, but the folder's frames are 64x48"), "{err}");
    harvey_bus::retire_domain(&prefix).expect("retire");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
}

//! What the landmark tests under the sweep's sensor conditions share: the conditions as
//! `conditions/` sets the camera, the hallway lit and rendered under one of them, and whether a
//! point stands in view.

use harvey_msgs::{Encoding, Pose2};
use harvey_render::{Effects, Renderer};
use harvey_world::World;

/// (name, illumination, noise sd, vignetting, blur px), as `conditions/` sets the camera.
pub const CONDITIONS: [(&str, f64, f64, f64, u32); 3] =
    [("nominal", 220.0, 3.0, 0.2, 0), ("dim", 170.0, 5.0, 0.25, 0), ("harsh", 170.0, 8.0, 0.35, 1)];

/// The image size the tests render.
pub const SIZE: (u32, u32) = (640, 480);

/// The hallway under `condition`, with a renderer and the camera's effects for `seed`, and a
/// frame to render into; its mount exactly aligned, or (`mounted`) off by the shipped world's
/// seeded draw (about 3 mrad of yaw and of pitch, which the recognisers' spreads take in).
pub fn lit(
    condition: (&str, f64, f64, f64, u32),
    seed: u64,
    mounted: bool,
) -> (World, Renderer, Effects, Vec<u8>) {
    let (_, light, noise, vignetting, blur) = condition;
    let mut w =
        harvey_world::load_str(include_str!("../../../../worlds/hallway.toml"), "hallway").expect("loads");
    (w.camera.illumination, w.camera.noise_sd, w.camera.vignetting, w.camera.blur_px) =
        (light, noise, vignetting, blur);
    let (yaw, pitch) = if mounted { harvey_render::mount_error(&w.camera, seed) } else { (0.0, 0.0) };
    w.camera.misalignment_sd_rad = 0.0;
    let r = Renderer::new(&w, SIZE.0, SIZE.1, Encoding::Mono8).misaligned(yaw, pitch);
    let fx = Effects::from_camera(&w.camera, seed);
    let px = vec![0u8; r.frame_bytes()];
    (w, r, fx, px)
}

/// Nothing stands between the camera and the point `at` (its wall is hit at its distance).
#[allow(dead_code, reason = "not every test of these looks past walls")]
pub fn unhidden(w: &World, pose: Pose2, at: [f64; 2]) -> bool {
    let (dx, dy) = (at[0] - pose.x_m, at[1] - pose.y_m);
    let d = dx.hypot(dy);
    w.cast_ray([pose.x_m, pose.y_m], [dx / d, dy / d], d).is_none_or(|h| h.distance_m > d - 0.05)
}

//! Camera rendering speed, one core, 640x480 mono8 in the hallway: Harvey's renderer (one ray
//! per column) against a straightforward reference that casts one ray per pixel, and against
//! the memory floor (filling the frame), all measured in the same run. Target: >= 60 frames/s.
//!
//! Run: `cargo bench -p harvey-render --bench render`.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::time::Instant;

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_world::{Pose2, World};

/// The reference: per pixel, cast the ray through it and shade what it meets first.
fn reference(world: &World, pose: Pose2, out: &mut [u8], w: usize, h: usize) {
    let cam = &world.camera;
    let f = cam.focal_px * w as f64 / f64::from(cam.width_px);
    for v in 0..h {
        for u in 0..w {
            let off = ((w as f64 / 2.0 - u as f64 - 0.5) / f).atan();
            let a = pose.heading_rad + off;
            let dir = [a.cos(), a.sin()];
            let down = (v as f64 + 0.5 - h as f64 / 2.0) / f;
            let refl = match world.cast_ray([pose.x_m, pose.y_m], dir, 1e3) {
                Some(hit) => {
                    let depth = hit.distance_m * off.cos();
                    let z = cam.height_m - down * depth;
                    let wall = &world.walls[hit.wall];
                    if (0.0..=wall.height_m).contains(&z) {
                        wall.reflectance_at(hit.along_m, z)
                    } else if z < 0.0 {
                        let range = cam.height_m / down / off.cos();
                        let p = [pose.x_m + dir[0] * range, pose.y_m + dir[1] * range];
                        let t = world.floor.tile_m;
                        world.floor.reflectance
                            [((p[0] / t).floor() as i64 + (p[1] / t).floor() as i64).rem_euclid(2) as usize]
                    } else {
                        world.floor.ceiling_reflectance
                    }
                }
                None => world.floor.ceiling_reflectance,
            };
            out[v * w + u] = (cam.illumination * refl).round().clamp(0.0, 255.0) as u8;
        }
    }
}

fn per_frame_ms(frames: usize, mut f: impl FnMut(usize)) -> f64 {
    let mut times: Vec<f64> = (0..frames)
        .map(|i| {
            let t = Instant::now();
            f(i);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/hallway.toml");
    let world = World::load(std::path::Path::new(path)).expect("hallway world");
    let (w, h) = (640usize, 480usize);
    let mut renderer = Renderer::new(&world, w as u32, h as u32, Encoding::Mono8);
    let mut frame = vec![0u8; w * h];
    let pose = |i: usize| {
        Pose2::new(
            0.5 + (i % 100) as f64 * 0.1,
            0.2 * ((i as f64) * 0.1).sin(),
            0.05 * ((i as f64) * 0.07).cos(),
        )
    };

    let harvey = per_frame_ms(300, |i| renderer.render(&world, pose(i), &mut frame).expect("render"));
    let mut check = vec![0u8; w * h];
    renderer.render(&world, pose(7), &mut frame).expect("render");
    reference(&world, pose(7), &mut check, w, h);
    let differing = frame.iter().zip(&check).filter(|(a, b)| a != b).count();
    let reference_ms = per_frame_ms(20, |i| reference(&world, pose(i), &mut check, w, h));
    let fill = per_frame_ms(300, |i| frame.fill(i as u8));

    println!("| renderer (640x480 mono8, hallway, 1 core) | ms/frame (median) | frames/s | vs reference |");
    println!("|---|---:|---:|---:|");
    println!(
        "| harvey (ray per column) | {harvey:.3} | {:.0} | {:.1}x faster |",
        1e3 / harvey,
        reference_ms / harvey
    );
    println!("| reference (ray per pixel) | {reference_ms:.3} | {:.0} | 1.0x |", 1e3 / reference_ms);
    println!("| memory floor (fill) | {fill:.3} | {:.0} | - |", 1e3 / fill);
    println!("\npixels differing from the reference: {differing} of {} (target: >= 60 frames/s)", w * h);
}

//! Ground truth for tests on rendered frames: what a pixel sees, by casting its ray.

use harvey_world::{Pose2, World};

/// Depth along the optical axis of what image point `at` of a `size` image from `pose` sees,
/// and the height of that point above the floor (0 for the floor itself).
pub fn seen(w: &World, size: [u32; 2], pose: Pose2, at: [f32; 2]) -> (f64, f64) {
    let f = w.camera.focal_for(size[0]);
    let left = (f64::from(size[0]) / 2.0 - f64::from(at[0])) / f;
    let down = (f64::from(at[1]) - f64::from(size[1]) / 2.0) / f;
    let a = pose.heading_rad + left.atan();
    let h = w.camera.height_m;
    let floor = if down > 0.0 { h / down } else { f64::INFINITY };
    // The nearest wall the ray meets between the floor and the wall's top (it passes over a
    // lower one), as the renderer draws it; else the floor.
    let wall = w
        .ray_hits([pose.x_m, pose.y_m], [a.cos(), a.sin()], 1e3)
        .map(|hit| (hit.distance_m * left.atan().cos(), w.walls[hit.wall].height_m))
        .filter(|&(depth, top)| (0.0..=top).contains(&(h - down * depth)))
        .map(|(depth, _)| depth)
        .min_by(f64::total_cmp);
    match wall {
        Some(depth) => (depth, h - down * depth),
        None => (floor, 0.0),
    }
}

/// [`seen`] for a tracked feature: a corner on an occluding edge moves with the nearer surface,
/// so when something within 2 px is more than 15 % nearer, that is what it sees.
pub fn feature(w: &World, size: [u32; 2], pose: Pose2, at: [f32; 2]) -> (f64, f64) {
    let centre = seen(w, size, pose, at);
    let offsets = (-2..=2).flat_map(|i| (-2..=2).map(move |j| [i as f32, j as f32]));
    let nearest = offsets
        .map(|d| seen(w, size, pose, [at[0] + d[0], at[1] + d[1]]))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or(centre);
    if nearest.0 < 0.85 * centre.0 { nearest } else { centre }
}

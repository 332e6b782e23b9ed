//! Depth from motion on rendered frames (001 §2.3, Table 1): the camera drives straight down the
//! hallway towards a box on the floor; tracked points' depths sharpen with every frame, and the
//! floor a calibrated camera expects separates the box's points from the floor's (the paper's
//! row-against-inverse-depth fit is reported beside it).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::Encoding;
use harvey_render::Renderer;
use harvey_vision::depth::{DepthFromMotion, DepthParams, Track, obstacles, standing_off_floor};
use harvey_vision::moravec::MoravecParams;
use harvey_vision::{Gray, Rect};
use harvey_world::{Pose2, Wall, World};

mod common;

const W: u32 = 640;
const H: u32 = 480;

/// The hallway with a dark 0.4 x 0.4 x 0.5 m box with a light band round it, 7 m ahead.
fn world_with_box() -> World {
    let mut w =
        harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("loads");
    let corners = [[7.0, -0.2], [7.0, 0.2], [7.4, 0.2], [7.4, -0.2]];
    let template = w.walls[0].clone();
    for k in 0..4 {
        let mut face: Wall = template.clone();
        (face.from, face.to) = (corners[k], corners[(k + 1) % 4]);
        (face.height_m, face.reflectance) = (0.5, 0.2);
        // A light band round it (tape): corners on its faces, not only on its outline.
        let along = (corners[(k + 1) % 4][0] - corners[k][0]).hypot(corners[(k + 1) % 4][1] - corners[k][1]);
        face.regions = vec![harvey_world::Region {
            along_m: [0.0, along],
            height_m: [0.2, 0.3],
            reflectance: 0.7,
            colour: [1.0, 1.0, 1.0],
        }];
        w.walls.push(face);
    }
    w
}

/// What a tracked feature sees: its depth, and whether it stands off the floor (at least 10 cm
/// up: a wall's foot is floor to any camera).
fn feature_truth(w: &World, pose: Pose2, at: [f32; 2]) -> (f64, bool) {
    let (depth, height) = common::feature(w, [W, H], pose, at);
    (depth, height > 0.10)
}

#[test]
fn depths_sharpen_frame_by_frame_and_the_box_stands_off_the_floor() {
    let w = world_with_box();
    let mut r = Renderer::new(&w, W, H, Encoding::Mono8);
    let mut px = vec![0u8; r.frame_bytes()];
    let f = w.camera.focal_for(W) as f32;
    let params = DepthParams {
        foe: [W as f32 / 2.0, H as f32 / 2.0],
        focal_px: f,
        patch: 11,
        startup_reach_px: 40.0,
        min_depth_m: 0.0,
        update_reach_px: 4.0,
        noise_px: 0.3,
        min_score: 0.97,
        recut_score: 0.995,
        register_reach_px: 0.0,
        moravec: MoravecParams { window: 5, threshold: 3000, suppress_radius: 5, max_corners: 120 },
    };
    let mut dfm = DepthFromMotion::new(params);
    let step = 0.15;
    let mut rows = Vec::new();
    let mut start_depth: Vec<f64> = Vec::new();
    for k in 0..9 {
        let travelled = k as f64 * step;
        let pose = Pose2::new(travelled, 0.0, 0.0);
        r.render(&w, pose, &mut px).expect("renders");
        let img = Gray::new(&px, W as usize, H as usize, W as usize).expect("frame");
        if k == 0 {
            // Below the horizon, ahead of the robot: where obstacles would be.
            let n = dfm.start(&img, Rect::new(200, 250, 440, 470), travelled).expect("starts");
            assert!(n >= 20, "only {n} points to track");
            // Each point's true depth at the start; it shrinks by the travel.
            start_depth = dfm.tracks().map(|t| feature_truth(&w, pose, t.at).0).collect();
            continue;
        }
        dfm.update(&img, travelled).expect("updates");
        let errors: Vec<(f64, f64)> = dfm
            .tracks()
            .filter_map(|t| t.depth.map(|(z, sd)| (t, f64::from(z), f64::from(sd))))
            .map(|(t, z, sd)| {
                let true_z = start_depth[t.id] - travelled;
                ((z - true_z).abs() / true_z, sd / true_z)
            })
            .collect();
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (err, sd) =
            (median(errors.iter().map(|e| e.0).collect()), median(errors.iter().map(|e| e.1).collect()));
        println!(
            "frame {k}: {} points, median depth error {:.1} %, median sd {:.1} %",
            errors.len(),
            100.0 * err,
            100.0 * sd
        );
        rows.push((errors.len(), err, sd));
    }
    let (first, last) = (rows[0], rows[rows.len() - 1]);
    assert!(last.0 >= 15, "{} points tracked to the end", last.0);
    assert!(last.1 < 0.05, "final median error {:.3}", last.1);
    assert!(last.1 < 0.5 * first.1 && last.2 < 0.3 * first.2, "no sharpening: {first:?} -> {last:?}");

    // The box's points stand off the floor's ground line; the floor's lie on it.
    let pose = Pose2::new(8.0 * step, 0.0, 0.0);
    let tracks: Vec<&Track> = dfm.tracks().filter(|t| t.depth.is_some()).collect();
    let fitted = obstacles(&tracks, params.foe[1], 2.0, 0.08, 0.1);
    let off = standing_off_floor(&tracks, params.foe[1], f, w.camera.height_m as f32, 0.1, 0.1);
    let agree = fitted.iter().zip(&off).filter(|(a, b)| a.is_some() && a == b).count();
    println!("the paper's fit agrees with the calibrated floor on {agree} of {} points", tracks.len());
    let judged: Vec<(&&Track, bool)> =
        tracks.iter().zip(&off).filter_map(|(t, o)| o.map(|o| (t, o))).collect();
    // A spread grown by its fit's residuals (a point whose match wandered) leaves a few unjudged.
    assert!(judged.len() * 4 >= tracks.len() * 3, "only {} of {} points judged", judged.len(), tracks.len());
    let (mut right, mut standing, mut on_box) = (0, 0, 0);
    for &(t, is_obstacle) in &judged {
        let (depth, stands) = feature_truth(&w, pose, t.at);
        standing += usize::from(stands);
        // The box's front face is 7 m from the start.
        on_box += usize::from(stands && (depth - (7.0 - 8.0 * step)).abs() < 0.3);
        right += usize::from(stands == is_obstacle);
    }
    let n = judged.len();
    println!(
        "{right} of {n} points classified right ({standing} off the floor, {on_box} of them on the box)"
    );
    assert!(on_box >= 3 && n - standing >= 3, "both kinds of point: {standing} of {n}");
    // 11 of 16 are right: the box's top edge against the floor beyond is an occluding contour
    // whose points slide (003's "bad features"), a baseboard's top (0.13-0.15 m up) is judged
    // against the 0.1 m floor with twice its spread to spare, and a floor point whose depth came
    // out 11 % short stands 0.13 m up. (With the paper's fit, before start-up dropped the slabs'
    // corners that have look-alikes along their radial lines, 22 of 28.)
    assert!(right as f64 >= 0.65 * n as f64, "{right} of {n}");
}

//! Coded poles under the sweep's sensor conditions (`conditions/*.toml`: nominal, dim, harsh),
//! on rendered arena frames with the camera's noise, vignetting and blur: the adaptive ring
//! threshold (`poles::ring_threshold`) finds the poles in view whatever the light, where the
//! fixed grey level 200 it replaced finds none under the dim light (the tape renders at 170
//! and below) and misses most of them under the nominal light too (vignetting takes the tape
//! under 200 away from the centre); an answer naming a wrong code or range stays rare.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_msgs::{Encoding, FrameHeader, Pose2, VisionAlgorithm, VisionRequest};
use harvey_render::{Effects, Renderer};
use harvey_vision_workers::dispatch::Dispatcher;
use harvey_world::{Pole, World};

/// (name, illumination, noise sd, vignetting, blur px), as `conditions/` sets the camera.
const CONDITIONS: [(&str, f64, f64, f64, u32); 3] =
    [("nominal", 220.0, 3.0, 0.2, 0), ("dim", 170.0, 5.0, 0.25, 0), ("harsh", 170.0, 8.0, 0.35, 1)];

#[derive(Debug, Default)]
struct Tally {
    /// Poles in view (centre inside the image's middle 90 %, unhidden, within 8 m).
    in_view: usize,
    /// Of those, found with their code and their range to within 5 %.
    found: usize,
    /// Answers naming a code no pole in view has, or a range off by more than 5 %.
    wrong: usize,
}

fn world() -> World {
    harvey_world::load_str(include_str!("../../../worlds/arena.toml"), "arena").expect("loads")
}

/// Depth of `p` ahead of `pose` (m).
fn depth(pose: Pose2, p: &Pole) -> f64 {
    (p.at[0] - pose.x_m) * pose.heading_rad.cos() + (p.at[1] - pose.y_m) * pose.heading_rad.sin()
}

/// Nothing stands between the camera and the pole (the ray to its centre first meets the
/// pole's own faces, 0.075 m from its centre).
fn unhidden(w: &World, pose: Pose2, p: &Pole) -> bool {
    let (dx, dy) = (p.at[0] - pose.x_m, p.at[1] - pose.y_m);
    let d = dx.hypot(dy);
    w.cast_ray([pose.x_m, pose.y_m], [dx / d, dy / d], d).is_none_or(|h| h.distance_m > d - 0.12)
}

/// Looks round from a few places of the arena, in steps of half the field of view.
fn tally(condition: (&str, f64, f64, f64, u32), seed: u64, fixed_grey: Option<f32>) -> Tally {
    let (_, light, noise, vignetting, blur) = condition;
    let mut w = world();
    (w.camera.illumination, w.camera.noise_sd, w.camera.vignetting, w.camera.blur_px) =
        (light, noise, vignetting, blur);
    let poles = w.place_poles(seed).expect("room");
    let mut d = Dispatcher::new(w.clone());
    let mut r = Renderer::new(&w, 640, 480, Encoding::Mono8);
    let fx = Effects::from_camera(&w.camera, seed);
    let mut px = vec![0u8; r.frame_bytes()];
    let mut req =
        VisionRequest { request_id: 1, algorithm: VisionAlgorithm::Poles as u32, ..Default::default() };
    req.params[0] = fixed_grey.unwrap_or(0.0);
    let mut t = Tally::default();
    let mut seq = 0;
    for at in [[1.5, 1.5], [7.0, 6.0], [12.5, 10.5], [3.0, 9.0], [11.0, 2.5]] {
        for k in 0..12 {
            seq += 1;
            let pose = Pose2::new(at[0], at[1], f64::from(k) * 30f64.to_radians());
            r.render(&w, pose, &mut px).expect("renders");
            fx.apply(640, 480, 1, seq, &mut px);
            let h = FrameHeader::new(seq, seq * 100_000_000, 640, 480, Encoding::Mono8);
            let res = d.answer(&h, &px, &req);
            let visible: Vec<&Pole> = poles
                .iter()
                .filter(|p| {
                    let z = depth(pose, p);
                    let col = w.camera.project(640, 480, pose, [p.at[0], p.at[1], 1.0]);
                    (0.8..8.0).contains(&z)
                        && col.is_some_and(|c| (32.0..608.0).contains(&c[0]))
                        && unhidden(&w, pose, p)
                })
                .collect();
            t.in_view += visible.len();
            for item in &res.items[..res.count as usize] {
                let [_, range, code, ..] = item.values;
                let good = |p: &&Pole| {
                    p.code == code as u32 && (f64::from(range) / depth(pose, p) - 1.0).abs() < 0.05
                };
                if visible.iter().any(good) {
                    t.found += 1;
                } else if !poles.iter().any(|p| good(&p)) {
                    t.wrong += 1;
                }
            }
        }
    }
    t
}

#[test]
fn poles_are_found_under_every_condition_and_a_wrong_code_is_rare() {
    // Seeds 1..8 of the poles' places, five places a look round each: 89 % of the poles in view
    // found under each condition (the fixed grey level: 24 %, 0 %, 0 %), wrong answers 0, 0 and
    // 3 of some 385 (the fixed level: 22 under nominal). Once the renderer showed what stands
    // above the arena's boxes harsh gave 6 wrong (ring fragments read as poles 33-74 m off);
    // with the range and width checks of `poles::group`, 0 under every condition.
    for condition in CONDITIONS {
        let (mut in_view, mut found, mut wrong) = (0, 0, 0);
        for seed in 1..=8 {
            let adaptive = tally(condition, seed, None);
            let fixed = tally(condition, seed, Some(200.0));
            eprintln!("{} seed {seed}: adaptive {adaptive:?}, fixed 200 {fixed:?}", condition.0);
            assert!(adaptive.in_view >= 40, "{adaptive:?}");
            assert!(
                adaptive.found as f64 >= 0.75 * adaptive.in_view as f64,
                "{} seed {seed}: {adaptive:?}",
                condition.0
            );
            assert!(
                adaptive.found > fixed.found,
                "{} seed {seed}: {adaptive:?} against {fixed:?}",
                condition.0
            );
            (in_view, found, wrong) =
                (in_view + adaptive.in_view, found + adaptive.found, wrong + adaptive.wrong);
        }
        let name = condition.0;
        assert!(found as f64 >= 0.85 * in_view as f64, "{name}: {found} of {in_view} found");
        assert!(wrong as f64 <= 0.01 * (found + wrong) as f64, "{name}: {wrong} wrong of {}", found + wrong);
    }
}

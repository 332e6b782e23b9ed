//! Class I landmarks (door jambs, the end wall's corner) under the sweep's sensor conditions
//! (`conditions/*.toml`: nominal, dim, harsh), on rendered hallway frames with the camera's
//! noise, vignetting and blur: the recogniser (`landmarks::LineLandmarks`) is given the window
//! an Expecter would give round the landmark's true column, from poses along the hall, and its
//! answers are judged against that column. Counted: right (within 1.5 px), wrong (another
//! edge: the blunders the UMS must refuse) and silent (not found or ambiguous). Prints the
//! table `docs/evaluation.md` quotes.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod light;

use harvey_msgs::{Encoding, Expectation, FrameHeader, Pose2, SightingKind};
use harvey_vision_workers::landmarks::LineLandmarks;
use harvey_world::LandmarkClass;
use light::{CONDITIONS, SIZE, lit, unhidden};

#[derive(Debug, Default)]
struct Tally {
    asked: usize,
    right: usize,
    wrong: usize,
}

/// Looks down the hall from poses along it, each class I landmark in view searched for in a
/// window from `window_px[0]` to `window_px[1]` columns from its true one; with `look`, the
/// window carries the landmark's look as an Expecter predicts it from a believed pose 5 cm
/// further along x and y (the hall's length and width) and 1 degree to the left of the true one.
fn tally(condition: (&str, f64, f64, f64, u32), seed: u64, window_px: [f64; 2], look: bool) -> Tally {
    let (w, mut r, fx, mut px) = lit(condition, seed, false);
    let (width, height) = SIZE;
    let mut lines = LineLandmarks::new(w.camera.focal_px, 12.0).with_blur(w.camera.blur_px);
    let mut t = Tally::default();
    let mut seq = 0;
    for x in [-0.5, 0.5, 1.5, 2.5, 3.5, 5.5, 6.5, 7.5, 8.5, 9.5] {
        for y in [-0.4, 0.0, 0.4] {
            for deg in [-8.0, 0.0, 8.0] {
                seq += 1;
                let pose = Pose2::new(x, y, f64::to_radians(deg));
                r.render(&w, pose, &mut px).expect("renders");
                fx.apply(width as usize, height as usize, 1, seq, &mut px);
                let h = FrameHeader::new(seq, seq * 100_000_000, width, height, Encoding::Mono8);
                for (i, l) in w.landmarks.iter().enumerate().filter(|(_, l)| l.class == LandmarkClass::I) {
                    let [lx, ly, lz] = l.position_m;
                    let (foot, head) = (
                        w.camera.project(width, height, pose, [lx, ly, lz]),
                        w.camera.project(width, height, pose, [lx, ly, lz + l.height_m]),
                    );
                    let (Some(foot), Some(head)) = (foot, head) else { continue };
                    let range = (lx - x).hypot(ly - y);
                    if !(40.0..600.0).contains(&foot[0])
                        || range > l.activation_range_m
                        || !unhidden(&w, pose, [lx, ly])
                    {
                        continue;
                    }
                    let believed = Pose2::new(x + 0.05, y + 0.05, f64::to_radians(deg + 1.0));
                    let predicted = || {
                        let [u, _] = w.camera.project(width, height, believed, [lx, ly, lz])?;
                        let rows = [head[1].max(0.0), foot[1].min(f64::from(height))];
                        Some(harvey_render::edge_contrast(&w, believed, SIZE, u, rows))
                    };
                    let contrast = if look { predicted().unwrap_or_default() } else { [0.0; 4] };
                    let e = Expectation {
                        contrast,
                        landmark_index: i as u32,
                        class: 1,
                        window_px: [
                            (foot[0] + window_px[0]) as f32,
                            head[1].max(0.0) as f32,
                            (foot[0] + window_px[1]) as f32,
                            foot[1].min(f64::from(height)) as f32,
                        ],
                        width_px: width,
                        height_px: height,
                        ..Default::default()
                    };
                    t.asked += 1;
                    let Some(s) = lines.recognise(&h, &px, &e) else { continue };
                    if s.kind != SightingKind::Bearing as u32 {
                        continue;
                    }
                    let seen = f64::from(width) / 2.0 - w.camera.focal_px * s.a.tan();
                    if (seen - foot[0]).abs() <= 1.5 { t.right += 1 } else { t.wrong += 1 }
                }
            }
        }
    }
    t
}

#[test]
fn the_landmarks_are_found_where_they_are_whatever_the_light() {
    println!(
        "| condition | window (px from the landmark) | look predicted | asked | right | wrong | silent |"
    );
    println!("|---|---|---|---:|---:|---:|---:|");
    for c in CONDITIONS {
        // Centred on the landmark, narrow and wide; then beside it, the landmark outside (a
        // map that is off): every answer there is another edge. Each without and with the
        // landmark's look predicted.
        let mut beside = [0.0; 2];
        for window in [[-15.0, 15.0], [-30.0, 30.0], [6.0, 36.0], [-36.0, -6.0]] {
            let [plain, look] = [false, true].map(|look| {
                let mut all = Tally::default();
                for seed in [1, 2] {
                    let t = tally(c, seed, window, look);
                    (all.asked, all.right, all.wrong) =
                        (all.asked + t.asked, all.right + t.right, all.wrong + t.wrong);
                }
                let pct = |n: usize| 100.0 * n as f64 / all.asked.max(1) as f64;
                println!(
                    "| {} | {:+} to {:+} | {} | {} | {:.1} % | {:.1} % | {:.1} % |",
                    c.0,
                    window[0],
                    window[1],
                    if look { "yes" } else { "no" },
                    all.asked,
                    pct(all.right),
                    pct(all.wrong),
                    pct(all.asked - all.right - all.wrong)
                );
                assert!(all.asked >= 100, "{}: too few landmarks in view ({})", c.0, all.asked);
                (pct(all.right), pct(all.wrong))
            });
            let centred = window[0] < 0.0 && window[1] > 0.0;
            if centred {
                for (right, wrong) in [plain, look] {
                    assert!(right >= 50.0, "{} {window:?}: found where they are {right:.1} %", c.0);
                    assert!(wrong <= 3.0, "{} {window:?}: wrong answers {wrong:.1} %", c.0);
                }
                // The look turns silences into answers, never into more wrong ones.
                assert!(
                    look.0 >= plain.0,
                    "{} {window:?}: right {:.1} % with the look, {:.1} %",
                    c.0,
                    look.0,
                    plain.0
                );
                assert!(look.1 <= plain.1 + 0.5, "{} {window:?}: wrong {:.1} % with the look", c.0, look.1);
            } else {
                assert!(plain.1 <= 30.0, "{} {window:?}: another edge taken {:.1} %", c.0, plain.1);
                beside = [beside[0] + plain.1, beside[1] + look.1];
            }
        }
        // Beside the landmark, the look refuses a quarter of the edges taken for it, or more.
        assert!(
            beside[1] <= 0.75 * beside[0],
            "{}: beside, {:.1} % with the look, {:.1} % without",
            c.0,
            beside[1],
            beside[0]
        );
    }
}

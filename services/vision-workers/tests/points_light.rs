//! Class II landmarks (the office's sign and the exit sign: points of known height) under the
//! sweep's sensor conditions (nominal, dim, harsh), on rendered hallway frames with the camera's
//! noise, vignetting and blur: the recogniser (`landmarks::point::PointLandmarks`) is given a
//! window round the sign's true place, as an Expecter would, from poses along the hall, and its
//! bearing and range are judged against the truth. Counted: right (bearing and range each within
//! three of their own standard deviations, which take in the mount's calibration: 1.8 px), wrong
//! (blunders among them: past five deviations, another thing taken for the sign) and silent; in
//! windows beside the sign (moved 120 px off: the sign outside even once the recogniser pads the
//! window by the sign's size, but for a sign seen close) nothing else may be taken for it.
//! Prints the table `docs/evaluation.md` quotes. The mount is aligned here: with the shipped
//! world's 3 mrad drawn, harsh's wider windows took another thing for the sign once in 196
//! (docs/evaluation.md), a miss left open.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod light;

use harvey_msgs::{Encoding, Expectation, FrameHeader, Pose2, SightingKind};
use harvey_vision_workers::landmarks::point::PointLandmarks;
use harvey_world::LandmarkClass;
use light::{CONDITIONS, SIZE, lit, unhidden};

#[derive(Debug, Default)]
struct Tally {
    asked: usize,
    right: usize,
    wrong: usize,
    /// Of the wrong, those off by more than five of their deviations in bearing or range
    /// (another thing taken for the sign).
    blunders: usize,
    /// The worst range error in its own standard deviations, and the worst bearing error
    /// (pixels), among the right and wrong answers.
    worst_z: f64,
    worst_px: f64,
}

/// From poses along the hall, each class II landmark in view searched for in a window of
/// `half_px` either side of its true place, moved `shift_px` sideways.
fn tally(condition: (&str, f64, f64, f64, u32), seed: u64, half_px: f64, shift_px: f64) -> Tally {
    let (w, mut r, fx, mut px) = lit(condition, seed, false);
    let (width, height) = SIZE;
    let mut points = PointLandmarks::new(&w, w.survey.calibration_sd_rad);
    let mut t = Tally::default();
    let mut seq = 0;
    for x in [-0.5, 1.5, 3.5, 5.5, 7.5, 9.0, 10.5] {
        for y in [-0.4, 0.0, 0.4] {
            for deg in [-8.0, 0.0, 8.0] {
                seq += 1;
                let pose = Pose2::new(x, y, f64::to_radians(deg));
                r.render(&w, pose, &mut px).expect("renders");
                fx.apply(width as usize, height as usize, 1, seq, &mut px);
                let h = FrameHeader::new(seq, seq * 100_000_000, width, height, Encoding::Mono8);
                for (i, l) in w.landmarks.iter().enumerate().filter(|(_, l)| l.class == LandmarkClass::II) {
                    let [lx, ly, _] = l.position_m;
                    let Some([u, v]) = w.camera.project(width, height, pose, l.position_m) else { continue };
                    let range = (lx - x).hypot(ly - y);
                    if !(60.0..580.0).contains(&u)
                        || range > l.activation_range_m
                        || !unhidden(&w, pose, [lx, ly])
                    {
                        continue;
                    }
                    let e = Expectation {
                        landmark_index: i as u32,
                        class: 2,
                        window_px: [
                            (u + shift_px - half_px) as f32,
                            (v - half_px) as f32,
                            (u + shift_px + half_px) as f32,
                            (v + half_px) as f32,
                        ],
                        width_px: width,
                        height_px: height,
                        ..Default::default()
                    };
                    t.asked += 1;
                    let Some(s) = points.recognise(&h, &px, &e) else { continue };
                    if s.kind != SightingKind::BearingRange as u32 {
                        continue;
                    }
                    let seen_u = f64::from(width) / 2.0 - w.camera.focal_px * s.a.tan();
                    let z = (s.b - range).abs() / s.b_sd;
                    let off_px = (seen_u - u).abs();
                    (t.worst_z, t.worst_px) = (t.worst_z.max(z), t.worst_px.max(off_px));
                    let zb = off_px / (s.a_sd * w.camera.focal_px);
                    if zb <= 3.0 && z <= 3.0 {
                        t.right += 1;
                    } else {
                        t.wrong += 1;
                        t.blunders += usize::from(zb > 5.0 || z > 5.0);
                    }
                }
            }
        }
    }
    t
}

#[test]
fn the_signs_are_ranged_by_their_rows_whatever_the_light() {
    println!(
        "| condition | window | asked | right | wrong | silent | worst range error (sd) | worst bearing (px) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    for c in CONDITIONS {
        // Centred, narrow and wide; then beside the sign, the sign outside the window.
        for (half, shift, what) in [(30.0, 0.0, "±30 px"), (60.0, 0.0, "±60 px"), (30.0, 120.0, "beside")] {
            let mut all = Tally::default();
            for seed in [1, 2] {
                let t = tally(c, seed, half, shift);
                (all.asked, all.right, all.wrong) =
                    (all.asked + t.asked, all.right + t.right, all.wrong + t.wrong);
                all.blunders += t.blunders;
                (all.worst_z, all.worst_px) = (all.worst_z.max(t.worst_z), all.worst_px.max(t.worst_px));
            }
            let pct = |n: usize| 100.0 * n as f64 / all.asked.max(1) as f64;
            let silent = all.asked - all.right - all.wrong;
            println!(
                "| {} | {what} | {} | {:.1} % | {:.1} % | {:.1} % | {:.1} | {:.1} |",
                c.0,
                all.asked,
                pct(all.right),
                pct(all.wrong),
                pct(silent),
                all.worst_z,
                all.worst_px
            );
            assert!(all.asked >= 50, "{} {what}: {} asked", c.0, all.asked);
            if shift == 0.0 {
                // Found nearly always in its window (under harsh, noise and blur break the far
                // exit sign, a dozen pixels wide, now and then: silence, not a wrong answer).
                let bar = if c.0 == "harsh" { 70.0 } else { 90.0 };
                assert!(pct(all.right) >= bar, "{} {what}: {:.1} % right", c.0, pct(all.right));
            }
            // Never another thing taken for the sign; now and then (harsh, a sign seen close at a
            // slant) a bearing a little past three deviations.
            assert_eq!(all.blunders, 0, "{} {what}: {} blunders", c.0, all.blunders);
            assert!(pct(all.wrong) <= 1.0, "{} {what}: {:.1} % wrong", c.0, pct(all.wrong));
        }
    }
}

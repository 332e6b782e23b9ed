//! Path following with the line finder (001 §2.1): a sidewalk drawn in perspective drifts
//! across the image frame by frame; the grouped edges, centreline and vanishing point follow it
//! from a bootstrap prediction 10 px and 3 degrees off; with an edge hidden, the path is lost
//! (confidence too low even with widened tolerances) and the last model is kept. A path too faint
//! for the line finder's fragments is found by its edges' steps (`path_steps.rs`).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::path::{ImageLine, PathParams, PathTracker};

#[path = "common/sidewalk.rs"]
mod sidewalk;
use sidewalk::path;

fn truth(vx: f32, xb: f32) -> ImageLine {
    ImageLine::through([vx, 200.0], [xb, 480.0])
}

#[test]
fn the_path_is_followed_frame_by_frame_and_lost_when_an_edge_is_hidden() {
    let mut flf = Flf::default();
    let p = FlfParams { min_length: 15.0, min_gradient: 10.0, ..FlfParams::default() };
    let params = PathParams { max_distance_px: 15.0, max_angle: 0.1, min_confidence: 300.0 };
    // Bootstrap: the map's prediction, 10 px and 3 degrees off the first frame's edges.
    let off = |l: ImageLine| ImageLine { point: [l.point[0] + 10.0, l.point[1]], angle: l.angle + 0.05 };
    let mut tracker =
        PathTracker::new(off(truth(320.0, 150.0)), off(truth(320.0, 490.0)), 200.0, 479.0, params);
    for k in 0..6 {
        let shift = 4.0 * k as f32;
        let (vx, xl, xr) = (320.0 + shift, 150.0 + 1.5 * shift, 490.0 + 1.5 * shift);
        let img = path(vx, xl, xr, false);
        let lines = flf.lines(&img.view(), img.view().full(), &p).expect("lines").to_vec();
        let fit = tracker.update(&lines).unwrap_or_else(|| panic!("frame {k}: lost"));
        let (tl, tr) = (truth(vx, xl), truth(vx, xr));
        for (got, want) in [(fit.left, tl), (fit.right, tr)] {
            assert!((got.x_at(470.0) - want.x_at(470.0)).abs() < 1.5, "frame {k}: {got:?} vs {want:?}");
            let mut turn = (got.angle - want.angle).rem_euclid(std::f32::consts::PI);
            turn = turn.min(std::f32::consts::PI - turn);
            assert!(turn < 1f32.to_radians(), "frame {k}: {got:?} vs {want:?}");
        }
        assert!(
            (fit.vanishing[0] - vx).abs() < 3.0 && (fit.vanishing[1] - 200.0).abs() < 3.0,
            "{:?}",
            fit.vanishing
        );
        assert!((fit.centreline.x_at(479.0) - (xl + xr) / 2.0).abs() < 1.5, "{:?}", fit.centreline);
        assert!(fit.confidence > 300.0);
    }
    // The clean sidewalk's fragments are its edges by their steps too: checked, the same fit.
    let mut search = harvey_vision::path_steps::StepSearch::default();
    let img = path(332.0, 168.0, 508.0, false);
    let lines = flf.lines(&img.view(), img.view().full(), &p).expect("lines").to_vec();
    let unchecked = tracker.clone().update(&lines);
    assert!(unchecked.is_some());
    assert_eq!(
        tracker.clone().update_checked(&lines, &img.view(), img.view().full(), &mut search),
        unchecked
    );
    // The right verge covered (a passer-by): lost, and the model is kept for the next image.
    let before = tracker.clone();
    let img = path(344.0, 180.0, 520.0, true);
    let lines = flf.lines(&img.view(), img.view().full(), &p).expect("lines").to_vec();
    assert_eq!(tracker.update(&lines), None);
    assert_eq!(tracker, before);
}

/// The sidewalk with its path only `step` grey levels above its verges, under noise of sd 8 (the
/// harsh day's camera: its gravel steps 16-25 above dry grass, but blurred and on a checker);
/// `step` 0: the verges alone.
fn faint(vx: f32, xl: f32, xr: f32, step: f32, seed: u64) -> harvey_vision::GrayBuf {
    let img = path(vx, xl, xr, false);
    let mut rng = harvey_geometry::Rng::new(seed);
    let noise: Vec<f64> = (0..640 * 480).map(|_| rng.normal(0.0, 8.0)).collect();
    harvey_vision::GrayBuf::from_fn(640, 480, |x, y| {
        let share = (f32::from(img.view().at(x, y)) - 50.0) / 130.0;
        (60.0 + step * share + noise[y * 640 + x] as f32).round().clamp(0.0, 255.0) as u8
    })
}

#[test]
fn a_faint_path_lost_by_its_fragments_is_found_by_its_steps() {
    use harvey_vision::path_steps::StepSearch;
    let mut flf = Flf::default();
    // The vision workers' path request's line finder (`services/vision-workers/src/path.rs`).
    let p = FlfParams { min_length: 5.0, min_gradient: 8.0, noise_factor: 1.2, ..FlfParams::default() };
    let params = PathParams { max_distance_px: 30.0, max_angle: 10f32.to_radians(), min_confidence: 60.0 };
    let off = |l: ImageLine| ImageLine { point: [l.point[0] + 10.0, l.point[1]], angle: l.angle + 0.05 };
    let mut search = StepSearch::default();
    let (mut worst_x, mut worst_turn, mut by_fragments) = (0.0f32, 0.0f32, 0);
    for seed in 1..=6u64 {
        let mut tracker =
            PathTracker::new(off(truth(320.0, 150.0)), off(truth(320.0, 490.0)), 240.0, 479.0, params);
        for k in 0..4 {
            let shift = 4.0 * k as f32;
            let (vx, xl, xr) = (320.0 + shift, 150.0 + 1.5 * shift, 490.0 + 1.5 * shift);
            let img = faint(vx, xl, xr, 10.0, seed * 10 + k as u64);
            let lines = flf.lines(&img.view(), img.view().full(), &p).expect("lines").to_vec();
            if tracker.clone().update(&lines).is_some() {
                by_fragments += 1;
            }
            // Checked against the steps, the fragments' fit (if any) gives way to the steps'.
            let checked = tracker.clone().update_checked(&lines, &img.view(), img.view().full(), &mut search);
            let fit = tracker
                .update_by_steps(&img.view(), img.view().full(), &mut search)
                .unwrap_or_else(|| panic!("seed {seed} frame {k}: lost"));
            assert_eq!(checked, Some(fit), "seed {seed} frame {k}");
            for (got, want) in [(fit.left, truth(vx, xl)), (fit.right, truth(vx, xr))] {
                worst_x = worst_x.max((got.x_at(470.0) - want.x_at(470.0)).abs());
                let mut turn = (got.angle - want.angle).rem_euclid(std::f32::consts::PI);
                turn = turn.min(std::f32::consts::PI - turn);
                worst_turn = worst_turn.max(turn);
            }
        }
    }
    println!(
        "by steps: worst {worst_x:.2} px at row 470, {:.2} deg; by fragments: {by_fragments} of 24 frames",
        worst_turn.to_degrees()
    );
    assert!(worst_x <= 2.0 && worst_turn.to_degrees() <= 1.0);
    assert!(by_fragments <= 12, "the fragments found {by_fragments} of 24: not a faint path");
    // The verges alone: nothing stands out, and the tracker keeps its model.
    for seed in 1..=6u64 {
        let mut tracker = PathTracker::new(truth(320.0, 150.0), truth(320.0, 490.0), 240.0, 479.0, params);
        let before = tracker.clone();
        let img = faint(320.0, 150.0, 490.0, 0.0, 100 + seed);
        assert_eq!(tracker.update_by_steps(&img.view(), img.view().full(), &mut search), None, "seed {seed}");
        assert_eq!(tracker, before);
    }
}

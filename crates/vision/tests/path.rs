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
            let turn = harvey_vision::path::turn_between(got.angle, want.angle);
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
            PathTracker::new(off(truth(320.0, 150.0)), off(truth(320.0, 490.0)), 200.0, 479.0, params);
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
                let turn = harvey_vision::path::turn_between(got.angle, want.angle);
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
        let mut tracker = PathTracker::new(truth(320.0, 150.0), truth(320.0, 490.0), 200.0, 479.0, params);
        let before = tracker.clone();
        let img = faint(320.0, 150.0, 490.0, 0.0, 100 + seed);
        assert_eq!(tracker.update_by_steps(&img.view(), img.view().full(), &mut search), None, "seed {seed}");
        assert_eq!(tracker, before);
    }
}

/// A fragment of `length` px along `line`, its middle at row `y` shifted `dx` px along the row.
fn fragment(line: &ImageLine, y: f32, dx: f32, length: f32) -> harvey_vision::flf::Line {
    let (s, c) = line.angle.sin_cos();
    let mid = [line.x_at(y) + dx, y];
    let h = length / 2.0;
    harvey_vision::flf::Line {
        from: [mid[0] - h * c, mid[1] - h * s],
        to: [mid[0] + h * c, mid[1] + h * s],
        length,
        orientation_deg: line.angle.to_degrees().rem_euclid(180.0),
        mean_gradient: 20.0,
        dispersion: 0.5,
        pixels: length as u32,
    }
}

#[test]
fn a_fit_that_does_not_follow_from_the_prediction_is_refused() {
    use harvey_vision::path::group;
    let params = PathParams { max_distance_px: 15.0, max_angle: 10f32.to_radians(), min_confidence: 40.0 };
    let (left, right) = (truth(320.0, 150.0), truth(320.0, 490.0));
    let on_right: Vec<_> = [300.0, 360.0, 420.0].iter().map(|&y| fragment(&right, y, 0.0, 30.0)).collect();
    let turn = |a: f32, b: f32| harvey_vision::path::turn_between(a, b).to_degrees();
    // Short fragments along the left edge's direction, each within the tolerances of it, but
    // stacked down one column: their ends' principal axis stands near upright (harsh seed 2's
    // gravel, where such a fit of 80 degrees took the tracker off the path for good).
    let x = left.x_at(420.0);
    let mut stacked: Vec<_> =
        [400.0, 420.0, 440.0].iter().map(|&y| fragment(&left, y, x - left.x_at(y), 8.0)).collect();
    stacked.extend(on_right.iter().copied());
    let fit = group(&stacked, &left, &right, 200.0, 479.0, &params).expect("grouped");
    assert!(turn(fit.left.angle, left.angle) > 20.0, "{:?}", fit.left);
    // Both edges vanishing 40 px higher (the camera would have pitched 4 degrees in a frame):
    // each edge turns only some degrees.
    let risen: Vec<_> = [150.0, 490.0]
        .iter()
        .flat_map(|&xb| {
            let higher = ImageLine::through([320.0, 160.0], [xb, 480.0]);
            [300.0, 360.0, 420.0].map(|y| fragment(&higher, y, 0.0, 30.0))
        })
        .collect();
    let fit = group(&risen, &left, &right, 200.0, 479.0, &params).expect("grouped");
    assert!(turn(fit.left.angle, left.angle) < 10.0 && (fit.vanishing[1] - 200.0).abs() > 30.0, "{fit:?}");
    for lines in [&stacked, &risen] {
        let mut tracker = PathTracker::new(left, right, 200.0, 479.0, params);
        let before = tracker.clone();
        assert_eq!(tracker.update(lines), None);
        assert_eq!(tracker, before);
    }
    // The same fragments along the predicted edges are followed.
    let mut along: Vec<_> = [300.0, 360.0, 420.0].iter().map(|&y| fragment(&left, y, 0.0, 30.0)).collect();
    along.extend(on_right.iter().copied());
    let fit = PathTracker::new(left, right, 200.0, 479.0, params).update(&along).expect("followed");
    assert!((fit.vanishing[1] - 200.0).abs() < 1.0 && (fit.vanishing[0] - 320.0).abs() < 1.0, "{fit:?}");
}

#[test]
fn a_fit_follows_when_its_edges_turn_and_its_vanishing_row_moves_within_the_tolerances() {
    use harvey_vision::path::PathFit;
    let params = PathParams { max_distance_px: 30.0, max_angle: 15f32.to_radians(), min_confidence: 60.0 };
    let (left, right) = (truth(320.0, 150.0), truth(320.0, 490.0));
    let tracker = PathTracker::new(left, right, 200.0, 479.0, params);
    // Both edges through `v`, the left one turned `turn` degrees about it.
    let fit = |v: [f32; 2], turn: f32| {
        let l =
            ImageLine { point: v, angle: ImageLine::through(v, [150.0, 480.0]).angle + turn.to_radians() };
        let r = ImageLine::through(v, [490.0, 480.0]);
        PathFit {
            left: l,
            right: r,
            centreline: ImageLine::through(v, [320.0, 479.0]),
            vanishing: v,
            confidence: 100.0,
        }
    };
    assert!(tracker.follows(&fit([320.0, 200.0], 0.0), &params));
    assert!(tracker.follows(&fit([320.0, 200.0], 14.0), &params));
    assert!(tracker.follows(&fit([320.0, 200.0], -14.0), &params));
    assert!(!tracker.follows(&fit([320.0, 200.0], 16.0), &params), "turned past the angle");
    assert!(!tracker.follows(&fit([320.0, 200.0], -16.0), &params), "turned past the angle");
    // The same direction given half a turn round.
    assert!(tracker.follows(&fit([320.0, 200.0], 180.0), &params));
    assert!(tracker.follows(&fit([335.0, 228.0], 0.0), &params));
    assert!(!tracker.follows(&fit([335.0, 232.0], 0.0), &params), "the vanishing row moved 32 px");
    assert!(!tracker.follows(&fit([320.0, 168.0], 0.0), &params), "the vanishing row moved 32 px");
}

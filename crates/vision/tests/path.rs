//! Path following with the line finder (001 §2.1): a sidewalk drawn in perspective drifts
//! across the image frame by frame; the grouped edges, centreline and vanishing point follow it
//! from a bootstrap prediction 10 px and 3 degrees off; with an edge hidden, the path is lost
//! (confidence too low even with widened tolerances) and the last model is kept.
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
    // The right verge covered (a passer-by): lost, and the model is kept for the next image.
    let before = tracker.clone();
    let img = path(344.0, 180.0, 520.0, true);
    let lines = flf.lines(&img.view(), img.view().full(), &p).expect("lines").to_vec();
    assert_eq!(tracker.update(&lines), None);
    assert_eq!(tracker, before);
}

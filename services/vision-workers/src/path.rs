//! The path-following request (001 §2.1, `VisionAlgorithm::Path`): the line finder's fragments in
//! the window grouped into the path's two edges by a tracker kept per request id, bootstrapped
//! from the request's predicted edges and fed forward from each confident fit that follows from
//! the prediction (`PathTracker::follows`). A fit whose edges
//! do not step in the frame (a checker's diagonals grouped on a dim, noisy day), or none, gives way
//! to the edges' steps searched near the prediction (`harvey_vision::path_steps`).

use std::collections::BTreeMap;

use harvey_msgs::{VisionRequest, VisionStatus};
use harvey_vision::flf::{Flf, FlfParams};
use harvey_vision::path::{ImageLine, PathParams, PathTracker};
use harvey_vision::path_steps::StepSearch;
use harvey_vision::{Gray, Rect};

/// The line finder's settings for path edges: fragments of at least this length (px), at this
/// least gradient (grey levels a pixel): a lawn's blades and a paver's joints give short ones.
const MIN_LENGTH_PX: f32 = 5.0;
const MIN_GRADIENT: f32 = 8.0;
/// The gradient floors rise to this many times the window's noise (the line finder's default is
/// 3.5): a gravel path's edge on a dim day steps little more than that.
const NOISE_FACTOR: f32 = 1.2;

/// What a tracker was started from: the request's parameters and the rows of its edges.
type Started = ([f32; 8], [f32; 2]);

/// One tracker per request id, with the parameters and rows it was started from (a request of the
/// id with others starts afresh; one with another window goes on in the new window).
#[derive(Debug, Default)]
pub struct PathTrackers {
    trackers: BTreeMap<u32, (Started, PathTracker)>,
    steps: StepSearch,
}

impl PathTrackers {
    /// Tracks the path in `window` of `img` for `req`: the fit's items (centreline, left edge,
    /// right edge) through `push`, none when no fit is confident.
    pub fn answer(
        &mut self,
        flf: &mut Flf,
        img: &Gray<'_>,
        window: Rect,
        req: &VisionRequest,
        push: &mut impl FnMut([f32; 6]),
    ) -> Result<(), VisionStatus> {
        let p = &req.params;
        let (top, bottom) = (window.y0 as f32, window.y1 as f32 - 1.0);
        let params = PathParams {
            max_distance_px: or(p[4], 30.0),
            max_angle: or(p[5], 10.0).to_radians(),
            min_confidence: or(p[6], 60.0),
        };
        // The rows the predicted edges' columns are given at.
        let rows = [req.expected.x_m as f32, req.expected.y_m as f32];
        let sane = p[..4].iter().all(|x| x.is_finite())
            && rows.iter().all(|r| r.is_finite())
            && rows[1] > rows[0]
            && params.max_distance_px > 0.0
            && params.max_distance_px < 1000.0
            && params.max_angle > 0.0
            && params.max_angle < std::f32::consts::FRAC_PI_2
            && params.min_confidence > 0.0
            && bottom > top;
        if !sane {
            return Err(VisionStatus::BadParameter);
        }
        let key = (*p, rows);
        // The horizon of a level camera until a fit's vanishing point takes its place.
        let horizon = img.height as f32 / 2.0;
        let fresh = |_: &u32| {
            let left = ImageLine::through([p[0], rows[0]], [p[1], rows[1]]);
            let right = ImageLine::through([p[2], rows[0]], [p[3], rows[1]]);
            (key, PathTracker::new(left, right, horizon, bottom, params))
        };
        let entry = self.trackers.entry(req.request_id).or_insert_with_key(fresh);
        if entry.0 != key {
            *entry = fresh(&req.request_id);
        }
        let tracker = &mut entry.1;
        let flf_params = FlfParams {
            min_length: MIN_LENGTH_PX,
            min_gradient: MIN_GRADIENT,
            noise_factor: NOISE_FACTOR,
            ..FlfParams::default()
        };
        let lines = flf.lines(img, window, &flf_params).map_err(|e| crate::dispatch::status_of(&e))?;
        let fit = tracker.update_checked(lines, img, window, &mut self.steps);
        if let Some(fit) = fit {
            let c = fit.centreline;
            push([fit.vanishing[0], fit.vanishing[1], c.x_at(bottom), bottom, fit.confidence, 0.0]);
            for e in [fit.left, fit.right] {
                push([e.point[0], e.point[1], e.angle, 0.0, 0.0, 0.0]);
            }
        }
        Ok(())
    }
}

/// `x`, or `default` when it is zero (unset).
fn or(x: f32, default: f32) -> f32 {
    if x == 0.0 { default } else { x }
}

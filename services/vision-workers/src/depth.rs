//! The depth-from-motion request (001 §2.3, `VisionAlgorithm::Depth`): one tracker per request
//! id, started on the Moravec points of the window and fed each later frame of a straight run
//! with the odometry's travel and turn (each frame registered against the run's first); each
//! answer carries every point's depth and spread and whether it stands off the floor the
//! calibrated camera expects.

use std::collections::BTreeMap;

use harvey_msgs::{VisionRequest, VisionStatus};
use harvey_vision::depth::{DepthFromMotion, DepthParams, Track, standing_off_floor};
use harvey_vision::moravec::MoravecParams;
use harvey_vision::{Gray, Rect};

use crate::dispatch::status_of;

/// Side of the patch a point is tracked by (px, odd).
const PATCH: usize = 11;
/// How far out along its radial line a point may have moved at the second frame (px), and
/// the search round its predicted place after (px each way).
const STARTUP_REACH_PX: f32 = 40.0;
/// The nearest depth a point is looked for at (m): a short obstacle nearer than this is below
/// the image's bottom row, a tall one the sonar's (001 §6.2's panic-stop).
const MIN_DEPTH_M: f64 = 1.5;
const UPDATE_REACH_PX: f32 = 4.0;
/// Below this score a point's patch is cut afresh from the frame.
const RECUT_SCORE: f32 = 0.995;
/// How far a frame's measured shift may be from the last frame's moved on by the odometry's
/// turn (px): a wheel's slip turns the camera by what the encoders do not see (002 Table 3's
/// drift, about 0.3 degrees a foot, is 3 px a step of a foot at this focal length), and 001
/// §2.3 warns that depth from motion is "quite sensitive to misregistration due to rotation".
const REGISTER_REACH_PX: f32 = 10.0;

/// A tracker, the free number and travel it has reached, and the odometry's turn at its last
/// frame (the registration's guess moves on from the last shift by the odometry's turn since).
#[derive(Debug)]
struct Run {
    generation: f32,
    travelled_m: f64,
    turned_rad: f64,
    dfm: DepthFromMotion,
}

/// One tracker per request id.
#[derive(Debug, Default)]
pub struct DepthTrackers {
    runs: BTreeMap<u32, Run>,
}

/// `params[i]`, or `default` when it is zero (unset).
fn or(v: f32, default: f32) -> f32 {
    if v == 0.0 { default } else { v }
}

impl DepthTrackers {
    /// Starts or goes on with `req`'s run on `img` (the camera's focal length and height above
    /// the floor, `camera`): the registration and counts, then the tracked points' items
    /// (standing off the floor first, each kind nearest first), through `push`.
    pub fn answer(
        &mut self,
        img: &Gray<'_>,
        window: Rect,
        (focal_px, camera_height_m): (f64, f64),
        req: &VisionRequest,
        push: &mut impl FnMut([f32; 6]),
    ) -> Result<(), VisionStatus> {
        let p = &req.params;
        let params = DepthParams {
            foe: [img.width as f32 / 2.0, img.height as f32 / 2.0],
            focal_px: focal_px as f32,
            patch: PATCH,
            startup_reach_px: STARTUP_REACH_PX,
            min_depth_m: MIN_DEPTH_M,
            update_reach_px: UPDATE_REACH_PX,
            noise_px: or(p[4], 0.5),
            min_score: or(p[1], 0.9),
            recut_score: RECUT_SCORE,
            register_reach_px: REGISTER_REACH_PX,
            moravec: MoravecParams {
                window: 5,
                threshold: or(p[2], 3000.0) as u32,
                suppress_radius: 5,
                max_corners: or(p[3], 60.0) as usize,
            },
        };
        let (min_height_m, max_rel_sd) = (or(p[5], 0.1), or(p[7], 0.1));
        let travelled = req.expected.x_m;
        let turned = req.expected.heading_rad;
        let sane = p.iter().all(|v| v.is_finite())
            && travelled.is_finite()
            && turned.abs() < 1.0
            && (0.0..=1.0).contains(&params.min_score)
            && (1.0..=10_000.0).contains(&(params.moravec.max_corners as f32))
            && params.noise_px > 0.0
            && min_height_m > 0.0
            && max_rel_sd > 0.0;
        if !sane {
            return Err(VisionStatus::BadParameter);
        }
        let fresh = match self.runs.get(&req.request_id) {
            Some(r) => r.generation != p[0] || r.dfm.params != params,
            None => true,
        };
        if fresh {
            // A run's first look is at travel 0: a later one for a run this worker does not hold
            // (it restarted meanwhile) cannot go on, and says so.
            if travelled != 0.0 {
                return Err(VisionStatus::NotFound);
            }
            let mut dfm = DepthFromMotion::new(params);
            let started = dfm.start(img, window, travelled).map_err(|e| status_of(&e))?;
            let run = Run { generation: p[0], travelled_m: travelled, turned_rad: turned, dfm };
            self.runs.insert(req.request_id, run);
            push([0.0, 0.0, started as f32, 0.0, p[0], travelled as f32]);
            return Ok(());
        }
        let Some(run) = self.runs.get_mut(&req.request_id) else { return Err(VisionStatus::BadParameter) };
        if travelled <= run.travelled_m {
            // The same frame's travel again (a request repeated): nothing new to fit.
            return Err(VisionStatus::BadParameter);
        }
        // The scene moves right in the image as the camera turns left.
        let last = run.dfm.shift();
        let more = focal_px * (turned.tan() - run.turned_rad.tan());
        let guess = [last[0] + more as f32, last[1]];
        run.dfm.update_registered(img, travelled, guess).map_err(|e| status_of(&e))?;
        (run.travelled_m, run.turned_rad) = (travelled, turned);
        let shift = run.dfm.shift();
        let tracks: Vec<&Track> = run.dfm.tracks().filter(|t| t.depth.is_some()).collect();
        let standing = standing_off_floor(
            &tracks,
            params.foe[1],
            params.focal_px,
            camera_height_m as f32,
            min_height_m,
            max_rel_sd,
        );
        let mut items: Vec<[f32; 6]> = tracks
            .iter()
            .zip(standing)
            .filter_map(|(t, s)| {
                let (z, sd) = t.depth?;
                let class = match s {
                    Some(true) => 1.0,
                    Some(false) => 0.0,
                    None => -1.0,
                };
                Some([t.at[0] + shift[0], t.at[1] + shift[1], z, sd, t.frames as f32, class])
            })
            .collect();
        // Those standing off the floor first (a result holds 32 items), each kind nearest first.
        items.sort_by(|a, b| b[5].total_cmp(&a[5]).then(a[2].total_cmp(&b[2])));
        let live = run.dfm.tracks().count();
        push([shift[0], shift[1], live as f32, items.len() as f32, p[0], travelled as f32]);
        items.into_iter().for_each(push);
        Ok(())
    }
}

//! The stereo visual odometry request (003, `VisionAlgorithm::StereoOdometry`): one odometry per
//! request id, started or stepped on a stereo frame with the requester's predicted motion, its
//! answer packed into the result's items: the motion, what it rests on, and the obstacle points.

use std::collections::BTreeMap;

use harvey_geometry::wrap;
use harvey_msgs::{Encoding, FrameHeader, VisionRequest, VisionStatus};
use harvey_vision::Gray;
use harvey_vision::odometry::{Motion, OdometryError, Prior, VisualOdometry};
use harvey_world::World;

use crate::odometry_config::OdometryConfig;

/// Obstacle points one answer carries at most (the result's other two items are the motion and
/// the counts).
pub const MAX_POINTS: usize = harvey_msgs::MAX_VISION_ITEMS - 2;

/// How a stop went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// The first stop, or one asked to start afresh: features ranged, no motion.
    Started,
    Solved,
    /// Too few features held: no motion (the odometry starts afresh from this stop).
    NoSolution,
}

/// One request's odometry and what it was built for.
struct Running {
    lucas: bool,
    size: [u32; 2],
    vo: VisualOdometry,
}

/// The odometries of the standing requests, by request id.
#[derive(Default)]
pub struct Odometries {
    config: Option<OdometryConfig>,
    running: BTreeMap<u32, Running>,
    points: Vec<[f32; 6]>,
}

impl Odometries {
    pub fn new(config: Option<OdometryConfig>) -> Self {
        Self { config, ..Self::default() }
    }

    /// Runs `req` on the stereo frame `h`/`pixels`: pushes the motion `[dx, dy, dheading, sd_x,
    /// sd_y, sd_heading]` (zeros unless solved), the counts `[features, used, carried,
    /// reacquired, pruned, error_scale]`, then the obstacle points `[x, y, z, range_sd, u, v]`
    /// (the features that held since the last stop, between the settings' heights; this stop's
    /// robot frame, nearest first).
    pub fn answer(
        &mut self,
        world: &World,
        h: &FrameHeader,
        pixels: &[u8],
        req: &VisionRequest,
        mut push: impl FnMut([f32; 6]),
    ) -> Result<Outcome, VisionStatus> {
        let config = self.config.as_ref().ok_or(VisionStatus::BadParameter)?;
        let baseline = world.camera.stereo_baseline_m.ok_or(VisionStatus::BadParameter)?;
        let (start, lucas) = match (req.params[0], req.params[1]) {
            (s @ (0.0 | 1.0), l @ (0.0 | 1.0)) => (s == 1.0, l == 1.0),
            _ => return Err(VisionStatus::BadParameter),
        };
        let prior = prior(config, req)?;
        if h.views() != 2 || h.encoding() != Some(Encoding::Mono8) {
            return Err(VisionStatus::BadFrame);
        }
        let (w, ht, stride) = (h.width_px as usize, h.height_px as usize, h.stride_bytes as usize);
        let view = |k| h.view(pixels, k).and_then(|v| Gray::new(v, w, ht, stride).ok());
        let (Some(left), Some(right)) = (view(0), view(1)) else { return Err(VisionStatus::BadFrame) };
        let size = [h.width_px, h.height_px];
        let stale = self.running.get(&req.request_id).is_none_or(|r| r.lucas != lucas || r.size != size);
        if stale {
            let focal = world.camera.focal_for(h.width_px);
            let params = config.params(focal, size, world.camera.height_m, baseline, lucas);
            let vo = VisualOdometry::new(params);
            self.running.insert(req.request_id, Running { lucas, size, vo });
        }
        let run = self.running.get_mut(&req.request_id).ok_or(VisionStatus::BadParameter)?;
        let (outcome, motion, counts) = if start || stale {
            let n = run.vo.start(&left, &right).map_err(|_| VisionStatus::BadFrame)?;
            (Outcome::Started, [0.0; 6], [n as f32, 0.0, 0.0, 0.0, 0.0, 0.0])
        } else {
            match run.vo.step(&left, &right, &prior) {
                Ok(r) => {
                    let (m, c) = (r.solution.motion, r.solution.covariance);
                    let sd = [c[0][0].sqrt(), c[1][1].sqrt(), c[2][2].sqrt()];
                    let motion = [m.x_m, m.y_m, m.heading_rad, sd[0], sd[1], sd[2]].map(|v| v as f32);
                    let n = |v: usize| v as f32;
                    let (s, e) = (&r.solution, r.error_scale as f32);
                    let counts = [n(r.features), n(s.used), n(r.carried), n(r.reacquired), n(r.pruned), e];
                    (Outcome::Solved, motion, counts)
                }
                Err(OdometryError::Implausible { report: r, chi2, .. }) => {
                    tracing::warn!(chi2, used = r.solution.used, "a motion past the reasonableness limit");
                    let n = |v: usize| v as f32;
                    let counts = [
                        n(run.vo.features().count()),
                        n(r.solution.used),
                        n(r.carried),
                        n(r.reacquired),
                        n(r.pruned),
                        0.0,
                    ];
                    (Outcome::NoSolution, [0.0; 6], counts)
                }
                Err(OdometryError::NoSolution { carried, reacquired, left, .. }) => {
                    let n = run.vo.features().count();
                    let counts = [n as f32, left as f32, carried as f32, reacquired as f32, 0.0, 0.0];
                    (Outcome::NoSolution, [0.0; 6], counts)
                }
                Err(OdometryError::Vision(_) | OdometryError::SizeChanged { .. }) => {
                    return Err(VisionStatus::BadFrame);
                }
            }
        };
        push(motion);
        push(counts);
        self.points.clear();
        let rig = run.vo.params().rig;
        let (lo, hi) = (config.obstacle_min_z_m, config.obstacle_max_z_m);
        // Only points seen from two stops: a single stereo match may be a blunder (an occluding
        // edge matched against what is behind it).
        for (at, p) in run.vo.held().filter(|(_, p)| (lo..=hi).contains(&p[2])) {
            let v = [p[0], p[1], p[2], rig.range_sd(p)].map(|v| v as f32);
            self.points.push([v[0], v[1], v[2], v[3], at[0], at[1]]);
        }
        self.points.sort_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])));
        for p in self.points.iter().take(MAX_POINTS) {
            push(*p);
        }
        Ok(outcome)
    }
}

/// The predicted motion `req.expected` with its standard deviations (`params[2..5]`: x, y in
/// metres, heading in radians; zeros: the config's share of the distance and heading's).
fn prior(config: &OdometryConfig, req: &VisionRequest) -> Result<Prior, VisionStatus> {
    let e = req.expected;
    let motion = Motion { x_m: e.x_m, y_m: e.y_m, heading_rad: e.heading_rad };
    if !(motion.x_m.is_finite() && motion.y_m.is_finite() && motion.heading_rad.is_finite()) {
        return Err(VisionStatus::BadParameter);
    }
    let given = [req.params[2], req.params[3], req.params[4]].map(f64::from);
    let sd = if given == [0.0; 3] {
        let d = motion.x_m.hypot(motion.y_m);
        let m = config.prior_sd_per_m * d + config.prior_sd_floor_m;
        let turn_deg = wrap(motion.heading_rad).abs().to_degrees();
        let h = config.prior_heading_sd_deg
            + config.prior_heading_sd_per_deg * turn_deg
            + config.prior_heading_sd_deg_per_m * d;
        [m, m, h.to_radians()]
    } else if given.iter().all(|s| s.is_finite() && *s > 0.0) {
        given
    } else {
        return Err(VisionStatus::BadParameter);
    };
    Ok(Prior { motion, sd })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]
    use super::*;
    use harvey_msgs::Pose2;

    fn config() -> OdometryConfig {
        let path = format!("{}/../../missions/odometry/003.toml", env!("CARGO_MANIFEST_DIR"));
        OdometryConfig::load(std::path::Path::new(&path)).expect("loads")
    }

    fn request(x_m: f64, y_m: f64, heading_deg: f64, sd: [f32; 3]) -> VisionRequest {
        let mut params = [0.0f32; 8];
        params[2..5].copy_from_slice(&sd);
        let expected = Pose2 { x_m, y_m, heading_rad: heading_deg.to_radians() };
        VisionRequest { expected, params, ..VisionRequest::default() }
    }

    #[test]
    fn the_prediction_s_margins_follow_its_travel_and_turn() {
        let c = config();
        let deg = |p: &Prior| p.sd[2].to_degrees();
        // A 13-degree turn in place: 0.5 + 3 % of 13 degrees; 1 cm either way.
        let turn = prior(&c, &request(0.0, 0.0, 13.0, [0.0; 3])).expect("a prior");
        assert!((deg(&turn) - 0.89).abs() < 1e-9 && (turn.sd[0] - 0.01).abs() < 1e-12, "{turn:?}");
        // A heading given past a turn counts as the turn it is (350 degrees: 10 to the right),
        // and 0.4 m of travel adds 1.3 degrees a metre and 5 % of the distance.
        let step = prior(&c, &request(0.4, 0.0, 350.0, [0.0; 3])).expect("a prior");
        assert!((deg(&step) - (0.5 + 0.3 + 0.52)).abs() < 1e-9, "{step:?}");
        assert!((step.sd[1] - 0.03).abs() < 1e-12, "{step:?}");
        // Margins the request gives are taken as they are; bad ones are refused.
        let given = prior(&c, &request(0.4, 0.0, 0.0, [0.02, 0.03, 0.01])).expect("a prior");
        assert_eq!(given.sd, [0.02f32, 0.03, 0.01].map(f64::from));
        assert_eq!(
            prior(&c, &request(0.4, 0.0, 0.0, [0.02, -1.0, 0.01])).err(),
            Some(VisionStatus::BadParameter)
        );
        assert_eq!(prior(&c, &request(f64::NAN, 0.0, 0.0, [0.0; 3])).err(), Some(VisionStatus::BadParameter));
    }
}

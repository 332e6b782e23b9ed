//! What plan-level servoing (000 §5.6) needs from the world, and which of its landmark vertices
//! are worth asking for from a pose: in the image, at a usable range, not hidden behind a wall.

use harvey_msgs::Pose2;

use crate::servo::pose::{PinholeCamera, RefineParams};

/// What refining needs from the world: each vertex with the landmark its request is anchored
/// on (the nearest) and its offset from that landmark's point, and the camera.
#[derive(Debug, Clone, PartialEq)]
pub struct RefineSetup {
    /// `(landmark index, offset from its point, the vertex in the world)`.
    pub vertices: Vec<(u32, [f64; 3], [f64; 3])>,
    pub camera: PinholeCamera,
    pub params: RefineParams,
    pub template_px: u32,
    pub min_score: f64,
    /// Fixes placing the robot no better than this are refused (`mission.refine.max_sd_m`).
    pub max_sd_m: f64,
    /// The world, to ask only for vertices in view and not hidden behind a wall; without it,
    /// every vertex is asked for.
    pub world: Option<harvey_world::World>,
}

/// At most this many vertices are asked for at once (the vision request queue holds 16).
pub const MAX_ASKED: usize = 16;
/// Fewer vertices in view than this, and no fix is tried.
pub const MIN_ASKED: usize = 3;

impl RefineSetup {
    /// The vertices (indices) worth asking for from `pose`: in the image clear of its edges by a
    /// template, 0.5 to 20 m ahead, with no wall between; the nearest `MAX_ASKED`, in list order.
    pub fn in_view(&self, pose: Pose2, image_px: [f64; 2]) -> Vec<usize> {
        let margin = f64::from(self.template_px);
        let mut seen: Vec<(usize, f64)> = self
            .vertices
            .iter()
            .enumerate()
            .filter_map(|(i, &(_, _, v))| {
                let [u, w] = self.camera.project(pose, v)?;
                let inside = (margin..image_px[0] - margin).contains(&u)
                    && (margin..image_px[1] - margin).contains(&w);
                let (dx, dy) = (v[0] - pose.x_m, v[1] - pose.y_m);
                let d = dx.hypot(dy);
                let clear = self.world.as_ref().is_none_or(|world| {
                    world
                        .cast_ray([pose.x_m, pose.y_m], [dx / d, dy / d], d)
                        .is_none_or(|h| h.distance_m > d - 0.05)
                });
                (inside && clear && (0.5..20.0).contains(&d)).then_some((i, d))
            })
            .collect();
        seen.sort_by(|a, b| a.1.total_cmp(&b.1));
        seen.truncate(MAX_ASKED);
        let mut ids: Vec<usize> = seen.into_iter().map(|(i, _)| i).collect();
        ids.sort_unstable();
        ids
    }
}

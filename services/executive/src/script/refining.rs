//! Plan-level servoing in the executive (000 §5.6): a `refine_pose` step asks the vision workers
//! to find the mission's landmark vertices from the believed pose, refines the pose from the
//! matches (`pose.rs`), and from then on the executive believes the refined pose (odometry's
//! later motion is composed onto it), so that the next subgoal starts from where the robot is.

use harvey_msgs::{Header, Pose2, PoseFix, VisionRequest, VisionResult, VisionStatus};

use crate::pose::{PinholeCamera, RefineParams, VertexMatch, refine};
use crate::{Executive, Output, Phase};

/// Results not in this long (ns) after the requests are taken as not found.
pub const WAIT_NS: u64 = 2_000_000_000;

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

/// `rel` (a pose in `base`'s frame) in the world.
pub fn compose(base: Pose2, rel: Pose2) -> Pose2 {
    let (c, s) = (base.heading_rad.cos(), base.heading_rad.sin());
    Pose2 {
        x_m: base.x_m + rel.x_m * c - rel.y_m * s,
        y_m: base.y_m + rel.x_m * s + rel.y_m * c,
        heading_rad: base.heading_rad + rel.heading_rad,
    }
}

/// The pose now, from a fix `(odometry then, pose then)` and odometry now: the fixed pose moved
/// by what odometry says happened since (odometry itself without a fix).
pub fn fixed(fix: Option<(Pose2, Pose2)>, odometry: Pose2) -> Pose2 {
    fix.map_or(odometry, |(then, pose)| compose(pose, relative(then, odometry)))
}

/// `to` in `from`'s frame.
pub fn relative(from: Pose2, to: Pose2) -> Pose2 {
    let (c, s) = (from.heading_rad.cos(), from.heading_rad.sin());
    let (dx, dy) = (to.x_m - from.x_m, to.y_m - from.y_m);
    Pose2 { x_m: dx * c + dy * s, y_m: -dx * s + dy * c, heading_rad: to.heading_rad - from.heading_rad }
}

impl Executive {
    /// The pose the executive believes: odometry, moved by the last refinement.
    pub(crate) fn believed(&self) -> Pose2 {
        fixed(self.belief, self.odometry)
    }

    /// Starts a `refine_pose` step: every vertex asked for at once, from the believed pose (off
    /// by the step's `belief_offset_m`, when given).
    pub(crate) fn begin_refine(&mut self, step: usize, now: u64) -> Vec<Output> {
        let Some(setup) = &self.refine else { return self.step_done(step, self.estimated, now) };
        if let Some([dx, dy]) = self.mission.steps[step].belief_offset_m {
            let b = self.believed();
            self.belief = Some((self.odometry, Pose2 { x_m: b.x_m + dx, y_m: b.y_m + dy, ..b }));
            self.estimated = self.believed();
        }
        let expected = self.estimated;
        let c = setup.camera.centre_px;
        self.asked = setup.in_view(expected, [2.0 * c[0], 2.0 * c[1]]);
        if self.asked.len() < MIN_ASKED {
            tracing::info!(in_view = self.asked.len(), "too few landmark vertices in view for a pose fix");
            return self.step_done(step, expected, now);
        }
        let first = self.next_request;
        let n = self.asked.len() as u32;
        self.next_request += n;
        self.looks = vec![None; n as usize];
        self.phase = Phase::Refining { step, first, received: 0, since_ns: now };
        self.asked
            .iter()
            .map(|&i| setup.vertices[i])
            .enumerate()
            .map(|(k, (landmark_index, offset, _))| {
                let id = first + k as u32;
                Output::Look(VisionRequest::correlate(
                    id,
                    now,
                    landmark_index,
                    expected,
                    offset,
                    setup.template_px,
                    setup.min_score,
                ))
            })
            .collect()
    }

    /// A vision result for the refinement under way; once all are in, the pose is refined.
    pub(crate) fn on_refine_result(&mut self, r: &VisionResult) -> Vec<Output> {
        let Phase::Refining { step, first, received, since_ns } = self.phase else { return Vec::new() };
        let Some(k) = r.request_id.checked_sub(first).map(|k| k as usize).filter(|&k| k < self.looks.len())
        else {
            return Vec::new();
        };
        if VisionStatus::from_raw(r.status) == Some(VisionStatus::Found) && r.count > 0 {
            let v = r.items[0].values;
            self.looks[k] = Some([f64::from(v[0]), f64::from(v[1])]);
        }
        let received = received + 1;
        self.phase = Phase::Refining { step, first, received, since_ns };
        if (received as usize) < self.looks.len() {
            return Vec::new();
        }
        self.finish_refine(step, r.header.stamp_ns)
    }

    /// Refines the pose from the vertices found (all answered, or the wait is over).
    pub(crate) fn finish_refine(&mut self, step: usize, now: u64) -> Vec<Output> {
        let Some(setup) = &self.refine else { return Vec::new() };
        let matches: Vec<VertexMatch> = self
            .asked
            .iter()
            .map(|&i| setup.vertices[i].2)
            .zip(&self.looks)
            .filter_map(|(world_m, seen)| seen.map(|image_px| VertexMatch { world_m, image_px }))
            .collect();
        let expected = self.estimated;
        let mut out = Vec::new();
        match refine(&setup.camera, expected, &matches, &setup.params) {
            // Too few matches agreeing: no fix (a pose from two vertices fits anything).
            Some(done) if done.kept.len() < MIN_ASKED => tracing::warn!(
                found = matches.len(),
                kept = done.kept.len(),
                "too few vertices agree to fix the pose"
            ),
            Some(done) if done.position_sd_m > setup.max_sd_m => tracing::warn!(
                position_sd_m = done.position_sd_m,
                vertices = done.kept.len(),
                "the vertices in view fix the pose too loosely"
            ),
            Some(done) => {
                tracing::info!(
                    expected_x = expected.x_m,
                    expected_y = expected.y_m,
                    refined_x = done.pose.x_m,
                    refined_y = done.pose.y_m,
                    refined_heading_deg = done.pose.heading_rad.to_degrees(),
                    vertices = done.kept.len(),
                    of = matches.len(),
                    rms_px = done.rms_px,
                    position_sd_m = done.position_sd_m,
                    "pose refined"
                );
                self.belief = Some((self.odometry, done.pose));
                self.estimated = done.pose;
                self.fixes += 1;
                self.servo_seq += 1;
                out.push(Output::Pose(PoseFix {
                    header: Header::new(self.servo_seq, now),
                    expected,
                    refined: done.pose,
                    asked: self.asked.len() as u32,
                    found: matches.len() as u32,
                    kept: done.kept.len() as u32,
                    reserved: 0,
                    rms_px: done.rms_px,
                }));
            }
            None => tracing::warn!(found = matches.len(), "too few vertices found to refine the pose"),
        }
        let at = self.estimated;
        out.extend(self.step_done(step, at, now));
        out
    }
}

//! A `refine_pose` step, plan-level servoing in the script (000 §5.6): it asks the vision workers
//! to find the mission's landmark vertices from the believed pose, refines the pose from the
//! matches (`servo/pose.rs`), and from then on the script believes the refined pose (odometry's
//! later motion is composed onto it), so that the next subgoal starts from where the robot is.

use harvey_msgs::{Header, Pose2, PoseFix, VisionRequest, VisionResult, VisionStatus};

use super::{Phase, Script, Sequel};
use crate::Output;
use crate::servo::pose::{SURPRISE_LIMIT, VertexMatch, refine};
use crate::servo::vertices::MIN_ASKED;

/// Results not in this long (ns) after the requests are taken as not found.
pub const WAIT_NS: u64 = 2_000_000_000;

impl Script {
    /// Starts a `refine_pose` step: every vertex asked for at once, from the believed pose (off
    /// by the step's `belief_offset_m`, when given).
    pub(super) fn begin_refine(&mut self, step: usize, now: u64, sequel: &mut dyn Sequel) -> Vec<Output> {
        let Some(setup) = &self.refine else { return self.step_done(step, self.estimated, now, sequel) };
        if let Some([dx, dy]) = self.steps[step].belief_offset_m {
            let b = self.belief.believed();
            self.belief.fix(Pose2 { x_m: b.x_m + dx, y_m: b.y_m + dy, ..b });
            self.estimated = self.belief.believed();
        }
        let expected = self.estimated;
        let c = setup.camera.centre_px;
        // Chosen for the prior the fix will have: what dead reckoning since the last fix leaves.
        let params = setup.prior(&self.belief);
        self.asked = setup.in_view(expected, [2.0 * c[0], 2.0 * c[1]], &params);
        if self.asked.len() < MIN_ASKED {
            tracing::info!(in_view = self.asked.len(), "too few landmark vertices in view for a pose fix");
            return self.step_done(step, expected, now, sequel);
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
    pub(super) fn on_refine_result(&mut self, r: &VisionResult, sequel: &mut dyn Sequel) -> Vec<Output> {
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
        self.finish_refine(step, r.header.stamp_ns, sequel)
    }

    /// Refines the pose from the vertices found (all answered, or the wait is over).
    pub(super) fn finish_refine(&mut self, step: usize, now: u64, sequel: &mut dyn Sequel) -> Vec<Output> {
        let Some(setup) = &self.refine else { return Vec::new() };
        let matches: Vec<VertexMatch> = self
            .asked
            .iter()
            .map(|&i| setup.vertices[i].2)
            .zip(&self.looks)
            .filter_map(|(world_m, seen)| seen.map(|image_px| VertexMatch { world_m, image_px }))
            .collect();
        let expected = self.estimated;
        // The prior is what dead reckoning since the last fix leaves of the pose.
        let params = setup.prior(&self.belief);
        let mut out = Vec::new();
        match refine(&setup.camera, expected, &matches, &params) {
            // Too few matches agreeing: no fix (a pose from two vertices fits anything).
            Some(done) if done.kept.len() < MIN_ASKED => tracing::warn!(
                found = matches.len(),
                kept = done.kept.len(),
                "too few vertices agree to fix the pose"
            ),
            Some(done) if done.surprise(expected, params.prior_sd) > SURPRISE_LIMIT => tracing::warn!(
                refined_x = done.pose.x_m,
                refined_y = done.pose.y_m,
                refined_heading_deg = done.pose.heading_rad.to_degrees(),
                surprise = done.surprise(expected, params.prior_sd),
                vertices = done.kept.len(),
                "the fix moves the pose further than its prior allows: refused"
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
                self.belief.fix(done.pose);
                self.estimated = done.pose;
                self.fixes += 1;
                self.fix_sd_m = done.map_position_sd_m;
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
        out.extend(self.step_done(step, at, now, sequel));
        out
    }
}

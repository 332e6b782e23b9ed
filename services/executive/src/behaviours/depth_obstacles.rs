//! Obstacle avoidance by depth from motion (001 §2.3, steered by the motor schemas of §3.1):
//! the robot drives in straight runs of short steps, stopping to look after each; the vision
//! workers track the run's interest points along their radial lines and fit their depths, and
//! the points standing off the floor become obstacles on the floor plan. At each stop
//! move-to-goal and avoid-static-obstacle (round every obstacle point) are summed: while the sum
//! points along the run, the run goes on; once it turns away (or the run has had its looks), the
//! robot turns to it and a new run starts. The robot's pose is the odometry's, corrected by the
//! turns the looks' registration measured that the encoders did not count (a wheel's slip: 002
//! Table 3's drift): a visual compass along each run.

use std::collections::BTreeMap;

use harvey_geometry::wrap;
use harvey_msgs::{
    BehaviourState, Header, MotionCommand, Pose2, SonarRing, VisionRequest, VisionResult, VisionStatus,
};

use super::depth_look::{Look, REQUEST_ID, nearest_of_each, rotation_about};
use super::drive;
use super::schemas::{V2, avoid_obstacle, move_to_goal};
use crate::mission::DepthGoal;

/// avoid-static-obstacle's push inside an obstacle point's radius (m/s): overrides the rest.
const CONTACT_GAIN: f64 = 10.0;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Standing still since then (the first tick sets it), before a look.
    Settling { since_ns: Option<u64> },
    /// Waiting for the look's answer until then.
    Looking { until_ns: u64 },
    /// Turning on the spot to odometry heading `to`; given up at the deadline (0: not set yet).
    Turning { to: f64, deadline_ns: u64 },
    /// Along the run to `to`; given up at the deadline (0: not set yet).
    Moving { to: [f64; 2], deadline_ns: u64 },
}

/// A straight run: where its first look was taken (odometry), its number (the request's first
/// parameter), its looks so far, the turn the camera made since its start that the odometry
/// did not count (rad, as of the last look) and where the robot was believed to be then, and
/// the look last asked (its answer echoes the number and travel).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Run {
    start: Pose2,
    number: u32,
    looks: u32,
    unseen_turn: f64,
    last_look: Pose2,
    asked: Option<Look>,
}

impl Run {
    fn new(start: Pose2, number: u32, believed: Pose2) -> Self {
        Self { start, number, looks: 0, unseen_turn: 0.0, last_look: believed, asked: None }
    }
}

/// The behaviour's state.
#[derive(Debug, Clone)]
pub struct DepthObstacles {
    g: DepthGoal,
    /// The camera's focal length and centre column (px), and the window the runs start in.
    focal_px: f64,
    cx: f64,
    window_px: [f64; 4],
    robot_radius_m: f64,
    phase: Phase,
    /// The odometry, and the world pose of its frame's origin as corrected by the looks'
    /// registration.
    at: Pose2,
    correction: Pose2,
    ring: Option<SonarRing>,
    run: Run,
    /// Obstacle points on the floor (world frame, m) by run: a run's newest answer replaces the
    /// points it places anew (its depths sharpen), the rest stay.
    points: BTreeMap<u32, Vec<[f64; 2]>>,
    /// The schemas' vectors at the last stop (move-to-goal, avoid-static-obstacle, their sum).
    vectors: [V2; 3],
    /// Looks answered.
    pub looks: u32,
    next_id: u32,
    seq: u64,
    pub done: Option<bool>,
}

impl DepthObstacles {
    /// `camera`: its focal length, image width and height (px) and height above the floor (m);
    /// `robot_radius_m`: the robot's reach. The window's top comes down to the row where the
    /// floor lies twice `max_range_m` off: above it lies nothing within range but what stands
    /// taller than the camera, and the far ground's texture, crowded into a few rows, shimmers
    /// as the camera moves (a point-sampled image aliases it) into points that seem near.
    pub fn new(g: DepthGoal, camera: [f64; 4], robot_radius_m: f64, start: Pose2) -> Self {
        let [focal_px, width_px, height_px, height_m] = camera;
        let floor_row = height_px / 2.0 + focal_px * height_m / (2.0 * g.max_range_m);
        // Within the image, whatever the table says.
        let mut window_px = g.window_px;
        window_px[2] = window_px[2].min(width_px);
        window_px[3] = window_px[3].min(height_px);
        window_px[0] = window_px[0].min(window_px[2] - 1.0);
        window_px[1] = window_px[1].max(floor_row.floor()).min(window_px[3] - 1.0);
        Self {
            window_px,
            g,
            focal_px,
            cx: width_px / 2.0,
            robot_radius_m,
            phase: Phase::Settling { since_ns: None },
            at: start,
            correction: Pose2::default(),
            ring: None,
            run: Run::new(start, 0, start),
            points: BTreeMap::new(),
            vectors: [V2::default(); 3],
            looks: 0,
            next_id: 1,
            seq: 0,
            done: None,
        }
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
    }

    /// The odometry corrected by the turns the looks measured.
    pub fn believed(&self) -> Pose2 {
        self.correction.compose(&self.at)
    }

    pub fn goal_pose(&self) -> Pose2 {
        Pose2 { x_m: self.g.goal_m[0], y_m: self.g.goal_m[1], heading_rad: 0.0 }
    }

    /// Every obstacle point found so far (world frame).
    pub fn obstacle_points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.points.values().flatten().copied()
    }

    /// The run's travel along its heading so far (m).
    fn travelled(&self) -> f64 {
        let s = self.run.start;
        let (sn, cs) = s.heading_rad.sin_cos();
        (self.at.x_m - s.x_m) * cs + (self.at.y_m - s.y_m) * sn
    }

    /// The answer to a look: the run's obstacle points placed on the floor, then the next move.
    pub fn on_vision(&mut self, r: &VisionResult) {
        if r.request_id != REQUEST_ID || !matches!(self.phase, Phase::Looking { .. }) {
            return;
        }
        self.looks += 1;
        self.run.looks += 1;
        let items = &r.items[..(r.count as usize).min(r.items.len())];
        let status = VisionStatus::from_raw(r.status);
        // A found answer to another look (a late one of the run before) is not this look's.
        if let (Some(VisionStatus::Found), Some(first), Some(asked)) = (status, items.first(), self.run.asked)
        {
            let [.., number, travel] = first.values.map(f64::from);
            if number != f64::from(asked.number as f32) || (travel - asked.travelled_m).abs() > 1e-3 {
                return;
            }
        }
        match (status, items.split_first()) {
            (Some(VisionStatus::Found), Some((registration, points))) => {
                let [shift_u, ..] = registration.values.map(f64::from);
                self.register((shift_u / self.focal_px).atan());
                let found: Vec<[f64; 2]> =
                    points.iter().filter_map(|i| self.place(i.values.map(f64::from), shift_u)).collect();
                // A point sharpened since the run's last look replaces where it was placed then;
                // one that has left the view stays where it was last placed.
                let link = self.g.link_m;
                let kept = self.points.entry(self.run.number).or_default();
                kept.retain(|k| found.iter().all(|p| (p[0] - k[0]).hypot(p[1] - k[1]) > link));
                kept.extend(found);
            }
            (status, _) => {
                // The worker lost the run (restarted, or the travel did not grow): start another.
                tracing::warn!(run = self.run.number, ?status, "the look failed: a new run");
                self.run.looks = self.g.frames;
            }
        }
        self.decide();
    }

    /// The camera has turned `turned` (rad) since the run's start, by the registration: what the
    /// odometry did not count goes into the correction, turned about where the robot was at the
    /// last look (the step since, driven straight by the odometry, was driven that much off).
    fn register(&mut self, turned: f64) {
        let unseen = wrap(turned - wrap(self.at.heading_rad - self.run.start.heading_rad));
        let more = unseen - self.run.unseen_turn;
        self.run.unseen_turn = unseen;
        self.correction = rotation_about(self.run.last_look, more).compose(&self.correction);
        self.run.last_look = self.believed();
    }

    /// Item `v` as a point on the floor when it is an obstacle judged well enough, seen from
    /// where the robot is believed to stand.
    fn place(&self, v: [f64; 6], shift_u: f64) -> Option<[f64; 2]> {
        super::depth_look::place(&self.g, v, shift_u, self.believed(), (self.focal_px, self.cx))
    }

    /// At a stop, after a look: done at the goal; else the schemas summed, and the run goes on
    /// while their sum points along it, or the robot turns to the sum for a new run.
    fn decide(&mut self) {
        let g = &self.g;
        let believed = self.believed();
        let here = V2::new(believed.x_m, believed.y_m);
        let goal = V2::new(g.goal_m[0], g.goal_m[1]);
        if goal.minus(here).norm() <= g.goal_tolerance_m {
            tracing::info!(looks = self.looks, runs = self.run.number + 1, "at the goal");
            self.done = Some(true);
            return;
        }
        let to_goal = move_to_goal(here, goal, g.goal_gain);
        let reach = self.robot_radius_m + g.point_radius_m;
        // One push per obstacle (its points linked within `link_m`), from its nearest point: a
        // cone seen by a dozen points repels as one cone.
        let mut points: Vec<[f64; 2]> = self.obstacle_points().collect();
        // What the sonar ring has right by the robot (a lamppost too thin for the camera's
        // points) repels as well.
        if let Some(ring) = &self.ring {
            let near = drive::echoes(ring, believed.heading_rad, self.robot_radius_m)
                .filter(|(_, d)| *d <= self.robot_radius_m + g.sonar_reach_m);
            points.extend(near.map(|(b, d)| [here.x + d * b.cos(), here.y + d * b.sin()]));
        }
        let push_at = |at: V2| {
            nearest_of_each(&points, [at.x, at.y], g.link_m).into_iter().fold(V2::default(), |v, p| {
                v.plus(avoid_obstacle(at, V2::new(p[0], p[1]), reach, g.sphere_m, g.avoid_gain, CONTACT_GAIN))
            })
        };
        let avoid = push_at(here);
        let sum = to_goal.plus(avoid);
        self.vectors = [to_goal, avoid, sum];
        // A guarded goal: where the obstacles by it push back along the approach harder than it
        // pulls, the schemas cannot bring the robot there (their sum turns back before it). Once
        // the robot is within the obstacles' reach of the goal and their sum points away from
        // it, it is as near as they let it come: arrived (nominal seed 10 turned back and forth
        // 0.8 m off for 200 s). An obstacle between the robot and the goal pushes the goal's way
        // at the goal: that one the robot slides past (the detour below).
        let gap = goal.minus(here).norm();
        let stalled = sum.dot(to_goal) <= 0.0;
        let back_at_goal = -push_at(goal).dot(to_goal.unit());
        if stalled && gap <= reach + g.sphere_m && back_at_goal >= to_goal.norm() {
            tracing::info!(
                looks = self.looks,
                gap_m = gap,
                "as near the goal as the obstacles by it let the robot come"
            );
            self.done = Some(true);
            return;
        }
        // Never further round than `max_detour_deg` from the goal: an obstacle dead ahead pushes
        // the sum backwards, and the robot would turn about at every stop; it slides past.
        let goal_dir = to_goal.y.atan2(to_goal.x);
        let widest = g.max_detour_deg.to_radians();
        let towards = match sum.norm() > 1e-9 {
            true => goal_dir + wrap(sum.y.atan2(sum.x) - goal_dir).clamp(-widest, widest),
            false => goal_dir,
        };
        // The run's heading in the world: the believed heading less the odometry's turn since.
        let run_heading = believed.heading_rad - wrap(self.at.heading_rad - self.run.start.heading_rad);
        let off_run = wrap(towards - run_heading).abs();
        if self.run.looks < g.frames && off_run <= g.replan_deg.to_radians() {
            let (sn, cs) = self.run.start.heading_rad.sin_cos();
            let d = self.travelled() + g.step_m.min(goal.minus(here).norm());
            let to = [self.run.start.x_m + d * cs, self.run.start.y_m + d * sn];
            self.phase = Phase::Moving { to, deadline_ns: 0 };
            return;
        }
        self.run = Run::new(self.at, self.run.number + 1, believed);
        let to = self.at.heading_rad + wrap(towards - believed.heading_rad);
        self.phase = Phase::Turning { to, deadline_ns: 0 };
    }

    /// One odometry tick: the look to send, the velocity command and the state to publish.
    pub fn on_odometry(
        &mut self,
        at: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        self.at = at;
        let (look, vw) = self.step(at, now);
        let vw = drive::held(self.ring.as_ref(), vw);
        let id = self.next_id;
        self.next_id += 1;
        self.seq += 1;
        let phase = match self.phase {
            Phase::Settling { .. } => 0,
            Phase::Looking { .. } => 1,
            Phase::Turning { .. } => 2,
            Phase::Moving { .. } => 3,
        };
        let [a, b, sum] = self.vectors;
        let vectors = drive::Vectors { parts: [a, b, V2::default(), V2::default(), V2::default()], sum };
        let state = BehaviourState {
            header: Header::new(self.seq, now),
            at: self.believed(),
            fsa_state: phase,
            transitions: self.run.number,
            last_trigger: 0,
            achieved: self.looks,
            vectors_mps: vectors.flat(),
            linear_mps: vw.0,
            angular_radps: vw.1,
        };
        (look, drive::command(id, now, vw), state)
    }
}

#[path = "depth_steps.rs"]
mod steps;

#[cfg(test)]
#[path = "depth_obstacles_tests.rs"]
mod tests;

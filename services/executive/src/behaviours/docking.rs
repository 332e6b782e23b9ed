//! The docking behaviour of 004 §4.2 under its finite state acceptor (`missions/fsa/docking.toml`):
//! each state asks the vision workers for its perceptual algorithm and drives the robot by motor
//! schemas; what perception returns, the believed distance to the dock and the sonar's range
//! are the triggers. q0 phototropic: move-to-goal towards the lamp's bearing, avoid-static-
//! obstacle, noise (ballistic); once the dock is believed within Hough range, q1 constrained
//! Hough: stop and recognise the dock; q2 adaptive region tracking of the target above the
//! frame: controlled motion towards it, until it is large (near); q3 ultrasonic positioning:
//! hold the heading until the sonar says the dock is at the final distance; q4 docked.

use harvey_geometry::wrap;
use harvey_msgs::{
    BehaviourState, MotionCommand, Pose2, SonarRing, UncertaintyMap, VisionAlgorithm, VisionRequest,
    VisionResult, VisionStatus,
};

use super::dock_pose::{dock_sight, face_distance, hough_band, weighed_fix};
use super::drive::{self, DriveParams, Vectors};
use super::fsa::{Fsa, Trigger};
use super::region::Region;
use super::schemas::{Noise, V2, move_to_goal};
use super::sequenced::Sequenced;
use crate::mission::DockingGoal;
use crate::servo::belief::Belief;

/// The docking behaviour's state.
#[derive(Debug, Clone)]
pub struct Docking {
    g: DockingGoal,
    pub seq: Sequenced,
    drive: DriveParams,
    noise: Noise,
    focal_px: f64,
    centre_px: [f64; 2],
    sensor_ring_m: f64,
    ring: Option<SonarRing>,
    /// World-frame direction of the lamp, last seen.
    light_rad: Option<f64>,
    /// The target's image centre and area (pixels), last tracked or predicted.
    target: Option<[f64; 3]>,
    /// Where the last Hough was tried.
    hough_at: Option<[f64; 2]>,
    /// Going back to the approach zone's entry on the axis (out of the zone in q0), until there.
    retreating: bool,
    /// Whether it docked, once the acceptor has accepted.
    pub done: Option<bool>,
    /// Odometry now, and the last fix from the dock.
    belief: Belief,
    /// Where the UMS last said the robot can be: the gate on the first fix.
    region: Option<Region>,
    /// The believed heading when the target was last seen, and ticks since the last fix asked.
    target_heading: f64,
    since_fix: u32,
    /// The believed heading's variance as of the last fix (rad²).
    heading_var: Option<f64>,
}

impl Docking {
    /// `camera` = (focal length, image width, height) in pixels; `sensor_ring_m` the sonar ring's
    /// radius; `seed` the noise schema's.
    pub fn new(g: DockingGoal, fsa: Fsa, camera: (f64, f64, f64), sensor_ring_m: f64, seed: u64) -> Self {
        let drive = DriveParams::new(
            g.ballistic_mps,
            g.max_turn_degps,
            g.turn_gain,
            sensor_ring_m,
            (g.avoid_sphere_m, g.avoid_gain),
        );
        let noise = Noise::new(seed, g.noise_mps, g.noise_ticks);
        Self {
            g,
            seq: Sequenced::new(fsa),
            drive,
            noise,
            focal_px: camera.0,
            centre_px: [camera.1 / 2.0, camera.2 / 2.0],
            sensor_ring_m,
            ring: None,
            light_rad: None,
            target: None,
            hough_at: None,
            retreating: false,
            done: None,
            belief: Belief::default(),
            region: None,
            target_heading: 0.0,
            since_fix: 0,
            heading_var: None,
        }
    }

    /// Where docking ends: `final_m` out from the face's centre, facing it.
    pub fn goal_pose(&self) -> Pose2 {
        let n = self.g.dock_facing_deg.to_radians();
        Pose2 {
            x_m: self.g.dock_m[0] + self.g.final_m * n.cos(),
            y_m: self.g.dock_m[1] + self.g.final_m * n.sin(),
            heading_rad: wrap(n + std::f64::consts::PI),
        }
    }

    fn perception(&self) -> &str {
        self.seq.perception()
    }

    fn trigger(&mut self, t: Trigger) {
        self.seq.trigger(t);
        if self.seq.fsa.accepted() {
            self.done = Some(self.seq.fsa.state().name == self.g.docked_state);
        }
    }

    /// Odometry, moved by the last fix from the dock.
    pub fn believed(&self) -> Pose2 {
        self.belief.believed()
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
    }

    pub fn on_map(&mut self, m: &UncertaintyMap) {
        self.region = Region::of(m);
    }

    /// The answer to the request awaited: the perceptual trigger of the state it was asked in.
    pub fn on_vision(&mut self, r: &VisionResult) {
        if !self.seq.answers(r) {
            return;
        }
        let at = self.believed();
        let found = VisionStatus::from_raw(r.status) == Some(VisionStatus::Found) && r.count > 0;
        let item = found.then(|| r.items[0].values.map(f64::from));
        let dock = r.algorithm == VisionAlgorithm::Dock as u32;
        // A fix far from the belief is a misreading, once the belief has had a first fix; the
        // first, one outside the UMS's region by more than a fix's own error.
        let (gate_m, gate_rad) = (self.g.fix_gate_m, self.g.fix_gate_deg.to_radians());
        let near = |p: &Pose2| match &self.region {
            _ if self.belief.has_fix() => {
                (p.x_m - at.x_m).hypot(p.y_m - at.y_m) < gate_m
                    && wrap(p.heading_rad - at.heading_rad).abs() < gate_rad
            }
            Some(region) => region.admits(p, gate_m, gate_rad),
            None => true,
        };
        let prior = self.heading_var.filter(|_| self.belief.has_fix());
        let weighed = item
            .as_ref()
            .filter(|_| dock)
            .and_then(|v| dock_sight(&self.g, self.focal_px, self.centre_px[0], v))
            .map(|s| weighed_fix(&self.g, &s, at, prior, self.belief.travelled_m()));
        if let Some((p, var)) = weighed.filter(|(p, _)| near(p)) {
            self.heading_var = Some(var);
            tracing::info!(
                x = p.x_m,
                y = p.y_m,
                heading_deg = p.heading_rad.to_degrees(),
                "pose from the dock"
            );
            // Keep the tracked target's prediction in odometry's terms: the fix moves the belief,
            // not the robot, so it must not move where the target is looked for.
            let before = self.believed().heading_rad;
            self.belief.fix(p);
            self.target_heading += wrap(self.believed().heading_rad - before);
        }
        match (self.perception(), item) {
            // A fix asked for while tracking: nothing more to it.
            ("region-tracking", _) if dock => {}
            ("phototropic", Some(v)) if self.is_lamp(&v) => {
                self.light_rad = Some(at.heading_rad + ((self.centre_px[0] - v[0]) / self.focal_px).atan());
            }
            // A lamp not seen now is no direction to go in: a bearing from elsewhere leads past the
            // dock once the robot has moved.
            ("phototropic", _) => self.light_rad = None,
            ("hough-dock", Some(v)) => {
                // The target sits above the frame's centre, at the same distance.
                let px_per_m = v[3] / (self.g.frame_width_m / 2.0);
                let up = (self.g.target_height_m - self.g.frame_height_m) * px_per_m;
                let side = self.g.target_side_m * px_per_m;
                self.target = Some([v[0], v[1] - up, side * side]);
                self.target_heading = self.believed().heading_rad;
                self.trigger(Trigger::Normal);
            }
            ("hough-dock", None) => self.trigger(Trigger::Recoverable),
            ("region-tracking", _) => self.track(r),
            _ => {}
        }
    }

    /// Whether a phototropic item `[cx, cy, area, mean, median, _]` can be the lamp: bright
    /// against the window's median, above the optical centre, no bigger than the lamp near.
    fn is_lamp(&self, v: &[f64; 6]) -> bool {
        let biggest = self.g.lamp_area_m2 * (self.focal_px / self.g.light_near_m).powi(2);
        v[3] >= self.g.light_contrast * v[4] && v[1] < self.centre_px[1] && v[2] <= biggest
    }

    /// A region-segmenter answer in tracking: the region nearest the prediction, if it is about
    /// the predicted size; else the target is lost.
    fn track(&mut self, r: &VisionResult) {
        let Some([pu, pv, area]) = self.target else { return self.trigger(Trigger::Recoverable) };
        let best = r.items[..r.count as usize]
            .iter()
            .map(|i| i.values.map(f64::from))
            .filter(|v| (area / 3.0..area * 3.0).contains(&v[2]))
            .min_by(|a, b| (a[0] - pu).hypot(a[1] - pv).total_cmp(&(b[0] - pu).hypot(b[1] - pv)));
        match best {
            Some(v) if VisionStatus::from_raw(r.status) == Some(VisionStatus::Found) => {
                self.target = Some([v[0], v[1], v[2]]);
                self.target_heading = self.believed().heading_rad;
                let t = if v[2] >= self.g.close_area_px { Trigger::Terminal } else { Trigger::Normal };
                self.trigger(t);
            }
            _ => {
                let seen: Vec<[f32; 3]> = r.items[..r.count as usize]
                    .iter()
                    .map(|i| [i.values[0], i.values[1], i.values[2]])
                    .collect();
                tracing::info!(predicted = ?[pu, pv, area], ?seen, "tracking lost the target");
                self.target = None;
                self.trigger(Trigger::Recoverable);
            }
        }
    }

    /// A constrained Hough request for the dock believed `d` from its face: five scale
    /// hypotheses over the distances the belief allows (004 §4.1.2: "generated from the
    /// expectations of scale ... as constrained by the uncertainty in the robot's position").
    fn hough_request(&mut self, now: u64, d: f64) -> VisionRequest {
        let unit = self.focal_px * self.g.frame_width_m / 2.0;
        let (near, far) = hough_band(&self.g, self.region.as_ref(), d);
        // The vision workers take a frame's half width of 2 to 1000 px: a band past that asks
        // for scales no dock in the image can have.
        let (near, far) = (near.max(unit / 999.0), far.min(unit / 2.0).max(near.max(unit / 999.0)));
        let min = self.g.hough_min_certainty as f32;
        let params = [(unit / far) as f32, (unit / near) as f32, 5.0, 0.0, min, 0.0, 0.0, 0.0];
        self.seq.request(now, VisionAlgorithm::Dock, [0.0; 4], params)
    }

    /// The nearest sonar range ahead (within 15 degrees), from the robot's centre.
    fn range_ahead(&self) -> Option<f64> {
        drive::echoes(self.ring.as_ref()?, 0.0, self.sensor_ring_m)
            .filter(|(b, _)| b.sin().abs() < 0.27 && b.cos() > 0.0)
            .map(|(_, r)| r)
            .min_by(f64::total_cmp)
    }

    /// One odometry tick at the believed pose `at`: the state's triggers from position and
    /// range, its perceptual request, its motor schemas; returns what to send.
    pub fn on_odometry(
        &mut self,
        odometry: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        self.belief.set_odometry(odometry);
        let at = self.believed();
        let d = face_distance(&self.g, at);
        let mut parts = [V2::default(); 5];
        let request = match self.perception() {
            "phototropic" => self.phototropic(at, d, now, &mut parts),
            "hough-dock" if !self.seq.waiting() => {
                self.hough_at = Some([at.x_m, at.y_m]);
                Some(self.hough_request(now, d))
            }
            "region-tracking" => self.region_tracking(at, d, now, &mut parts),
            "sonar-positioning" => {
                self.sonar_positioning(at, &mut parts);
                None
            }
            _ => None,
        };
        let vectors: Vectors = drive::vectors(parts, &self.drive);
        let (v, w) = if self.perception() == "sonar-positioning" {
            (vectors.sum.norm(), 0.0)
        } else {
            drive::velocity(vectors.sum, at, &self.drive)
        };
        let (v, w) = drive::held(self.ring.as_ref(), (v, w));
        let achieved = u32::from(self.done == Some(true));
        let (command, state) = self.seq.output(at, now, &vectors, (v, w), achieved);
        (request, command, state)
    }

    /// q0, ballistic: move-to-goal towards the lamp's bearing (the dock's place until the lamp is
    /// seen), avoid-static-obstacle and noise, until the dock is believed within Hough range of
    /// a place the Hough has not been tried from.
    fn phototropic(&mut self, at: Pose2, d: f64, now: u64, parts: &mut [V2; 5]) -> Option<VisionRequest> {
        let moved =
            self.hough_at.is_none_or(|p| (p[0] - at.x_m).hypot(p[1] - at.y_m) >= self.g.retry_after_m);
        let here = V2::new(at.x_m, at.y_m);
        let dock = V2::new(self.g.dock_m[0], self.g.dock_m[1]);
        let to_dock = dock.minus(here);
        // In view: inside the camera's half field of view, less 5 degrees for the dock's own width.
        let half_fov = (self.centre_px[0] / self.focal_px).atan() - 5f64.to_radians();
        let in_view = wrap(to_dock.y.atan2(to_dock.x) - at.heading_rad).abs() <= half_fov;
        let n = self.g.dock_facing_deg.to_radians();
        let n = V2::new(n.cos(), n.sin());
        let lateral = (to_dock.x * n.y - to_dock.y * n.x).abs();
        // In the approach zone: on the axis's cone, and far enough out that the whole frame, its
        // foot included, fits the image (`fix_beyond_m`): nearer, the Hough cannot see the dock.
        let in_zone = d >= self.g.fix_beyond_m && lateral <= d * self.g.approach_cone_deg.to_radians().tan();
        let approach = dock.plus(n.scale(self.g.hough_range_m - 0.5 * self.g.hough_range_sd_m));
        // Latched, so that a robot on the zone's edge does not turn back and forth across it.
        if !in_zone {
            self.retreating = true;
        } else if self.retreating && approach.minus(here).norm() < self.g.retry_after_m {
            // Back at the zone's entry: a new view, so the Hough may be tried here again.
            self.retreating = false;
            self.hough_at = None;
        }
        if d <= self.g.hough_range_m && moved && in_view && in_zone && !self.retreating {
            self.trigger(Trigger::Terminal);
            self.seq.forget();
            return None;
        }
        let request = (!self.seq.waiting())
            .then(|| self.seq.request(now, VisionAlgorithm::Phototropic, [0.0; 4], [0.0; 8]));
        let goal = match self.light_rad {
            // Off the approach zone (beside the dock, past it): back to the axis first (002 §5.2:
            // when tracking fails, go back to where discovery works).
            _ if self.retreating => approach,
            Some(a) => here.plus(V2::new(a.cos(), a.sin()).scale(5.0)),
            None => dock,
        };
        // Within Hough range in the zone but not facing the dock: turn to it on the spot first,
        // rather than drive on past the range where the frame fits the image.
        let speed = if d <= self.g.hough_range_m && in_zone && !in_view && !self.retreating {
            0.01
        } else {
            self.g.ballistic_mps
        };
        parts[0] = move_to_goal(here, goal, speed);
        if let Some(ring) = &self.ring {
            parts[1] = drive::avoid_echoes(ring, at, self.sensor_ring_m, &self.drive);
        }
        parts[2] = self.noise.vector();
        request
    }

    /// q2, controlled: towards the tracked target, channelled onto the dock's axis; asks for the
    /// target again, or now and then for a fix from the frame while it is in view.
    fn region_tracking(&mut self, at: Pose2, d: f64, now: u64, parts: &mut [V2; 5]) -> Option<VisionRequest> {
        self.since_fix += 1;
        let [u, v, area] = self.target?;
        let here = V2::new(at.x_m, at.y_m);
        // Where the target is now, the robot having turned since it was seen.
        let u = u + self.focal_px * (at.heading_rad - self.target_heading);
        let side = area.sqrt();
        let range = self.focal_px * self.g.target_side_m / side.max(1.0);
        let bearing = at.heading_rad + ((self.centre_px[0] - u) / self.focal_px).atan();
        // Channelled onto the dock's axis (004 §4.2: the approach zone): the target seen fixes
        // the axis, and the robot steers for a point on it `lead_m` nearer the dock than itself.
        let target = here.plus(V2::new(bearing.cos(), bearing.sin()).scale(range));
        let n = self.g.dock_facing_deg.to_radians();
        let n = V2::new(n.cos(), n.sin());
        let out = here.minus(target);
        let along = out.dot(n);
        let goal = target.plus(n.scale((along - self.g.lead_m).max(self.g.final_m)));
        // ...but never so far off the target that it would leave the image.
        let to_goal = goal.minus(here);
        let off = wrap(to_goal.y.atan2(to_goal.x) - bearing);
        let keep = self.g.keep_in_view_deg.to_radians();
        let dir = bearing + off.clamp(-keep, keep);
        let speed = self.g.controlled_mps.min(0.5 * (range - self.g.final_m)).max(0.0);
        parts[0] = V2::new(dir.cos(), dir.sin()).scale(speed);
        if self.seq.waiting() {
            return None;
        }
        let frame_in_view = d > self.g.fix_beyond_m;
        if frame_in_view && self.since_fix >= self.g.fix_every_ticks {
            // Now and then a fix from the frame, while it is in view.
            self.since_fix = 0;
            return Some(self.hough_request(now, d));
        }
        let half = (2.0 * side).max(24.0);
        let c = [self.centre_px[0] * 2.0, self.centre_px[1] * 2.0];
        let window = [(u - half).max(0.0), (v - half).max(0.0), (u + half).min(c[0]), (v + half).min(c[1])]
            .map(|x| x as f32);
        let g = self.g.target_grey.map(|x| x as f32);
        let params = [g[0], g[1], 10.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        Some(self.seq.request(now, VisionAlgorithm::RegionSegmenter, window, params))
    }

    /// q3: hold the heading, move-to-goal straight ahead slowing to the mark, until the sonar
    /// says the dock is at the final distance (too close is fatal).
    fn sonar_positioning(&mut self, at: Pose2, parts: &mut [V2; 5]) {
        match self.range_ahead() {
            Some(r) if r < self.g.too_close_m => self.trigger(Trigger::Fatal),
            Some(r) if r <= self.g.final_m => self.trigger(Trigger::Terminal),
            Some(r) => {
                let speed = self.g.controlled_mps.min(r - self.g.final_m + 0.02);
                parts[0] = V2::new(at.heading_rad.cos(), at.heading_rad.sin()).scale(speed);
            }
            None => {}
        }
    }
}

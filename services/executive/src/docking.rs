//! The docking behaviour of 004 §4.2 under its finite state acceptor (`missions/fsa/docking.toml`):
//! each state asks the vision workers for its perceptual algorithm and drives the robot by motor
//! schemas; what perception returns, the believed distance to the dock and the sonar's range
//! are the triggers. q0 phototropic: move-to-goal towards the lamp's bearing, avoid-static-
//! obstacle, noise (ballistic); once the dock is believed within Hough range, q1 constrained
//! Hough: stop and recognise the dock; q2 adaptive region tracking of the target above the
//! frame: controlled motion towards it, until it is large (near); q3 ultrasonic positioning:
//! hold the heading until the sonar says the dock is at the final distance; q4 docked.

use harvey_msgs::{
    BehaviourState, MotionCommand, Pose2, SonarRing, VisionAlgorithm, VisionRequest, VisionResult,
    VisionStatus,
};

use crate::drive::{self, DriveParams, Vectors};
use crate::fsa::{Fsa, Trigger};
use crate::mission::DockingGoal;
use crate::schemas::{Noise, V2, move_to_goal};
use crate::sequenced::Sequenced;

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
    /// Whether it docked, once the acceptor has accepted.
    pub done: Option<bool>,
    /// Odometry now, and `(odometry then, pose then)` of the last fix from the dock.
    odometry: Pose2,
    fix: Option<(Pose2, Pose2)>,
    /// The believed heading when the target was last seen, and ticks since the last fix asked.
    target_heading: f64,
    since_fix: u32,
}

/// The robot's pose from the dock recognised in the image (the inverse perspective of 004
/// §4.1.3 on the Hough's frame): the end posts' apparent heights `item[4..6]` give their depths,
/// their difference the angle the face is seen at, their mean the frame's depth, and the frame
/// centre's column `item[0]` its bearing. `None` without both posts, or with a post whose height
/// disagrees with the match's scale by more than a third (a post cut short or lengthened by
/// something in front of the dock), or seen at more than 35 degrees.
pub fn pose_from_dock(g: &DockingGoal, focal_px: f64, centre_u: f64, item: &[f64; 6]) -> Option<Pose2> {
    let [u, _, _, scale, left, right] = *item;
    let plausible = |h: f64| (0.75 * scale..1.33 * scale).contains(&h);
    if !plausible(left) || !plausible(right) {
        return None;
    }
    let post_m = g.frame_width_m / 2.0;
    let (z_left, z_right) = (focal_px * post_m / left, focal_px * post_m / right);
    let sin_turned = (z_left - z_right) / g.frame_width_m;
    if sin_turned.abs() > 0.57 {
        return None;
    }
    let turned = sin_turned.asin();
    let heading = crate::recover::wrap(g.dock_facing_deg.to_radians() + std::f64::consts::PI + turned);
    let bearing = ((centre_u - u) / focal_px).atan();
    let ray = (z_left + z_right) / 2.0 / bearing.cos();
    let a = heading + bearing;
    Some(Pose2 { x_m: g.dock_m[0] - ray * a.cos(), y_m: g.dock_m[1] - ray * a.sin(), heading_rad: heading })
}

/// The face's distance from `at` along the face's normal (the robot's centre to the face).
fn face_distance(g: &DockingGoal, at: Pose2) -> f64 {
    let n = g.dock_facing_deg.to_radians();
    (at.x_m - g.dock_m[0]) * n.cos() + (at.y_m - g.dock_m[1]) * n.sin()
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
            done: None,
            odometry: Pose2::default(),
            fix: None,
            target_heading: 0.0,
            since_fix: 0,
        }
    }

    /// Where docking ends: `final_m` out from the face's centre, facing it.
    pub fn goal_pose(&self) -> Pose2 {
        let n = self.g.dock_facing_deg.to_radians();
        Pose2 {
            x_m: self.g.dock_m[0] + self.g.final_m * n.cos(),
            y_m: self.g.dock_m[1] + self.g.final_m * n.sin(),
            heading_rad: crate::recover::wrap(n + std::f64::consts::PI),
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
        crate::refining::fixed(self.fix, self.odometry)
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
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
        // A fix far from the belief is a misreading, once the belief has had a first fix.
        let near = |p: &Pose2| {
            self.fix.is_none()
                || ((p.x_m - at.x_m).hypot(p.y_m - at.y_m) < self.g.fix_gate_m
                    && crate::recover::wrap(p.heading_rad - at.heading_rad).abs()
                        < self.g.fix_gate_deg.to_radians())
        };
        if let (true, Some(v)) = (dock, &item)
            && let Some(p) = pose_from_dock(&self.g, self.focal_px, self.centre_px[0], v).filter(near)
        {
            tracing::info!(
                x = p.x_m,
                y = p.y_m,
                heading_deg = p.heading_rad.to_degrees(),
                "pose from the dock"
            );
            self.fix = Some((self.odometry, p));
        }
        match (self.perception(), item) {
            // A fix asked for while tracking: nothing more to it.
            ("region-tracking", _) if dock => {}
            ("phototropic", Some(v)) if v[3] >= self.g.light_min_grey => {
                self.light_rad = Some(at.heading_rad + ((self.centre_px[0] - v[0]) / self.focal_px).atan());
            }
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
    /// hypotheses over the distances the belief allows (004 §4.2.2).
    fn hough_request(&mut self, now: u64, d: f64) -> VisionRequest {
        let unit = self.focal_px * self.g.frame_width_m / 2.0;
        let (far, near) = (d + self.g.hough_range_sd_m, (d - self.g.hough_range_sd_m).max(0.5));
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
        self.odometry = odometry;
        let at = self.believed();
        let here = V2::new(at.x_m, at.y_m);
        let d = face_distance(&self.g, at);
        let mut request = None;
        let mut parts = [V2::default(); 5];
        match self.perception() {
            "phototropic" => {
                let moved = self
                    .hough_at
                    .is_none_or(|p| (p[0] - at.x_m).hypot(p[1] - at.y_m) >= self.g.retry_after_m);
                if d <= self.g.hough_range_m && moved {
                    self.trigger(Trigger::Terminal);
                    self.seq.forget();
                } else {
                    if !self.seq.waiting() {
                        request =
                            Some(self.seq.request(now, VisionAlgorithm::Phototropic, [0.0; 4], [0.0; 8]));
                    }
                    let goal = match self.light_rad {
                        Some(a) => here.plus(V2::new(a.cos(), a.sin()).scale(5.0)),
                        None => V2::new(self.g.dock_m[0], self.g.dock_m[1]),
                    };
                    parts[0] = move_to_goal(here, goal, self.g.ballistic_mps);
                    if let Some(ring) = &self.ring {
                        parts[1] = drive::avoid_echoes(ring, at, self.sensor_ring_m, &self.drive);
                    }
                    parts[2] = self.noise.vector();
                }
            }
            "hough-dock" if !self.seq.waiting() => {
                request = Some(self.hough_request(now, d));
                self.hough_at = Some([at.x_m, at.y_m]);
            }
            "region-tracking" => {
                self.since_fix += 1;
                if let Some([u, v, area]) = self.target {
                    // Where the target is now, the robot having turned since it was seen.
                    let u = u + self.focal_px * (at.heading_rad - self.target_heading);
                    let side = area.sqrt();
                    let range = self.focal_px * self.g.target_side_m / side.max(1.0);
                    let bearing = at.heading_rad + ((self.centre_px[0] - u) / self.focal_px).atan();
                    // Channelled onto the dock's axis (004 §4.2: the approach zone): the target
                    // seen fixes the axis, and the robot steers for a point on it `lead_m` nearer
                    // the dock than itself.
                    let target = here.plus(V2::new(bearing.cos(), bearing.sin()).scale(range));
                    let n = self.g.dock_facing_deg.to_radians();
                    let n = V2::new(n.cos(), n.sin());
                    let out = here.minus(target);
                    let along = out.x * n.x + out.y * n.y;
                    let goal = target.plus(n.scale((along - self.g.lead_m).max(self.g.final_m)));
                    // ...but never so far off the target that it would leave the image.
                    let to_goal = goal.minus(here);
                    let off = crate::recover::wrap(to_goal.y.atan2(to_goal.x) - bearing);
                    let keep = self.g.keep_in_view_deg.to_radians();
                    let dir = bearing + off.clamp(-keep, keep);
                    let speed = self.g.controlled_mps.min(0.5 * (range - self.g.final_m)).max(0.0);
                    parts[0] = V2::new(dir.cos(), dir.sin()).scale(speed);
                    let frame_in_view = d > self.g.fix_beyond_m;
                    if !self.seq.waiting() && frame_in_view && self.since_fix >= self.g.fix_every_ticks {
                        // Now and then a fix from the frame, while it is in view.
                        self.since_fix = 0;
                        request = Some(self.hough_request(now, d));
                    } else if !self.seq.waiting() {
                        let half = (2.0 * side).max(24.0);
                        let window = [u - half, v - half, u + half, v + half].map(|x| x as f32);
                        let c = [self.centre_px[0] * 2.0, self.centre_px[1] * 2.0];
                        let window = [
                            window[0].max(0.0),
                            window[1].max(0.0),
                            window[2].min(c[0] as f32),
                            window[3].min(c[1] as f32),
                        ];
                        let g = self.g.target_grey.map(|x| x as f32);
                        request = Some(self.seq.request(
                            now,
                            VisionAlgorithm::RegionSegmenter,
                            window,
                            [g[0], g[1], 10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                        ));
                    }
                }
            }
            "sonar-positioning" => match self.range_ahead() {
                Some(r) if r < self.g.too_close_m => self.trigger(Trigger::Fatal),
                Some(r) if r <= self.g.final_m => self.trigger(Trigger::Terminal),
                Some(r) => {
                    // Hold the heading: move-to-goal straight ahead, slowing to the mark.
                    let speed = self.g.controlled_mps.min(r - self.g.final_m + 0.02);
                    let ahead = V2::new(at.heading_rad.cos(), at.heading_rad.sin());
                    parts[0] = ahead.scale(speed);
                }
                None => {}
            },
            _ => {}
        }
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn goal() -> DockingGoal {
        let text =
            std::fs::read_to_string(format!("{}/../../missions/docking.toml", env!("CARGO_MANIFEST_DIR")))
                .expect("readable");
        crate::mission::parse(&text, "docking.toml").expect("parses").docking.expect("docking")
    }

    /// The Hough's item for a robot at `at`: frame centre column, scale, and the end posts'
    /// heights (left post at y = +0.5, on the robot's left when it faces the dock).
    fn seen_from(at: Pose2, f: f64) -> [f64; 6] {
        let (c, s) = (at.heading_rad.cos(), at.heading_rad.sin());
        let depth = |p: [f64; 2]| (p[0] - at.x_m) * c + (p[1] - at.y_m) * s;
        let left_of = |p: [f64; 2]| -(p[0] - at.x_m) * s + (p[1] - at.y_m) * c;
        let centre = [13.6, 0.0];
        let u = 320.0 - f * left_of(centre) / depth(centre);
        [u, 200.0, 0.9, f * 0.5 / depth(centre), f * 0.5 / depth([13.6, 0.5]), f * 0.5 / depth([13.6, -0.5])]
    }

    #[test]
    fn the_frame_s_posts_and_centre_give_the_robot_s_pose() {
        let g = goal();
        for truth in [
            Pose2 { x_m: 10.0, y_m: -0.5, heading_rad: 10f64.to_radians() },
            Pose2 { x_m: 9.0, y_m: 1.2, heading_rad: -20f64.to_radians() },
            Pose2 { x_m: 11.5, y_m: 0.0, heading_rad: 0.0 },
        ] {
            let p = pose_from_dock(&g, 554.0, 320.0, &seen_from(truth, 554.0)).expect("a pose");
            assert!((p.x_m - truth.x_m).abs() < 1e-9 && (p.y_m - truth.y_m).abs() < 1e-9, "{p:?} {truth:?}");
            assert!((p.heading_rad - truth.heading_rad).abs() < 1e-9, "{p:?} {truth:?}");
        }
        // A post cut short by something in front of it: no pose.
        let mut cut = seen_from(Pose2 { x_m: 10.0, y_m: 0.0, heading_rad: 0.0 }, 554.0);
        cut[4] *= 0.6;
        assert_eq!(pose_from_dock(&g, 554.0, 320.0, &cut), None);
    }
}

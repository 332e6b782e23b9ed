//! The pole hunt of the AAAI-92 competition (004 §5): a schema assemblage that, pole after
//! pole, runs the move-to-pole acceptor (`missions/fsa/move-to-pole.toml`). q0 visual pole
//! recognition: look, and turn half the field of view after each look without the pole
//! (recoverable), centre it once seen (normal), go on once centred (terminal); q1 the IR beacon
//! (the simulator has none, so the visual estimate goes on unchanged, as the paper's robot did
//! without a reading); q2 ballistic motion to where the pole was seen, by move-to-goal,
//! avoid-static-obstacle, probe, avoid-past and noise, until near (terminal) or a timer runs out
//! (recoverable: re-acquire the pole); q3 parking by the sonar's nearest echo towards the pole;
//! q4 parked, and the assemblage starts on the next pole.

use harvey_geometry::wrap;
use harvey_msgs::{
    BehaviourState, MotionCommand, Pose2, SonarRing, VisionAlgorithm, VisionRequest, VisionResult,
};

use super::drive::{self, DriveParams};
use super::fsa::{Fsa, Trigger};
use super::schemas::{AvoidPast, Noise, V2, move_to_goal, probe};
use super::sequenced::Sequenced;
use crate::mission::PolesGoal;

/// What q0 is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Look {
    /// Backing away from the pole just parked by, until then.
    Backing {
        until_ns: u64,
    },
    Ask,
    Waiting,
    Turning {
        to: f64,
    },
    Wandering {
        until_ns: u64,
    },
}

/// The hunt's state.
#[derive(Debug, Clone)]
pub struct PoleHunt {
    g: PolesGoal,
    pub seq: Sequenced,
    drive: DriveParams,
    noise: Noise,
    past: AvoidPast,
    focal_px: f64,
    centre_u: f64,
    sensor_ring_m: f64,
    pole_half_m: f64,
    ring: Option<SonarRing>,
    /// The ring's echoes as (world bearing, range), for probe (kept between ticks).
    echo_buf: Vec<(f64, f64)>,
    at: Pose2,
    look: Look,
    /// Looks in a row without a pole to go to.
    fruitless: u32,
    /// The pole being sought (its code) and where it was seen to be.
    target: Option<u32>,
    estimate: [f64; 2],
    timer_ns: u64,
    beacon_until_ns: u64,
    /// q3: since when no echo has come from towards the pole.
    silent_since_ns: Option<u64>,
    /// Codes parked by, in order.
    pub visited: Vec<u32>,
    pub done: Option<bool>,
}

impl PoleHunt {
    /// `camera` = (focal length, image width) in pixels; `pole_side_m` from the world's poles.
    pub fn new(
        g: PolesGoal,
        fsa: Fsa,
        camera: (f64, f64),
        sensor_ring_m: f64,
        pole_side_m: f64,
        seed: u64,
        start: Pose2,
    ) -> Self {
        let drive = DriveParams::new(
            g.ballistic_mps,
            g.max_turn_degps,
            g.turn_gain,
            sensor_ring_m,
            (g.avoid_sphere_m, g.avoid_gain),
        );
        let noise = Noise::new(seed, g.noise_mps, g.noise_ticks);
        let past =
            AvoidPast::new(V2::new(start.x_m, start.y_m), 80, g.past_cell_m, g.past_gain, g.past_decay);
        Self {
            g,
            seq: Sequenced::new(fsa),
            drive,
            noise,
            past,
            focal_px: camera.0,
            centre_u: camera.1 / 2.0,
            sensor_ring_m,
            pole_half_m: pole_side_m / 2.0,
            ring: None,
            echo_buf: Vec::with_capacity(harvey_msgs::SONAR_SENSORS),
            at: start,
            look: Look::Ask,
            fruitless: 0,
            target: None,
            estimate: [start.x_m, start.y_m],
            timer_ns: 0,
            beacon_until_ns: 0,
            silent_since_ns: None,
            visited: Vec::new(),
            done: None,
        }
    }

    /// The pole sought (where it was seen), or where the robot is.
    pub fn goal_pose(&self) -> Pose2 {
        Pose2 { x_m: self.estimate[0], y_m: self.estimate[1], heading_rad: 0.0 }
    }

    /// Whether the hunt counts as done when its time runs out.
    pub fn enough(&self) -> bool {
        self.visited.len() as u32 >= self.g.enough
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
    }

    /// A pole-recognition answer: the pole sought (or the nearest not yet visited) centred,
    /// to be centred, or not there.
    pub fn on_vision(&mut self, r: &VisionResult) {
        if !self.seq.answers(r) || self.seq.perception() != "pole-recognition" {
            return;
        }
        let seen = r.items[..r.count as usize].iter().map(|i| i.values.map(f64::from)).find(|v| {
            let code = v[2] as u32;
            self.target.map_or(!self.visited.contains(&code), |t| t == code)
        });
        let h = self.at.heading_rad;
        match seen {
            Some(v) => {
                let bearing = ((self.centre_u - v[0]) / self.focal_px).atan();
                let reach = v[1] / bearing.cos() + self.pole_half_m;
                self.target = Some(v[2] as u32);
                self.estimate =
                    [self.at.x_m + reach * (h + bearing).cos(), self.at.y_m + reach * (h + bearing).sin()];
                self.fruitless = 0;
                if bearing.abs() <= self.g.centred_deg.to_radians() {
                    self.seq.trigger(Trigger::Terminal);
                    self.look = Look::Ask;
                } else {
                    self.seq.trigger(Trigger::Normal);
                    self.look = Look::Turning { to: h + bearing };
                }
            }
            None => {
                self.seq.trigger(Trigger::Recoverable);
                self.fruitless += 1;
                let whole_turn = (360.0 / self.g.sweep_deg).ceil() as u32;
                self.look = if self.fruitless > whole_turn {
                    // Nothing new from here: look from elsewhere.
                    self.fruitless = 0;
                    self.target = None;
                    Look::Wandering { until_ns: r.header.stamp_ns + (self.g.wander_s * 1e9) as u64 }
                } else {
                    Look::Turning { to: h + self.g.sweep_deg.to_radians() }
                };
            }
        }
    }

    /// One odometry tick: the state's triggers from position, time and range, its request and
    /// its motor schemas; returns what to send.
    pub fn on_odometry(
        &mut self,
        odometry: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        if self.seq.fsa.accepted() {
            // q4 was published once: the assemblage re-invokes move-to-pole, once clear of
            // the pole.
            self.seq.fsa.reset();
            self.look = Look::Backing { until_ns: now + (self.g.back_off_s * 1e9) as u64 };
        }
        self.at = odometry;
        let at = odometry;
        let here = V2::new(at.x_m, at.y_m);
        self.past.visit(here);
        let goal = V2::new(self.estimate[0], self.estimate[1]);
        let mut request = None;
        let mut parts = [V2::default(); 5];
        let mut spin = None;
        match self.seq.perception() {
            "pole-recognition" => match self.look {
                Look::Backing { until_ns } if now >= until_ns => self.look = Look::Ask,
                Look::Backing { .. } => spin = Some(0.0),
                Look::Ask => {
                    // The whole frame; params: no fixed grey level, the default area, the contrast.
                    let params = [0.0, 0.0, self.g.ring_contrast as f32, 0.0, 0.0, 0.0, 0.0, 0.0];
                    request = Some(self.seq.request(now, VisionAlgorithm::Poles, [0.0; 4], params));
                    self.look = Look::Waiting;
                }
                Look::Waiting => {}
                Look::Turning { to } => {
                    let e = wrap(to - at.heading_rad);
                    if e.abs() < 1f64.to_radians() {
                        self.look = Look::Ask;
                    } else {
                        spin = Some(
                            (self.g.turn_gain * e)
                                .clamp(-self.drive.max_turn_radps, self.drive.max_turn_radps),
                        );
                    }
                }
                Look::Wandering { until_ns } if now >= until_ns => self.look = Look::Ask,
                Look::Wandering { .. } => parts = self.wander(at, here, None),
            },
            "ir-beacon" => {
                // The robot waits as long as a beacon would take to come round (004 §5.3); the
                // simulator has none, so the visual estimate goes on unchanged.
                if self.beacon_until_ns == 0 {
                    self.beacon_until_ns = now + (self.g.beacon_wait_s * 1e9) as u64;
                } else if now >= self.beacon_until_ns {
                    self.beacon_until_ns = 0;
                    self.seq.trigger(Trigger::Normal);
                    let far = goal.minus(here).norm();
                    self.timer_ns =
                        now + ((1.5 * far / self.g.ballistic_mps + self.g.timer_slack_s) * 1e9) as u64;
                }
            }
            "encoders" => {
                if goal.minus(here).norm() <= self.g.near_m {
                    self.seq.trigger(Trigger::Terminal);
                } else if now >= self.timer_ns {
                    self.seq.trigger(Trigger::Recoverable);
                    self.look = Look::Ask;
                } else {
                    parts = self.wander(at, here, Some(goal));
                }
            }
            "sonar-parking" => {
                let towards = goal.minus(here);
                let bearing = towards.y.atan2(towards.x);
                let nearest = self.ring.as_ref().and_then(|r| {
                    drive::echoes(r, at.heading_rad, self.sensor_ring_m)
                        .filter(|(b, _)| wrap(b - bearing).abs() <= 30f64.to_radians())
                        .min_by(|a, b| a.1.total_cmp(&b.1))
                });
                let echo = nearest.filter(|&(_, r)| r <= self.g.lost_m);
                self.silent_since_ns = if echo.is_some() { None } else { self.silent_since_ns.or(Some(now)) };
                match echo {
                    Some((_, r)) if r <= self.g.park_m => self.park(true),
                    Some((b, r)) => {
                        let echo = here.plus(V2::new(b.cos(), b.sin()).scale(r));
                        parts[0] =
                            move_to_goal(here, echo, self.g.controlled_mps.min(r - self.g.park_m + 0.02));
                    }
                    // A sensor's reading lost now and then (a dropout, an echo gone another
                    // way) is not the pole gone: the robot waits still for the next readings.
                    None if now
                        < self.silent_since_ns.unwrap_or(now) + (self.g.lost_after_s * 1e9) as u64 =>
                    {
                        spin = Some(0.0);
                    }
                    None => {
                        tracing::debug!(
                            ?nearest,
                            goal = ?(goal.x, goal.y),
                            here = ?(here.x, here.y),
                            "parking: no echo towards the pole within reach"
                        );
                        self.park(false)
                    }
                }
            }
            _ => {}
        }
        let vectors = drive::vectors(parts, &self.drive);
        let vw = match (spin, self.look) {
            (Some(_), Look::Backing { .. }) => (-self.g.controlled_mps, 0.0),
            (Some(w), _) => (0.0, w),
            (None, _) => drive::velocity(vectors.sum, at, &self.drive),
        };
        let vw = drive::held(self.ring.as_ref(), vw);
        let (command, state) = self.seq.output(at, now, &vectors, vw, self.visited.len() as u32);
        (request, command, state)
    }

    /// q2's schemas (or wandering's, without a goal): move-to-goal, avoid-static-obstacle,
    /// noise, avoid-past, probe.
    fn wander(&mut self, at: Pose2, here: V2, goal: Option<V2>) -> [V2; 5] {
        self.echo_buf.clear();
        if let Some(r) = &self.ring {
            self.echo_buf.extend(drive::echoes(r, at.heading_rad, self.sensor_ring_m));
        }
        let avoid = self
            .ring
            .as_ref()
            .map_or(V2::default(), |r| drive::avoid_echoes(r, at, self.sensor_ring_m, &self.drive));
        let to_goal = goal.map_or(V2::default(), |g| move_to_goal(here, g, self.g.ballistic_mps));
        let open = probe(&self.echo_buf, self.g.probe_gain);
        [to_goal, avoid, self.noise.vector(), self.past.vector(here), open]
    }

    /// q3 is over (parked or the pole lost): q4, then the next pole.
    fn park(&mut self, parked: bool) {
        self.silent_since_ns = None;
        self.seq.trigger(if parked { Trigger::Terminal } else { Trigger::Recoverable });
        if let Some(code) = self.target.take().filter(|_| parked) {
            tracing::info!(code, visited = self.visited.len() + 1, "parked by a pole");
            self.visited.push(code);
        }
        if self.visited.len() as u32 >= self.g.count {
            self.done = Some(true);
        }
    }
}

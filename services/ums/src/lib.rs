//! The uncertainty management subsystem (002 ch. VII) as a state machine: odometry grows the map
//! turn by turn and run by run (§3.3), landmark sightings slice it (§3.4) at their own time
//! stamps — a late sighting is applied to the map as it was then and the growth since replayed —
//! the Expecter publishes where each active landmark must appear (§4, §5.1), the executive's pose
//! fixes (000 §5.6) shrink it to a small region, and the map reports "lost" when it grows too
//! large or predicted landmarks go missing. Optionally the camera mount is measured from the
//! sightings at the start and taken off every sighting (`mount.rs`).

mod consensus;
mod error;
pub mod expecter;
mod fix;
pub mod geometry;
pub mod look;
pub mod map;
pub mod mount;
pub mod node;
pub mod reduction;
pub mod resume;

use std::collections::VecDeque;

use harvey_msgs::{
    Expectation, Header, LandmarkSighting, MAX_POLYGON_VERTICES, Odometry, Pose2, SightingKind,
    UncertaintyMap,
};
use harvey_world::{LandmarkClass, Strategy, World};

pub use error::{FixError, OdometryError, SightingError};
use expecter::View;
use map::{Growth, Map};
use reduction::{Known, Observation};

/// How the UMS works; the defaults follow 002 §3.1 (3 sigma).
#[derive(Debug, Clone)]
pub struct Config {
    pub sigmas: f64,
    /// Above this area the robot is lost.
    pub lost_area_m2: f64,
    /// This many predicted landmarks missed in a row and the robot is lost.
    pub lost_after_misses: u32,
    /// How long a sighting may lag the odometry and still be applied at its own stamp.
    pub history_ns: u64,
    pub image_px: (u32, u32),
    /// How well a pose fix from landmark vertices places the robot: half the side of the square
    /// round the fixed position (m), and the heading either way (rad).
    pub fix_m: f64,
    pub fix_heading_rad: f64,
    /// Measure the camera mount from the sightings at the start and take it off every sighting
    /// (`mount.rs`); `None` takes the sightings as the vision workers give them.
    pub mount_gate: Option<mount::Gate>,
}

/// Pixels added around a window for the strategy that searches it: a correlation template's
/// half-size, a line finder's gradient support, a region's growth.
pub fn margin_px(s: Strategy) -> f64 {
    match s {
        Strategy::LineFinder => 4.0,
        Strategy::RegionSegmenter | Strategy::Hough => 6.0,
        Strategy::Correlation => 8.0,
    }
}

/// One growth step taken from odometry.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct Step {
    turn_rad: f64,
    run_m: f64,
    first_run: bool,
}

/// What the UMS publishes.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    Map(Box<UncertaintyMap>),
    Expectation(Expectation),
    /// A sighting that fell due could not be applied (why, naming it); the map and the
    /// expectations of the same odometry go out all the same.
    Rejected(SightingError),
}

/// The UMS's state.
pub struct Ums {
    world: World,
    config: Config,
    map: Map,
    /// (stamp, map after the step, step): what a late sighting rewinds to.
    history: VecDeque<(u64, Map, Step)>,
    pending: Vec<LandmarkSighting>,
    command_id: u32,
    travelled_m: f64,
    turned_rad: f64,
    run_started: bool,
    last_stamp_ns: u64,
    missed: u32,
    seq: u64,
    /// Each expectation's own sequence number (several go out per map, or none).
    expectation_seq: u64,
    /// The camera mount measured at the start.
    mount: mount::Mount,
}

impl Ums {
    /// Starts with the pose known exactly at the world's start.
    pub fn new(world: World, config: Config) -> Self {
        let s = world.start;
        let map = Map::exact(s.x_m, s.y_m, s.heading_rad);
        Self {
            world,
            config,
            map,
            history: VecDeque::new(),
            pending: Vec::new(),
            command_id: 0,
            travelled_m: 0.0,
            turned_rad: 0.0,
            run_started: false,
            last_stamp_ns: 0,
            missed: 0,
            seq: 0,
            expectation_seq: 0,
            mount: mount::Mount::default(),
        }
    }

    pub fn map(&self) -> &Map {
        &self.map
    }

    fn grow(&self, map: &mut Map, step: Step) {
        let terrain = self.world.terrain_at(map.centre[0], map.centre[1]);
        let g = Growth { terrain, sigmas: self.config.sigmas };
        g.turn(map, step.turn_rad);
        if step.run_m != 0.0 || step.first_run {
            g.run(map, step.run_m, step.first_run);
        }
    }

    /// One odometry message: grow by the motion since the last, apply sightings now due.
    pub fn on_odometry(&mut self, o: &Odometry) -> Result<Vec<Output>, OdometryError> {
        if o.header.stamp_ns < self.last_stamp_ns {
            return Err(OdometryError::OutOfOrder {
                stamp_ns: o.header.stamp_ns,
                last_ns: self.last_stamp_ns,
            });
        }
        if !(o.travelled_m.is_finite() && o.turned_rad.is_finite() && o.command.distance_m.is_finite()) {
            return Err(OdometryError::NotFinite);
        }
        self.last_stamp_ns = o.header.stamp_ns;
        if o.command_accepted == 1 && o.command.command_id != self.command_id {
            self.command_id = o.command.command_id;
            (self.travelled_m, self.turned_rad, self.run_started) = (0.0, 0.0, false);
        }
        let mut step = Step { turn_rad: 0.0, run_m: 0.0, first_run: false };
        if o.command_accepted == 1 {
            step.turn_rad = map::wrap(o.turned_rad - self.turned_rad);
            let sign = if o.command.distance_m < 0.0 { -1.0 } else { 1.0 };
            step.run_m = sign * (o.travelled_m - self.travelled_m).max(0.0);
            // The inertial loss (002 §3.2) is a MOVE's, starting from rest; a velocity command
            // steers a robot already rolling (the simulator loses none at its start either).
            let from_rest = o.command.kind != harvey_msgs::CommandKind::Velocity as u32;
            step.first_run = step.run_m != 0.0 && !self.run_started && from_rest;
            self.run_started |= step.first_run;
            (self.travelled_m, self.turned_rad) = (o.travelled_m, o.turned_rad);
        }
        let mut map = std::mem::replace(&mut self.map, Map::exact(0.0, 0.0, 0.0));
        self.grow(&mut map, step);
        self.history.push_back((o.header.stamp_ns, map.clone(), step));
        self.map = map;
        while self.history.front().is_some_and(|(t, ..)| t + self.config.history_ns < o.header.stamp_ns) {
            self.history.pop_front();
        }
        let mut due: Vec<LandmarkSighting> =
            self.pending.iter().copied().filter(|s| s.header.stamp_ns <= o.header.stamp_ns).collect();
        // Frame by frame (stable: a frame's sightings keep their order).
        due.sort_by_key(|s| s.header.stamp_ns);
        self.pending.retain(|s| s.header.stamp_ns > o.header.stamp_ns);
        let mut rejected: Vec<Output> = Vec::new();
        for frame in due.chunk_by(|a, b| a.header.stamp_ns == b.header.stamp_ns) {
            let frame: Vec<LandmarkSighting> = frame.iter().map(|s| self.calibrated(s)).collect();
            let frame = frame.as_slice();
            let blunders = consensus::outliers(&self.world, &self.map, frame, self.config.sigmas);
            for (i, s) in frame.iter().enumerate() {
                let why = if blunders.contains(&i) {
                    Some(reduction::Rejection::Disagrees)
                } else if consensus::implausible(&self.world, &self.map, s, self.config.sigmas) {
                    Some(reduction::Rejection::Implausible)
                } else {
                    None
                };
                let outcome = match why {
                    Some(why) => {
                        let landmark = self.world.landmarks[s.landmark_index as usize].name.clone();
                        Err(SightingError::Rejected { landmark, why })
                    }
                    None => self.apply_sighting(s),
                };
                rejected.extend(outcome.err().map(Output::Rejected));
            }
        }
        let mut out = vec![Output::Map(Box::new(self.publishable(o.header.stamp_ns)))];
        for mut e in self.expectations(o.header.stamp_ns) {
            self.expectation_seq += 1;
            e.header.seq = self.expectation_seq;
            out.push(Output::Expectation(e));
        }
        out.extend(rejected);
        Ok(out)
    }

    /// A sighting: checked, then applied at its stamp once odometry has reached it.
    pub fn on_sighting(&mut self, s: &LandmarkSighting) -> Result<(), SightingError> {
        self.check_sighting(s)?;
        if s.header.stamp_ns > self.last_stamp_ns {
            self.pending.push(*s);
            return Ok(());
        }
        let s = self.calibrated(s);
        self.apply_sighting(&s)
    }

    fn check_sighting(&self, s: &LandmarkSighting) -> Result<(), SightingError> {
        let name = self.world.landmarks.get(s.landmark_index as usize).map(|l| l.name.as_str());
        let name = name.ok_or(SightingError::UnknownLandmark { index: s.landmark_index })?;
        if SightingKind::from_raw(s.kind).is_none() {
            return Err(SightingError::UnknownKind { landmark: name.to_owned(), kind: s.kind });
        }
        if ![s.a, s.a_sd, s.b, s.b_sd].iter().all(|v| v.is_finite()) {
            return Err(SightingError::NotFinite { landmark: name.to_owned() });
        }
        Ok(())
    }

    fn apply_sighting(&mut self, s: &LandmarkSighting) -> Result<(), SightingError> {
        let l = &self.world.landmarks[s.landmark_index as usize];
        let obs = match SightingKind::from_raw(s.kind) {
            Some(SightingKind::NotFound) | None => {
                self.missed += 1;
                return Ok(());
            }
            Some(SightingKind::Bearing) => Observation::Bearing { bearing_rad: s.a, sd_rad: s.a_sd },
            Some(SightingKind::BearingRange) => Observation::BearingRange {
                bearing_rad: s.a,
                sd_rad: s.a_sd,
                range_m: s.b,
                range_sd_m: s.b_sd,
            },
            Some(SightingKind::GroundLine) => Observation::GroundLine {
                heading_rad: s.a,
                heading_sd_rad: s.a_sd,
                offset_m: s.b,
                offset_sd_m: s.b_sd,
            },
        };
        let known = Known {
            at: [l.position_m[0], l.position_m[1]],
            to: l.to_m.map(|t| [t[0], t[1]]),
            position_sd_m: self.world.landmark_sd_m(l),
        };
        let (sigmas, name, stamp_ns) = (self.config.sigmas, l.name.clone(), s.header.stamp_ns);
        self.rewrite_at(
            stamp_ns,
            || SightingError::TooOld { landmark: name.clone(), stamp_ns },
            |then| {
                reduction::apply(then, &known, &obs, sigmas)
                    .map_err(|why| SightingError::Rejected { landmark: name.clone(), why })
            },
        )
    }

    /// Replaces the map as it was at `stamp_ns` by `change` of it, then replays the growth since
    /// (a late observation applies at its own time); `too_old` when the history no longer
    /// reaches back to `stamp_ns`.
    fn rewrite_at<E>(
        &mut self,
        stamp_ns: u64,
        too_old: impl FnOnce() -> E,
        change: impl FnOnce(&Map) -> Result<Map, E>,
    ) -> Result<(), E> {
        let i = self.history.iter().rposition(|(t, ..)| *t <= stamp_ns).ok_or_else(too_old)?;
        let mut m = change(&self.history[i].1)?;
        self.history[i].1 = m.clone();
        for j in i + 1..self.history.len() {
            let step = self.history[j].2;
            self.grow(&mut m, step);
            self.history[j].1 = m.clone();
        }
        self.map = m;
        self.missed = 0;
        Ok(())
    }

    fn lost(&self) -> bool {
        self.map.area_m2() > self.config.lost_area_m2 || self.missed >= self.config.lost_after_misses
    }

    fn publishable(&mut self, stamp_ns: u64) -> UncertaintyMap {
        self.seq += 1;
        let m = &self.map;
        let mut vertices_m = [[0.0; 2]; MAX_POLYGON_VERTICES];
        for (v, p) in vertices_m.iter_mut().zip(&m.polygon) {
            *v = *p;
        }
        UncertaintyMap {
            header: Header::new(self.seq, stamp_ns),
            centre: Pose2 { x_m: m.centre[0], y_m: m.centre[1], heading_rad: m.heading_rad },
            vertex_count: m.polygon.len().min(MAX_POLYGON_VERTICES) as u32,
            lost: u32::from(self.lost()),
            vertices_m,
            heading_cw_rad: m.cw_rad,
            heading_ccw_rad: m.ccw_rad,
            area_m2: m.area_m2(),
            missed_landmarks: self.missed,
            reserved: 0,
        }
    }

    /// Windows for the landmarks of the meadow under the map's centre that are active from it,
    /// for the next frame (`expecter::window_ahead`); sequence number 0: `on_odometry` numbers
    /// what it publishes.
    pub fn expectations(&self, stamp_ns: u64) -> Vec<Expectation> {
        let m = &self.map;
        let Some(meadow) = self.world.meadow_at(m.centre[0], m.centre[1]) else { return Vec::new() };
        let (w, h) = self.config.image_px;
        let view = View { camera: &self.world.camera, width_px: w, height_px: h };
        let last_step = self.history.back().map_or((0.0, 0.0), |(_, _, s)| (s.turn_rad, s.run_m));
        self.world
            .landmarks
            .iter()
            .enumerate()
            .filter(|(_, l)| {
                meadow.landmarks.contains(&l.name)
                    && l.active_from(m.centre[0], m.centre[1], m.heading_rad.to_degrees())
            })
            .filter_map(|(i, l)| {
                let win = expecter::window_ahead(m, view, l, margin_px(l.strategy), last_step)?;
                let class = match l.class {
                    LandmarkClass::I => 1,
                    LandmarkClass::II => 2,
                    LandmarkClass::III => 3,
                };
                Some(Expectation {
                    header: Header::new(0, stamp_ns),
                    landmark_index: i as u32,
                    class,
                    window_px: [win.u0 as f32, win.v0 as f32, win.u1 as f32, win.v1 as f32],
                    width_px: w,
                    height_px: h,
                    contrast: if class == 1 { look::look(&self.world, m, (w, h), l, &win) } else { [0.0; 4] },
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests;

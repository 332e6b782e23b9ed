//! Door finding by sonar alone (001 §3.2), both ways the paper gives. The robot first locates
//! the wall (`door_locate.rs`) and turns parallel to it. Wall
//! following (`wall-follow`): it keeps an even distance from the wall (`wall.rs`), watching the
//! side sensor for the opening (`opening.rs`); when the wall is found again it "splits the
//! difference between the two detected wall ends, dead-reckons its position backwards, turns 90
//! degrees towards the wall and moves through the door". Motor schemas (`schemas`, Chapter 8's
//! system, `door_schemas.rs`): the wall's echoes repel, move-ahead presses the robot along and
//! into the wall, and where the opening lets it the press carries it into the doorway.

use harvey_geometry::wrap;
use harvey_msgs::{BehaviourState, Header, MotionCommand, Pose2, SonarRing};

use super::door_follow;
use super::door_locate::Look;
use super::door_schemas::{self, Slide};
use super::drive::{self, DriveParams};
use super::opening::Opening;
use super::schemas::V2;
use super::wall::{Line, Wall};
use crate::mission::{DoorGoal, DoorVariant};

/// The ring's sensor at the robot's left (90 degrees) and right (270 degrees), and straight ahead.
/// Located within 10 s of standing (five readings a sensor take 0.75 s), or the mission fails.
const LOCATE_WITHIN_NS: u64 = 10_000_000_000;
pub(crate) const LEFT: usize = 6;
pub(crate) const RIGHT: usize = 18;
const AHEAD: usize = 0;

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Phase {
    /// Standing, the ring read over and over since then, until the wall is located.
    Locating { since_ns: Option<u64> },
    /// Turning parallel to the wall.
    Aligning { to: f64 },
    /// Along the wall (the schemas' slide, too).
    Following,
    /// Back to halfway between the opening's ends, keeping the heading along the wall.
    Backing { to: [f64; 2], along: f64 },
    /// Turning to face the doorway.
    Facing { to: f64 },
    /// Through the doorway from `from` along `heading`, `length` of it (m).
    Through { from: [f64; 2], heading: f64, length: f64 },
}

/// The behaviour's state.
#[derive(Debug, Clone)]
pub struct DoorFinding {
    pub(crate) g: DoorGoal,
    pub(crate) drive: DriveParams,
    pub(crate) side: f64,
    pub(crate) ring_m: f64,
    pub(crate) phase: Phase,
    look: Look,
    pub(crate) wall: Wall,
    pub(crate) opening: Opening,
    pub(crate) ring: Option<SonarRing>,
    /// The side and front sensors' last readings used (their stamps); whether the first new
    /// reading ahead in the doorway is still to be checked.
    pub(crate) side_stamp: u64,
    ahead_stamp: u64,
    check_ahead: bool,
    /// The schemas' slide along the wall.
    pub(crate) slide: Slide,
    pub(crate) at: Pose2,
    pub(crate) travelled_m: f64,
    /// Door-sized openings passed, and the midpoint of the one taken.
    pub openings: u32,
    pub(crate) door: Option<[f64; 2]>,
    /// Where the robot means to end, once it turns into the doorway.
    goal: Option<[f64; 2]>,
    transitions: u32,
    next_id: u32,
    seq: u64,
    pub done: Option<bool>,
}

impl DoorFinding {
    /// `ring_m`: the sonar ring's radius (the robot's, too).
    pub fn new(g: DoorGoal, ring_m: f64, start: Pose2) -> Self {
        let drive = DriveParams::new(
            g.speed_mps,
            g.max_turn_degps,
            g.turn_gain,
            ring_m,
            (g.avoid_sphere_m, g.avoid_gain),
        );
        let side = g.side.sign();
        let line = Line::seen_from(
            [start.x_m, start.y_m],
            start.heading_rad + side * std::f64::consts::FRAC_PI_2,
            g.keep_m,
        );
        Self {
            wall: Wall::new(line, g.fit_m, (g.gate_m, g.jump_m / 2.0)),
            opening: Opening::new(g.jump_m, g.confirm),
            g,
            drive,
            side,
            ring_m,
            phase: Phase::Locating { since_ns: None },
            look: Look::default(),
            ring: None,
            side_stamp: 0,
            ahead_stamp: 0,
            check_ahead: false,
            slide: Slide::default(),
            at: start,
            travelled_m: 0.0,
            openings: 0,
            door: None,
            goal: None,
            transitions: 0,
            next_id: 1,
            seq: 0,
            done: None,
        }
    }

    pub fn on_sonar(&mut self, r: &SonarRing) {
        self.ring = Some(*r);
    }

    /// Where the robot means to end once it has turned into the doorway (past it, in the room),
    /// the doorway's middle once found, else where the robot is.
    pub fn goal_pose(&self) -> Pose2 {
        self.goal.or(self.door).map_or(self.at, |d| Pose2 {
            x_m: d[0],
            y_m: d[1],
            heading_rad: self.at.heading_rad,
        })
    }

    /// Sensor `i`'s reading as a distance from the robot's centre, if it is new since `stamp`
    /// (then `stamp` moves on); `Some(None)` for a new reading without an echo.
    pub(crate) fn fresh(&self, i: usize, stamp: &mut u64) -> Option<Option<f64>> {
        let r = self.ring.as_ref()?;
        if r.reading_stamp_ns[i] == 0 || r.reading_stamp_ns[i] == *stamp {
            return None;
        }
        *stamp = r.reading_stamp_ns[i];
        let valid = r.valid_mask & (1 << i) != 0 && r.range_m[i].is_finite();
        Some(valid.then(|| self.ring_m + f64::from(r.range_m[i])))
    }

    /// Into the doorway from `here` along `heading`, `length` of it; the first new reading
    /// ahead is checked against the wall (wall following's turn must face the opening).
    pub(crate) fn enter(&mut self, here: [f64; 2], heading: f64, length: f64) {
        self.goal = Some([here[0] + length * heading.cos(), here[1] + length * heading.sin()]);
        self.ahead_stamp = self.ring.map_or(0, |r| r.reading_stamp_ns[AHEAD]);
        self.check_ahead = self.g.variant == DoorVariant::WallFollow;
        self.go(Phase::Through { from: here, heading, length });
    }

    pub(crate) fn go(&mut self, p: Phase) {
        self.phase = p;
        self.transitions += 1;
    }

    /// Turns towards heading `to` on the spot: the command, and whether it is there.
    pub(crate) fn turn_to(&self, to: f64) -> ((f64, f64), bool) {
        let e = wrap(to - self.at.heading_rad);
        let w = (self.drive.turn_gain * e).clamp(-self.drive.max_turn_radps, self.drive.max_turn_radps);
        ((0.0, w), e.abs() <= self.g.aligned_deg.to_radians())
    }

    /// Drives at `v` holding heading `to`.
    pub(crate) fn hold(&self, v: f64, to: f64) -> (f64, f64) {
        let e = wrap(to - self.at.heading_rad);
        (
            v * e.cos().max(0.0),
            (self.drive.turn_gain * e).clamp(-self.drive.max_turn_radps, self.drive.max_turn_radps),
        )
    }

    /// One odometry tick: the velocity command and the state to publish.
    pub fn on_odometry(&mut self, at: Pose2, now: u64) -> (MotionCommand, BehaviourState) {
        self.travelled_m += (at.x_m - self.at.x_m).hypot(at.y_m - self.at.y_m);
        self.at = at;
        let here = [at.x_m, at.y_m];
        let mut parts = [V2::default(); 5];
        let vw = match self.phase {
            _ if self.done.is_some() => (0.0, 0.0),
            Phase::Locating { since_ns: None } => {
                self.phase = Phase::Locating { since_ns: Some(now) };
                (0.0, 0.0)
            }
            Phase::Locating { since_ns: Some(t) } if now > t + LOCATE_WITHIN_NS => {
                tracing::warn!(side = self.side, "no wall located beside the robot");
                self.done = Some(false);
                (0.0, 0.0)
            }
            Phase::Locating { since_ns: Some(t) } => {
                if let Some(r) = &self.ring {
                    self.look.take(r, t);
                }
                if let Some(line) = self.look.wall(at, self.side, self.ring_m, self.g.gate_m) {
                    self.wall.set(line);
                    self.go(Phase::Aligning { to: line.along(self.side) });
                }
                (0.0, 0.0)
            }
            Phase::Aligning { to } => {
                let (vw, there) = self.turn_to(to);
                if there {
                    self.go(Phase::Following);
                }
                vw
            }
            Phase::Following => match self.g.variant {
                DoorVariant::WallFollow => door_follow::follow(self, here),
                DoorVariant::Schemas => door_schemas::slide(self, &mut parts),
            },
            Phase::Backing { to, along } => {
                let (u, p) = ([along.cos(), along.sin()], [here[0] - to[0], here[1] - to[1]]);
                if u[0] * p[0] + u[1] * p[1] <= 0.0 {
                    self.go(Phase::Facing { to: wrap(along + self.side * std::f64::consts::FRAC_PI_2) });
                    (0.0, 0.0)
                } else {
                    let (_, w) = self.hold(self.g.back_mps, along);
                    (-self.g.back_mps, w)
                }
            }
            Phase::Facing { to } => {
                let (vw, there) = self.turn_to(to);
                if there {
                    let length = self.wall.line.distance(here) + self.g.through_m;
                    self.enter(here, to, length);
                }
                vw
            }
            Phase::Through { from, heading, length } => self.through(here, from, heading, length, &mut parts),
        };
        let vw = drive::held(self.ring.as_ref(), vw);
        let id = self.next_id;
        self.next_id += 1;
        self.seq += 1;
        let state = BehaviourState {
            header: Header::new(self.seq, now),
            at,
            fsa_state: phase_index(self.phase),
            transitions: self.transitions,
            last_trigger: 0,
            achieved: self.openings,
            vectors_mps: drive::vectors(parts, &self.drive).flat(),
            linear_mps: vw.0,
            angular_radps: vw.1,
        };
        (drive::command(id, now, vw), state)
    }

    /// Through the doorway, holding the heading (the schemas: pressed on, the jambs repelling),
    /// until `length` past `from`. The first new reading ahead must see past the wall.
    fn through(
        &mut self,
        here: [f64; 2],
        from: [f64; 2],
        heading: f64,
        length: f64,
        parts: &mut [V2; 5],
    ) -> (f64, f64) {
        let mut stamp = self.ahead_stamp;
        if self.check_ahead
            && let Some(d) = self.fresh(AHEAD, &mut stamp)
        {
            (self.ahead_stamp, self.check_ahead) = (stamp, false);
            let wall = self.wall.line.distance(here);
            if let Some(d) = d
                && d < wall + self.g.gate_m
            {
                tracing::warn!(ahead_m = d, wall_m = wall, "no opening ahead: the wall is there");
                self.done = Some(false);
                return (0.0, 0.0);
            }
        }
        let gone = (here[0] - from[0]) * heading.cos() + (here[1] - from[1]) * heading.sin();
        if gone >= length {
            self.done = Some(true);
            return (0.0, 0.0);
        }
        match self.g.variant {
            DoorVariant::WallFollow => self.hold(self.g.speed_mps, heading),
            DoorVariant::Schemas => door_schemas::press(self, heading, parts),
        }
    }
}

fn phase_index(p: Phase) -> u32 {
    use Phase::*;
    match p {
        Locating { .. } => 0,
        Aligning { .. } => 1,
        Following => 2,
        Backing { .. } => 3,
        Facing { .. } => 4,
        Through { .. } => 5,
    }
}

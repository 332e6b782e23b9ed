//! Path following (001 §2.1): a standing path request to the vision workers per segment of the
//! path (its edges predicted from the map and the UMS's pose, then fed forward by the workers'
//! tracker), each fit taken to the ground and the robot steered for the centreline a look-ahead
//! distance ahead; at the end of a segment it turns on the spot onto the next, and it stops a set
//! distance before the last one's end. The position along the path comes from the UMS.

use std::collections::VecDeque;

use harvey_geometry::wrap;
use harvey_msgs::{
    BehaviourState, Header, MotionCommand, Pose2, UncertaintyMap, VisionAlgorithm, VisionRequest,
    VisionResult, VisionStatus,
};

use harvey_world::{LandmarkClass, World};

use super::drive;
use super::path_view::{Seen, Segment, View};
use crate::mission::PathGoal;

/// The path request's id (one standing request, replaced at each segment and when the tracker
/// starts afresh).
const REQUEST_ID: u32 = 2;
/// Odometry poses kept to place a fit where the robot was when its frame was taken (ns).
const HISTORY_NS: u64 = 3_000_000_000;
/// The fewest rows the window keeps above its bottom one near a bend.
const MIN_ROWS: f64 = 16.0;
/// Fits in a row whose width disagrees with the map before the tracker starts afresh.
const MISFITS: u32 = 3;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Along segment `k`.
    Following,
    /// Turning on the spot to odometry heading `to` onto the next segment.
    Turning { to: f64 },
}

/// The behaviour's state.
#[derive(Debug, Clone)]
pub struct PathFollow {
    g: PathGoal,
    view: View,
    /// The window's top and bottom rows.
    rows: (f64, f64),
    segments: Vec<Segment>,
    k: usize,
    phase: Phase,
    odometry: Pose2,
    history: VecDeque<(u64, Pose2)>,
    /// The UMS's newest pose and the odometry of its stamp.
    map: Option<(Pose2, Pose2)>,
    /// Where to steer for (odometry frame) and the travel when a fit last gave it.
    target: Option<[f64; 2]>,
    travelled_m: f64,
    fitted_at_m: f64,
    /// A request to send with the next command, and the segment's standing one.
    request: Option<VisionRequest>,
    standing: Option<VisionRequest>,
    /// Near a bend, where the window would reach past it: fits are not steered by.
    blind: bool,
    /// Fits in a row too wide or narrow, and the tracker's restarts (the request's last
    /// parameter: a new value starts the worker's tracker afresh).
    misfits: u32,
    generation: u32,
    /// The travel when the tracker was last started afresh (fits lacking, or misfits).
    restarted_at_m: f64,
    /// Fits steered by, and the last one taken to the ground.
    pub fits: u32,
    pub last: Option<Seen>,
    transitions: u32,
    seq: u64,
    next_id: u32,
    pub done: Option<bool>,
}

impl PathFollow {
    /// `segments`: the path's, from the map; `image`: the frame's width and height (px).
    pub fn new(g: PathGoal, view: View, image: (f64, f64), segments: Vec<Segment>, start: Pose2) -> Self {
        let rows = (view.cy + g.below_horizon_px, image.1 - 1.0);
        let mut p = Self {
            g,
            view,
            rows,
            segments,
            k: 0,
            phase: Phase::Following,
            odometry: start,
            history: VecDeque::new(),
            map: None,
            target: None,
            travelled_m: 0.0,
            fitted_at_m: 0.0,
            request: None,
            standing: None,
            blind: false,
            misfits: 0,
            generation: 0,
            restarted_at_m: 0.0,
            fits: 0,
            last: None,
            transitions: 0,
            seq: 0,
            next_id: 1,
            done: None,
        };
        p.request = p.bootstrap(start, 0);
        p.standing = p.request;
        p
    }

    /// The UMS's newest map: its centre is the robot's pose where the odometry was at its stamp.
    pub fn on_map(&mut self, m: &UncertaintyMap) {
        let stamp = m.header.stamp_ns;
        if let Some(&(_, o)) = self.history.iter().rev().find(|(t, _)| *t <= stamp) {
            self.map = Some((m.centre, o));
        }
    }

    /// Where the robot is believed to be: the UMS's pose moved on by the odometry since.
    pub fn believed(&self) -> Pose2 {
        self.map.map_or(self.odometry, |(c, o)| c.compose(&o.relative(&self.odometry)))
    }

    /// Where the robot means to stop: on the last segment's centreline, `stop_before_end_m` short
    /// of its end.
    pub fn goal_pose(&self) -> Pose2 {
        let Some(s) = self.segments.last() else { return self.odometry };
        let (sn, cs) = s.heading().sin_cos();
        let back = self.g.stop_before_end_m;
        Pose2 { x_m: s.to[0] - back * cs, y_m: s.to[1] - back * sn, heading_rad: s.heading() }
    }

    /// The standing request for segment `k`, its edges predicted from `at`.
    fn bootstrap(&self, at: Pose2, stamp_ns: u64) -> Option<VisionRequest> {
        let s = self.segments.get(k_or(self.k, self.segments.len()))?;
        let (top, bottom) = self.rows;
        let e = self.view.predict(s, at, top, bottom)?;
        let g = &self.g;
        Some(VisionRequest {
            header: Header::new(u64::from(REQUEST_ID), stamp_ns),
            request_id: REQUEST_ID,
            algorithm: VisionAlgorithm::Path as u32,
            standing: 1,
            // The rows the edges are predicted at; the window's top may come down under them.
            expected: Pose2 { x_m: top, y_m: bottom, heading_rad: 0.0 },
            window_px: [0.0, top as f32, (2.0 * self.view.cx) as f32, (bottom + 1.0) as f32],
            params: [
                e[0] as f32,
                e[1] as f32,
                e[2] as f32,
                e[3] as f32,
                g.max_distance_px as f32,
                g.max_angle_deg as f32,
                g.min_confidence_px as f32,
                self.generation as f32,
            ],
            ..VisionRequest::default()
        })
    }

    /// A path fit: taken to the ground, checked against the map's width, and made the point to
    /// steer for (where the robot was when its frame was taken, carried on by the odometry).
    pub fn on_vision(&mut self, r: &VisionResult) {
        if r.request_id != REQUEST_ID || r.status != VisionStatus::Found as u32 || r.count < 3 {
            return;
        }
        if self.phase != Phase::Following || self.blind {
            return;
        }
        let Some(&(_, then)) = self.history.iter().rev().find(|(t, _)| *t <= r.header.stamp_ns) else {
            return;
        };
        let Some(s) = self.segments.get(self.k) else { return };
        let item = |i: usize| r.items[i].values;
        let Some(seen) = self.view.seen(item(0), item(1), item(2)) else { return };
        if (seen.width_m / s.width_m - 1.0).abs() > self.g.width_tolerance {
            // The tracker holds something else (a tile's joint beside an edge): after a few such
            // fits in a row it starts afresh from the map.
            self.misfits += 1;
            if self.misfits >= MISFITS {
                self.misfits = 0;
                self.restart(r.header.stamp_ns);
            }
            return;
        }
        self.misfits = 0;
        // The centreline's point `lookahead_m` ahead of the robot's foot on it.
        let (sh, ch) = seen.heading_rad.sin_cos();
        let foot = [seen.offset_m * sh, -seen.offset_m * ch];
        let ahead = [foot[0] + self.g.lookahead_m * ch, foot[1] + self.g.lookahead_m * sh];
        self.target = Some(then.apply(ahead));
        self.fitted_at_m = self.travelled_m;
        (self.fits, self.last) = (self.fits + 1, Some(seen));
    }

    /// One odometry tick: the request to send, the velocity command and the state to publish.
    pub fn on_odometry(
        &mut self,
        at: Pose2,
        now: u64,
    ) -> (Option<VisionRequest>, MotionCommand, BehaviourState) {
        self.travelled_m += at.distance(&self.odometry);
        self.odometry = at;
        self.history.push_back((now, at));
        while self.history.front().is_some_and(|(t, _)| now.saturating_sub(*t) > HISTORY_NS) {
            self.history.pop_front();
        }
        let vw = if self.done.is_some() { (0.0, 0.0) } else { self.step(now) };
        self.seq += 1;
        let id = self.next_id;
        self.next_id += 1;
        let state = BehaviourState {
            header: Header::new(self.seq, now),
            at: self.believed(),
            fsa_state: self.k as u32 * 2 + u32::from(matches!(self.phase, Phase::Turning { .. })),
            transitions: self.transitions,
            last_trigger: 0,
            achieved: self.fits,
            vectors_mps: [0.0; 12],
            linear_mps: vw.0,
            angular_radps: vw.1,
        };
        (self.request.take(), drive::command(id, now, vw), state)
    }

    fn step(&mut self, now: u64) -> (f64, f64) {
        let believed = self.believed();
        let Some(s) = self.segments.get(self.k).copied() else {
            self.done = Some(true);
            return (0.0, 0.0);
        };
        let max_w = self.g.max_turn_degps.to_radians();
        match self.phase {
            Phase::Turning { to } => {
                let e = wrap(to - self.odometry.heading_rad);
                if e.abs() <= self.g.aligned_deg.to_radians() {
                    self.phase = Phase::Following;
                    self.transitions += 1;
                    (self.fitted_at_m, self.target, self.blind) = (self.travelled_m, None, false);
                    self.misfits = 0;
                    self.request = self.bootstrap(believed, now);
                    self.standing = self.request;
                    return (0.0, 0.0);
                }
                (0.0, (self.g.turn_gain * e).clamp(-max_w, max_w))
            }
            Phase::Following => {
                let (along, _) = s.local([believed.x_m, believed.y_m]);
                let last = self.k + 1 == self.segments.len();
                if last && along >= s.length_m() - self.g.stop_before_end_m {
                    self.done = Some(true);
                    return (0.0, 0.0);
                }
                if !last && along >= s.length_m() {
                    self.k += 1;
                    let to = self.odometry.heading_rad
                        + wrap(self.segments[self.k].heading() - believed.heading_rad);
                    self.phase = Phase::Turning { to };
                    self.transitions += 1;
                    return (0.0, 0.0);
                }
                if !last {
                    self.window_short_of_bend(s.length_m() - along, now);
                }
                if !self.blind && self.travelled_m - self.fitted_at_m > self.g.lost_after_m {
                    tracing::warn!(segment = self.k, travelled_m = self.travelled_m, "the path is lost");
                    self.done = Some(false);
                    return (0.0, 0.0);
                }
                // The tracker may hold a model the frames no longer fit (a wrong fit fed forward):
                // without fits for a while it starts afresh from the map.
                let unfitted = self.travelled_m - self.fitted_at_m.max(self.restarted_at_m);
                if !self.blind && unfitted > self.g.restart_after_m {
                    tracing::info!(
                        segment = self.k,
                        travelled_m = self.travelled_m,
                        "no path fit: tracking afresh"
                    );
                    self.restart(now);
                }
                // Steer for the fit's point while it is ahead; else (before a segment's first fit,
                // or fits lacking) for the map's, from where the UMS has the robot.
                let from_fit = self.target.map(|t| self.odometry.inverse().apply(t));
                let local = from_fit.filter(|l| l[0] > self.g.lookahead_m / 2.0).unwrap_or_else(|| {
                    let (sn, cs) = s.heading().sin_cos();
                    let d = along + self.g.lookahead_m;
                    believed.inverse().apply([s.from[0] + d * cs, s.from[1] + d * sn])
                });
                let bearing = local[1].atan2(local[0]);
                let w = (self.g.turn_gain * bearing).clamp(-max_w, max_w);
                (self.g.speed_mps * bearing.cos().max(0.0), w)
            }
        }
    }
}

impl PathFollow {
    /// Starts the workers' tracker afresh (a new generation of the standing request) from the
    /// map's edges where the robot is believed to be.
    /// The window keeps its top where `window_short_of_bend` has brought it (the next segment's
    /// edges kept out of the fresh tracker's first frames).
    fn restart(&mut self, now: u64) {
        self.generation += 1;
        self.restarted_at_m = self.travelled_m;
        let top = self.standing.map(|r| r.window_px[1]);
        let at = self.believed();
        self.request = self.bootstrap(at, now).map(|mut r| {
            r.window_px[1] = top.map_or(r.window_px[1], |t| t.max(r.window_px[1]));
            r
        });
        self.standing = self.request;
    }

    /// Keeps the window's top row nearer than the bend `remaining_m` ahead (less the margin),
    /// so that the next segment's edges do not enter it; blind once that leaves less than
    /// `least_depth_m` of the path in view. The tracker goes on from frame to frame: only the
    /// window changes.
    fn window_short_of_bend(&mut self, remaining_m: f64, now: u64) {
        let depth = remaining_m - self.g.bend_margin_m;
        self.blind = depth < self.g.least_depth_m;
        let Some(mut r) = self.standing else { return };
        let v = &self.view;
        // At least a few rows above the bottom one, whatever the settings.
        let lowest = self.rows.1 - MIN_ROWS;
        let top =
            (v.cy + v.focal_px * v.height_m / depth.max(1e-3)).clamp(self.rows.0, lowest).floor() as f32;
        if !self.blind && top > r.window_px[1] {
            (r.window_px[1], r.header.stamp_ns) = (top, now);
            (self.request, self.standing) = (Some(r), Some(r));
        }
    }
}

/// Path following in world `w`: its camera, and the segments between the edges `g` names (each a
/// class III landmark); `Err` names a landmark that is not one.
pub fn in_world(g: &PathGoal, w: &World) -> Result<PathFollow, String> {
    let c = &w.camera;
    let (width, height) = (f64::from(c.width_px), f64::from(c.height_px));
    let view =
        View { focal_px: c.focal_for(c.width_px), cx: width / 2.0, cy: height / 2.0, height_m: c.height_m };
    let edge = |name: &String| {
        w.landmark(name)
            .filter(|l| l.class == LandmarkClass::III)
            .and_then(|l| l.to_m.map(|to| [[l.position_m[0], l.position_m[1]], [to[0], to[1]]]))
            .ok_or_else(|| format!("{name} (a class III line)"))
    };
    let segments = g
        .segments
        .iter()
        .map(|[l, r]| {
            let s = Segment::between(edge(l)?, edge(r)?);
            let real = s.width_m > 0.0 && s.length_m() > 0.0;
            real.then_some(s).ok_or_else(|| format!("{l} and {r} (edges a path lies between)"))
        })
        .collect::<Result<_, String>>()?;
    Ok(PathFollow::new(g.clone(), view, (width, height), segments, w.start))
}

/// `k`, or the last index when past the end.
fn k_or(k: usize, n: usize) -> usize {
    k.min(n.saturating_sub(1))
}

#[cfg(test)]
#[path = "path_follow_tests.rs"]
mod tests;

//! Plan-and-monitor (000 §2, §4): develops a `(ptrans here goal)` into a plan sketch over the
//! locale graph (`sketch.rs`) and executes its primitive subgoals one by one: TURN to face the
//! milestone, fix the pose from landmarks (plan-level servoing, 000 §5.6: the subgoal starts from
//! where the robot is, not where it should be), MOVE, fix again and check the milestone. A check
//! returns success, or failure with the last known location: a small miss is retried from there
//! (plan level), a large one or a repeated one re-develops the plan from there (goal level).

use harvey_geometry::wrap;
use harvey_msgs::{CheckOutcome, Header, PlanSketch, PlanStage, Pose2, SKETCH_PLACES};
use harvey_world::World;

use super::sketch::{Place, PlanError, Ptrans, refine_leading};
use crate::mission::{PtransGoal, Step};

/// Turns and moves smaller than these are not worth commanding (the DRV's units are 0.1° and
/// 0.01 ft).
const NEGLIGIBLE_TURN_RAD: f64 = 0.2 * std::f64::consts::PI / 180.0;
const NEGLIGIBLE_MOVE_M: f64 = 0.003;
/// A near target to one side is approached from this many `back_off_m` behind it.
const BACK_OFF_FACTOR: f64 = 1.5;
/// A fixed check this many of the fix's standard deviations from its milestone is as near as
/// the fix can tell (two: about 95 % of fixes of a robot at the milestone).
const FIX_SIGMAS: f64 = 2.0;

/// How a milestone check came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    Reached,
    /// Missed by a little: the subgoal is retried from the last known location.
    Retried,
    /// Missed by a lot, or too often: the plan is developed afresh from there.
    Replanned,
}

/// One milestone check: the milestone, where the robot was believed to be, and whether that
/// belief came from a pose fix at the milestone (rather than dead reckoning alone).
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    pub milestone: String,
    pub target: [f64; 2],
    pub believed: Pose2,
    pub off_m: f64,
    pub fixed: bool,
    pub outcome: Outcome,
}

/// What to do next.
#[derive(Debug, Clone, PartialEq)]
pub enum Next {
    Steps(Vec<Step>),
    /// The goal is reached, facing the goal heading.
    Arrived,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Stage {
    Develop,
    Aim,
    Go,
    Arrive {
        fixes: u32,
    },
    Check {
        fixes: u32,
    },
    /// The goal is reached: take its heading.
    Settle,
    Finish,
}

/// The plan under way.
#[derive(Debug, Clone)]
pub struct Monitor {
    goal: PtransGoal,
    world: World,
    /// The sketch: its first subgoal is under way, the front primitive, the back abstract.
    pub sketch: Vec<Ptrans>,
    stage: Stage,
    attempts: u32,
    pub replans: u32,
    pub checks: Vec<Check>,
    /// The UMS reported the robot lost: relocate (a pose fix) and develop the plan afresh at
    /// the next step boundary; how often that happened.
    relocate: bool,
    pub relocations: u32,
    /// The last pose fix's position standard deviation (m).
    fix_sd_m: f64,
}

fn turn(rad: f64) -> Step {
    Step { turn_deg: Some(rad.to_degrees()), ..Step::default() }
}

fn go(m: f64) -> Step {
    Step { move_m: Some(m), ..Step::default() }
}

fn fix() -> Step {
    Step { refine_pose: true, ..Step::default() }
}

/// Distance to `p` and its bearing from the heading.
fn toward(at: Pose2, p: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (p[0] - at.x_m, p[1] - at.y_m);
    (dx.hypot(dy), wrap(dy.atan2(dx) - at.heading_rad))
}

impl Monitor {
    pub fn new(goal: PtransGoal, world: World) -> Self {
        Self {
            goal,
            world,
            sketch: Vec::new(),
            stage: Stage::Develop,
            attempts: 0,
            replans: 0,
            checks: Vec::new(),
            relocate: false,
            relocations: 0,
            fix_sd_m: 0.0,
        }
    }

    /// The goal place, with its heading.
    pub fn goal_pose(&self) -> Pose2 {
        let [x_m, y_m] = self.goal.goal_m;
        Pose2 { x_m, y_m, heading_rad: self.goal.goal_heading_deg.to_radians() }
    }

    fn place(&self, name: &str, at: [f64; 2], fallback: &str) -> Place {
        let locale = self.world.locale_at(at[0], at[1]).map_or(fallback, |l| l.name.as_str());
        Place { name: name.to_owned(), at, locale: locale.to_owned() }
    }

    /// `(ptrans here approach) (ptrans approach goal)`, the front refined to a primitive.
    fn develop(&mut self, at: Pose2) -> Result<(), PlanError> {
        let g = self.goal_pose();
        let back = self.goal.approach_m;
        let approach = [g.x_m - back * g.heading_rad.cos(), g.y_m - back * g.heading_rad.sin()];
        let to = self.goal.to.clone();
        let goal = Place { name: "goal".into(), at: self.goal.goal_m, locale: to.clone() };
        let approach = Place { name: "approach".into(), at: approach, locale: to.clone() };
        let here = self.place("here", [at.x_m, at.y_m], &to);
        let near = here.locale == to && toward(at, goal.at).0 < 2.0 * back;
        self.sketch = if near {
            // Already by the goal: straight there (the near-target rules aim without far turns).
            vec![Ptrans { from: here, to: goal, primitive: true }]
        } else {
            vec![
                Ptrans { from: here, to: approach.clone(), primitive: false },
                Ptrans { from: approach, to: goal, primitive: true },
            ]
        };
        refine_leading(&self.world, &mut self.sketch, self.goal.door_depth_m)
    }

    /// The UMS says the robot is lost (002 §3.1: its map grew too large, or predicted
    /// landmarks went missing): goal-level servoing relocates and re-develops the plan.
    pub fn lost(&mut self) {
        if !matches!(self.stage, Stage::Settle | Stage::Finish) && !self.relocate {
            tracing::warn!("the UMS reports the robot lost: relocating");
            self.relocate = true;
        }
    }

    /// The last pose fix placed the robot to `sd_m` (its standard deviation, map error in).
    pub fn last_fix_sd(&mut self, sd_m: f64) {
        self.fix_sd_m = sd_m;
    }

    /// What to do once the steps given last are done, from the believed pose `at`; `fixes` counts
    /// the pose fixes so far.
    pub fn next(&mut self, at: Pose2, fixes: u32) -> Result<Next, PlanError> {
        if std::mem::take(&mut self.relocate) {
            self.relocations += 1;
            self.sketch.clear();
            self.stage = Stage::Develop;
            return Ok(Next::Steps(vec![fix()]));
        }
        loop {
            let done = matches!(self.stage, Stage::Settle | Stage::Finish);
            if matches!(self.stage, Stage::Develop) || (self.sketch.is_empty() && !done) {
                self.develop(at)?;
                self.stage = Stage::Aim;
            }
            let Some(sub) = self.sketch.first().cloned() else {
                // Settling or finished (any other stage has just developed a sketch).
                if matches!(self.stage, Stage::Finish) {
                    return Ok(Next::Arrived);
                }
                self.stage = Stage::Finish;
                let last = wrap(self.goal_pose().heading_rad - at.heading_rad);
                if last.abs() > NEGLIGIBLE_TURN_RAD {
                    return Ok(Next::Steps(vec![turn(last)]));
                }
                continue;
            };
            let (d, bearing) = toward(at, sub.to.at);
            match self.stage {
                Stage::Aim if d < self.goal.back_off_m => {
                    // Near: aiming would turn far for little (turns skitter, 002 §3.2). Nearly
                    // dead ahead or behind, just move; else back off along the heading and aim
                    // from there, with a small turn.
                    let (ahead, left) = (d * bearing.cos(), d * bearing.sin());
                    if left.abs() <= self.tolerance() / 2.0 {
                        self.stage = Stage::Arrive { fixes };
                        if ahead.abs() > NEGLIGIBLE_MOVE_M {
                            return Ok(Next::Steps(vec![go(ahead)]));
                        }
                    } else {
                        return Ok(Next::Steps(vec![go(ahead - BACK_OFF_FACTOR * self.goal.back_off_m)]));
                    }
                }
                Stage::Aim => {
                    self.stage = Stage::Go;
                    let mut steps = Vec::new();
                    if bearing.abs() > NEGLIGIBLE_TURN_RAD {
                        steps.push(turn(bearing));
                    }
                    steps.push(fix());
                    return Ok(Next::Steps(steps));
                }
                Stage::Go => {
                    self.stage = Stage::Arrive { fixes };
                    let mut steps = Vec::new();
                    if bearing.abs() > NEGLIGIBLE_TURN_RAD {
                        steps.push(turn(bearing));
                    }
                    if d > NEGLIGIBLE_MOVE_M {
                        steps.push(go(d));
                    }
                    if !steps.is_empty() {
                        return Ok(Next::Steps(steps));
                    }
                }
                Stage::Arrive { .. } => {
                    self.stage = Stage::Check { fixes };
                    return Ok(Next::Steps(vec![fix()]));
                }
                Stage::Check { fixes: before } => self.check(&sub, at, d, fixes > before)?,
                // Develop was handled above, and Settle and Finish come with an empty sketch; a
                // sketch given back later is aimed at.
                Stage::Develop | Stage::Settle | Stage::Finish => self.stage = Stage::Aim,
            }
        }
    }

    /// The sketch and the latest check, to publish (places past `SKETCH_PLACES` are left out).
    pub fn sketch_msg(&self, seq: u64, stamp_ns: u64) -> PlanSketch {
        let mut m = PlanSketch { header: Header::new(seq, stamp_ns), ..PlanSketch::default() };
        let places =
            self.sketch.first().map(|p| &p.from).into_iter().chain(self.sketch.iter().map(|p| &p.to));
        for (k, place) in places.take(SKETCH_PLACES).enumerate() {
            (m.places_m[2 * k], m.places_m[2 * k + 1]) = (place.at[0], place.at[1]);
            m.place_count += 1;
        }
        for (k, p) in self.sketch.iter().enumerate().take(SKETCH_PLACES - 1) {
            m.primitive_mask |= u32::from(p.primitive) << k;
        }
        m.stage = match self.stage {
            Stage::Develop => PlanStage::Developing,
            Stage::Aim => PlanStage::Aiming,
            Stage::Go => PlanStage::Moving,
            Stage::Arrive { .. } => PlanStage::Arriving,
            Stage::Check { .. } => PlanStage::Checking,
            Stage::Settle => PlanStage::Settling,
            Stage::Finish => PlanStage::Arrived,
        } as u32;
        m.checks = self.checks.len() as u32;
        m.replans = self.replans;
        if let Some(c) = self.checks.last() {
            m.last_outcome = match c.outcome {
                Outcome::Reached => CheckOutcome::Reached,
                Outcome::Retried => CheckOutcome::Retried,
                Outcome::Replanned => CheckOutcome::Replanned,
            } as u32;
            m.last_off_m = c.off_m;
        }
        m
    }

    /// How near the current subgoal's milestone counts as there.
    fn tolerance(&self) -> f64 {
        if self.sketch.len() == 1 { self.goal.goal_tolerance_m } else { self.goal.milestone_m }
    }

    /// The milestone check at the end of subgoal `sub`.
    fn check(&mut self, sub: &Ptrans, at: Pose2, off_m: f64, fixed: bool) -> Result<(), PlanError> {
        let tolerance = self.tolerance();
        // A fix cannot tell the robot from a place nearer than it can see: another move would
        // chase the fix's own error (000 §5: servoing is as good as its pose fixes).
        let told = fixed && off_m <= FIX_SIGMAS * self.fix_sd_m;
        let outcome = if off_m <= tolerance || told {
            Outcome::Reached
        } else if off_m < self.goal.escalate_m && self.attempts + 1 < self.goal.attempts {
            Outcome::Retried
        } else {
            Outcome::Replanned
        };
        tracing::info!(milestone = %sub.to.name, off_m, fixed, fix_sd_m = self.fix_sd_m, ?outcome, "milestone check");
        let at_xy = [at.x_m, at.y_m];
        self.checks.push(Check {
            milestone: sub.to.name.clone(),
            target: sub.to.at,
            believed: at,
            off_m,
            fixed,
            outcome,
        });
        match outcome {
            Outcome::Reached => {
                self.attempts = 0;
                self.sketch.remove(0);
                if let Some(next) = self.sketch.first_mut() {
                    // The next subgoal starts where the robot is.
                    next.from.at = at_xy;
                    refine_leading(&self.world, &mut self.sketch, self.goal.door_depth_m)?;
                    self.stage = Stage::Aim;
                } else {
                    self.stage = Stage::Settle;
                }
            }
            Outcome::Retried => {
                self.attempts += 1;
                self.stage = Stage::Aim;
            }
            Outcome::Replanned => {
                self.attempts = 0;
                self.replans += 1;
                self.stage = Stage::Develop;
                self.sketch.clear();
                if self.replans > self.goal.attempts {
                    return Err(PlanError::GaveUp(sub.to.name.clone(), at_xy));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;

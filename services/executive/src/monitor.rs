//! Plan-and-monitor (000 §2, §4): develops a `(ptrans here goal)` into a plan sketch over the
//! locale graph (`plan.rs`) and executes its primitive subgoals one by one: TURN to face the
//! milestone, fix the pose from landmarks (plan-level servoing, 000 §5.6: the subgoal starts from
//! where the robot is, not where it should be), MOVE, fix again and check the milestone. A check
//! returns success, or failure with the last known location: a small miss is retried from there
//! (plan level), a large one or a repeated one re-develops the plan from there (goal level).

use harvey_msgs::{CheckOutcome, Header, PlanSketch, PlanStage, Pose2, SKETCH_PLACES};
use harvey_world::World;

use crate::mission::{PtransGoal, Step};
use crate::plan::{Place, PlanError, Ptrans, refine_leading};
use crate::recover::wrap;

/// Turns and moves smaller than these are not worth commanding (the DRV's units are 0.1° and
/// 0.01 ft).
const NEGLIGIBLE_TURN_RAD: f64 = 0.2 * std::f64::consts::PI / 180.0;
const NEGLIGIBLE_MOVE_M: f64 = 0.003;
/// A near target to one side is approached from this many `back_off_m` behind it.
const BACK_OFF_FACTOR: f64 = 1.5;

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
            let Some(sub) = self.sketch.first().cloned() else {
                match self.stage {
                    Stage::Settle => {
                        self.stage = Stage::Finish;
                        let last = wrap(self.goal_pose().heading_rad - at.heading_rad);
                        if last.abs() > NEGLIGIBLE_TURN_RAD {
                            return Ok(Next::Steps(vec![turn(last)]));
                        }
                    }
                    Stage::Finish => return Ok(Next::Arrived),
                    _ => {
                        self.develop(at)?;
                        self.stage = Stage::Aim;
                    }
                }
                continue;
            };
            let (d, bearing) = toward(at, sub.to.at);
            match self.stage {
                Stage::Develop => {
                    self.develop(at)?;
                    self.stage = Stage::Aim;
                }
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
                // Only with an empty sketch (above); a sketch given back later is aimed at.
                Stage::Settle | Stage::Finish => self.stage = Stage::Aim,
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
        let outcome = if off_m <= tolerance {
            Outcome::Reached
        } else if off_m < self.goal.escalate_m && self.attempts + 1 < self.goal.attempts {
            Outcome::Retried
        } else {
            Outcome::Replanned
        };
        tracing::info!(milestone = %sub.to.name, off_m, fixed, ?outcome, "milestone check");
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
mod tests {
    use super::*;

    fn goal() -> PtransGoal {
        PtransGoal {
            to: "teds-office".into(),
            goal_m: [12.0, 2.5],
            goal_heading_deg: 60.0,
            approach_m: 0.4,
            door_depth_m: 1.0,
            milestone_m: 0.15,
            goal_tolerance_m: 0.0127,
            escalate_m: 0.5,
            attempts: 3,
            back_off_m: 0.3,
        }
    }

    fn hallway() -> World {
        harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("world")
    }

    /// Runs the plan on a robot that falls `loss` short of every move while odometry says it
    /// went the whole way; every pose fix tells the truth. `kick` moves the robot unbeknown to
    /// it once, after the check of milestone `kick.0`.
    fn run(start: Pose2, loss: f64, kick: Option<(&str, [f64; 2])>) -> (Monitor, Pose2) {
        let mut m = Monitor::new(goal(), hallway());
        let (mut truth, mut belief, mut fixes) = (start, start, 0);
        let mut kicked = false;
        for _ in 0..200 {
            if let Some((after, [dx, dy])) = kick
                && !kicked
                && m.checks.iter().any(|c| c.milestone == after)
            {
                (truth.x_m, truth.y_m, kicked) = (truth.x_m + dx, truth.y_m + dy, true);
            }
            match m.next(belief, fixes).expect("plans") {
                Next::Arrived => return (m, truth),
                Next::Steps(steps) => {
                    for s in steps {
                        if let Some(deg) = s.turn_deg {
                            truth.heading_rad += deg.to_radians();
                            belief.heading_rad += deg.to_radians();
                        }
                        if let Some(d) = s.move_m {
                            let (c, sn) = (truth.heading_rad.cos(), truth.heading_rad.sin());
                            (truth.x_m, truth.y_m) =
                                (truth.x_m + d * (1.0 - loss) * c, truth.y_m + d * (1.0 - loss) * sn);
                            let (c, sn) = (belief.heading_rad.cos(), belief.heading_rad.sin());
                            (belief.x_m, belief.y_m) = (belief.x_m + d * c, belief.y_m + d * sn);
                        }
                        if s.refine_pose {
                            (belief, fixes) = (truth, fixes + 1);
                        }
                    }
                }
            }
        }
        panic!("never arrived: {:?}", m.checks);
    }

    const BENCH: Pose2 = Pose2 { x_m: 5.0, y_m: 4.0, heading_rad: -std::f64::consts::FRAC_PI_2 };

    #[test]
    fn the_plan_goes_through_both_doors_and_retries_a_short_leg() {
        let (m, end) = run(BENCH, 0.042, None);
        let reached: Vec<&str> =
            m.checks.iter().filter(|c| c.outcome == Outcome::Reached).map(|c| c.milestone.as_str()).collect();
        assert_eq!(
            reached,
            [
                "robot-lab-side-of-door-0",
                "hallway-side-of-door-0",
                "hallway-side-of-door-1",
                "teds-office-side-of-door-1",
                "approach",
                "goal"
            ]
        );
        // 4.2 % short of 7 m down the hall is 0.29 m: missed, retried from there.
        let miss = m.checks.iter().find(|c| c.outcome == Outcome::Retried).expect("a retry");
        assert_eq!(miss.milestone, "hallway-side-of-door-1");
        assert!((miss.off_m - 0.042 * 7.0).abs() < 0.02, "{miss:?}");
        assert_eq!(m.replans, 0);
        assert!((end.x_m - 12.0).hypot(end.y_m - 2.5) <= 0.0127, "{end:?}");
        assert!((wrap(end.heading_rad) - 60f64.to_radians()).abs() < 0.01, "{end:?}");
    }

    #[test]
    fn a_milestone_missed_by_far_develops_the_plan_afresh_from_there() {
        // Carried 1.2 m back up the hall after leaving the lab: the office door's milestone is
        // missed by far, and the plan is developed again from where the robot is.
        let (m, end) = run(BENCH, 0.0, Some(("hallway-side-of-door-0", [-1.2, 0.0])));
        let miss = m.checks.iter().find(|c| c.outcome == Outcome::Replanned).expect("a replan");
        assert_eq!(miss.milestone, "hallway-side-of-door-1");
        assert!((miss.off_m - 1.2).abs() < 1e-6, "{miss:?}");
        assert_eq!(m.replans, 1);
        assert!((end.x_m - 12.0).hypot(end.y_m - 2.5) <= 0.0127, "{end:?}");
    }

    #[test]
    fn when_the_ums_reports_lost_it_relocates_and_develops_the_plan_afresh() {
        let mut m = Monitor::new(goal(), hallway());
        let Ok(Next::Steps(first)) = m.next(BENCH, 0) else { panic!("steps") };
        assert!(first.iter().any(|s| s.turn_deg.is_some()));
        m.lost();
        m.lost();
        // At the next step boundary: a pose fix, then a plan developed from where that says.
        assert_eq!(m.next(BENCH, 0), Ok(Next::Steps(vec![fix()])));
        assert_eq!((m.relocations, m.replans, m.sketch.len()), (1, 0, 0));
        let fixed = Pose2 { x_m: 4.45, y_m: 3.0, heading_rad: -std::f64::consts::FRAC_PI_2 };
        let Ok(Next::Steps(_)) = m.next(fixed, 1) else { panic!("steps") };
        assert_eq!(m.sketch[0].from.at, [4.45, 3.0]);
        assert_eq!(m.sketch[0].to.name, "robot-lab-side-of-door-0");
    }

    #[test]
    fn near_the_goal_it_moves_straight_or_backs_off_rather_than_turn_far() {
        // 2 cm short, dead ahead: one move. 3 cm to the side: back off, aim, come in again.
        let g = Pose2 { x_m: 12.0, y_m: 2.5, heading_rad: 60f64.to_radians() };
        let near = |ahead: f64, left: f64| {
            let (c, s) = (g.heading_rad.cos(), g.heading_rad.sin());
            Pose2 { x_m: g.x_m - ahead * c + left * s, y_m: g.y_m - ahead * s - left * c, ..g }
        };
        let one_move = |at: Pose2| match Monitor::new(goal(), hallway()).next(at, 0) {
            Ok(Next::Steps(s)) if s.len() == 1 => s[0].move_m,
            other => panic!("{other:?}"),
        };
        assert!(one_move(near(0.02, 0.0)).is_some_and(|d| (d - 0.02).abs() < 1e-9));
        assert!(one_move(near(0.0, 0.03)).is_some_and(|d| (d + 0.45).abs() < 1e-9));
        let bad = PtransGoal { to: "attic".into(), ..goal() };
        assert_eq!(
            Monitor::new(bad, hallway()).next(BENCH, 0),
            Err(PlanError::UnknownLocale("attic".into()))
        );
    }
}

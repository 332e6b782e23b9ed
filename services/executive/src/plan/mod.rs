//! Plan-and-monitor as the executive's mode (000 §2, §4): the monitor (`monitor.rs`) develops
//! the mission's `(ptrans here goal)` into a plan sketch over the locale graph (`sketch.rs`) and
//! hands its primitive subgoals, step by step, to a script runner, which runs them as it runs
//! any script; every time the script runs out, the monitor checks, re-plans and appends.

pub mod monitor;
pub mod sketch;

use harvey_msgs::{MissionState, Odometry, Pose2, VisionResult};

use crate::Output;
use crate::mission::Step;
use crate::script::{Fixes, More, Script, Sequel};
use monitor::{Monitor, Next};

/// The plan under way: the monitor and the script it appends to.
#[derive(Debug, Clone)]
pub struct Plan {
    pub script: Script,
    pub monitor: Monitor,
    /// Plan sketches published so far.
    sketches: u64,
}

impl Plan {
    /// `script` starts empty (plan-and-monitor makes every step); it may carry plan-level
    /// servoing's set-up, which the monitor's pose fixes need.
    pub fn new(script: Script, monitor: Monitor) -> Self {
        Self { script, monitor, sketches: 0 }
    }

    /// The UMS says the robot is lost: the monitor relocates at the next step boundary.
    pub fn lost(&mut self) {
        self.monitor.lost();
    }

    pub fn on_vision(&mut self, r: &VisionResult) -> Vec<Output> {
        let Self { script, monitor, sketches } = self;
        script.on_vision(r, &mut Developing { monitor, sketches })
    }

    pub fn on_odometry(&mut self, o: &Odometry) -> Vec<Output> {
        let Self { script, monitor, sketches } = self;
        script.on_odometry(o, &mut Developing { monitor, sketches })
    }
}

/// The monitor as the script's sequel: each time the script runs out, its next steps, with the
/// sketch as it stands then.
struct Developing<'a> {
    monitor: &'a mut Monitor,
    sketches: &'a mut u64,
}

impl Sequel for Developing<'_> {
    fn goal(&self, _: Pose2, _: &[Step]) -> Pose2 {
        self.monitor.goal_pose()
    }

    fn more(&mut self, at: Pose2, fixes: Fixes, now: u64, out: &mut Vec<Output>) -> More {
        self.monitor.last_fix_sd(fixes.last_sd_m);
        let next = self.monitor.next(at, fixes.count);
        *self.sketches += 1;
        out.push(Output::Plan(self.monitor.sketch_msg(*self.sketches, now)));
        match next {
            Ok(Next::Steps(steps)) => More::Steps(steps),
            Ok(Next::Arrived) => More::End(MissionState::Succeeded),
            Err(e) => {
                tracing::error!(error = %e, "plan-and-monitor failed");
                More::End(MissionState::Failed)
            }
        }
    }
}

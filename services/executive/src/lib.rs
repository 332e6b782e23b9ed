//! The executive's logic, first version: runs a mission's TURN/MOVE script, one primitive at a
//! time, checking each against odometry, and reports progress. Plan-and-monitor, perceptual
//! servoing and FSA sequencing grow from here in their own issue.

pub mod fsa;
pub mod mission;
pub mod schemas;
pub mod servo;

use harvey_msgs::{CommandKind, Header, MissionState, MissionStatus, MotionCommand, Odometry, Pose2};
use mission::{Mission, Step};

/// What the executive wants sent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Output {
    Command(MotionCommand),
    Status(MissionStatus),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// No odometry yet: the vehicle's state is unknown.
    Waiting,
    /// Step `i` was commanded with id `id`.
    Executing {
        step: usize,
        id: u32,
    },
    Done(MissionState),
}

/// The executive's state.
#[derive(Debug)]
pub struct Executive {
    mission: Mission,
    phase: Phase,
    start_ns: u64,
    goal: Pose2,
    estimated: Pose2,
    next_id: u32,
    seq: u64,
    pub sonar_rings_seen: u64,
    pub detections_seen: u64,
    pub maps_seen: u64,
}

/// Where a script ends when executed exactly from `start`.
pub fn goal_of(start: Pose2, steps: &[Step]) -> Pose2 {
    steps.iter().fold(start, |p, s| match (s.move_m, s.turn_deg) {
        (Some(d), _) => {
            Pose2 { x_m: p.x_m + d * p.heading_rad.cos(), y_m: p.y_m + d * p.heading_rad.sin(), ..p }
        }
        (_, Some(a)) => Pose2 { heading_rad: p.heading_rad + a.to_radians(), ..p },
        _ => p,
    })
}

impl Executive {
    pub fn new(mission: Mission) -> Self {
        Self {
            mission,
            phase: Phase::Waiting,
            start_ns: 0,
            goal: Pose2::default(),
            estimated: Pose2::default(),
            next_id: 1,
            seq: 0,
            sonar_rings_seen: 0,
            detections_seen: 0,
            maps_seen: 0,
        }
    }

    pub fn state(&self) -> MissionState {
        match self.phase {
            Phase::Done(s) => s,
            _ => MissionState::Running,
        }
    }

    fn command(&mut self, step: usize, stamp_ns: u64) -> MotionCommand {
        let s = self.mission.steps[step];
        let id = self.next_id;
        self.next_id += 1;
        self.phase = Phase::Executing { step, id };
        let header = Header::new(u64::from(id), stamp_ns);
        match (s.move_m, s.turn_deg) {
            (Some(d), _) => MotionCommand {
                header,
                kind: CommandKind::Move as u32,
                distance_m: d,
                command_id: id,
                ..Default::default()
            },
            (_, a) => MotionCommand {
                header,
                kind: CommandKind::Turn as u32,
                angle_rad: a.unwrap_or(0.0).to_radians(),
                command_id: id,
                ..Default::default()
            },
        }
    }

    /// One odometry message: advance the script; returns commands and the status to publish.
    pub fn on_odometry(&mut self, o: &Odometry) -> Vec<Output> {
        let now = o.header.stamp_ns;
        self.estimated = o.world_from_robot;
        let mut out = Vec::new();
        match self.phase {
            Phase::Waiting => {
                self.start_ns = now;
                self.goal = goal_of(o.world_from_robot, &self.mission.steps);
                out.push(Output::Command(self.command(0, now)));
            }
            Phase::Executing { step, id } => {
                let finished = o.command.command_id == id && o.command_accepted == 1 && o.moving == 0;
                if finished && step + 1 < self.mission.steps.len() {
                    out.push(Output::Command(self.command(step + 1, now)));
                } else if finished {
                    self.phase = Phase::Done(MissionState::Succeeded);
                } else if now.saturating_sub(self.start_ns) as f64 > self.mission.timeout_s * 1e9 {
                    self.phase = Phase::Done(MissionState::Failed);
                    out.push(Output::Command(MotionCommand {
                        header: Header::new(u64::from(self.next_id), now),
                        kind: CommandKind::Stop as u32,
                        command_id: self.next_id,
                        ..Default::default()
                    }));
                }
            }
            Phase::Done(_) => {}
        }
        out.push(Output::Status(self.status(now)));
        out
    }

    fn status(&mut self, stamp_ns: u64) -> MissionStatus {
        self.seq += 1;
        let step = match self.phase {
            Phase::Waiting => 0,
            Phase::Executing { step, .. } => step,
            Phase::Done(_) => self.mission.steps.len(),
        };
        MissionStatus {
            header: Header::new(self.seq, stamp_ns),
            state: self.state() as u32,
            step: step as u32,
            step_count: self.mission.steps.len() as u32,
            reserved: 0,
            estimated: self.estimated,
            goal: self.goal,
            sonar_rings_seen: self.sonar_rings_seen,
            detections_seen: self.detections_seen,
            maps_seen: self.maps_seen,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mission(timeout_s: f64) -> Mission {
        Mission {
            description: "t".into(),
            timeout_s,
            steps: vec![
                Step { move_m: Some(2.0), turn_deg: None },
                Step { move_m: None, turn_deg: Some(90.0) },
            ],
        }
    }

    fn odo(stamp_s: f64, x_m: f64, cmd: MotionCommand, accepted: bool, moving: bool) -> Odometry {
        Odometry {
            header: Header::new(1, (stamp_s * 1e9) as u64),
            world_from_robot: Pose2 { x_m, ..Default::default() },
            command: cmd,
            command_accepted: u32::from(accepted),
            moving: u32::from(moving),
            ..Default::default()
        }
    }

    #[test]
    fn the_script_runs_step_by_step_to_success() {
        let mut e = Executive::new(mission(60.0));
        let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
        let Output::Command(mv) = out[0] else { panic!("{out:?}") };
        assert_eq!((mv.kind, mv.distance_m, mv.command_id), (CommandKind::Move as u32, 2.0, 1));
        // Accepted but still moving: nothing new.
        assert_eq!(e.on_odometry(&odo(1.0, 0.3, mv, true, true)).len(), 1);
        let out = e.on_odometry(&odo(7.0, 1.9, mv, true, false));
        let Output::Command(turn) = out[0] else { panic!("{out:?}") };
        assert_eq!((turn.kind, turn.command_id), (CommandKind::Turn as u32, 2));
        assert!((turn.angle_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let out = e.on_odometry(&odo(10.0, 1.9, turn, true, false));
        let Output::Status(s) = out[0] else { panic!("{out:?}") };
        assert_eq!((s.state(), s.step, s.step_count), (Some(MissionState::Succeeded), 2, 2));
        assert!(
            (s.goal.x_m - 2.0).abs() < 1e-12
                && (s.goal.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
    }

    #[test]
    fn a_mission_past_its_time_fails_and_stops_the_robot() {
        let mut e = Executive::new(mission(5.0));
        let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
        let Output::Command(mv) = out[0] else { panic!("{out:?}") };
        let out = e.on_odometry(&odo(6.0, 1.0, mv, true, true));
        assert!(matches!(out[0], Output::Command(c) if c.kind == CommandKind::Stop as u32));
        assert_eq!(e.state(), MissionState::Failed);
    }
}

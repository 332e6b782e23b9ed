//! The script runner's tests: steps in order, recovery after a reflex, the mission timeout.

use super::*;
use harvey_msgs::Odometry;

fn mission(timeout_s: f64) -> Mission {
    Mission {
        description: "t".into(),
        timeout_s,
        servo: None,
        refine: None,
        ptrans: None,
        docking: None,
        poles: None,
        steps: vec![
            Step { move_m: Some(2.0), ..Step::default() },
            Step { turn_deg: Some(90.0), ..Step::default() },
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
    let mut e = Executive::new(mission(60.0), Vec::new());
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
        (s.goal.x_m - 2.0).abs() < 1e-12 && (s.goal.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12
    );
}

#[test]
fn after_a_reflex_the_interrupted_step_is_finished_from_where_the_robot_is() {
    let one = Mission { steps: vec![Step { move_m: Some(4.0), ..Step::default() }], ..mission(60.0) };
    let mut e = Executive::new(one, Vec::new());
    let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
    let Output::Command(mv) = out[0] else { panic!("{out:?}") };
    // The sonar's panic-avoid takes over 2 m in, and keeps the vehicle busy for a while.
    let reflex =
        |id: u32| MotionCommand { command_id: 0x8000_0000 | id, urgent: 1, ..MotionCommand::default() };
    assert_eq!(e.on_odometry(&odo(1.0, 1.0, mv, true, true)).len(), 1);
    assert_eq!(e.on_odometry(&odo(7.0, 2.0, reflex(1), true, false)).len(), 1);
    assert_eq!(e.on_odometry(&odo(8.0, 2.0, reflex(2), true, true)).len(), 1);
    assert_eq!(e.preemptions, 1);
    let mut at = odo(12.0, 2.0, reflex(3), true, false);
    at.world_from_robot = Pose2 { x_m: 2.0, y_m: 0.9, heading_rad: std::f64::consts::FRAC_PI_2 };
    assert_eq!(e.on_odometry(&at).len(), 1, "quiet for less than 2 s");
    at.header.stamp_ns = 14_500_000_000;
    let out = e.on_odometry(&at);
    let Output::Command(turn) = out[0] else { panic!("{out:?}") };
    assert_eq!(turn.kind, CommandKind::Turn as u32);
    assert!((turn.angle_rad - (-std::f64::consts::FRAC_PI_2 + (-0.9f64).atan2(2.0))).abs() < 1e-9);
    // The vehicle still reports the reflex's last command: no new preemption.
    assert_eq!(e.on_odometry(&at).len(), 1);
    let out = e.on_odometry(&odo(16.0, 2.0, turn, true, false));
    let Output::Command(go) = out[0] else { panic!("{out:?}") };
    assert!(go.kind == CommandKind::Move as u32 && (go.distance_m - 2.0f64.hypot(0.9)).abs() < 1e-9);
    let out = e.on_odometry(&odo(24.0, 4.0, go, true, false));
    let Output::Command(last) = out[0] else { panic!("{out:?}") };
    assert_eq!(last.kind, CommandKind::Turn as u32);
    e.on_odometry(&odo(26.0, 4.0, last, true, false));
    assert_eq!((e.state(), e.preemptions), (MissionState::Succeeded, 1));
}

#[test]
fn a_mission_past_its_time_fails_and_stops_the_robot() {
    let mut e = Executive::new(mission(5.0), Vec::new());
    let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
    let Output::Command(mv) = out[0] else { panic!("{out:?}") };
    let out = e.on_odometry(&odo(6.0, 1.0, mv, true, true));
    assert!(matches!(out[0], Output::Command(c) if c.kind == CommandKind::Stop as u32));
    assert_eq!(e.state(), MissionState::Failed);
}

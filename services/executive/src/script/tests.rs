//! The script runner's tests: steps in order, legs driven in increments (open loop and servoed),
//! recovery after a reflex, the mission timeout, and a `refine_pose` step's pose fix.

use harvey_msgs::{
    CommandKind, Header, MissionState, MotionCommand, Odometry, Pose2, ServoLevel, VisionItem, VisionResult,
    VisionStatus,
};

use super::leg::Tracking;
use super::{Script, WAIT_NS};
use crate::mission::{Servo, Step};
use crate::servo::pose::{PinholeCamera, RefineParams};
use crate::servo::vertices::{Choose, Growth, RefineSetup};
use crate::{Executive, Mode, Output};

fn two_steps() -> Vec<Step> {
    vec![Step { move_m: Some(2.0), ..Step::default() }, Step { turn_deg: Some(90.0), ..Step::default() }]
}

fn script(timeout_s: f64, steps: Vec<Step>) -> Executive {
    Executive::new(Mode::Script(Box::new(Script::new(steps, None, Vec::new()))), timeout_s)
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

/// The commands among `out`.
fn commands(out: &[Output]) -> Vec<MotionCommand> {
    out.iter().filter_map(|o| if let Output::Command(c) = o { Some(*c) } else { None }).collect()
}

/// The status `out` ends with.
fn status(out: &[Output]) -> harvey_msgs::MissionStatus {
    match out.last() {
        Some(Output::Status(s)) => *s,
        other => panic!("no status last: {other:?}"),
    }
}

fn preemptions(e: &Executive) -> u32 {
    e.script().map_or(0, |s| s.preemptions)
}

#[test]
fn the_script_runs_step_by_step_to_success() {
    let mut e = script(60.0, two_steps());
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
fn an_open_loop_move_is_driven_in_its_increments_the_last_taking_what_is_left() {
    let leg = Step { move_m: Some(1.5), increment_m: Some(0.6), ..Step::default() };
    let mut e = script(60.0, vec![leg, Step { turn_deg: Some(-45.0), ..Step::default() }]);
    let mut sent = commands(&e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false)));
    let mut x = 0.0;
    for k in 1..=2 {
        let c = *sent.last().expect("a command");
        x += c.distance_m;
        let out = e.on_odometry(&odo(f64::from(k) * 3.0, x, c, true, false));
        assert_eq!(status(&out).servo, ServoLevel::None as u32, "no servoing without a landmark");
        sent.extend(commands(&out));
    }
    let moves: Vec<(u32, f64, u32)> = sent.iter().map(|c| (c.kind, c.distance_m, c.command_id)).collect();
    let mv = CommandKind::Move as u32;
    assert_eq!(&moves[..2], &[(mv, 0.6, 1), (mv, 0.6, 2)]);
    assert!(moves[2].0 == mv && (moves[2].1 - 0.3).abs() < 1e-12 && moves[2].2 == 3, "{moves:?}");
    // The last increment done: the turn, step 1 of 2.
    let out = e.on_odometry(&odo(9.0, 1.5, sent[2], true, false));
    let turn = commands(&out)[0];
    assert_eq!((turn.kind, turn.command_id), (CommandKind::Turn as u32, 4));
    assert!((turn.angle_rad + std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    assert_eq!((status(&out).step, status(&out).step_count), (1, 2));
    e.on_odometry(&odo(12.0, 1.5, turn, true, false));
    assert_eq!(e.state(), MissionState::Succeeded);
    assert_eq!(e.legs().len(), 1, "the open-loop leg is kept for the summary");
    assert!(e.legs()[0].corrections.is_empty());
}

/// A leg servoed on a landmark 16 m down the line, 0.2 m to its left, at the camera's height.
fn servoed() -> Executive {
    let setup = super::leg::test_setup();
    let table = Servo {
        aim_m: 1.2,
        misalignment_deg: 0.0,
        calibrate_mount: false,
        gate_deg: 3.0,
        gate_range: 0.1,
        template_px: 16,
        min_score: 0.9,
        offset: Tracking::Increment,
    };
    let leg = Step {
        move_m: Some(1.2),
        increment_m: Some(0.6),
        servo_landmark: Some("sign".into()),
        ..Step::default()
    };
    Executive::new(Mode::Script(Box::new(Script::new(vec![leg], Some(table), vec![Some(setup)]))), 60.0)
}

fn seen(request_id: u32, stamp_s: f64, px: Option<[f32; 2]>) -> VisionResult {
    let mut r = VisionResult {
        header: Header::new(1, (stamp_s * 1e9) as u64),
        request_id,
        status: (if px.is_some() { VisionStatus::Found } else { VisionStatus::NotFound }) as u32,
        count: u32::from(px.is_some()),
        ..VisionResult::default()
    };
    if let Some([u, v]) = px {
        r.items[0] = VisionItem { values: [u, v, 0.0, 0.0, 0.0, 0.0] };
    }
    r
}

#[test]
fn a_servoed_leg_looks_after_each_increment_and_turns_the_correction() {
    let mut e = servoed();
    let mv = commands(&e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false)))[0];
    assert_eq!((mv.distance_m, mv.command_id), (0.6, 1));
    let out = e.on_odometry(&odo(3.0, 0.6, mv, true, false));
    let Output::Look(look) = out[0] else { panic!("a look: {out:?}") };
    assert_eq!((look.request_id, look.landmark_index), (100, 7));
    assert!((look.expected.x_m - 0.6).abs() < 1e-12 && look.expected.y_m == 0.0, "{look:?}");
    assert_eq!(status(&out).servo, ServoLevel::Action as u32);
    // Tracked in the window the gates allow (3 degrees, 29 px either way), not the whole frame:
    // 10 px off is inside, 40 px off is not.
    let [u0, _, u1, _] = look.window_px;
    let predicted = (320.0 - 554.0 * (0.2f64 / 15.4)) as f32;
    assert!(u0 < predicted - 10.0 && predicted + 10.0 < u1, "{:?}", look.window_px);
    assert!(u0 > predicted - 45.0 && predicted + 45.0 > u1, "{:?}", look.window_px);
    // Another request's answer is not this look's.
    assert!(e.on_vision(&seen(99, 3.1, Some([300.0, 240.0]))).is_empty());
    // Seen 10 px right of where the line puts it: turned left, so a turn back right.
    let u = (320.0 - 554.0 * (0.2f64 / 15.4) + 10.0) as f32;
    let out = e.on_vision(&seen(100, 3.1, Some([u, 240.0])));
    let Output::Servo(c) = out[0] else { panic!("a correction: {out:?}") };
    let Output::Command(turn) = out[1] else { panic!("the turn: {out:?}") };
    assert_eq!((c.increment, c.landmark_index, c.header.seq), (1, 7, 1));
    assert!(
        c.heading_error_rad > 0.0 && (c.heading_error_rad - (10.0f64 / 554.0).atan()).abs() < 2e-3,
        "{c:?}"
    );
    assert!(
        turn.kind == CommandKind::Turn as u32 && turn.angle_rad == c.correction_rad && turn.angle_rad < 0.0
    );
    // Turned: the second increment, then a look that misses, which ends the leg uncorrected.
    let mv2 = commands(&e.on_odometry(&odo(5.0, 0.6, turn, true, false)))[0];
    assert_eq!((mv2.kind, mv2.distance_m, mv2.command_id), (CommandKind::Move as u32, 0.6, 3));
    let out = e.on_odometry(&odo(8.0, 1.2, mv2, true, false));
    let Output::Look(look) = out[0] else { panic!("a look: {out:?}") };
    assert_eq!(look.request_id, 101);
    assert!(e.on_vision(&seen(101, 8.1, None)).is_empty(), "a miss: no correction, no command");
    assert_eq!(e.state(), MissionState::Succeeded);
    let legs = e.legs();
    assert_eq!((legs.len(), legs[0].corrections.len(), legs[0].misses), (1, 1, 1));
}

#[test]
fn after_a_reflex_the_interrupted_step_is_finished_from_where_the_robot_is() {
    let mut e = script(60.0, vec![Step { move_m: Some(4.0), ..Step::default() }]);
    let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
    let Output::Command(mv) = out[0] else { panic!("{out:?}") };
    // The sonar's panic-avoid takes over 2 m in, and keeps the vehicle busy for a while.
    let reflex =
        |id: u32| MotionCommand { command_id: 0x8000_0000 | id, urgent: 1, ..MotionCommand::default() };
    assert_eq!(e.on_odometry(&odo(1.0, 1.0, mv, true, true)).len(), 1);
    let out = e.on_odometry(&odo(7.0, 2.0, reflex(1), true, false));
    assert_eq!((out.len(), status(&out).servo), (1, ServoLevel::Goal as u32));
    assert_eq!(e.on_odometry(&odo(8.0, 2.0, reflex(2), true, true)).len(), 1);
    assert_eq!(preemptions(&e), 1);
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
    assert_eq!((e.state(), preemptions(&e)), (MissionState::Succeeded, 1));
}

#[test]
fn a_reflex_stop_the_vehicle_never_took_does_not_hold_the_step_for_ever() {
    let mut e = script(60.0, vec![Step { move_m: Some(4.0), ..Step::default() }]);
    let mv = commands(&e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false)))[0];
    e.on_odometry(&odo(1.0, 1.0, mv, true, true));
    // The panic-avoid's last dash ran, and odometry names a stop sent beside it, which the
    // vehicle never reported running: still, and that stop is the newest command for good.
    let stop = MotionCommand { command_id: 0xC000_0009, urgent: 1, ..MotionCommand::default() };
    assert!(commands(&e.on_odometry(&odo(2.0, 1.5, stop, false, false))).is_empty());
    assert!(commands(&e.on_odometry(&odo(3.0, 1.5, stop, false, false))).is_empty(), "quiet for 1 s");
    let go = commands(&e.on_odometry(&odo(4.1, 1.5, stop, false, false)));
    assert!(go.len() == 1 && (go[0].distance_m - 2.5).abs() < 1e-9, "quiet for 2 s: on to the goal: {go:?}");
}

/// A sonar ring reading `behind_m` all round (what matters: behind), the panic-stop's flag as
/// `blocked`.
fn ring(behind_m: f32, blocked: bool) -> harvey_msgs::SonarRing {
    let n = harvey_msgs::SONAR_SENSORS;
    let mut r = harvey_msgs::SonarRing {
        valid_mask: (1 << n) - 1,
        panic_stop: u32::from(blocked),
        ..Default::default()
    };
    for i in 0..n {
        r.bearing_rad[i] = (i as f64 * std::f64::consts::TAU / n as f64) as f32;
        r.range_m[i] = behind_m;
    }
    r
}

/// A servoed leg whose first increment (0.6 m) a reflex interrupts 0.3 m in (a right turn and a
/// 0.4 m dash), the ring reading `behind_m` behind; and the odometry, quiet long enough, that
/// sets it on the way back.
fn interrupted_leg(behind_m: f32) -> (Executive, Odometry) {
    let mut e = servoed();
    let mv = commands(&e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false)))[0];
    assert_eq!(mv.distance_m, 0.6);
    let reflex =
        |id: u32| MotionCommand { command_id: 0x8000_0000 | id, urgent: 1, ..MotionCommand::default() };
    e.on_odometry(&odo(1.0, 0.3, mv, true, true));
    e.on_odometry(&odo(1.5, 0.3, reflex(1), true, false));
    let mut at = odo(6.0, 0.3, reflex(3), true, false);
    at.world_from_robot = Pose2 { x_m: 0.3, y_m: -0.4, heading_rad: -std::f64::consts::FRAC_PI_2 };
    e.on_odometry(&at);
    e.on_sonar(&ring(behind_m, false));
    at.header.stamp_ns = 8_500_000_000;
    (e, at)
}

/// A servoed leg whose first increment a reflex interrupts 0.3 m in (a right turn and a 0.4 m
/// dash), the ring reading `behind_m` behind: the primitives of the recovery and the redone
/// increment, and where they leave the robot, once the leg looks again.
fn recover_leg(behind_m: f32) -> (Vec<(u32, f64, f64)>, Pose2, Executive) {
    let (mut e, at) = interrupted_leg(behind_m);
    let mut pose = at.world_from_robot;
    let mut sent = Vec::new();
    let mut cmd = commands(&e.on_odometry(&at))[0];
    for k in 0..4 {
        sent.push((cmd.kind, cmd.distance_m, cmd.angle_rad));
        match CommandKind::from_raw(cmd.kind) {
            Some(CommandKind::Turn) => pose.heading_rad += cmd.angle_rad,
            _ => pose = pose.arc(cmd.distance_m, 0.0),
        }
        let mut done = odo(10.0 + 2.0 * f64::from(k), 0.0, cmd, true, false);
        done.world_from_robot = pose;
        let out = e.on_odometry(&done);
        if k == 3 {
            let Output::Look(look) = out[0] else { panic!("then the look: {out:?}") };
            assert!((look.expected.x_m - 0.6).abs() < 1e-12 && look.expected.y_m == 0.0, "{look:?}");
            break;
        }
        cmd = commands(&out)[0];
    }
    (sent, pose, e)
}

#[test]
fn after_a_reflex_a_servoed_leg_does_its_increment_again_from_where_it_began() {
    let (turn, mv) = (CommandKind::Turn as u32, CommandKind::Move as u32);
    // The way behind clear for 3 m: back (it came from there) to where the increment began,
    // facing along the line, not on to the step's goal; then the increment again.
    let (sent, pose, e) = recover_leg(3.0);
    assert_eq!(sent.iter().map(|s| s.0).collect::<Vec<_>>(), [turn, mv, turn, mv], "{sent:?}");
    assert!((sent[1].1 + 0.5).abs() < 1e-9, "backing up 0.5 m: {sent:?}");
    assert!((sent[3].1 - 0.6).abs() < 1e-12, "the increment again: {sent:?}");
    assert!((pose.x_m - 0.6).abs() < 1e-9 && pose.y_m.abs() < 1e-9, "{pose:?}");
    assert!(pose.heading_rad.sin().abs() < 1e-9 && pose.heading_rad.cos() > 0.0, "{pose:?}");
    assert_eq!(preemptions(&e), 1);
}

#[test]
fn a_recovery_backs_up_only_as_far_as_the_way_behind_is_clear() {
    // Turned to back up 0.5 m to where the increment began, with something 0.6 m behind (0.3 m
    // clear, with the margin): it waits, and backs up once the way is clear.
    let (mut e, at) = interrupted_leg(0.6);
    let turn = commands(&e.on_odometry(&at))[0];
    assert_eq!(turn.kind, CommandKind::Turn as u32);
    let mut done = odo(10.0, 0.0, turn, true, false);
    done.world_from_robot.heading_rad = at.world_from_robot.heading_rad + turn.angle_rad;
    (done.world_from_robot.x_m, done.world_from_robot.y_m) = (0.3, -0.4);
    assert!(commands(&e.on_odometry(&done)).is_empty(), "waits: 0.3 m clear behind");
    done.header.stamp_ns = 13_000_000_000;
    assert!(commands(&e.on_odometry(&done)).is_empty(), "still waits");
    e.on_sonar(&ring(3.0, false));
    done.header.stamp_ns = 15_100_000_000;
    let back = commands(&e.on_odometry(&done));
    assert!(back.len() == 1 && (back[0].distance_m + 0.5).abs() < 1e-9, "{back:?}");
}

#[test]
fn after_a_reflex_no_move_goes_out_into_what_the_panic_stop_sees_ahead() {
    // Stopped by the panic-stop 2 m into a 4 m move, before something that stays: the vehicle
    // stands, the panic-stop sends no more stops, and the way ahead stays blocked.
    let mut e = script(60.0, vec![Step { move_m: Some(4.0), ..Step::default() }]);
    let mv = commands(&e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false)))[0];
    let stop = MotionCommand { command_id: 0xC000_0001, urgent: 1, ..MotionCommand::default() };
    e.on_odometry(&odo(1.0, 1.0, mv, true, true));
    e.on_sonar(&ring(3.0, true));
    for t in [2.0, 5.0, 8.0, 11.0] {
        assert!(commands(&e.on_odometry(&odo(t, 2.0, stop, true, false))).is_empty(), "at {t} s");
    }
    // Gone: on to the goal after quiet.
    e.on_sonar(&ring(3.0, false));
    assert!(commands(&e.on_odometry(&odo(12.0, 2.0, stop, true, false))).is_empty(), "quiet again first");
    let go = commands(&e.on_odometry(&odo(14.1, 2.0, stop, true, false)));
    assert!(go.len() == 1 && (go[0].distance_m - 2.0).abs() < 1e-9, "{go:?}");
}

#[test]
fn a_mission_past_its_time_fails_and_stops_the_robot() {
    let mut e = script(5.0, two_steps());
    let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
    let Output::Command(mv) = out[0] else { panic!("{out:?}") };
    let out = e.on_odometry(&odo(6.0, 1.0, mv, true, true));
    assert!(matches!(out[0], Output::Command(c) if c.kind == CommandKind::Stop as u32 && c.command_id == 2));
    assert_eq!(e.state(), MissionState::Failed);
}

/// Vertices down a hallway (as `missions/pose-refine.toml`'s), a camera 1.2 m up.
fn refining() -> RefineSetup {
    let vertices = [
        [6.9, 1.0, 1.8],
        [8.1, 1.0, 1.8],
        [6.9, 1.0, 1.1],
        [8.1, 1.0, 1.1],
        [9.0, -1.0, 2.1],
        [8.1, -1.0, 2.1],
        [16.0, 0.2, 2.3],
        [16.0, -0.2, 2.3],
    ];
    RefineSetup {
        vertices: vertices.iter().enumerate().map(|(i, &v)| (i as u32, [0.0; 3], v)).collect(),
        camera: PinholeCamera { focal_px: 554.0, centre_px: [320.0, 240.0], height_m: 1.2 },
        params: RefineParams {
            prior_sd: [0.3, 0.3, 3f64.to_radians()],
            pitch_sd_rad: 0.003,
            image_sd_px: 0.5,
            map_sd_m: 0.01,
            gate_px: 3.0,
        },
        template_px: 16,
        min_score: 0.9,
        max_sd_m: f64::INFINITY,
        growth: Growth::default(),
        world: None,
        choose: Choose::Nearest,
    }
}

fn refine_step(offset_m: [f64; 2]) -> Step {
    Step { refine_pose: true, belief_offset_m: Some(offset_m), ..Step::default() }
}

#[test]
fn a_refine_pose_step_fixes_the_belief_from_the_vertices_found() {
    let setup = refining();
    let steps = vec![refine_step([0.0, -0.1524]), refine_step([0.0, 0.0762])];
    let mut e = Executive::new(
        Mode::Script(Box::new(Script::new(steps, None, Vec::new()).with_refine(setup.clone()))),
        60.0,
    );
    let truth = Pose2::default();
    let out = e.on_odometry(&odo(0.0, 0.0, MotionCommand::default(), false, false));
    let looks: Vec<_> =
        out.iter().filter_map(|o| if let Output::Look(r) = o { Some(*r) } else { None }).collect();
    assert_eq!(looks.len(), 8, "every vertex is in view from the start of the hall");
    assert_eq!(looks.iter().map(|r| r.request_id).collect::<Vec<_>>(), (100..108).collect::<Vec<_>>());
    assert!(looks.iter().all(|r| (r.expected.y_m + 0.1524).abs() < 1e-12), "asked from the belief 6 in off");
    assert_eq!(status(&out).servo, ServoLevel::Plan as u32);
    // The workers find each vertex where the truth puts it, a few tenths of a pixel off.
    let mut out = Vec::new();
    for (k, r) in looks.iter().enumerate() {
        let q = setup.camera.project(truth, setup.vertices[k].2).expect("ahead");
        let e_px = 0.3 * ((k as f64) * 2.1).sin();
        out = e.on_vision(&seen(r.request_id, 0.1, Some([(q[0] + e_px) as f32, (q[1] - e_px) as f32])));
        if k + 1 < looks.len() {
            assert!(out.is_empty(), "nothing until all are in");
        }
    }
    let Output::Pose(fix) = out[0] else { panic!("a fix: {out:?}") };
    let off = (fix.refined.x_m - truth.x_m).hypot(fix.refined.y_m - truth.y_m);
    assert!(off < 0.0254, "refined {off} m from the truth: {fix:?}");
    assert!((fix.expected.y_m + 0.1524).abs() < 1e-12 && (fix.asked, fix.found) == (8, 8) && fix.kept >= 6);
    assert!(fix.rms_px < 1.0 && fix.refined.heading_rad.abs() < 0.2f64.to_radians(), "{fix:?}");
    // The next step starts from the refined pose, 3 in off it.
    let Output::Look(next) = out[1] else { panic!("the next step's looks: {out:?}") };
    assert_eq!(next.request_id, 108);
    assert!((next.expected.y_m - (fix.refined.y_m + 0.0762)).abs() < 1e-12, "{next:?}");
    // Its answers never come: after the wait, no fix, and the script is done.
    assert_eq!(e.on_odometry(&odo(1.0, 0.0, MotionCommand::default(), false, false)).len(), 1);
    let out =
        e.on_odometry(&odo(0.1 + (WAIT_NS as f64 + 1e6) / 1e9, 0.0, MotionCommand::default(), false, false));
    assert!(!out.iter().any(|o| matches!(o, Output::Pose(_))), "{out:?}");
    assert_eq!((e.state(), e.script().map(|s| s.fixes)), (MissionState::Succeeded, Some(1)));
    let s = status(&out);
    assert!((s.estimated.y_m - (fix.refined.y_m + 0.0762)).abs() < 1e-12, "the offset belief stays: {s:?}");
}

#[test]
fn without_the_vertices_in_view_a_refine_pose_step_is_skipped() {
    // Turned round, the hall's vertices are behind the camera.
    let steps = vec![refine_step([0.0, 0.0])];
    let mut e = Executive::new(
        Mode::Script(Box::new(Script::new(steps, None, Vec::new()).with_refine(refining()))),
        60.0,
    );
    let mut o = odo(0.0, 0.0, MotionCommand::default(), false, false);
    o.world_from_robot.heading_rad = std::f64::consts::PI;
    let out = e.on_odometry(&o);
    assert_eq!(out.len(), 1, "no looks: {out:?}");
    assert_eq!((e.state(), e.script().map(|s| s.fixes)), (MissionState::Succeeded, Some(0)));
}

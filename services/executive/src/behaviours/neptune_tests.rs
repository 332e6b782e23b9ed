//! The stop-go-stop navigation on made-up looks: the model moved by the solved motion, by the
//! encoders' when none was solved, obstacles planned round, the goal reached, a stuck step given
//! up, a step the panic-stop holds ending with its echoes mapped and a back-off, and a model lost
//! outside the room failing.

use super::*;
use harvey_msgs::VisionItem;

fn goal() -> NeptuneGoal {
    NeptuneGoal {
        goal_m: [7.2, 3.0],
        goal_tolerance_m: 0.1,
        step_m: 0.4,
        settle_s: 0.5,
        look_timeout_s: 2.0,
        lucas: false,
        clearance_m: 0.65,
        hard_clearance_m: 0.45,
        shadow_m: 0.6,
        cell_m: 0.1,
        room_min_m: [0.0, 0.0],
        room_max_m: [8.0, 6.0],
        speed_mps: 0.2,
        max_turn_degps: 20.0,
        turn_gain: 1.5,
        arrive_m: 0.02,
        aligned_deg: 2.0,
        max_step_turn_deg: 15.0,
        back_off_m: 0.2,
    }
}

const START: Pose2 = Pose2::new(0.8, 3.0, 0.0);
const TICK: u64 = 50_000_000;
/// The sonar ring: its radius (m) and a sensor's beam.
const RING: Sonar = Sonar { ring_m: 0.23, beam_rad: 0.52 };

/// Ticks at `at` until the behaviour asks to look; returns the tick it did.
fn until_look(n: &mut Neptune, at: Pose2, mut now: u64) -> (VisionRequest, u64) {
    for _ in 0..100 {
        let (look, command, _) = n.on_odometry(at, now);
        assert_eq!((command.linear_mps, command.angular_radps), (0.0, 0.0), "still while settling");
        if let Some(l) = look {
            return (l, now);
        }
        now += TICK;
    }
    panic!("no look within 100 ticks");
}

fn answer(status: VisionStatus, motion: [f32; 3], carried: f32, points: &[[f32; 2]]) -> VisionResult {
    let mut r = VisionResult { request_id: REQUEST_ID, status: status as u32, ..VisionResult::default() };
    r.items[0] = VisionItem { values: [motion[0], motion[1], motion[2], 0.01, 0.01, 0.001] };
    r.items[1] = VisionItem { values: [50.0, 30.0, carried, 40.0, 2.0, 1.0] };
    for (k, p) in points.iter().enumerate() {
        r.items[2 + k] = VisionItem { values: [p[0], p[1], 0.5, 0.01, 0.0, 0.0] };
    }
    r.count = 2 + points.len() as u32;
    r
}

#[test]
fn looks_move_the_model_and_steps_go_round_what_was_seen() {
    let mut n = Neptune::new(goal(), START, RING);
    let (first, now) = until_look(&mut n, START, 0);
    assert_eq!((first.params[0], first.algorithm), (1.0, VisionAlgorithm::StereoOdometry as u32), "starts");
    // A wall of points 1.5 m ahead across the line: the step turns off it.
    let wall: Vec<[f32; 2]> = (0..7).map(|k| [1.5, -0.3 + 0.1 * k as f32]).collect();
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &wall));
    let (_, command, state) = n.on_odometry(START, now + TICK);
    assert!(command.angular_radps.abs() > 0.0, "turning off the line: {command:?}");
    assert_eq!((state.fsa_state, state.transitions), (2, 1));
    // The encoders say 0.4 m on; stereo says 0.38 m: the model takes stereo's.
    let moved = Pose2::new(1.2, 3.0, 0.0);
    let mut n2 = n.clone();
    n2.phase = Phase::Settling { since_ns: Some(now) };
    let (second, now) = until_look(&mut n2, moved, now + TICK);
    assert_eq!((second.params[0], second.expected), (0.0, START.relative(&moved)), "the encoders predict");
    n2.on_vision(&answer(VisionStatus::Found, [0.38, 0.0, 0.0], 40.0, &[]));
    assert!((n2.believed().x_m - 1.18).abs() < 1e-6, "{:?}", n2.believed());
    // None solved: the encoders' motion, and the stop is counted.
    let mut n3 = n.clone();
    n3.phase = Phase::Settling { since_ns: Some(now) };
    until_look(&mut n3, moved, now);
    n3.on_vision(&answer(VisionStatus::NotFound, [0.0; 3], 0.0, &[]));
    assert_eq!((n3.unsolved, n3.believed().x_m), (1, 1.2));
    // Another request's answer, or one while not looking, changes nothing.
    let before = n3.believed();
    n3.on_vision(&answer(VisionStatus::Found, [1.0, 0.0, 0.0], 40.0, &[]));
    assert_eq!(n3.believed(), before);
}

#[test]
fn the_goal_ends_it_a_held_step_is_given_up_and_a_walled_in_robot_fails() {
    let near = Pose2::new(7.15, 3.0, 0.0);
    let mut n = Neptune::new(goal(), near, RING);
    let (_, now) = until_look(&mut n, near, 0);
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &[]));
    assert_eq!(n.done, Some(true), "within 10 cm of the goal");
    // A step the robot cannot make (a reflex holds it): given up, and it looks again.
    let mut n = Neptune::new(goal(), START, RING);
    let (_, now2) = until_look(&mut n, START, now);
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &[]));
    let mut t = now2;
    let mut looked = false;
    for _ in 0..400 {
        t += TICK;
        let (look, ..) = n.on_odometry(START, t);
        looked |= look.is_some();
    }
    assert!(looked, "the step was given up and the robot looked again");
    // A look nobody answers is asked again after the timeout.
    let mut n = Neptune::new(goal(), START, RING);
    let (_, asked) = until_look(&mut n, START, t);
    let again: Vec<u64> =
        (1..=100).map(|k| asked + k * TICK).filter(|&t| n.on_odometry(START, t).0.is_some()).collect();
    assert_eq!(again, [asked + 40 * TICK, asked + 80 * TICK], "every 2 s");
    // A position model outside the room: no path, and the mission fails.
    let lost = Pose2::new(9.0, 3.0, 0.0);
    let mut n = Neptune::new(goal(), lost, RING);
    until_look(&mut n, lost, t);
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &[]));
    assert_eq!(n.done, Some(false));
}

#[test]
fn a_path_round_one_side_is_kept_while_the_other_is_not_much_cheaper() {
    let mut n = Neptune::new(goal(), START, RING);
    // A post straight ahead on the line to the goal: either side is as good.
    n.obstacles.push(([3.0, 3.0], [0.8, 3.0]));
    let first = n.plan([0.8, 3.0]).expect("a path");
    let side = (n.route[n.route.len() / 3][1] - 3.0).signum();
    assert!(side != 0.0, "round one side: {:?}", n.route);
    // A quarter of a metre to the other side of the line: a fresh plan would go round that side
    // (the robot turned to and fro between stops); the kept one goes on round the first.
    let other = [1.2, 3.0 - 0.25 * side];
    let mut fresh = n.clone();
    fresh.route.clear();
    fresh.plan(other).expect("a path");
    assert_eq!((fresh.route[fresh.route.len() / 3][1] - 3.0).signum(), -side, "{:?}", fresh.route);
    let next = n.plan(other).expect("a path");
    assert_eq!((n.route[n.route.len() / 3][1] - 3.0).signum(), side, "{:?}", n.route);
    assert!((next[1] - 3.0) * side >= (first[1] - 3.0) * side - 0.1, "{first:?} then {next:?}");
    // Once its side is walled off, the kept path is dropped for the other.
    for k in 0..8 {
        n.obstacles.push(([3.0, 3.0 + side * 0.1 * f64::from(k)], [1.2, 3.0]));
    }
    n.plan(other).expect("a path");
    assert_eq!((n.route[n.route.len() / 3][1] - 3.0).signum(), -side, "{:?}", n.route);
}

/// A ring read at `stamp` whose sensors hear `ranges` (index: sensor, 15 degrees apart from
/// ahead; the rest hear nothing within 3 m), the panic-stop set.
fn held_ring(stamp: u64, ranges: &[(usize, f32)]) -> SonarRing {
    let mut r = SonarRing { panic_stop: 1, ..SonarRing::default() };
    for i in 0..r.range_m.len() {
        r.bearing_rad[i] = (i as f32 * 15.0).to_radians();
        r.range_m[i] = 3.0;
        r.reading_stamp_ns[i] = stamp;
    }
    for &(i, range) in ranges {
        r.range_m[i] = range;
    }
    r.valid_mask = (1 << r.range_m.len()) - 1;
    r
}

#[test]
fn a_step_the_panic_stop_holds_ends_its_echoes_mapped_and_the_robot_backs_off() {
    // Facing north; the sensor 15 degrees left of ahead hears something 0.25 m out twice.
    let facing = Pose2::new(0.8, 3.0, std::f64::consts::FRAC_PI_2);
    let mut n = Neptune::new(goal(), facing, RING);
    n.route = vec![[0.8, 3.4], [7.2, 3.0]];
    n.phase = Phase::Moving { to: [0.8, 3.4], deadline_ns: 0 };
    n.on_sonar(&held_ring(1, &[(1, 0.25), (5, 2.0)]));
    n.on_sonar(&held_ring(2, &[(1, 0.25), (5, 0.3)]));
    let (_, command, state) = n.on_odometry(facing, 0);
    assert_eq!((command.linear_mps, state.fsa_state, n.holds), (0.0, 4, 1), "held: it stops, then backs");
    // The echo is mapped from its sensor (0.23 m out at 105 degrees) across its beam (0.52
    // rad: seven points at most 5 degrees apart); sensor 5's single near reading is not (one
    // alone may be crosstalk); the route that led here is dropped.
    assert_eq!(n.obstacles.len(), 7, "{:?}", n.obstacles);
    let b = 105f64.to_radians();
    let sensor = [0.8 + 0.23 * b.cos(), 3.0 + 0.23 * b.sin()];
    for (p, from) in &n.obstacles {
        let d = (p[0] - sensor[0]).hypot(p[1] - sensor[1]);
        let off = ((p[1] - sensor[1]).atan2(p[0] - sensor[0]) - b).to_degrees();
        assert!((d - 0.25).abs() < 1e-6 && off.abs() <= 15.0 + 1e-6, "{p:?}");
        assert!((from[0] - sensor[0]).abs() < 1e-6 && (from[1] - sensor[1]).abs() < 1e-6);
    }
    assert!(n.route.is_empty());
    // The next path turns off it: its first step ends well away from the echo.
    let echo = [sensor[0] + 0.25 * b.cos(), sensor[1] + 0.25 * b.sin()];
    let mut planner = n.clone();
    let next = planner.plan([0.8, 3.0]).expect("a path");
    assert!((next[0] - echo[0]).hypot(next[1] - echo[1]) > 0.35, "{next:?} by {echo:?}");
    // It backs straight until the encoders have 0.2 m behind them, then settles to look.
    let (_, command, _) = n.on_odometry(facing, TICK);
    assert_eq!((command.linear_mps, command.angular_radps), (-0.2, 0.0));
    let (_, command, _) = n.on_odometry(Pose2 { y_m: 2.9, ..facing }, 2 * TICK);
    assert_eq!(command.linear_mps, -0.2, "0.1 m back, not yet");
    let (_, command, state) = n.on_odometry(Pose2 { y_m: 2.79, ..facing }, 3 * TICK);
    assert_eq!((command.linear_mps, state.fsa_state), (0.0, 0), "settling");
}

#[test]
fn a_held_robot_backs_only_as_far_as_the_way_behind_is_clear() {
    let held = |behind: &[(usize, f32)]| {
        let mut n = Neptune::new(goal(), START, RING);
        n.phase = Phase::Moving { to: [1.2, 3.0], deadline_ns: 0 };
        let ahead: Vec<(usize, f32)> = [(0, 0.25)].into_iter().chain(behind.iter().copied()).collect();
        n.on_sonar(&held_ring(1, &ahead));
        n.on_sonar(&held_ring(2, &ahead));
        n.on_odometry(START, 0);
        n
    };
    // Something 0.45 m behind the sensor 30 degrees off straight behind (210 degrees): 0.15 m
    // of the 0.2 m (0.3 m kept), and the same at 150 degrees.
    for sensor in [10, 14] {
        let n = held(&[(sensor, 0.45)]);
        let Phase::Backing { back_m, .. } = n.phase else { panic!("{:?}", n.phase) };
        assert!((back_m - 0.15).abs() < 1e-6, "sensor {sensor}: {back_m}");
    }
    // 0.3 m behind: no room (a back-off within a step's 2 cm arrival is none), it settles to look.
    let n = held(&[(12, 0.3)]);
    assert!(matches!(n.phase, Phase::Settling { .. }), "{:?}", n.phase);
    // The way behind closing to 1 cm while it backs stops it; so does the deadline (2 x 1 s + 3 s).
    let mut n = held(&[]);
    n.on_sonar(&held_ring(3, &[(12, 0.31)]));
    let (_, command, state) = n.on_odometry(START, TICK);
    assert_eq!((command.linear_mps, state.fsa_state), (0.0, 0), "the way behind closed");
    let mut n = held(&[]);
    let (_, command, _) = n.on_odometry(START, 4_900_000_000);
    assert_eq!(command.linear_mps, -0.2, "stuck but within the deadline");
    let (_, command, _) = n.on_odometry(START, 5_000_000_000);
    assert_eq!(command.linear_mps, 0.0, "the deadline");
}

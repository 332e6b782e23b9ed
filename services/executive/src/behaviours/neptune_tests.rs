//! The stop-go-stop navigation on made-up looks: the model moved by the solved motion, by the
//! encoders' when none was solved, obstacles planned round, the goal reached, a stuck step given
//! up, and a model lost outside the room failing.

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
    }
}

const START: Pose2 = Pose2::new(0.8, 3.0, 0.0);
const TICK: u64 = 50_000_000;

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
    let mut n = Neptune::new(goal(), START);
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
    let mut n = Neptune::new(goal(), near);
    let (_, now) = until_look(&mut n, near, 0);
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &[]));
    assert_eq!(n.done, Some(true), "within 10 cm of the goal");
    // A step the robot cannot make (a reflex holds it): given up, and it looks again.
    let mut n = Neptune::new(goal(), START);
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
    let mut n = Neptune::new(goal(), START);
    let (_, asked) = until_look(&mut n, START, t);
    let again: Vec<u64> =
        (1..=100).map(|k| asked + k * TICK).filter(|&t| n.on_odometry(START, t).0.is_some()).collect();
    assert_eq!(again, [asked + 40 * TICK, asked + 80 * TICK], "every 2 s");
    // A position model outside the room: no path, and the mission fails.
    let lost = Pose2::new(9.0, 3.0, 0.0);
    let mut n = Neptune::new(goal(), lost);
    until_look(&mut n, lost, t);
    n.on_vision(&answer(VisionStatus::Found, [0.0; 3], 0.0, &[]));
    assert_eq!(n.done, Some(false));
}

#[test]
fn a_path_round_one_side_is_kept_while_the_other_is_not_much_cheaper() {
    let mut n = Neptune::new(goal(), START);
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

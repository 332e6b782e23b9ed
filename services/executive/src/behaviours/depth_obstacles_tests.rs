//! The depth-obstacles behaviour's decisions at a stop, on obstacle points put in by hand.

use super::*;

fn goal() -> DepthGoal {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../missions/depth-obstacles.toml"))
            .expect("mission");
    crate::mission::parse(&text, "depth-obstacles.toml").expect("parses").depth.expect("[mission.depth]")
}

/// The behaviour standing at `(x, y)` facing east, with `points` on its floor plan; it decides.
fn decided_at(x: f64, y: f64, points: &[[f64; 2]]) -> DepthObstacles {
    let at = Pose2 { x_m: x, y_m: y, heading_rad: 0.0 };
    let mut b = DepthObstacles::new(goal(), [554.0, 640.0, 480.0, 1.0], 0.23, at);
    b.points.insert(0, points.to_vec());
    b.decide();
    b
}

#[test]
fn a_goal_guarded_by_an_obstacle_is_arrived_at_where_the_push_turns_the_robot_back() {
    // The goal (22, 0) with a point 0.3 m beyond it: 0.6 m short the push outweighs the pull.
    let b = decided_at(21.4, 0.0, &[[22.3, 0.0]]);
    assert_eq!(b.done, Some(true), "vectors {:?}", b.vectors);
}

#[test]
fn far_from_a_guarded_goal_or_with_a_free_goal_the_robot_goes_on() {
    // The same point, 2.5 m short of the goal: further than the obstacle's reach.
    let b = decided_at(19.5, 0.0, &[[22.3, 0.0]]);
    assert_eq!(b.done, None);
    // A point 0.6 m short of the goal and 1.2 m beside the line, the robot 1.5 m short: the sum
    // still leads on towards the goal.
    let b = decided_at(20.5, 0.0, &[[21.4, 1.2]]);
    assert_eq!(b.done, None, "vectors {:?}", b.vectors);
    // Stalled by a point dead ahead, 1.1 m short of the goal: at the goal its push (0.29) is
    // weaker than the pull (0.3), so the goal is no guarded one, and the robot slides past.
    let b = decided_at(20.2, 0.0, &[[20.9, 0.0]]);
    assert_eq!(b.done, None, "vectors {:?}", b.vectors);
    // No obstacle: on it goes, towards the goal.
    let b = decided_at(21.2, 0.0, &[]);
    assert_eq!(b.done, None);
    assert!(matches!(b.phase, Phase::Moving { .. } | Phase::Turning { .. }), "{:?}", b.phase);
}

#[test]
fn an_obstacle_between_the_robot_and_a_near_goal_is_passed_not_taken_for_the_goal_s_guard() {
    // 0.8 m short of the goal, dead ahead, the robot 1.8 m short: stalled, within reach of the
    // goal, and the push at the goal (0.39) outweighs the pull, but it points on, the goal's
    // way: the robot slides round the point.
    let b = decided_at(20.2, 0.0, &[[21.2, 0.0]]);
    let [_, _, sum] = b.vectors;
    assert!(sum.x <= 0.0, "stalled: {:?}", b.vectors);
    assert_eq!(b.done, None, "vectors {:?}", b.vectors);
    assert!(matches!(b.phase, Phase::Turning { .. }), "{:?}", b.phase);
}

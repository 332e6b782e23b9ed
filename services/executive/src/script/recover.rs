//! Getting back to the plan after a reflex took the vehicle (001 §6.2: once a panic-avoid
//! episode is over, "special procedures are invoked to allow the robot to regain its bearings and
//! then satisfy the previously specified navigational goals"): from where dead reckoning says
//! the robot now is, face the interrupted step's goal, drive to it and take its heading; or,
//! back to a pose the robot has already been at (a leg's), back up to it if it is behind and
//! the way behind is clear.

use harvey_geometry::wrap;
use harvey_msgs::{CommandKind, Pose2, REFLEX_ID_BIT};

/// Whether the vehicle's current command is a reflex's.
pub fn is_reflex(command_id: u32) -> bool {
    command_id & REFLEX_ID_BIT != 0
}

/// Quiet time (ns) after a reflex's last motion before the executive takes over again.
pub const QUIET_NS: u64 = 2_000_000_000;

/// The primitives from `at` to `goal`: TURN to face it, MOVE there, TURN to its heading (each
/// left out when negligible), in order. A goal at most `max_back_m` away is reached backwards
/// (the TURN points the robot's back at it, the MOVE is negative) when that turns it less in
/// all: every turn costs odometry heading, and for a pose the robot came from along its heading
/// backing saves up to a whole turn.
pub fn back_to(at: Pose2, goal: Pose2, max_back_m: f64) -> Vec<(CommandKind, f64)> {
    let (dx, dy) = (goal.x_m - at.x_m, goal.y_m - at.y_m);
    let d = dx.hypot(dy);
    let mut out = Vec::new();
    let mut heading = at.heading_rad;
    if d > 0.01 {
        let mut face = wrap(dy.atan2(dx) - heading);
        let turning = |face: f64| face.abs() + wrap(goal.heading_rad - heading - face).abs();
        let back_face = wrap(face - std::f64::consts::PI);
        let backwards = d <= max_back_m && turning(back_face) < turning(face);
        if backwards {
            face = back_face;
        }
        if face.abs() > 1e-3 {
            out.push((CommandKind::Turn, face));
        }
        heading += face;
        out.push((CommandKind::Move, if backwards { -d } else { d }));
    }
    let last = wrap(goal.heading_rad - heading);
    if last.abs() > 1e-3 {
        out.push((CommandKind::Turn, last));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn back_to_the_goal_after_a_sideways_dash() {
        // Evaded: turned left a right angle and dashed 0.9 m; the step wanted (4, 0) heading 0.
        let at = Pose2 { x_m: 2.0, y_m: 0.9, heading_rad: std::f64::consts::FRAC_PI_2 };
        let goal = Pose2 { x_m: 4.0, y_m: 0.0, heading_rad: 0.0 };
        let steps = back_to(at, goal, 0.0);
        assert_eq!(steps.len(), 3);
        let face = -std::f64::consts::FRAC_PI_2 + (-0.9f64).atan2(2.0);
        assert!(steps[0].0 == CommandKind::Turn && (steps[0].1 - face).abs() < 1e-12);
        assert!(steps[1].0 == CommandKind::Move && (steps[1].1 - 2.0f64.hypot(0.9)).abs() < 1e-12);
        assert!(steps[2].0 == CommandKind::Turn && (steps[2].1 + (-0.9f64).atan2(2.0)).abs() < 1e-12);
        assert!(back_to(goal, goal, 0.0).is_empty());
        // Backing would turn it 222 degrees in all, forwards 138: forwards, however clear.
        assert_eq!(back_to(at, goal, 10.0), steps);
        // Turned right and dashed 0.4 m, 0.3 m into a step from (0, 0): forwards it turns 270
        // degrees in all, backing 90.
        let at = Pose2 { x_m: 0.3, y_m: -0.4, heading_rad: -std::f64::consts::FRAC_PI_2 };
        let start = Pose2::default();
        let back = back_to(at, start, 0.5);
        let face = (0.4f64).atan2(-0.3) + std::f64::consts::FRAC_PI_2 - std::f64::consts::PI;
        assert!(back[0].0 == CommandKind::Turn && (back[0].1 - face).abs() < 1e-12, "{back:?}");
        assert!(back[1].0 == CommandKind::Move && (back[1].1 + 0.5).abs() < 1e-12, "{back:?}");
        assert!(
            back[2].0 == CommandKind::Turn && (back[2].1 + face - std::f64::consts::FRAC_PI_2).abs() < 1e-12
        );
        let ahead = back_to(at, start, 0.4);
        assert!(ahead[1].0 == CommandKind::Move && (ahead[1].1 - 0.5).abs() < 1e-12, "not clear: {ahead:?}");
        assert!(is_reflex(0x8000_0003) && !is_reflex(3));
        assert!((wrap(3.5 * std::f64::consts::PI) + 0.5 * std::f64::consts::PI).abs() < 1e-12);
    }
}

//! Panic-avoid's tests: what is and is not an approach (a wall, a turn, a jump to another
//! surface), the stop, the turn to the clear side and the dash, and a refused turn sent again.

use super::*;
use harvey_msgs::Pose2;

const P: AvoidParams = AvoidParams {
    ttc_s: 4.0,
    confirm: 3,
    min_approach_mps: 0.15,
    arc_rad: std::f64::consts::FRAC_PI_6,
    turn_rad: std::f64::consts::FRAC_PI_2,
    dash_m: 0.9,
    stop_m: 0.61,
};

/// A ring read at `t` s: `ahead` m on sensor 0, `left` and `right` on sensors 6 and 18,
/// 8 m elsewhere.
fn ring(t: f64, ahead: f32, left: f32, right: f32) -> SonarRing {
    let mut r = SonarRing {
        header: Header::new(1, (t * 1e9) as u64),
        valid_mask: (1 << 24) - 1,
        ..Default::default()
    };
    r.range_m = [8.0; SONAR_SENSORS];
    (r.range_m[0], r.range_m[6], r.range_m[18]) = (ahead, left, right);
    r.reading_stamp_ns = [(t * 1e9) as u64; SONAR_SENSORS];
    r
}

fn odo(t: f64, x: f64, moving: bool, id: u32) -> Odometry {
    Odometry {
        header: Header::new(1, (t * 1e9) as u64),
        world_from_robot: Pose2 { x_m: x, ..Pose2::default() },
        moving: u32::from(moving),
        command: MotionCommand { command_id: id, ..MotionCommand::default() },
        command_accepted: 1,
        ..Odometry::default()
    }
}

#[test]
fn driving_at_a_wall_is_no_approach() {
    let mut a = PanicAvoid::new(P);
    // 0.3 m/s towards a wall 3 m ahead: the range closes exactly as fast as the robot drives.
    for k in 0..20 {
        let t = 0.15 * k as f64;
        assert_eq!(a.on_odometry(&odo(t, 0.3 * t, true, 1)), None);
        assert_eq!(a.on_ring(&ring(t, (3.0 - 0.3 * t) as f32, 2.0, 2.0)), None, "at {t} s");
    }
    assert_eq!(a.episodes, 0);
}

#[test]
fn quantised_readings_a_lagging_odometry_and_a_turn_are_no_approach() {
    let mut a = PanicAvoid::new(P);
    let tenth_ft = |m: f64| ((m / 0.03048).round() * 0.03048) as f32;
    // Driving at 0.3 m/s at a wall 2.5 m ahead, readings in tenths of a foot, odometry one
    // 50 ms tick behind them.
    for k in 0..30 {
        let t = 0.05 * k as f64;
        a.on_odometry(&odo(t - 0.05, 0.3 * (t - 0.05).max(0.0), true, 1));
        if k % 3 == 0 {
            assert_eq!(a.on_ring(&ring(t, tenth_ft(2.5 - 0.3 * t), 2.0, 2.0)), None, "at {t} s");
        }
    }
    // Turning on the spot: the forward sensor sweeps from a far wall onto a near one.
    for k in 0..30 {
        let t = 2.0 + 0.15 * k as f64;
        let mut o = odo(t, 0.0, true, 2);
        o.world_from_robot.heading_rad = 0.5 * (t - 2.0);
        a.on_odometry(&o);
        let ahead = if k < 10 { 6.0 - 0.4 * k as f32 } else { 1.5 };
        assert_eq!(a.on_ring(&ring(t, ahead, 2.0, 2.0)), None, "turning, at {t} s");
    }
    assert_eq!(a.episodes, 0);
}

#[test]
fn a_range_that_jumps_to_another_surface_is_no_approach() {
    let mut a = PanicAvoid::new(P);
    // Backing away from a room's corner: the forward beam slides off one wall onto the
    // other, and its range drops by a metre between two readings, then keeps growing.
    for k in 0..20 {
        let t = 0.15 * k as f64;
        a.on_odometry(&odo(t, -0.3 * t, true, 1));
        let ahead = if k < 8 { 3.0 + 0.3 * t } else { 2.0 + 0.3 * t };
        assert_eq!(a.on_ring(&ring(t, ahead as f32, 2.0, 2.0)), None, "at {t} s");
    }
    assert_eq!(a.episodes, 0);
}

#[test]
fn a_small_turn_far_from_the_origin_is_no_approach() {
    let mut a = PanicAvoid::new(P);
    // 12 m from the world's origin and facing across that line, standing, then turning 1
    // degree (under the turn that restarts a window): every range stays the same.
    for k in 0..20 {
        let t = 0.15 * k as f64;
        let mut o = odo(t, 12.0, k == 6, 1);
        o.world_from_robot.heading_rad = if k < 6 { 90f64 } else { 91f64 }.to_radians();
        a.on_odometry(&o);
        assert_eq!(a.on_ring(&ring(t, 1.2, 2.0, 2.0)), None, "at {t} s");
    }
    assert_eq!(a.episodes, 0);
}

#[test]
fn an_object_bearing_down_makes_the_robot_stop_turn_to_the_clear_side_and_dash() {
    let mut a = PanicAvoid::new(P);
    // The robot stands still; something comes at it at 0.6 m/s from 5 m; more room on the right.
    let mut stop = None;
    let mut k = 0;
    while stop.is_none() {
        let t = 0.15 * k as f64;
        a.on_odometry(&odo(t, 0.0, false, 7));
        stop = a.on_ring(&ring(t, (5.0 - 0.6 * t) as f32, 1.0, 4.0));
        k += 1;
        assert!(k < 40, "never fired");
    }
    let stop = stop.expect("fired");
    assert_eq!((stop.kind(), stop.urgent), (Some(CommandKind::Stop), 1));
    // Time to contact under 4 s (2.4 m at 0.6 m/s), confirmed by 3 readings after the first.
    let t = 0.15 * (k - 1) as f64;
    let range = 5.0 - 0.6 * t;
    assert!(range <= 2.4 && range > 2.4 - 3.0 * 0.09 - 1e-6, "fired at {range} m");
    assert!(a.evading());
    // Still: turn right (negative), a right angle, urgent, with a reflex id.
    let turn = a.on_odometry(&odo(t + 0.05, 0.0, false, 7)).expect("turns");
    assert_eq!((turn.kind(), turn.urgent), (Some(CommandKind::Turn), 1));
    assert!((turn.angle_rad + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert!(turn.command_id & ID_BASE != 0);
    // Nothing more while it turns; the dash once the turn is done.
    assert_eq!(a.on_odometry(&odo(t + 0.5, 0.0, true, turn.command_id)), None);
    let dash = a.on_odometry(&odo(t + 2.0, 0.0, false, turn.command_id)).expect("dashes");
    assert_eq!((dash.kind(), dash.distance_m, dash.urgent), (Some(CommandKind::Move), 0.9, 1));
    // The object goes on by: the readings stop closing, and the evasion ends after the dash.
    a.on_ring(&ring(t + 2.1, 8.0, 1.0, 4.0));
    a.on_ring(&ring(t + 2.25, 8.0, 1.0, 4.0));
    assert_eq!(a.on_odometry(&odo(t + 4.0, 0.9, false, dash.command_id)), None);
    assert!(!a.evading());
    assert_eq!(a.episodes, 1);
}

#[test]
fn a_spurious_reading_or_a_slow_drift_does_not_trigger() {
    let mut a = PanicAvoid::new(P);
    let ranges = [3.0, 3.0, 1.5, 3.0, 3.0, 2.98, 2.96, 2.94, 2.92, 2.90];
    for (k, &r) in ranges.iter().enumerate() {
        let t = 0.15 * k as f64;
        a.on_odometry(&odo(t, 0.0, false, 1));
        assert_eq!(a.on_ring(&ring(t, r, 2.0, 2.0)), None, "reading {k}");
    }
    assert_eq!(a.episodes, 0);
}

#[test]
fn a_refused_turn_is_sent_again() {
    let mut a = PanicAvoid::new(P);
    let mut k = 0;
    while !a.evading() {
        let t = 0.15 * k as f64;
        a.on_odometry(&odo(t, 0.0, false, 7));
        a.on_ring(&ring(t, (3.0 - 0.6 * t) as f32, 4.0, 1.0));
        k += 1;
        assert!(k < 20, "never fired");
    }
    let turn = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("turns");
    assert!(turn.angle_rad > 0.0, "left is clearer");
    assert_eq!(a.on_odometry(&odo(2.5, 0.0, false, 7)), None, "give it time");
    let again = a.on_odometry(&odo(3.1, 0.0, false, 7)).expect("sent again");
    assert_eq!(again.kind(), Some(CommandKind::Turn));
    assert_ne!(again.command_id, turn.command_id);
}

//! Panic-avoid's tests: what is and is not an approach (a wall, a turn, a jump to another
//! surface), the stop, the turn to the clear side and the dash, and a refused turn sent again.

use super::*;
use harvey_msgs::Pose2;

pub(super) const P: AvoidParams = AvoidParams {
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
pub(super) fn ring(t: f64, ahead: f32, left: f32, right: f32) -> SonarRing {
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

pub(super) fn odo(t: f64, x: f64, moving: bool, id: u32) -> Odometry {
    Odometry {
        header: Header::new(1, (t * 1e9) as u64),
        world_from_robot: Pose2 { x_m: x, ..Pose2::default() },
        moving: u32::from(moving),
        command: MotionCommand { command_id: id, ..MotionCommand::default() },
        command_accepted: 1,
        ..Odometry::default()
    }
}

/// The robot stands still (its last command 7); something comes at it from 3 m at 0.6 m/s,
/// the walls `left` and `right` m away; until the reflex fires.
fn bearing_down(a: &mut PanicAvoid, left: f32, right: f32) {
    for k in 0..20 {
        let t = 0.15 * f64::from(k);
        a.on_odometry(&odo(t, 0.0, false, 7));
        a.on_ring(&ring(t, (3.0 - 0.6 * t) as f32, left, right));
        if a.evading() {
            return;
        }
    }
    panic!("never fired");
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
fn a_dash_is_cut_short_of_what_the_panic_stop_watches_not_only_of_what_is_dead_ahead() {
    let mut a = PanicAvoid::new(P);
    bearing_down(&mut a, 4.0, 1.0);
    let turn = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("turns");
    assert_eq!(a.on_odometry(&odo(2.5, 0.0, true, turn.command_id)), None);
    // Turned to face a doorway: straight ahead reads 3 m into the room, the sensor 15 degrees
    // off reads its jamb 0.8 m away, which the panic-stop (30 degrees either way) watches.
    let mut r = ring(3.0, 3.0, 1.0, 1.0);
    r.range_m[1] = 0.8;
    a.on_ring(&r);
    let dash = a.on_odometry(&odo(3.5, 0.0, false, turn.command_id)).expect("dashes");
    assert_eq!(dash.kind(), Some(CommandKind::Move));
    assert!((dash.distance_m - (0.8 - P.stop_m - DASH_MARGIN_M)).abs() < 1e-6, "{dash:?}");
}

#[test]
fn a_refused_turn_is_sent_again() {
    let mut a = PanicAvoid::new(P);
    bearing_down(&mut a, 4.0, 1.0);
    let turn = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("turns");
    assert!(turn.angle_rad > 0.0, "left is clearer");
    assert_eq!(a.on_odometry(&odo(2.5, 0.0, false, 7)), None, "give it time");
    let again = a.on_odometry(&odo(3.1, 0.0, false, 7)).expect("sent again");
    assert_eq!(again.kind(), Some(CommandKind::Turn));
    assert_ne!(again.command_id, turn.command_id);
}

#[test]
fn one_dash_once_the_object_has_gone_whatever_the_ring_s_noise() {
    // Twenty draws of the noise: a rule that ends the evasion on a ring that happens to show
    // nothing closing passes some of them.
    for draw in 1..=20_u64 {
        let (steps, held_s) = evade_then_noise(draw);
        assert_eq!(steps, [Some(CommandKind::Move)], "draw {draw}: the dash, and nothing more");
        // The turn and the dash take a second each.
        assert!(held_s < 2.5, "draw {draw}: the reflex held the robot {held_s} s after its turn");
    }
}

/// Every sensor reads a still scene 1.5-2.7 m away with uniform noise of +-5 cm (sd 2.9 cm,
/// harsh's range noise): some sensor of the 24 shows a reading closing on most rings, but none
/// several in a row. An object comes at the robot head-on and has gone once it has turned.
/// The steps the reflex sends after its turn, and how long after the turn it was evading.
fn evade_then_noise(draw: u64) -> (Vec<Option<CommandKind>>, f64) {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64.wrapping_mul(draw);
    let mut noise = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 0.1 - 0.05
    };
    let mut noisy = |t: f64, ahead: Option<f64>| {
        let mut r = ring(t, 2.0, 1.0, 1.5);
        for (i, range) in r.range_m.iter_mut().enumerate() {
            *range = (1.5 + 0.05 * i as f64 + noise()) as f32;
        }
        if let Some(m) = ahead {
            r.range_m[0] = m as f32;
        }
        r
    };
    let mut a = PanicAvoid::new(P);
    let mut k = 0;
    while !a.evading() {
        let t = 0.15 * k as f64;
        a.on_odometry(&odo(t, 0.0, false, 7));
        a.on_ring(&noisy(t, Some(3.5 - 0.6 * t)));
        k += 1;
        assert!(k < 30, "never fired");
    }
    let mut last = a.on_odometry(&odo(0.15 * k as f64, 0.0, false, 7)).expect("turns").command_id;
    let turned = 0.15 * k as f64;
    let (mut steps, mut held_until, mut sent) = (Vec::new(), turned, turned);
    for j in k..k + 100 {
        let t = 0.15 * j as f64;
        assert_eq!(a.on_ring(&noisy(t, None)), None, "no new evasion from noise, at {t} s");
        // Each step the reflex sends takes a second.
        if let Some(c) = a.on_odometry(&odo(t + 0.05, 0.0, t < sent + 1.0, last)) {
            (last, sent) = (c.command_id, t);
            steps.push(c.kind());
        }
        if a.evading() {
            held_until = t;
        }
    }
    assert_eq!(a.episodes, 1);
    (steps, held_until - turned)
}

#[test]
fn a_step_runs_to_its_end_while_odometry_names_a_refused_command() {
    let mut a = PanicAvoid::new(P);
    bearing_down(&mut a, 4.0, 1.0);
    let turn = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("turns");
    // The executive goes on publishing (the bridge refuses it): odometry names its command 8,
    // not accepted, while the vehicle turns for three seconds.
    let refused = |t: f64, moving: bool| Odometry { command_accepted: 0, ..odo(t, 0.0, moving, 8) };
    for j in 1..=30 {
        let t = 2.0 + 0.1 * f64::from(j);
        assert_eq!(a.on_odometry(&refused(t, true)), None, "turning, at {t} s: nothing sent again");
    }
    let dash = a.on_odometry(&refused(5.1, false)).expect("the turn is over: the dash");
    assert_eq!(dash.kind(), Some(CommandKind::Move));
    assert_ne!(dash.command_id, turn.command_id);
}

#[test]
fn with_no_room_to_dash_either_way_the_robot_keeps_still_instead_of_turning() {
    let mut a = PanicAvoid::new(P);
    // Walls 0.7 m left and right: a dash needs 0.61 + 0.05 + 0.1 m.
    bearing_down(&mut a, 0.7, 0.7);
    let hold = a.on_odometry(&odo(2.0, 0.0, false, 7)).expect("holds");
    assert_eq!((hold.kind(), hold.urgent), (Some(CommandKind::Stop), 1));
    // The object goes by: the hold ends, the robot never turned.
    a.on_ring(&ring(2.1, 8.0, 0.7, 0.7));
    assert_eq!(a.on_odometry(&odo(2.2, 0.0, false, hold.command_id)), None);
    assert!(!a.evading());
}

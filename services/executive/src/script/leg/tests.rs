//! A leg's tests: open loop, servoed with its looks' corrections, and the mount measured
//! by the first look (or kept, when a reflex interrupts it).

use super::*;

fn setup() -> ServoSetup {
    test_setup()
}

#[test]
fn an_open_loop_leg_is_its_increments() {
    let mut leg = Leg::new(Pose2::default(), 1.5, 0.6, None);
    assert_eq!(leg.start(), LegStep::Move(0.6));
    assert_eq!(leg.on_done(), LegStep::Move(0.6));
    let LegStep::Move(last) = leg.on_done() else { panic!("a third increment") };
    assert!((last - 0.3).abs() < 1e-12);
    assert_eq!(leg.on_done(), LegStep::Done);
}

#[test]
fn a_servoed_leg_looks_after_each_increment_and_turns_the_correction() {
    let mut leg = Leg::new(Pose2::default(), 1.2, 0.6, Some(setup()));
    assert_eq!(leg.start(), LegStep::Move(0.6));
    let LegStep::Look(at) = leg.on_done() else { panic!("looks") };
    assert!((at.x_m - 0.6).abs() < 1e-12 && at.y_m == 0.0);
    // Seen where expected from the line (x left = f * 0.2 / 15.4): no heading error.
    let u = 320.0 - 554.0 * (0.2f64 / 15.4);
    let LegStep::Turn(t) = leg.on_seen(Some([u, 240.0])) else { panic!("turns") };
    assert!(t.abs() < 1e-9, "{t}");
    assert_eq!(leg.on_done(), LegStep::Move(0.6));
    // Seen 10 px right of where expected: the robot is turned left; it turns back right.
    let LegStep::Look(_) = leg.on_done() else { panic!("looks") };
    let u = 320.0 - 554.0 * (0.2f64 / 14.8) + 10.0;
    assert_eq!(leg.on_seen(Some([u, 240.0])), LegStep::Done, "the last increment ends the leg");
    let (h, turn) = leg.corrections[1];
    assert!(h > 0.0 && turn < 0.0 && (h - (10.0f64 / 554.0).atan()).abs() < 2e-3, "{h} {turn}");
    // A miss skips the correction.
    let mut leg = Leg::new(Pose2::default(), 1.2, 0.6, Some(setup()));
    leg.start();
    leg.on_done();
    assert_eq!(leg.on_seen(None), LegStep::Move(0.6));
    assert_eq!(leg.misses, 1);
    // A match 60 px off (6 degrees: no 0.6 m increment turns that far) is refused.
    let u = 320.0 - 554.0 * (0.2f64 / 15.4) + 60.0;
    let LegStep::Look(_) = leg.on_done() else { panic!("looks") };
    assert_eq!(leg.on_seen(Some([u, 240.0])), LegStep::Done, "refused: no turn");
    assert_eq!((leg.misses, leg.refused, leg.corrections.len()), (2, 1, 0));
}

#[test]
fn a_calibrating_leg_measures_the_mount_first_and_then_sees_through_it() {
    let s = ServoSetup { calibrate: true, point: [16.0, 0.2, 3.3], ..setup() };
    let (yaw, pitch) = (0.01, -0.004);
    // Where a camera yawed left by `yaw` and tilted down by `pitch` sees the point from
    // `ahead` m before it on the line.
    let seen = |ahead: f64| {
        let u = 320.0 - 554.0 * ((0.2f64).atan2(ahead) - yaw).tan();
        let v = 240.0 - 554.0 * ((1.0f64).atan2(ahead) + pitch).tan();
        [u, v]
    };
    let mut leg = Leg::new(Pose2::default(), 1.2, 0.6, Some(s));
    assert_eq!(leg.start(), LegStep::Look(Pose2::default()), "looks before moving");
    assert!(leg.discovering(), "the first look, the mount unknown, discovers the landmark");
    assert_eq!(leg.on_seen(Some(seen(16.0))), LegStep::Move(0.6));
    assert!(!leg.discovering());
    assert!((leg.mount_rad.0 - yaw).abs() < 1e-12 && (leg.mount_rad.1 - pitch).abs() < 1e-12);
    let LegStep::Look(_) = leg.on_done() else { panic!("looks") };
    // On the line after the increment, seen through the same mount: nothing to correct, and
    // the distance from the row is right (no shortfall).
    let LegStep::Turn(t) = leg.on_seen(Some(seen(15.4))) else { panic!("turns") };
    assert!(t.abs() < 1e-9 && leg.shortfall_m.abs() < 1e-9, "{t} {}", leg.shortfall_m);
    // A reflex during the first look: the mount stays as configured, the increment follows.
    let mut interrupted = Leg::new(Pose2::default(), 1.2, 0.6, Some(s));
    interrupted.start();
    assert_eq!(interrupted.skip_calibration(), LegStep::Move(0.6));
    assert!(!interrupted.discovering() && interrupted.misses == 1);
    assert_eq!(interrupted.mount_rad, (s.params.misalignment_rad, 0.0));
    // Unmeasured, the same sightings steer off the line.
    let mut blind = Leg::new(Pose2::default(), 1.2, 0.6, Some(setup()));
    blind.start();
    blind.on_done();
    let LegStep::Turn(t) = blind.on_seen(Some(seen(15.4))) else { panic!("turns") };
    assert!(t.abs() > 0.01, "{t}");
}

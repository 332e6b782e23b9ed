//! Tests of the UMS state machine: growth from odometry, sightings at their stamps (late ones
//! replayed), rejection of bad input without corrupting the map, and "lost".

use harvey_msgs::{CommandKind, Header, LandmarkSighting, MotionCommand, Odometry, SightingKind};

use crate::{Config, Output, Ums};

pub(crate) fn hallway() -> harvey_world::World {
    harvey_world::load_str(include_str!("../../../worlds/hallway.toml"), "hallway").expect("hallway")
}

/// The tests' configuration, measuring the mount through `mount_gate` or not.
pub(crate) fn config(mount_gate: Option<crate::mount::Gate>) -> Config {
    Config {
        sigmas: 3.0,
        lost_area_m2: 0.05,
        lost_after_misses: 2,
        history_ns: 2_000_000_000,
        image_px: (640, 480),
        fix_m: 0.05,
        fix_heading_rad: 0.01,
        mount_gate,
    }
}

fn ums() -> Ums {
    Ums::new(hallway(), config(None))
}

pub(crate) fn odo(stamp_ms: u64, travelled_m: f64) -> Odometry {
    let command = MotionCommand {
        kind: CommandKind::Move as u32,
        distance_m: 5.0,
        command_id: 1,
        ..Default::default()
    };
    Odometry {
        header: Header::new(stamp_ms, stamp_ms * 1_000_000),
        travelled_m,
        command,
        command_accepted: 1,
        moving: 1,
        ..Default::default()
    }
}

fn map_of(out: &[Output]) -> &harvey_msgs::UncertaintyMap {
    out.iter().find_map(|o| if let Output::Map(m) = o { Some(&**m) } else { None }).expect("a map")
}

fn sighting(stamp_ms: u64, landmark: &str, kind: SightingKind, a: f64, b: f64) -> LandmarkSighting {
    let index = hallway().landmarks.iter().position(|l| l.name == landmark).expect("landmark") as u32;
    LandmarkSighting {
        header: Header::new(1, stamp_ms * 1_000_000),
        landmark_index: index,
        kind: kind as u32,
        a,
        a_sd: 0.005,
        b,
        b_sd: 0.05,
        ..Default::default()
    }
}

#[test]
fn odometry_grows_the_map_and_the_expecter_looks_ahead() {
    let mut u = ums();
    let mut last = 0.0;
    for k in 1..=20 {
        let out = u.on_odometry(&odo(k * 50, k as f64 * 0.2)).expect("ok");
        let m = map_of(&out);
        assert!(m.area_m2 >= last);
        last = m.area_m2;
        assert!(
            (m.centre.x_m - k as f64 * 0.2 * (1.0 - 0.042)).abs() < 0.01,
            "centre follows the mean motion"
        );
    }
    let out = u.on_odometry(&odo(1050, 4.0)).expect("ok");
    let windows: Vec<_> = out.iter().filter(|o| matches!(o, Output::Expectation(_))).collect();
    assert!(!windows.is_empty(), "landmarks down the hall are expected");
}

#[test]
fn a_late_sighting_applies_at_its_stamp_and_the_growth_since_is_replayed() {
    let mut u = ums();
    for k in 1..=10 {
        u.on_odometry(&odo(k * 50, k as f64 * 0.3)).expect("ok");
    }
    let before = u.map().clone();
    // At t = 300 ms the robot was on the centre line, heading along the hall: the north
    // baseboard (a ground line along +x at y = 1) runs parallel, 1 m to its left.
    u.on_sighting(&sighting(300, "north-baseboard", SightingKind::GroundLine, 0.0, -1.0)).expect("applied");
    let after = u.map();
    assert!(after.area_m2() < before.area_m2(), "{} -> {}", before.area_m2(), after.area_m2());
    assert!(after.cw_rad + after.ccw_rad < before.cw_rad + before.ccw_rad);
    // A sighting older than the history is out of order: rejected, the map untouched.
    let snapshot = u.map().clone();
    let mut old = sighting(0, "north-baseboard", SightingKind::GroundLine, 0.0, -1.0);
    old.header.stamp_ns = 10;
    assert!(u.on_sighting(&old).expect_err("too old").to_string().contains("stamps out of order"));
    assert_eq!(u.map(), &snapshot);
}

#[test]
fn bad_sightings_are_rejected_with_reasons_and_never_corrupt_the_map() {
    let mut u = ums();
    for k in 1..=5 {
        u.on_odometry(&odo(k * 50, k as f64 * 0.2)).expect("ok");
    }
    let snapshot = u.map().clone();
    let mut unknown = sighting(100, "office-sign", SightingKind::Bearing, 0.0, 0.0);
    unknown.landmark_index = 999;
    assert!(
        u.on_sighting(&unknown)
            .expect_err("unknown")
            .to_string()
            .contains("landmark #999 which is not in the world")
    );
    let nan = sighting(100, "office-sign", SightingKind::Bearing, f64::NAN, 0.0);
    assert!(u.on_sighting(&nan).expect_err("nan").to_string().contains("non-finite"));
    // The office sign straight behind the robot: no pose in the map sees it there.
    let impossible = sighting(100, "office-sign", SightingKind::BearingRange, std::f64::consts::PI, 3.0);
    assert!(u.on_sighting(&impossible).is_err());
    assert_eq!(u.map(), &snapshot);
    assert!(
        u.on_odometry(&odo(10, 0.0)).expect_err("old odometry").to_string().contains("older than the last")
    );
}

#[test]
fn too_large_a_map_or_missed_landmarks_mean_lost() {
    let mut u = ums();
    let out = u.on_odometry(&odo(50, 0.1)).expect("ok");
    assert_eq!(map_of(&out).lost, 0);
    for k in 0..2 {
        u.on_sighting(&sighting(50, "office-sign", SightingKind::NotFound, 0.0, 0.0)).expect("a miss");
        let out = u.on_odometry(&odo(100 + k * 50, 0.1)).expect("ok");
        assert_eq!(map_of(&out).missed_landmarks, k as u32 + 1);
    }
    assert_eq!(map_of(&u.on_odometry(&odo(300, 0.1)).expect("ok")).lost, 1, "two misses");
    let mut far = ums();
    let out = far.on_odometry(&odo(50, 6.0)).expect("ok");
    assert!(map_of(&out).area_m2 > 0.05);
    assert_eq!(map_of(&out).lost, 1, "area over the limit");
}

#[test]
fn a_pose_fix_shrinks_the_map_at_its_stamp_and_a_bad_one_is_refused() {
    let mut u = ums();
    for k in 0..=20 {
        u.on_odometry(&odo(100 * k, 0.25 * k as f64)).expect("odometry");
    }
    let grown = u.map().area_m2();
    assert!(grown > 0.01, "{grown}");
    // Fixed at 1.5 s (3.75 m travelled) to 4 cm to the left of the odometry's line.
    let fix = harvey_msgs::PoseFix {
        header: Header::new(1, 1_500_000_000),
        refined: harvey_msgs::Pose2 { x_m: 3.75, y_m: 0.04, heading_rad: 0.0 },
        ..Default::default()
    };
    u.on_fix(&fix).expect("applies");
    // A 10 cm square then, grown over the 1.25 m since: far smaller than before.
    let fixed = u.map().area_m2();
    assert!(fixed < grown / 4.0 && fixed > 0.01, "{fixed} against {grown}");
    let c = u.map().centre;
    assert!((c[0] - 5.0).abs() < 0.1 && (c[1] - 0.04).abs() < 0.01, "{c:?}");
    let bad = harvey_msgs::PoseFix { refined: harvey_msgs::Pose2 { x_m: f64::NAN, ..fix.refined }, ..fix };
    assert!(u.on_fix(&bad).expect_err("refused").to_string().contains("non-finite"));
    assert_eq!(u.map().area_m2(), fixed);
}

#[test]
fn a_sighting_rejected_when_it_falls_due_costs_neither_the_map_nor_the_expectations() {
    let mut u = ums();
    for k in 1..=5 {
        u.on_odometry(&odo(k * 50, k as f64 * 0.2)).expect("ok");
    }
    // Stamped after the odometry so far, so held until odometry reaches it; then impossible.
    let impossible = sighting(300, "office-sign", SightingKind::BearingRange, std::f64::consts::PI, 3.0);
    u.on_sighting(&impossible).expect("held until due");
    let out = u.on_odometry(&odo(300, 1.2)).expect("the odometry itself is sound");
    assert_eq!(map_of(&out).header.seq, 6, "the map goes out, next in sequence");
    assert!(out.iter().any(|o| matches!(o, Output::Expectation(_))));
    let why: Vec<String> = out
        .iter()
        .filter_map(|o| if let Output::Rejected(e) = o { Some(e.to_string()) } else { None })
        .collect();
    assert_eq!(why.len(), 1, "{why:?}");
    assert!(why[0].contains("sighting of `office-sign`"), "{why:?}");
}

#[test]
fn expectations_are_numbered_one_by_one_across_maps() {
    let mut u = ums();
    let mut seqs = Vec::new();
    for k in 1..=20 {
        let out = u.on_odometry(&odo(k * 50, k as f64 * 0.2)).expect("ok");
        seqs.extend(
            out.iter().filter_map(|o| if let Output::Expectation(e) = o { Some(e.header.seq) } else { None }),
        );
    }
    assert!(seqs.len() > 20, "several windows per map: {}", seqs.len());
    assert_eq!(seqs, (1..=seqs.len() as u64).collect::<Vec<_>>());
}

#[test]
fn a_restored_ums_goes_on_as_the_original_would() {
    let mut a = ums();
    for k in 1..=12 {
        a.on_odometry(&odo(k * 50, k as f64 * 0.2)).expect("ok");
    }
    // A sighting waiting for its odometry travels in the state too.
    let _ = a.on_sighting(&sighting(650, "end-wall-corner", SightingKind::Bearing, 0.01, 0.0));
    let bytes = postcard::to_allocvec(&a.state()).expect("encodes");
    let mut b = ums();
    b.restore(postcard::from_bytes(&bytes).expect("decodes"));
    assert_eq!(b.state(), a.state());
    // A fresh UMS would not go on so: it starts from the start's point.
    let fresh = ums().on_odometry(&odo(13 * 50, 13.0 * 0.2)).expect("ok");
    for k in 13..=30 {
        let (x, y) =
            (a.on_odometry(&odo(k * 50, k as f64 * 0.2)), b.on_odometry(&odo(k * 50, k as f64 * 0.2)));
        let (x, y) = (x.expect("ok"), y.expect("ok"));
        if k == 13 {
            assert_ne!(map_of(&fresh), map_of(&y));
        }
        assert_eq!(x, y, "tick {k}");
    }
}

//! Path following's behaviour on made-up fits: steering, the width check, bends and the end.

use super::*;

fn campus() -> World {
    harvey_world::load_str(include_str!("../../../../worlds/campus.toml"), "campus").expect("world")
}

fn goal() -> PathGoal {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../missions/path-follow.toml"))
            .expect("mission");
    crate::mission::parse(&text, "path-follow.toml").expect("parses").path.expect("[mission.path]")
}

#[test]
fn the_campus_path_is_three_segments_of_its_width_and_the_first_request_is_symmetric() {
    let p = in_world(&goal(), &campus()).expect("built");
    let lengths: Vec<f64> = p.segments.iter().map(Segment::length_m).collect();
    assert!((lengths[0] - 30.0).abs() < 1e-3 && (lengths[1] - 12.0 * 2f64.sqrt()).abs() < 1e-3);
    assert!((lengths[2] - 22.0).abs() < 1e-3, "{lengths:?}");
    assert!(p.segments.iter().all(|s| (s.width_m - 3.0).abs() < 1e-3));
    // On the centreline, heading along it: the edges mirror each other about the centre column.
    let r = p.request.expect("a request");
    assert_eq!((r.standing, r.algorithm), (1, VisionAlgorithm::Path as u32));
    assert!(
        (r.params[0] + r.params[2] - 640.0).abs() < 1e-3 && (r.params[1] + r.params[3] - 640.0).abs() < 1e-3
    );
    let goal = p.goal_pose();
    assert!((goal.x_m - 58.0).abs() < 1e-3 && (goal.y_m + 12.0).abs() < 1e-3);
}

#[test]
fn a_fit_left_of_the_robot_steers_it_left_and_the_bend_turns_it_right() {
    let mut p = in_world(&goal(), &campus()).expect("built");
    let (_, c, _) = p.on_odometry(Pose2::default(), 1);
    assert!(c.linear_mps > 0.0 && c.angular_radps.abs() < 1e-9, "along the centreline: {c:?}");
    // The path seen 0.5 m to the left: the centreline crosses the bottom row left of centre.
    let mut r = VisionResult {
        request_id: REQUEST_ID,
        status: VisionStatus::Found as u32,
        count: 3,
        ..VisionResult::default()
    };
    r.header.stamp_ns = 1;
    let z = 554.0 * 1.2 / 239.0;
    let (bl, br) = (320.0 - 554.0 * 2.0 / z, 320.0 + 554.0 * 1.0 / z);
    r.items[0].values = [320.0, 240.0, ((bl + br) / 2.0) as f32, 479.0, 200.0, 0.0];
    let edge = |b: f64| [320.0, 240.0, (239.0f64).atan2(b - 320.0) as f32, 0.0, 0.0, 0.0];
    (r.items[1].values, r.items[2].values) = (edge(bl), edge(br));
    p.on_vision(&r);
    let seen = p.last.expect("taken");
    assert!((seen.offset_m + 0.5).abs() < 1e-3 && (seen.width_m - 3.0).abs() < 1e-3, "{seen:?}");
    let (_, c, _) = p.on_odometry(Pose2::default(), 2);
    assert!(c.angular_radps > 0.0, "towards the centreline: {c:?}");
    // At the first bend (by the UMS's pose) the robot stops and turns 45 degrees right.
    let mut m = UncertaintyMap::default();
    (m.header.stamp_ns, m.centre) = (3, Pose2::new(28.05, 0.0, 0.0));
    p.on_odometry(Pose2::default(), 3);
    p.on_map(&m);
    let (_, c, _) = p.on_odometry(Pose2::default(), 4);
    assert_eq!(c.linear_mps, 0.0);
    let (_, c, _) = p.on_odometry(Pose2::default(), 5);
    assert!(c.linear_mps == 0.0 && c.angular_radps < 0.0, "{c:?}");
    assert_eq!(p.k, 1);
}

#[test]
fn without_fits_the_tracker_starts_afresh_from_the_map_and_the_path_is_lost_later() {
    let g = goal();
    let mut p = in_world(&g, &campus()).expect("built");
    let generation = |r: Option<VisionRequest>| r.map(|r| r.params[7]);
    let at = |x: f64| Pose2::new(x, 0.0, 0.0);
    let (r, _, _) = p.on_odometry(at(0.0), 1);
    assert_eq!(generation(r), Some(0.0));
    // Fits lacking: the same tracker (window changes aside) up to `restart_after_m`, then a new
    // generation of the request, predicted from where the robot is believed to be, its window's
    // top where the last request had it.
    let (mut restarts, mut top, mut lost_at) = (Vec::new(), 0.0f32, None);
    for k in 1..=40u64 {
        let x = 0.1 * k as f64;
        let (r, c, _) = p.on_odometry(at(x), 1 + k);
        if let Some(r) = r {
            if r.params[7] > restarts.last().map_or(0.0, |r: &(f64, f32)| r.1) {
                assert!(r.window_px[1] >= top, "the restart at {x} raised the window's top");
                restarts.push((x, r.params[7]));
            }
            top = r.window_px[1];
        }
        if p.done.is_some() {
            assert_eq!((p.done, c.linear_mps), (Some(false), 0.0));
            lost_at = Some(x);
            break;
        }
    }
    assert_eq!(restarts.iter().map(|r| r.1).collect::<Vec<_>>(), [1.0, 2.0], "{restarts:?}");
    let r = g.restart_after_m;
    assert!(restarts[0].0 > r && restarts[0].0 < r + 0.15, "{restarts:?}");
    assert!(restarts[1].0 > 2.0 * r && restarts[1].0 < 2.0 * r + 0.25, "{restarts:?}");
    let lost = lost_at.expect("the path is lost");
    assert!(lost > g.lost_after_m && lost < g.lost_after_m + 0.15, "lost at {lost}");
    assert!(top > p.rows.0 as f32, "the window was cut short by the distance to the bend: {top}");
}

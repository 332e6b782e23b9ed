//! The walking skeleton end to end: `harvey run` on the default mission starts every service as a
//! process, the executive's MOVEs drive the simulated DRV over its pty, data reaches every
//! consumer, the recorder writes every topic to `run.mcap`, and everything is cleaned up.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use harvey_msgs::{
    CommandKind, MissionState, MissionStatus, MotionCommand, TruePose, UncertaintyMap, topics,
};

#[test]
fn the_default_mission_runs_records_and_cleans_up() {
    let prefix = common::unique_prefix("ws");
    let run_dir = common::scratch("walking-skeleton");
    let child = common::harvey(&[
        "run",
        "missions/default.toml",
        "--prefix",
        &prefix,
        "--run-dir",
        run_dir.to_str().expect("utf8"),
    ])
    .stdout(std::process::Stdio::piped())
    .stderr(std::process::Stdio::piped())
    .spawn()
    .expect("harvey starts");
    let out = child.wait_with_output().expect("harvey runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "harvey run failed ({}):\n{stdout}\n{stderr}", out.status);
    assert!(stdout.contains("mission: goal reached (3/3 steps)"), "{stdout}");

    assert!(!stderr.contains("exited with"), "a service failed during the mission:\n{stderr}");
    // Every service ran and stopped in reverse order of start.
    let started: Vec<&str> = [
        "recorder",
        "sim-drv",
        "denning-bridge",
        "sonar",
        "encoders",
        "camera",
        "vision-workers",
        "ums",
        "executive",
    ]
    .to_vec();
    for s in &started {
        assert!(stderr.contains(&format!("ready service={s}")), "{s} never became ready:\n{stderr}");
    }
    let stop_pos = |s: &str| {
        stderr
            .find(&format!("stopped: exit code 0 service={s}"))
            .unwrap_or_else(|| panic!("{s} not stopped cleanly:\n{stderr}"))
    };
    let stops: Vec<usize> = started[..started.len() - 1].iter().map(|s| stop_pos(s)).collect();
    assert!(stops.windows(2).all(|w| w[0] > w[1]), "services must stop in reverse order");

    // The recording holds every topic, decodable, with the mission's story in it.
    let bytes = std::fs::read(run_dir.join("run.mcap")).expect("run.mcap");
    let mut counts: BTreeMap<String, u64> = BTreeMap::new();
    let mut moves = 0;
    let mut last_status = None;
    let mut truth = Vec::new();
    let mut maps = Vec::new();
    for m in mcap::MessageStream::new(&bytes).expect("mcap") {
        let m = m.expect("valid message");
        let topic = m.channel.topic.trim_start_matches('/').to_owned();
        *counts.entry(topic.clone()).or_default() += 1;
        match topic.as_str() {
            "vehicle/command" => {
                let c: MotionCommand = harvey_cdr::decode(&m.data).expect("command decodes");
                moves += u32::from(c.kind() == Some(CommandKind::Move));
            }
            "executive/status" => {
                last_status = Some(harvey_cdr::decode::<MissionStatus>(&m.data).expect("status"))
            }
            "sim/truth" => truth.push(harvey_cdr::decode::<TruePose>(&m.data).expect("truth")),
            "ums/map" => maps.push(harvey_cdr::decode::<UncertaintyMap>(&m.data).expect("map")),
            _ => {}
        }
    }
    // The sonar reflexes speak only when something is in the way (tests/panic_avoid.rs), the
    // servoing only on servoed moves and refinements (tests/hallway.rs, tests/pose_refine.rs),
    // plan-and-monitor and the acceptor-sequenced behaviours only in their missions
    // (tests/ptrans.rs, tests/docking.rs); the services warn on rosout only when something
    // goes wrong, which a clean default run need not (tests/rosout.rs).
    let eventful = [
        topics::ROSOUT.name,
        topics::VEHICLE_REFLEX.name,
        topics::EXECUTIVE_SERVO.name,
        topics::EXECUTIVE_POSE.name,
        topics::EXECUTIVE_PLAN.name,
        topics::EXECUTIVE_BEHAVIOUR.name,
    ];
    for t in topics::ALL.iter().filter(|t| !eventful.contains(t)) {
        assert!(counts.get(*t).copied().unwrap_or(0) > 0, "no message on {t}: {counts:?}");
    }
    assert!(counts["camera/frame"] >= 50, "{counts:?}");
    assert_eq!(moves, 2, "two MOVEs in the mission");
    let status = last_status.expect("status recorded");
    assert_eq!(status.state(), Some(MissionState::Succeeded));
    assert!(
        status.sonar_rings_seen > 100 && status.detections_seen > 20 && status.maps_seen > 100,
        "{status:?}"
    );
    // The robot really moved: out 4 m (less the terrain's losses), then back 2 m.
    let max_x = truth.iter().map(|t| t.world_from_robot.x_m).fold(f64::MIN, f64::max);
    let last = truth.last().expect("truth").world_from_robot;
    assert!((3.7..4.0).contains(&max_x), "furthest {max_x}");
    assert!((last.x_m - max_x + 1.9).abs() < 0.15, "came back about 2 m: {last:?}");
    // Stamps come from simulated time: strictly increasing, 50 ms apart.
    assert!(truth.windows(2).all(|w| w[1].header.stamp_ns == w[0].header.stamp_ns + 50_000_000));

    // Vision's landmark sightings keep the UMS's map smaller than dead reckoning alone would
    // (0.58 m^2), and on this seed the map holds the true pose throughout, as the summary counts
    // it. Under the ideal condition that is checked over several seeds
    // (`tests/uncertainty_missions.rs`); with the shipped worlds' map and mount errors the map
    // loses the truth on some seeds (nominal 7, 8 and 19 of 1..20: docs/evaluation.md).
    let held = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("the true pose inside the uncertainty map: "))
        .and_then(|l| l.strip_suffix(" maps"))
        .and_then(|l| l.split_once(" of "))
        .map(|(n, of)| (n.parse::<usize>().expect("count"), of.parse::<usize>().expect("count")));
    let (n, of) = held.unwrap_or_else(|| panic!("no truth count in the summary:\n{stdout}"));
    // Strict on purpose: a change that makes the shipped run's map lose the truth is a
    // regression to look at, not noise (the map's 3-sigma promise, docs/evaluation.md).
    assert!(n == of && of > 400, "the map held the true pose in {n} of {of} maps");
    let sightings = counts.get("vision/sightings").copied().unwrap_or(0);
    assert!(sightings > 50, "door jambs recognised in their windows: {sightings}");
    let checked =
        maps.iter().filter(|m| truth.iter().any(|t| t.header.stamp_ns == m.header.stamp_ns)).count();
    assert!(checked > 400, "{checked} maps with the truth at their stamp");
    let last = maps.last().expect("maps");
    assert!(last.area_m2 < 0.3, "final area {}", last.area_m2);

    // Nothing left behind.
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(common::processes_with_prefix(&prefix), Vec::<u32>::new(), "orphaned processes");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new(), "stale shared memory");
}

//! The safe stop in real time (issue 20): the executive is killed with SIGKILL while the robot
//! drives a long MOVE; the bridge's watchdog stops the vehicle, which moves less than 0.1 m
//! after the kill (from `sim/truth` in the recording).
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::fs::File;
use std::process::Stdio;
use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter};
use harvey_msgs::{TruePose, topics};

/// Waits until `done` holds, polling every 50 ms; fails the test after `timeout`.
fn wait_for(what: &str, timeout: Duration, mut done: impl FnMut() -> bool) {
    let deadline = Instant::now() + timeout;
    while !done() {
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn executive_pid(prefix: &str) -> Option<i32> {
    harvey_bus::live_nodes(prefix).ok()?.into_iter().find(|n| n.alive && n.name == "executive").map(|n| n.pid)
}

fn moved(a: &TruePose, b: &TruePose) -> f64 {
    (a.world_from_robot.x_m - b.world_from_robot.x_m).hypot(a.world_from_robot.y_m - b.world_from_robot.y_m)
}

#[test]
fn killing_the_executive_stops_the_robot_within_a_tenth_of_a_metre() {
    let (prefix, dir) = (common::unique_prefix("ss"), common::scratch("safe-stop"));
    let log_path = dir.join("launch.log");
    let log = File::create(&log_path).expect("log file");
    let mut sup = common::harvey(&[
        "launch",
        "missions/safe-stop.toml",
        "--prefix",
        &prefix,
        "--run-dir",
        dir.to_str().expect("utf8"),
    ])
    .stdout(Stdio::from(log.try_clone().expect("log")))
    .stderr(Stdio::from(log))
    .spawn()
    .expect("harvey starts");

    // Every service is up once the executive (started last) is.
    let mut pid = None;
    wait_for("the executive", Duration::from_secs(60), || {
        pid = executive_pid(&prefix);
        pid.is_some()
    });
    let bus = Bus::join_with_prefix("safe-stop-test", &prefix).expect("join");
    let truth = bus.subscriber(topics::SIM_TRUTH).expect("truth");
    let waiter = Waiter::new().expect("waiter");
    let _t = waiter.attach(&truth).expect("attach");
    let mut seen: Vec<TruePose> = Vec::new();
    let poll = |seen: &mut Vec<TruePose>| {
        waiter.wait(Some(Duration::from_millis(100))).expect("wait");
        truth.drain(|m| seen.push(*m)).expect("drain");
    };

    // Driving: the truth has moved 5 cm from where it was first seen.
    let deadline = Instant::now() + Duration::from_secs(30);
    while !seen.last().is_some_and(|last| moved(last, &seen[0]) > 0.05) {
        assert!(Instant::now() < deadline, "the robot never moved: see {}", log_path.display());
        poll(&mut seen);
    }
    let pid = pid.expect("pid");
    // SAFETY: kill(2) on the executive this launch started.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGKILL) }, 0, "killing the executive");
    let killed_at = *seen.last().expect("a truth");

    // A second of vehicle time after the kill: long past the watchdog's 200 ms.
    let deadline = Instant::now() + Duration::from_secs(30);
    while seen.last().is_none_or(|t| t.header.stamp_ns <= killed_at.header.stamp_ns + 1_000_000_000) {
        assert!(Instant::now() < deadline, "the simulation stalled after the kill");
        poll(&mut seen);
    }
    drop(_t);
    drop((waiter, truth, bus));
    common::signal(&sup, libc::SIGTERM);
    let status = common::wait_exit(&mut sup, Duration::from_secs(30));
    let text = std::fs::read_to_string(&log_path).expect("log");
    assert_eq!(status.code(), Some(130), "stopped by the signal:\n{text}");
    assert!(text.contains("no heartbeat from the executive: stopping the vehicle"), "{text}");
    assert!(text.contains("not restarted"), "the executive stays dead:\n{text}");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());

    // From the recording: where the robot was at the kill, and how far it went afterwards.
    let bytes = std::fs::read(dir.join("run.mcap")).expect("run.mcap");
    let recorded: Vec<TruePose> = mcap::MessageStream::new(&bytes)
        .expect("mcap")
        .map(|m| m.expect("valid message"))
        .filter(|m| m.channel.topic.trim_start_matches('/') == "sim/truth")
        .map(|m| harvey_cdr::decode::<TruePose>(&m.data).expect("truth"))
        .collect();
    let at_kill = recorded
        .iter()
        .find(|t| t.header.stamp_ns == killed_at.header.stamp_ns)
        .expect("the truth at the kill is recorded");
    let after: Vec<&TruePose> =
        recorded.iter().filter(|t| t.header.stamp_ns >= at_kill.header.stamp_ns).collect();
    assert!(after.len() >= 20, "a second of truth after the kill: {}", after.len());
    let worst = after.iter().map(|t| moved(t, at_kill)).fold(0.0, f64::max);
    assert!(worst < 0.1, "the robot drove {worst:.3} m after the executive was killed");
    let _ = std::fs::remove_dir_all(&dir);
}

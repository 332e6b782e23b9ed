//! Deterministic mode and replay, across real processes: the same mission and seed record the
//! same messages (topic, log time, bytes) even when two runs share the machine; another seed does
//! not; the reference recording replays exactly through the live services; and a clock party
//! killed mid-run is restarted and the chain resumed, so the mission still ends.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::path::Path;
use std::process::Output;

fn text(out: &Output) -> String {
    format!("{}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// The run's folder (its recording is `run.mcap` there).
fn run(mission: &Path, tag: &str) -> common::Scratch {
    let (prefix, dir) = (common::unique_prefix(tag), common::scratch(tag));
    let out = common::harvey(&[
        "run",
        mission.to_str().expect("utf8"),
        "--prefix",
        &prefix,
        "--run-dir",
        dir.to_str().expect("utf8"),
    ])
    .output()
    .expect("runs");
    assert!(out.status.success(), "{}", text(&out));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    dir
}

/// The number in "identical: N messages ...".
fn agreed(out: &Output) -> usize {
    common::agreed(out).unwrap_or_else(|| panic!("no count of identical messages: {}", text(out)))
}

fn diff(a: &Path, b: &Path) -> Output {
    common::harvey(&["diff", a.to_str().expect("utf8"), b.to_str().expect("utf8")])
        .output()
        .expect("diff runs")
}

#[test]
fn the_same_seed_records_the_same_messages_and_another_seed_does_not() {
    let default = common::repo().join("missions/default.toml");
    // Two runs at once: they compete for the CPU, and must not care.
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| run(&default, "det-a"));
        let b = s.spawn(|| run(&default, "det-b"));
        (a.join().expect("run a"), b.join().expect("run b"))
    });
    let (a, b) = (a.join("run.mcap"), b.join("run.mcap"));
    let same = diff(&a, &b);
    assert_eq!(same.status.code(), Some(0), "{}", text(&same));
    let n = agreed(&same);
    assert!(n > 6000, "only {n} messages compared");

    let (_seed_dir, file) = common::at_seed(&default, 2, "det-seed");
    let c_dir = run(&file, "det-c");
    let c = c_dir.join("run.mcap");
    let other = diff(&a, &c);
    let out = String::from_utf8_lossy(&other.stdout);
    assert_eq!(other.status.code(), Some(1), "{}", text(&other));
    assert!(out.starts_with("DIFFERENT at message "), "{out}");
}

#[test]
fn the_reference_recording_replays_exactly() {
    let reference = common::repo().join("recordings/reference/default.mcap");
    let (out, prefix, dir) = common::replay_check(&reference, "replay");
    assert_eq!(
        out.status.code(),
        Some(0),
        "the reference no longer replays: if a service was meant to change its output, run \
         scripts/update-reference and say so in the commit\n{}",
        text(&out)
    );
    let bytes = std::fs::read(&reference).expect("reference");
    let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
    let recorded = summary.stats.expect("statistics").message_count as usize;
    assert!(recorded > 6000, "{recorded}");
    assert_eq!(agreed(&out), recorded, "{}", text(&out));
    assert!(text(&out).contains("replay finished"), "{}", text(&out));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    // The replay refuses to overwrite what it replays.
    let clash = common::harvey(&[
        "replay",
        dir.join("run.mcap").to_str().expect("utf8"),
        "--prefix",
        &prefix,
        "--run-dir",
        dir.to_str().expect("utf8"),
    ])
    .output()
    .expect("runs");
    assert_eq!(clash.status.code(), Some(2));
    assert!(text(&clash).contains("would overwrite"), "{}", text(&clash));
    // A cut recording is refused with the file named, before anything starts.
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).expect("written");
    let out =
        common::harvey(&["replay", cut.to_str().expect("utf8"), "--prefix", &prefix]).output().expect("runs");
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(
        text(&out).contains(&format!(
            "harvey: error: {}: no summary (run `harvey recover` on it first)",
            cut.display()
        )),
        "{}",
        text(&out)
    );
    let diff_out = diff(&cut, &reference);
    assert_eq!(diff_out.status.code(), Some(2), "{}", text(&diff_out));
    // The damage is named with its byte offset: a record longer than what the file has left.
    let said = text(&diff_out);
    assert!(
        said.contains("corrupt after") && said.contains("at byte") && said.contains("are left"),
        "{said}"
    );
}

#[test]
fn the_reference_recording_replays_exactly_in_one_process() {
    let reference = common::repo().join("recordings/reference/default.mcap");
    let (out, _, dir) = common::replay_check_with(&reference, "replay-inproc", &["--in-process"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let bytes = std::fs::read(&reference).expect("reference");
    let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
    let recorded = summary.stats.expect("statistics").message_count as usize;
    assert_eq!(agreed(&out), recorded, "{}", text(&out));
    // It says how fast it went and where the time went, party by party.
    let said = text(&out);
    assert!(said.contains("x real time") && said.contains("turns: replayer"), "{said}");
    for party in ["sonar", "encoders", "vision-workers", "ums", "executive", "recorder"] {
        assert!(said.contains(&format!(", {party} ")), "{party}: {said}");
    }
    // A launch with a service that has no node for in-process runs is refused, naming it and
    // the services that do.
    let launch = std::fs::read_to_string(common::repo().join("missions/default.toml")).expect("default")
        + "\n[[service]]\nname = \"foxglove-bridge\"\n";
    let mut rec = harvey_recording::Recorder::create(&dir.join("odd.mcap")).expect("create");
    rec.attach_launch("odd.toml", &launch).expect("launch");
    rec.attach_world(
        "w.toml",
        &std::fs::read_to_string(common::repo().join("worlds/hallway.toml")).expect("world"),
        1,
    )
    .expect("world");
    rec.finish().expect("finish");
    let odd = common::harvey(&["replay", "--in-process", dir.join("odd.mcap").to_str().expect("utf8")])
        .args(["--run-dir", dir.join("odd").to_str().expect("utf8")])
        .output()
        .expect("runs");
    assert_eq!(odd.status.code(), Some(2), "{}", text(&odd));
    assert!(
        text(&odd).contains("service foxglove-bridge (harvey-foxglove-bridge) has no node registered for in-process runs; these can run in process: harvey-sonar"),
        "{}",
        text(&odd)
    );
    // A recording whose messages another Harvey laid out otherwise is refused, naming the topic,
    // before anything starts.
    let foreign = dir.join("foreign.mcap");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&foreign).expect("create")))
        .expect("writer");
    let schema =
        w.add_schema("harvey_msgs/msg/MotionCommand", "ros2msg", b"float32 distance_m\n").expect("schema");
    let channel = w.add_channel(schema, "/vehicle/command", "cdr", &Default::default()).expect("channel");
    let header =
        mcap::records::MessageHeader { channel_id: channel, sequence: 1, log_time: 1, publish_time: 1 };
    w.write_to_known_channel(&header, &[0, 1, 0, 0, 0, 0, 0, 0]).expect("message");
    w.finish().expect("finish");
    for how in [&["--in-process"][..], &[][..]] {
        let out = common::harvey(&["replay", foreign.to_str().expect("utf8")])
            .args(how)
            .args(["--run-dir", dir.join("foreign").to_str().expect("utf8")])
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2), "{}", text(&out));
        assert!(
            text(&out).contains("its messages are not this build's (/vehicle/command: harvey_msgs/msg/MotionCommand is defined otherwise than in this build)"),
            "{}",
            text(&out)
        );
        assert!(!dir.join("foreign").exists(), "nothing written");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_clock_party_killed_mid_run_is_resumed_and_the_mission_ends() {
    let (prefix, dir) = (common::unique_prefix("det-kill"), common::scratch("det-kill"));
    let mut child = common::harvey(&[
        "run",
        "missions/default.toml",
        "--prefix",
        &prefix,
        "--run-dir",
        dir.to_str().expect("utf8"),
    ])
    .stdout(std::process::Stdio::piped())
    .stderr(std::process::Stdio::piped())
    .spawn()
    .expect("starts");
    // Kill the sonar once odometry has flowed for a while (the chain is running).
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let sonar = loop {
        assert!(std::time::Instant::now() < deadline, "the sonar never came up");
        let nodes = harvey_bus::live_nodes(&prefix).unwrap_or_default();
        if let Some(n) = nodes.iter().find(|n| n.alive && n.name == "sonar")
            && nodes.iter().any(|n| n.alive && n.name == "executive")
        {
            break n.pid;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    std::thread::sleep(std::time::Duration::from_millis(300));
    // SAFETY: kill(2) on a process of this test's own launch.
    unsafe { libc::kill(sonar, libc::SIGKILL) };
    let status = common::wait_exit(&mut child, std::time::Duration::from_secs(120));
    let out = child.wait_with_output().expect("output");
    let all = text(&out);
    assert!(status.success(), "{all}");
    assert!(all.contains("restarted service=sonar"), "{all}");
    assert!(all.contains("goal reached (3/3 steps)"), "{all}");
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
}

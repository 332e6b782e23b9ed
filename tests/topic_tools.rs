//! `harvey topic list | echo | hz` and `harvey iox2-config` on a running domain: the default
//! mission run in real time (`harvey run --realtime`), looked at from outside while it runs.
//! The sonar ring comes at about 20 Hz of wall time; what `echo` prints is what the recorder
//! recorded, message for message.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use harvey_msgs::Odometry;

fn json_lines(out: &std::process::Output) -> Vec<serde_json::Value> {
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect()
}

#[test]
fn a_realtime_run_is_listed_echoed_and_timed_from_outside() {
    let (prefix, dir) = (common::unique_prefix("topic"), common::scratch("topic"));
    let mut run =
        common::harvey(&["run", "--realtime", "--prefix", &prefix, "--run-dir", dir.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("harvey run");

    // The ring at about 20 Hz by the wall clock (each of its messages is one tick of 50 ms).
    let hz = common::harvey(&["topic", "hz", "sonar/ring", "--prefix", &prefix, "--count", "40", "--json"])
        .args(["--wait-s", "30", "--timeout-s", "10"])
        .output()
        .expect("hz");
    let rates = json_lines(&hz);
    let last = rates.last().expect("a rate");
    let rate = last["rate_hz"].as_f64().expect("rate_hz");
    assert!((15.0..=25.0).contains(&rate), "sonar/ring at {rate} Hz: {rates:?}");
    assert_eq!(last["window"], 39, "40 messages, 39 intervals");

    let list = json_lines(
        &common::harvey(&["topic", "list", "--prefix", &prefix, "--json"]).output().expect("list"),
    );
    let ring = list.iter().find(|t| t["topic"] == "sonar/ring").expect("sonar/ring listed");
    assert_eq!(ring["type"], "harvey_msgs/SonarRing");
    let nodes: Vec<&str> = ring["nodes"].as_array().unwrap().iter().filter_map(|n| n.as_str()).collect();
    assert!(nodes.contains(&"sonar") && nodes.contains(&"recorder"), "{nodes:?}");
    assert!(list.iter().any(|t| t["topic"] == "camera/frame"), "{list:?}");

    let echo = common::harvey(&["topic", "echo", "/odometry", "--prefix", &prefix, "--count", "5", "--json"])
        .args(["--timeout-s", "10"])
        .output()
        .expect("echo");
    let echoed = json_lines(&echo);
    assert_eq!(echoed.len(), 5);
    let frame = json_lines(
        &common::harvey(&["topic", "echo", "camera/frame", "--prefix", &prefix, "--count", "1", "--json"])
            .args(["--timeout-s", "10"])
            .output()
            .expect("echo frame"),
    );
    assert_eq!((frame[0]["width"].as_u64(), frame[0]["encoding"].as_str()), (Some(640), Some("mono8")));

    let config = common::harvey(&["iox2-config", "--prefix", &prefix]).output().expect("iox2-config");
    let config = String::from_utf8_lossy(&config.stdout);
    assert!(config.contains(&format!("prefix = \"{prefix}\"")), "{config}");

    // Bad input: a topic Harvey does not have, a domain with nothing in it.
    let bad = common::harvey(&["topic", "echo", "no/such", "--prefix", &prefix, "--wait-s", "0.2"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(
        String::from_utf8_lossy(&bad.stderr).contains("no topic `no/such`"),
        "{}",
        String::from_utf8_lossy(&bad.stderr)
    );

    // The run is stopped early; the recording holds what echo printed, decoded the same way.
    common::signal(&run, libc::SIGINT);
    common::wait_exit(&mut run, Duration::from_secs(30));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    let mcap = std::fs::read(dir.join("run.mcap")).expect("recording");
    let mut recorded = BTreeMap::new();
    for m in mcap::MessageStream::new(&mcap).expect("mcap") {
        let m = m.expect("message");
        if m.channel.topic == "/odometry" {
            let o: Odometry = harvey_cdr::decode(&m.data).expect("odometry");
            recorded.insert(o.header.seq, o);
        }
    }
    for e in &echoed {
        let seq = e["seq"].as_u64().expect("seq");
        let o = recorded.get(&seq).unwrap_or_else(|| panic!("odometry {seq} is not in the recording"));
        let stamp = e["header"]["stamp"]["sec"].as_u64().unwrap() * 1_000_000_000
            + e["header"]["stamp"]["nanosec"].as_u64().unwrap();
        assert_eq!(stamp, o.header.stamp_ns);
        assert_eq!(e["world_from_robot"]["x_m"].as_f64(), Some(o.world_from_robot.x_m));
        assert_eq!(e["travelled_m"].as_f64(), Some(o.travelled_m));
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The camera's frames have room for the recorder, the vision workers and observers: two
/// observers started before the launch do not take a service's slot (the launch comes up), and
/// when every slot is taken the refusal names the nodes that hold them.
#[test]
fn observers_of_the_camera_leave_the_services_their_slots_and_a_full_topic_names_its_holders() {
    let (prefix, dir) = (common::unique_prefix("slots"), common::scratch("slots"));
    let observe = || {
        common::harvey(&["topic", "hz", "camera/frame", "--prefix", &prefix, "--wait-s", "60"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("observer")
    };
    let mut observers = vec![observe(), observe()];
    let mut run =
        common::harvey(&["run", "--realtime", "--prefix", &prefix, "--run-dir", dir.to_str().unwrap()])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("harvey run");
    // Wait until the observers, the recorder and the vision workers are on the camera's topic.
    let mut holders = |want: usize| {
        let deadline = std::time::Instant::now() + Duration::from_secs(60);
        loop {
            let out =
                common::harvey(&["topic", "list", "--prefix", &prefix, "--json"]).output().expect("list");
            let nodes: Vec<String> = String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
                .filter(|t| t["topic"] == "camera/frame")
                .flat_map(|t| t["nodes"].as_array().cloned().unwrap_or_default())
                .filter_map(|n| n.as_str().map(str::to_owned))
                .collect();
            let observing = nodes.iter().filter(|n| *n == "harvey-topic").count();
            if observing == want
                && nodes.iter().any(|n| n == "recorder")
                && nodes.iter().any(|n| n == "vision-workers")
            {
                return nodes;
            }
            assert!(std::time::Instant::now() < deadline, "camera/frame held by {nodes:?}");
            assert!(run.try_wait().expect("try_wait").is_none(), "the launch ended early");
            std::thread::sleep(Duration::from_millis(100));
        }
    };
    holders(2);
    // Two more observers fill the six slots (recorder, vision workers, four observers)...
    observers.push(observe());
    observers.push(observe());
    holders(4);
    // ...and a fifth is refused, naming who holds them.
    let full = common::harvey(&["topic", "echo", "camera/frame", "--prefix", &prefix, "--count", "1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&full.stderr);
    assert!(!full.status.success());
    assert!(
        err.contains("all 6 subscriber slots are taken")
            && err.contains("recorder")
            && err.contains("harvey-topic"),
        "{err}"
    );
    for o in &mut observers {
        common::signal(o, libc::SIGINT);
        common::wait_exit(o, Duration::from_secs(10));
    }
    common::signal(&run, libc::SIGINT);
    common::wait_exit(&mut run, Duration::from_secs(30));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

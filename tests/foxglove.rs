//! `harvey run --foxglove`: the default mission run in real time with the Foxglove bridge, seen
//! by a third-party Foxglove WebSocket client (`scripts/foxglove_client.mjs`: Foxglove's own
//! protocol client and ROS 2 decoders, in Node, installed by `scripts/foxglove_setup`). Every
//! topic is advertised with its `ros2msg` schema, the mission's topics stream live, every
//! message decodes by its channel's schema, and what the client got is what the recorder
//! recorded, byte for byte.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::collections::BTreeMap;
use std::io::BufRead;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use harvey_msgs::{Odometry, topics};
use serde_json::Value;

/// Installs the client's Node packages (once per target folder); fails the test saying why not.
fn node_modules() -> std::path::PathBuf {
    let dir = common::bin_dir().parent().expect("target folder").join("foxglove-node");
    let out = Command::new(common::repo().join("scripts/foxglove_setup")).arg(&dir).output().expect("setup");
    assert!(
        out.status.success(),
        "scripts/foxglove_setup could not install the Foxglove client's packages:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").expect("a free port").local_addr().expect("addr").port()
}

fn from_hex(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex")).collect()
}

fn number(v: &Value) -> u64 {
    v.as_u64()
        .or_else(|| v.as_str().and_then(|s| s.parse().ok()))
        .unwrap_or_else(|| panic!("{v} is no number"))
}

/// The derived topics matched with the recording by log time too (the others by bytes alone).
fn stamped(topic: &str) -> bool {
    topic == "/tf" || topic == "/camera/camera_info"
}

#[test]
fn a_foxglove_client_sees_every_topic_live_as_it_is_recorded() {
    let modules = node_modules();
    let (prefix, dir) = (common::unique_prefix("fox"), common::scratch("foxglove"));
    let port = free_port();
    let mut run =
        common::harvey(&["run", "--realtime", "--prefix", &prefix, "--run-dir", dir.to_str().unwrap()])
            .arg(format!("--foxglove=127.0.0.1:{port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("harvey run");
    // The launch's log, line by line: the bridge says when it serves.
    let (tx, rx) = mpsc::channel();
    let stderr = run.stderr.take().expect("stderr");
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let (mut log, deadline) = (Vec::new(), Instant::now() + Duration::from_secs(60));
    while !log.iter().any(|l: &String| l.contains("[foxglove-bridge]") && l.contains("serving Foxglove")) {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(line) => log.push(line),
            Err(_) => panic!("the bridge did not come up:\n{}", log.join("\n")),
        }
    }

    let need = [
        ("sonar/ring", 40),
        ("odometry", 20),
        ("sim/truth", 20),
        ("drv/sonar_raw", 20),
        ("drv/encoders_raw", 20),
        ("executive/status", 20),
        ("ums/map", 20),
        ("camera/frame", 10),
        ("vision/detections", 10),
        // Derived as the recorder derives them (`harvey_recording::derive`).
        ("tf", 40),
        ("tf_static", 1),
        ("markers/map", 1),
        ("markers/uncertainty", 10),
        // From each frame's header, whether or not a client watches the frames.
        ("camera/camera_info", 10),
    ];
    let mut client = Command::new("node");
    client.arg(common::repo().join("scripts/foxglove_client.mjs")).arg("--modules").arg(&modules);
    client.args(["--url", &format!("ws://127.0.0.1:{port}"), "--timeout-s", "60"]);
    for (topic, n) in need {
        client.args(["--need", &format!("{topic}={n}")]);
    }
    client.args(["--echo", "odometry", "--echo", "sonar/ring", "--echo", "camera/frame"]);
    client.args(["--echo", "tf", "--echo", "tf_static", "--echo", "markers/map"]);
    client.args(["--echo", "camera/camera_info"]);
    let out = client.output().expect("node runs the client");
    let lines: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    let summary =
        lines.iter().find_map(|l| l.get("summary")).cloned().unwrap_or_else(|| {
            panic!("no summary from the client:\n{}", String::from_utf8_lossy(&out.stderr))
        });
    assert!(out.status.success(), "the client: {:?}\n{summary:#}", out.status);
    assert_eq!(summary["errors"], serde_json::json!([]), "every message decodes by its schema");
    assert_eq!(summary["subprotocol"], "foxglove.sdk.v1");
    assert!(number(&summary["time_messages"]) > 0, "the server's time follows the stamps");

    // Every topic is advertised, as a `cdr` channel with a `ros2msg` schema.
    let advertised: BTreeMap<String, &Value> = lines
        .iter()
        .filter_map(|l| l.get("advertised"))
        .map(|a| (a["topic"].as_str().expect("topic").to_owned(), a))
        .collect();
    let derived = harvey_recording::derive::TOPICS.iter().map(|(t, ..)| t);
    let mut want: Vec<String> = topics::ALL.iter().chain(derived).map(|t| format!("/{t}")).collect();
    want.sort();
    assert_eq!(advertised.keys().cloned().collect::<Vec<_>>(), want, "every topic, and no other");
    assert_eq!(advertised["/tf"]["schemaName"], "tf2_msgs/msg/TFMessage");
    assert_eq!(advertised["/markers/map"]["schemaName"], "visualization_msgs/msg/MarkerArray");
    for (topic, a) in &advertised {
        assert_eq!(
            (a["encoding"].as_str(), a["schemaEncoding"].as_str()),
            (Some("cdr"), Some("ros2msg")),
            "{topic}"
        );
    }
    assert_eq!(advertised["/camera/frame"]["schemaName"], "sensor_msgs/msg/Image");
    assert_eq!(advertised["/odometry"]["schemaName"], "harvey_msgs/msg/Odometry");
    let (received, decoded) = (&summary["received"], &summary["decoded"]);
    assert_eq!(received, decoded, "every message received was decoded");
    for (topic, n) in need {
        assert!(number(&decoded[format!("/{topic}")]) >= n, "{topic}: {summary:#}");
    }
    let echoed: Vec<&Value> = lines.iter().filter_map(|l| l.get("message")).collect();
    let of = |topic: &'static str| echoed.iter().filter(move |m| m["topic"] == topic).copied();
    let ring_stamps: Vec<u64> = of("/sonar/ring").map(|m| number(&m["log_time"])).collect();
    let mut steps: Vec<u64> = ring_stamps.windows(2).map(|w| w[1].saturating_sub(w[0])).collect();
    steps.sort_unstable();
    assert!(ring_stamps.windows(2).all(|w| w[0] < w[1]), "in order: {ring_stamps:?}");
    assert_eq!(steps[steps.len() / 2], 50_000_000, "the ring every tick of 50 ms: {ring_stamps:?}");

    // The run is stopped early; the recording holds what the client got, byte for byte.
    common::signal(&run, libc::SIGINT);
    common::wait_exit(&mut run, Duration::from_secs(30));
    log.extend(rx.try_iter());
    assert!(log.iter().any(|l| l.contains("Foxglove bridge stopped")), "a clean stop:\n{}", log.join("\n"));
    assert_eq!(common::shm_leftovers(&prefix), Vec::<String>::new());
    let mcap = std::fs::read(dir.join("run.mcap")).expect("recording");
    let mut recorded: BTreeMap<(String, u64), Vec<u8>> = BTreeMap::new();
    // The derived topics, by bytes (and, for /tf and the camera's calibration, log time): the
    // bridge numbers its own.
    let mut recorded_derived = std::collections::BTreeSet::new();
    for m in mcap::MessageStream::new(&mcap).expect("mcap") {
        let m = m.expect("message");
        if harvey_recording::derive::is_derived(&m.channel.topic) {
            let at = if stamped(&m.channel.topic) { m.log_time } else { 0 };
            recorded_derived.insert((m.channel.topic.clone(), at, m.data.into_owned()));
            continue;
        }
        let key = if m.channel.topic == "/camera/frame" { m.log_time } else { u64::from(m.sequence) };
        recorded.insert((m.channel.topic.clone(), key), m.data.into_owned());
    }
    let mut matched = BTreeMap::<&str, usize>::new();
    for topic in ["/odometry", "/sonar/ring", "/camera/frame"] {
        for m in of(topic) {
            let key =
                if topic == "/camera/frame" { number(&m["log_time"]) } else { number(&m["value"]["seq"]) };
            let data = recorded
                .get(&(topic.to_owned(), key))
                .unwrap_or_else(|| panic!("{topic} {key} is not in the recording"));
            assert_eq!(
                &from_hex(m["cdr"].as_str().expect("cdr")),
                data,
                "{topic} {key}: the recorder's bytes"
            );
            *matched.entry(topic).or_default() += 1;
        }
    }
    for topic in ["/tf", "/tf_static", "/markers/map", "/camera/camera_info"] {
        for m in of(topic) {
            let at = if stamped(topic) { number(&m["log_time"]) } else { 0 };
            let data = from_hex(m["cdr"].as_str().expect("cdr"));
            assert!(
                recorded_derived.contains(&(topic.to_owned(), at, data)),
                "{topic} at {at}: the bridge derived what the recorder did not: {m:#}"
            );
            *matched.entry(topic).or_default() += 1;
        }
    }
    assert!(
        matched.get("/tf").is_some_and(|&n| n >= 40)
            && matched.contains_key("/markers/map")
            && matched.get("/camera/camera_info").is_some_and(|&n| n >= 10),
        "{matched:?}"
    );
    // And the decoded values are the recorded message's.
    let odometry = of("/odometry").next().expect("an odometry message");
    let o: Odometry =
        harvey_cdr::decode(&recorded[&("/odometry".to_owned(), number(&odometry["value"]["seq"]))])
            .expect("decode");
    let v = &odometry["value"];
    assert_eq!(number(&v["seq"]), o.header.seq);
    assert_eq!(number(&odometry["log_time"]), o.header.stamp_ns);
    assert_eq!(v["world_from_robot"]["x_m"].as_f64(), Some(o.world_from_robot.x_m));
    assert_eq!(v["world_from_robot"]["heading_rad"].as_f64(), Some(o.world_from_robot.heading_rad));
    assert_eq!(v["travelled_m"].as_f64(), Some(o.travelled_m));
    let frame = of("/camera/frame").next().expect("a frame");
    let (h, pixels) =
        harvey_cdr::decode_image(&recorded[&("/camera/frame".to_owned(), number(&frame["log_time"]))])
            .expect("image");
    let f = &frame["value"];
    assert_eq!(
        (number(&f["width"]), number(&f["height"]), f["encoding"].as_str()),
        (640, 480, Some("mono8"))
    );
    assert_eq!((number(&f["width"]), number(&f["step"])), (u64::from(h.width_px), u64::from(h.stride_bytes)));
    let sum = pixels.iter().fold(0u32, |s, &b| s.wrapping_add(u32::from(b)));
    assert_eq!(
        (number(&f["data"]["bytes"]), number(&f["data"]["sum"])),
        (pixels.len() as u64, u64::from(sum))
    );
    println!(
        "foxglove: {} topics advertised, {} messages decoded, matched with run.mcap: {matched:?}",
        advertised.len(),
        decoded.as_object().map_or(0, |d| d.values().map(number).sum::<u64>())
    );
    std::fs::remove_dir_all(&dir).ok();
}

//! Crash safety of the recorder: SIGKILLed mid-stream it loses at most about a second (it flushes
//! every 500 ms), `harvey recover` salvages every complete chunk into a valid file, and a
//! truncated or corrupt file gets a clear error from the tools, never a panic.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::Bus;
use harvey_msgs::{Header, Pose2, TruePose, topics};

#[test]
fn a_killed_recorder_loses_at_most_a_second_and_recover_salvages_the_rest() {
    let prefix = common::unique_prefix("crash");
    let dir = common::scratch("crash");
    let mcap = dir.join("run.mcap");
    let mut recorder = Command::new(common::bin("harvey-recorder"))
        .args(["--output", mcap.to_str().expect("utf8"), "--flush-ms", "500"])
        .args(["--world", "worlds/arena.toml", "--seed", "5"])
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .stderr(Stdio::null())
        .spawn()
        .expect("recorder starts");
    let bus = Bus::join_with_prefix("crash-test", &prefix).expect("bus");
    let truth = bus.publisher(topics::SIM_TRUTH).expect("publisher");
    // Wait until the recorder subscribes, then publish at 500 Hz, stamps in milliseconds.
    let deadline = Instant::now() + Duration::from_secs(20);
    while truth.send(&TruePose::default()).expect("send") == 0 {
        assert!(Instant::now() < deadline, "the recorder never subscribed");
        std::thread::sleep(Duration::from_millis(10));
    }
    // Subscribed is not yet recording: give it time to open its other topics and start draining.
    std::thread::sleep(Duration::from_millis(500));
    let start = Instant::now();
    let mut seq = 0u64;
    let mut sent_at = Vec::new();
    while start.elapsed() < Duration::from_secs(3) {
        seq += 1;
        let m = TruePose {
            header: Header::new(seq, seq * 1_000_000),
            world_from_robot: Pose2 { x_m: seq as f64, ..Default::default() },
        };
        truth.send(&m).expect("send");
        sent_at.push(start.elapsed());
        std::thread::sleep(Duration::from_millis(2));
    }
    // SAFETY: kill(2) on our own child.
    unsafe { libc::kill(recorder.id() as i32, libc::SIGKILL) };
    let killed_at = start.elapsed();
    recorder.wait().expect("reaped");

    // The killed file has no summary; the tools say so clearly.
    let info = common::harvey(&["info", mcap.to_str().expect("utf8")]).output().expect("info runs");
    let text = String::from_utf8_lossy(&info.stderr);
    assert_eq!(info.status.code(), Some(2), "{text}");
    assert!(text.contains(&format!("harvey: error: {}: corrupt after", mcap.display())), "{text}");

    let fixed = dir.join("fixed.mcap");
    let out = common::harvey(&["recover", mcap.to_str().expect("utf8"), "-o", fixed.to_str().expect("utf8")])
        .output()
        .expect("recover runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&fixed).expect("fixed file");
    let summary = mcap::Summary::read(&bytes).expect("valid").expect("has a summary");
    let msgs: Vec<TruePose> = mcap::MessageStream::new(&bytes)
        .expect("stream")
        .map(|m| m.expect("every message reads"))
        .filter(|m| m.channel.topic == "/sim/truth")
        .map(|m| harvey_cdr::decode(&m.data).expect("decodes"))
        .filter(|m: &TruePose| m.header.seq > 0)
        .collect();
    assert!(summary.stats.expect("stats").message_count >= msgs.len() as u64);
    // The world and the seed that places its poles survive, for `harvey export`.
    let worlds: Vec<&str> = summary.attachment_indexes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(worlds, ["arena.toml"]);
    let world_md =
        summary.metadata_indexes.iter().find(|m| m.name == "harvey.world").expect("world metadata");
    let world_md = mcap::read::metadata(&bytes, world_md).expect("reads");
    assert_eq!(world_md.metadata.get("seed").map(String::as_str), Some("5"));
    let last = msgs.last().expect("something salvaged").header.seq;
    // A prefix of what was sent, in order, with nothing missing inside it.
    let gaps: Vec<(u64, u64)> = msgs
        .windows(2)
        .filter(|w| w[1].header.seq != w[0].header.seq + 1)
        .map(|w| (w[0].header.seq, w[1].header.seq))
        .collect();
    assert_eq!(msgs[0].header.seq, 1, "the first message is salvaged");
    assert!(gaps.is_empty(), "salvaged messages are not contiguous: {gaps:?}");
    let lost = sent_at.len() as u64 - last;
    let lost_time = killed_at - sent_at[last as usize - 1];
    println!("sent {}, salvaged {last}, lost {lost} = the last {lost_time:?} before the kill", sent_at.len());
    assert!(lost_time <= Duration::from_millis(1200), "lost {lost_time:?} of data");
    drop(truth);
    drop(bus);
    harvey_bus::retire_domain(&prefix).expect("retire");
}

#[test]
fn corrupt_and_foreign_files_get_clear_errors() {
    let dir = common::scratch("corrupt");
    let junk = dir.join("junk.mcap");
    std::fs::write(&junk, b"this is not a recording at all").expect("write");
    for args in [
        vec!["info", junk.to_str().expect("utf8")],
        vec!["recover", junk.to_str().expect("utf8"), "-o", "/dev/null"],
        vec!["export", junk.to_str().expect("utf8"), "-o", "/dev/null"],
    ] {
        let out = common::harvey(&args).output().expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("harvey: error:") && err.contains("junk.mcap"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

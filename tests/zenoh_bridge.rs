//! Two bus domains (two prefixes, which never see each other over iceoryx2) joined only by two
//! `harvey-zenoh-bridge` processes over `tcp/127.0.0.1:<free port>`: messages and camera frames
//! published in one domain arrive in the other exactly (fields, sequence numbers, stamps,
//! every pixel), frames in loaned shared memory; an importing bridge whose topics nobody
//! exports gives up naming them; a bad endpoint is named. Launches split over two hosts:
//! `tests/zenoh_split.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::io::Read;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::Bus;
use harvey_msgs::{Encoding, FrameHeader, Header, Odometry, topics};

/// A bridge process, stopped (SIGTERM, then waited for) when dropped.
struct Bridge(Child);

impl Drop for Bridge {
    fn drop(&mut self) {
        common::signal(&self.0, libc::SIGTERM);
        common::wait_exit(&mut self.0, Duration::from_secs(10));
    }
}

fn bridge(prefix: &str, args: &[&str]) -> Command {
    let mut c = Command::new(common::bin("harvey-zenoh-bridge"));
    c.args(args).env(harvey_bus::PREFIX_ENV, prefix).stdin(Stdio::null());
    c
}

/// Waits (at most `limit`) until `got` yields something, calling `poke` between tries.
fn until<T>(limit: Duration, mut poke: impl FnMut(), mut got: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    loop {
        if let Some(v) = got() {
            return v;
        }
        assert!(start.elapsed() < limit, "nothing arrived within {limit:?}");
        poke();
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn messages_and_frames_cross_from_one_domain_to_another_exactly() {
    let (pa, pb) = (common::unique_prefix("zba"), common::unique_prefix("zbb"));
    let port = common::free_port();
    let at = format!("tcp/127.0.0.1:{port}");
    let carried = "odometry,camera/frame";
    let a = Bridge(
        bridge(&pa, &["--host", "a", "--export", carried, "--zenoh-listen", &at]).spawn().expect("bridge a"),
    );
    let b = Bridge(
        bridge(&pb, &["--host", "b", "--import", carried, "--zenoh-connect", &at]).spawn().expect("bridge b"),
    );
    let bus_a = Bus::join_with_prefix("test-a", &pa).expect("domain a");
    let bus_b = Bus::join_with_prefix("test-b", &pb).expect("domain b");
    let odometry = bus_a.publisher(topics::ODOMETRY).expect("publisher");
    let frames = bus_a.frame_publisher(topics::CAMERA_FRAME, 640 * 480).expect("frame publisher");
    let odometry_b = bus_b.subscriber(topics::ODOMETRY).expect("subscriber");
    let frames_b = bus_b.frame_subscriber(topics::CAMERA_FRAME).expect("frame subscriber");

    // The bridges find each other: probes go out until one comes through.
    let probe = Odometry { header: Header::new(0, 1), ..Default::default() };
    until(Duration::from_secs(60), || drop(odometry.send(&probe)), || odometry_b.latest().ok().flatten());
    while odometry_b.latest().expect("drain").is_some() {}

    for seq in 1..=100u64 {
        let sent = Odometry {
            header: Header::new(seq, seq * 50_000_000),
            travelled_m: seq as f64 * 0.01,
            turned_rad: -(seq as f64) * 0.001,
            ..Default::default()
        };
        odometry.send(&sent).expect("send");
        let got = until(Duration::from_secs(10), || {}, || odometry_b.latest().ok().flatten());
        assert_eq!(got, sent, "message {seq} arrives as sent");
    }
    for seq in 1..=6u64 {
        let header = FrameHeader::new(seq, seq * 100_000_000, 640, 480, Encoding::Mono8);
        let mut loan = frames.loan(header).expect("loan");
        for (i, p) in loan.pixels_mut().iter_mut().enumerate() {
            *p = (i as u64 * 7 + seq * 13) as u8;
        }
        loan.send().expect("send");
        let (h, ok) = until(
            Duration::from_secs(10),
            || {},
            || {
                let f = frames_b.take().ok().flatten()?;
                let ok = f.pixels().iter().enumerate().all(|(i, p)| *p == (i as u64 * 7 + seq * 13) as u8);
                Some((*f.header(), ok))
            },
        );
        assert_eq!(h, header, "frame {seq}'s header, its sequence number carried beside the CDR");
        assert!(ok, "frame {seq}: every pixel as sent");
    }
    drop((odometry, frames, odometry_b, frames_b, bus_a, bus_b, a, b));
    for p in [&pa, &pb] {
        harvey_bus::retire_domain(p).expect("retire");
    }
}

#[test]
fn an_import_nobody_exports_and_a_bad_endpoint_are_named() {
    let prefix = common::unique_prefix("zbn");
    let at = format!("tcp/127.0.0.1:{}", common::free_port());
    let mut c = bridge(&prefix, &["--import", "ums/map", "--zenoh-listen", &at, "--wait-s", "1"])
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let status = common::wait_exit(&mut c, Duration::from_secs(30));
    let mut err = String::new();
    c.stderr.take().expect("stderr").read_to_string(&mut err).expect("read");
    assert!(!status.success());
    assert!(err.contains("no host exports [\"ums/map\"] after 1 s"), "{err}");

    let out =
        bridge(&prefix, &["--export", "all", "--zenoh-listen", "udp/127.0.0.1:7447"]).output().expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("--zenoh-listen udp/127.0.0.1:7447: not `tcp/HOST:PORT`"), "{err}");
    harvey_bus::retire_domain(&prefix).expect("retire");
}

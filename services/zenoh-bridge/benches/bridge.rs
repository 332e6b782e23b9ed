//! Zenoh bridge benchmark: a camera stream (640x480 mono8, 1920x1080 rgb8) from one bus domain
//! through two `harvey-zenoh-bridge` processes on `tcp/127.0.0.1` into another domain, against
//! raw Zenoh pub/sub of the same bytes on the same loopback, measured in the same run.
//!
//! Every frame: the sender writes it whole, stamps it with CLOCK_MONOTONIC and sends it; the
//! receiver (this process, in another domain or another Zenoh session) takes it, records now -
//! stamp and checks its sequence (Harvey) and its first and last bytes. Each path runs one frame
//! at a time (the next sent when the last has arrived: the latency figures) and as a stream with
//! two frames in flight (the throughput figure the target is set on; no more than the camera
//! topic's queue holds, so the bus drops none). Throughput counts frame bytes over the wall time
//! of all rounds, frame writing included. Harvey's path: bus (loaned
//! frame) -> bridge A (CDR) -> Zenoh TCP -> bridge B (decoded into a loaned frame) -> bus; the
//! raw path: a Zenoh publisher -> TCP -> a Zenoh subscriber, both in this process.
//!
//! Run: `cargo build --release --workspace && cargo bench -p harvey-zenoh-bridge --bench bridge`.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::process::{Child, Command, Stdio};
use std::sync::mpsc::channel;
use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter};
use harvey_msgs::{Encoding, FrameHeader, Header, Odometry, topics};
use zenoh::Wait;
use zenoh::qos::CongestionControl;

fn now_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes into the timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// Latencies (ns) and throughput (MB/s) of one row.
struct Row {
    lat: Vec<u64>,
    mb_s: f64,
}

impl Row {
    fn p(&self, q: f64) -> f64 {
        let mut l = self.lat.clone();
        l.sort_unstable();
        l[((l.len() - 1) as f64 * q).round() as usize] as f64 / 1e3
    }
}

fn fill(buf: &mut [u8], round: u64) {
    let v = (round % 251) as u8;
    buf.fill(v);
}

fn peer(listen: Option<&str>, connect: Option<&str>) -> zenoh::Session {
    let mut c = zenoh::Config::default();
    c.insert_json5("mode", "\"peer\"").unwrap();
    c.insert_json5("scouting/multicast/enabled", "false").unwrap();
    c.insert_json5("scouting/gossip/enabled", "false").unwrap();
    c.insert_json5(
        "listen/endpoints",
        &format!("[{}]", listen.map(|e| format!("\"{e}\"")).unwrap_or_default()),
    )
    .unwrap();
    c.insert_json5(
        "connect/endpoints",
        &format!("[{}]", connect.map(|e| format!("\"{e}\"")).unwrap_or_default()),
    )
    .unwrap();
    zenoh::open(c).wait().unwrap()
}

/// Raw Zenoh: a publisher session and a subscriber session joined on loopback.
fn raw(bytes: usize, rounds: usize, window: u64) -> Row {
    let at = format!("tcp/127.0.0.1:{}", free_port());
    let subscriber_side = peer(Some(&at), None);
    let publisher_side = peer(None, Some(&at));
    let (tx, rx) = channel::<Vec<u8>>();
    let _sub = subscriber_side
        .declare_subscriber("raw/frame")
        .callback(move |s| drop(tx.send(s.payload().to_bytes().into_owned())))
        .wait()
        .unwrap();
    let publisher = publisher_side
        .declare_publisher("raw/frame")
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
    let mut buf = vec![0u8; bytes];
    // Until the subscriber is matched, puts go nowhere.
    loop {
        publisher.put(vec![0u8; 16]).wait().unwrap();
        if rx.recv_timeout(Duration::from_millis(50)).is_ok() {
            break;
        }
    }
    while rx.try_recv().is_ok() {}
    let (mut lat, start) = (Vec::with_capacity(rounds), Instant::now());
    let mut sent = 0u64;
    for round in 0..rounds as u64 {
        while sent < rounds as u64 && sent < round + window {
            fill(&mut buf, sent);
            buf[..8].copy_from_slice(&now_ns().to_le_bytes());
            publisher.put(buf.clone()).wait().unwrap();
            sent += 1;
        }
        let got = rx.recv_timeout(Duration::from_secs(10)).expect("raw frame");
        let t = now_ns();
        let stamp = u64::from_le_bytes(got[..8].try_into().unwrap());
        assert_eq!((got.len(), got[bytes - 1]), (bytes, (round % 251) as u8));
        lat.push(t - stamp);
    }
    Row { lat, mb_s: (bytes * rounds) as f64 / start.elapsed().as_secs_f64() / 1e6 }
}

struct Bridge(Child);
impl Drop for Bridge {
    fn drop(&mut self) {
        unsafe { libc::kill(self.0.id() as i32, libc::SIGTERM) };
        let _ = self.0.wait();
    }
}

fn bridge(prefix: &str, args: &[&str]) -> Bridge {
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().and_then(|d| d.parent()).unwrap().join("harvey-zenoh-bridge");
    assert!(bin.is_file(), "{} missing: cargo build --release --workspace first", bin.display());
    let child = Command::new(bin)
        .args(args)
        .env(harvey_bus::PREFIX_ENV, prefix)
        .env("RUST_LOG", "error")
        .stdin(Stdio::null())
        .spawn()
        .unwrap();
    Bridge(child)
}

/// Harvey: domain A -> bridge A -> Zenoh -> bridge B -> domain B.
fn harvey(bytes: usize, (w, h, enc): (u32, u32, Encoding), rounds: usize, window: u64, tag: &str) -> Row {
    let (pa, pb) =
        (format!("zbench{tag}a{}_", std::process::id()), format!("zbench{tag}b{}_", std::process::id()));
    let at = format!("tcp/127.0.0.1:{}", free_port());
    let carried = "odometry,camera/frame";
    let _a = bridge(&pa, &["--host", "a", "--export", carried, "--zenoh-listen", &at]);
    let _b = bridge(&pb, &["--host", "b", "--import", carried, "--zenoh-connect", &at]);
    let bus_a = Bus::join_with_prefix("bench-a", &pa).unwrap();
    let bus_b = Bus::join_with_prefix("bench-b", &pb).unwrap();
    let frames = bus_a.frame_publisher(topics::CAMERA_FRAME, bytes).unwrap();
    let probe = bus_a.publisher(topics::ODOMETRY).unwrap();
    let frames_b = bus_b.frame_subscriber(topics::CAMERA_FRAME).unwrap();
    let probe_b = bus_b.subscriber(topics::ODOMETRY).unwrap();
    let waiter = Waiter::new().unwrap();
    let _w = waiter.attach(&frames_b).unwrap();
    // The bridges have found each other once a probe comes through.
    while probe_b.latest().unwrap().is_none() {
        probe.send(&Odometry { header: Header::new(1, 1), ..Default::default() }).unwrap();
        std::thread::sleep(Duration::from_millis(50));
    }
    // More in flight than the topic's queue holds and the bus would drop the oldest.
    assert!(window as usize <= topics::CAMERA_FRAME.qos.buffer, "window {window}");
    let (mut lat, start) = (Vec::with_capacity(rounds), Instant::now());
    let mut sent = 0u64;
    for round in 0..rounds as u64 {
        while sent < rounds as u64 && sent < round + window {
            let mut loan = frames.loan(FrameHeader::new(sent, 0, w, h, enc)).unwrap();
            fill(loan.pixels_mut(), sent);
            loan.set_header(FrameHeader::new(sent, now_ns(), w, h, enc));
            loan.send().unwrap();
            sent += 1;
        }
        let frame = loop {
            if let Some(f) = frames_b.take().unwrap() {
                break f;
            }
            waiter.wait(Some(Duration::from_secs(10))).unwrap();
        };
        let t = now_ns();
        let px = frame.pixels();
        assert_eq!(frame.header().seq, round, "a frame lost or out of order");
        assert_eq!((px.len(), px[0], px[bytes - 1]), (bytes, (round % 251) as u8, (round % 251) as u8));
        lat.push(t - frame.header().stamp_ns);
    }
    let row = Row { lat, mb_s: (bytes * rounds) as f64 / start.elapsed().as_secs_f64() / 1e6 };
    drop(_w);
    drop((frames, probe, frames_b, probe_b, waiter, bus_a, bus_b));
    for p in [&pa, &pb] {
        harvey_bus::retire_domain(p).ok();
    }
    row
}

fn main() {
    println!(
        "CPU: {}; SIMD features: {}",
        harvey_vision::simd::cpu_model(),
        harvey_vision::simd::cpu_features()
    );
    println!(
        "| stream | path | p50 µs (one at a time) | p99 µs (one at a time) | MB/s, one at a time | MB/s, two in flight | p50 / raw | MB/s / raw (two in flight) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    let streams = [
        ("640x480 mono8", (640, 480, Encoding::Mono8), 1000),
        ("1920x1080 rgb8", (1920, 1080, Encoding::Rgb8), 200),
    ];
    let only = std::env::var("BRIDGE_BENCH_ONLY").ok();
    for (name, (w, h, enc), rounds) in streams {
        if only.as_deref().is_some_and(|o| !name.starts_with(o)) {
            continue;
        }
        let bytes = (w * h * if enc == Encoding::Rgb8 { 3 } else { 1 }) as usize;
        // [raw, Harvey] x [one at a time, two in flight], interleaved, twice each: the machine
        // is shared.
        let mut rows: [[Vec<Row>; 2]; 2] = Default::default();
        for i in 0..2 {
            for (k, window) in [1, 2].into_iter().enumerate() {
                rows[0][k].push(raw(bytes, rounds, window));
                rows[1][k].push(harvey(bytes, (w, h, enc), rounds, window, &format!("{w}{i}{window}")));
            }
        }
        let merge = |rows: &mut Vec<Row>| {
            let mb_s = rows.iter().map(|r| r.mb_s).sum::<f64>() / rows.len() as f64;
            Row { lat: rows.drain(..).flat_map(|r| r.lat).collect(), mb_s }
        };
        let [[r1, r2], [h1, h2]] = rows.each_mut().map(|pair| pair.each_mut().map(merge));
        println!(
            "| {name} | raw Zenoh | {:.0} | {:.0} | {:.0} | {:.0} | 1.00 | 1.00 |",
            r1.p(0.5),
            r1.p(0.99),
            r1.mb_s,
            r2.mb_s
        );
        println!(
            "| {name} | Harvey: bus, two bridges, bus | {:.0} | {:.0} | {:.0} | {:.0} | {:.2} | {:.2} |",
            h1.p(0.5),
            h1.p(0.99),
            h1.mb_s,
            h2.mb_s,
            h1.p(0.5) / r1.p(0.5),
            h2.mb_s / r2.mb_s
        );
    }
}

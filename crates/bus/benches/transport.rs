//! Transport benchmark: one-way latency and throughput between two processes, for Harvey's
//! frame topics at 8 B, 64 KiB, 1 MiB and 6.2 MiB (1080p rgb8), against two baselines measured in
//! the same run: raw iceoryx2 with 8-byte payloads, and a copying transport (a Unix socket).
//!
//! Every round: the publisher writes the whole payload, stamps it with CLOCK_MONOTONIC, sends it;
//! the subscriber (another process, woken by an event, never polling) reads it, records
//! now - stamp, checks the payload's first and last byte, and acks. Throughput counts payload
//! bytes over the wall time of all rounds, payload writing included.
//!
//! Run: `cargo bench -p harvey-bus --bench transport`.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::{Encoding, FrameHeader, FrameTopic, Header, Message, Qos, Topic, ZeroCopySend};
use iceoryx2::prelude::*;

#[derive(Debug, Default, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("harvey_bench/Ack")]
struct Ack {
    header: Header,
}
impl Message for Ack {
    fn header(&self) -> &Header {
        &self.header
    }
}

const FRAMES: FrameTopic = FrameTopic {
    name: "bench/frame",
    qos: Qos { buffer: 1, borrowed: 1, history: 0, max_publishers: 1, max_subscribers: 1 },
};
const ACKS: Topic<Ack> = Topic::new(
    "bench/ack",
    Qos { buffer: 1, borrowed: 1, history: 0, max_publishers: 1, max_subscribers: 1 },
);

fn now_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime writes into the timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

fn report(mut lat: Vec<u64>) {
    lat.sort_unstable();
    let p = |q: f64| lat[((lat.len() - 1) as f64 * q).round() as usize];
    println!("result {} {} {}", p(0.5), p(0.99), lat.len());
}

/// Subscriber side of Harvey's bus.
fn sub_harvey(prefix: &str, iters: usize) -> anyhow::Result<()> {
    let bus = Bus::join_with_prefix("bench-sub", prefix)?;
    let frames = bus.frame_subscriber(FRAMES)?;
    let acks = bus.publisher(ACKS)?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&frames)?;
    println!("ready");
    let mut lat = Vec::with_capacity(iters);
    while lat.len() < iters {
        if waiter.wait(Some(Duration::from_secs(10)))? != Wake::Ready {
            anyhow::bail!("no frame within 10 s");
        }
        while let Some(f) = frames.take()? {
            let t = now_ns();
            let h = *f.header();
            let px = f.pixels();
            let expect = (h.seq % 251) as u8;
            anyhow::ensure!(
                px[0] == expect && px[px.len() - 1] == expect,
                "payload of round {} not as written",
                h.seq
            );
            lat.push(t - h.stamp_ns);
            drop(f);
            acks.send(&Ack { header: Header::new(h.seq, t) })?;
        }
    }
    report(lat);
    Ok(())
}

fn pub_harvey(prefix: &str, size: usize, iters: usize) -> anyhow::Result<Duration> {
    let bus = Bus::join_with_prefix("bench-pub", prefix)?;
    let frames = bus.frame_publisher(FRAMES, size)?;
    let acks = bus.subscriber(ACKS)?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&acks)?;
    let start = Instant::now();
    for i in 1..=iters as u64 {
        let mut loan = frames.loan(FrameHeader::new(i, 0, size as u32, 1, Encoding::Mono8))?;
        loan.pixels_mut().fill((i % 251) as u8);
        let mut h = *loan.header();
        h.stamp_ns = now_ns();
        loan.set_header(h);
        loan.send()?;
        while acks.drain(|_| {})? == 0 {
            anyhow::ensure!(
                waiter.wait(Some(Duration::from_secs(10)))? == Wake::Ready,
                "no ack for round {i}"
            );
        }
    }
    Ok(start.elapsed())
}

type RawNode = Node<ipc::Service>;

fn raw_node(prefix: &str, name: &str) -> anyhow::Result<RawNode> {
    let mut config = iceoryx2::config::Config::default();
    config.global.prefix = FileName::new(prefix.as_bytes()).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    NodeBuilder::new()
        .name(&NodeName::new(name).map_err(|e| anyhow::anyhow!("{e:?}"))?)
        .config(&config)
        .create::<ipc::Service>()
        .map_err(|e| anyhow::anyhow!("{e:?}"))
}

macro_rules! iox {
    ($e:expr) => {
        $e.map_err(|e| anyhow::anyhow!("{:?}", e))?
    };
}

/// Raw iceoryx2: `[u64; 1]` payloads (8 bytes) with the same event-driven wake-up, no Harvey code.
fn raw_pair(
    node: &RawNode,
    topic: &str,
) -> anyhow::Result<(
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, u64, ()>,
    iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
)> {
    let name = ServiceName::new(topic).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let ps = iox!(
        node.service_builder(&name)
            .publish_subscribe::<u64>()
            .subscriber_max_buffer_size(1)
            .max_publishers(1)
            .max_subscribers(1)
            .open_or_create()
    );
    let ev = iox!(node.service_builder(&name).event().open_or_create());
    Ok((ps, ev))
}

fn sub_raw(prefix: &str, iters: usize) -> anyhow::Result<()> {
    let node = raw_node(prefix, "raw-sub")?;
    let (ps, ev) = raw_pair(&node, "raw/data")?;
    let (aps, aev) = raw_pair(&node, "raw/ack")?;
    let sub = iox!(ps.subscriber_builder().create());
    let listener = iox!(ev.listener_builder().create());
    let ack = iox!(aps.publisher_builder().create());
    let notifier = iox!(aev.notifier_builder().create());
    println!("ready");
    let mut lat = Vec::with_capacity(iters);
    while lat.len() < iters {
        iox!(listener.timed_wait(|_| {}, Duration::from_secs(10)));
        while let Some(s) = iox!(sub.receive()) {
            let t = now_ns();
            lat.push(t - *s.payload());
            iox!(ack.send_copy(t));
            iox!(notifier.notify());
        }
    }
    report(lat);
    Ok(())
}

fn pub_raw(prefix: &str, iters: usize) -> anyhow::Result<Duration> {
    let node = raw_node(prefix, "raw-pub")?;
    let (ps, ev) = raw_pair(&node, "raw/data")?;
    let (aps, aev) = raw_pair(&node, "raw/ack")?;
    let publisher = iox!(ps.publisher_builder().create());
    let notifier = iox!(ev.notifier_builder().create());
    let acks = iox!(aps.subscriber_builder().create());
    let listener = iox!(aev.listener_builder().create());
    let start = Instant::now();
    for _ in 0..iters {
        iox!(publisher.send_copy(now_ns()));
        iox!(notifier.notify());
        loop {
            iox!(listener.timed_wait(|_| {}, Duration::from_secs(10)));
            if iox!(acks.receive()).is_some() {
                break;
            }
        }
    }
    Ok(start.elapsed())
}

/// The copying baseline: length-prefixed messages over a Unix stream socket.
fn sub_uds(path: &str, size: usize, iters: usize) -> anyhow::Result<()> {
    let mut s = UnixStream::connect(path)?;
    println!("ready");
    let mut buf = vec![0u8; size];
    let mut lat = Vec::with_capacity(iters);
    for _ in 0..iters {
        let mut head = [0u8; 16];
        s.read_exact(&mut head)?;
        s.read_exact(&mut buf)?;
        let t = now_ns();
        let stamp = u64::from_le_bytes(head[..8].try_into()?);
        let seq = u64::from_le_bytes(head[8..].try_into()?);
        anyhow::ensure!(
            buf[0] == (seq % 251) as u8 && buf[size - 1] == (seq % 251) as u8,
            "payload of round {seq} not as written"
        );
        lat.push(t - stamp);
        s.write_all(&[1])?;
    }
    report(lat);
    Ok(())
}

fn pub_uds(listener: &UnixListener, size: usize, iters: usize) -> anyhow::Result<Duration> {
    let (mut s, _) = listener.accept()?;
    let mut payload = vec![0u8; size];
    let start = Instant::now();
    for i in 1..=iters as u64 {
        payload.fill((i % 251) as u8);
        let mut head = [0u8; 16];
        head[..8].copy_from_slice(&now_ns().to_le_bytes());
        head[8..].copy_from_slice(&i.to_le_bytes());
        s.write_all(&head)?;
        s.write_all(&payload)?;
        let mut ack = [0u8; 1];
        s.read_exact(&mut ack)?;
    }
    Ok(start.elapsed())
}

struct Row {
    name: String,
    size: usize,
    p50_ns: u64,
    p99_ns: u64,
    mb_per_s: f64,
}

fn spawn_child(args: &[String]) -> anyhow::Result<(Child, BufReader<std::process::ChildStdout>)> {
    let mut child = Command::new(std::env::current_exe()?).args(args).stdout(Stdio::piped()).spawn()?;
    let mut out = BufReader::new(child.stdout.take().ok_or_else(|| anyhow::anyhow!("child stdout"))?);
    let mut line = String::new();
    out.read_line(&mut line)?;
    anyhow::ensure!(line.trim() == "ready", "child said {line:?}");
    Ok((child, out))
}

fn finish_child(
    mut child: Child,
    mut out: BufReader<std::process::ChildStdout>,
    name: &str,
    size: usize,
    elapsed: Duration,
) -> anyhow::Result<Row> {
    let mut line = String::new();
    out.read_line(&mut line)?;
    anyhow::ensure!(child.wait()?.success(), "{name} subscriber failed");
    let f: Vec<u64> = line.split_whitespace().skip(1).map(str::parse).collect::<Result<_, _>>()?;
    let mb = (size * f[2] as usize) as f64 / 1e6 / elapsed.as_secs_f64();
    Ok(Row { name: name.to_owned(), size, p50_ns: f[0], p99_ns: f[1], mb_per_s: mb })
}

fn run_case(kind: &str, size: usize, iters: usize, tag: usize) -> anyhow::Result<Row> {
    let prefix = format!("bench{}x{tag}_", std::process::id());
    let row = match kind {
        "harvey" => {
            let (child, out) =
                spawn_child(&["--role".into(), "sub-harvey".into(), prefix.clone(), iters.to_string()])?;
            let elapsed = pub_harvey(&prefix, size, iters)?;
            finish_child(child, out, "harvey bus (frames)", size, elapsed)?
        }
        "raw" => {
            let (child, out) =
                spawn_child(&["--role".into(), "sub-raw".into(), prefix.clone(), iters.to_string()])?;
            let elapsed = pub_raw(&prefix, iters)?;
            finish_child(child, out, "raw iceoryx2 (baseline)", size, elapsed)?
        }
        _ => {
            let path = std::env::temp_dir().join(format!("{prefix}.sock"));
            let _ = std::fs::remove_file(&path);
            let listener = UnixListener::bind(&path)?;
            let p = path.to_string_lossy().into_owned();
            let mut child = Command::new(std::env::current_exe()?)
                .args(["--role", "sub-uds", &p, &size.to_string(), &iters.to_string()])
                .stdout(Stdio::piped())
                .spawn()?;
            let elapsed = pub_uds(&listener, size, iters)?;
            let out = BufReader::new(child.stdout.take().ok_or_else(|| anyhow::anyhow!("stdout"))?);
            let mut lines = out.lines();
            anyhow::ensure!(lines.next().transpose()?.as_deref() == Some("ready"), "uds child not ready");
            let result = lines.next().transpose()?.unwrap_or_default();
            anyhow::ensure!(child.wait()?.success(), "uds subscriber failed");
            let _ = std::fs::remove_file(&path);
            let f: Vec<u64> = result.split_whitespace().skip(1).map(str::parse).collect::<Result<_, _>>()?;
            Row {
                name: "unix socket (copying)".into(),
                size,
                p50_ns: f[0],
                p99_ns: f[1],
                mb_per_s: (size * f[2] as usize) as f64 / 1e6 / elapsed.as_secs_f64(),
            }
        }
    };
    let _ = harvey_bus::retire_domain(&prefix);
    Ok(row)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--role") {
        let a = &args[i + 1..];
        return match a[0].as_str() {
            "sub-harvey" => sub_harvey(&a[1], a[2].parse()?),
            "sub-raw" => sub_raw(&a[1], a[2].parse()?),
            "sub-uds" => sub_uds(&a[1], a[2].parse()?, a[3].parse()?),
            other => anyhow::bail!("unknown role {other}"),
        };
    }
    iceoryx2::prelude::set_log_level(LogLevel::Error);
    let sizes = [(8usize, 4000usize), (64 << 10, 3000), (1 << 20, 1000), (1920 * 1080 * 3, 300)];
    let mut rows = vec![run_case("raw", 8, 4000, 0)?];
    for (k, (size, iters)) in sizes.iter().enumerate() {
        rows.push(run_case("harvey", *size, *iters, k + 1)?);
        rows.push(run_case("uds", *size, *iters, k + 10)?);
    }
    let raw = rows[0].p50_ns as f64;
    println!("| transport | payload | p50 µs | p99 µs | throughput MB/s | p50 / raw iceoryx2 8 B |");
    println!("|---|---:|---:|---:|---:|---:|");
    for r in &rows {
        println!(
            "| {} | {} B | {:.1} | {:.1} | {:.1} | {:.2} |",
            r.name,
            r.size,
            r.p50_ns as f64 / 1e3,
            r.p99_ns as f64 / 1e3,
            r.mb_per_s,
            r.p50_ns as f64 / raw
        );
    }
    let big = rows
        .iter()
        .find(|r| r.name.starts_with("harvey") && r.size == 1920 * 1080 * 3)
        .map_or(f64::NAN, |r| r.p50_ns as f64 / raw);
    let small = rows
        .iter()
        .find(|r| r.name.starts_with("harvey") && r.size == 8)
        .map_or(f64::NAN, |r| r.p50_ns as f64 / raw);
    println!(
        "\nHarvey p50 at 6.2 MiB / raw iceoryx2 p50 at 8 B = {big:.2} (target <= 1.5); at 8 B = {small:.2}"
    );
    Ok(())
}

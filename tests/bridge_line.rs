//! The denning-bridge on a real pseudo-terminal, with this test playing the DRV: valid reports
//! arrive on the bus intact and in order although random garbage and cut frames are injected
//! between them; bus commands come out as DRV frames, and impossible ones never reach the line.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

mod common;

use std::fs::File;
use std::io::{Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter};
use harvey_drv_protocol::{Decoder, Line, Report, encode};
use harvey_msgs::{CommandKind, Header, MotionCommand, topics};

/// A small seeded generator for the garbage.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
}

fn report(i: u64) -> Report {
    if i.is_multiple_of(2) {
        Report::Encoders {
            time_ms: i * 50,
            x_hundredths_ft: i as i32 * 3,
            y_hundredths_ft: -(i as i32),
            heading_tenths_deg: (i % 3600) as i32,
            moving: i.is_multiple_of(4),
            command_id: 7,
        }
    } else {
        Report::Sonar {
            time_ms: i * 50,
            bank: (i % 3) as u8,
            ranges_tenths_ft: std::array::from_fn(|k| ((i as usize + k * 7) % 256) as u16),
        }
    }
}

#[test]
fn garbage_on_the_line_loses_no_valid_frame_and_bad_commands_never_leave() {
    let prefix = common::unique_prefix("br");
    let dir = common::scratch("bridge");
    let pty = nix::pty::openpty(None, None).expect("pty");
    harvey_drv_protocol::serial::make_raw(&pty.slave).expect("raw");
    let link = dir.join("drv.pty");
    std::os::unix::fs::symlink(nix::unistd::ttyname(&pty.slave).expect("name"), &link).expect("link");
    let mut line = File::from(pty.master);

    let bus = Bus::join_with_prefix("drv-test", &prefix).expect("bus");
    let encoders = bus.subscriber(topics::DRV_ENCODERS_RAW).expect("sub");
    let sonar = bus.subscriber(topics::DRV_SONAR_RAW).expect("sub");
    let commands = bus.publisher(topics::VEHICLE_COMMAND).expect("pub");
    let waiter = Waiter::new().expect("waiter");
    let _a = waiter.attach(&encoders).expect("attach");
    let _b = waiter.attach(&sonar).expect("attach");

    let mut bridge = Command::new(common::bin("harvey-denning-bridge"))
        .args(["--device", link.to_str().expect("utf8")])
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .stderr(Stdio::piped())
        .spawn()
        .expect("bridge starts");
    let deadline = Instant::now() + Duration::from_secs(20);
    while !harvey_bus::live_nodes(&prefix)
        .expect("nodes")
        .iter()
        .any(|n| n.alive && n.name == "denning-bridge")
    {
        assert!(Instant::now() < deadline, "bridge never joined the bus");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(100)); // its line is open once it is on the bus

    let n = 400u64;
    let mut rng = Lcg(42);
    let (mut got_enc, mut got_sonar) = (Vec::new(), Vec::new());
    let mut injected = 0usize;
    for chunk in 0..n / 10 {
        let mut bytes = Vec::new();
        for i in chunk * 10..chunk * 10 + 10 {
            let frame = encode(&Line::Report(report(i)));
            match rng.next() % 4 {
                0 => {
                    let len = (rng.next() % 40) as usize;
                    bytes.extend((0..len).map(|_| rng.next() as u8));
                    injected += len;
                }
                1 => {
                    let cut = 1 + (rng.next() as usize % (frame.len() - 2));
                    bytes.extend_from_slice(&frame.as_bytes()[..cut]);
                    injected += cut;
                }
                2 => {
                    let mut bad = frame.clone().into_bytes();
                    let k = 1 + rng.next() as usize % (bad.len() - 6);
                    bad[k] ^= 0x04; // a flipped bit: bad checksum or bad field
                    bytes.extend_from_slice(&bad);
                    injected += bad.len();
                }
                _ => {}
            }
            bytes.extend_from_slice(frame.as_bytes());
        }
        // Delivered in arbitrary pieces, as a serial port would.
        let mut rest = &bytes[..];
        while !rest.is_empty() {
            let k = (1 + rng.next() as usize % 64).min(rest.len());
            line.write_all(&rest[..k]).expect("write");
            rest = &rest[k..];
        }
        let want = (chunk + 1) * 10;
        let deadline = Instant::now() + Duration::from_secs(10);
        while ((got_enc.len() + got_sonar.len()) as u64) < want {
            assert!(
                Instant::now() < deadline,
                "only {} of {want} reports arrived",
                got_enc.len() + got_sonar.len()
            );
            waiter.wait(Some(Duration::from_millis(100))).expect("wait");
            encoders.drain(|m| got_enc.push(*m)).expect("drain");
            sonar.drain(|m| got_sonar.push(*m)).expect("drain");
        }
    }
    assert!(injected > 1000, "the test must inject real damage: {injected} bytes");
    assert_eq!((got_enc.len(), got_sonar.len()), (n as usize / 2, n as usize / 2));
    for (k, e) in got_enc.iter().enumerate() {
        let i = 2 * k as u64;
        let Report::Encoders { time_ms, x_hundredths_ft, heading_tenths_deg, moving, .. } = report(i) else {
            unreachable!()
        };
        assert_eq!(e.header.stamp_ns, time_ms * 1_000_000, "report {i} out of order or lost");
        assert!((e.x_m - f64::from(x_hundredths_ft) / 100.0 * 0.3048).abs() < 1e-9);
        assert!((e.heading_rad - (f64::from(heading_tenths_deg) / 10.0).to_radians()).abs() < 1e-9);
        assert_eq!(e.moving, u32::from(moving));
    }
    for (k, s) in got_sonar.iter().enumerate() {
        let i = 2 * k as u64 + 1;
        let Report::Sonar { time_ms, bank, ranges_tenths_ft } = report(i) else { unreachable!() };
        assert_eq!((s.header.stamp_ns, s.bank), (time_ms * 1_000_000, u32::from(bank)));
        for (r, t) in s.range_m.iter().zip(ranges_tenths_ft) {
            assert!((f64::from(*r) - f64::from(t) / 10.0 * 0.3048).abs() < 1e-5);
        }
        let echoes =
            ranges_tenths_ft.iter().enumerate().filter(|(_, r)| **r < 255).fold(0, |m, (k, _)| m | 1 << k);
        assert_eq!(s.echo_mask, echoes);
    }

    // Commands: one good MOVE, then a NaN TURN and a mile-long MOVE that must never be sent.
    let cmd = |id: u32, kind: CommandKind, distance_m: f64, angle_rad: f64| MotionCommand {
        header: Header::new(u64::from(id), 0),
        kind: kind as u32,
        distance_m,
        angle_rad,
        command_id: id,
        ..Default::default()
    };
    commands.send(&cmd(5, CommandKind::Move, 1.0, 0.0)).expect("send");
    commands.send(&cmd(6, CommandKind::Turn, 0.0, f64::NAN)).expect("send");
    commands.send(&cmd(7, CommandKind::Move, 1609.0, 0.0)).expect("send");
    commands.send(&cmd(8, CommandKind::Stop, 0.0, 0.0)).expect("send");
    let mut decoder = Decoder::new();
    let mut sent = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut buf = [0u8; 256];
    harvey_drv_protocol::serial::set_nonblocking(&line).expect("nonblocking");
    while sent.len() < 2 && Instant::now() < deadline {
        match line.read(&mut buf) {
            // Heartbeats (`HB`, real time: the executive is alive) go out between the commands.
            Ok(k) => decoder.push(&buf[..k], |f| {
                let f = f.expect("the bridge sends valid frames");
                if !matches!(f, Line::Heartbeat { .. }) {
                    sent.push(f);
                }
            }),
            Err(_) => std::thread::sleep(Duration::from_millis(10)),
        }
    }
    std::thread::sleep(Duration::from_millis(200));
    while let Ok(k) = line.read(&mut buf) {
        decoder.push(&buf[..k], |f| {
            let f = f.expect("valid");
            if !matches!(f, Line::Heartbeat { .. }) {
                sent.push(f);
            }
        });
    }
    use harvey_drv_protocol::Command as Drv;
    assert_eq!(
        sent,
        vec![Line::Command(Drv::Move { id: 5, hundredths_ft: 328 }), Line::Command(Drv::Stop { id: 8 })]
    );

    common::signal(&bridge, libc::SIGTERM);
    let status = common::wait_exit(&mut bridge, Duration::from_secs(10));
    let mut log = String::new();
    bridge.stderr.take().expect("stderr").read_to_string(&mut log).expect("log");
    assert!(status.success(), "{status}: {log}");
    assert!(log.contains("refused: command 6: angle_rad is not a finite number"), "{log}");
    assert!(
        log.contains("refused: command 7: distance_ft = 5278.871 is beyond the vehicle's limit of 100"),
        "{log}"
    );
    assert!(log.contains("bad frame from the DRV"), "garbage is logged: {log}");
    let stats = log.lines().find(|l| l.contains("bridge stopped")).expect("final stats");
    assert!(stats.contains(&format!("frames: {n}")), "{stats}");
    drop((_a, _b));
    drop((encoders, sonar, commands, waiter));
    drop(bus);
    harvey_bus::retire_domain(&prefix).expect("retire");
}

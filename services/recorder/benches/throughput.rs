//! Recording throughput: the real recorder process records 1080p rgb8 camera frames (rendered
//! hallway views: clean, and with the shipped world's camera noise and the `harsh` condition's)
//! published over the bus at 30, 60 and 120 Hz and flat out; reported as frame MB/s taken in and
//! drops, against the disk's sequential write speed measured in the same run (the same bytes
//! written raw to a file and synced).
//!
//! Run: `cargo build --release --workspace && cargo bench -p harvey-recorder --bench throughput`.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "benchmark code")]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use harvey_bus::Bus;
use harvey_msgs::{Encoding, FrameHeader, topics};
use harvey_recording::Recording;
use harvey_render::Renderer;

const W: u32 = 1920;
const H: u32 = 1080;

fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("bench path");
    exe.parent().and_then(Path::parent).expect("target dir").to_owned()
}

/// Sequential write speed of the disk under `dir`: `bytes` in 4 MiB blocks, synced.
fn disk_mb_s(dir: &Path, bytes: usize) -> f64 {
    let path = dir.join("disk-baseline.bin");
    let block = vec![0x5au8; 4 << 20];
    let t = Instant::now();
    let mut f = std::fs::File::create(&path).expect("baseline file");
    let mut left = bytes;
    while left > 0 {
        let n = left.min(block.len());
        f.write_all(&block[..n]).expect("write");
        left -= n;
    }
    f.sync_all().expect("sync");
    let mb_s = bytes as f64 / 1e6 / t.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&path);
    mb_s
}

struct Run {
    frames: &'static str,
    compression: &'static str,
    rate: String,
    sent: u64,
    recorded: u64,
    mb_s: f64,
    file_mb: f64,
}

fn record(
    dir: &Path,
    set: &FrameSet,
    compression: &'static str,
    rate_hz: Option<f64>,
    seconds: f64,
    tag: usize,
) -> Run {
    let frames = &set.frames;
    let prefix = format!("rtp{}x{tag}_", std::process::id());
    let mcap = dir.join(format!("bench-{tag}.mcap"));
    let mut recorder: Child = Command::new(bin_dir().join("harvey-recorder"))
        .args(["--output", mcap.to_str().expect("utf8"), "--compression", compression])
        .env(harvey_bus::PREFIX_ENV, &prefix)
        .stderr(Stdio::null())
        .spawn()
        .expect("harvey-recorder (build the workspace first)");
    let bus = Bus::join_with_prefix("throughput-bench", &prefix).expect("bus");
    let publisher = bus.frame_publisher(topics::CAMERA_FRAME, (W * H * 3) as usize).expect("publisher");
    let probe = FrameHeader::new(0, 0, W, H, Encoding::Rgb8);
    while publisher.loan(probe).expect("loan").send().expect("send") == 0 {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(500));
    let start = Instant::now();
    let mut sent = 0u64;
    while start.elapsed().as_secs_f64() < seconds {
        sent += 1;
        let mut loan =
            publisher.loan(FrameHeader::new(sent, sent * 1_000_000, W, H, Encoding::Rgb8)).expect("loan");
        loan.pixels_mut().copy_from_slice(&frames[sent as usize % frames.len()]);
        loan.send().expect("send");
        if let Some(hz) = rate_hz {
            let next = Duration::from_secs_f64(sent as f64 / hz);
            if let Some(wait) = next.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_millis(300));
    // SAFETY: kill(2) on our own child: SIGTERM makes it finish the file.
    unsafe { libc::kill(recorder.id() as i32, libc::SIGTERM) };
    recorder.wait().expect("recorder exits");
    let recording = Recording::open(&mcap).expect("recording");
    let recorded = recording
        .messages()
        .expect("mcap")
        .filter_map(Result::ok)
        .filter(|m| m.topic() == "camera/frame" && m.sequence() > 0)
        .count() as u64;
    let file_bytes = std::fs::metadata(&mcap).expect("recording").len();
    let _ = std::fs::remove_file(&mcap);
    drop(publisher);
    drop(bus);
    let _ = harvey_bus::retire_domain(&prefix);
    let rate = rate_hz.map_or("flat out".into(), |hz| format!("{hz} Hz"));
    Run {
        frames: set.name,
        compression,
        rate,
        sent,
        recorded,
        mb_s: recorded as f64 * f64::from(W * H * 3) / 1e6 / elapsed,
        file_mb: file_bytes as f64 / 1e6,
    }
}

/// Frames cycled through in one set of runs, and what they are.
struct FrameSet {
    name: &'static str,
    frames: Vec<Vec<u8>>,
}

/// Rendered hallway views through `world`'s camera (its light, noise, vignetting and blur): the
/// noise is drawn per frame, so no two frames share it (zstd cannot match one against another).
fn frame_set(name: &'static str, world: &harvey_world::World) -> FrameSet {
    let mut r = Renderer::new(world, W, H, Encoding::Rgb8);
    let effects = harvey_render::Effects::from_camera(&world.camera, 7);
    let frames = (0..16)
        .map(|i| {
            let mut px = vec![0u8; r.frame_bytes()];
            r.render(world, harvey_world::Pose2::new(0.5 * i as f64, 0.1, 0.05 * i as f64), &mut px)
                .expect("render");
            effects.apply(W as usize, H as usize, 3, i, &mut px);
            px
        })
        .collect();
    FrameSet { name, frames }
}

/// The hallway under `conditions/harsh.toml`'s camera (its light, noise, vignetting and blur).
fn harsh_world(world: &harvey_world::World) -> harvey_world::World {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../conditions/harsh.toml");
    let text = std::fs::read_to_string(path).expect("conditions/harsh.toml");
    let table: toml::Table = text.parse().expect("harsh.toml parses");
    let camera = table["camera"].as_table().expect("[camera]");
    let num = |key: &str| camera[key].as_float().expect(key);
    let mut w = world.clone();
    w.camera.illumination = num("illumination");
    w.camera.noise_sd = num("noise_sd");
    w.camera.vignetting = num("vignetting");
    w.camera.blur_px = camera["blur_px"].as_integer().expect("blur_px") as u32;
    w
}

fn main() {
    let world_path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../worlds/hallway.toml");
    let world = harvey_world::World::load(Path::new(world_path)).expect("world");
    let mut clean = world.clone();
    clean.camera.noise_sd = 0.0;
    clean.camera.vignetting = 0.0;
    clean.camera.illumination_drift = 0.0;
    let sets = [
        frame_set("clean render", &clean),
        frame_set("world's camera", &world),
        frame_set("harsh camera", &harsh_world(&world)),
    ];
    // `cargo bench … -- TEXT` runs only the rows whose frames, compression or rate contain TEXT.
    let only: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let wanted = |set: &str, compression: &str, hz: Option<f64>| {
        let rate = hz.map_or("flat out".into(), |hz| format!("{hz} Hz"));
        only.as_ref().is_none_or(|o| [set, compression, rate.as_str()].join(" / ").contains(o.as_str()))
    };
    let dir = bin_dir();
    let seconds = 4.0;
    let mut runs = Vec::new();
    for hz in [Some(30.0), Some(60.0), Some(120.0), None] {
        if !wanted(sets[0].name, "zstd", hz) {
            continue;
        }
        let tag = runs.len();
        runs.push(record(&dir, &sets[0], "zstd", hz, seconds, tag));
    }
    for set in &sets[1..] {
        for compression in ["zstd", "zstd-fast", "lz4", "none"] {
            for hz in [Some(60.0), Some(120.0), None] {
                if !wanted(set.name, compression, hz) {
                    continue;
                }
                let tag = runs.len();
                runs.push(record(&dir, set, compression, hz, seconds, tag));
            }
        }
    }
    let disk = disk_mb_s(&dir, 1 << 30);
    println!(
        "| 1080p rgb8 frames | compression | rate | sent | recorded | drops | frame MB/s in | MCAP MB written | vs disk |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|---:|");
    for run in &runs {
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {:.0} % |",
            run.frames,
            run.compression,
            run.rate,
            run.sent,
            run.recorded,
            run.sent - run.recorded,
            run.mb_s,
            run.file_mb,
            100.0 * run.mb_s / disk
        );
    }
    let harsh = harsh_world(&world);
    for (name, w) in [("world's camera", &world), ("harsh camera", &harsh)] {
        let c = &w.camera;
        println!(
            "{name}: illumination {}, noise sd {}, vignetting {}, blur {} px",
            c.illumination, c.noise_sd, c.vignetting, c.blur_px
        );
    }
    println!("\ndisk sequential write, same run: {disk:.0} MB/s (1 GiB in 4 MiB blocks, synced)");
}

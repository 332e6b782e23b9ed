//! harvey-vision-workers: runs perceptual algorithms on camera frames read in place from shared
//! memory: vertical edges across the frame, and the landmarks the Expecter asks for, inside
//! their windows.

use std::collections::BTreeMap;
use std::path::PathBuf;

use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_msgs::{Expectation, VisionAlgorithm, VisionRequest, topics};
use harvey_runtime::{Resume, Sent};
use harvey_vision_workers::VerticalEdges;
use harvey_vision_workers::dispatch::Dispatcher;
use harvey_vision_workers::landmarks::LineLandmarks;

#[derive(Parser)]
#[command(about = "Vision workers on shared-memory camera frames")]
struct Args {
    /// World file (for the camera calibration).
    #[arg(long)]
    world: PathBuf,
    /// Half-height of the band searched for vertical edges, in rows.
    #[arg(long, default_value_t = 24)]
    band_half_rows: u32,
    /// Edge strength threshold in grey levels.
    #[arg(long, default_value_t = 12.0)]
    edge_threshold: f32,
    /// Look for the landmarks the Expecter asks for (`false`: dead reckoning only, 002 Fig. 79).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    landmarks: bool,
    /// Expectations older than this (message time) are not searched for.
    #[arg(long, default_value_t = 300)]
    expectation_max_age_ms: u64,
    /// This worker's share of `vision/requests`, `K/N`: the requests whose id is K modulo N
    /// (several workers share the load; any of them gives the same answer).
    #[arg(long, default_value = "0/1")]
    shard: String,
    /// A standing request of this worker's own: the fast line finder on every frame, lines
    /// between these orientations (degrees, `LO,HI`), published on `vision/requests` as id 1.
    #[arg(long, value_delimiter = ',')]
    lines: Option<Vec<f32>>,
    /// The window of the `--lines` request, `U0,V0,U1,V1` pixels (default: the whole frame).
    #[arg(long, value_delimiter = ',')]
    lines_window: Option<Vec<f32>>,
}

/// `K/N` with `K < N`.
fn shard(text: &str) -> anyhow::Result<(u32, u32)> {
    let parsed = text.split_once('/').and_then(|(k, n)| Some((k.parse().ok()?, n.parse().ok()?)));
    match parsed {
        Some((k, n)) if k < n => Ok((k, n)),
        _ => anyhow::bail!("--shard `{text}`: expected K/N with K < N, like 0/2"),
    }
}

/// Sends `m` unless a predecessor of this process sent it before it was killed.
fn send<T: harvey_msgs::Message>(
    sent: &mut Sent,
    port: &harvey_bus::Publisher<T>,
    m: &T,
) -> anyhow::Result<()> {
    let h = *m.header();
    if sent.due(port.topic(), h.stamp_ns, h.seq) {
        port.send(m)?;
        sent.done(port.topic(), h.stamp_ns, h.seq)?;
    }
    Ok(())
}

/// Room for the requests and expectations in force.
const SLOT_BYTES: usize = 256 << 10;

/// What a worker keeps from tick to tick.
#[derive(Default, serde::Serialize, serde::Deserialize)]
struct Kept {
    asked: BTreeMap<u32, VisionRequest>,
    wanted: BTreeMap<u32, Expectation>,
    /// The detector's, the landmark recogniser's and the dispatcher's numbering.
    numbered: [u64; 3],
}

/// The tick is done: what is in force is saved.
fn keep(
    resume: &mut Resume<Kept>,
    asked: &BTreeMap<u32, VisionRequest>,
    wanted: &BTreeMap<u32, Expectation>,
    numbered: [u64; 3],
) -> anyhow::Result<()> {
    let kept = resume.state();
    (kept.asked, kept.wanted, kept.numbered) = (asked.clone(), wanted.clone(), numbered);
    Ok(resume.tick_done()?)
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let world = harvey_world::World::load(&args.world)?;
    let bus = Bus::join("vision-workers")?;
    let frames = bus.frame_subscriber(topics::CAMERA_FRAME)?;
    let expectations = bus.subscriber(topics::UMS_EXPECTATIONS)?;
    let detections = bus.publisher(topics::VISION_DETECTIONS)?;
    let sightings = bus.publisher(topics::VISION_SIGHTINGS)?;
    let requests = bus.subscriber(topics::VISION_REQUESTS)?;
    let request_pub = bus.publisher(topics::VISION_REQUESTS)?;
    let results = bus.publisher(topics::VISION_RESULTS)?;
    let (k, n) = shard(&args.shard)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&frames, &expectations, &requests])?;
    harvey_runtime::notify_ready()?;

    // What a restarted worker takes back from its checkpoint: the requests and expectations in
    // force and its numbering. (The region tracker's and activity detector's frames are not
    // kept: a restarted worker's begin afresh.)
    let mut resume = Resume::from_env("vision-workers", SLOT_BYTES, Kept::default)?;
    let mut sent = Sent::from_env("vision-workers")?;
    // Requests by id (ascending, so answers come in a fixed order); one-shot ones go once answered.
    let mut asked: BTreeMap<u32, VisionRequest> = BTreeMap::new();
    if let Some(range) = &args.lines {
        anyhow::ensure!(range.len() == 2, "--lines takes LO,HI in degrees; got {range:?}");
        let mut own = VisionRequest {
            request_id: 1,
            algorithm: VisionAlgorithm::LineFinder as u32,
            standing: 1,
            ..Default::default()
        };
        own.params[4..6].copy_from_slice(range);
        if let Some(win) = &args.lines_window {
            anyhow::ensure!(win.len() == 4, "--lines-window takes U0,V0,U1,V1; got {win:?}");
            own.window_px.copy_from_slice(win);
        }
        // Published so the recording shows what was asked (once: not again by a restarted
        // worker); answered like any other.
        if !resume.resumed() {
            request_pub.send(&own)?;
        }
        asked.insert(own.request_id, own);
    }
    let mut dispatcher = Dispatcher::new(world.clone());

    let mut edges = VerticalEdges::new(args.band_half_rows, args.edge_threshold);
    let mut lines = LineLandmarks::new(world.camera.focal_px, args.edge_threshold)
        .with_calibration_sd(world.survey.calibration_sd_rad)
        .with_blur(world.camera.blur_px);
    let mut wanted: BTreeMap<u32, Expectation> = BTreeMap::new();
    if resume.resumed() {
        let kept = resume.state();
        (asked, wanted) = (kept.asked.clone(), kept.wanted.clone());
        edges.number_from(kept.numbered[0]);
        lines.number_from(kept.numbered[1]);
        dispatcher.number_from(kept.numbered[2]);
        tracing::warn!(requests = asked.len(), expectations = wanted.len(), "resumed from the checkpoint");
    }
    let max_age_ns = args.expectation_max_age_ms * 1_000_000;
    let mut rosout = harvey_runtime::Rosout::new(&bus, "vision-workers")?;
    let (mut processed, mut found, mut newest) = (0u64, 0u64, 0);
    while let Step::Go(tick) = pace.next(&waiter, None)? {
        rosout.begin();
        expectations.drain(|e| {
            if resume.fresh(expectations.topic(), e.header.stamp_ns, e.header.seq) {
                wanted.insert(e.landmark_index, *e);
            }
        })?;
        requests.drain(|r| {
            if r.request_id % n == k && resume.fresh(requests.topic(), r.header.stamp_ns, r.header.seq) {
                asked.insert(r.request_id, *r);
            }
        })?;
        // Work on the newest frame only: a late worker skips, it does not fall further behind.
        let frame =
            frames.latest()?.filter(|f| resume.fresh(frames.topic(), f.header().stamp_ns, f.header().seq));
        let Some(frame) = frame else {
            rosout.end(tick.unwrap_or(newest))?;
            keep(&mut resume, &asked, &wanted, [edges.numbered(), lines.numbered(), dispatcher.numbered()])?;
            pace.done()?;
            continue;
        };
        let h = *frame.header();
        newest = newest.max(h.stamp_ns);
        match edges.run(&h, frame.pixels()) {
            Ok(d) => {
                send(&mut sent, &detections, &d)?;
                processed += 1;
            }
            Err(e) => tracing::warn!("skipping a frame: {e}"),
        }
        lines.focal_px = world.camera.focal_for(h.width_px);
        wanted.retain(|_, e| e.header.stamp_ns + max_age_ns >= h.stamp_ns);
        for e in wanted.values().filter(|_| args.landmarks) {
            if let Some(s) = lines.recognise(&h, frame.pixels(), e) {
                found += u64::from(s.kind != 0);
                send(&mut sent, &sightings, &s)?;
            }
        }
        for req in asked.values() {
            send(&mut sent, &results, &dispatcher.answer(&h, frame.pixels(), req))?;
        }
        asked.retain(|_, r| r.standing != 0);
        drop(frame);
        rosout.end(tick.unwrap_or(newest))?;
        keep(&mut resume, &asked, &wanted, [edges.numbered(), lines.numbered(), dispatcher.numbered()])?;
        pace.done()?;
    }
    tracing::info!(processed, found, "vision workers stopped");
    Ok(())
}

//! The vision-workers service as a node (`harvey_runtime::Node`): its arguments, ports and turn.
use std::collections::BTreeMap;
use std::path::PathBuf;

use clap::Parser;

use crate::VerticalEdges;
use crate::dispatch::Dispatcher;
use crate::landmarks::LineLandmarks;
use crate::landmarks::ground::GroundLines;
use crate::landmarks::point::PointLandmarks;
use crate::odometry_config::OdometryConfig;
use harvey_msgs::{
    Detections, Expectation, LandmarkSighting, VisionAlgorithm, VisionRequest, VisionResult, topics,
};
use harvey_runtime::{End, FrameIn, In, Io, Node, Out, Ports};

#[derive(Parser)]
#[command(about = "Vision workers on shared-memory camera frames")]
pub struct Args {
    /// World file (for the camera calibration).
    #[arg(long)]
    pub world: PathBuf,
    /// Half-height of the band searched for vertical edges, in rows.
    #[arg(long, default_value_t = 24)]
    pub band_half_rows: u32,
    /// Edge strength threshold in grey levels.
    #[arg(long, default_value_t = 12.0)]
    pub edge_threshold: f32,
    /// Look for the landmarks the Expecter asks for (`false`: dead reckoning only, 002 Fig. 79).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    pub landmarks: bool,
    /// Look for class II landmarks too (signs: a point of known height, its bearing and range,
    /// 002 §3.4), not only class I (`false`: class I only, as the missions that predate it).
    #[arg(long, default_value_t = false, action = clap::ArgAction::Set)]
    pub point_landmarks: bool,
    /// Look for class III landmarks too (a wall's foot with its baseboard: the robot's heading
    /// relative to it and its distance from it, 002 §3.4).
    #[arg(long, default_value_t = false, action = clap::ArgAction::Set)]
    pub ground_landmarks: bool,
    /// Expectations older than this (message time) are not searched for.
    #[arg(long, default_value_t = 300)]
    pub expectation_max_age_ms: u64,
    /// This worker's share of `vision/requests`, `K/N`: the requests whose id is K modulo N
    /// (several workers share the load; any of them gives the same answer).
    #[arg(long, default_value = "0/1")]
    pub shard: String,
    /// A standing request of this worker's own: the fast line finder on every frame, lines
    /// between these orientations (degrees, `LO,HI`), published on `vision/requests` as id 1.
    #[arg(long, value_delimiter = ',')]
    pub lines: Option<Vec<f32>>,
    /// The window of the `--lines` request, `U0,V0,U1,V1` pixels (default: the whole frame).
    #[arg(long, value_delimiter = ',')]
    pub lines_window: Option<Vec<f32>>,
    /// The stereo visual odometry's settings: a file's `[odometry]` table
    /// (`missions/odometry/003.toml`). Without it, odometry requests are refused.
    #[arg(long)]
    pub odometry: Option<PathBuf>,
}

/// `K/N` with `K < N`.
fn shard(text: &str) -> anyhow::Result<(u32, u32)> {
    let parsed = text.split_once('/').and_then(|(k, n)| Some((k.parse().ok()?, n.parse().ok()?)));
    match parsed {
        Some((k, n)) if k < n => Ok((k, n)),
        _ => anyhow::bail!("--shard `{text}`: expected K/N with K < N, like 0/2"),
    }
}

/// What a worker keeps from tick to tick.
#[derive(Default, serde::Serialize, serde::Deserialize)]
pub struct Kept {
    /// Requests by id (ascending, so answers come in a fixed order); one-shot ones go once
    /// answered.
    asked: BTreeMap<u32, VisionRequest>,
    wanted: BTreeMap<u32, Expectation>,
    /// The detector's, the landmark recogniser's and the dispatcher's numbering.
    numbered: [u64; 3],
}

/// The vision workers as a node: expectations and requests first, then the newest frame.
pub struct Workers {
    frames: FrameIn,
    expectations: In<Expectation>,
    requests: In<VisionRequest>,
    detections: Out<Detections>,
    sightings: Out<LandmarkSighting>,
    request_out: Out<VisionRequest>,
    results: Out<VisionResult>,
    /// This worker's share of the requests: ids K modulo N.
    shard: (u32, u32),
    /// The standing `--lines` request of this worker's own.
    own: Option<VisionRequest>,
    landmarks: bool,
    max_age_ns: u64,
    camera: harvey_world::Camera,
    dispatcher: Dispatcher,
    edges: VerticalEdges,
    lines: LineLandmarks,
    /// The class II recogniser, when asked for (`--point-landmarks`).
    points: Option<PointLandmarks>,
    /// The class III recogniser, when asked for (`--ground-landmarks`).
    grounds: Option<GroundLines>,
    new_expectations: Vec<Expectation>,
    new_requests: Vec<VisionRequest>,
    processed: u64,
    found: u64,
}

impl Node for Workers {
    /// What a restarted worker takes back: the requests and expectations in force and its
    /// numbering. (The region tracker's and activity detector's frames are not kept: a
    /// restarted worker's begin afresh.)
    type State = Kept;
    /// Room for the requests and expectations in force.
    const CHECKPOINT_BYTES: usize = 256 << 10;

    fn start(&mut self) -> Kept {
        Kept { asked: self.own.iter().map(|r| (r.request_id, *r)).collect(), ..Kept::default() }
    }

    fn begin(&mut self, kept: &mut Kept, resumed: bool, io: &mut Io<'_>) -> anyhow::Result<()> {
        if resumed {
            self.edges.number_from(kept.numbered[0]);
            self.lines.number_from(kept.numbered[1]);
            self.dispatcher.number_from(kept.numbered[2]);
            let (requests, expectations) = (kept.asked.len(), kept.wanted.len());
            tracing::warn!(requests, expectations, "resumed from the checkpoint");
        } else if let Some(own) = &self.own {
            // Published so the recording shows what was asked (once: not again by a restarted
            // worker); answered like any other.
            io.send(self.request_out, own)?;
        }
        Ok(())
    }

    fn step(&mut self, kept: &mut Kept, io: &mut Io<'_>) -> anyhow::Result<()> {
        io.take(self.expectations, &mut self.new_expectations)?;
        kept.wanted.extend(self.new_expectations.iter().map(|e| (e.landmark_index, *e)));
        io.take(self.requests, &mut self.new_requests)?;
        let (k, n) = self.shard;
        kept.asked
            .extend(self.new_requests.iter().filter(|r| r.request_id % n == k).map(|r| (r.request_id, *r)));
        if let Some(frame) = io.latest_frame(self.frames)? {
            let (h, pixels) = (*frame.header(), frame.pixels());
            match self.edges.run(&h, pixels) {
                Ok(d) => {
                    io.send(self.detections, &d)?;
                    self.processed += 1;
                }
                Err(e) => tracing::warn!("skipping a frame: {e}"),
            }
            self.lines.focal_px = self.camera.focal_for(h.width_px);
            kept.wanted.retain(|_, e| e.header.stamp_ns + self.max_age_ns >= h.stamp_ns);
            for e in kept.wanted.values().filter(|_| self.landmarks) {
                let point = match (&mut self.points, &mut self.grounds, e.class) {
                    (Some(points), _, 2) => {
                        points.focal_px = self.lines.focal_px;
                        points.recognise(&h, pixels, e)
                    }
                    (_, Some(grounds), 3) => {
                        grounds.focal_px = self.lines.focal_px;
                        grounds.recognise(&h, pixels, e)
                    }
                    _ => None,
                }
                .map(|mut s| {
                    self.lines.number(&mut s);
                    s
                });
                if let Some(s) = point.or_else(|| self.lines.recognise(&h, pixels, e)) {
                    self.found += u64::from(s.kind != 0);
                    io.send(self.sightings, &s)?;
                }
            }
            for req in kept.asked.values() {
                io.send(self.results, &self.dispatcher.answer(&h, pixels, req))?;
            }
            kept.asked.retain(|_, r| r.standing != 0);
        }
        kept.numbered = [self.edges.numbered(), self.lines.numbered(), self.dispatcher.numbered()];
        Ok(())
    }

    fn stopped(&mut self, _: &Kept, _: End) -> anyhow::Result<u8> {
        tracing::info!(processed = self.processed, found = self.found, "vision workers stopped");
        Ok(0)
    }
}

/// The `--lines` request: the fast line finder on every frame, as request 1.
fn own_request(args: &Args) -> anyhow::Result<Option<VisionRequest>> {
    let Some(range) = &args.lines else {
        return Ok(None);
    };
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
    Ok(Some(own))
}

/// The node the arguments describe, its ports declared on `p`.
pub fn build(args: Args, p: &mut Ports) -> anyhow::Result<Workers> {
    let shard = shard(&args.shard)?;
    let own = own_request(&args)?;
    let world = harvey_world::World::load(&args.world)?;
    let odometry = args.odometry.as_deref().map(OdometryConfig::load).transpose()?;
    let frames = p.frames(topics::CAMERA_FRAME);
    // In real time a turn is as late as the newest of these.
    p.time_from_frames(frames);
    Ok(Workers {
        frames,
        expectations: p.input(topics::UMS_EXPECTATIONS),
        requests: p.input(topics::VISION_REQUESTS),
        detections: p.output(topics::VISION_DETECTIONS),
        sightings: p.output(topics::VISION_SIGHTINGS),
        request_out: p.output(topics::VISION_REQUESTS),
        results: p.output(topics::VISION_RESULTS),
        shard,
        own,
        landmarks: args.landmarks,
        max_age_ns: args.expectation_max_age_ms * 1_000_000,
        edges: VerticalEdges::new(args.band_half_rows, args.edge_threshold),
        lines: LineLandmarks::new(world.camera.focal_px, args.edge_threshold)
            .with_calibration_sd(world.survey.calibration_sd_rad)
            .with_blur(world.camera.blur_px),
        points: args.point_landmarks.then(|| PointLandmarks::new(&world, world.survey.calibration_sd_rad)),
        grounds: args.ground_landmarks.then(|| GroundLines::new(&world, world.survey.calibration_sd_rad)),
        dispatcher: Dispatcher::new(world.clone()).with_odometry(odometry),
        camera: world.camera,
        new_expectations: Vec::new(),
        new_requests: Vec::new(),
        processed: 0,
        found: 0,
    })
}

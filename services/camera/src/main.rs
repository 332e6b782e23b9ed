//! harvey-camera: renders the simulated world into loaned shared-memory frames, from the
//! simulator's true pose (`sim/truth`), or from a fixed pose at a fixed rate (`--pose`).

mod folder;

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FramePublisher, Pace, Step, Waiter, Wake};
use harvey_msgs::{Encoding, FrameHeader, topics};
use harvey_render::{Effects, Renderer, checksum, mount_error};
use harvey_world::{Pose2, World};

#[derive(Parser)]
#[command(about = "Simulated camera rendering into shared memory, or a folder of images played as frames")]
struct Args {
    /// World to render (required unless `--images` is given).
    #[arg(long)]
    world: Option<PathBuf>,
    /// Play the PNG/JPEG images of this folder, in name order, at `--rate-hz`, looping.
    #[arg(long, conflicts_with = "world")]
    images: Option<PathBuf>,
    /// Image size; defaults to the world's calibrated camera.
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// mono8 or rgb8.
    #[arg(long, default_value = "mono8")]
    encoding: String,
    /// Render one frame per this many true-pose messages.
    #[arg(long, default_value_t = 2)]
    every: u64,
    /// Render from this fixed pose `x_m,y_m,heading_deg` instead of following `sim/truth`.
    #[arg(long, value_delimiter = ',')]
    pose: Option<Vec<f64>>,
    /// With `--pose` or `--images`: frames per second (wall clock), and how many to send (0:
    /// until stopped).
    #[arg(long, default_value_t = 10.0)]
    rate_hz: f64,
    #[arg(long, default_value_t = 0)]
    frames: u64,
    /// Seed of the sensor noise, the light's phase and the mount's misalignment (the world's
    /// camera sets how much), of the map error and of the poles' places.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A launch file whose `[[mover]]` tables put moving things in the world.
    #[arg(long)]
    movers: Option<PathBuf>,
}

struct Camera {
    world: World,
    renderer: Renderer,
    effects: Effects,
    publisher: FramePublisher,
    seq: u64,
}

impl Camera {
    fn shoot(&mut self, pose: Pose2, stamp_ns: u64) -> anyhow::Result<()> {
        self.seq += 1;
        // Moving things where they are at the frame's simulated time.
        self.world.set_time(stamp_ns as f64 * 1e-9);
        let r = &self.renderer;
        let header = FrameHeader::new(self.seq, stamp_ns, r.width_px(), r.height_px(), r.encoding());
        let mut frame = self.publisher.loan(header)?;
        self.renderer.render(&self.world, pose, frame.pixels_mut())?;
        let (w, h, bpp) = (
            header.width_px as usize,
            header.height_px as usize,
            header.stride_bytes as usize / header.width_px as usize,
        );
        self.effects.apply_at(w, h, bpp, self.seq, stamp_ns, frame.pixels_mut());
        tracing::debug!(seq = self.seq, checksum = checksum(frame.pixels_mut()), "frame");
        frame.send()?;
        Ok(())
    }
}

/// Plays a folder of images as frames until stopped or `--frames` are sent.
fn play_folder(dir: &std::path::Path, args: &Args) -> anyhow::Result<()> {
    let folder = folder::Folder::open(dir)?;
    anyhow::ensure!(args.rate_hz > 0.0, "--rate-hz must be positive");
    let bus = Bus::join("camera")?;
    let publisher = bus.frame_publisher(topics::CAMERA_FRAME, folder.frame_bytes())?;
    let waiter = Waiter::new()?;
    let _tick = waiter.attach_interval(Duration::from_secs_f64(1.0 / args.rate_hz))?;
    harvey_runtime::notify_ready()?;
    tracing::info!(
        images = folder.count(),
        width = folder.width_px,
        height = folder.height_px,
        encoding = folder.encoding.ros_name(),
        "playing {}",
        dir.display()
    );
    let period_ns = (1e9 / args.rate_hz) as u64;
    let mut seq = 0u64;
    while waiter.wait(None)? != Wake::Shutdown && (args.frames == 0 || seq < args.frames) {
        let header = FrameHeader::new(
            seq + 1,
            (seq + 1) * period_ns,
            folder.width_px,
            folder.height_px,
            folder.encoding,
        );
        let mut frame = publisher.loan(header)?;
        folder.decode_into(seq as usize, frame.pixels_mut())?;
        frame.send()?;
        seq += 1;
    }
    Ok(())
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    if let Some(dir) = &args.images {
        return play_folder(dir, &args);
    }
    let world_path = args.world.as_ref().context("--world or --images is required")?;
    // The world as built, not as mapped: the robot's services keep the file (`[map_error]`).
    let mut world = World::load(world_path)?.as_built(args.seed);
    world.place_poles(args.seed)?;
    if let Some(file) = &args.movers {
        world.add_movers(harvey_world::load_movers(file)?);
    }
    let encoding = Encoding::parse(&args.encoding)
        .with_context(|| format!("--encoding `{}`: expected mono8 or rgb8", args.encoding))?;
    let width = args.width.unwrap_or(world.camera.width_px);
    let height = args.height.unwrap_or(world.camera.height_px);
    anyhow::ensure!(
        width > 0 && height > 0 && width <= 8192 && height <= 8192,
        "image size {width}x{height} out of range"
    );
    let (yaw, pitch) = mount_error(&world.camera, args.seed);
    if yaw != 0.0 || pitch != 0.0 {
        tracing::info!(yaw_rad = yaw, pitch_rad = pitch, "camera mount misaligned (unknown to the robot)");
    }
    let renderer = Renderer::new(&world, width, height, encoding).misaligned(yaw, pitch);
    let bus = Bus::join("camera")?;
    let publisher = bus.frame_publisher(topics::CAMERA_FRAME, renderer.frame_bytes())?;
    let effects = Effects::from_camera(&world.camera, args.seed);
    let mut cam = Camera { world, renderer, effects, publisher, seq: 0 };
    let waiter = Waiter::new()?;

    if let Some(p) = args.pose {
        anyhow::ensure!(p.len() == 3, "--pose takes x_m,y_m,heading_deg; got {} values", p.len());
        anyhow::ensure!(args.rate_hz > 0.0, "--rate-hz must be positive");
        let pose = Pose2::from_degrees(p[0], p[1], p[2]);
        let _tick = waiter.attach_interval(Duration::from_secs_f64(1.0 / args.rate_hz))?;
        harvey_runtime::notify_ready()?;
        let period_ns = (1e9 / args.rate_hz) as u64;
        while waiter.wait(None)? != Wake::Shutdown && (args.frames == 0 || cam.seq < args.frames) {
            cam.shoot(pose, (cam.seq + 1) * period_ns)?;
        }
        return Ok(());
    }

    let truth = bus.subscriber(topics::SIM_TRUTH)?;
    let pace = Pace::from_env(&bus)?;
    let _a = pace.attach(&waiter, &[&truth])?;
    // The frame count is the camera's only state (the effects are drawn from seed, frame and
    // stamp): checkpointed, a restarted camera numbers on and draws the same noise.
    let mut resume = harvey_runtime::Resume::from_env("camera", 4 << 10, || 0u64)?;
    cam.seq = *resume.state();
    let mut sent = harvey_runtime::Sent::from_env("camera")?;
    harvey_runtime::notify_ready()?;
    let every = args.every.max(1);
    let mut poses = Vec::new();
    while pace.next(&waiter, None)? != Step::Stop {
        truth.drain_into(&mut poses)?;
        poses.retain(|t| resume.fresh(truth.topic(), t.header.stamp_ns, t.header.seq));
        for t in poses.iter().filter(|t| t.header.seq % every == 0) {
            // A frame its predecessor sent before it was killed is not sent twice.
            let (topic, stamp, seq) = (topics::CAMERA_FRAME.name, t.header.stamp_ns, cam.seq + 1);
            if sent.due(topic, stamp, seq) {
                cam.shoot(t.world_from_robot, stamp)?;
                sent.done(topic, stamp, seq)?;
            } else {
                cam.seq += 1;
            }
        }
        *resume.state() = cam.seq;
        resume.tick_done()?;
        pace.done()?;
    }
    tracing::info!(frames = cam.seq, "camera stopped");
    Ok(())
}

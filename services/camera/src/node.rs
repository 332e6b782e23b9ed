//! The camera as a node (`harvey_runtime::Node`): its arguments, its source (the simulator's
//! true pose, a fixed pose at a rate, or a folder of images at a rate) and its turn; with
//! `--stereo`, each frame a stereo pair (003's two cameras).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use clap::Parser;
use harvey_msgs::{Encoding, FrameHeader, TruePose, topics};
use harvey_render::{Effects, Renderer, Shooter, checksum, mount_error};
use harvey_runtime::{End, FrameOut, In, Io, Node, Ports};
use harvey_world::{Pose2, World};

use crate::folder::Folder;

#[derive(Parser)]
#[command(about = "Simulated camera rendering into shared memory, or a folder of images played as frames")]
pub struct Args {
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
    /// A stereo pair (003) in each frame, the left image then the right, taken at one instant
    /// by two cameras the world's `[camera] stereo_baseline_m` apart, centred on the mount.
    #[arg(long, conflicts_with = "images")]
    stereo: bool,
}

/// The rendered world.
struct Scene {
    world: World,
    shooter: Shooter,
}

impl Scene {
    /// Renders frame `seq` from `pose` at `stamp_ns` and sends it (unless a predecessor did).
    fn shoot(
        &mut self,
        io: &mut Io<'_>,
        out: FrameOut,
        seq: u64,
        pose: Pose2,
        stamp_ns: u64,
    ) -> anyhow::Result<()> {
        // Moving things where they are at the frame's simulated time.
        self.world.set_time(stamp_ns as f64 * 1e-9);
        let header = self.shooter.header(seq, stamp_ns);
        io.send_frame(out, header, |pixels| {
            self.shooter.take(&self.world, pose, seq, stamp_ns, pixels)?;
            tracing::debug!(seq, checksum = checksum(pixels), "frame");
            Ok(())
        })?;
        Ok(())
    }
}

/// Where frames come from.
enum Source {
    /// The simulator's true pose: a frame per `every` poses.
    Truth { scene: Scene, truth: In<TruePose>, every: u64, poses: Vec<TruePose> },
    /// A fixed pose, a frame per turn.
    Fixed { scene: Scene, pose: Pose2, period_ns: u64 },
    /// A folder of images in name order, looping, a frame per turn.
    Folder { folder: Folder, period_ns: u64 },
}

/// The camera as a node.
pub struct Camera {
    source: Source,
    out: FrameOut,
    /// With a rate: frames to send (0: until stopped).
    frames: u64,
}

impl Node for Camera {
    /// The frame count is the camera's only state (the effects are drawn from seed, frame and
    /// stamp): checkpointed, a restarted camera numbers on and draws the same noise.
    type State = u64;
    const CHECKPOINT_BYTES: usize = 4 << 10;

    fn start(&mut self) -> u64 {
        0
    }

    fn step(&mut self, seq: &mut u64, io: &mut Io<'_>) -> anyhow::Result<()> {
        let out = self.out;
        match &mut self.source {
            Source::Truth { scene, truth, every, poses } => {
                io.take(*truth, poses)?;
                for t in poses.iter().filter(|t| t.header.seq % *every == 0) {
                    scene.shoot(io, out, *seq + 1, t.world_from_robot, t.header.stamp_ns)?;
                    *seq += 1;
                }
            }
            Source::Fixed { scene, pose, period_ns } => {
                scene.shoot(io, out, *seq + 1, *pose, (*seq + 1) * *period_ns)?;
                *seq += 1;
            }
            Source::Folder { folder, period_ns } => {
                let header = FrameHeader::new(
                    *seq + 1,
                    (*seq + 1) * *period_ns,
                    folder.width_px,
                    folder.height_px,
                    folder.encoding,
                );
                io.send_frame(out, header, |pixels| folder.decode_into(*seq as usize, pixels))?;
                *seq += 1;
            }
        }
        Ok(())
    }

    fn finished(&self, seq: &u64) -> bool {
        !matches!(self.source, Source::Truth { .. }) && self.frames != 0 && *seq >= self.frames
    }

    fn stopped(&mut self, seq: &u64, _: End) -> anyhow::Result<u8> {
        tracing::info!(frames = seq, "camera stopped");
        Ok(0)
    }
}

/// The camera the arguments describe, its ports declared on `p`.
pub fn build(args: Args, p: &mut Ports) -> anyhow::Result<Camera> {
    let rate = || -> anyhow::Result<(Duration, u64)> {
        anyhow::ensure!(args.rate_hz > 0.0 && args.rate_hz.is_finite(), "--rate-hz must be positive");
        Ok((Duration::from_secs_f64(1.0 / args.rate_hz), (1e9 / args.rate_hz) as u64))
    };
    if let Some(dir) = &args.images {
        let folder = Folder::open(dir)?;
        let (period, period_ns) = rate()?;
        tracing::info!(
            images = folder.count(),
            width = folder.width_px,
            height = folder.height_px,
            encoding = folder.encoding.ros_name(),
            "playing {}",
            dir.display()
        );
        let out = p.frames_out(topics::CAMERA_FRAME, folder.frame_bytes());
        p.every(period);
        return Ok(Camera { source: Source::Folder { folder, period_ns }, out, frames: args.frames });
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
    let effects = Effects::from_camera(&world.camera, args.seed);
    let baseline_m = match (args.stereo, world.camera.stereo_baseline_m) {
        (false, _) => None,
        (true, Some(b)) => Some(b),
        (true, None) => anyhow::bail!(
            "--stereo: the world {} has no `[camera] stereo_baseline_m` (the distance between the pair's cameras)",
            world_path.display()
        ),
    };
    let shooter = Shooter { renderer, effects, baseline_m };
    let out = p.frames_out(topics::CAMERA_FRAME, shooter.frame_bytes());
    let scene = Scene { world, shooter };
    let source = match &args.pose {
        Some(v) => {
            anyhow::ensure!(v.len() == 3, "--pose takes x_m,y_m,heading_deg; got {} values", v.len());
            let (period, period_ns) = rate()?;
            p.every(period);
            Source::Fixed { scene, pose: Pose2::from_degrees(v[0], v[1], v[2]), period_ns }
        }
        None => Source::Truth {
            scene,
            truth: p.input(topics::SIM_TRUTH),
            every: args.every.max(1),
            poses: Vec::new(),
        },
    };
    Ok(Camera { source, out, frames: args.frames })
}

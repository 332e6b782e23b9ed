//! harvey-vision-workers: runs perceptual algorithms on camera frames read in place from shared
//! memory and publishes what they find.

use clap::Parser;
use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::topics;
use harvey_vision_workers::VerticalEdges;

#[derive(Parser)]
#[command(about = "Vision workers on shared-memory camera frames")]
struct Args {
    /// Half-height of the band searched for vertical edges, in rows.
    #[arg(long, default_value_t = 24)]
    band_half_rows: u32,
    /// Edge strength threshold in grey levels.
    #[arg(long, default_value_t = 12.0)]
    edge_threshold: f32,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let bus = Bus::join("vision-workers")?;
    let frames = bus.frame_subscriber(topics::CAMERA_FRAME)?;
    let detections = bus.publisher(topics::VISION_DETECTIONS)?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&frames)?;
    harvey_runtime::notify_ready()?;

    let mut edges = VerticalEdges::new(args.band_half_rows, args.edge_threshold);
    let mut processed = 0u64;
    while waiter.wait(None)? != Wake::Shutdown {
        // Work on the newest frame only: a late worker skips, it does not fall further behind.
        if let Some(frame) = frames.latest()? {
            match edges.run(frame.header(), frame.pixels()) {
                Ok(d) => {
                    detections.send(&d)?;
                    processed += 1;
                }
                Err(e) => tracing::warn!("skipping a frame: {e}"),
            }
        }
    }
    tracing::info!(processed, "vision workers stopped");
    Ok(())
}

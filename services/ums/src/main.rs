//! harvey-ums: odometry in, the spatial uncertainty map out.

use std::path::PathBuf;

use clap::Parser;
use harvey_bus::{Bus, Waiter, Wake};
use harvey_msgs::topics;
use harvey_ums::Ums;

#[derive(Parser)]
#[command(about = "Spatial uncertainty management")]
struct Args {
    /// World file (for the terrain's error statistics).
    #[arg(long)]
    world: PathBuf,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let world = harvey_world::World::load(&args.world)?;
    let bus = Bus::join("ums")?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let map = bus.publisher(topics::UMS_MAP)?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(&odometry)?;
    harvey_runtime::notify_ready()?;

    let mut ums = Ums::new(world.ground_terrain().clone());
    let mut batch = Vec::new();
    while waiter.wait(None)? != Wake::Shutdown {
        odometry.drain_into(&mut batch)?;
        for o in &batch {
            match ums.on_odometry(o) {
                Ok(m) => {
                    map.send(&m)?;
                }
                Err(e) => tracing::warn!("ignoring odometry: {e}"),
            }
        }
    }
    Ok(())
}

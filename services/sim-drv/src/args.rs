//! The simulated DRV's arguments as a launch line gives them, and the simulator they make: the
//! world as built (not as mapped), the mission's start, the poles placed, the movers added.

use std::path::PathBuf;

use clap::Parser;

use crate::SimDrv;

#[derive(Parser)]
#[command(about = "Simulated Denning DRV speaking the DRV protocol on a pseudo-terminal")]
pub struct Args {
    /// World file to drive in.
    #[arg(long)]
    pub world: PathBuf,
    /// Where to put the symlink to the terminal the bridge opens.
    #[arg(long)]
    pub pty: PathBuf,
    /// Simulated time per tick.
    #[arg(long, default_value_t = 50)]
    pub tick_ms: u64,
    /// Simulated seconds per wall-clock second.
    #[arg(long, default_value_t = 1.0)]
    pub speedup: f64,
    /// Seed of the error model.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where the robot starts, `x_m,y_m,heading_deg`, instead of the world's `[start]` (a
    /// mission's own start).
    #[arg(long)]
    pub start: Option<harvey_world::Pose2>,
    /// A launch file whose `[[mover]]` tables put moving things in the world.
    #[arg(long)]
    pub movers: Option<PathBuf>,
    /// Stop when no frame has come from the host for this long of simulated time (the DRV's
    /// watchdog; in lockstep every tick's `SY` feeds it).
    #[arg(long, default_value_t = 200)]
    pub watchdog_ms: u64,
}

impl Args {
    /// The simulator these arguments describe.
    pub fn simulator(&self) -> anyhow::Result<SimDrv> {
        anyhow::ensure!(self.tick_ms > 0 && self.speedup > 0.0, "--tick-ms and --speedup must be positive");
        // The world as built, not as mapped: the robot's services keep the file (`[map_error]`).
        let mut world = harvey_world::World::load(&self.world)?.as_built(self.seed);
        if let Some(start) = self.start {
            world.start = start;
        }
        for p in world.place_poles(self.seed)? {
            tracing::info!(code = p.code, x_m = p.at[0], y_m = p.at[1], "pole placed");
        }
        if let Some(file) = &self.movers {
            world.add_movers(harvey_world::load_movers(file)?);
        }
        Ok(SimDrv::new(world, self.tick_ms, self.seed))
    }
}

//! harvey-executive: runs the launch file's `[mission]`, commanding the vehicle and watching
//! odometry, sonar, vision and the uncertainty map. Exits 0 when the mission succeeds, 3 when it
//! fails.

use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_executive::{Executive, Output, mission};
use harvey_msgs::{MissionState, topics};

#[derive(Parser)]
#[command(about = "Mission executive")]
struct Args {
    /// The launch file holding the `[mission]` table.
    #[arg(long)]
    mission: PathBuf,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let text = std::fs::read_to_string(&args.mission)
        .with_context(|| format!("reading {}", args.mission.display()))?;
    let mission = mission::parse(&text, &args.mission.display().to_string()).map_err(anyhow::Error::msg)?;
    tracing::info!(description = %mission.description, steps = mission.steps.len(), "mission loaded");

    let bus = Bus::join("executive")?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let sonar = bus.subscriber(topics::SONAR_RING)?;
    let detections = bus.subscriber(topics::VISION_DETECTIONS)?;
    let maps = bus.subscriber(topics::UMS_MAP)?;
    let commands = bus.publisher(topics::VEHICLE_COMMAND)?;
    let status = bus.publisher(topics::EXECUTIVE_STATUS)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&odometry, &sonar, &detections, &maps])?;
    harvey_runtime::notify_ready()?;

    let mut exec = Executive::new(mission);
    let mut odos = Vec::new();
    while exec.state() == MissionState::Running {
        if pace.next(&waiter, None)? == Step::Stop {
            tracing::warn!("stopped before the mission ended");
            return Ok(());
        }
        exec.sonar_rings_seen += sonar.drain(|_| {})? as u64;
        exec.detections_seen += detections.drain(|_| {})? as u64;
        exec.maps_seen += maps.drain(|_| {})? as u64;
        odometry.drain_into(&mut odos)?;
        for o in &odos {
            for out in exec.on_odometry(o) {
                match out {
                    Output::Command(c) => {
                        tracing::info!(
                            id = c.command_id,
                            kind = c.kind,
                            distance_m = c.distance_m,
                            angle_rad = c.angle_rad,
                            "command"
                        );
                        commands.send(&c)?;
                    }
                    Output::Status(s) => {
                        status.send(&s)?;
                    }
                }
            }
        }
        pace.done()?;
    }
    match exec.state() {
        MissionState::Succeeded => {
            tracing::info!("mission succeeded");
            Ok(())
        }
        _ => {
            tracing::error!("mission failed");
            std::process::exit(3)
        }
    }
}

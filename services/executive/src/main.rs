//! harvey-executive: runs the launch file's `[mission]`, commanding the vehicle and watching
//! odometry, sonar, vision and the uncertainty map; asks the vision workers for the landmarks it
//! servos on. Exits 0 when the mission succeeds, 3 when it fails.

use std::path::PathBuf;

use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_executive::{Executive, Output, setup};
use harvey_msgs::{MissionState, topics};

#[derive(Parser)]
#[command(about = "Mission executive")]
struct Args {
    /// The launch file holding the `[mission]` table.
    #[arg(long)]
    mission: PathBuf,
    /// The world file (needed by missions that servo on landmarks).
    #[arg(long)]
    world: Option<PathBuf>,
    /// Seed of the noise motor schema.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let loaded = setup::load(&args.mission, args.world.as_deref(), args.seed)?;
    let mission = &loaded.mission;
    tracing::info!(description = %mission.description, steps = mission.steps.len(), "mission loaded");
    let mut exec = loaded.executive;

    let bus = Bus::join("executive")?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let sonar = bus.subscriber(topics::SONAR_RING)?;
    let detections = bus.subscriber(topics::VISION_DETECTIONS)?;
    let maps = bus.subscriber(topics::UMS_MAP)?;
    let results = bus.subscriber(topics::VISION_RESULTS)?;
    let commands = bus.publisher(topics::VEHICLE_COMMAND)?;
    let status = bus.publisher(topics::EXECUTIVE_STATUS)?;
    let requests = bus.publisher(topics::VISION_REQUESTS)?;
    let servo_pub = bus.publisher(topics::EXECUTIVE_SERVO)?;
    let pose_pub = bus.publisher(topics::EXECUTIVE_POSE)?;
    let behaviour_pub = bus.publisher(topics::EXECUTIVE_BEHAVIOUR)?;
    let plan_pub = bus.publisher(topics::EXECUTIVE_PLAN)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&odometry, &sonar, &detections, &maps, &results])?;
    harvey_runtime::notify_ready()?;

    let (mut odos, mut seen, mut rings, mut map_batch) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut out = Vec::new();
    while exec.state() == MissionState::Running {
        if pace.next(&waiter, None)? == Step::Stop {
            tracing::warn!("stopped before the mission ended");
            return Ok(());
        }
        sonar.drain_into(&mut rings)?;
        for r in &rings {
            exec.on_sonar(r);
        }
        exec.on_detections(detections.drain(|_| {})? as u64);
        maps.drain_into(&mut map_batch)?;
        for m in &map_batch {
            exec.on_map(m);
        }
        results.drain_into(&mut seen)?;
        odometry.drain_into(&mut odos)?;
        out.clear();
        for r in &seen {
            out.extend(exec.on_vision(r));
        }
        for o in &odos {
            out.extend(exec.on_odometry(o));
        }
        for o in &out {
            match o {
                Output::Command(c) => {
                    tracing::info!(
                        id = c.command_id,
                        kind = c.kind,
                        distance_m = c.distance_m,
                        angle_rad = c.angle_rad,
                        "command"
                    );
                    commands.send(c)?;
                }
                Output::Look(r) => {
                    requests.send(r)?;
                }
                Output::Status(s) => {
                    status.send(s)?;
                }
                Output::Servo(c) => {
                    servo_pub.send(c)?;
                }
                Output::Pose(p) => {
                    pose_pub.send(p)?;
                }
                Output::Plan(p) => {
                    plan_pub.send(p)?;
                }
                Output::Behaviour(b) => {
                    behaviour_pub.send(b)?;
                }
            }
        }
        pace.done()?;
    }
    summarise(&exec)
}

/// Logs the servoed legs and exits as the mission ended.
fn summarise(exec: &Executive) -> anyhow::Result<()> {
    for (k, leg) in exec.legs().iter().enumerate() {
        let worst = leg.corrections.iter().map(|c| c.1.abs()).fold(0.0, f64::max);
        tracing::info!(
            leg = k,
            corrections = leg.corrections.len(),
            misses = leg.misses,
            largest_correction_deg = worst.to_degrees(),
            "servoed leg"
        );
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

//! harvey-sonar: raw DRV sonar banks in, the 24-sensor ring out; panic-stop commands go
//! straight to the vehicle.

use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_msgs::topics;
use harvey_sonar::SonarRingBuilder;

#[derive(Parser)]
#[command(about = "Sonar ring assembly and the panic-stop reflex")]
struct Args {
    /// A reading ahead closer than this stops the robot (001 §6.2 gives 2 ft as its example).
    #[arg(long, default_value_t = 2.0)]
    panic_stop_ft: f64,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let bus = Bus::join("sonar")?;
    let raw = bus.subscriber(topics::DRV_SONAR_RAW)?;
    let ring_pub = bus.publisher(topics::SONAR_RING)?;
    let stop_pub = bus.publisher(topics::VEHICLE_COMMAND)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&raw])?;
    harvey_runtime::notify_ready()?;

    let mut ring = SonarRingBuilder::new(args.panic_stop_ft * 0.3048);
    let mut banks = Vec::new();
    let mut rings = 0u64;
    while pace.next(&waiter, None)? != Step::Stop {
        raw.drain_into(&mut banks)?;
        for bank in &banks {
            match ring.on_bank(bank) {
                Ok(update) => {
                    if let Some(stop) = update.panic_stop {
                        stop_pub.send(&stop)?;
                    }
                    ring_pub.send(&update.ring)?;
                    rings += 1;
                }
                Err(e) => tracing::warn!("dropping a sonar report: {e}"),
            }
        }
        pace.done()?;
    }
    tracing::info!(rings, "sonar stopped");
    Ok(())
}

//! harvey-encoders: DRV shaft-encoder reports and motion commands in, odometry out.

use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_encoders::OdometryBuilder;
use harvey_msgs::topics;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let bus = Bus::join("encoders")?;
    let raw = bus.subscriber(topics::DRV_ENCODERS_RAW)?;
    let commands = bus.subscriber(topics::VEHICLE_COMMAND)?;
    let reflexes = bus.subscriber(topics::VEHICLE_REFLEX)?;
    let odometry = bus.publisher(topics::ODOMETRY)?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&raw, &commands, &reflexes])?;
    harvey_runtime::notify_ready()?;

    let mut builder = OdometryBuilder::default();
    let (mut reports, mut cmds) = (Vec::new(), Vec::new());
    while pace.next(&waiter, None)? != Step::Stop {
        commands.drain_into(&mut cmds)?;
        cmds.iter().for_each(|c| builder.on_command(c));
        reflexes.drain_into(&mut cmds)?;
        cmds.iter().for_each(|c| builder.on_command(c));
        raw.drain_into(&mut reports)?;
        for r in &reports {
            match builder.on_encoders(r) {
                Ok(odo) => {
                    odometry.send(&odo)?;
                }
                Err(e) => tracing::warn!("dropping an encoder report: {e}"),
            }
        }
        pace.done()?;
    }
    Ok(())
}

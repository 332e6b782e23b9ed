//! harvey-encoders: DRV shaft-encoder reports and motion commands in, odometry out. Its state
//! (the command under way and where it started) is checkpointed at every tick, so a restarted
//! encoders service goes on with the same command (`harvey_runtime::Resume`).

use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_encoders::OdometryBuilder;
use harvey_msgs::{Message, topics};
use harvey_runtime::{Resume, Rosout};

/// Room for the builder and the marks of its three inputs.
const SLOT_BYTES: usize = 4 << 10;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let bus = Bus::join("encoders")?;
    let raw = bus.subscriber(topics::DRV_ENCODERS_RAW)?;
    let commands = bus.subscriber(topics::VEHICLE_COMMAND)?;
    let reflexes = bus.subscriber(topics::VEHICLE_REFLEX)?;
    let odometry = bus.publisher(topics::ODOMETRY)?;
    let mut rosout = Rosout::new(&bus, "encoders")?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&raw, &commands, &reflexes])?;
    let mut resume = Resume::from_env("encoders", SLOT_BYTES, OdometryBuilder::default)?;
    if resume.resumed() {
        tracing::warn!("resumed from the checkpoint");
    }
    let mut sent = harvey_runtime::Sent::from_env("encoders")?;
    harvey_runtime::notify_ready()?;

    let (mut reports, mut cmds) = (Vec::new(), Vec::new());
    let fresh = |resume: &mut Resume<OdometryBuilder>, topic: &str, msgs: &mut Vec<_>| {
        msgs.retain(|m: &harvey_msgs::MotionCommand| {
            resume.fresh(topic, m.header().stamp_ns, m.header().seq)
        });
    };
    let mut newest = 0;
    while let Step::Go(tick) = pace.next(&waiter, None)? {
        rosout.begin();
        commands.drain_into(&mut cmds)?;
        fresh(&mut resume, commands.topic(), &mut cmds);
        cmds.iter().for_each(|c| resume.state().on_command(c));
        reflexes.drain_into(&mut cmds)?;
        fresh(&mut resume, reflexes.topic(), &mut cmds);
        cmds.iter().for_each(|c| resume.state().on_command(c));
        raw.drain_into(&mut reports)?;
        reports.retain(|r| resume.fresh(raw.topic(), r.header.stamp_ns, r.header.seq));
        newest = reports.iter().map(|r| r.header.stamp_ns).fold(newest, u64::max);
        for r in &reports {
            match resume.state().on_encoders(r) {
                Ok(odo) => {
                    let (topic, h) = (odometry.topic(), odo.header);
                    if sent.due(topic, h.stamp_ns, h.seq) {
                        odometry.send(&odo)?;
                        sent.done(topic, h.stamp_ns, h.seq)?;
                    }
                }
                Err(e) => tracing::warn!("dropping an encoder report: {e}"),
            }
        }
        rosout.end(tick.unwrap_or(newest))?;
        resume.tick_done()?;
        pace.done()?;
    }
    Ok(())
}

//! harvey-sonar: raw DRV sonar banks in, the 24-sensor ring out; the panic-stop and panic-avoid
//! reflexes' commands go straight to the vehicle (001 §6.2). The ring and the reflexes' state are
//! checkpointed every tick, so a restarted sonar service goes on where it was.

use clap::Parser;
use harvey_bus::{Bus, Pace, Publisher, Step, Waiter};
use harvey_msgs::{Message, topics};
use harvey_runtime::{Resume, Sent};
use harvey_sonar::SonarRingBuilder;
use harvey_sonar::avoid::{AvoidParams, PanicAvoid};

#[derive(Parser)]
#[command(about = "Sonar ring assembly and the panic-stop and panic-avoid reflexes")]
struct Args {
    /// A reading ahead closer than this stops the robot (001 §6.2 gives 2 ft as its example).
    #[arg(long, default_value_t = 2.0)]
    panic_stop_ft: f64,
    /// Panic-avoid: an object approaching head-on with less than this time to contact (s)…
    /// (the paper gives none; the DRV needs about 6 s to turn a right angle at 30 deg/s and dash
    /// 2 ft at 1 ft/s, plus a second to confirm the approach)
    #[arg(long, default_value_t = 8.0)]
    avoid_ttc_s: f64,
    /// …over this many consecutive readings ("several", 001 §6.2)…
    #[arg(long, default_value_t = 3)]
    avoid_confirm: u32,
    /// …and coming at the robot at least this fast (ft/s) of its own…
    #[arg(long, default_value_t = 0.5)]
    avoid_min_approach_ftps: f64,
    /// …makes it turn this far (001 §6.2: 90 degrees)…
    #[arg(long, default_value_t = 90.0)]
    avoid_turn_deg: f64,
    /// …and dash this far to the side, again while the object still approaches (0: no
    /// panic-avoid).
    #[arg(long, default_value_t = 2.0)]
    avoid_dash_ft: f64,
}

/// Sends `m` unless a predecessor of this process sent it before it was killed; `key` names
/// the numbering (the panic-stop and the panic-avoid number their commands apart).
fn send<T: Message>(sent: &mut Sent, key: &str, port: &Publisher<T>, m: &T) -> anyhow::Result<()> {
    let h = *m.header();
    if sent.due(key, h.stamp_ns, h.seq) {
        port.send(m)?;
        sent.done(key, h.stamp_ns, h.seq)?;
    }
    Ok(())
}

/// Room for the ring, the reflexes' state and the marks.
const SLOT_BYTES: usize = 64 << 10;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let bus = Bus::join("sonar")?;
    let raw = bus.subscriber(topics::DRV_SONAR_RAW)?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let ring_pub = bus.publisher(topics::SONAR_RING)?;
    let command_pub = bus.publisher(topics::VEHICLE_REFLEX)?;
    let mut rosout = harvey_runtime::Rosout::new(&bus, "sonar")?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&raw, &odometry])?;
    harvey_runtime::notify_ready()?;

    use harvey_geometry::FT;
    let ring = SonarRingBuilder::new(args.panic_stop_ft * FT);
    let avoid = (args.avoid_dash_ft > 0.0).then(|| {
        PanicAvoid::new(AvoidParams {
            ttc_s: args.avoid_ttc_s,
            confirm: args.avoid_confirm,
            min_approach_mps: args.avoid_min_approach_ftps * FT,
            arc_rad: std::f64::consts::FRAC_PI_6,
            turn_rad: args.avoid_turn_deg.to_radians(),
            dash_m: args.avoid_dash_ft * FT,
            stop_m: args.panic_stop_ft * FT,
        })
    });
    let mut resume = Resume::from_env("sonar", SLOT_BYTES, || (ring, avoid))?;
    let mut sent = Sent::from_env("sonar")?;
    if resume.resumed() {
        tracing::warn!("resumed from the checkpoint");
    }
    let (mut banks, mut poses) = (Vec::new(), Vec::new());
    let (mut rings, mut newest) = (0u64, 0);
    while let Step::Go(tick) = pace.next(&waiter, None)? {
        rosout.begin();
        odometry.drain_into(&mut poses)?;
        poses.retain(|m| resume.fresh(odometry.topic(), m.header().stamp_ns, m.header().seq));
        raw.drain_into(&mut banks)?;
        banks.retain(|m| resume.fresh(raw.topic(), m.header().stamp_ns, m.header().seq));
        newest = banks.iter().map(|b| b.header.stamp_ns).fold(newest, u64::max);
        for o in &poses {
            if let Some(c) = resume.state().1.as_mut().and_then(|a| a.on_odometry(o)) {
                tracing::warn!(command = c.command_id, kind = c.kind, "panic-avoid");
                send(&mut sent, "panic-avoid", &command_pub, &c)?;
            }
        }
        for bank in &banks {
            let (ring, avoid) = resume.state();
            match ring.on_bank(bank) {
                Ok(update) => {
                    let evade = avoid.as_mut().and_then(|a| a.on_ring(&update.ring));
                    if let Some(stop) = update.panic_stop {
                        send(&mut sent, "panic-stop", &command_pub, &stop)?;
                    }
                    if let Some(c) = evade {
                        tracing::warn!("panic-avoid: an object is bearing down; stopping to evade");
                        send(&mut sent, "panic-avoid", &command_pub, &c)?;
                    }
                    send(&mut sent, ring_pub.topic(), &ring_pub, &update.ring)?;
                    rings += 1;
                }
                Err(e) => tracing::warn!("dropping a sonar report: {e}"),
            }
        }
        rosout.end(tick.unwrap_or(newest))?;
        resume.tick_done()?;
        pace.done()?;
    }
    let episodes = resume.state().1.as_ref().map_or(0, |a| a.episodes);
    tracing::info!(rings, episodes, "sonar stopped");
    Ok(())
}

//! harvey-ums: odometry and landmark sightings in; the uncertainty map and the Expecter's
//! windows out.

use std::path::PathBuf;

use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waiter};
use harvey_msgs::topics;
use harvey_runtime::{Rosout, Sent, Throttle};
use harvey_ums::{Config, Output, Ums};

#[derive(Parser)]
#[command(about = "Spatial uncertainty management: the uncertainty map and the Expecter")]
struct Args {
    /// World file: terrain statistics, meadows, landmarks, camera.
    #[arg(long)]
    world: PathBuf,
    /// Probability of the map in standard deviations (002 §3.1: 2 or 3).
    #[arg(long, default_value_t = 3.0)]
    sigmas: f64,
    /// Area above which the robot counts as lost.
    #[arg(long, default_value_t = 4.0)]
    lost_area_m2: f64,
    /// Predicted landmarks missed in a row before the robot counts as lost.
    #[arg(long, default_value_t = 3)]
    lost_after_misses: u32,
    /// Where the robot starts, `x_m,y_m,heading_deg`, instead of the world's `[start]` (a
    /// mission's own start).
    #[arg(long)]
    start: Option<harvey_world::Pose2>,
    /// A pose fix places the robot within this square's half side (m)…
    #[arg(long, default_value_t = 0.05)]
    fix_m: f64,
    /// …and its heading within this either way (degrees).
    #[arg(long, default_value_t = 0.5)]
    fix_heading_deg: f64,
    /// How late a sighting may arrive and still be applied at its own stamp.
    #[arg(long, default_value_t = 2000)]
    history_ms: u64,
    /// A refusal repeated (the same landmark, the same reason) is logged at most once in this
    /// many seconds of message time, with its count.
    #[arg(long, default_value_t = 5.0)]
    repeat_warning_s: f64,
}

/// Sends `m` unless a predecessor of this process sent it before it was killed.
fn send<T: harvey_msgs::Message>(
    sent: &mut Sent,
    port: &harvey_bus::Publisher<T>,
    m: &T,
) -> anyhow::Result<()> {
    let h = *m.header();
    if sent.due(port.topic(), h.stamp_ns, h.seq) {
        port.send(m)?;
        sent.done(port.topic(), h.stamp_ns, h.seq)?;
    }
    Ok(())
}

/// Logs a refusal, unless the same one was logged less than a period ago.
fn warn(throttle: &mut Throttle, e: &dyn std::fmt::Display, stamp_ns: u64) {
    if let Some(said) = throttle.raise(e.to_string(), stamp_ns) {
        tracing::warn!("rejected: {said}");
    }
}

/// Room for the map, its history and the pending sightings.
const SLOT_BYTES: usize = 1 << 20;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    anyhow::ensure!(
        args.sigmas > 0.0 && args.lost_area_m2 > 0.0,
        "--sigmas and --lost-area-m2 must be positive"
    );
    anyhow::ensure!(
        args.repeat_warning_s.is_finite() && args.repeat_warning_s >= 0.0,
        "--repeat-warning-s must be a duration in seconds, not {}",
        args.repeat_warning_s
    );
    let mut world = harvey_world::World::load(&args.world)?;
    if let Some(start) = args.start {
        world.start = start;
    }
    let image_px = (world.camera.width_px, world.camera.height_px);
    let config = Config {
        sigmas: args.sigmas,
        lost_area_m2: args.lost_area_m2,
        lost_after_misses: args.lost_after_misses,
        history_ns: args.history_ms * 1_000_000,
        image_px,
        fix_m: args.fix_m,
        fix_heading_rad: args.fix_heading_deg.to_radians(),
    };
    let bus = Bus::join("ums")?;
    let odometry = bus.subscriber(topics::ODOMETRY)?;
    let sightings = bus.subscriber(topics::VISION_SIGHTINGS)?;
    let fixes = bus.subscriber(topics::EXECUTIVE_POSE)?;
    let map_pub = bus.publisher(topics::UMS_MAP)?;
    let expectations = bus.publisher(topics::UMS_EXPECTATIONS)?;
    let mut rosout = Rosout::new(&bus, "ums")?;
    let pace = Pace::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let _a = pace.attach(&waiter, &[&odometry, &sightings, &fixes])?;
    harvey_runtime::notify_ready()?;

    let mut ums = Ums::new(world, config);
    // The uncertainty and the warnings held back as the last finished tick left them, for a
    // restarted UMS.
    let throttle = Throttle::new((args.repeat_warning_s * 1e9) as u64);
    let mut resume = harvey_runtime::Resume::from_env("ums", SLOT_BYTES, || (ums.state(), throttle))?;
    let mut sent = Sent::from_env("ums")?;
    if resume.resumed() {
        ums.restore(resume.state().0.clone());
        tracing::warn!(
            area_m2 = harvey_ums::geometry::area(&ums.map().polygon),
            "resumed from the checkpoint"
        );
    }
    let mut warnings = resume.state().1.clone();
    let (mut odos, mut seen, mut fixed) = (Vec::new(), Vec::new(), Vec::new());
    let mut newest = 0;
    while let Step::Go(tick) = pace.next(&waiter, None)? {
        rosout.begin();
        sightings.drain_into(&mut seen)?;
        seen.retain(|m| resume.fresh(sightings.topic(), m.header.stamp_ns, m.header.seq));
        for s in &seen {
            if let Err(e) = ums.on_sighting(s) {
                warn(&mut warnings, &e, s.header.stamp_ns);
            }
        }
        fixes.drain_into(&mut fixed)?;
        fixed.retain(|m| resume.fresh(fixes.topic(), m.header.stamp_ns, m.header.seq));
        for f in &fixed {
            if let Err(e) = ums.on_fix(f) {
                warn(&mut warnings, &e, f.header.stamp_ns);
            }
        }
        odometry.drain_into(&mut odos)?;
        odos.retain(|m| resume.fresh(odometry.topic(), m.header.stamp_ns, m.header.seq));
        newest = odos.iter().map(|o| o.header.stamp_ns).fold(newest, u64::max);
        for o in &odos {
            match ums.on_odometry(o) {
                Ok(out) => {
                    for x in out {
                        match x {
                            Output::Map(m) => send(&mut sent, &map_pub, &m)?,
                            Output::Expectation(e) => send(&mut sent, &expectations, &e)?,
                            Output::Rejected(e) => warn(&mut warnings, &e, o.header.stamp_ns),
                        }
                    }
                }
                Err(e) => warn(&mut warnings, &e, o.header.stamp_ns),
            }
        }
        let now = tick.unwrap_or(newest);
        for said in warnings.expire(now) {
            tracing::warn!("rejected: {said}");
        }
        rosout.end(now)?;
        *resume.state() = (ums.state(), warnings.clone());
        resume.tick_done()?;
        pace.done()?;
    }
    Ok(())
}

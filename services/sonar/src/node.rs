//! The sonar service as a node (`harvey_runtime::Node`): its arguments, ports and turn.
use crate::SonarRingBuilder;
use crate::avoid::{AvoidParams, PanicAvoid};
use clap::Parser;
use harvey_msgs::{MotionCommand, Odometry, SonarRaw, SonarRing, topics};
use harvey_runtime::{End, In, Io, Node, Out, Ports};

#[derive(Parser)]
#[command(about = "Sonar ring assembly and the panic-stop and panic-avoid reflexes")]
pub struct Args {
    /// A reading ahead closer than this stops the robot (001 §6.2 gives 2 ft as its example).
    #[arg(long, default_value_t = 2.0)]
    pub panic_stop_ft: f64,
    /// Panic-avoid: an object approaching head-on with less than this time to contact (s)…
    /// (the paper gives none; the DRV needs about 6 s to turn a right angle at 30 deg/s and dash
    /// 2 ft at 1 ft/s, plus a second to confirm the approach)
    #[arg(long, default_value_t = 8.0)]
    pub avoid_ttc_s: f64,
    /// …over this many consecutive readings ("several", 001 §6.2)…
    #[arg(long, default_value_t = 3)]
    pub avoid_confirm: u32,
    /// …and coming at the robot at least this fast (ft/s) of its own…
    #[arg(long, default_value_t = 0.5)]
    pub avoid_min_approach_ftps: f64,
    /// …makes it turn this far (001 §6.2: 90 degrees)…
    #[arg(long, default_value_t = 90.0)]
    pub avoid_turn_deg: f64,
    /// …and dash this far to the side, again while the object still approaches (0: no
    /// panic-avoid).
    #[arg(long, default_value_t = 2.0)]
    pub avoid_dash_ft: f64,
}

/// The sonar service as a node: odometry first (the panic-avoid's dash), then the banks.
pub struct Sonar {
    raw: In<SonarRaw>,
    odometry: In<Odometry>,
    ring_out: Out<SonarRing>,
    commands: Out<MotionCommand>,
    /// The panic-stop's distance and the panic-avoid's settings (none: no panic-avoid).
    stop_m: f64,
    avoid: Option<AvoidParams>,
    banks: Vec<SonarRaw>,
    poses: Vec<Odometry>,
    rings: u64,
}

impl Node for Sonar {
    type State = (SonarRingBuilder, Option<PanicAvoid>);
    /// Room for the ring, the reflexes' state and the marks.
    const CHECKPOINT_BYTES: usize = 64 << 10;

    fn start(&mut self) -> Self::State {
        (SonarRingBuilder::new(self.stop_m), self.avoid.map(PanicAvoid::new))
    }

    fn step(&mut self, (ring, avoid): &mut Self::State, io: &mut Io<'_>) -> anyhow::Result<()> {
        io.take(self.odometry, &mut self.poses)?;
        io.take(self.raw, &mut self.banks)?;
        for o in &self.poses {
            ring.on_odometry(o);
            if let Some(c) = avoid.as_mut().and_then(|a| a.on_odometry(o)) {
                tracing::warn!(command = c.command_id, kind = c.kind, "panic-avoid");
                io.send_as(self.commands, "panic-avoid", &c)?;
            }
        }
        for bank in &self.banks {
            match ring.on_bank(bank) {
                Ok(update) => {
                    let evade = avoid.as_mut().and_then(|a| a.on_ring(&update.ring));
                    if let Some(stop) = update.panic_stop {
                        io.send_as(self.commands, "panic-stop", &stop)?;
                    }
                    if let Some(c) = evade {
                        tracing::warn!("panic-avoid: an object is bearing down; stopping to evade");
                        io.send_as(self.commands, "panic-avoid", &c)?;
                    }
                    io.send(self.ring_out, &update.ring)?;
                    self.rings += 1;
                }
                Err(e) => tracing::warn!("dropping a sonar report: {e}"),
            }
        }
        Ok(())
    }

    fn stopped(&mut self, (_, avoid): &Self::State, _: End) -> anyhow::Result<u8> {
        let episodes = avoid.as_ref().map_or(0, |a| a.episodes);
        tracing::info!(rings = self.rings, episodes, "sonar stopped");
        Ok(0)
    }
}

/// The node the arguments describe, its ports declared on `p`.
pub fn build(args: Args, p: &mut Ports) -> anyhow::Result<Sonar> {
    use harvey_geometry::FT;
    let avoid = (args.avoid_dash_ft > 0.0).then_some(AvoidParams {
        ttc_s: args.avoid_ttc_s,
        confirm: args.avoid_confirm,
        min_approach_mps: args.avoid_min_approach_ftps * FT,
        arc_rad: std::f64::consts::FRAC_PI_6,
        turn_rad: args.avoid_turn_deg.to_radians(),
        dash_m: args.avoid_dash_ft * FT,
        stop_m: args.panic_stop_ft * FT,
    });
    let raw = p.input(topics::DRV_SONAR_RAW);
    // In real time a turn is as late as the newest of these.
    p.time_from(raw);
    Ok(Sonar {
        raw,
        odometry: p.input(topics::ODOMETRY),
        ring_out: p.output(topics::SONAR_RING),
        commands: p.output(topics::VEHICLE_REFLEX),
        stop_m: args.panic_stop_ft * FT,
        avoid,
        banks: Vec::new(),
        poses: Vec::new(),
        rings: 0,
    })
}

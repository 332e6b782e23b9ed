//! The denning-bridge's logic: SI motion commands from the bus become DRV protocol commands (after
//! checks), DRV reports become SI messages for the bus. The only place that knows DRV units.
//! [`watchdog`] stops the vehicle when the executive falls silent; [`link`] is the bridge on a
//! line, whatever carries the line and the topics.

mod args;
mod latch;
pub mod link;
pub mod resume;
pub mod watchdog;

pub use args::Args;
pub use latch::PanicLatch;
pub use resume::{BridgeState, Source};
pub use watchdog::{SHUTDOWN_STOP_ID, WATCHDOG_STOP_ID, Watchdog};

use harvey_drv_protocol::{Command, NakReason, Report};
use harvey_msgs::{CommandKind, EncodersRaw, Header, MotionCommand, SonarRaw};
use latch::forward;

use harvey_geometry::FT;
/// Longest MOVE the bridge sends: the DRV's limit, in feet.
pub const MAX_MOVE_FT: f64 = 100.0;
/// Largest TURN the bridge sends, in degrees.
pub const MAX_TURN_DEG: f64 = 360.0;
/// Fastest velocity command the bridge sends.
pub const MAX_SPEED_FT_PER_S: f64 = 2.0;
pub const MAX_RATE_DEG_PER_S: f64 = 60.0;

/// Why a command was not sent to the vehicle.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refusal {
    #[error("command {id}: unknown kind {kind}")]
    UnknownKind { id: u32, kind: u32 },
    #[error("command {id}: {field} is not a finite number")]
    NotFinite { id: u32, field: &'static str },
    #[error("command {id}: {field} = {value:.3} is beyond the vehicle's limit of {limit}")]
    OutOfRange { id: u32, field: &'static str, value: f64, limit: f64 },
    #[error("command {id}: a panic-stop is in force until t = {until_ns} ns")]
    PanicStop { id: u32, until_ns: u64 },
    #[error("command {id}: the panic-avoid has the vehicle (its command {reflex})")]
    Evading { id: u32, reflex: u32 },
}

/// Converts a bus command to the DRV's, or says why it must not be sent.
pub fn to_drv(cmd: &MotionCommand) -> Result<Command, Refusal> {
    let id = cmd.command_id;
    let kind = cmd.kind().ok_or(Refusal::UnknownKind { id, kind: cmd.kind })?;
    let finite = |field, v: f64| {
        if v.is_finite() { Ok(v) } else { Err(Refusal::NotFinite { id, field }) }
    };
    let within = |field, value: f64, limit: f64| {
        if value.abs() <= limit { Ok(value) } else { Err(Refusal::OutOfRange { id, field, value, limit }) }
    };
    Ok(match kind {
        CommandKind::Stop => Command::Stop { id },
        CommandKind::Move => {
            let ft = within("distance_ft", finite("distance_m", cmd.distance_m)? / FT, MAX_MOVE_FT)?;
            Command::Move { id, hundredths_ft: (ft * 100.0).round() as i32 }
        }
        CommandKind::Turn => {
            let deg = within("angle_deg", finite("angle_rad", cmd.angle_rad)?.to_degrees(), MAX_TURN_DEG)?;
            Command::Turn { id, tenths_deg: (deg * 10.0).round() as i32 }
        }
        CommandKind::Velocity => {
            let v = within("speed_ft_per_s", finite("linear_mps", cmd.linear_mps)? / FT, MAX_SPEED_FT_PER_S)?;
            let w = within(
                "rate_deg_per_s",
                finite("angular_radps", cmd.angular_radps)?.to_degrees(),
                MAX_RATE_DEG_PER_S,
            )?;
            Command::Velocity {
                id,
                hundredths_ft_per_s: (v * 100.0).round() as i32,
                tenths_deg_per_s: (w * 10.0).round() as i32,
            }
        }
    })
}

/// Picks what to send from a batch of commands that arrived together: an urgent stop pre-empts
/// every command in the batch that would drive the vehicle forward, and goes first; the other
/// reflexes' commands (the panic-avoid's stop, which starts its evasion, at the stamp of the
/// panic-stop's) and the executive's turns on the spot and backing away follow it, as the
/// panic-stop's hold lets them; otherwise all, in order.
pub fn prioritise(batch: &[MotionCommand]) -> Vec<MotionCommand> {
    let urgent_stop = |c: &MotionCommand| c.urgent != 0 && c.kind() == Some(CommandKind::Stop);
    let Some(first) = batch.iter().position(urgent_stop) else { return batch.to_vec() };
    let follows = |c: &MotionCommand| c.urgent != 0 || (c.kind() != Some(CommandKind::Stop) && !forward(c));
    std::iter::once(batch[first])
        .chain(batch.iter().enumerate().filter(|&(i, c)| i != first && follows(c)).map(|(_, c)| *c))
        .collect()
}

/// A report turned into a bus message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outgoing {
    Encoders(EncodersRaw),
    Sonar(SonarRaw),
    /// The vehicle refused a command.
    Refused {
        id: u32,
        reason: NakReason,
    },
    Accepted {
        id: u32,
    },
    /// Deterministic mode: the DRV has sent every report of the tick ending at `time_ms`.
    Tick {
        time_ms: u64,
    },
}

/// Report → message converter; numbers each output topic's messages.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Bridge {
    encoder_seq: u64,
    sonar_seq: u64,
}

impl Bridge {
    pub fn on_report(&mut self, r: Report) -> Outgoing {
        match r {
            Report::Encoders {
                time_ms,
                x_hundredths_ft,
                y_hundredths_ft,
                heading_tenths_deg,
                moving,
                command_id,
            } => {
                self.encoder_seq += 1;
                Outgoing::Encoders(EncodersRaw {
                    header: Header::new(self.encoder_seq, time_ms * 1_000_000),
                    x_m: f64::from(x_hundredths_ft) / 100.0 * FT,
                    y_m: f64::from(y_hundredths_ft) / 100.0 * FT,
                    heading_rad: (f64::from(heading_tenths_deg) / 10.0).to_radians(),
                    moving: u32::from(moving),
                    command_id,
                })
            }
            Report::Sonar { time_ms, bank, ranges_tenths_ft } => {
                self.sonar_seq += 1;
                let mut echo_mask = 0;
                let range_m = std::array::from_fn(|i| {
                    let r = ranges_tenths_ft[i];
                    if r < harvey_drv_protocol::SONAR_NO_ECHO {
                        echo_mask |= 1 << i;
                    }
                    (f64::from(r) / 10.0 * FT) as f32
                });
                Outgoing::Sonar(SonarRaw {
                    header: Header::new(self.sonar_seq, time_ms * 1_000_000),
                    bank: u32::from(bank),
                    echo_mask,
                    range_m,
                })
            }
            Report::Ack { id } => Outgoing::Accepted { id },
            Report::Nak { id, reason } => Outgoing::Refused { id, reason },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(kind: CommandKind, distance_m: f64, angle_rad: f64) -> MotionCommand {
        MotionCommand { kind: kind as u32, distance_m, angle_rad, command_id: 4, ..Default::default() }
    }

    #[test]
    fn si_commands_become_drv_units() {
        assert_eq!(
            to_drv(&cmd(CommandKind::Move, 3.048, 0.0)),
            Ok(Command::Move { id: 4, hundredths_ft: 1000 })
        );
        assert_eq!(
            to_drv(&cmd(CommandKind::Turn, 0.0, -std::f64::consts::FRAC_PI_2)),
            Ok(Command::Turn { id: 4, tenths_deg: -900 })
        );
    }

    #[test]
    fn impossible_commands_are_refused() {
        assert!(matches!(
            to_drv(&cmd(CommandKind::Move, 1609.0, 0.0)),
            Err(Refusal::OutOfRange { field: "distance_ft", .. })
        ));
        assert!(matches!(
            to_drv(&cmd(CommandKind::Turn, 0.0, f64::NAN)),
            Err(Refusal::NotFinite { field: "angle_rad", .. })
        ));
        let bad = MotionCommand { kind: 77, ..Default::default() };
        assert!(matches!(to_drv(&bad), Err(Refusal::UnknownKind { kind: 77, .. })));
    }

    #[test]
    fn an_urgent_stop_preempts_its_batch() {
        let mv = cmd(CommandKind::Move, 1.0, 0.0);
        let stop = MotionCommand { urgent: 1, ..cmd(CommandKind::Stop, 0.0, 0.0) };
        assert_eq!(prioritise(&[mv, stop, mv]), vec![stop]);
        let turn = cmd(CommandKind::Turn, 0.0, 0.5);
        assert_eq!(prioritise(&[mv, turn, stop]), vec![stop, turn], "a turn on the spot stays");
        assert_eq!(prioritise(&[mv, mv]).len(), 2);
        // The panic-stop's and the panic-avoid's stops of one ring: both go.
        let evade = MotionCommand { command_id: 9, ..stop };
        assert_eq!(prioritise(&[stop, evade, mv, cmd(CommandKind::Stop, 0.0, 0.0)]), vec![stop, evade]);
    }

    #[test]
    fn reports_become_si_messages() {
        let mut b = Bridge::default();
        let out = b.on_report(Report::Sonar {
            time_ms: 150,
            bank: 1,
            ranges_tenths_ft: [10, 255, 0, 0, 0, 0, 0, 0],
        });
        let Outgoing::Sonar(s) = out else { panic!("{out:?}") };
        assert_eq!((s.header.stamp_ns, s.bank, s.echo_mask & 0b11), (150_000_000, 1, 0b01));
        assert!((s.range_m[0] - 0.3048).abs() < 1e-6);
    }
}

//! The reflexes' hold on the vehicle (001 §6.2): the panic-stop's, which keeps the robot from
//! driving on into what is ahead, and the panic-avoid's, which gives it the vehicle for as
//! long as its evasion runs ("the panic motor commands override any others").

use harvey_drv_protocol::Report;
use harvey_msgs::{CommandKind, MotionCommand, PANIC_STOP_IDS, REFLEX_ID_BIT};

use crate::Refusal;

/// After the panic-avoid's latest step (sent, or seen finished by the vehicle) the executive
/// waits this long (vehicle time, ns) before it has the vehicle back: the reflex sends its next
/// step within a few ticks of the last one finishing, and repeats its holding stop every half
/// second, so a gap shorter than this is still the same evasion.
const EVASION_GAP_NS: u64 = 1_000_000_000;

/// The panic-avoid's latest step.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
struct Evasion {
    id: u32,
    /// A turn or dash the vehicle has not yet reported finished (or refused).
    running: bool,
    /// The vehicle has reported running it.
    named: bool,
    /// Until when (vehicle time, ns) the executive is refused once it is not running.
    until_ns: u64,
}

/// After an urgent stop, commands that would drive the vehicle forward, stamped within
/// `hold_ns` of it, are refused (unless urgent themselves: the panic-avoid's), so that no old
/// or new motion command slips in while the vehicle is brought to a stop (the sonar re-sends
/// the stop with every ring while the vehicle still drives forward; once it stands, the
/// executive holds back its forward commands while the ring says the way ahead is too close).
/// Turning on the spot and backing away are let through:
/// without them a robot stopped before a wall would stay there. While the panic-avoid evades
/// (its stop, turn, dash and holding stops) every command but a reflex's is refused: an
/// executive's command would replace the reflex's step on the vehicle, or find it busy.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct PanicLatch {
    hold_ns: u64,
    until_ns: Option<u64>,
    evasion: Option<Evasion>,
}

impl PanicLatch {
    pub fn new(hold_ns: u64) -> Self {
        Self { hold_ns, until_ns: None, evasion: None }
    }

    /// Lets a command through, or refuses it while a reflex holds the vehicle.
    pub fn admit(&mut self, cmd: &MotionCommand) -> Result<(), Refusal> {
        let (id, stamp) = (cmd.command_id, cmd.header.stamp_ns);
        let stop = cmd.kind() == Some(CommandKind::Stop);
        if cmd.urgent != 0 && id & PANIC_STOP_IDS == REFLEX_ID_BIT {
            // The panic-avoid's (the panic-stop's ids have both top bits).
            let until_ns = stamp.saturating_add(EVASION_GAP_NS);
            self.evasion = Some(Evasion { id, running: !stop, named: false, until_ns });
        }
        if stop && cmd.urgent != 0 {
            let until = stamp.saturating_add(self.hold_ns);
            self.until_ns = Some(self.until_ns.map_or(until, |u| u.max(until)));
            return Ok(());
        }
        if cmd.urgent != 0 {
            return Ok(());
        }
        if let Some(e) = self.evasion {
            if e.running || stamp <= e.until_ns {
                return Err(Refusal::Evading { id, reflex: e.id });
            }
            self.evasion = None;
        }
        match self.until_ns {
            Some(until_ns) if forward(cmd) && stamp <= until_ns => Err(Refusal::PanicStop { id, until_ns }),
            _ => Ok(()),
        }
    }

    /// A report from the vehicle: the panic-avoid's turn or dash is over once the vehicle,
    /// having run it, is still (a panic-stop may have cut it short, and the vehicle then names
    /// the stop), or if the vehicle refused it or never ran it.
    pub fn on_report(&mut self, r: &Report) {
        let Some(e) = self.evasion.as_mut().filter(|e| e.running) else { return };
        match *r {
            Report::Encoders { time_ms, moving, command_id, .. } => {
                let now = time_ms * 1_000_000;
                e.named |= command_id == e.id;
                if !moving && (e.named || now > e.until_ns) {
                    e.running = false;
                    e.until_ns = e.until_ns.max(now + EVASION_GAP_NS);
                }
            }
            Report::Nak { id, .. } if id == e.id => e.running = false,
            _ => {}
        }
    }
}

/// Whether a command would move the vehicle forward (a stop or a turn on the spot would not).
pub(crate) fn forward(cmd: &MotionCommand) -> bool {
    match cmd.kind() {
        Some(CommandKind::Move) => cmd.distance_m > 0.0,
        Some(CommandKind::Velocity) => cmd.linear_mps > 0.0,
        Some(CommandKind::Stop | CommandKind::Turn) => false,
        None => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::Header;

    fn cmd(kind: CommandKind, distance_m: f64, angle_rad: f64) -> MotionCommand {
        MotionCommand { kind: kind as u32, distance_m, angle_rad, command_id: 4, ..Default::default() }
    }

    fn at(c: MotionCommand, stamp_ns: u64) -> MotionCommand {
        MotionCommand { header: Header::new(1, stamp_ns), ..c }
    }

    fn encoders(time_ms: u64, command_id: u32, moving: bool) -> Report {
        Report::Encoders {
            time_ms,
            x_hundredths_ft: 0,
            y_hundredths_ft: 0,
            heading_tenths_deg: 0,
            moving,
            command_id,
        }
    }

    #[test]
    fn a_panic_stop_holds_motion_until_the_obstacle_is_gone() {
        let mut latch = PanicLatch::new(200_000_000);
        let mv = cmd(CommandKind::Move, 1.0, 0.0);
        let panic =
            MotionCommand { urgent: 1, command_id: PANIC_STOP_IDS | 9, ..cmd(CommandKind::Stop, 0.0, 0.0) };
        assert_eq!(latch.admit(&at(mv, 1_000)), Ok(()));
        assert_eq!(latch.admit(&at(panic, 1_000_000_000)), Ok(()));
        assert!(matches!(
            latch.admit(&at(mv, 1_100_000_000)),
            Err(Refusal::PanicStop { until_ns: 1_200_000_000, .. })
        ));
        // The sonar repeats the stop while the obstacle stays: the hold extends.
        assert_eq!(latch.admit(&at(panic, 1_150_000_000)), Ok(()));
        assert!(latch.admit(&at(mv, 1_300_000_000)).is_err());
        assert_eq!(
            latch.admit(&at(cmd(CommandKind::Stop, 0.0, 0.0), 1_300_000_000)),
            Ok(()),
            "plain stops always pass"
        );
        assert_eq!(latch.admit(&at(mv, 1_400_000_000)), Ok(()), "obstacle gone: motion resumes");
        // Held again: turning on the spot and backing away pass, driving on does not.
        latch.admit(&at(panic, 2_000_000_000)).expect("the stop");
        assert_eq!(latch.admit(&at(cmd(CommandKind::Turn, 0.0, 1.0), 2_050_000_000)), Ok(()));
        assert_eq!(latch.admit(&at(cmd(CommandKind::Move, -0.3, 0.0), 2_060_000_000)), Ok(()));
        let back = MotionCommand { linear_mps: -0.1, ..cmd(CommandKind::Velocity, 0.0, 0.0) };
        assert_eq!(latch.admit(&at(back, 2_070_000_000)), Ok(()));
        let on = MotionCommand { linear_mps: 0.1, ..back };
        assert!(latch.admit(&at(on, 2_080_000_000)).is_err());
    }

    #[test]
    fn the_panic_avoid_has_the_vehicle_until_its_evasion_is_over() {
        let mut latch = PanicLatch::new(200_000_000);
        let reflex = |kind, angle, id, stamp| {
            at(MotionCommand { urgent: 1, command_id: REFLEX_ID_BIT | id, ..cmd(kind, 0.6, angle) }, stamp)
        };
        let spin = MotionCommand { angular_radps: 0.4, ..cmd(CommandKind::Velocity, 0.0, 0.0) };
        let s = 1_000_000_000;
        assert_eq!(latch.admit(&reflex(CommandKind::Stop, 0.0, 1, 10 * s)), Ok(()));
        // Between the stop and the turn, even a turn on the spot would take the vehicle.
        assert!(matches!(
            latch.admit(&at(spin, 10 * s + 100_000_000)),
            Err(Refusal::Evading { reflex, .. }) if reflex == REFLEX_ID_BIT | 1
        ));
        let turn = reflex(CommandKind::Turn, 1.57, 2, 10 * s + 150_000_000);
        assert_eq!(latch.admit(&turn), Ok(()));
        // The turn takes three seconds, longer than the gap: refused while it runs.
        latch.on_report(&encoders(11_000, turn.command_id, true));
        assert!(latch.admit(&at(spin, 13 * s)).is_err(), "turning");
        latch.on_report(&encoders(13_200, turn.command_id, false));
        assert!(latch.admit(&at(spin, 13 * s + 900_000_000)).is_err(), "the dash is still to come");
        let dash = reflex(CommandKind::Move, 0.0, 3, 13 * s + 300_000_000);
        assert_eq!(latch.admit(&dash), Ok(()));
        // The vehicle refuses the dash: the reflex will send it again, within the gap.
        latch.on_report(&Report::Nak { id: dash.command_id, reason: harvey_drv_protocol::NakReason::Busy });
        assert!(latch.admit(&at(spin, 14 * s)).is_err(), "within a second of the dash");
        assert_eq!(latch.admit(&reflex(CommandKind::Move, 0.0, 4, 14 * s + 300_000_000)), Ok(()));
        latch.on_report(&encoders(14_400, REFLEX_ID_BIT | 4, true));
        // A panic-stop cuts the dash short: the vehicle names the stop.
        latch.on_report(&encoders(16_000, PANIC_STOP_IDS | 8, false));
        // A second after the dash finished, the executive has the vehicle back.
        assert!(latch.admit(&at(spin, 16 * s + 900_000_000)).is_err());
        assert_eq!(latch.admit(&at(spin, 17 * s + 100_000_000)), Ok(()));
        assert_eq!(latch.admit(&at(cmd(CommandKind::Move, 1.0, 0.0), 17 * s + 200_000_000)), Ok(()));
        // A panic-stop's id is not an evasion: turns on the spot still pass after it.
        let panic =
            MotionCommand { urgent: 1, command_id: PANIC_STOP_IDS | 5, ..cmd(CommandKind::Stop, 0.0, 0.0) };
        assert_eq!(latch.admit(&at(panic, 20 * s)), Ok(()));
        assert_eq!(latch.admit(&at(spin, 20 * s + 50_000_000)), Ok(()));
        // A step the vehicle never names (its Nak lost) is over once the gap has passed.
        assert_eq!(latch.admit(&reflex(CommandKind::Turn, 1.57, 6, 30 * s)), Ok(()));
        latch.on_report(&encoders(30_500, PANIC_STOP_IDS | 5, false));
        assert!(latch.admit(&at(spin, 30 * s + 600_000_000)).is_err(), "not yet named");
        latch.on_report(&encoders(31_100, PANIC_STOP_IDS | 5, false));
        assert!(latch.admit(&at(spin, 32 * s)).is_err(), "a second after it was given up");
        assert_eq!(latch.admit(&at(spin, 32 * s + 200_000_000)), Ok(()));
    }
}

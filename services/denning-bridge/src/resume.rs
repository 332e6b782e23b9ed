//! What lets the bridge pick up where it left off, after its line hung up (the simulated DRV
//! restarted) or after it restarted itself: the last round it sent (to send again), what it has
//! already published and forwarded (to drop what a restart delivers twice), and its numbering.
//! The whole state is checkpointed by `main.rs` at every change; nothing here does IO.

use harvey_drv_protocol::{Line, Report};
use harvey_msgs::MotionCommand;

use crate::{Bridge, PanicLatch, Watchdog};

/// Where a command came from (each source numbers its own).
#[derive(Debug, Clone, Copy)]
pub enum Source {
    Commands,
    Reflexes,
}

/// The bridge's state across reconnections and restarts.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct BridgeState {
    pub bridge: Bridge,
    pub latch: PanicLatch,
    pub watchdog: Watchdog,
    /// Lockstep: the tick the last `SY` closed, and that round's lines (the commands and the `SY`).
    pub synced: Option<u64>,
    pub round: Vec<String>,
    /// Vehicle times of the newest encoder report, sonar report and tick mark published.
    encoders_ms: Option<u64>,
    sonar_ms: Option<u64>,
    tick_ms: Option<u64>,
    /// The newest stamp among the commands forwarded from each source, and the ids forwarded
    /// at that stamp.
    commands: Newest,
    reflexes: Newest,
}

/// The newest stamp a source's commands were forwarded at, and which ids were.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct Newest {
    stamp_ns: Option<u64>,
    ids: Vec<u32>,
}

impl BridgeState {
    pub fn new(panic_hold_ns: u64, watchdog_ns: u64) -> Self {
        Self {
            bridge: Bridge::default(),
            latch: PanicLatch::new(panic_hold_ns),
            watchdog: Watchdog::new(watchdog_ns),
            synced: None,
            round: Vec::new(),
            encoders_ms: None,
            sonar_ms: None,
            tick_ms: None,
            commands: Newest::default(),
            reflexes: Newest::default(),
        }
    }

    /// Whether a line from the DRV is news: reports and tick marks at or before what was
    /// already published are a repeat (the DRV sent a tick's lines again after a restart).
    pub fn fresh_from_drv(&mut self, line: &Line) -> bool {
        let (slot, t) = match *line {
            Line::Report(Report::Encoders { time_ms, .. }) => (&mut self.encoders_ms, time_ms),
            Line::Report(Report::Sonar { time_ms, .. }) => (&mut self.sonar_ms, time_ms),
            Line::Tick { time_ms } => (&mut self.tick_ms, time_ms),
            _ => return true,
        };
        newer(slot, t)
    }

    /// Whether a command is news: a restarted bridge's subscriber is handed the newest command
    /// again (the topic's history), which its predecessor may already have forwarded. Known by
    /// its stamp and id, not its sequence number: the reflexes' topic has two senders (the
    /// panic-stop and the panic-avoid) numbering their own, often at the same stamp.
    pub fn fresh_command(&mut self, source: Source, cmd: &MotionCommand) -> bool {
        let newest = match source {
            Source::Commands => &mut self.commands,
            Source::Reflexes => &mut self.reflexes,
        };
        let (stamp_ns, id) = (cmd.header.stamp_ns, cmd.command_id);
        match newest.stamp_ns {
            Some(last) if stamp_ns < last => false,
            Some(last) if stamp_ns == last && newest.ids.contains(&id) => false,
            Some(last) if stamp_ns == last => {
                newest.ids.push(id);
                true
            }
            _ => {
                newest.stamp_ns = Some(stamp_ns);
                newest.ids.clear();
                newest.ids.push(id);
                true
            }
        }
    }

    /// Whether the chain's tick `t` still needs its `SY` (a resumed chain may report a tick
    /// twice).
    pub fn needs_sync(&self, t_ms: u64) -> bool {
        self.synced.is_none_or(|s| t_ms > s)
    }
}

fn newer(slot: &mut Option<u64>, t: u64) -> bool {
    if slot.is_some_and(|last| t <= last) {
        return false;
    }
    *slot = Some(t);
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::{CommandKind, Header};

    fn cmd(seq: u64, stamp_ns: u64) -> MotionCommand {
        MotionCommand {
            header: Header::new(seq, stamp_ns),
            kind: CommandKind::Stop as u32,
            command_id: seq as u32,
            ..Default::default()
        }
    }

    fn enc(time_ms: u64) -> Line {
        Line::Report(Report::Encoders {
            time_ms,
            x_hundredths_ft: 0,
            y_hundredths_ft: 0,
            heading_tenths_deg: 0,
            moving: false,
            command_id: 0,
        })
    }

    #[test]
    fn a_tick_sent_again_is_dropped_and_the_next_is_not() {
        let mut s = BridgeState::new(0, 0);
        let sonar = |t| Line::Report(Report::Sonar { time_ms: t, bank: 0, ranges_tenths_ft: [0; 8] });
        assert!(s.fresh_from_drv(&enc(50)));
        // The simulator died after the encoders went out; it sends the whole tick again.
        assert!(!s.fresh_from_drv(&enc(50)));
        assert!(s.fresh_from_drv(&sonar(50)));
        assert!(s.fresh_from_drv(&Line::Tick { time_ms: 50 }));
        assert!(!s.fresh_from_drv(&Line::Tick { time_ms: 50 }));
        assert!(s.fresh_from_drv(&enc(100)));
        assert!(s.fresh_from_drv(&Line::Report(Report::Ack { id: 3 })), "answers are never repeats");
    }

    #[test]
    fn a_command_handed_over_again_is_not_forwarded_twice() {
        let mut s = BridgeState::new(0, 0);
        assert!(s.fresh_command(Source::Commands, &cmd(4, 1_000)));
        assert!(!s.fresh_command(Source::Commands, &cmd(4, 1_000)));
        assert!(s.fresh_command(Source::Reflexes, &cmd(4, 1_000)), "each source numbers its own");
        // The panic-avoid's stop at the stamp of the panic-stop's, numbered lower by its sender.
        let evade = MotionCommand { command_id: harvey_msgs::REFLEX_ID_BIT | 1, ..cmd(1, 1_000) };
        assert!(s.fresh_command(Source::Reflexes, &evade), "another sender at the same stamp");
        assert!(!s.fresh_command(Source::Reflexes, &evade));
        assert!(!s.fresh_command(Source::Reflexes, &cmd(3, 900)), "older");
        // A restarted executive numbers from 1 again, later.
        assert!(s.fresh_command(Source::Commands, &cmd(1, 2_000)));
        assert!(!s.needs_sync(0) || s.synced.is_none());
        s.synced = Some(100);
        assert!(!s.needs_sync(100));
        assert!(s.needs_sync(150));
    }

    #[test]
    fn the_state_survives_its_checkpoint_encoding() {
        let mut s = BridgeState::new(200, 300);
        s.fresh_command(Source::Commands, &cmd(9, 77));
        s.synced = Some(1_250);
        s.round = vec!["$SY,1250*00\n".into()];
        let bytes = postcard::to_allocvec(&s).unwrap();
        let back: BridgeState = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(format!("{back:?}"), format!("{s:?}"));
    }
}

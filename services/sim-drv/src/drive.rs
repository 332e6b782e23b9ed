//! The simulated DRV's side of the line, tick by tick, with its state checkpointed so that a
//! restarted simulator is the same robot at the same moment.
//!
//! In lockstep a tick is a round: the host's commands, then its `SY t` for the tick it has
//! finished; the DRV answers the commands, simulates the next tick and sends its reports and
//! `TK`. The state after the tick and the round's lines are saved before anything goes out, so a
//! simulator killed at any point comes back either before the tick (the host's repeated round
//! runs it) or after it (a repeated `SY` for the tick before gets the saved lines again; the
//! bridge drops reports it has already published).

use std::io::Write;

use harvey_drv_protocol::serial::write_frame;
use harvey_drv_protocol::{Command, Line, encode};
use harvey_msgs::{Header, TruePose};
use harvey_runtime::Checkpoint;

use crate::watchdog::HostWatchdog;
use crate::{SimDrv, SimState};

/// Room for the state and a round's lines.
pub const SLOT_BYTES: usize = 16 << 10;

/// What a checkpoint keeps.
#[derive(serde::Serialize, serde::Deserialize)]
struct Saved {
    state: SimState,
    /// The last round's lines, as sent (lockstep).
    round: Vec<String>,
    /// Whether the tick's true pose went out on the bus.
    truth_sent: bool,
}

/// The simulator on its line; `T` puts the true pose on the bus (or an in-process hub).
pub struct Drive<T> {
    pub sim: SimDrv,
    pub watchdog: HostWatchdog,
    truth_out: T,
    tick_ms: u64,
    checkpoint: Option<Checkpoint>,
    round: Vec<String>,
    truth_sent: bool,
    /// Commands of the round under way (lockstep), answered when its `SY` comes.
    pending: Vec<Command>,
    pub dropped_frames: u64,
}

impl<T: FnMut(&TruePose) -> anyhow::Result<()>> Drive<T> {
    /// A simulator, restored from its checkpoint if an earlier one of this run left one.
    pub fn new(
        mut sim: SimDrv,
        watchdog: HostWatchdog,
        truth_out: T,
        tick_ms: u64,
        mut checkpoint: Option<Checkpoint>,
    ) -> anyhow::Result<Self> {
        let (mut round, mut truth_sent, mut watchdog) = (Vec::new(), true, watchdog);
        if let Some(saved) = checkpoint.as_mut().map(|c| c.load::<Saved>()).transpose()?.flatten() {
            sim.restore(saved.state);
            tracing::warn!(time_ms = sim.time_ms(), truth = ?sim.truth(), "resumed from the checkpoint: the same vehicle, the same moment");
            // A host silent from here on stops a vehicle that was moving.
            watchdog.feed(sim.time_ms());
            (round, truth_sent) = (saved.round, saved.truth_sent);
        }
        let d = Self {
            sim,
            watchdog,
            truth_out,
            tick_ms,
            checkpoint,
            round,
            truth_sent,
            pending: Vec::new(),
            dropped_frames: 0,
        };
        Ok(d)
    }

    /// A frame from the host.
    pub fn on_line(&mut self, line: &mut impl Write, l: Line, lockstep: bool) -> anyhow::Result<()> {
        self.watchdog.feed(self.sim.time_ms());
        match l {
            Line::Command(cmd) if lockstep => self.pending.push(cmd),
            Line::Command(cmd) => {
                let answer = Line::Report(self.sim.handle(cmd));
                self.send(line, &encode(&answer))?;
            }
            Line::Sync { time_ms } if lockstep => self.on_sync(line, time_ms)?,
            Line::Heartbeat { .. } => {}
            other => tracing::warn!(?other, "ignoring a frame the DRV does not take here"),
        }
        Ok(())
    }

    /// `SY t`: the host has finished tick `t`.
    fn on_sync(&mut self, line: &mut impl Write, time_ms: u64) -> anyhow::Result<()> {
        let commands = std::mem::take(&mut self.pending);
        let now = self.sim.time_ms();
        if time_ms == now {
            let mut round = Vec::with_capacity(commands.len() + 3);
            for cmd in commands {
                round.push(encode(&Line::Report(self.sim.handle(cmd))));
            }
            self.guard();
            let out = self.sim.tick();
            round.extend(out.reports.iter().map(|r| encode(&Line::Report(*r))));
            round.push(encode(&Line::Tick { time_ms: out.time_ms }));
            self.round = round;
            self.truth_sent = false;
            self.save()?;
            self.publish_truth()?;
            self.resend(line)
        } else if time_ms + self.tick_ms == now && !self.round.is_empty() {
            // The host missed the tick's lines (it or this simulator restarted): again, as they
            // were, and not the commands a second time.
            tracing::warn!(time_ms, sim_ms = now, "SY for the tick before: sending its lines again");
            if !self.truth_sent {
                self.publish_truth()?;
            }
            self.resend(line)
        } else {
            tracing::warn!(time_ms, sim_ms = now, "SY for another tick: ignored");
            Ok(())
        }
    }

    /// Real time: the next tick, with its reports sent at once.
    pub fn tick_now(&mut self, line: &mut impl Write) -> anyhow::Result<()> {
        self.guard();
        let out = self.sim.tick();
        self.round = out.reports.iter().map(|r| encode(&Line::Report(*r))).collect();
        self.truth_sent = false;
        self.save()?;
        self.publish_truth()?;
        self.resend(line)
    }

    /// The DRV's watchdog: a vehicle whose host has fallen silent stops before the next tick.
    fn guard(&mut self) {
        if self.sim.is_moving() && self.watchdog.lapsed(self.sim.time_ms()) {
            tracing::error!(
                time_ms = self.sim.time_ms(),
                "no frame from the host within the deadline: stopping"
            );
            self.sim.halt();
        }
    }

    fn publish_truth(&mut self) -> anyhow::Result<()> {
        let stamp_ns = self.sim.time_ms() * 1_000_000;
        (self.truth_out)(&TruePose {
            header: Header::new(stamp_ns / (self.tick_ms * 1_000_000), stamp_ns),
            world_from_robot: self.sim.truth(),
        })?;
        self.truth_sent = true;
        self.save()
    }

    fn resend(&mut self, line: &mut impl Write) -> anyhow::Result<()> {
        for frame in &self.round {
            self.dropped_frames += u64::from(!write_frame(line, frame.as_bytes())?);
        }
        Ok(())
    }

    fn send(&mut self, line: &mut impl Write, frame: &str) -> anyhow::Result<()> {
        self.dropped_frames += u64::from(!write_frame(line, frame.as_bytes())?);
        Ok(())
    }

    fn save(&mut self) -> anyhow::Result<()> {
        let Some(c) = self.checkpoint.as_mut() else { return Ok(()) };
        let saved = Saved { state: self.sim.state(), round: self.round.clone(), truth_sent: self.truth_sent };
        Ok(c.save(&saved)?)
    }
}

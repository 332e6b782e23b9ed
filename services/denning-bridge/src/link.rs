//! The bridge's side of one DRV line: the line with the state that outlives it (checkpointed
//! at every change), forwarding commands down the line once each, and putting the DRV's lines
//! on the bus. The line is any byte stream (a serial port, a pseudo-terminal, an in-process
//! buffer) and the bus whatever [`BridgePorts`] a runner gives (iceoryx2, an in-process hub).

use std::io::Write;

use harvey_drv_protocol::serial::write_frame;
use harvey_drv_protocol::{Command, Decoder, Line, encode};
use harvey_msgs::{EncodersRaw, MotionCommand, SonarRaw};
use harvey_runtime::{Checkpoint, Rosout};

use crate::{BridgeState, Outgoing, Refusal, Source, WATCHDOG_STOP_ID, prioritise, to_drv};

/// Why the loop over one connection ended.
pub enum Ended {
    Shutdown,
    HungUp,
}

/// The bridge's topics as a runner opened them.
pub trait BridgePorts {
    /// The motion commands that came in since the last call, oldest first, into `batch`: the
    /// reflexes' first, then the executive's. Returns how many are the reflexes'.
    fn commands(&mut self, batch: &mut Vec<MotionCommand>) -> anyhow::Result<usize>;
    fn encoders(&mut self, m: &EncodersRaw) -> anyhow::Result<()>;
    fn sonar(&mut self, m: &SonarRaw) -> anyhow::Result<()>;
    /// The DRV's `TK`: it has closed the reports of tick `time_ms`. In lockstep the bridge's
    /// warnings since the last tick go out on `rosout` before the chain starts on the tick.
    fn tick(&mut self, rosout: &mut Rosout, time_ms: u64) -> anyhow::Result<()>;
}

/// The line and the state that outlives it.
pub struct Link<'a, P> {
    pub port: P,
    pub state: &'a mut BridgeState,
    pub checkpoint: Option<&'a mut Checkpoint>,
    /// The bridge's warnings, published with each tick it starts (lockstep) or each wake-up.
    pub rosout: Rosout,
}

impl<P: Write> Link<'_, P> {
    pub fn save(&mut self) -> anyhow::Result<()> {
        match self.checkpoint.as_deref_mut() {
            Some(c) => Ok(c.save(&*self.state)?),
            None => Ok(()),
        }
    }

    pub fn send_raw(&mut self, frame: &str) -> anyhow::Result<()> {
        if !write_frame(&mut self.port, frame.as_bytes())? {
            tracing::error!(frame, "serial line full: frame not sent");
        }
        Ok(())
    }
}

/// Sends the commands that arrived (each once, across restarts); in lockstep the round's lines
/// are kept to send again. True if any came from the executive.
pub fn forward<P: Write>(
    link: &mut Link<'_, P>,
    ports: &mut impl BridgePorts,
    batch: &mut Vec<MotionCommand>,
    round: &mut Vec<String>,
) -> anyhow::Result<bool> {
    batch.clear();
    // The reflexes' commands first: an urgent stop among them pre-empts the batch.
    let reflexes = ports.commands(batch)?;
    let executive = batch.len() > reflexes;
    let mut i = 0;
    batch.retain(|c| {
        let source = if i < reflexes { Source::Reflexes } else { Source::Commands };
        i += 1;
        link.state.fresh_command(source, c)
    });
    for cmd in prioritise(batch) {
        match link.state.latch.admit(&cmd).and_then(|()| to_drv(&cmd)) {
            Ok(drv) => {
                let frame = encode(&Line::Command(drv));
                link.send_raw(&frame)?;
                round.push(frame);
            }
            // The executive's commands while the panic-avoid evades: expected, many a second.
            Err(refusal @ Refusal::Evading { .. }) => tracing::debug!("refused: {refusal}"),
            Err(refusal) => tracing::error!("refused: {refusal}"),
        }
    }
    Ok(executive)
}

/// Lockstep: the chain has finished tick `t_ms`. The commands that came in go down the line,
/// closed by `SY t`, and the round is kept to send again after a restart. True if any came from
/// the executive.
pub fn sync<P: Write>(
    link: &mut Link<'_, P>,
    ports: &mut impl BridgePorts,
    t_ms: u64,
    batch: &mut Vec<MotionCommand>,
    round: &mut Vec<String>,
) -> anyhow::Result<bool> {
    if !link.state.needs_sync(t_ms) {
        return Ok(false);
    }
    round.clear();
    let commanded = forward(link, ports, batch, round)?;
    let sync = encode(&Line::Sync { time_ms: t_ms });
    round.push(sync.clone());
    (link.state.synced, link.state.round) = (Some(t_ms), std::mem::take(round));
    link.save()?;
    link.send_raw(&sync)?;
    Ok(commanded)
}

/// Puts what the DRV sent (`bytes`, read off the line) on the bus, line by line; repeats of
/// lines already published are dropped.
pub fn receive<P: Write>(
    watchdog_ms: u64,
    link: &mut Link<'_, P>,
    ports: &mut impl BridgePorts,
    decoder: &mut Decoder,
    bytes: &[u8],
) -> anyhow::Result<()> {
    let mut lines = Vec::new();
    decoder.push(bytes, |frame| match frame {
        Ok(line) => lines.push(line),
        Err(e) => tracing::warn!("bad frame from the DRV: {e}"),
    });
    for line in lines {
        if !link.state.fresh_from_drv(&line) {
            tracing::debug!(?line, "a repeat of a line already published");
            continue;
        }
        publish(watchdog_ms, link, ports, line)?;
    }
    Ok(())
}

/// Puts one line from the DRV on the bus.
pub fn publish<P: Write>(
    watchdog_ms: u64,
    link: &mut Link<'_, P>,
    ports: &mut impl BridgePorts,
    line: Line,
) -> anyhow::Result<()> {
    let out = match line {
        Line::Report(r) => {
            link.state.latch.on_report(&r);
            link.state.bridge.on_report(r)
        }
        Line::Tick { time_ms } => Outgoing::Tick { time_ms },
        line @ (Line::Command(_) | Line::Sync { .. } | Line::Heartbeat { .. }) => {
            tracing::warn!(?line, "ignoring a host frame echoed by the vehicle");
            return Ok(());
        }
    };
    let stamp_ns = match out {
        Outgoing::Encoders(m) => {
            ports.encoders(&m)?;
            Some(m.header.stamp_ns)
        }
        Outgoing::Sonar(m) => {
            ports.sonar(&m)?;
            Some(m.header.stamp_ns)
        }
        Outgoing::Tick { time_ms } => {
            ports.tick(&mut link.rosout, time_ms)?;
            None
        }
        Outgoing::Refused { id, reason } => {
            tracing::error!(id, ?reason, "the DRV refused a command");
            None
        }
        Outgoing::Accepted { id } => {
            tracing::debug!(id, "the DRV accepted a command");
            None
        }
    };
    if stamp_ns.is_some_and(|t| link.state.watchdog.on_vehicle_time(t)) {
        tracing::error!(
            deadline_ms = watchdog_ms,
            vehicle_ms = link.state.watchdog.now_ms(),
            "no heartbeat from the executive: stopping the vehicle"
        );
        send(&mut link.port, &Line::Command(Command::Stop { id: WATCHDOG_STOP_ID }))?;
    }
    link.save()
}

/// Writes one frame to the DRV; a full line loses it, loudly.
pub fn send(port: &mut impl Write, line: &Line) -> anyhow::Result<()> {
    if !write_frame(port, encode(line).as_bytes())? {
        tracing::error!(?line, "serial line full: frame not sent");
    }
    Ok(())
}

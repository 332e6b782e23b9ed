//! The bridge's side of one DRV line: the line with the state that outlives it (checkpointed
//! at every change), the bus ports, forwarding commands down the line once each, and putting
//! the DRV's lines on the bus.

use std::fs::File;

use harvey_bus::{Lockstep, Publisher, Subscriber};
use harvey_denning_bridge::{BridgeState, Outgoing, Source, WATCHDOG_STOP_ID, prioritise, to_drv};
use harvey_drv_protocol::serial::write_frame;
use harvey_drv_protocol::{Command, Line, encode};
use harvey_msgs::{EncodersRaw, MissionStatus, MotionCommand, SonarRaw};
use harvey_runtime::{Checkpoint, Rosout};

/// Why the loop over one connection ended.
pub enum Ended {
    Shutdown,
    HungUp,
}

/// The line and the state that outlives it.
pub struct Link<'a> {
    pub port: File,
    pub state: &'a mut BridgeState,
    pub checkpoint: Option<&'a mut Checkpoint>,
    /// The bridge's warnings, published with each tick it starts (lockstep) or each wake-up.
    pub rosout: Rosout,
}

impl Link<'_> {
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

/// The bus ports of the bridge.
pub struct Ports {
    pub commands: Subscriber<MotionCommand>,
    pub reflexes: Subscriber<MotionCommand>,
    pub heartbeat: Subscriber<MissionStatus>,
    pub encoders: Publisher<EncodersRaw>,
    pub sonar: Publisher<SonarRaw>,
}

/// Sends the commands that arrived (each once, across restarts); in lockstep the round's lines
/// are kept to send again. True if any came from the executive.
pub fn forward(
    link: &mut Link,
    ports: &Ports,
    batch: &mut Vec<MotionCommand>,
    round: &mut Vec<String>,
) -> anyhow::Result<bool> {
    batch.clear();
    // The reflexes' commands first: an urgent stop among them pre-empts the batch.
    ports.reflexes.drain(|c| batch.push(*c))?;
    let reflexes = batch.len();
    ports.commands.drain(|c| batch.push(*c))?;
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
            Err(refusal) => tracing::error!("refused: {refusal}"),
        }
    }
    Ok(executive)
}

/// Puts one line from the DRV on the bus.
pub fn publish(
    watchdog_ms: u64,
    link: &mut Link,
    lockstep: &Option<Lockstep>,
    ports: &Ports,
    line: Line,
) -> anyhow::Result<()> {
    let out = match line {
        Line::Report(r) => link.state.bridge.on_report(r),
        Line::Tick { time_ms } => Outgoing::Tick { time_ms },
        line @ (Line::Command(_) | Line::Sync { .. } | Line::Heartbeat { .. }) => {
            tracing::warn!(?line, "ignoring a host frame echoed by the vehicle");
            return Ok(());
        }
    };
    let stamp_ns = match out {
        Outgoing::Encoders(m) => {
            ports.encoders.send(&m)?;
            Some(m.header.stamp_ns)
        }
        Outgoing::Sonar(m) => {
            ports.sonar.send(&m)?;
            Some(m.header.stamp_ns)
        }
        Outgoing::Tick { time_ms } => {
            match lockstep {
                Some(l) => {
                    // What went wrong since the last tick goes out with this one, before the
                    // chain starts on it.
                    link.rosout.end(time_ms * 1_000_000)?;
                    link.rosout.begin();
                    l.finish(time_ms * 1_000_000)?
                }
                None => tracing::warn!(time_ms, "a tick mark from the DRV in real-time mode"),
            }
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
pub fn send(port: &mut File, line: &Line) -> anyhow::Result<()> {
    if !write_frame(port, encode(line).as_bytes())? {
        tracing::error!(?line, "serial line full: frame not sent");
    }
    Ok(())
}

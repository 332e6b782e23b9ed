//! harvey-denning-bridge: connects a DRV serial line (a real port, or the simulated DRV's
//! pseudo-terminal) to the bus. It reopens a line that hangs up, and keeps its state in a
//! checkpoint, so that neither its own restart nor the DRV's loses or repeats a message.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FdSource, Lockstep, Publisher, Reoffers, Subscriber, Waiter, Wake};
use harvey_denning_bridge::link::{BridgePorts, Ended, Link, forward, receive, send, sync};
use harvey_denning_bridge::{Args, BridgeState, SHUTDOWN_STOP_ID};
use harvey_drv_protocol::serial::{make_raw, read_available};
use harvey_drv_protocol::{Command, Decoder, Line};
use harvey_msgs::{EncodersRaw, MissionStatus, MotionCommand, SonarRaw, topics};
use harvey_runtime::{Checkpoint, Rosout};

/// Room for the bridge's state and a round's lines.
const SLOT_BYTES: usize = 16 << 10;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let reopen_for = Duration::from_secs_f64(args.reopen_s.max(0.0));
    let mut checkpoint = Checkpoint::from_env("denning-bridge", SLOT_BYTES)?;
    let restored = checkpoint.as_mut().map(|c| c.load::<BridgeState>()).transpose()?.flatten();
    // A fresh start with no line is a mistake in the launch: say so at once. A restart may
    // race the simulated DRV's own: wait for its line.
    let first_wait = if restored.is_some() { reopen_for } else { Duration::ZERO };
    let port = open_line(&args.device, first_wait)?;

    let bus = Bus::join("denning-bridge")?;
    let ports = Ports {
        commands: bus.subscriber(topics::VEHICLE_COMMAND)?,
        reflexes: bus.subscriber(topics::VEHICLE_REFLEX)?,
        // The executive's heartbeat: it publishes its status every tick.
        heartbeat: bus.subscriber(topics::EXECUTIVE_STATUS)?,
        encoders: bus.publisher(topics::DRV_ENCODERS_RAW)?,
        sonar: bus.publisher(topics::DRV_SONAR_RAW)?,
    };
    // Deterministic mode: the bridge is the clock master on the bus. A tick's turn starts when
    // the DRV's `TK` closes its reports; when the chain's tail has finished the tick, the
    // tick's commands go out, closed by `SY`.
    let lockstep = Lockstep::from_env(&bus)?;
    let mut resumed = restored.is_some();
    let mut state = restored
        .unwrap_or_else(|| BridgeState::new(args.panic_hold_ms * 1_000_000, args.watchdog_ms * 1_000_000));
    if resumed {
        tracing::warn!(synced_ms = ?state.synced, "resumed from the checkpoint");
        // What the predecessor left half read on the line goes: the DRV sends the whole tick
        // again when the last round comes again, and what the predecessor had published of it
        // (its samples outlive it) is dropped as a repeat.
        nix::sys::termios::tcflush(&port, nix::sys::termios::FlushArg::TCIFLUSH)
            .with_context(|| format!("flushing {}", args.device.display()))?;
    }
    let waiter = Waiter::new()?;
    let reoffers = bus.reoffers();
    harvey_runtime::notify_ready()?;
    tracing::info!(device = %args.device.display(), lockstep = lockstep.is_some(), "bridge up");

    let rosout = harvey_runtime::Rosout::new(&bus, "denning-bridge")?;
    let mut link = Link { port, state: &mut state, checkpoint: checkpoint.as_mut(), rosout };
    let result = loop {
        // After a hang-up or a restart the DRV may have missed the last round: it goes again
        // (the DRV answers a round it has already run with that tick's lines, which the bridge
        // then drops as repeats).
        if resumed && lockstep.is_some() {
            for frame in link.state.round.clone() {
                link.send_raw(&frame)?;
            }
        }
        let ended = run(&args, &mut link, &lockstep, &waiter, &ports, &reoffers);
        // Reopening the line is plumbing, not the run's: its warnings stay off `rosout`.
        link.rosout.pause();
        match ended {
            Ok(Ended::Shutdown) => break Ok(()),
            Ok(Ended::HungUp) => {
                tracing::warn!(device = %args.device.display(), "the DRV line hung up: reopening");
                match open_line(&args.device, reopen_for) {
                    Ok(p) => link.port = p,
                    Err(e) => break Err(e),
                }
                resumed = true;
            }
            Err(e) => break Err(e),
        }
    };
    // Whatever ended the loop (a shutdown, an error), the vehicle stops before the bridge goes.
    let stop = send(&mut link.port, &Line::Command(Command::Stop { id: SHUTDOWN_STOP_ID }));
    tracing::info!(sent = stop.is_ok(), "stop sent on the way out");
    result
}

/// Opens the DRV's line, waiting up to `wait` for it to appear (a simulated DRV re-creating its
/// terminal, a USB adapter coming back).
fn open_line(device: &Path, wait: Duration) -> anyhow::Result<File> {
    let deadline = Instant::now() + wait;
    loop {
        let opened = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(nix::libc::O_NOCTTY | nix::libc::O_NONBLOCK)
            .open(device);
        match opened {
            Ok(port) => {
                make_raw(&port).with_context(|| format!("setting {} to raw mode", device.display()))?;
                return Ok(port);
            }
            Err(_) if Instant::now() < deadline => std::thread::sleep(REOPEN_POLL),
            Err(e) => {
                return Err(e).with_context(|| format!("opening DRV serial device {}", device.display()));
            }
        }
    }
}

/// How often a missing line is tried again.
const REOPEN_POLL: Duration = Duration::from_millis(20);

/// The bus ports of the bridge.
struct Ports {
    commands: Subscriber<MotionCommand>,
    reflexes: Subscriber<MotionCommand>,
    heartbeat: Subscriber<MissionStatus>,
    encoders: Publisher<EncodersRaw>,
    sonar: Publisher<SonarRaw>,
}

/// The ports with the bridge's place in the clock chain (lockstep).
struct OnBus<'a> {
    ports: &'a Ports,
    lockstep: &'a Option<Lockstep>,
}

impl BridgePorts for OnBus<'_> {
    fn commands(&mut self, batch: &mut Vec<MotionCommand>) -> anyhow::Result<usize> {
        self.ports.reflexes.drain(|c| batch.push(*c))?;
        let reflexes = batch.len();
        self.ports.commands.drain(|c| batch.push(*c))?;
        Ok(reflexes)
    }

    fn encoders(&mut self, m: &EncodersRaw) -> anyhow::Result<()> {
        self.ports.encoders.send(m)?;
        Ok(())
    }

    fn sonar(&mut self, m: &SonarRaw) -> anyhow::Result<()> {
        self.ports.sonar.send(m)?;
        Ok(())
    }

    fn tick(&mut self, rosout: &mut Rosout, time_ms: u64) -> anyhow::Result<()> {
        match self.lockstep {
            Some(l) => {
                // What went wrong since the last tick goes out with this one, before the
                // chain starts on it.
                rosout.end(time_ms * 1_000_000)?;
                rosout.begin();
                Ok(l.finish(time_ms * 1_000_000)?)
            }
            None => {
                tracing::warn!(time_ms, "a tick mark from the DRV in real-time mode");
                Ok(())
            }
        }
    }
}

/// The bridge's loop over one connection, until shutdown or the line hangs up.
fn run(
    args: &Args,
    link: &mut Link<'_, File>,
    lockstep: &Option<Lockstep>,
    waiter: &Waiter,
    ports: &Ports,
    reoffers: &Reoffers,
) -> anyhow::Result<Ended> {
    let line_source = FdSource::new(&link.port)?;
    let _a = match lockstep {
        Some(l) => waiter.attach(l.predecessor())?,
        None => waiter.attach(&ports.commands)?,
    };
    let _b = waiter.attach(&line_source)?;
    // Real time: a reflex's command wakes the bridge too (in lockstep the chain's turn does).
    let _c = match lockstep {
        Some(_) => None,
        None => Some((waiter.attach(&ports.reflexes)?, waiter.attach(&ports.heartbeat)?)),
    };
    // Lockstep: the supervisor asks for re-offers when a party restarts.
    let _d = match lockstep {
        Some(_) => Some(waiter.attach(reoffers)?),
        None => None,
    };
    let mut on_bus = OnBus { ports, lockstep };
    let mut decoder = Decoder::new();
    let (mut buf, mut batch, mut ticks, mut round) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    link.rosout.begin();
    loop {
        if waiter.wait(None)? == Wake::Shutdown {
            tracing::info!(stats = ?decoder.stats(), "bridge stopped");
            return Ok(Ended::Shutdown);
        }
        reoffers.serve()?;
        let beats = ports.heartbeat.drain(|_| {})?;
        let mut commanded = false;
        match lockstep {
            Some(l) => {
                ticks.clear();
                l.finished(|t| ticks.push(t))?;
                for &t in &ticks {
                    commanded |= sync(link, &mut on_bus, t / 1_000_000, &mut batch, &mut round)?;
                }
            }
            None => {
                commanded = forward(link, &mut on_bus, &mut batch, &mut round)?;
                round.clear();
            }
        }
        if beats > 0 || commanded {
            link.state.watchdog.heartbeat();
            // Real time: the DRV's own watchdog hears of the executive from the bridge (in
            // lockstep every tick's `SY` feeds it).
            if lockstep.is_none() {
                let now_ms = link.state.watchdog.now_ms();
                send(&mut link.port, &Line::Heartbeat { time_ms: now_ms })?;
            }
        }
        if !read_available(&mut link.port, &mut buf).context("reading the DRV line")? {
            return Ok(Ended::HungUp);
        }
        receive(args.watchdog_ms, link, &mut on_bus, &mut decoder, &buf)?;
        // Real time: no tick marks; the warnings go out stamped with the vehicle's time.
        if lockstep.is_none() {
            link.rosout.end(link.state.watchdog.now_ms() * 1_000_000)?;
            link.rosout.begin();
        }
    }
}

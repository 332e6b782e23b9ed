//! harvey-denning-bridge: connects a DRV serial line (a real port, or the simulated DRV's
//! pseudo-terminal) to the bus.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::OpenOptionsExt;
use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FdSource, Lockstep, Publisher, Subscriber, Waiter, Wake};
use harvey_denning_bridge::{
    Bridge, Outgoing, PanicLatch, SHUTDOWN_STOP_ID, WATCHDOG_STOP_ID, Watchdog, prioritise, to_drv,
};
use harvey_drv_protocol::serial::{make_raw, read_available, write_frame};
use harvey_drv_protocol::{Command, Decoder, Line, encode};
use harvey_msgs::{EncodersRaw, MissionStatus, MotionCommand, SonarRaw, topics};

#[derive(Parser)]
#[command(about = "Bridge between a Denning DRV serial line and the Harvey bus")]
struct Args {
    /// Serial device of the DRV (or the simulated DRV's pseudo-terminal link).
    #[arg(long)]
    device: PathBuf,
    /// After a panic-stop, refuse motion commands for this long (simulated or sensor time).
    #[arg(long, default_value_t = 200)]
    panic_hold_ms: u64,
    /// Stop the vehicle when neither a status nor a command has come from the executive for
    /// this long (vehicle time, from the DRV's reports), and on shutdown.
    #[arg(long, default_value_t = 200)]
    watchdog_ms: u64,
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let mut port = OpenOptions::new()
        .read(true)
        .write(true)
        .custom_flags(nix::libc::O_NOCTTY | nix::libc::O_NONBLOCK)
        .open(&args.device)
        .with_context(|| format!("opening DRV serial device {}", args.device.display()))?;
    make_raw(&port).with_context(|| format!("setting {} to raw mode", args.device.display()))?;

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
    let waiter = Waiter::new()?;
    let line_source = FdSource::new(&port)?;
    let _a = match &lockstep {
        Some(l) => waiter.attach(l.predecessor())?,
        None => waiter.attach(&ports.commands)?,
    };
    let _b = waiter.attach(&line_source)?;
    // Real time: a reflex's command wakes the bridge too (in lockstep the chain's turn does).
    let _c = match &lockstep {
        Some(_) => None,
        None => Some((waiter.attach(&ports.reflexes)?, waiter.attach(&ports.heartbeat)?)),
    };
    harvey_runtime::notify_ready()?;
    tracing::info!(device = %args.device.display(), lockstep = lockstep.is_some(), "bridge up");

    let mut watchdog = Watchdog::new(args.watchdog_ms * 1_000_000);
    let result = run(&args, &mut port, &lockstep, &waiter, &ports, &mut watchdog);
    // Whatever ended the loop (a shutdown, an error), the vehicle stops before the bridge goes.
    let stop = send(&mut port, &Line::Command(Command::Stop { id: SHUTDOWN_STOP_ID }));
    tracing::info!(sent = stop.is_ok(), "stop sent on the way out");
    result
}

/// The bus ports of the bridge.
struct Ports {
    commands: Subscriber<MotionCommand>,
    reflexes: Subscriber<MotionCommand>,
    heartbeat: Subscriber<MissionStatus>,
    encoders: Publisher<EncodersRaw>,
    sonar: Publisher<SonarRaw>,
}

/// The bridge's loop, until shutdown.
fn run(
    args: &Args,
    port: &mut File,
    lockstep: &Option<Lockstep>,
    waiter: &Waiter,
    ports: &Ports,
    watchdog: &mut Watchdog,
) -> anyhow::Result<()> {
    let mut bridge = Bridge::default();
    let mut latch = PanicLatch::new(args.panic_hold_ms * 1_000_000);
    let mut decoder = Decoder::new();
    let (mut buf, mut batch, mut ticks) = (Vec::new(), Vec::new(), Vec::new());
    // Sends the commands that arrived; true if any came from the executive.
    let mut forward = |port: &mut File| -> anyhow::Result<bool> {
        batch.clear();
        // The reflexes' commands first: an urgent stop among them pre-empts the batch.
        ports.reflexes.drain(|c| batch.push(*c))?;
        let reflexes = batch.len();
        ports.commands.drain(|c| batch.push(*c))?;
        for cmd in prioritise(&batch) {
            match latch.admit(&cmd).and_then(|()| to_drv(&cmd)) {
                Ok(drv) => send(port, &Line::Command(drv))?,
                Err(refusal) => tracing::error!("refused: {refusal}"),
            }
        }
        Ok(batch.len() > reflexes)
    };
    loop {
        if waiter.wait(None)? == Wake::Shutdown {
            break;
        }
        let beats = ports.heartbeat.drain(|_| {})?;
        let mut commanded = false;
        match lockstep {
            Some(l) => {
                ticks.clear();
                l.finished(|t| ticks.push(t))?;
                for &t in &ticks {
                    commanded |= forward(port)?;
                    send(port, &Line::Sync { time_ms: t / 1_000_000 })?;
                }
            }
            None => commanded = forward(port)?,
        }
        if beats > 0 || commanded {
            watchdog.heartbeat();
            // Real time: the DRV's own watchdog hears of the executive from the bridge (in
            // lockstep every tick's `SY` feeds it).
            if lockstep.is_none() {
                send(port, &Line::Heartbeat { time_ms: watchdog.now_ms() })?;
            }
        }
        if !read_available(port, &mut buf).context("reading the DRV line")? {
            anyhow::bail!("the DRV line {} hung up", args.device.display());
        }
        let mut out = Vec::new();
        decoder.push(&buf, |frame| match frame {
            Ok(Line::Report(r)) => out.push(bridge.on_report(r)),
            Ok(Line::Tick { time_ms }) => out.push(Outgoing::Tick { time_ms }),
            Ok(line @ (Line::Command(_) | Line::Sync { .. } | Line::Heartbeat { .. })) => {
                tracing::warn!(?line, "ignoring a host frame echoed by the vehicle")
            }
            Err(e) => tracing::warn!("bad frame from the DRV: {e}"),
        });
        for o in out {
            let stamp_ns = match o {
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
                        Some(l) => l.finish(time_ms * 1_000_000)?,
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
            if stamp_ns.is_some_and(|t| watchdog.on_vehicle_time(t)) {
                tracing::error!(
                    deadline_ms = args.watchdog_ms,
                    vehicle_ms = watchdog.now_ms(),
                    "no heartbeat from the executive: stopping the vehicle"
                );
                send(port, &Line::Command(Command::Stop { id: WATCHDOG_STOP_ID }))?;
            }
        }
    }
    tracing::info!(stats = ?decoder.stats(), "bridge stopped");
    Ok(())
}

/// Writes one frame to the DRV; a full line loses it, loudly.
fn send(port: &mut File, line: &Line) -> anyhow::Result<()> {
    if !write_frame(port, encode(line).as_bytes())? {
        tracing::error!(?line, "serial line full: frame not sent");
    }
    Ok(())
}

//! harvey-denning-bridge: connects a DRV serial line (a real port, or the simulated DRV's
//! pseudo-terminal) to the bus.

use std::fs::OpenOptions;
use std::os::unix::fs::OpenOptionsExt;
use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FdSource, Lockstep, Waiter, Wake};
use harvey_denning_bridge::{Bridge, Outgoing, PanicLatch, prioritise, to_drv};
use harvey_drv_protocol::serial::{make_raw, read_available, write_frame};
use harvey_drv_protocol::{Decoder, Line, encode};
use harvey_msgs::topics;

#[derive(Parser)]
#[command(about = "Bridge between a Denning DRV serial line and the Harvey bus")]
struct Args {
    /// Serial device of the DRV (or the simulated DRV's pseudo-terminal link).
    #[arg(long)]
    device: PathBuf,
    /// After a panic-stop, refuse motion commands for this long (simulated or sensor time).
    #[arg(long, default_value_t = 200)]
    panic_hold_ms: u64,
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
    let commands = bus.subscriber(topics::VEHICLE_COMMAND)?;
    let reflexes = bus.subscriber(topics::VEHICLE_REFLEX)?;
    let encoders = bus.publisher(topics::DRV_ENCODERS_RAW)?;
    let sonar = bus.publisher(topics::DRV_SONAR_RAW)?;
    // Deterministic mode: the bridge is the clock master on the bus. A tick's turn starts when
    // the DRV's `TK` closes its reports; when the chain's tail has finished the tick, the
    // tick's commands go out, closed by `SY`.
    let lockstep = Lockstep::from_env(&bus)?;
    let waiter = Waiter::new()?;
    let line_source = FdSource::new(&port)?;
    let _a = match &lockstep {
        Some(l) => waiter.attach(l.predecessor())?,
        None => waiter.attach(&commands)?,
    };
    let _b = waiter.attach(&line_source)?;
    // Real time: a reflex's command wakes the bridge too (in lockstep the chain's turn does).
    let _c = match &lockstep {
        Some(_) => None,
        None => Some(waiter.attach(&reflexes)?),
    };
    harvey_runtime::notify_ready()?;
    tracing::info!(device = %args.device.display(), lockstep = lockstep.is_some(), "bridge up");

    let mut bridge = Bridge::default();
    let mut latch = PanicLatch::new(args.panic_hold_ms * 1_000_000);
    let mut decoder = Decoder::new();
    let (mut buf, mut batch, mut ticks) = (Vec::new(), Vec::new(), Vec::new());
    let mut forward = |port: &mut std::fs::File| -> anyhow::Result<()> {
        batch.clear();
        // The reflexes' commands first: an urgent stop among them pre-empts the batch.
        reflexes.drain(|c| batch.push(*c))?;
        commands.drain(|c| batch.push(*c))?;
        for cmd in prioritise(&batch) {
            match latch.admit(&cmd).and_then(|()| to_drv(&cmd)) {
                Ok(drv) => send(port, &Line::Command(drv))?,
                Err(refusal) => tracing::error!("refused: {refusal}"),
            }
        }
        Ok(())
    };
    loop {
        if waiter.wait(None)? == Wake::Shutdown {
            break;
        }
        match &lockstep {
            Some(l) => {
                ticks.clear();
                l.finished(|t| ticks.push(t))?;
                for &t in &ticks {
                    forward(&mut port)?;
                    send(&mut port, &Line::Sync { time_ms: t / 1_000_000 })?;
                }
            }
            None => forward(&mut port)?,
        }
        if !read_available(&mut port, &mut buf).context("reading the DRV line")? {
            anyhow::bail!("the DRV line {} hung up", args.device.display());
        }
        let mut out = Vec::new();
        decoder.push(&buf, |frame| match frame {
            Ok(Line::Report(r)) => out.push(bridge.on_report(r)),
            Ok(Line::Tick { time_ms }) => out.push(Outgoing::Tick { time_ms }),
            Ok(line @ (Line::Command(_) | Line::Sync { .. })) => {
                tracing::warn!(?line, "ignoring a host frame echoed by the vehicle")
            }
            Err(e) => tracing::warn!("bad frame from the DRV: {e}"),
        });
        for o in out {
            match o {
                Outgoing::Encoders(m) => {
                    encoders.send(&m)?;
                }
                Outgoing::Sonar(m) => {
                    sonar.send(&m)?;
                }
                Outgoing::Tick { time_ms } => match &lockstep {
                    Some(l) => l.finish(time_ms * 1_000_000)?,
                    None => tracing::warn!(time_ms, "a tick mark from the DRV in real-time mode"),
                },
                Outgoing::Refused { id, reason } => {
                    tracing::error!(id, ?reason, "the DRV refused a command")
                }
                Outgoing::Accepted { id } => tracing::debug!(id, "the DRV accepted a command"),
            }
        }
    }
    tracing::info!(stats = ?decoder.stats(), "bridge stopped");
    Ok(())
}

/// Writes one frame to the DRV; a full line loses it, loudly.
fn send(port: &mut std::fs::File, line: &Line) -> anyhow::Result<()> {
    if !write_frame(port, encode(line).as_bytes())? {
        tracing::error!(?line, "serial line full: frame not sent");
    }
    Ok(())
}

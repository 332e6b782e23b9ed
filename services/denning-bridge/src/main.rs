//! harvey-denning-bridge: connects a DRV serial line (a real port, or the simulated DRV's
//! pseudo-terminal) to the bus.

use std::fs::OpenOptions;
use std::os::unix::fs::OpenOptionsExt;
use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FdSource, Waiter, Wake};
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
    let encoders = bus.publisher(topics::DRV_ENCODERS_RAW)?;
    let sonar = bus.publisher(topics::DRV_SONAR_RAW)?;
    let waiter = Waiter::new()?;
    let line_source = FdSource::new(&port)?;
    let _a = waiter.attach(&commands)?;
    let _b = waiter.attach(&line_source)?;
    harvey_runtime::notify_ready()?;
    tracing::info!(device = %args.device.display(), "bridge up");

    let mut bridge = Bridge::default();
    let mut latch = PanicLatch::new(args.panic_hold_ms * 1_000_000);
    let mut decoder = Decoder::new();
    let mut buf = Vec::new();
    let mut batch = Vec::new();
    loop {
        if waiter.wait(None)? == Wake::Shutdown {
            break;
        }
        batch.clear();
        commands.drain(|c| batch.push(*c))?;
        for cmd in prioritise(&batch) {
            match latch.admit(&cmd).and_then(|()| to_drv(&cmd)) {
                Ok(drv) => {
                    if !write_frame(&mut port, encode(&Line::Command(drv)).as_bytes())? {
                        tracing::error!(?drv, "serial line full: command not sent");
                    }
                }
                Err(refusal) => tracing::error!("refused: {refusal}"),
            }
        }
        if !read_available(&mut port, &mut buf).context("reading the DRV line")? {
            anyhow::bail!("the DRV line {} hung up", args.device.display());
        }
        let mut out = Vec::new();
        decoder.push(&buf, |frame| match frame {
            Ok(Line::Report(r)) => out.push(bridge.on_report(r)),
            Ok(Line::Command(c)) => tracing::warn!(?c, "ignoring a command echoed by the vehicle"),
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

//! harvey-sim-drv: the simulated Denning DRV on a pseudo-terminal. The bridge opens the
//! terminal's slave end (a symlink at `--pty`) as if it were the DRV's serial port.

use std::fs::File;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FdSource, Waiter, Wake};
use harvey_drv_protocol::Decoder;
use harvey_drv_protocol::serial::{make_raw, read_available, set_nonblocking};
use harvey_msgs::topics;
use harvey_sim_drv::Args;
use harvey_sim_drv::drive::{self, Drive};
use harvey_sim_drv::watchdog::HostWatchdog;

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let sim = args.simulator()?;

    let bus = Bus::join("sim-drv")?;
    let truth_pub = bus.publisher(topics::SIM_TRUTH)?;

    let pty = nix::pty::openpty(None, None).context("opening a pseudo-terminal")?;
    make_raw(&pty.slave).context("setting the pseudo-terminal to raw mode")?;
    set_nonblocking(&pty.master).context("making the pseudo-terminal non-blocking")?;
    let slave_path = nix::unistd::ttyname(&pty.slave).context("naming the pseudo-terminal")?;
    let _ = std::fs::remove_file(&args.pty);
    std::os::unix::fs::symlink(&slave_path, &args.pty)
        .with_context(|| format!("linking {} -> {}", args.pty.display(), slave_path.display()))?;
    // Keep the slave open ourselves so the line stays up while the bridge restarts.
    let _slave = pty.slave;
    let mut line = File::from(pty.master);

    let waiter = Waiter::new()?;
    let line_source = FdSource::new(&line)?;
    let _line_attached = waiter.attach(&line_source)?;
    // Lockstep: the supervisor asks for re-offers (of `sim/truth`) when a party restarts.
    let reoffers = bus.reoffers();
    let _reoffers_attached =
        if harvey_bus::lockstep_from_env() { Some(waiter.attach(reoffers.as_ref())?) } else { None };
    harvey_runtime::notify_ready()?;
    tracing::info!(pty = %args.pty.display(), tty = %slave_path.display(), seed = args.seed, "simulated DRV up");

    // Deterministic mode: no timer; each `SY` from the bridge (after the tick's commands)
    // releases the next tick. Real time: a tick every `tick_ms / speedup` of wall time.
    let lockstep = harvey_bus::lockstep_from_env();
    let checkpoint = harvey_runtime::Checkpoint::from_env("sim-drv", drive::SLOT_BYTES)?;
    let truth = |m: &harvey_msgs::TruePose| -> anyhow::Result<()> {
        truth_pub.send(m)?;
        Ok(())
    };
    let mut drive = Drive::new(sim, HostWatchdog::new(args.watchdog_ms), truth, args.tick_ms, checkpoint)?;
    let period = Duration::from_secs_f64(args.tick_ms as f64 / 1000.0 / args.speedup);
    let mut next_tick = Instant::now() + period;
    let mut decoder = Decoder::new();
    let (mut buf, mut lines) = (Vec::new(), Vec::new());
    loop {
        let now = Instant::now();
        let timeout = (!lockstep).then(|| next_tick.saturating_duration_since(now));
        if (lockstep || now < next_tick) && waiter.wait(timeout)? == Wake::Shutdown {
            break;
        }
        reoffers.serve()?;
        read_available(&mut line, &mut buf).context("reading the pseudo-terminal")?;
        lines.clear();
        decoder.push(&buf, |frame| match frame {
            Ok(l) => lines.push(l),
            Err(e) => tracing::warn!("bad frame from the host: {e}"),
        });
        for l in lines.drain(..) {
            drive.on_line(&mut line, l, lockstep)?;
        }
        if !lockstep && Instant::now() >= next_tick {
            next_tick += period;
            drive.tick_now(&mut line)?;
        }
    }
    let _ = std::fs::remove_file(&args.pty);
    tracing::info!(time_ms = drive.sim.time_ms(), dropped_frames = drive.dropped_frames, stats = ?decoder.stats(), "simulated DRV stopped");
    Ok(())
}

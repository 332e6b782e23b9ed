//! harvey-replayer: the clock master of a replay. It publishes a recording's inputs one tick at
//! a time, each once every service has finished the previous tick (`harvey replay` launches it).
//!
//! A run's inputs are what came from outside the software under test: the simulator's truth,
//! the DRV's raw reports and the camera's frames (`harvey_recording::ticks`). `harvey replay`
//! runs every other service again and this replayer, as clock master, hands them the recorded
//! inputs one tick at a time, just as the bridge did live. In deterministic mode every party saw
//! each tick's inputs at its turn, so the services publish again exactly what they published then.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, Lockstep, Reoffers, Waiter, Wake};
use harvey_msgs::topics;
use harvey_recording::Recording;
use harvey_recording::ticks::{Input, for_each_tick};

#[derive(Parser)]
#[command(
    about = "Feed a recording's inputs through the live services, tick by tick (run by `harvey replay`)"
)]
struct Args {
    /// The MCAP recording to replay.
    #[arg(long)]
    recording: PathBuf,
    /// Give up when the services have not finished a tick for this long (wall clock).
    #[arg(long, default_value_t = 30)]
    stall_timeout_s: u64,
}

/// Waits until the chain's tail has finished `tick` (`None`: until the supervisor starts the
/// chain). Returns false on SIGINT/SIGTERM.
fn wait_for(
    lockstep: &Lockstep,
    waiter: &Waiter,
    reoffers: &Reoffers,
    done: &mut Option<u64>,
    tick: Option<u64>,
    stall: Duration,
) -> anyhow::Result<bool> {
    while !done.is_some_and(|d| tick.is_none_or(|t| d >= t)) {
        let wake = waiter.wait(Some(stall))?;
        // A party restarted: the replayed inputs' history goes to it (`harvey_bus` reoffer.rs).
        reoffers.serve()?;
        lockstep.finished(|t| *done = Some(done.map_or(t, |d| d.max(t))))?;
        match wake {
            Wake::Shutdown => return Ok(false),
            Wake::Timeout if !done.is_some_and(|d| tick.is_none_or(|t| d >= t)) => anyhow::bail!(
                "no service finished tick {:.3} s within {} s: is a service stuck or gone?",
                tick.unwrap_or(0) as f64 / 1e9,
                stall.as_secs()
            ),
            _ => {}
        }
    }
    Ok(true)
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let recording = Recording::open(&args.recording)?;
    // A first pass checks the whole recording before any service sees it, and sizes the frames.
    let contents = for_each_tick::<anyhow::Error>(&recording, |_, _| Ok(()))?;
    anyhow::ensure!(contents.ticks > 0, "{}: holds no inputs to replay", args.recording.display());

    let bus = Bus::join("replayer")?;
    let lockstep = Lockstep::from_env(&bus)?
        .context("harvey-replayer runs as the clock master of a lockstep launch: use `harvey replay`")?;
    let truth = bus.publisher(topics::SIM_TRUTH)?;
    let sonar = bus.publisher(topics::DRV_SONAR_RAW)?;
    let encoders = bus.publisher(topics::DRV_ENCODERS_RAW)?;
    let rosout = bus.publisher(topics::ROSOUT)?;
    let frames = (contents.max_frame_bytes > 0)
        .then(|| bus.frame_publisher(topics::CAMERA_FRAME, contents.max_frame_bytes))
        .transpose()?;
    let waiter = Waiter::new()?;
    let _a = waiter.attach(lockstep.predecessor())?;
    let reoffers = bus.reoffers();
    let _b = waiter.attach(reoffers.as_ref())?;
    harvey_runtime::notify_ready()?;
    tracing::info!(
        ticks = contents.ticks,
        inputs = contents.inputs,
        "replaying {}",
        args.recording.display()
    );

    let stall = Duration::from_secs(args.stall_timeout_s.max(1));
    let mut done = None;
    if !wait_for(&lockstep, &waiter, &reoffers, &mut done, None, stall)? {
        return Ok(());
    }
    let started = Instant::now();
    let mut previous = None;
    let mut interrupted = false;
    for_each_tick(&recording, |stamp, inputs| {
        if interrupted || !wait_for(&lockstep, &waiter, &reoffers, &mut done, previous, stall)? {
            interrupted = true;
            return Ok(());
        }
        for input in inputs {
            match input {
                Input::Truth(m) => truth.send(m).map(drop)?,
                Input::Sonar(m) => sonar.send(m).map(drop)?,
                Input::Encoders(m) => encoders.send(m).map(drop)?,
                Input::Log(m) => rosout.send(m.as_ref()).map(drop)?,
                Input::Frame { header, pixels } => {
                    let publisher = frames.as_ref().context("a frame the first pass did not see")?;
                    let mut loan = publisher.loan(*header)?;
                    let slot = loan.pixels_mut();
                    anyhow::ensure!(
                        slot.len() == pixels.len(),
                        "frame {} at {} ns: {} bytes of pixels for a {}x{} image",
                        header.seq,
                        header.stamp_ns,
                        pixels.len(),
                        header.width_px,
                        header.height_px
                    );
                    slot.copy_from_slice(pixels);
                    loan.send()?;
                }
            }
        }
        lockstep.finish(stamp)?;
        previous = Some(stamp);
        Ok(())
    })
    .with_context(|| args.recording.display().to_string())?;
    if interrupted || !wait_for(&lockstep, &waiter, &reoffers, &mut done, previous, stall)? {
        tracing::warn!("replay interrupted");
        return Ok(());
    }
    let wall = started.elapsed().as_secs_f64();
    let sim = (contents.last_ns - contents.first_ns) as f64 / 1e9;
    tracing::info!(
        ticks = contents.ticks,
        sim_s = format!("{sim:.2}"),
        wall_s = format!("{wall:.3}"),
        "replay finished: {:.1}x real time",
        sim / wall.max(1e-9)
    );
    Ok(())
}

//! harvey-recorder: subscribes to every topic and writes them to `run.mcap` (and, with `--rrd`,
//! draws them into a Rerun file). It never slows a publisher (its queues overwrite when full; the
//! gaps are counted), flushes at least every second, and finishes the files on SIGINT/SIGTERM.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, FrameSubscriber, Pace, Step, Subscriber, Waitable, Waiter};
use harvey_cdr::Ros2Msg;
use harvey_msgs::{Message, Topic, topics};
use harvey_recorder::draw::Draw;
use harvey_recorder::rrd::RrdWriter;
use harvey_recorder::{Channel, Recorder};

#[derive(Parser)]
#[command(about = "Record every topic to an MCAP file")]
struct Args {
    /// Output file.
    #[arg(long)]
    output: PathBuf,
    /// Longest time between flushes (the most a SIGKILL can lose).
    #[arg(long, default_value_t = 500)]
    flush_ms: u64,
    /// Also draw the run into this Rerun (.rrd) file.
    #[arg(long)]
    rrd: Option<PathBuf>,
    /// The world file of the run: attached to the MCAP file and drawn in the Rerun file.
    #[arg(long)]
    world: Option<PathBuf>,
}

/// Where recorded messages go.
struct Sinks {
    mcap: Recorder,
    rrd: Option<RrdWriter>,
    /// Deterministic mode: messages stamped after this belong to a tick the chain never
    /// finished (the launch stopped inside it) and are left out.
    until_ns: u64,
    left_out: u64,
}

impl Sinks {
    fn admits(&mut self, stamp_ns: u64) -> bool {
        let keep = stamp_ns <= self.until_ns;
        self.left_out += u64::from(!keep);
        keep
    }
}

/// A subscribed topic feeding a channel.
trait Tap {
    fn waitable(&self) -> &dyn Waitable;
    fn drain(&self, out: &mut Sinks) -> anyhow::Result<usize>;
}

struct MsgTap<T: Message> {
    sub: Subscriber<T>,
    channel: Channel,
}

impl<T: Message + Ros2Msg + Draw> Tap for MsgTap<T> {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }
    fn drain(&self, out: &mut Sinks) -> anyhow::Result<usize> {
        let mut written = Ok(());
        let n = self.sub.drain(|m| {
            if written.is_ok() && out.admits(m.header().stamp_ns) {
                written = out.mcap.record(self.channel, m);
            }
            if let (Ok(()), Some(rrd), true) = (&written, out.rrd.as_mut(), m.header().stamp_ns <= out.until_ns) {
                written = m.draw(rrd);
            }
        })?;
        written?;
        Ok(n)
    }
}

struct FrameTap {
    sub: FrameSubscriber,
    channel: Channel,
}

impl Tap for FrameTap {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }
    fn drain(&self, out: &mut Sinks) -> anyhow::Result<usize> {
        let mut n = 0;
        while let Some(frame) = self.sub.take()? {
            if !out.admits(frame.header().stamp_ns) {
                continue;
            }
            out.mcap.record_frame(self.channel, frame.header(), frame.pixels())?;
            if let Some(rrd) = out.rrd.as_mut() {
                rrd.frame(frame.header(), frame.pixels())?;
            }
            n += 1;
        }
        Ok(n)
    }
}

fn tap<T: Message + Ros2Msg + Draw>(
    bus: &Bus,
    rec: &mut Recorder,
    topic: Topic<T>,
) -> anyhow::Result<Box<dyn Tap>> {
    let channel = rec.channel::<T>(topic.name)?;
    Ok(Box::new(MsgTap { sub: bus.subscriber(topic)?, channel }))
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    let mut rec = Recorder::create(&args.output)?;
    let world = match &args.world {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            let name = path.file_name().map_or("world.toml".into(), |n| n.to_string_lossy().into_owned());
            let world = harvey_world::load_str(&text, &path.display().to_string())?;
            rec.attach_world(&name, &text)?;
            Some(world)
        }
        None => None,
    };
    let rrd = args.rrd.as_ref().map(|p| RrdWriter::create(p, world.as_ref())).transpose()?;
    let bus = Bus::join("recorder")?;
    let frame_channel = rec.image_channel(topics::CAMERA_FRAME.name)?;
    let taps: Vec<Box<dyn Tap>> = vec![
        tap(&bus, &mut rec, topics::SIM_TRUTH)?,
        tap(&bus, &mut rec, topics::DRV_SONAR_RAW)?,
        tap(&bus, &mut rec, topics::DRV_ENCODERS_RAW)?,
        tap(&bus, &mut rec, topics::VEHICLE_COMMAND)?,
        tap(&bus, &mut rec, topics::SONAR_RING)?,
        tap(&bus, &mut rec, topics::ODOMETRY)?,
        tap(&bus, &mut rec, topics::VISION_DETECTIONS)?,
        tap(&bus, &mut rec, topics::UMS_MAP)?,
        tap(&bus, &mut rec, topics::VISION_SIGHTINGS)?,
        tap(&bus, &mut rec, topics::UMS_EXPECTATIONS)?,
        tap(&bus, &mut rec, topics::EXECUTIVE_STATUS)?,
        Box::new(FrameTap { sub: bus.frame_subscriber(topics::CAMERA_FRAME)?, channel: frame_channel }),
    ];
    let recorded: Vec<&str> = rec.stats().map(|s| s.topic.as_str()).collect();
    let missing: Vec<&&str> = topics::ALL.iter().filter(|t| !recorded.contains(t)).collect();
    anyhow::ensure!(missing.is_empty(), "the recorder has no tap for {missing:?}");
    let mut sinks = Sinks { mcap: rec, rrd, until_ns: u64::MAX, left_out: 0 };

    let pace = Pace::from_env(&bus)?;
    let lockstep = pace.lockstep().is_some();
    let waiter = Waiter::new()?;
    let waitables: Vec<&dyn Waitable> = taps.iter().map(|t| t.waitable()).collect();
    let _attached = pace.attach(&waiter, &waitables)?;
    harvey_runtime::notify_ready()?;
    tracing::info!(output = %args.output.display(), topics = taps.len(), lockstep, "recording");

    let flush_every = Duration::from_millis(args.flush_ms.max(1));
    let mut last_flush = Instant::now();
    let mut last_turn: Option<Instant> = None;
    loop {
        let step = pace.next(&waiter, Some(flush_every))?;
        if let Step::Go(Some(tick)) = step {
            sinks.until_ns = tick;
            // Wall time the whole chain took for this tick: the loop latency plot.
            let now = Instant::now();
            if let (Some(at), Some(rrd)) = (last_turn, sinks.rrd.as_mut()) {
                rrd.loop_latency(tick, now.duration_since(at).as_secs_f64() * 1e3)?;
            }
            last_turn = Some(now);
        }
        // In deterministic mode an idle wake-up must not take a tick still under way.
        if !(lockstep && step == Step::Idle) {
            for t in &taps {
                t.drain(&mut sinks)?;
            }
        }
        pace.done()?;
        if last_flush.elapsed() >= flush_every {
            sinks.mcap.flush()?;
            if let Some(rrd) = &sinks.rrd {
                rrd.flush()?;
            }
            last_flush = Instant::now();
        }
        if step == Step::Stop {
            break;
        }
    }
    drop(_attached);
    let stats = sinks.mcap.finish()?;
    if let Some(rrd) = sinks.rrd {
        rrd.finish()?;
    }
    let total: u64 = stats.iter().map(|s| s.messages).sum();
    let gaps: u64 = stats.iter().map(|s| s.seq_gaps).sum();
    tracing::info!(messages = total, seq_gaps = gaps, left_out = sinks.left_out, output = %args.output.display(), "recording finished");
    Ok(())
}

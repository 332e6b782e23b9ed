//! harvey-recorder: subscribes to every topic and writes them to `run.mcap` (and, with `--rrd`,
//! draws them into a Rerun file). In real time it never slows a publisher (its queues overwrite
//! when full; the gaps are counted); in deterministic mode it is the clock chain's tail and
//! records every tick whole. It flushes at least every `--flush-ms` and finishes the files on
//! SIGINT/SIGTERM. Restarted under the supervisor, it continues the recording it was writing
//! (`harvey_recording::carry_over`): one file, less only what was not yet flushed.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use harvey_bus::{Bus, Pace, Step, Waitable, Waiter};
use harvey_cdr::Ros2Msg;
use harvey_msgs::{Message, Topic, topics};
use harvey_recording::derive::{self, Deriver};
use harvey_recording::draw::draw_recorded;
use harvey_recording::rrd::RrdWriter;
use harvey_recording::topics::{TopicVisitor, visit_message_topics};
use harvey_recording::{ChunkCompression, Recorder, carry_over, data_files};

mod taps;
mod writer;

use taps::{Batch, FrameTap, Intake, MsgTap, Tap};
use writer::{Files, Writer};

/// Ticks of messages the bus thread gathers before handing them to the writer thread.
const TICKS_PER_BATCH: usize = 8;
/// …or sooner, once they hold this many bytes.
const BATCH_BYTES: usize = 8 << 20;

/// The live viewer's address `harvey run --live` hands its recorder.
const LIVE_ENV: &str = "HARVEY_RERUN_LIVE";

/// Whether something accepts connections at a `rerun+http://HOST:PORT/proxy` address.
fn viewer_answers(url: &str) -> anyhow::Result<()> {
    use std::net::ToSocketAddrs;
    let rest = url.split_once("://").map_or(url, |(_, r)| r);
    let host_port = rest.split('/').next().unwrap_or(rest);
    let addrs: Vec<_> =
        host_port.to_socket_addrs().with_context(|| format!("`{host_port}` is not HOST:PORT"))?.collect();
    let timeout = std::time::Duration::from_secs(1);
    anyhow::ensure!(
        addrs.iter().any(|a| std::net::TcpStream::connect_timeout(a, timeout).is_ok()),
        "nothing answers at {host_port}"
    );
    Ok(())
}

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
    /// With `--rrd`, also stream the drawing live to the Rerun viewer at this address
    /// (`rerun+http://HOST:PORT/proxy`; default: `$HARVEY_RERUN_LIVE`, which `harvey run
    /// --live` sets).
    #[arg(long)]
    live: Option<String>,
    /// The world file of the run: attached to the MCAP file and drawn in the Rerun file.
    #[arg(long)]
    world: Option<PathBuf>,
    /// The seed of the run: where the world's `[poles]` stand, to draw them.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The launch file of the run: attached to the MCAP file for `harvey replay`.
    #[arg(long)]
    launch: Option<PathBuf>,
    /// How chunks are compressed: `zstd` (smallest), `zstd-fast` (a noisy 1080p camera at 60 Hz
    /// on two cores), `lz4` (one thread) or `none`. `docs/benchmarks.md` compares them.
    #[arg(long, value_enum, default_value_t = Compression::Zstd)]
    compression: Compression,
}

/// What the recorder's checkpoint says: a recording of this run is under way.
#[derive(serde::Serialize, serde::Deserialize)]
struct Started {
    recording: bool,
}

/// `--compression`'s values.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Compression {
    Zstd,
    ZstdFast,
    Lz4,
    None,
}

impl From<Compression> for ChunkCompression {
    fn from(c: Compression) -> Self {
        match c {
            Compression::Zstd => Self::Zstd,
            Compression::ZstdFast => Self::ZstdFast,
            Compression::Lz4 => Self::Lz4,
            Compression::None => Self::None,
        }
    }
}

/// Builds a tap (and its channel) for each recorded message topic, in the recorder's order.
struct Taps<'a> {
    bus: &'a Bus,
    rec: &'a mut Recorder,
    taps: Vec<Box<dyn Tap>>,
}

impl TopicVisitor for Taps<'_> {
    type Error = anyhow::Error;
    fn message<T: Message + Ros2Msg>(&mut self, topic: Topic<T>) -> anyhow::Result<()> {
        let channel = self.rec.channel::<T>(topic.name)?;
        self.taps.push(Box::new(MsgTap { sub: self.bus.subscriber(topic)?, channel }));
        Ok(())
    }
}

fn main() -> anyhow::Result<()> {
    harvey_runtime::init_logging();
    let args = Args::parse();
    // A checkpoint says this run's recording is under way: a restart continues it.
    let mut checkpoint = harvey_runtime::Checkpoint::from_env("recorder", 4 << 10)?;
    let restarted = checkpoint.as_mut().map(|c| c.load::<Started>()).transpose()?.flatten().is_some();
    let interrupted = if restarted { carry_over::set_aside(&args.output)? } else { None };
    let mut rec = Recorder::create_with(&args.output, args.compression.into())?;
    let world = match &args.world {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            let name = path.file_name().map_or("world.toml".into(), |n| n.to_string_lossy().into_owned());
            let mut world = harvey_world::load_str(&text, &path.display().to_string())?;
            world.place_poles(args.seed)?;
            rec.attach_world(&name, &text, args.seed)?;
            Some(world)
        }
        None => None,
    };
    if let Some(path) = &args.launch {
        let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        let name = path.file_name().map_or("launch.toml".into(), |n| n.to_string_lossy().into_owned());
        rec.attach_launch(&name, &text)?;
        let base = path.parent().unwrap_or(std::path::Path::new("."));
        for file in data_files::named_in(&text, &path.display().to_string())? {
            let at = base.join(&file);
            let bytes = std::fs::read(&at).with_context(|| format!("reading {}", at.display()))?;
            rec.attach_data(&file, &bytes)?;
        }
    }
    let live = args.live.clone().or_else(|| std::env::var(LIVE_ENV).ok().filter(|u| !u.is_empty()));
    // rerun's gRPC sink holds the stream up until it has connected: a viewer that does not
    // answer now is not waited for; the file is drawn all the same.
    let live = live.filter(|url| match viewer_answers(url) {
        Ok(()) => true,
        Err(e) => {
            tracing::warn!(url, "not drawing live: {e}");
            false
        }
    });
    if let (Some(url), Some(_)) = (&live, &args.rrd) {
        tracing::info!(url, "drawing live to a Rerun viewer");
    }
    let mut rrd =
        args.rrd.as_ref().map(|p| RrdWriter::create_live(p, world.as_ref(), live.as_deref())).transpose()?;
    let bus = Bus::join("recorder")?;
    let frame_channel = rec.image_channel(topics::CAMERA_FRAME.name)?;
    let mut taps = Taps { bus: &bus, rec: &mut rec, taps: Vec::new() };
    visit_message_topics(&mut taps)?;
    let mut taps = taps.taps;
    taps.push(Box::new(FrameTap {
        sub: bus.frame_subscriber(topics::CAMERA_FRAME)?,
        channel: frame_channel,
    }));
    let recorded: Vec<&str> = rec.stats().map(|s| s.topic.as_str()).collect();
    let missing: Vec<&&str> = topics::ALL.iter().filter(|t| !recorded.contains(t)).collect();
    anyhow::ensure!(missing.is_empty(), "the recorder has no tap for {missing:?}");
    let derived = rec.derived_channels()?;
    let mut deriver = Deriver::new(world.as_ref());
    let mut recorded = std::collections::BTreeMap::new();
    let mut to_derive = Vec::new();
    if let Some(old) = &interrupted {
        // The deriver goes through the carried-over messages as it went through them the first
        // time; what it derives that the killed recorder had not written follows them.
        let mut present = std::collections::BTreeSet::new();
        let carried =
            carry_over::carry_over(old, &mut rec, |topic, log_time, seq, data| -> anyhow::Result<()> {
                if derive::is_derived(topic) {
                    present.insert((topic.to_owned(), log_time, seq));
                    return Ok(());
                }
                deriver
                    .derive(topic, log_time, data, &mut to_derive)
                    .map_err(|e| anyhow::anyhow!("deriving from {topic}: {e}"))?;
                if let Some(rrd) = rrd.as_mut() {
                    draw_recorded(rrd, topic, data).map_err(|e| anyhow::anyhow!("drawing {topic}: {e}"))?;
                }
                Ok(())
            })?;
        to_derive = derive::missing(to_derive, &present);
        tracing::warn!(messages = carried.messages, derived_again = to_derive.len(), damaged_chunks = ?carried.damaged_chunks, from = %old.display(), "continuing the recording a killed recorder left");
        recorded = carried.newest;
    }
    if let Some(c) = checkpoint.as_mut() {
        c.save(&Started { recording: true })?;
    }
    let pace = Pace::from_env(&bus)?;
    let lockstep = pace.lockstep().is_some();
    let waiter = Waiter::new()?;
    let waitables: Vec<&dyn Waitable> = taps.iter().map(|t| t.waitable()).collect();
    let _attached = pace.attach(&waiter, &waitables)?;
    let flush_every = Duration::from_millis(args.flush_ms.max(1));
    let quarter_flush_ns = args.flush_ms.max(1) * 250_000;
    let mut files = Files { mcap: rec, rrd, deriver, derived };
    files.record_derived(to_derive)?;
    let writer = Writer::start(files, flush_every)?;
    harvey_runtime::notify_ready()?;
    tracing::info!(output = %args.output.display(), topics = taps.len(), lockstep, "recording");

    let mut intake =
        Intake { batch: Batch::default(), spare: Vec::new(), until_ns: u64::MAX, left_out: 0, recorded };
    let mut last_turn: Option<Instant> = None;
    let (mut turns_held, mut last_send, mut sent_ns) = (0usize, Instant::now(), 0u64);
    loop {
        let step = pace.next(&waiter, Some(flush_every))?;
        if let Step::Go(Some(tick)) = step {
            intake.until_ns = tick;
            // Wall time the whole chain took for this tick: the loop latency plot.
            let now = Instant::now();
            if let Some(at) = last_turn {
                intake.batch.loop_latency.push((tick, now.duration_since(at).as_secs_f64() * 1e3));
            }
            last_turn = Some(now);
        }
        while let Some(b) = writer.returned() {
            intake.recycle(b);
        }
        // In deterministic mode an idle wake-up must not take a tick still under way.
        if !(lockstep && step == Step::Idle) {
            for t in &taps {
                t.take(&mut intake)?;
            }
        }
        // The tick's messages are out of shared memory: the chain may go on while they are
        // written.
        pace.done()?;
        // Hand over in batches of several ticks (each hand-over wakes the writer thread), but
        // at least every half flush interval, so that a crash loses no more than it would.
        turns_held += 1;
        let due = step == Step::Stop
            || turns_held >= TICKS_PER_BATCH
            || intake.batch.bytes >= BATCH_BYTES
            || last_send.elapsed() >= flush_every / 2
            || intake.until_ns != u64::MAX && intake.until_ns >= sent_ns.saturating_add(quarter_flush_ns);
        if due && (!intake.batch.items.is_empty() || !intake.batch.loop_latency.is_empty()) {
            // What a SIGKILL would lose: this batch, what is held until the next (a quarter
            // interval), and what the writer has not flushed, kept within half an interval.
            if intake.until_ns != u64::MAX {
                writer.bound_lag(intake.until_ns, 2 * quarter_flush_ns)?;
            }
            writer.send(std::mem::take(&mut intake.batch), intake.until_ns)?;
            (turns_held, last_send) = (0, Instant::now());
            if intake.until_ns != u64::MAX {
                sent_ns = intake.until_ns;
            }
        }
        if step == Step::Stop {
            break;
        }
    }
    drop(_attached);
    let stats = writer.finish()?;
    let total: u64 = stats.iter().map(|s| s.messages).sum();
    let gaps: u64 = stats.iter().map(|s| s.seq_gaps).sum();
    tracing::info!(messages = total, seq_gaps = gaps, left_out = intake.left_out, output = %args.output.display(), "recording finished");
    Ok(())
}

//! The in-process recorder: every topic of the hub into the MCAP file, at the end of each tick,
//! in the order and with the derived topics the recorder service writes (so that an in-process
//! run and a multi-process one record the same messages).

use std::path::PathBuf;
use std::rc::Rc;

use anyhow::Context;
use clap::Parser;
use harvey_cdr::{Ros2Msg, encode, encode_image};
use harvey_msgs::{Message, Topic, topics};
use harvey_recording::derive::{self, Derived, Deriver};
use harvey_recording::draw::draw_recorded;
use harvey_recording::rrd::RrdWriter;
use harvey_recording::topics::{TopicVisitor, visit_message_topics};
use harvey_recording::{Channel, ChunkCompression, Recorder, data_files};
use harvey_runtime::node::memory::{Hub, OwnedFrame, Receiver};

/// The recorder service's arguments, as its launch line gives them (`harvey-recorder`'s own;
/// in process `--live` and `--flush-ms` are accepted and not used: the Rerun file is written
/// whole, not streamed).
#[derive(Parser)]
#[command(name = "harvey-recorder")]
pub struct RecorderArgs {
    #[arg(long)]
    pub output: PathBuf,
    #[arg(long, default_value_t = 500)]
    flush_ms: u64,
    #[arg(long)]
    pub rrd: Option<PathBuf>,
    #[arg(long)]
    live: Option<String>,
    #[arg(long)]
    world: Option<PathBuf>,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[arg(long)]
    launch: Option<PathBuf>,
    #[arg(long, default_value = "zstd")]
    compression: String,
}

/// The chunk compression the recorder's `--compression` names.
fn compression(name: &str) -> anyhow::Result<ChunkCompression> {
    Ok(match name {
        "zstd" => ChunkCompression::Zstd,
        "zstd-fast" => ChunkCompression::ZstdFast,
        "lz4" => ChunkCompression::Lz4,
        "none" => ChunkCompression::None,
        other => anyhow::bail!("--compression `{other}`: expected zstd, zstd-fast, lz4 or none"),
    })
}

/// A recorded topic's subscription on the hub.
trait Tap {
    /// Encodes the messages stamped at or before `until_ns` for `f`; drops later ones.
    fn take(&self, until_ns: u64, f: &mut dyn FnMut(Channel, &'static str, u64, u64, Vec<u8>)) -> usize;
}

struct MsgTap<T> {
    rx: Receiver<T>,
    channel: Channel,
}

impl<T: Message + Ros2Msg> Tap for MsgTap<T> {
    fn take(&self, until_ns: u64, f: &mut dyn FnMut(Channel, &'static str, u64, u64, Vec<u8>)) -> usize {
        let mut left_out = 0;
        self.rx.drain(|m| {
            let h = *m.header();
            match h.stamp_ns <= until_ns {
                true => f(self.channel, self.rx.topic(), h.seq, h.stamp_ns, encode(&m, Vec::new())),
                false => left_out += 1,
            }
        });
        left_out
    }
}

struct FrameTap {
    rx: Receiver<Rc<OwnedFrame>>,
    channel: Channel,
}

impl Tap for FrameTap {
    fn take(&self, until_ns: u64, f: &mut dyn FnMut(Channel, &'static str, u64, u64, Vec<u8>)) -> usize {
        let mut left_out = 0;
        self.rx.drain(|fr| {
            let h = fr.header;
            match h.stamp_ns <= until_ns {
                true => f(
                    self.channel,
                    self.rx.topic(),
                    h.seq,
                    h.stamp_ns,
                    encode_image(&h, &fr.pixels, Vec::new()),
                ),
                false => left_out += 1,
            }
        });
        left_out
    }
}

struct Taps<'a> {
    hub: &'a Hub,
    rec: &'a mut Recorder,
    taps: Vec<Box<dyn Tap>>,
}

impl TopicVisitor for Taps<'_> {
    type Error = anyhow::Error;
    fn message<T: Message + Ros2Msg>(&mut self, topic: Topic<T>) -> anyhow::Result<()> {
        let channel = self.rec.channel::<T>(topic.name)?;
        self.taps
            .push(Box::new(MsgTap { rx: self.hub.subscribe::<T>(topic.name, topic.qos.buffer)?, channel }));
        Ok(())
    }
}

/// One message on its way to the file: channel, topic, sequence, stamp and CDR bytes.
type Item = (Channel, &'static str, u64, u64, Vec<u8>);

/// The file, written on a thread of its own (as the recorder service does), so that compression
/// and the derived topics overlap the next ticks' turns.
struct Files {
    rec: Recorder,
    rrd: Option<RrdWriter>,
    deriver: Deriver,
    derived: Vec<Channel>,
}

impl Files {
    fn write(&mut self, items: Vec<Item>, scratch: &mut Vec<Derived>) -> anyhow::Result<()> {
        for (ch, topic, seq, stamp, data) in items {
            self.rec.record_encoded(ch, seq, stamp, &data)?;
            self.deriver
                .derive(topic, stamp, &data, scratch)
                .map_err(|e| anyhow::anyhow!("deriving from {topic}: {e}"))?;
            for d in scratch.drain(..) {
                let ch = derive::index(d.topic).and_then(|k| self.derived.get(k).copied());
                let ch = ch.ok_or_else(|| anyhow::anyhow!("no channel for the derived topic {}", d.topic))?;
                self.rec.record_encoded(ch, d.seq, d.stamp_ns, &d.data)?;
            }
            if let Some(rrd) = self.rrd.as_mut() {
                draw_recorded(rrd, topic, &data).map_err(|e| anyhow::anyhow!("drawing {topic}: {e}"))?;
            }
        }
        Ok(())
    }
}

/// Ticks the main thread may hand over before it waits for the writer.
const QUEUE: usize = 16;

/// The recording being written.
pub struct Sink {
    taps: Vec<Box<dyn Tap>>,
    to_writer: std::sync::mpsc::SyncSender<Vec<Item>>,
    writer: std::thread::JoinHandle<anyhow::Result<()>>,
    pub messages: u64,
    pub left_out: u64,
}

impl Sink {
    /// The recording the recorder's arguments describe, its world and launch attached, every
    /// topic subscribed on `hub`.
    pub fn open(args: &RecorderArgs, hub: &Hub) -> anyhow::Result<Self> {
        let mut rec = Recorder::create_with(&args.output, compression(&args.compression)?)?;
        let mut world = None;
        if let Some(path) = &args.world {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            let name = path.file_name().map_or("world.toml".into(), |n| n.to_string_lossy().into_owned());
            let mut w = harvey_world::load_str(&text, &path.display().to_string())?;
            w.place_poles(args.seed)?;
            rec.attach_world(&name, &text, args.seed)?;
            world = Some(w);
        }
        if let Some(path) = &args.launch {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
            let name = path.file_name().map_or("launch.toml".into(), |n| n.to_string_lossy().into_owned());
            rec.attach_launch(&name, &text)?;
            let base = path.parent().unwrap_or(std::path::Path::new("."));
            for file in data_files::named_in(&text, &path.display().to_string())? {
                let at = base.join(&file);
                let bytes = std::fs::read(&at).with_context(|| format!("reading {}", at.display()))?;
                rec.attach_data(&file, &bytes)?;
            }
        }
        let frame_channel = rec.image_channel(topics::CAMERA_FRAME.name)?;
        let mut taps = Taps { hub, rec: &mut rec, taps: Vec::new() };
        visit_message_topics(&mut taps)?;
        let mut taps = taps.taps;
        let rx =
            hub.subscribe::<Rc<OwnedFrame>>(topics::CAMERA_FRAME.name, topics::CAMERA_FRAME.qos.buffer)?;
        taps.push(Box::new(FrameTap { rx, channel: frame_channel }));
        let derived = rec.derived_channels()?;
        let rrd = args.rrd.as_ref().map(|p| RrdWriter::create(p, world.as_ref())).transpose()?;
        let mut files = Files { rec, rrd, deriver: Deriver::new(world.as_ref()), derived };
        let (to_writer, ticks) = std::sync::mpsc::sync_channel::<Vec<Item>>(QUEUE);
        let writer = std::thread::Builder::new().name("mcap-writer".into()).spawn(move || {
            let mut scratch = Vec::new();
            for items in ticks {
                files.write(items, &mut scratch)?;
            }
            files.rec.finish()?;
            if let Some(rrd) = files.rrd {
                rrd.finish()?;
            }
            Ok(())
        })?;
        Ok(Self { taps, to_writer, writer, messages: 0, left_out: 0 })
    }

    /// The recorder's turn on tick `tick`: what every topic holds, in tap order, to the writer.
    pub fn record_tick(&mut self, tick: u64) -> anyhow::Result<()> {
        let mut items = Vec::new();
        for t in &self.taps {
            self.left_out += t
                .take(tick, &mut |ch, topic, seq, stamp, data| items.push((ch, topic, seq, stamp, data)))
                as u64;
        }
        self.messages += items.len() as u64;
        // A send fails only once the writer has stopped on an error, which `finish` reports.
        self.to_writer.send(items).map_err(|_| anyhow::anyhow!("the MCAP writer stopped"))
    }

    /// Writes what is queued and finishes the file.
    pub fn finish(self) -> anyhow::Result<()> {
        drop(self.to_writer);
        self.writer.join().map_err(|_| anyhow::anyhow!("the MCAP writer thread panicked"))?
    }
}

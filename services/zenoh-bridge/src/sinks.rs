//! The bus publishers of what comes off Zenoh, one per topic, opened on first use (a topic the
//! other host never sends gets no publisher here, which matters for the frames' one publisher):
//! each message decoded from its CDR into the topic's type; a camera frame written once,
//! straight into a loaned shared-memory frame, its sequence number restored from the
//! attachment.

use std::collections::BTreeMap;

use harvey_bus::{Bus, FramePublisher, Origin, Publisher};
use harvey_cdr::{Ros2Msg, decode, decode_image, image_def};
use harvey_msgs::{Message, Topic, topics};
use harvey_recording::topics::{TopicVisitor, visit_message_topics};

use crate::wire::{self, Meta};

/// What a topic's samples are published with.
pub trait Sink {
    fn fingerprint(&self) -> u32;
    /// Its publisher, as the bus's subscribers see it.
    fn origin(&self) -> Origin;
    fn publish(&self, meta: &Meta, cdr: &[u8]) -> anyhow::Result<()>;
}

struct MsgSink<T: Message> {
    publisher: Publisher<T>,
    fingerprint: u32,
}

impl<T: Message + Ros2Msg> Sink for MsgSink<T> {
    fn fingerprint(&self) -> u32 {
        self.fingerprint
    }

    fn origin(&self) -> Origin {
        self.publisher.origin()
    }

    fn publish(&self, _meta: &Meta, cdr: &[u8]) -> anyhow::Result<()> {
        let msg: T = decode(cdr)?;
        self.publisher.send(&msg)?;
        Ok(())
    }
}

struct FrameSink {
    publisher: FramePublisher,
    fingerprint: u32,
}

impl Sink for FrameSink {
    fn fingerprint(&self) -> u32 {
        self.fingerprint
    }

    fn origin(&self) -> Origin {
        self.publisher.origin()
    }

    fn publish(&self, meta: &Meta, cdr: &[u8]) -> anyhow::Result<()> {
        let (mut header, pixels) = decode_image(cdr)?;
        header.seq = meta.seq;
        let mut loan = self.publisher.loan(header)?;
        let into = loan.pixels_mut();
        anyhow::ensure!(
            into.len() == pixels.len(),
            "a {}-byte frame for a {}-byte loan ({}x{})",
            pixels.len(),
            into.len(),
            header.width_px,
            header.height_px
        );
        into.copy_from_slice(pixels);
        loan.send()?;
        Ok(())
    }
}

/// Opens the sink of one message topic, if `wanted` names it.
struct Opener<'a> {
    bus: &'a Bus,
    wanted: &'a str,
    sink: Option<Box<dyn Sink>>,
}

impl TopicVisitor for Opener<'_> {
    type Error = anyhow::Error;
    fn message<T: Message + Ros2Msg>(&mut self, topic: Topic<T>) -> anyhow::Result<()> {
        if self.sink.is_none() && self.wanted == topic.name {
            let sink =
                MsgSink { publisher: self.bus.publisher(topic)?, fingerprint: wire::fingerprint(T::DEF) };
            self.sink = Some(Box::new(sink));
        }
        Ok(())
    }
}

/// The sinks of a bridge, by topic name.
pub struct Sinks {
    sinks: BTreeMap<&'static str, Box<dyn Sink>>,
    max_frame_bytes: usize,
}

impl Sinks {
    /// Frames up to `max_frame_bytes` are taken (a larger one is refused, named).
    pub fn new(max_frame_bytes: usize) -> Self {
        Self { sinks: BTreeMap::new(), max_frame_bytes }
    }

    /// The publishers of the sinks opened so far: what this bridge published itself.
    pub fn origins(&self) -> Vec<Origin> {
        self.sinks.values().map(|s| s.origin()).collect()
    }

    /// The sink of `topic` (a name of `topics::ALL`), opened on `bus` if it is not yet.
    pub fn get(&mut self, bus: &Bus, topic: &str) -> anyhow::Result<&dyn Sink> {
        let Some(name) = topics::ALL.iter().copied().find(|t| *t == topic) else {
            anyhow::bail!("`{topic}` is no Harvey topic (topics: {:?})", topics::ALL);
        };
        if !self.sinks.contains_key(name) {
            let sink: Box<dyn Sink> = if name == topics::CAMERA_FRAME.name {
                Box::new(FrameSink {
                    publisher: bus.frame_publisher(topics::CAMERA_FRAME, self.max_frame_bytes)?,
                    fingerprint: wire::fingerprint(image_def()),
                })
            } else {
                let mut o = Opener { bus, wanted: name, sink: None };
                visit_message_topics(&mut o)?;
                o.sink.ok_or_else(|| anyhow::anyhow!("no sink for `{name}`"))?
            };
            self.sinks.insert(name, sink);
        }
        self.sinks.get(name).map(|s| s.as_ref()).ok_or_else(|| anyhow::anyhow!("no sink for `{name}`"))
    }
}

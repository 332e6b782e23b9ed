//! Importing: the chosen topics subscribed on Zenoh and published on the local bus, each sample
//! decoded from its CDR into the topic's message (a camera frame written once, straight into a
//! loaned shared-memory frame). Samples arrive on Zenoh's threads; they are queued and the bus
//! thread is woken through a socket pair, since the bus's ports stay on the thread that made
//! them. A sample that is not Harvey's, of another layout or another message definition is
//! refused, said once per topic and counted, and nothing else is lost.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::sync::mpsc::{Receiver, Sender, channel};

use harvey_bus::{Bus, FramePublisher, Publisher};
use harvey_cdr::{Ros2Msg, decode, decode_image, image_def};
use harvey_msgs::{Message, Topic, topics};
use harvey_recording::topics::{TopicVisitor, visit_message_topics};
use zenoh::Wait;
use zenoh::pubsub::Subscriber;

use crate::wire::{self, Meta};

/// What a topic's imported samples are published with.
trait Sink {
    fn fingerprint(&self) -> u32;
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

/// Opens a sink for each wanted message topic.
struct Sinks<'a> {
    bus: &'a Bus,
    wanted: &'a [String],
    sinks: BTreeMap<String, Box<dyn Sink>>,
}

impl TopicVisitor for Sinks<'_> {
    type Error = anyhow::Error;
    fn message<T: Message + Ros2Msg>(&mut self, topic: Topic<T>) -> anyhow::Result<()> {
        if self.wanted.iter().any(|w| w == topic.name) {
            let sink =
                MsgSink { publisher: self.bus.publisher(topic)?, fingerprint: wire::fingerprint(T::DEF) };
            self.sinks.insert(topic.name.to_owned(), Box::new(sink));
        }
        Ok(())
    }
}

/// A sample as it came off Zenoh.
struct Arrived {
    key: String,
    payload: Vec<u8>,
    attachment: Option<Vec<u8>>,
}

/// Counts of one imported topic.
#[derive(Debug, Clone, Copy, Default)]
pub struct Counts {
    pub published: u64,
    pub refused: u64,
}

/// The imported topics of a bridge.
pub struct Importer {
    namespace: String,
    sinks: BTreeMap<String, Box<dyn Sink>>,
    counts: BTreeMap<String, Counts>,
    _subscribers: Vec<Subscriber<()>>,
    arrived: Receiver<Arrived>,
    bell: UnixStream,
}

impl Importer {
    /// Publishes `wanted` topics on `bus` and subscribes to their keys.
    /// Frames up to `max_frame_bytes` are taken (a larger one is refused, named).
    pub fn new(
        session: &zenoh::Session,
        bus: &Bus,
        namespace: &str,
        wanted: &[String],
        max_frame_bytes: usize,
    ) -> anyhow::Result<Self> {
        let mut s = Sinks { bus, wanted, sinks: BTreeMap::new() };
        visit_message_topics(&mut s)?;
        let mut sinks = s.sinks;
        if wanted.iter().any(|w| w == topics::CAMERA_FRAME.name) {
            let sink = FrameSink {
                publisher: bus.frame_publisher(topics::CAMERA_FRAME, max_frame_bytes)?,
                fingerprint: wire::fingerprint(image_def()),
            };
            sinks.insert(topics::CAMERA_FRAME.name.to_owned(), Box::new(sink));
        }
        let unknown: Vec<&String> = wanted.iter().filter(|w| !sinks.contains_key(w.as_str())).collect();
        anyhow::ensure!(
            unknown.is_empty(),
            "--import names no Harvey topic: {unknown:?} (topics: {:?})",
            topics::ALL
        );
        // The bus thread sleeps on `bell`; Zenoh's threads write to `ringer`.
        let (bell, ringer) = UnixStream::pair()?;
        bell.set_nonblocking(true)?;
        ringer.set_nonblocking(true)?;
        let (tx, arrived) = channel();
        let mut subscribers = Vec::new();
        for topic in sinks.keys() {
            let key = wire::data_key(namespace, topic);
            let (tx, ringer): (Sender<Arrived>, UnixStream) = (tx.clone(), ringer.try_clone()?);
            let sub = session
                .declare_subscriber(key.clone())
                .callback(move |sample| {
                    let a = Arrived {
                        key: sample.key_expr().as_str().to_owned(),
                        payload: sample.payload().to_bytes().into_owned(),
                        attachment: sample.attachment().map(|a| a.to_bytes().into_owned()),
                    };
                    if tx.send(a).is_ok() {
                        // A full socket already holds a wake-up.
                        let _ = (&ringer).write(&[1]);
                    }
                })
                .wait()
                .map_err(|e| anyhow::anyhow!("cannot subscribe to {key} on Zenoh: {e}"))?;
            subscribers.push(sub);
        }
        let counts = sinks.keys().map(|k| (k.clone(), Counts::default())).collect();
        Ok(Self { namespace: namespace.to_owned(), sinks, counts, _subscribers: subscribers, arrived, bell })
    }

    /// What wakes the bus thread when samples are queued.
    pub fn bell(&self) -> &UnixStream {
        &self.bell
    }

    /// Publishes every queued sample on the bus; returns how many.
    pub fn drain(&mut self) -> anyhow::Result<u64> {
        let mut buf = [0u8; 256];
        while matches!((&self.bell).read(&mut buf), Ok(n) if n > 0) {}
        let mut n = 0;
        while let Ok(a) = self.arrived.try_recv() {
            let Some(topic) = wire::topic_of(&self.namespace, &a.key) else { continue };
            let (Some(sink), Some(count)) = (self.sinks.get(topic), self.counts.get_mut(topic)) else {
                continue;
            };
            let meta = match Meta::decode(a.attachment.as_deref()) {
                Ok(m) if m.fingerprint == sink.fingerprint() => m,
                Ok(m) => {
                    refuse(
                        topic,
                        count,
                        &format!(
                            "message definition {:08x}, this build's is {:08x}: a peer of another Harvey version",
                            m.fingerprint,
                            sink.fingerprint()
                        ),
                    );
                    continue;
                }
                Err(e) => {
                    refuse(topic, count, &e.to_string());
                    continue;
                }
            };
            match sink.publish(&meta, &a.payload) {
                Ok(()) => {
                    count.published += 1;
                    n += 1;
                }
                Err(e) => refuse(topic, count, &format!("seq {}: {e}", meta.seq)),
            }
        }
        Ok(n)
    }

    pub fn counts(&self) -> &BTreeMap<String, Counts> {
        &self.counts
    }
}

/// Counts a refused sample; the first of a topic is said (an error), the rest only counted.
fn refuse(topic: &str, count: &mut Counts, why: &str) {
    if count.refused == 0 {
        tracing::error!(topic, "refusing samples from Zenoh: {why} (further ones are counted)");
    }
    count.refused += 1;
}

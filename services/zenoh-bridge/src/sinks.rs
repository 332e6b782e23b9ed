//! The bus publishers of what comes off Zenoh, one per topic, opened on first use (a topic the
//! other host never sends gets no publisher here, which matters for the frames' one publisher):
//! each message decoded from its CDR into the topic's type; a camera frame written once,
//! straight into a loaned shared-memory frame from the pieces it arrived in (a large Zenoh
//! sample comes as one piece per fragment, not gathered first), its sequence number restored
//! from the attachment.

use std::collections::BTreeMap;

use harvey_bus::{Bus, FramePublisher, Origin, Publisher};
use harvey_cdr::{Ros2Msg, decode, decode_image_head, image_def};
use harvey_msgs::{Message, Topic, topics};
use harvey_recording::topics::{TopicVisitor, visit_message_topics};

use crate::wire::{self, Meta};

/// What a topic's samples are published with.
pub trait Sink {
    fn fingerprint(&self) -> u32;
    /// Its publisher, as the bus's subscribers see it.
    fn origin(&self) -> Origin;
    /// Publishes the message whose CDR is `pieces`, in order (one piece, or a Zenoh sample's
    /// fragments).
    fn publish(&self, meta: &Meta, pieces: &[&[u8]]) -> anyhow::Result<()>;
}

/// Copies the bytes of `pieces` from offset `skip` on into `into`, until it is full or the
/// pieces end; returns how many it copied.
fn copy_pieces(pieces: &[&[u8]], mut skip: usize, into: &mut [u8]) -> usize {
    let mut filled = 0;
    for p in pieces {
        if filled == into.len() {
            break;
        }
        if skip >= p.len() {
            skip -= p.len();
            continue;
        }
        let from = &p[skip..];
        skip = 0;
        let n = from.len().min(into.len() - filled);
        into[filled..filled + n].copy_from_slice(&from[..n]);
        filled += n;
    }
    filled
}

/// A frame's fields before its pixels are read from at most this many first bytes.
const HEAD_MAX: usize = 4096;

/// The first `max` bytes of `pieces`: the first piece itself if it holds them all, else gathered
/// into `buf`.
fn prefix<'a>(pieces: &[&'a [u8]], max: usize, buf: &'a mut Vec<u8>) -> &'a [u8] {
    match pieces {
        [] => &[],
        [first, ..] if first.len() >= max || pieces.len() == 1 => first,
        _ => {
            for p in pieces {
                let room = max - buf.len();
                buf.extend_from_slice(&p[..p.len().min(room)]);
                if buf.len() == max {
                    break;
                }
            }
            buf
        }
    }
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

    fn publish(&self, _meta: &Meta, pieces: &[&[u8]]) -> anyhow::Result<()> {
        let mut whole = Vec::new();
        let msg: T = decode(prefix(pieces, usize::MAX, &mut whole))?;
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

    fn publish(&self, meta: &Meta, pieces: &[&[u8]]) -> anyhow::Result<()> {
        let mut head = Vec::new();
        let (mut header, at) = decode_image_head(prefix(pieces, HEAD_MAX, &mut head))?;
        header.seq = meta.seq;
        let (len, total) = (header.payload_len(), pieces.iter().map(|p| p.len()).sum::<usize>());
        anyhow::ensure!(
            at + len <= total,
            "a {}x{} frame's {len} pixel bytes from byte {at} of a {total}-byte message",
            header.width_px,
            header.height_px
        );
        let mut loan = self.publisher.loan(header)?;
        let into = loan.pixels_mut();
        anyhow::ensure!(
            into.len() == len,
            "a {len}-byte frame for a {}-byte loan ({}x{})",
            into.len(),
            header.width_px,
            header.height_px
        );
        let copied = copy_pieces(pieces, at, into);
        debug_assert_eq!(copied, len, "the pieces were checked to hold the pixels");
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]
    use super::*;
    use harvey_msgs::{Encoding, FrameHeader};

    /// `bytes` cut at each of `cuts` (ascending offsets).
    fn cut<'a>(bytes: &'a [u8], cuts: &[usize]) -> Vec<&'a [u8]> {
        let mut at = 0;
        let mut pieces = Vec::new();
        for &c in cuts.iter().chain(std::iter::once(&bytes.len())) {
            pieces.push(&bytes[at..c]);
            at = c;
        }
        pieces
    }

    #[test]
    fn a_frame_in_pieces_is_read_as_the_whole_message_is() {
        let h = FrameHeader::new(7, 1_500_000_000, 5, 3, Encoding::Rgb8);
        let pixels: Vec<u8> = (0..45).collect();
        let cdr = harvey_cdr::encode_image(&h, &pixels, Vec::new());
        let (whole_h, whole_px) = harvey_cdr::decode_image(&cdr).unwrap();
        // Cut everywhere a fragment could end: inside the header, at the pixels' start, inside them.
        for a in 1..cdr.len() - 1 {
            for b in [a + 1, (a + 17).min(cdr.len() - 1)] {
                let pieces = cut(&cdr, &[a, b]);
                let mut head = Vec::new();
                let (got, at) = decode_image_head(prefix(&pieces, HEAD_MAX, &mut head)).unwrap();
                assert_eq!(
                    (got.width_px, got.height_px, got.stamp_ns),
                    (whole_h.width_px, whole_h.height_px, h.stamp_ns)
                );
                let mut into = vec![0u8; got.payload_len()];
                assert_eq!(copy_pieces(&pieces, at, &mut into), 45, "cut at {a} and {b}");
                assert_eq!(into, whole_px, "cut at {a} and {b}");
            }
        }
    }

    #[test]
    fn pieces_that_end_early_fill_less_and_a_short_header_is_refused() {
        let h = FrameHeader::new(1, 2, 4, 2, Encoding::Mono8);
        let cdr = harvey_cdr::encode_image(&h, &[9; 8], Vec::new());
        let pieces = cut(&cdr[..cdr.len() - 3], &[10]);
        let (_, at) = decode_image_head(&cdr).unwrap();
        let mut into = [0u8; 8];
        assert_eq!(copy_pieces(&pieces, at, &mut into), 5);
        let mut head = Vec::new();
        assert!(decode_image_head(prefix(&cut(&cdr[..20], &[6]), HEAD_MAX, &mut head)).is_err());
        let mut whole = Vec::new();
        assert_eq!(prefix(&cut(&cdr, &[3, 30]), usize::MAX, &mut whole), &cdr[..]);
    }
}

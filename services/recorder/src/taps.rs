//! The recorder's taps: one subscription per topic, taking its queued messages out of shared
//! memory as CDR into a [`Batch`] for the writer thread.

use std::collections::BTreeMap;

use harvey_bus::{FrameSubscriber, Subscriber, Waitable};
use harvey_cdr::{Ros2Msg, encode, encode_image};
use harvey_msgs::Message;
use harvey_recording::Channel;

/// One message on its way to the files.
pub struct Item {
    pub channel: Channel,
    pub topic: &'static str,
    pub seq: u64,
    pub stamp_ns: u64,
    pub data: Vec<u8>,
}

/// What one wake-up took: the messages in the order taken, and (deterministic mode) the wall
/// time the chain spent on the tick.
#[derive(Default)]
pub struct Batch {
    pub items: Vec<Item>,
    /// `(tick stamp, wall ms)` for each tick in the batch.
    pub loop_latency: Vec<(u64, f64)>,
    /// Payload bytes held.
    pub bytes: usize,
}

/// Where taps put messages: the batch, buffers to reuse, and the deterministic-mode limit.
pub struct Intake {
    pub batch: Batch,
    /// Buffers of earlier batches, reused so that steady recording does not allocate.
    pub spare: Vec<Vec<u8>>,
    /// Messages stamped after this belong to a tick the chain never finished (the launch
    /// stopped inside it) and are left out.
    pub until_ns: u64,
    pub left_out: u64,
    /// A continued recording: per topic, the newest (stamp, sequence) already in it.
    pub recorded: BTreeMap<String, (u64, u32)>,
}

impl Intake {
    fn admits(&mut self, topic: &str, stamp_ns: u64, seq: u64) -> bool {
        let keep = stamp_ns <= self.until_ns;
        self.left_out += u64::from(!keep);
        // The MCAP sequence is the message's number modulo 2^32, as the writer keeps it.
        let seen = self.recorded.get(topic).is_some_and(|&m| (stamp_ns, seq as u32) <= m);
        keep && !seen
    }

    /// A spare buffer that holds `bytes` without growing (a fresh frame-sized buffer would cost
    /// a page fault per 4 KiB), else any spare one.
    fn buffer(&mut self, bytes: usize) -> Vec<u8> {
        match self.spare.iter().position(|b| b.capacity() >= bytes) {
            Some(i) => self.spare.swap_remove(i),
            None => self.spare.pop().unwrap_or_default(),
        }
    }

    fn push(
        &mut self,
        channel: Channel,
        topic: &'static str,
        (seq, stamp_ns, bytes): (u64, u64, usize),
        fill: impl FnOnce(Vec<u8>) -> Vec<u8>,
    ) {
        let data = fill(self.buffer(bytes));
        self.batch.bytes += data.len();
        self.batch.items.push(Item { channel, topic, seq, stamp_ns, data });
    }

    /// Takes back a batch the writer is done with.
    pub fn recycle(&mut self, mut b: Batch) {
        self.spare.extend(b.items.drain(..).map(|i| i.data));
        if self.batch.items.is_empty() && self.batch.items.capacity() < b.items.capacity() {
            std::mem::swap(&mut self.batch.items, &mut b.items);
        }
    }
}

/// A subscribed topic feeding a channel.
pub trait Tap {
    fn waitable(&self) -> &dyn Waitable;
    /// Takes every queued message; returns how many.
    fn take(&self, into: &mut Intake) -> anyhow::Result<usize>;
}

pub struct MsgTap<T: Message> {
    pub sub: Subscriber<T>,
    pub channel: Channel,
}

impl<T: Message + Ros2Msg> Tap for MsgTap<T> {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }
    fn take(&self, into: &mut Intake) -> anyhow::Result<usize> {
        Ok(self.sub.drain(|m| {
            let h = *m.header();
            if into.admits(self.sub.topic(), h.stamp_ns, h.seq) {
                let bytes = 64 + core::mem::size_of::<T>();
                into.push(self.channel, self.sub.topic(), (h.seq, h.stamp_ns, bytes), |buf| encode(m, buf));
            }
        })?)
    }
}

pub struct FrameTap {
    pub sub: FrameSubscriber,
    pub channel: Channel,
}

impl Tap for FrameTap {
    fn waitable(&self) -> &dyn Waitable {
        &self.sub
    }
    fn take(&self, into: &mut Intake) -> anyhow::Result<usize> {
        // At most a queue's worth per call: against a publisher going flat out, an unbounded
        // loop would never end, and would pile frames up in memory.
        let mut n = 0;
        while n < harvey_msgs::Qos::FRAMES.buffer
            && let Some(frame) = self.sub.take()?
        {
            let h = *frame.header();
            if into.admits(self.sub.topic(), h.stamp_ns, h.seq) {
                let bytes = 128 + frame.pixels().len();
                into.push(self.channel, self.sub.topic(), (h.seq, h.stamp_ns, bytes), |buf| {
                    encode_image(&h, frame.pixels(), buf)
                });
            }
            n += 1;
        }
        Ok(n)
    }
}

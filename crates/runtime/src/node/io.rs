//! A node's view of its ports during one turn: inputs taken less what a predecessor took,
//! outputs sent unless a predecessor sent them.

use harvey_msgs::{FrameHeader, Message};

use super::{FrameIn, In, Out, Wired};
use crate::Sent;
use crate::resume::Marks;

/// A received camera frame, read in place: header and pixels.
pub trait FrameView {
    fn header(&self) -> &FrameHeader;
    fn pixels(&self) -> &[u8];
}

impl FrameView for harvey_bus::Frame {
    fn header(&self) -> &FrameHeader {
        harvey_bus::Frame::header(self)
    }

    fn pixels(&self) -> &[u8] {
        harvey_bus::Frame::pixels(self)
    }
}

/// A node's ports during one turn (or [`super::Node::begin`]).
pub struct Io<'a> {
    pub(crate) ports: &'a Wired,
    pub(crate) taken: &'a mut Marks,
    pub(crate) sent: &'a mut Sent,
    pub(crate) tick: Option<u64>,
    pub(crate) newest: &'a mut u64,
}

impl Io<'_> {
    /// Replaces `out` with the messages that came in on `input` since the last turn, oldest first,
    /// less those a predecessor of this process had taken already. Reuse `out` across turns.
    pub fn take<T: Message>(&mut self, input: In<T>, out: &mut Vec<T>) -> anyhow::Result<()> {
        self.ports.inputs[input.index].take(out)?;
        let taken = &mut *self.taken;
        out.retain(|m| taken.fresh(input.topic, m.header().stamp_ns, m.header().seq));
        *self.newest = out.iter().map(|m| m.header().stamp_ns).fold(*self.newest, u64::max);
        Ok(())
    }

    /// The newest frame that came in on `input` (older ones are dropped: a late worker skips,
    /// it does not fall further behind), unless a predecessor of this process had taken it.
    pub fn latest_frame(&mut self, input: FrameIn) -> anyhow::Result<Option<Box<dyn FrameView>>> {
        let frame = self.ports.inputs[input.index].latest_frame()?;
        let frame = frame.filter(|f| self.taken.fresh(input.topic, f.header().stamp_ns, f.header().seq));
        if let Some(f) = &frame {
            *self.newest = (*self.newest).max(f.header().stamp_ns);
        }
        Ok(frame)
    }

    /// Notes the message `(stamp_ns, seq)` of `input` taken without a transport: a node that
    /// rebuilds itself from a journal of its inputs marks them, so that they are not taken twice.
    pub fn mark_taken<T>(&mut self, input: In<T>, stamp_ns: u64, seq: u64) {
        self.taken.fresh(input.topic, stamp_ns, seq);
    }

    /// Sends `msg` on `output`, unless a predecessor of this process sent it before it was killed.
    pub fn send<T: Message>(&mut self, output: Out<T>, msg: &T) -> anyhow::Result<()> {
        self.send_as(output, output.topic, msg)
    }

    /// [`Io::send`] for an output whose messages `key` numbers apart from the others sent on
    /// the same topic (two reflexes, each numbering its own commands).
    pub fn send_as<T: Message>(&mut self, output: Out<T>, key: &str, msg: &T) -> anyhow::Result<()> {
        let h = *msg.header();
        if self.sent.due(key, h.stamp_ns, h.seq) {
            self.ports.outputs[output.index].put(msg)?;
            self.sent.done(key, h.stamp_ns, h.seq)?;
        }
        Ok(())
    }

    /// The turn's time: the tick in deterministic mode; in real time the newest stamp taken so
    /// far (of this turn or an earlier one).
    pub fn now(&self) -> u64 {
        self.tick.unwrap_or(*self.newest)
    }
}

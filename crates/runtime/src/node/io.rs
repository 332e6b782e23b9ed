//! A node's view of its ports during one turn: inputs taken less what a predecessor took,
//! outputs sent unless a predecessor sent them.

use harvey_msgs::{FrameHeader, Message};

use super::{FrameIn, FrameOut, In, Out, Wired};
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
    /// Whether what the node keeps outlives this process (a supervised process's state folder).
    pub(crate) persistent: bool,
}

impl Io<'_> {
    /// Replaces `out` with the messages that came in on `input` since the last turn, oldest first,
    /// less those a predecessor of this process had taken already. Reuse `out` across turns.
    pub fn take<T: Message>(&mut self, input: In<T>, out: &mut Vec<T>) -> anyhow::Result<()> {
        self.ports.input(input.index, input.topic)?.take(out)?;
        let taken = &mut *self.taken;
        out.retain(|m| taken.fresh(input.topic, m.header().stamp_ns, m.header().seq));
        if self.ports.times(input.index) {
            *self.newest = out.iter().map(|m| m.header().stamp_ns).fold(*self.newest, u64::max);
        }
        Ok(())
    }

    /// The newest frame that came in on `input` (older ones are dropped: a late worker skips,
    /// it does not fall further behind), unless a predecessor of this process had taken it.
    pub fn latest_frame(&mut self, input: FrameIn) -> anyhow::Result<Option<Box<dyn FrameView>>> {
        let frame = self.ports.input(input.index, input.topic)?.latest_frame()?;
        let frame = frame.filter(|f| self.taken.fresh(input.topic, f.header().stamp_ns, f.header().seq));
        if let Some(f) = frame.as_ref().filter(|_| self.ports.times(input.index)) {
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
            self.ports.output(output.index, output.topic)?.put(msg)?;
            self.sent.done(key, h.stamp_ns, h.seq)?;
        }
        Ok(())
    }

    /// Sends a frame of `header` on `output`, its pixels written in place by `fill` (every byte:
    /// the slot holds an earlier frame's), unless a predecessor of this process sent it (then
    /// `fill` is not called). Returns whether the frame went out now.
    pub fn send_frame(
        &mut self,
        output: FrameOut,
        header: FrameHeader,
        mut fill: impl FnMut(&mut [u8]) -> anyhow::Result<()>,
    ) -> anyhow::Result<bool> {
        if !self.sent.due(output.topic, header.stamp_ns, header.seq) {
            return Ok(false);
        }
        self.ports.output(output.index, output.topic)?.put_frame(header, &mut fill)?;
        self.sent.done(output.topic, header.stamp_ns, header.seq)?;
        Ok(true)
    }

    /// Whether the runner keeps state across restarts (a supervised process; never in process):
    /// a node that keeps more of its own (a journal) does so only then.
    pub fn persistent(&self) -> bool {
        self.persistent
    }

    /// The turn's time: the tick in deterministic mode; in real time the newest stamp taken so
    /// far (of this turn or an earlier one) from the input that times the node's turns
    /// ([`super::Ports::time_from`]), or from any input.
    pub fn now(&self) -> u64 {
        self.tick.unwrap_or(*self.newest)
    }
}

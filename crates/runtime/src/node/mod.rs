//! The node: a service's logic as the runtime runs it, declared ports and one step a turn.
//!
//! A service declares its inputs and outputs once ([`Ports`], typed handles [`In`] and [`Out`])
//! and implements [`Node::step`]: take what came in, work, send what goes out, through [`Io`].
//! Everything around the step is the runner's, the same for every service: joining the bus,
//! pacing (real time or its turn in the clock chain), readiness, the checkpoint a restarted
//! process resumes from ([`crate::Resume`]: inputs already taken are dropped, outputs already
//! sent are not sent twice), and the turn's warnings on `rosout`. [`run`] runs a node as a
//! process over the bus.

mod bus;
mod ports;

pub use bus::run;
pub use ports::{In, Out, Ports};

use std::any::Any;

use harvey_msgs::Message;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::Sent;
use crate::resume::Marks;

/// A service's logic: what it keeps across restarts, and what it does with a turn's inputs.
///
/// The node itself holds its ports, settings and scratch buffers; what a restarted process
/// needs to go on is its [`Node::State`], which the runner owns, saves at the end of every turn
/// and hands back to a restarted process.
pub trait Node {
    /// What a restarted process needs to go on where its predecessor stopped.
    type State: Serialize + DeserializeOwned;
    /// Room for the state and the marks of its inputs in the checkpoint.
    const CHECKPOINT_BYTES: usize;

    /// The state of a fresh start.
    fn start(&mut self) -> Self::State;

    /// The state came from a predecessor's checkpoint (before the first turn): take it up.
    fn resumed(&mut self, _state: &mut Self::State) {
        tracing::warn!("resumed from the checkpoint");
    }

    /// One turn: take the inputs, work, send.
    fn step(&mut self, state: &mut Self::State, io: &mut Io<'_>) -> anyhow::Result<()>;

    /// The service stops, after its last turn: say what it did.
    fn stopped(&mut self, _state: &Self::State) {}
}

/// Moves messages between a node and its ports; the runner's transport behind [`Io`].
pub(crate) trait Transport {
    /// Replaces `out` (a `Vec<T>` of input `index`'s type) with what came in, oldest first.
    fn take(&self, index: usize, out: &mut dyn Any) -> anyhow::Result<()>;
    /// Sends `msg` (a `T` of output `index`'s type).
    fn put(&self, index: usize, msg: &dyn Any) -> anyhow::Result<()>;
}

/// A node's view of its ports during one turn.
pub struct Io<'a> {
    transport: &'a dyn Transport,
    taken: &'a mut Marks,
    sent: &'a mut Sent,
    tick: Option<u64>,
    newest: &'a mut u64,
}

impl Io<'_> {
    /// Replaces `out` with the messages that came in on `input` since the last turn, oldest first,
    /// less those a predecessor of this process had taken already. Reuse `out` across turns.
    pub fn take<T: Message>(&mut self, input: In<T>, out: &mut Vec<T>) -> anyhow::Result<()> {
        self.transport.take(input.index, out)?;
        let taken = &mut *self.taken;
        out.retain(|m| taken.fresh(input.topic, m.header().stamp_ns, m.header().seq));
        *self.newest = out.iter().map(|m| m.header().stamp_ns).fold(*self.newest, u64::max);
        Ok(())
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
            self.transport.put(output.index, msg)?;
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

/// `out` as the `Vec<T>` a port of type `T` fills, or an error naming the topic.
pub(crate) fn vec_of<'v, T: 'static>(out: &'v mut dyn Any, topic: &str) -> anyhow::Result<&'v mut Vec<T>> {
    out.downcast_mut::<Vec<T>>()
        .ok_or_else(|| anyhow::anyhow!("{topic}: a handle of another type was used for this input"))
}

/// `msg` as the `T` a port of type `T` sends, or an error naming the topic.
pub(crate) fn msg_of<'m, T: 'static>(msg: &'m dyn Any, topic: &str) -> anyhow::Result<&'m T> {
    msg.downcast_ref::<T>()
        .ok_or_else(|| anyhow::anyhow!("{topic}: a handle of another type was used for this output"))
}

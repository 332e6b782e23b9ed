//! The node: a service's logic as the runtime runs it, declared ports and one step a turn.
//!
//! A service declares its inputs and outputs once ([`Ports`], typed handles [`In`], [`Out`] and
//! [`FrameIn`]) and implements [`Node::step`]: take what came in, work, send what goes out,
//! through [`Io`]. Everything around the step is the runner's, the same for every service:
//! joining the bus, pacing (real time or its turn in the clock chain), readiness, the
//! checkpoint a restarted process resumes from ([`crate::Resume`]: inputs already taken are
//! dropped, outputs already sent are not sent twice), and the turn's warnings on `rosout`.
//! [`run`] runs a node as a process over the bus.

mod bus;
mod inproc;
mod io;
pub mod memory;
mod ports;

pub use bus::run;
pub use inproc::{Hosted, host};
pub use io::{FrameView, Io};
pub use ports::{FrameIn, FrameOut, In, Out, Ports};

use std::any::Any;

use serde::Serialize;
use serde::de::DeserializeOwned;

/// How a node's run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// The node said it was done ([`Node::finished`]).
    Finished,
    /// The runner was told to stop (SIGINT or SIGTERM; in deterministic mode once the turns
    /// granted have run).
    Stopped,
}

/// A service's logic: what it keeps across restarts, and what it does with a turn's inputs.
///
/// The node itself holds its ports, settings and scratch buffers; what a restarted process
/// needs to go on is its [`Node::State`], which the runner owns, saves at the end of every turn
/// and hands back to a restarted process.
pub trait Node {
    /// What a restarted process needs to go on where its predecessor stopped.
    type State: Serialize + DeserializeOwned;
    /// Room for the state and the marks of its inputs in the checkpoint; 0: no checkpoint (a
    /// node that rebuilds itself otherwise, in [`Node::begin`]).
    const CHECKPOINT_BYTES: usize;

    /// The state of a fresh start.
    fn start(&mut self) -> Self::State;

    /// Once, before the first turn, with the state fresh or (`resumed`) a predecessor's. What a
    /// node sends here goes out before the first tick.
    fn begin(&mut self, _state: &mut Self::State, resumed: bool, _io: &mut Io<'_>) -> anyhow::Result<()> {
        if resumed {
            tracing::warn!("resumed from the checkpoint");
        }
        Ok(())
    }

    /// One turn: take the inputs, work, send.
    fn step(&mut self, state: &mut Self::State, io: &mut Io<'_>) -> anyhow::Result<()>;

    /// Brings `state` up to date before the runner saves it, at the end of a turn, for a node
    /// that keeps part of what it needs elsewhere (called only when a checkpoint is kept).
    fn save(&mut self, _state: &mut Self::State) {}

    /// Whether the node is done (checked before each turn): the runner stops it.
    fn finished(&self, _state: &Self::State) -> bool {
        false
    }

    /// The service stops, after its last turn: say what it did. The process exits with the
    /// code returned.
    fn stopped(&mut self, _state: &Self::State, _end: End) -> anyhow::Result<u8> {
        Ok(0)
    }
}

/// An input port as a runner opened it (a bus subscriber, a hub queue).
pub(crate) trait InputPort {
    fn topic(&self) -> &'static str;

    /// Replaces `out` (a `Vec<T>` of the port's type) with what came in, oldest first.
    fn take(&self, _out: &mut dyn Any) -> anyhow::Result<()> {
        anyhow::bail!("{}: a frame input is read with `latest_frame`", self.topic())
    }

    /// The newest frame, older ones released.
    fn latest_frame(&self) -> anyhow::Result<Option<Box<dyn FrameView>>> {
        anyhow::bail!("{}: a message input is read with `take`", self.topic())
    }

    /// What wakes a process runner when the port has news (none in process).
    fn waitable(&self) -> Option<&dyn harvey_bus::Waitable> {
        None
    }
}

/// An output port as a runner opened it.
pub(crate) trait OutputPort {
    fn topic(&self) -> &'static str;

    /// Sends `msg` (a `T` of the port's type).
    fn put(&self, _msg: &dyn Any) -> anyhow::Result<()> {
        anyhow::bail!("{}: a frame output is sent with `send_frame`", self.topic())
    }

    /// Sends a frame of `header` whose pixels `fill` writes in place.
    fn put_frame(
        &self,
        _header: harvey_msgs::FrameHeader,
        _fill: &mut dyn FnMut(&mut [u8]) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        anyhow::bail!("{}: a message output is sent with `send`", self.topic())
    }
}

/// A node's ports as a runner opened them, in the order [`Ports`] declared them: what [`Io`]
/// moves messages through.
pub(crate) struct Wired {
    pub inputs: Vec<Box<dyn InputPort>>,
    pub outputs: Vec<Box<dyn OutputPort>>,
    /// The input whose stamps time a real-time turn ([`Ports::time_from`]; none: every input's).
    pub time_from: Option<usize>,
}

impl Wired {
    /// Whether input `index`'s stamps time a turn.
    fn times(&self, index: usize) -> bool {
        self.time_from.is_none_or(|i| i == index)
    }

    /// Input `index`, or an error naming the topic (a handle another node's ports made).
    fn input(&self, index: usize, topic: &str) -> anyhow::Result<&dyn InputPort> {
        let port = self.inputs.get(index).filter(|p| p.topic() == topic);
        port.map(|p| p.as_ref()).ok_or_else(|| anyhow::anyhow!("{topic}: not an input this node declared"))
    }

    /// Output `index`, or an error naming the topic.
    fn output(&self, index: usize, topic: &str) -> anyhow::Result<&dyn OutputPort> {
        let port = self.outputs.get(index).filter(|p| p.topic() == topic);
        port.map(|p| p.as_ref()).ok_or_else(|| anyhow::anyhow!("{topic}: not an output this node declared"))
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

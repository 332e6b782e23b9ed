//! Nodes hosted in one process: each node's ports on a [`Hub`], its turn called by the runner
//! in the clock chain's order, its warnings on the hub's `rosout`.

use std::any::Any;
use std::rc::Rc;

use harvey_msgs::{FrameHeader, LogLine, Message, topics};

use super::memory::{Hub, OwnedFrame, Receiver, Sender};
use super::{End, FrameView, InputPort, Io, Node, OutputPort, Ports, Wired, msg_of, vec_of};
use crate::resume::Marks;
use crate::{Rosout, Sent};

impl<T: Message> InputPort for Receiver<T> {
    fn topic(&self) -> &'static str {
        Receiver::topic(self)
    }

    fn take(&self, out: &mut dyn Any) -> anyhow::Result<()> {
        let out = vec_of::<T>(out, Receiver::topic(self))?;
        out.clear();
        self.drain(|m| out.push(m));
        Ok(())
    }
}

/// A frame input on a hub.
pub(crate) struct FrameReceiver(pub Receiver<Rc<OwnedFrame>>);

impl InputPort for FrameReceiver {
    fn topic(&self) -> &'static str {
        self.0.topic()
    }

    fn latest_frame(&self) -> anyhow::Result<Option<Box<dyn FrameView>>> {
        Ok(self.0.latest().map(|f| Box::new(f) as Box<dyn FrameView>))
    }
}

impl<T: Message> OutputPort for Sender<T> {
    fn topic(&self) -> &'static str {
        Sender::topic(self)
    }

    fn put(&self, msg: &dyn Any) -> anyhow::Result<()> {
        self.send(*msg_of::<T>(msg, self.topic())?);
        Ok(())
    }
}

/// A frame output on a hub: each frame a buffer of its own, shared by the subscribers.
pub(crate) struct FrameSender {
    pub tx: Sender<Rc<OwnedFrame>>,
    pub max_frame_bytes: usize,
}

impl OutputPort for FrameSender {
    fn topic(&self) -> &'static str {
        self.tx.topic()
    }

    fn put_frame(
        &self,
        header: FrameHeader,
        fill: &mut dyn FnMut(&mut [u8]) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        let len = header.payload_len();
        anyhow::ensure!(
            len > 0 && len <= self.max_frame_bytes,
            "{}: frame size out of range: {len} bytes, publisher sized for 1..={}",
            self.tx.topic(),
            self.max_frame_bytes
        );
        let mut pixels = vec![0; len];
        fill(&mut pixels)?;
        self.tx.send(Rc::new(OwnedFrame { header, pixels }));
        Ok(())
    }
}

/// A node as the in-process runner holds it, whatever its state's type.
pub trait Hosted {
    /// The service's name (its `rosout` name).
    fn name(&self) -> &str;
    /// Before the first turn ([`Node::begin`], never resumed).
    fn begin(&mut self) -> anyhow::Result<()>;
    /// The node's turn on tick `tick`; its warnings go out on `rosout` stamped with it.
    fn step(&mut self, tick: u64) -> anyhow::Result<()>;
    /// Whether the node is done ([`Node::finished`]).
    fn finished(&self) -> bool;
    /// After the last turn; the exit code the node gives.
    fn stop(&mut self, end: End) -> anyhow::Result<u8>;
}

struct InProcess<N: Node> {
    name: String,
    node: N,
    state: N::State,
    wired: Wired,
    taken: Marks,
    sent: Sent,
    newest: u64,
    rosout: Rosout,
    log: Sender<LogLine>,
}

impl<N: Node> InProcess<N> {
    fn io(&mut self, tick: Option<u64>) -> (&mut N, &mut N::State, Io<'_>) {
        let io = Io {
            ports: &self.wired,
            taken: &mut self.taken,
            sent: &mut self.sent,
            tick,
            newest: &mut self.newest,
            persistent: false,
        };
        (&mut self.node, &mut self.state, io)
    }
}

impl<N: Node> Hosted for InProcess<N> {
    fn name(&self) -> &str {
        &self.name
    }

    fn begin(&mut self) -> anyhow::Result<()> {
        let (node, state, mut io) = self.io(None);
        node.begin(state, false, &mut io)
    }

    fn step(&mut self, tick: u64) -> anyhow::Result<()> {
        self.rosout.begin();
        let (node, state, mut io) = self.io(Some(tick));
        node.step(state, &mut io)?;
        let log = &self.log;
        self.rosout.end_with(tick, |line| {
            log.send(*line);
            Ok(())
        })?;
        Ok(())
    }

    fn finished(&self) -> bool {
        self.node.finished(&self.state)
    }

    fn stop(&mut self, end: End) -> anyhow::Result<u8> {
        self.node.stopped(&self.state, end)
    }
}

/// Hosts the node `build` makes as service `name`, its ports opened on `hub`.
pub fn host<N: Node + 'static>(
    name: &str,
    hub: &Hub,
    build: impl FnOnce(&mut Ports) -> anyhow::Result<N>,
) -> anyhow::Result<Box<dyn Hosted>> {
    let mut ports = Ports::default();
    let mut node = build(&mut ports)?;
    let wired = Wired {
        inputs: ports.inputs.iter().map(|i| i.open_memory(hub)).collect::<anyhow::Result<_>>()?,
        outputs: ports.outputs.iter().map(|o| o.open_memory(hub)).collect::<anyhow::Result<_>>()?,
        time_from: ports.time_from,
    };
    let state = node.start();
    Ok(Box::new(InProcess {
        name: name.to_owned(),
        node,
        state,
        wired,
        taken: Marks::default(),
        sent: Sent::detached(),
        newest: 0,
        rosout: Rosout::detached(name),
        log: hub.publisher(topics::ROSOUT.name, topics::ROSOUT.qos.buffer)?,
    }))
}

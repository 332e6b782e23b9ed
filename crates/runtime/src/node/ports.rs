//! A node's declared ports: typed handles for the node, and what each runner needs to open them.

use core::marker::PhantomData;
use core::time::Duration;

use harvey_bus::Bus;
use harvey_msgs::Message;
use harvey_msgs::topics::{FrameTopic, Topic};

use super::inproc::{FrameReceiver, FrameSender};
use super::memory::Hub;
use super::{InputPort, OutputPort};

/// An input of a node: messages of type `T` from one topic.
pub struct In<T> {
    pub(crate) index: usize,
    pub(crate) topic: &'static str,
    _t: PhantomData<fn() -> T>,
}

/// An output of a node: messages of type `T` to one topic.
pub struct Out<T> {
    pub(crate) index: usize,
    pub(crate) topic: &'static str,
    _t: PhantomData<fn() -> T>,
}

/// A frame input of a node: camera frames read in place.
#[derive(Debug, Clone, Copy)]
pub struct FrameIn {
    pub(crate) index: usize,
    pub(crate) topic: &'static str,
}

/// A frame output of a node: camera frames written in place.
#[derive(Debug, Clone, Copy)]
pub struct FrameOut {
    pub(crate) index: usize,
    pub(crate) topic: &'static str,
}

impl<T> Clone for In<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for In<T> {}
impl<T> Clone for Out<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Out<T> {}

impl<T> In<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }
}

impl<T> Out<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }
}

/// An input as a runner opens it.
pub(crate) trait InputSpec {
    fn topic(&self) -> &'static str;
    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn InputPort>>;
    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn InputPort>>;
}

/// An output as a runner opens it.
pub(crate) trait OutputSpec {
    fn topic(&self) -> &'static str;
    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn OutputPort>>;
    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn OutputPort>>;
}

impl<T: Message> InputSpec for Topic<T> {
    fn topic(&self) -> &'static str {
        self.name
    }

    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn InputPort>> {
        Ok(Box::new(bus.subscriber::<T>(*self)?))
    }

    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn InputPort>> {
        Ok(Box::new(hub.subscribe::<T>(self.name, self.qos.buffer)?))
    }
}

impl InputSpec for FrameTopic {
    fn topic(&self) -> &'static str {
        self.name
    }

    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn InputPort>> {
        Ok(Box::new(bus.frame_subscriber(*self)?))
    }

    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn InputPort>> {
        Ok(Box::new(FrameReceiver(hub.subscribe(self.name, self.qos.buffer)?)))
    }
}

impl<T: Message> OutputSpec for Topic<T> {
    fn topic(&self) -> &'static str {
        self.name
    }

    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn OutputPort>> {
        Ok(Box::new(bus.publisher::<T>(*self)?))
    }

    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn OutputPort>> {
        Ok(Box::new(hub.publisher::<T>(self.name, self.qos.buffer)?))
    }
}

/// A frame output as a runner opens it: its shared memory sized for the largest frame.
struct FrameOutSpec {
    topic: FrameTopic,
    max_frame_bytes: usize,
}

impl OutputSpec for FrameOutSpec {
    fn topic(&self) -> &'static str {
        self.topic.name
    }

    fn open_bus(&self, bus: &Bus) -> anyhow::Result<Box<dyn OutputPort>> {
        Ok(Box::new(bus.frame_publisher(self.topic, self.max_frame_bytes)?))
    }

    fn open_memory(&self, hub: &Hub) -> anyhow::Result<Box<dyn OutputPort>> {
        let tx = hub.publisher(self.topic.name, self.topic.qos.buffer)?;
        Ok(Box::new(FrameSender { tx, max_frame_bytes: self.max_frame_bytes }))
    }
}

/// What a node declares: its inputs, in the order it takes them, its outputs, and how often it
/// wakes without input in real time.
#[derive(Default)]
pub struct Ports {
    pub(crate) inputs: Vec<Box<dyn InputSpec>>,
    pub(crate) outputs: Vec<Box<dyn OutputSpec>>,
    pub(crate) interval: Option<Duration>,
    /// The input whose stamps time a turn in real time (none: every input's).
    pub(crate) time_from: Option<usize>,
}

impl Ports {
    /// Declares an input; the node takes its messages with [`super::Io::take`].
    pub fn input<T: Message>(&mut self, topic: Topic<T>) -> In<T> {
        self.inputs.push(Box::new(topic));
        In { index: self.inputs.len() - 1, topic: topic.name, _t: PhantomData }
    }

    /// Declares a frame input; the node reads its frames with [`super::Io::latest_frame`].
    pub fn frames(&mut self, topic: FrameTopic) -> FrameIn {
        self.inputs.push(Box::new(topic));
        FrameIn { index: self.inputs.len() - 1, topic: topic.name }
    }

    /// Declares an output; the node sends on it with [`super::Io::send`].
    pub fn output<T: Message>(&mut self, topic: Topic<T>) -> Out<T> {
        self.outputs.push(Box::new(topic));
        Out { index: self.outputs.len() - 1, topic: topic.name, _t: PhantomData }
    }

    /// Declares a frame output of frames up to `max_frame_bytes`; the node writes and sends
    /// its frames with [`super::Io::send_frame`].
    pub fn frames_out(&mut self, topic: FrameTopic, max_frame_bytes: usize) -> FrameOut {
        self.outputs.push(Box::new(FrameOutSpec { topic, max_frame_bytes }));
        FrameOut { index: self.outputs.len() - 1, topic: topic.name }
    }

    /// In real time, also gives the node a turn every `period` (a source with no input: a camera
    /// at a fixed rate). A clock party's turns come from the chain only.
    pub fn every(&mut self, period: Duration) {
        self.interval = Some(period);
    }

    /// In real time, a turn's time ([`super::Io::now`], its warnings' stamp) is the newest stamp
    /// taken from `input` (the one that drives the node), not from any input.
    pub fn time_from<T>(&mut self, input: In<T>) {
        self.time_from = Some(input.index);
    }

    /// [`Ports::time_from`] for a frame input.
    pub fn time_from_frames(&mut self, input: FrameIn) {
        self.time_from = Some(input.index);
    }

    /// The topics declared, inputs then outputs (for errors and listings).
    pub fn topics(&self) -> (Vec<&'static str>, Vec<&'static str>) {
        (self.inputs.iter().map(|i| i.topic()).collect(), self.outputs.iter().map(|o| o.topic()).collect())
    }
}

//! Topics in memory, for nodes run in one process: what the bus does between processes, with
//! the same delivery (every subscriber its own queue, oldest first, the oldest dropped when a
//! queue holds its QoS buffer) and no shared memory.

use std::any::Any;
use std::cell::RefCell;
use std::collections::{BTreeMap, VecDeque};
use std::rc::Rc;

use harvey_msgs::FrameHeader;

use super::FrameView;

/// A frame held in memory: header and pixels, shared by every subscriber that has it queued.
#[derive(Debug, Clone)]
pub struct OwnedFrame {
    pub header: FrameHeader,
    pub pixels: Vec<u8>,
}

impl FrameView for Rc<OwnedFrame> {
    fn header(&self) -> &FrameHeader {
        &self.header
    }

    fn pixels(&self) -> &[u8] {
        &self.pixels
    }
}

type Queue<T> = Rc<RefCell<VecDeque<T>>>;

/// One topic's subscribers.
struct Subscribers<T> {
    queues: Vec<Queue<T>>,
    buffer: usize,
}

/// The topics of one process's nodes, by name.
#[derive(Default)]
pub struct Hub {
    topics: RefCell<BTreeMap<&'static str, Box<dyn Any>>>,
}

impl Hub {
    fn topic<T: 'static>(
        &self,
        name: &'static str,
        buffer: usize,
    ) -> anyhow::Result<Rc<RefCell<Subscribers<T>>>> {
        let mut topics = self.topics.borrow_mut();
        let entry = topics.entry(name).or_insert_with(|| {
            Box::new(Rc::new(RefCell::new(Subscribers::<T> { queues: Vec::new(), buffer })))
        });
        entry
            .downcast_ref::<Rc<RefCell<Subscribers<T>>>>()
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("topic {name} is used with two message types"))
    }

    /// A new subscriber of `name`: it receives what is published from now on.
    pub fn subscribe<T: 'static>(&self, name: &'static str, buffer: usize) -> anyhow::Result<Receiver<T>> {
        let topic = self.topic::<T>(name, buffer)?;
        let queue = Queue::default();
        topic.borrow_mut().queues.push(Rc::clone(&queue));
        Ok(Receiver { topic: name, queue })
    }

    /// A publisher on `name`.
    pub fn publisher<T: 'static>(&self, name: &'static str, buffer: usize) -> anyhow::Result<Sender<T>> {
        Ok(Sender { topic: name, subscribers: self.topic::<T>(name, buffer)? })
    }
}

/// A subscriber's queue.
pub struct Receiver<T> {
    topic: &'static str,
    queue: Queue<T>,
}

impl<T> Receiver<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// Everything queued, oldest first.
    pub fn drain(&self, mut f: impl FnMut(T)) -> usize {
        let mut q = self.queue.borrow_mut();
        let n = q.len();
        q.drain(..).for_each(&mut f);
        n
    }

    /// The newest queued, older ones dropped.
    pub fn latest(&self) -> Option<T> {
        self.queue.borrow_mut().drain(..).last()
    }
}

/// A publisher: each send goes into every subscriber's queue.
pub struct Sender<T> {
    topic: &'static str,
    subscribers: Rc<RefCell<Subscribers<T>>>,
}

impl<T: Clone> Sender<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    pub fn send(&self, msg: T) {
        let subs = self.subscribers.borrow();
        for q in &subs.queues {
            let mut q = q.borrow_mut();
            q.push_back(msg.clone());
            while q.len() > subs.buffer.max(1) {
                q.pop_front();
            }
        }
    }
}

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

/// A subscriber's queues, one per publisher, by the order the publishers came.
type Queues<T> = Rc<RefCell<Vec<VecDeque<T>>>>;

/// One topic's connections. As iceoryx2 does, each publisher reaches each subscriber through a
/// queue of its own (of the topic's QoS buffer, the oldest dropped when full), and a subscriber
/// takes its queues in the order the publishers came.
struct Connections<T> {
    buffer: usize,
    publishers: usize,
    subscribers: Vec<Queues<T>>,
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
    ) -> anyhow::Result<Rc<RefCell<Connections<T>>>> {
        let mut topics = self.topics.borrow_mut();
        let entry = topics.entry(name).or_insert_with(|| {
            Box::new(Rc::new(RefCell::new(Connections::<T> {
                buffer,
                publishers: 0,
                subscribers: Vec::new(),
            })))
        });
        entry
            .downcast_ref::<Rc<RefCell<Connections<T>>>>()
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("topic {name} is used with two message types"))
    }

    /// A new subscriber of `name`: it receives what is published from now on.
    pub fn subscribe<T: 'static>(&self, name: &'static str, buffer: usize) -> anyhow::Result<Receiver<T>> {
        let topic = self.topic::<T>(name, buffer)?;
        let mut t = topic.borrow_mut();
        let queues: Queues<T> = Rc::new(RefCell::new((0..t.publishers).map(|_| VecDeque::new()).collect()));
        t.subscribers.push(Rc::clone(&queues));
        Ok(Receiver { topic: name, queues })
    }

    /// A publisher on `name`.
    pub fn publisher<T: 'static>(&self, name: &'static str, buffer: usize) -> anyhow::Result<Sender<T>> {
        let topic = self.topic::<T>(name, buffer)?;
        let id = {
            let mut t = topic.borrow_mut();
            t.subscribers.iter().for_each(|q| q.borrow_mut().push(VecDeque::new()));
            t.publishers += 1;
            t.publishers - 1
        };
        Ok(Sender { topic: name, id, connections: topic })
    }
}

/// A subscriber.
pub struct Receiver<T> {
    topic: &'static str,
    queues: Queues<T>,
}

impl<T> Receiver<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// Everything queued, publisher by publisher, each one's oldest first.
    pub fn drain(&self, mut f: impl FnMut(T)) -> usize {
        let mut queues = self.queues.borrow_mut();
        let n = queues.iter().map(VecDeque::len).sum();
        queues.iter_mut().for_each(|q| q.drain(..).for_each(&mut f));
        n
    }

    /// The last of everything queued (taken as [`Receiver::drain`] takes it), the rest dropped.
    pub fn latest(&self) -> Option<T> {
        let mut last = None;
        self.drain(|m| last = Some(m));
        last
    }
}

/// A publisher: each send goes into its queue to every subscriber.
pub struct Sender<T> {
    topic: &'static str,
    id: usize,
    connections: Rc<RefCell<Connections<T>>>,
}

impl<T: Clone> Sender<T> {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    pub fn send(&self, msg: T) {
        let c = self.connections.borrow();
        for queues in &c.subscribers {
            let mut queues = queues.borrow_mut();
            if let Some(q) = queues.get_mut(self.id) {
                q.push_back(msg.clone());
                while q.len() > c.buffer.max(1) {
                    q.pop_front();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_publisher_has_its_own_queue_to_each_subscriber_taken_in_the_order_they_came() {
        let hub = Hub::default();
        let early = hub.subscribe::<u32>("t", 3).expect("subscribes");
        let (a, b) = (hub.publisher::<u32>("t", 3).expect("a"), hub.publisher::<u32>("t", 3).expect("b"));
        let late = hub.subscribe::<u32>("t", 3).expect("subscribes");
        b.send(1);
        a.send(2);
        (10..15).for_each(|m| b.send(m));
        // a's queue first; b's kept its newest 3 of 6.
        for r in [&early, &late] {
            let mut got = Vec::new();
            assert_eq!(r.drain(|m| got.push(m)), 4);
            assert_eq!(got, [2, 12, 13, 14]);
        }
        assert_eq!(early.latest(), None);
        a.send(7);
        b.send(8);
        assert_eq!(late.latest(), Some(8));
        assert!(hub.publisher::<u8>("t", 3).is_err(), "another type on the same topic");
    }
}

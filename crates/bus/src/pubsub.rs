//! Typed publishers and subscribers of fixed-size messages, each paired with an event port so
//! that subscribers are woken, never polled.

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher as IoxPublisher;
use iceoryx2::port::subscriber::Subscriber as IoxSubscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenOrCreateError;

use harvey_msgs::{Message, Qos, Topic};

use crate::{Bus, BusError, Result};

pub(crate) fn open_error(topic: &str, e: PublishSubscribeOpenOrCreateError) -> BusError {
    let detail = format!("{e:?}");
    if detail.contains("Incompatible") || detail.contains("DoesNotSupport") {
        BusError::IncompatibleTopic { topic: topic.to_owned(), detail }
    } else {
        BusError::topic(topic, "cannot open or create the topic", e)
    }
}

/// The event service that carries a topic's "new data" notifications.
pub(crate) fn event_ports(
    bus: &Bus,
    topic: &str,
    qos: Qos,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>> {
    bus.node
        .service_builder(&Bus::service_name(topic)?)
        .event()
        .max_notifiers(qos.max_publishers)
        .max_listeners(qos.max_subscribers)
        .max_nodes(qos.max_publishers + qos.max_subscribers + 2)
        .open_or_create()
        .map_err(|e| BusError::topic(topic, "cannot open or create its event service", e))
}

pub(crate) fn max_nodes(qos: Qos) -> usize {
    qos.max_publishers + qos.max_subscribers + 2
}

/// Applies a topic's [`Qos`] to a publish-subscribe service builder of any payload type.
macro_rules! apply_qos {
    ($builder:expr, $qos:expr) => {
        $builder
            .history_size($qos.history)
            .subscriber_max_buffer_size($qos.buffer)
            .subscriber_max_borrowed_samples($qos.borrowed)
            .enable_safe_overflow(true)
            .max_publishers($qos.max_publishers)
            .max_subscribers($qos.max_subscribers)
            .max_nodes(crate::pubsub::max_nodes($qos))
    };
}
pub(crate) use apply_qos;

fn open_service<T: Message>(
    bus: &Bus,
    topic: Topic<T>,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>> {
    let qos = topic.qos;
    let builder = bus.node.service_builder(&Bus::service_name(topic.name)?).publish_subscribe::<T>();
    apply_qos!(builder, qos).open_or_create().map_err(|e| open_error(topic.name, e))
}

/// Which publisher sent a message: a bridge takes what it published itself off its own
/// subscriptions by this, never sending it back where it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Origin(pub(crate) iceoryx2::identifiers::UniquePublisherId);

/// The publisher's id in hex, unique on this host (a restarted service's publishers get new ones).
impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// Publishes messages of type `T` on one topic.
pub struct Publisher<T: Message> {
    topic: &'static str,
    port: std::rc::Rc<IoxPublisher<ipc::Service, T, ()>>,
    notifier: Notifier<ipc::Service>,
}

impl<T: Message> Publisher<T> {
    pub(crate) fn new(bus: &Bus, topic: Topic<T>) -> Result<Self> {
        let qos = topic.qos;
        let service = open_service(bus, topic)?;
        let port = service
            .publisher_builder()
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a publisher", e))?;
        let notifier = event_ports(bus, topic.name, qos)?
            .notifier_builder()
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a notifier", e))?;
        Ok(Self { topic: topic.name, port: crate::reoffer::registered(bus, port), notifier })
    }

    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// This publisher, as its subscribers see it.
    pub fn origin(&self) -> Origin {
        Origin(self.port.id())
    }

    /// Sends one message and wakes the subscribers. Returns how many subscribers received it.
    pub fn send(&self, msg: &T) -> Result<usize> {
        let sample =
            self.port.loan_uninit().map_err(|e| BusError::topic(self.topic, "cannot loan a sample", e))?;
        let receivers =
            sample.write_payload(*msg).send().map_err(|e| BusError::topic(self.topic, "cannot send", e))?;
        self.notifier.notify().map_err(|e| BusError::topic(self.topic, "cannot notify", e))?;
        Ok(receivers)
    }
}

/// Receives messages of type `T` from one topic.
pub struct Subscriber<T: Message> {
    topic: &'static str,
    port: IoxSubscriber<ipc::Service, T, ()>,
    pub(crate) listener: Listener<ipc::Service>,
}

impl<T: Message> Subscriber<T> {
    pub(crate) fn new(bus: &Bus, topic: Topic<T>) -> Result<Self> {
        let qos = topic.qos;
        let service = open_service(bus, topic)?;
        let port = service
            .subscriber_builder()
            .buffer_size(qos.buffer)
            .create()
            .map_err(|e| BusError::subscriber(&bus.prefix, topic.name, qos.max_subscribers, e))?;
        let listener = event_ports(bus, topic.name, qos)?
            .listener_builder()
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a listener", e))?;
        Ok(Self { topic: topic.name, port, listener })
    }

    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// Hands every queued message to `f`, oldest first, and returns how many there were.
    /// Pending wake-ups are consumed before the queue is found empty, so a message that arrives
    /// later wakes the waiter again.
    pub fn drain(&self, mut f: impl FnMut(&T)) -> Result<usize> {
        self.drain_with_origin(|m, _| f(m))
    }

    /// [`Subscriber::drain`], with each message's publisher.
    pub fn drain_with_origin(&self, mut f: impl FnMut(&T, Origin)) -> Result<usize> {
        let mut n = 0;
        let mut receive_all = |n: &mut usize| -> Result<()> {
            while let Some(sample) =
                self.port.receive().map_err(|e| BusError::topic(self.topic, "cannot receive", e))?
            {
                f(sample.payload(), Origin(sample.origin()));
                *n += 1;
            }
            Ok(())
        };
        receive_all(&mut n)?;
        crate::waiter::consume_events(&self.listener, self.topic)?;
        receive_all(&mut n)?;
        Ok(n)
    }

    /// Replaces the contents of `out` with every queued message, oldest first; reuse `out` across
    /// wake-ups so the loop does not allocate.
    pub fn drain_into(&self, out: &mut Vec<T>) -> Result<usize> {
        out.clear();
        self.drain(|m| out.push(*m))
    }

    /// The newest queued message, discarding older ones.
    pub fn latest(&self) -> Result<Option<T>> {
        let mut last = None;
        self.drain(|m| last = Some(*m))?;
        Ok(last)
    }
}

impl Bus {
    pub fn publisher<T: Message>(&self, topic: Topic<T>) -> Result<Publisher<T>> {
        Publisher::new(self, topic)
    }

    pub fn subscriber<T: Message>(&self, topic: Topic<T>) -> Result<Subscriber<T>> {
        Subscriber::new(self, topic)
    }
}

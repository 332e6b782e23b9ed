//! Handing a restarted subscriber what it missed. iceoryx2 gives a new subscriber a topic's
//! newest messages (the topic's history) only when a publisher next updates its connections,
//! which in lockstep is its next turn, a tick too late. So before the supervisor grants a
//! restarted party the turn it missed, it asks every process of the domain to re-offer: each
//! updates the connections of all its publishers (delivering their history to the newcomer)
//! and acknowledges. Only then does the newcomer take its turn, with the tick's inputs there.
//!
//! The request is an event (its id the request's number) every process listens to; the
//! acknowledgement a message on [`REOFFERED`] (the request's number as `seq`, the process id as
//! `stamp_ns`).

use std::cell::RefCell;
use std::rc::{Rc, Weak};

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;

use harvey_msgs::{Header, Progress, Qos, Topic};

use iceoryx2::port::publisher::Publisher as IoxPublisher;

use crate::{Bus, BusError, Result, Subscriber, Waitable};

/// The request's event service.
const REOFFER: &str = "harvey/reoffer";
/// Requests are numbered modulo this (an event id is a slot of the event's state).
const EVENT_IDS: usize = 64;
/// Processes a domain may hold that answer.
const MAX_PROCESSES: usize = 64;
/// The acknowledgements.
pub const REOFFERED: Topic<Progress> = Topic::new(
    "harvey/reoffered",
    Qos { buffer: MAX_PROCESSES, borrowed: 1, history: 0, max_publishers: MAX_PROCESSES, max_subscribers: 2 },
);

/// A port whose connections can be brought up to date.
pub(crate) trait Reconnect {
    fn reconnect(&self);
}

impl<T: UpdateConnections> Reconnect for T {
    fn reconnect(&self) {
        if let Err(e) = self.update_connections() {
            tracing::warn!("re-offering to a restarted subscriber: {e:?}");
        }
    }
}

/// A process's side: its publishers, the request listener and its acknowledgement port.
pub struct Reoffers {
    ports: RefCell<Vec<Weak<dyn Reconnect>>>,
    listener: Listener<ipc::Service>,
    ack: IoxPublisher<ipc::Service, Progress, ()>,
}

fn event_service(
    node: &Node<ipc::Service>,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>> {
    node.service_builder(&Bus::service_name(REOFFER)?)
        .event()
        .max_notifiers(2)
        .event_id_max_value(EVENT_IDS)
        .max_listeners(MAX_PROCESSES)
        .max_nodes(MAX_PROCESSES + 2)
        .open_or_create()
        .map_err(|e| BusError::topic(REOFFER, "cannot open or create the re-offer events", e))
}

impl Reoffers {
    pub(crate) fn new(node: &Node<ipc::Service>) -> Result<Self> {
        let listener = event_service(node)?
            .listener_builder()
            .create()
            .map_err(|e| BusError::topic(REOFFER, "cannot create a listener", e))?;
        let builder =
            node.service_builder(&Bus::service_name(REOFFERED.name)?).publish_subscribe::<Progress>();
        let ack = crate::pubsub::apply_qos!(builder, REOFFERED.qos)
            .open_or_create()
            .map_err(|e| crate::pubsub::open_error(REOFFERED.name, e))?
            .publisher_builder()
            .create()
            .map_err(|e| BusError::topic(REOFFERED.name, "cannot create a publisher", e))?;
        Ok(Self { ports: RefCell::new(Vec::new()), listener, ack })
    }

    pub(crate) fn register(&self, port: Weak<dyn Reconnect>) {
        let mut ports = self.ports.borrow_mut();
        ports.retain(|p| p.strong_count() > 0);
        ports.push(port);
    }

    /// Answers the requests that came: every publisher re-offers, then each is acknowledged.
    /// Returns how many were answered.
    pub fn serve(&self) -> Result<usize> {
        let mut requests = Vec::new();
        self.listener
            .try_wait(|a| requests.push(a.id.as_value() as u64))
            .map_err(|e| BusError::topic(REOFFER, "cannot take a request", e))?;
        if requests.is_empty() {
            return Ok(0);
        }
        for p in self.ports.borrow().iter().filter_map(Weak::upgrade) {
            p.reconnect();
        }
        self.ack.reconnect();
        for r in &requests {
            let answer = Progress { header: Header::new(*r, u64::from(std::process::id())) };
            self.ack
                .send_copy(answer)
                .map_err(|e| BusError::topic(REOFFERED.name, "cannot acknowledge", e))?;
        }
        Ok(requests.len())
    }
}

impl Waitable for Reoffers {
    fn multiplexed(&self) -> &dyn crate::waiter::Multiplexed {
        &self.listener
    }
}

/// The supervisor's side: asks and counts the answers.
pub struct ReofferRequests {
    notifier: Notifier<ipc::Service>,
    acks: Subscriber<Progress>,
    next: u64,
}

impl ReofferRequests {
    pub fn new(bus: &Bus) -> Result<Self> {
        let notifier = event_service(&bus.node)?
            .notifier_builder()
            .create()
            .map_err(|e| BusError::topic(REOFFER, "cannot create a notifier", e))?;
        Ok(Self { notifier, acks: bus.subscriber(REOFFERED)?, next: 1 })
    }

    /// Asks every process to re-offer; returns the request's number.
    pub fn request(&mut self) -> Result<u64> {
        let n = self.next;
        self.next = self.next % (EVENT_IDS as u64 - 1) + 1;
        self.acks.drain(|_| {})?;
        self.notifier
            .notify_with_custom_event_id(EventId::new(n as usize))
            .map_err(|e| BusError::topic(REOFFER, "cannot notify", e))?;
        Ok(n)
    }

    /// The processes (by id) that have answered request `n` since the last call.
    pub fn answered(&self, n: u64, into: &mut Vec<u32>) -> Result<()> {
        self.acks.drain(|m| {
            if m.header.seq == n {
                into.push(m.header.stamp_ns as u32);
            }
        })?;
        Ok(())
    }
}

/// Lets a type keep its port registered for re-offers while it lives.
pub(crate) fn registered<P: Reconnect + 'static>(bus: &Bus, port: P) -> Rc<P> {
    let port = Rc::new(port);
    let weak: Weak<dyn Reconnect> = Rc::downgrade(&(port.clone() as Rc<dyn Reconnect>));
    bus.reoffers.register(weak);
    port
}

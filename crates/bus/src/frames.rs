//! Camera frames over shared memory: the producer loans a `[u8]` slice, writes pixels into it in
//! place and sends it; consumers read the very same bytes. Nothing copies pixels.

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher as IoxPublisher;
use iceoryx2::port::subscriber::Subscriber as IoxSubscriber;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::sample_mut::SampleMut;

use harvey_msgs::{FrameHeader, FrameTopic};

use crate::pubsub::{apply_qos, event_ports, open_error};
use crate::{Bus, BusError, Result};

fn open_frame_service(
    bus: &Bus,
    topic: FrameTopic,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [u8], FrameHeader>>
{
    let qos = topic.qos;
    let builder = bus
        .node
        .service_builder(&Bus::service_name(topic.name)?)
        .publish_subscribe::<[u8]>()
        .user_header::<FrameHeader>();
    apply_qos!(builder, qos).open_or_create().map_err(|e| open_error(topic.name, e))
}

/// Publishes camera frames of at most `max_frame_bytes` bytes.
pub struct FramePublisher {
    topic: &'static str,
    max_frame_bytes: usize,
    port: std::rc::Rc<IoxPublisher<ipc::Service, [u8], FrameHeader>>,
    notifier: Notifier<ipc::Service>,
}

/// A frame being written in shared memory; [`FrameLoan::send`] hands it to the subscribers.
pub struct FrameLoan<'p> {
    publisher: &'p FramePublisher,
    sample: SampleMut<ipc::Service, [u8], FrameHeader>,
}

impl FramePublisher {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// This publisher, as its subscribers see it.
    pub fn origin(&self) -> crate::Origin {
        crate::Origin(self.port.id())
    }

    pub fn max_frame_bytes(&self) -> usize {
        self.max_frame_bytes
    }

    /// Loans a slice for a frame described by `header` (its `payload_len()` bytes). The slice
    /// holds whatever an earlier frame left there: write every byte.
    pub fn loan(&self, header: FrameHeader) -> Result<FrameLoan<'_>> {
        let len = header.payload_len();
        if len == 0 || len > self.max_frame_bytes {
            return Err(BusError::Topic {
                topic: self.topic.to_owned(),
                what: "frame size out of range",
                detail: format!("{len} bytes, publisher sized for 1..={}", self.max_frame_bytes),
            });
        }
        let mut uninit = self
            .port
            .loan_slice_uninit(len)
            .map_err(|e| BusError::topic(self.topic, "cannot loan a frame", e))?;
        *uninit.user_header_mut() = header;
        // SAFETY: the slice lies in a shared-memory data segment that the kernel zero-filled
        // when the segment was created, and that since then only ever held bytes written by
        // earlier frames. Every byte is therefore an initialised `u8`; `MaybeUninit` is
        // iceoryx2's conservative typing, not a statement about this memory.
        let sample = unsafe { uninit.assume_init() };
        Ok(FrameLoan { publisher: self, sample })
    }
}

impl FrameLoan<'_> {
    pub fn header(&self) -> &FrameHeader {
        self.sample.user_header()
    }

    /// Replaces the header, e.g. to stamp the frame once its pixels are written.
    pub fn set_header(&mut self, header: FrameHeader) {
        *self.sample.user_header_mut() = header;
    }

    /// The pixels, in shared memory: render straight into them.
    pub fn pixels_mut(&mut self) -> &mut [u8] {
        self.sample.payload_mut()
    }

    /// Publishes the frame and wakes the subscribers; returns how many received it.
    pub fn send(self) -> Result<usize> {
        let topic = self.publisher.topic;
        let n = self.sample.send().map_err(|e| BusError::topic(topic, "cannot send a frame", e))?;
        self.publisher.notifier.notify().map_err(|e| BusError::topic(topic, "cannot notify", e))?;
        Ok(n)
    }
}

/// Receives camera frames in place.
pub struct FrameSubscriber {
    topic: &'static str,
    port: IoxSubscriber<ipc::Service, [u8], FrameHeader>,
    pub(crate) listener: Listener<ipc::Service>,
}

/// A received frame: header and pixels, read in place from shared memory. Holding it keeps the
/// slot borrowed; drop it when done.
pub struct Frame {
    sample: Sample<ipc::Service, [u8], FrameHeader>,
}

impl Frame {
    pub fn header(&self) -> &FrameHeader {
        self.sample.user_header()
    }

    pub fn pixels(&self) -> &[u8] {
        self.sample.payload()
    }

    /// The publisher that sent it.
    pub fn origin(&self) -> crate::Origin {
        crate::Origin(self.sample.origin())
    }
}

impl FrameSubscriber {
    pub fn topic(&self) -> &'static str {
        self.topic
    }

    /// The oldest queued frame, if any. Call until it returns `None` after each wake-up: the
    /// pending wake-ups are consumed before `None` is reported, so a frame sent later wakes the
    /// waiter again.
    pub fn take(&self) -> Result<Option<Frame>> {
        let receive = || self.port.receive().map_err(|e| BusError::topic(self.topic, "cannot receive", e));
        if let Some(sample) = receive()? {
            return Ok(Some(Frame { sample }));
        }
        crate::waiter::consume_events(&self.listener, self.topic)?;
        Ok(receive()?.map(|sample| Frame { sample }))
    }

    /// The newest queued frame, releasing older ones first (a subscriber may hold only
    /// `Qos::borrowed` frames at once).
    pub fn latest(&self) -> Result<Option<Frame>> {
        let mut last = self.take()?;
        while last.is_some()
            && self.port.has_samples().map_err(|e| BusError::topic(self.topic, "cannot receive", e))?
        {
            drop(last.take());
            last = self.take()?;
        }
        Ok(last)
    }
}

impl Bus {
    /// A frame publisher whose shared memory is sized for frames of at most `max_frame_bytes`.
    pub fn frame_publisher(&self, topic: FrameTopic, max_frame_bytes: usize) -> Result<FramePublisher> {
        let service = open_frame_service(self, topic)?;
        let port = service
            .publisher_builder()
            .initial_max_slice_len(max_frame_bytes)
            .max_loaned_samples(1)
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a frame publisher", e))?;
        let notifier = event_ports(self, topic.name, topic.qos)?
            .notifier_builder()
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a notifier", e))?;
        Ok(FramePublisher {
            topic: topic.name,
            max_frame_bytes,
            port: crate::reoffer::registered(self, port),
            notifier,
        })
    }

    pub fn frame_subscriber(&self, topic: FrameTopic) -> Result<FrameSubscriber> {
        let service = open_frame_service(self, topic)?;
        let port = service
            .subscriber_builder()
            .buffer_size(topic.qos.buffer)
            .create()
            .map_err(|e| BusError::subscriber(&self.prefix, topic.name, topic.qos.max_subscribers, e))?;
        let listener = event_ports(self, topic.name, topic.qos)?
            .listener_builder()
            .create()
            .map_err(|e| BusError::topic(topic.name, "cannot create a listener", e))?;
        Ok(FrameSubscriber { topic: topic.name, port, listener })
    }
}

//! Event-driven waiting: a service sleeps in a [`Waiter`] until one of its subscribers has data,
//! a timer fires, or SIGINT/SIGTERM asks it to stop.

use core::time::Duration;

use std::os::fd::AsRawFd;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSet, WaitSetGuard, WaitSetRunResult};
use iceoryx2_bb_posix::file_descriptor::{FileDescriptor, FileDescriptorBased};
use iceoryx2_bb_posix::file_descriptor_set::SynchronousMultiplexing;

use crate::{BusError, FrameSubscriber, Result, Subscriber};

/// Why [`Waiter::wait`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// A subscriber has data or a timer fired.
    Ready,
    /// The timeout passed with nothing to do.
    Timeout,
    /// SIGINT or SIGTERM: finish up and exit.
    Shutdown,
}

/// Something a [`Waiter`] can sleep on.
pub trait Waitable {
    #[doc(hidden)]
    fn multiplexed(&self) -> &dyn Multiplexed;
}

#[doc(hidden)]
pub trait Multiplexed: SynchronousMultiplexing + core::fmt::Debug {}
impl<T: SynchronousMultiplexing + core::fmt::Debug> Multiplexed for T {}

impl<T: harvey_msgs::Message> Waitable for Subscriber<T> {
    fn multiplexed(&self) -> &dyn Multiplexed {
        &self.listener
    }
}

impl Waitable for FrameSubscriber {
    fn multiplexed(&self) -> &dyn Multiplexed {
        &self.listener
    }
}

/// A file descriptor (a serial line, a pipe) a [`Waiter`] can sleep on beside the bus. It does
/// not own the descriptor: keep the file open while this exists.
#[derive(Debug)]
pub struct FdSource {
    fd: FileDescriptor,
}

impl FdSource {
    pub fn new(fd: &impl AsRawFd) -> Result<Self> {
        let raw = fd.as_raw_fd();
        FileDescriptor::non_owning_new(raw)
            .map(|fd| Self { fd })
            .ok_or_else(|| BusError::Wait(format!("file descriptor {raw} is not open")))
    }
}

impl FileDescriptorBased for FdSource {
    fn file_descriptor(&self) -> &FileDescriptor {
        &self.fd
    }
}
impl SynchronousMultiplexing for FdSource {}

impl Waitable for FdSource {
    fn multiplexed(&self) -> &dyn Multiplexed {
        self
    }
}

pub(crate) fn consume_events(listener: &Listener<ipc::Service>, topic: &str) -> Result<()> {
    listener.try_wait(|_| {}).map(|_| ()).map_err(|e| BusError::topic(topic, "cannot consume wake-ups", e))
}

/// Keeps a subscriber or timer attached to a [`Waiter`]; detaches on drop.
pub struct Attachment<'w, 'a> {
    _guard: WaitSetGuard<'w, 'a, ipc::Service>,
}

/// Sleeps until data arrives on attached subscribers, an attached interval elapses, or the
/// process is asked to stop.
pub struct Waiter {
    waitset: WaitSet<ipc::Service>,
}

impl Waiter {
    pub fn new() -> Result<Self> {
        let waitset = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(|e| BusError::Wait(format!("cannot create: {e:?}")))?;
        Ok(Self { waitset })
    }

    pub fn attach<'w, 'a>(&'w self, source: &'a (impl Waitable + ?Sized)) -> Result<Attachment<'w, 'a>> {
        let guard = self
            .waitset
            .attach_notification(source.multiplexed())
            .map_err(|e| BusError::Wait(format!("cannot attach: {e:?}")))?;
        Ok(Attachment { _guard: guard })
    }

    /// Wakes the waiter every `period` (measured on the monotonic clock; for pacing in `main`,
    /// never for service logic).
    pub fn attach_interval(&self, period: Duration) -> Result<Attachment<'_, 'static>> {
        let guard = self
            .waitset
            .attach_interval(period)
            .map_err(|e| BusError::Wait(format!("cannot attach an interval: {e:?}")))?;
        Ok(Attachment { _guard: guard })
    }

    /// Blocks until something attached is ready, `timeout` passes (`None`: no timeout), or a
    /// termination signal arrives. The caller then drains its subscribers.
    pub fn wait(&self, timeout: Option<Duration>) -> Result<Wake> {
        let mut woke = false;
        let on_event = |_| {
            woke = true;
            CallbackProgression::Continue
        };
        let result = match timeout {
            Some(t) => self.waitset.wait_and_process_once_with_timeout(on_event, t),
            None => self.waitset.wait_and_process_once(on_event),
        }
        .map_err(|e| BusError::Wait(format!("{e:?}")))?;
        Ok(match result {
            WaitSetRunResult::TerminationRequest | WaitSetRunResult::Interrupt => Wake::Shutdown,
            _ if woke => Wake::Ready,
            _ => Wake::Timeout,
        })
    }
}

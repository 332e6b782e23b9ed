//! Event-driven waiting: a service sleeps in a [`Waiter`] until one of its subscribers has data,
//! a timer fires, or SIGINT/SIGTERM asks it to stop.

use core::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSet, WaitSetGuard, WaitSetRunResult};

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
    fn listener(&self) -> &Listener<ipc::Service>;
}

impl<T: harvey_msgs::Message> Waitable for Subscriber<T> {
    fn listener(&self) -> &Listener<ipc::Service> {
        &self.listener
    }
}

impl Waitable for FrameSubscriber {
    fn listener(&self) -> &Listener<ipc::Service> {
        &self.listener
    }
}

pub(crate) fn consume_events(listener: &Listener<ipc::Service>, topic: &str) -> Result<()> {
    listener
        .try_wait(|_| {})
        .map(|_| ())
        .map_err(|e| BusError::topic(topic, "cannot consume wake-ups", e))
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

    pub fn attach<'w, 'a>(&'w self, source: &'a impl Waitable) -> Result<Attachment<'w, 'a>> {
        let guard = self
            .waitset
            .attach_notification(source.listener())
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

//! Samples off a Zenoh subscriber, for the bus thread: Zenoh calls back on its own threads,
//! so each sample is queued and the bus thread, asleep in its waiter, is woken through a socket
//! pair (the bus's ports stay on the thread that made them).

use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::sync::mpsc::{Receiver, Sender, channel};

use zenoh::Wait;
use zenoh::pubsub::Subscriber;

/// A sample as it came off Zenoh (its payload in Zenoh's own buffers, not copied).
pub struct Arrived {
    pub key: String,
    pub payload: zenoh::bytes::ZBytes,
    pub attachment: Option<Vec<u8>>,
}

/// The queue of one or more subscribers and the socket that rings when it fills.
pub struct Mailbox {
    tx: Sender<Arrived>,
    rx: Receiver<Arrived>,
    bell: UnixStream,
    ringer: UnixStream,
    subscribers: Vec<Subscriber<()>>,
}

impl Mailbox {
    pub fn new() -> anyhow::Result<Self> {
        let (bell, ringer) = UnixStream::pair()?;
        bell.set_nonblocking(true)?;
        ringer.set_nonblocking(true)?;
        let (tx, rx) = channel();
        Ok(Self { tx, rx, bell, ringer, subscribers: Vec::new() })
    }

    /// Subscribes to `key`; its samples come out of [`Mailbox::next`].
    pub fn subscribe(&mut self, session: &zenoh::Session, key: &str) -> anyhow::Result<()> {
        let (tx, ringer) = (self.tx.clone(), self.ringer.try_clone()?);
        let sub = session
            .declare_subscriber(key.to_owned())
            .callback(move |sample| {
                let a = Arrived {
                    key: sample.key_expr().as_str().to_owned(),
                    payload: sample.payload().clone(),
                    attachment: sample.attachment().map(|a| a.to_bytes().into_owned()),
                };
                if tx.send(a).is_ok() {
                    // A full socket already holds a wake-up.
                    let _ = (&ringer).write(&[1]);
                }
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {key} on Zenoh: {e}"))?;
        self.subscribers.push(sub);
        Ok(())
    }

    /// What to attach to the bus thread's waiter.
    pub fn bell(&self) -> &UnixStream {
        &self.bell
    }

    /// The next queued sample, if any; silences the bell first, so a sample queued after the
    /// queue is found empty rings it again.
    pub fn next(&self) -> Option<Arrived> {
        let mut buf = [0u8; 256];
        while matches!((&self.bell).read(&mut buf), Ok(n) if n > 0) {}
        self.rx.try_recv().ok()
    }
}

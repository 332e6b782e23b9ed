//! The clock chain carried across two hosts (`docs/zenoh.md`). On the main host the bridge is a
//! party standing in for the other host's services at their place in the chain: at its turn
//! for tick T it sends everything the main host's services published since its last turn,
//! closed by T, waits for the other host's share of T, publishes it, and passes the turn on. On
//! the other host the bridge is the clock master: it publishes what came, starts the tick, waits
//! for its chain's tail and sends back what its services published. Each direction is one key on
//! one publisher, so a tick's messages and its progress arrive together and in order; what the
//! bridge itself published is known by its publishers and never sent back. In real time there
//! are no turns: each side sends what its services publish as it comes (`run_live`).

use std::time::{Duration, Instant};

use harvey_bus::{Bus, FdSource, Lockstep, Waiter, Wake};
use harvey_runtime::taps::Tap;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;

use crate::bundle::{self, Kind};
use crate::mailbox::Mailbox;
use crate::sinks::Sinks;
use crate::wire::{self, Meta};

/// How often a wait for the other host is reported.
const STALL_REPORT: Duration = Duration::from_secs(5);

/// The key from one host's bridge to the other's.
fn chain_key(namespace: &str, from: &str, to: &str) -> String {
    format!("{namespace}/@chain/v{}/{from}/{to}", wire::LAYOUT)
}

/// The liveliness token of a bridge whose chain has started.
fn ready_key(namespace: &str, host: &str) -> String {
    format!("{namespace}/@chain/v{}/ready/{host}", wire::LAYOUT)
}

/// One host's end of the chain between two hosts.
pub struct Chain<'a> {
    pub bus: &'a Bus,
    pub taps: &'a [Box<dyn Tap>],
    pub sinks: &'a mut Sinks,
    peer: String,
    out: Publisher<'static>,
    inbox: Mailbox,
    /// What this host's services published since the last bundle went out.
    pending: bundle::Writer,
}

impl<'a> Chain<'a> {
    pub fn new(
        session: &zenoh::Session,
        namespace: &str,
        (host, peer): (&str, &str),
        bus: &'a Bus,
        taps: &'a [Box<dyn Tap>],
        sinks: &'a mut Sinks,
    ) -> anyhow::Result<Self> {
        let key = chain_key(namespace, host, peer);
        let out = session
            .declare_publisher(key.clone())
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot publish {key} on Zenoh: {e}"))?;
        let mut inbox = Mailbox::new()?;
        inbox.subscribe(session, &chain_key(namespace, peer, host))?;
        Ok(Self { bus, taps, sinks, peer: peer.to_owned(), out, inbox, pending: bundle::Writer::new() })
    }

    /// What rings when the other host's bundle arrives.
    pub fn bell(&self) -> &std::os::unix::net::UnixStream {
        self.inbox.bell()
    }

    /// Sends what is pending and the messages queued on the taps stamped at most `until_ns`,
    /// closed by `kind`.
    fn send(&mut self, kind: Kind, until_ns: u64) -> anyhow::Result<()> {
        self.collect(until_ns)?;
        let bundle = self.pending.finish(kind);
        self.out.put(bundle).wait().map_err(|e| anyhow::anyhow!("sending to host {}: {e}", self.peer))
    }

    /// Adds the messages queued on the taps stamped at most `until_ns` to what is pending, but
    /// for those this bridge published itself (what came from the other host).
    fn collect(&mut self, until_ns: u64) -> anyhow::Result<()> {
        let own = self.sinks.origins();
        let (w, mut failed) = (&mut self.pending, None);
        for tap in self.taps {
            let fingerprint = wire::fingerprint(tap.def());
            tap.take_owned(&|from| own.contains(&from), &mut |seq, stamp_ns, cdr| {
                if stamp_ns <= until_ns && failed.is_none() {
                    let meta = Meta { seq, stamp_ns, fingerprint };
                    failed = w.push(tap.topic(), &meta, &cdr).err();
                }
            })?;
        }
        failed.map_or(Ok(()), Err)
    }

    /// Says this host's bridge is up (a liveliness token the other host's bridge waits for).
    pub fn declare_ready(
        &self,
        session: &zenoh::Session,
        namespace: &str,
        host: &str,
    ) -> anyhow::Result<LivelinessToken> {
        session
            .liveliness()
            .declare_token(ready_key(namespace, host))
            .wait()
            .map_err(|e| anyhow::anyhow!("declaring this host ready on Zenoh: {e}"))
    }

    /// In real time: whatever this host's services publish goes to the other host as it comes,
    /// and what comes is published here, until the main host ends the launch (a `Live` bundle
    /// per wake-up; the order of each topic's messages is kept). The main host's bridge tells
    /// the other it ends when it is stopped.
    pub fn run_live(&mut self, main_side: bool) -> anyhow::Result<()> {
        let waiter = Waiter::new()?;
        let bell = FdSource::new(self.inbox.bell())?;
        let mut attached = vec![waiter.attach(&bell)?];
        for t in self.taps {
            attached.push(waiter.attach(t.waitable())?);
        }
        loop {
            if waiter.wait(Some(STALL_REPORT))? == Wake::Shutdown {
                if main_side {
                    self.end()?;
                }
                return Ok(());
            }
            self.collect(u64::MAX)?;
            if !self.pending.is_empty() {
                let bundle = self.pending.finish(Kind::Live);
                self.out
                    .put(bundle)
                    .wait()
                    .map_err(|e| anyhow::anyhow!("sending to host {}: {e}", self.peer))?;
            }
            while let Some(a) = self.inbox.next() {
                if self.publish(&a.payload.to_bytes())? == Kind::End {
                    return Ok(());
                }
            }
        }
    }

    /// Waits for the other host's next bundle; `None` if this process is asked to stop first.
    fn receive(&self, waiter: &Waiter, waiting_for: &str) -> anyhow::Result<Option<zenoh::bytes::ZBytes>> {
        let since = Instant::now();
        loop {
            if let Some(a) = self.inbox.next() {
                return Ok(Some(a.payload));
            }
            match waiter.wait(Some(STALL_REPORT))? {
                Wake::Shutdown => return Ok(None),
                Wake::Timeout => tracing::warn!(
                    host = self.peer,
                    waited_s = since.elapsed().as_secs(),
                    "waiting for host {} ({waiting_for})",
                    self.peer
                ),
                Wake::Ready => {}
            }
        }
    }

    /// Publishes a bundle's messages on the bus (the taps will skip them: their publishers are
    /// this bridge's). What this host's services published before (outside the chain's turns:
    /// a standing request made at start-up) is kept for the next bundle first.
    fn publish(&mut self, payload: &[u8]) -> anyhow::Result<Kind> {
        let (kind, items) =
            bundle::read(payload).map_err(|e| anyhow::anyhow!("from host {}: {e}", self.peer))?;
        self.collect(u64::MAX)?;
        for item in &items {
            let sink = self.sinks.get(self.bus, item.topic)?;
            anyhow::ensure!(
                sink.fingerprint() == item.meta.fingerprint,
                "host {} sends {} of another message definition ({:08x}, this build's {:08x}): another Harvey version",
                self.peer,
                item.topic,
                item.meta.fingerprint,
                sink.fingerprint()
            );
            sink.publish(&item.meta, item.cdr)
                .map_err(|e| anyhow::anyhow!("{} from host {}: {e}", item.topic, self.peer))?;
        }
        Ok(kind)
    }

    /// The stand-in's turn for `tick`: this host's messages out, the other host's in. False if
    /// asked to stop while waiting.
    pub fn stand_in_turn(&mut self, waiter: &Waiter, tick: u64) -> anyhow::Result<bool> {
        self.send(Kind::Tick(tick), tick)?;
        let Some(reply) = self.receive(waiter, &format!("its share of tick {:.3} s", tick as f64 / 1e9))?
        else {
            return Ok(false);
        };
        match self.publish(&reply.to_bytes())? {
            Kind::Tick(t) if t == tick => Ok(true),
            other => anyhow::bail!("host {} answered tick {tick} with {other:?}", self.peer),
        }
    }

    /// Tells the other host the launch is ending.
    pub fn end(&mut self) -> anyhow::Result<()> {
        self.send(Kind::End, 0)
    }

    /// The other host's clock master: until the main host ends the launch (or this process is
    /// stopped), each tick that comes is published, run through this host's chain and answered.
    pub fn run_segment(
        &mut self,
        session: &zenoh::Session,
        namespace: &str,
        host: &str,
        lockstep: &Lockstep,
    ) -> anyhow::Result<()> {
        let waiter = Waiter::new()?;
        let bell = FdSource::new(self.inbox.bell())?;
        let _a = (waiter.attach(lockstep.predecessor())?, waiter.attach(&bell)?);
        // The supervisor starts the chain once every service here is ready (tick 0 of the tail).
        let mut done: Option<u64> = None;
        while done.is_none() {
            if waiter.wait(Some(STALL_REPORT))? == Wake::Shutdown {
                return Ok(());
            }
            lockstep.finished(|t| done = Some(t))?;
        }
        let _ready = self.declare_ready(session, namespace, host)?;
        loop {
            let Some(payload) = self.receive(&waiter, "the next tick")? else { return Ok(()) };
            let tick = match self.publish(&payload.to_bytes())? {
                Kind::End => return Ok(()),
                Kind::Tick(t) => t,
                Kind::Live => anyhow::bail!(
                    "host {} runs in real time, this host deterministic: start both shares with --realtime or both without",
                    self.peer
                ),
            };
            lockstep.finish(tick)?;
            let since = Instant::now();
            while done.is_none_or(|d| d < tick) {
                match waiter.wait(Some(STALL_REPORT))? {
                    Wake::Shutdown => return Ok(()),
                    Wake::Timeout => tracing::warn!(
                        waited_s = since.elapsed().as_secs(),
                        "this host's chain has not finished tick {tick}"
                    ),
                    Wake::Ready => {}
                }
                lockstep.finished(|t| done = Some(done.map_or(t, |d| d.max(t))))?;
            }
            self.send(Kind::Tick(tick), tick)?;
        }
    }
}

/// Waits (at most `wait`) until the other host's bridge has started its chain, or names it.
pub fn await_peer(
    session: &zenoh::Session,
    namespace: &str,
    peer: &str,
    wait: Duration,
) -> anyhow::Result<()> {
    let key = ready_key(namespace, peer);
    let start = Instant::now();
    loop {
        if !crate::peers::live_keys(session, &key)?.is_empty() {
            return Ok(());
        }
        anyhow::ensure!(
            start.elapsed() < wait,
            "host {peer} never joined within {} s: start its share (`harvey launch FILE --host {peer}` with \
             --zenoh-connect or --zenoh-listen pointing here)",
            wait.as_secs()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

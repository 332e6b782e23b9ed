//! The clock chain carried across two hosts (`docs/zenoh.md`). On the main host the bridge is a
//! party standing in for the other host's services at their place in the chain: at its turn
//! for tick T it sends everything the main host's services published since its last turn,
//! closed by T, waits for the other host's share of T, publishes it, and passes the turn on. On
//! the other host the bridge is the clock master: it publishes what came, starts the tick, waits
//! for its chain's tail and sends back what its services published. Each direction is one key on
//! one publisher, so a tick's messages and its progress arrive together and in order; what the
//! bridge itself published is known by its publishers and never sent back. In real time there
//! are no turns: each side sends what its services publish as it comes (`run_live`).
//!
//! Either bridge may be killed and restarted mid-launch ([`Keep`]): the main host's sends the
//! tick it was in again, and the other host's answers a tick it answered before from the answer
//! it kept; the other host's asks for the tick under way again (`Kind::Resync`), which may have
//! gone while nobody listened. A tick's messages taken or published before the kill are not
//! sent or published twice, so the recording is the one without the kill.

use std::time::{Duration, Instant};

use harvey_bus::{Bus, Waiter, Wake};
use harvey_runtime::taps::Tap;
use zenoh::Wait;
use zenoh::pubsub::Publisher;
use zenoh::qos::CongestionControl;

use crate::bundle::{self, Kind};
use crate::keep::{Keep, Ticks};
use crate::mailbox::Mailbox;
use crate::sinks::Sinks;
use crate::wire::{self, Meta};

/// How often a wait for the other host is reported.
pub(crate) const STALL_REPORT: Duration = Duration::from_secs(5);

/// The key from one host's bridge to the other's.
fn chain_key(namespace: &str, from: &str, to: &str) -> String {
    format!("{namespace}/@chain/v{}/{from}/{to}", wire::LAYOUT)
}

/// One host's end of the chain between two hosts.
pub struct Chain<'a> {
    pub bus: &'a Bus,
    pub taps: &'a [Box<dyn Tap>],
    pub sinks: &'a mut Sinks,
    pub(crate) peer: String,
    out: Publisher<'static>,
    pub(crate) inbox: Mailbox,
    /// What this host's services published since the last bundle went out.
    pending: bundle::Writer,
    pub(crate) keep: Keep,
    /// Whether the other host's bridge has been heard listening on the key to it; until then a
    /// bundle waits (at most `patience`), since one put before the sessions meet is lost.
    met: std::cell::Cell<bool>,
    patience: Duration,
    /// The messages of the answer a predecessor kept (the other host), until the next bundle:
    /// never sent again, though the taps may hand them over before the checkpoint knew them taken.
    answered: Vec<(String, u64, u64)>,
    /// The supervisor's requests to re-offer to a restarted party of this host, served while
    /// the bridge waits (it publishes what came from the other host, which that party needs).
    reoffers: std::rc::Rc<harvey_bus::Reoffers>,
}

impl<'a> Chain<'a> {
    pub fn new(
        session: &zenoh::Session,
        namespace: &str,
        (host, peer, patience): (&str, &str, Duration),
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
        let keep = Keep::from_env()?;
        Ok(Self {
            bus,
            taps,
            sinks,
            peer: peer.to_owned(),
            out,
            inbox,
            pending: bundle::Writer::new(),
            keep,
            met: std::cell::Cell::new(false),
            patience,
            answered: Vec::new(),
            reoffers: bus.reoffers(),
        })
    }

    /// What rings when the supervisor asks this process to re-offer (attach it to the waiters
    /// the bridge waits on: [`Chain::receive`] serves it).
    pub fn reoffer_bell(&self) -> std::rc::Rc<harvey_bus::Reoffers> {
        self.reoffers.clone()
    }

    /// Answers the supervisor's pending re-offer requests.
    pub(crate) fn serve_reoffers(&self) -> anyhow::Result<()> {
        self.reoffers.serve()?;
        Ok(())
    }

    /// What rings when the other host's bundle arrives.
    pub fn bell(&self) -> &std::os::unix::net::UnixStream {
        self.inbox.bell()
    }

    /// What is pending and the messages queued on the taps stamped at most `until_ns`, closed
    /// by `kind`, as a bundle.
    pub(crate) fn bundle(&mut self, kind: Kind, until_ns: u64) -> anyhow::Result<zenoh::bytes::ZBytes> {
        self.collect(until_ns)?;
        self.keep.bundle_left();
        self.answered.clear();
        Ok(self.pending.finish(kind).into())
    }

    /// Puts a bundle (or a copy of one: Zenoh's bytes are shared, not copied) on the key to the
    /// other host, once its bridge has been heard listening there.
    pub(crate) fn put(&self, bundle: zenoh::bytes::ZBytes) -> anyhow::Result<()> {
        self.heard()?;
        self.out.put(bundle).wait().map_err(|e| anyhow::anyhow!("sending to host {}: {e}", self.peer))
    }

    /// Waits until the other host's bridge subscribes to the key to it (once: a bridge that
    /// restarts later asks for what it missed), or names it after `patience`.
    fn heard(&self) -> anyhow::Result<()> {
        let since = Instant::now();
        while !self.met.get() {
            let status = self.out.matching_status().wait();
            let matching = status.map_err(|e| anyhow::anyhow!("asking Zenoh who listens: {e}"))?.matching();
            self.met.set(matching);
            anyhow::ensure!(
                matching || since.elapsed() < self.patience,
                "host {}'s bridge has not listened within {} s",
                self.peer,
                self.patience.as_secs()
            );
            if !matching {
                std::thread::sleep(Duration::from_millis(5));
            }
        }
        Ok(())
    }

    /// Whether this host's services published anything since the last bundle (taken now).
    pub(crate) fn has_news(&mut self) -> anyhow::Result<bool> {
        self.collect(u64::MAX)?;
        Ok(!self.pending.is_empty())
    }

    /// Adds the messages queued on the taps stamped at most `until_ns` to what is pending, but
    /// for those this bridge published itself (what came from the other host) and those a
    /// predecessor took before it was killed.
    fn collect(&mut self, until_ns: u64) -> anyhow::Result<()> {
        let own = self.sinks.origins();
        let (w, keep, mut failed) = (&mut self.pending, &mut self.keep, None);
        let answered = &self.answered;
        for tap in self.taps {
            let fingerprint = wire::fingerprint(tap.def());
            let again =
                |seq, stamp| answered.iter().any(|(t, q, s)| (*q, *s) == (seq, stamp) && t == tap.topic());
            tap.take_owned(&|from| own.contains(&from), &mut |from, seq, stamp_ns, cdr| {
                if stamp_ns <= until_ns
                    && failed.is_none()
                    && keep.fresh(tap.topic(), from, stamp_ns, seq)
                    && !again(seq, stamp_ns)
                {
                    let meta = Meta { seq, stamp_ns, fingerprint };
                    failed = w.push(tap.topic(), &meta, &cdr).err();
                }
            })?;
        }
        failed.map_or(Ok(()), Err)
    }

    /// Waits for the other host's next bundle, sending `again` every few seconds meanwhile;
    /// `None` if this process is asked to stop first.
    pub(crate) fn receive(
        &self,
        waiter: &Waiter,
        waiting_for: &str,
        again: &zenoh::bytes::ZBytes,
    ) -> anyhow::Result<Option<zenoh::bytes::ZBytes>> {
        let since = Instant::now();
        loop {
            if let Some(a) = self.inbox.next() {
                return Ok(Some(a.payload));
            }
            let wake = waiter.wait(Some(STALL_REPORT))?;
            self.serve_reoffers()?;
            match wake {
                Wake::Shutdown => return Ok(None),
                Wake::Timeout => {
                    tracing::warn!(
                        host = self.peer,
                        waited_s = since.elapsed().as_secs(),
                        "waiting for host {} ({waiting_for}): asking again",
                        self.peer
                    );
                    // What was last sent goes again: every bundle can be taken twice, and one
                    // lost while a link came back would otherwise hold both hosts for good.
                    self.put(again.clone())?;
                }
                Wake::Ready => {}
            }
        }
    }
    /// Notes the messages of the answer a predecessor kept, not to send them again.
    pub(crate) fn answered(&mut self, bundle: &[u8]) -> anyhow::Result<()> {
        let (_, items) = bundle::read(bundle).map_err(|e| anyhow::anyhow!("the answer kept: {e}"))?;
        self.answered.clear();
        self.answered.extend(items.iter().map(|i| (i.topic.to_owned(), i.meta.seq, i.meta.stamp_ns)));
        Ok(())
    }

    /// Reads a bundle from the other host.
    pub(crate) fn read<'p>(&self, payload: &'p [u8]) -> anyhow::Result<(Kind, Vec<bundle::Item<'p>>)> {
        bundle::read(payload).map_err(|e| anyhow::anyhow!("from host {}: {e}", self.peer))
    }

    /// Publishes a bundle's messages on the bus (the taps will skip them: their publishers are
    /// this bridge's), but for those of the bundle for `tick` a killed predecessor published. What
    /// this host's services published before (outside the chain's turns: a standing request made
    /// at start-up) is kept for the next bundle first.
    pub(crate) fn publish(&mut self, tick: Option<u64>, items: &[bundle::Item]) -> anyhow::Result<()> {
        self.collect(u64::MAX)?;
        for (i, item) in items.iter().enumerate() {
            if tick.is_some_and(|t| !self.keep.due(t, i)) {
                continue;
            }
            let sink = self.sinks.get(self.bus, item.topic)?;
            anyhow::ensure!(
                sink.fingerprint() == item.meta.fingerprint,
                "host {} sends {} of another message definition ({:08x}, this build's {:08x}): another Harvey version",
                self.peer,
                item.topic,
                item.meta.fingerprint,
                sink.fingerprint()
            );
            sink.publish(&item.meta, &[item.cdr])
                .map_err(|e| anyhow::anyhow!("{} from host {}: {e}", item.topic, self.peer))?;
            if let Some(t) = tick {
                self.keep.published(t, i)?;
            }
        }
        Ok(())
    }

    /// The stand-in's turn for `tick`: this host's messages out, the other host's in. False if
    /// asked to stop while waiting. An answer to an earlier tick is one already published, sent
    /// again by a restarted bridge on the other host; when that bridge asks for the tick after
    /// its last, the tick goes again.
    pub fn stand_in_turn(&mut self, waiter: &Waiter, tick: u64) -> anyhow::Result<bool> {
        let sent = self.bundle(Kind::Tick(tick), tick)?;
        self.put(sent.clone())?;
        let waiting_for = format!("its share of tick {:.3} s", tick as f64 / 1e9);
        loop {
            let Some(reply) = self.receive(waiter, &waiting_for, &sent)? else { return Ok(false) };
            let bytes = reply.to_bytes();
            match self.read(&bytes)? {
                (Kind::Tick(t), items) if t == tick => {
                    self.publish(Some(tick), &items)?;
                    self.keep.save(Ticks { done: tick, started: None })?;
                    return Ok(true);
                }
                (Kind::Tick(t), _) if t < tick => {
                    tracing::debug!(tick = t, "an answer published before, again")
                }
                (Kind::Resync(done), _) if done < tick => {
                    tracing::warn!(
                        host = self.peer,
                        "host {}'s bridge was restarted after tick {:.3} s: tick {:.3} s sent again",
                        self.peer,
                        done as f64 / 1e9,
                        tick as f64 / 1e9
                    );
                    self.put(sent.clone())?;
                }
                (Kind::Resync(_), _) => {}
                (other, _) => anyhow::bail!("host {} answered tick {tick} with {other:?}", self.peer),
            }
        }
    }

    /// Tells the other host the launch is ending.
    pub fn end(&mut self) -> anyhow::Result<()> {
        let b = self.bundle(Kind::End, 0)?;
        self.put(b)
    }
}

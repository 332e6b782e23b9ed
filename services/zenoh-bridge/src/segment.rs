//! The other host's end of the clock chain across two hosts (`docs/zenoh.md`): the clock master
//! of this host's chain. Until the main host ends the launch (or this process is stopped), each
//! tick that comes is published, run through this host's chain and answered. Restarted
//! mid-launch ([`crate::keep`]), it finishes the tick its predecessor had started, sends the
//! last answer again and asks for the tick after it (it may have come while nobody listened); a
//! tick asked for again is answered from the answer kept.

use std::time::Instant;

use harvey_bus::{FdSource, Lockstep, Waiter, Wake};
use zenoh::bytes::ZBytes;

use crate::bundle::{self, Kind};
use crate::chain::{Chain, STALL_REPORT};
use crate::keep::Ticks;

/// The segment's place: where the chain stands and the last answer sent.
struct Place {
    ticks: Ticks,
    answer: Option<(u64, ZBytes)>,
    /// The newest tick this host's chain has finished (its tail's progress).
    tail: Option<u64>,
}

impl Chain<'_> {
    pub fn run_segment(
        &mut self,
        session: &zenoh::Session,
        namespace: &str,
        host: &str,
        lockstep: &Lockstep,
    ) -> anyhow::Result<()> {
        let waiter = Waiter::new()?;
        let bell = FdSource::new(self.inbox.bell())?;
        let reoffers = self.reoffer_bell();
        let _a = (waiter.attach(lockstep.predecessor())?, waiter.attach(&bell)?, waiter.attach(&*reoffers)?);
        let kept = self.keep.last_answer()?;
        if let Some((_, b)) = &kept {
            self.answered(b)?;
        }
        let answer = kept.map(|(t, b)| (t, ZBytes::from(b)));
        let mut at = Place { ticks: self.keep.ticks(), answer, tail: None };
        let resumed = self.keep.resumed();
        // The supervisor starts the chain once every service here is ready (tick 0 of the tail).
        if !resumed {
            if !self.await_tail(&waiter, lockstep, &mut at, 0)? {
                return Ok(());
            }
            // From here on a successor is a restart: it asks for the tick under way.
            self.keep.save(at.ticks)?;
        }
        let _ready = crate::peers::declare_ready(session, namespace, host)?;
        if resumed && !self.rejoin(&waiter, lockstep, &mut at)? {
            return Ok(());
        }
        loop {
            let again = bundle::Writer::new().finish(Kind::Resync(at.ticks.done)).into();
            let Some(payload) = self.receive(&waiter, "the next tick", &again)? else { return Ok(()) };
            let bytes = payload.to_bytes();
            let (kind, items) = self.read(&bytes)?;
            let tick = match kind {
                Kind::End => return Ok(()),
                Kind::Tick(t) if t <= at.ticks.done => {
                    self.answer_again(t, &at)?;
                    continue;
                }
                Kind::Tick(t) => t,
                // Only this side asks so; the main host's bridge, restarted, sends its tick again.
                Kind::Resync(_) => continue,
                Kind::Live => anyhow::bail!(
                    "host {} runs in real time, this host deterministic: start both shares with --realtime or both without",
                    self.peer
                ),
            };
            self.publish(Some(tick), &items)?;
            lockstep.finish(tick)?;
            at.ticks.started = Some(tick);
            self.keep.save(at.ticks)?;
            if !self.await_tail(&waiter, lockstep, &mut at, tick)? {
                return Ok(());
            }
            self.answer(tick, &mut at)?;
        }
    }

    /// After a restart: the tick under way finished and answered (unless its answer was kept
    /// already), the last answer sent again, and the tick after it asked for. False if asked to
    /// stop first.
    fn rejoin(&mut self, waiter: &Waiter, lockstep: &Lockstep, at: &mut Place) -> anyhow::Result<bool> {
        if let (Some(s), Some((a, _))) = (at.ticks.started, &at.answer)
            && s <= *a
        {
            at.ticks = Ticks { done: *a, started: None };
        }
        if let Some(s) = at.ticks.started {
            if !self.await_tail(waiter, lockstep, at, s)? {
                return Ok(false);
            }
            self.answer(s, at)?;
        } else if let Some((a, b)) = &at.answer
            && *a == at.ticks.done
        {
            self.put(b.clone())?;
        }
        tracing::warn!(
            host = self.peer,
            "restarted: asking host {} for the tick after {:.3} s",
            self.peer,
            at.ticks.done as f64 / 1e9
        );
        self.put(bundle::Writer::new().finish(Kind::Resync(at.ticks.done)).into())?;
        Ok(true)
    }

    /// Sends this host's share of `tick`, kept first.
    fn answer(&mut self, tick: u64, at: &mut Place) -> anyhow::Result<()> {
        let b = self.bundle(Kind::Tick(tick), tick)?;
        self.keep.keep_answer(tick, &b.to_bytes())?;
        at.ticks = Ticks { done: tick, started: None };
        self.keep.save(at.ticks)?;
        self.put(b.clone())?;
        at.answer = Some((tick, b));
        Ok(())
    }

    /// The main host asks for a tick answered before (its bridge was restarted in that tick).
    fn answer_again(&self, tick: u64, at: &Place) -> anyhow::Result<()> {
        match &at.answer {
            Some((a, b)) if *a == tick => {
                tracing::info!(
                    host = self.peer,
                    tick_ms = tick / 1_000_000,
                    "a tick answered before, asked for again"
                );
                self.put(b.clone())
            }
            // A copy of an earlier request, sent again while the answer was on its way.
            _ if tick < at.ticks.done => Ok(()),
            _ => anyhow::bail!(
                "host {} asks for tick {:.3} s again, whose answer is not kept here (both bridges restarted within one tick?)",
                self.peer,
                tick as f64 / 1e9
            ),
        }
    }

    /// Waits until this host's chain has finished `tick`. False if asked to stop first.
    fn await_tail(
        &self,
        waiter: &Waiter,
        lockstep: &Lockstep,
        at: &mut Place,
        tick: u64,
    ) -> anyhow::Result<bool> {
        let since = Instant::now();
        loop {
            lockstep.finished(|t| at.tail = Some(at.tail.map_or(t, |d| d.max(t))))?;
            if at.tail.is_some_and(|d| d >= tick) {
                return Ok(true);
            }
            let wake = waiter.wait(Some(STALL_REPORT))?;
            self.serve_reoffers()?;
            match wake {
                Wake::Shutdown => return Ok(false),
                Wake::Timeout => tracing::warn!(
                    waited_s = since.elapsed().as_secs(),
                    "this host's chain has not finished tick {:.3} s",
                    tick as f64 / 1e9
                ),
                Wake::Ready => {}
            }
        }
    }
}

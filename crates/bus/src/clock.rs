//! Pacing a service: on its inputs (real-time mode), or on its turn in the clock chain
//! (deterministic mode).
//!
//! Deterministic mode orders the parties of a launch in a ring, starting at the clock master.
//! For each tick every party waits until its predecessor reports, on its progress topic
//! `clock/<predecessor>`, that it has finished the tick; it then drains its inputs, publishes its
//! outputs and reports in turn. When the last party (the tail) reports, the master starts the
//! next tick. Only one party works at a time and iceoryx2 delivers at send time, so every party
//! sees exactly the same inputs on every run, whatever the machine's speed: the outputs are
//! byte-identical run after run.
//!
//! The supervisor hands each party its place through the environment ([`CLOCK_ENV`],
//! [`PARTY_ENV`], [`AFTER_ENV`]), starts the chain once all are ready by reporting tick 0 for the
//! tail, and resumes it after a restart.

use core::cell::{Cell, RefCell};
use core::time::Duration;
use std::collections::VecDeque;

use harvey_msgs::{Header, Progress, topics};

use crate::{Attachment, Bus, Publisher, Result, Subscriber, Waitable, Waiter, Wake};

/// `lockstep` (deterministic mode) or `realtime`.
pub const CLOCK_ENV: &str = "HARVEY_CLOCK";
/// This service's name as a clock party.
pub const PARTY_ENV: &str = "HARVEY_CLOCK_PARTY";
/// The party whose progress starts this party's turns (for the master: the tail).
pub const AFTER_ENV: &str = "HARVEY_CLOCK_AFTER";

/// True when the launch runs in deterministic mode.
pub fn lockstep_from_env() -> bool {
    std::env::var(CLOCK_ENV).is_ok_and(|v| v == "lockstep")
}

/// One party's place in the clock chain: its predecessor's progress in, its own out.
pub struct Lockstep {
    party: String,
    after: Subscriber<Progress>,
    me: Publisher<Progress>,
    turns: Cell<u64>,
}

impl Lockstep {
    pub fn new(bus: &Bus, party: &str, after: &str) -> Result<Self> {
        Ok(Self {
            party: party.to_owned(),
            after: bus.subscriber(topics::clock_progress(after))?,
            me: bus.publisher(topics::clock_progress(party))?,
            turns: Cell::new(0),
        })
    }

    /// The party the environment names, if the launch is deterministic and this service is a
    /// party of it.
    pub fn from_env(bus: &Bus) -> Result<Option<Self>> {
        if !lockstep_from_env() {
            return Ok(None);
        }
        match (std::env::var(PARTY_ENV), std::env::var(AFTER_ENV)) {
            (Ok(party), Ok(after)) => Self::new(bus, &party, &after).map(Some),
            _ => Ok(None),
        }
    }

    pub fn party(&self) -> &str {
        &self.party
    }

    /// The predecessor's progress, to attach to a [`Waiter`].
    pub fn predecessor(&self) -> &Subscriber<Progress> {
        &self.after
    }

    /// Hands `f` the stamp of every tick the predecessor finished since the last call, oldest
    /// first.
    pub fn finished(&self, mut f: impl FnMut(u64)) -> Result<usize> {
        self.after.drain(|p| f(p.header.stamp_ns))
    }

    /// Reports that this party has finished every tick up to `stamp_ns`.
    pub fn finish(&self, stamp_ns: u64) -> Result<()> {
        self.turns.set(self.turns.get() + 1);
        self.me.send(&Progress { header: Header::new(self.turns.get(), stamp_ns) })?;
        Ok(())
    }
}

/// What a service does next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Drain the inputs and work. In deterministic mode, the tick whose turn it is.
    Go(Option<u64>),
    /// The timeout passed with nothing to do.
    Idle,
    /// SIGINT or SIGTERM, and no turn is left: finish up and exit.
    Stop,
}

/// How a service paces its loop.
pub struct Pace {
    lockstep: Option<Lockstep>,
    /// Deterministic mode: the supervisor's requests to re-offer to a restarted party.
    reoffers: Option<std::rc::Rc<crate::Reoffers>>,
    pending: RefCell<VecDeque<u64>>,
    /// The latest tick taken into `pending`: a report of it or an earlier one again is dropped.
    latest: Cell<Option<u64>>,
    current: Cell<Option<u64>>,
    stopping: Cell<bool>,
}

impl Pace {
    /// Deterministic if the environment makes this service a clock party, else real time.
    pub fn from_env(bus: &Bus) -> Result<Self> {
        let mut pace = Self::with(Lockstep::from_env(bus)?);
        if pace.lockstep.is_some() {
            pace.reoffers = Some(bus.reoffers());
        }
        Ok(pace)
    }

    pub fn with(lockstep: Option<Lockstep>) -> Self {
        Self {
            lockstep,
            reoffers: None,
            pending: RefCell::new(VecDeque::new()),
            latest: Cell::new(None),
            current: Cell::new(None),
            stopping: Cell::new(false),
        }
    }

    pub fn lockstep(&self) -> Option<&Lockstep> {
        self.lockstep.as_ref()
    }

    /// Attaches what wakes this service: its inputs in real time, its predecessor's progress in
    /// deterministic mode (the inputs are drained on each turn, and need not wake it).
    pub fn attach<'w, 'a>(
        &'a self,
        waiter: &'w Waiter,
        inputs: &[&'a dyn Waitable],
    ) -> Result<Vec<Attachment<'w, 'a>>> {
        match &self.lockstep {
            Some(l) => {
                let mut a = vec![waiter.attach(l.predecessor())?];
                if let Some(r) = &self.reoffers {
                    a.push(waiter.attach(r.as_ref())?);
                }
                Ok(a)
            }
            None => inputs.iter().map(|i| waiter.attach(*i)).collect(),
        }
    }

    /// Sleeps until there is work, the timeout passes, or the service must stop. In
    /// deterministic mode a stop request still lets the turns already granted run first.
    pub fn next(&self, waiter: &Waiter, timeout: Option<Duration>) -> Result<Step> {
        let Some(l) = &self.lockstep else {
            return Ok(match waiter.wait(timeout)? {
                Wake::Ready => Step::Go(None),
                Wake::Timeout => Step::Idle,
                Wake::Shutdown => Step::Stop,
            });
        };
        loop {
            if let Some(t) = self.pending.borrow_mut().pop_front() {
                self.current.set(Some(t));
                return Ok(Step::Go(Some(t)));
            }
            if self.stopping.get() {
                return Ok(Step::Stop);
            }
            let wake = waiter.wait(timeout)?;
            if let Some(r) = &self.reoffers {
                r.serve()?;
            }
            // A tick is run once, however often it is reported: a restarted predecessor may
            // report again a tick it had reported before it died (its checkpoint a tick behind),
            // and a second turn for it would drain the next tick's inputs early.
            l.finished(|t| {
                if self.latest.get().is_some_and(|latest| t <= latest) {
                    tracing::info!(party = l.party(), tick_ns = t, "a tick reported again: run once");
                } else {
                    self.latest.set(Some(t));
                    self.pending.borrow_mut().push_back(t);
                }
            })?;
            match wake {
                Wake::Shutdown => self.stopping.set(true),
                Wake::Timeout if self.pending.borrow().is_empty() => return Ok(Step::Idle),
                _ => {}
            }
        }
    }

    /// Ends the current turn: reports the tick done (deterministic mode; no-op in real time).
    pub fn done(&self) -> Result<()> {
        if let (Some(l), Some(t)) = (&self.lockstep, self.current.take()) {
            l.finish(t)?;
        }
        Ok(())
    }
}

//! The supervisor's side of deterministic mode: it starts the clock chain once every service is
//! ready, resumes it after a party restarts, and says which party holds it up when it stalls.

use std::time::{Duration, Instant};

use harvey_bus::{Bus, BusError, Publisher, ReofferRequests, Subscriber};
use harvey_msgs::{Header, Progress, topics};

/// How long the chain may stand still before the supervisor names the party it waits for, and
/// how often it says so again while the stall lasts.
const STALL_WARNING: Duration = Duration::from_secs(5);
/// How long the supervisor waits for every process to re-offer to a restarted party.
const REOFFER_TIMEOUT: Duration = Duration::from_secs(2);

struct Party {
    name: String,
    progress: Subscriber<Progress>,
    /// The supervisor's own port on the party's topic, to start or resume the chain.
    stand_in: Publisher<Progress>,
    last: Option<u64>,
}

/// Watches every party's progress.
pub struct ClockWatch {
    parties: Vec<Party>,
    moved_at: Instant,
    /// When the stall was last reported.
    warned_at: Option<Instant>,
    reoffers: ReofferRequests,
    _bus: Bus,
}

impl ClockWatch {
    /// `chain` is the parties in turn order, master first.
    pub fn new(prefix: &str, chain: &[String]) -> Result<Self, BusError> {
        let bus = Bus::join_with_prefix("harvey-supervisor", prefix)?;
        let parties = chain
            .iter()
            .map(|name| {
                let topic = topics::clock_progress(name);
                Ok(Party {
                    name: name.clone(),
                    progress: bus.subscriber(topic)?,
                    stand_in: bus.publisher(topic)?,
                    last: None,
                })
            })
            .collect::<Result<Vec<_>, BusError>>()?;
        let reoffers = ReofferRequests::new(&bus)?;
        Ok(Self { parties, moved_at: Instant::now(), warned_at: None, reoffers, _bus: bus })
    }

    /// Starts the chain: the tail "has finished" tick 0, so the master begins tick 1.
    pub fn start(&mut self) -> Result<(), BusError> {
        let Some(tail) = self.parties.last_mut() else { return Ok(()) };
        tail.stand_in.send(&Progress { header: Header::new(0, 0) })?;
        tail.last = Some(0);
        self.moved_at = Instant::now();
        tracing::info!(chain = ?self.parties.iter().map(|p| &p.name).collect::<Vec<_>>(), "deterministic clock started");
        Ok(())
    }

    /// Takes in the parties' progress; while the chain stands still, says every few seconds
    /// which party it waits for.
    pub fn poll(&mut self) -> Result<(), BusError> {
        for p in &mut self.parties {
            if let Some(m) = p.progress.latest()? {
                p.last = Some(m.header.stamp_ns);
                self.moved_at = Instant::now();
                self.warned_at = None;
            }
        }
        let due = self.warned_at.map_or(self.moved_at, |w| w) + STALL_WARNING;
        if Instant::now() >= due {
            self.warned_at = Some(Instant::now());
            let (waiting, tick) = self.holder();
            tracing::warn!(
                party = %waiting,
                tick_ms = tick / 1_000_000,
                "deterministic clock has not moved for {} s: waiting for `{waiting}`",
                self.moved_at.elapsed().as_secs()
            );
        }
        Ok(())
    }

    /// The party whose turn it is, and the last tick its predecessor finished.
    pub fn holder(&self) -> (&str, u64) {
        let newest = self.parties.iter().filter_map(|p| p.last).max().unwrap_or(0);
        let n = self.parties.len();
        for i in 0..n {
            let pred = self.parties[(i + n - 1) % n].last.unwrap_or(0);
            if self.parties[i].last.unwrap_or(0) < pred || (i == 0 && pred == newest) {
                return (&self.parties[i].name, pred);
            }
        }
        (&self.parties[0].name, newest)
    }

    /// After `party` restarted: if its predecessor finished a tick it had not, hand the restarted
    /// party that turn again (its earlier self took the notice with it). The clock master's turn
    /// is the tick the tail finished, which is the master's own last one: it gets that tick
    /// again whenever the tail has caught up with it (the master, the bridge, tells a repeat
    /// from news).
    ///
    /// First every other process (`others`, by pid) re-offers its publishers' newest messages,
    /// so that the restarted party finds the inputs of the tick it missed (`harvey_bus`'s
    /// `reoffer.rs`).
    pub fn resume(&mut self, party: &str, others: &[u32]) -> Result<(), BusError> {
        let n = self.reoffers.request()?;
        let (mut answered, since) = (Vec::new(), Instant::now());
        while others.iter().any(|p| !answered.contains(p)) && since.elapsed() < REOFFER_TIMEOUT {
            std::thread::sleep(Duration::from_millis(1));
            self.reoffers.answered(n, &mut answered)?;
        }
        let silent: Vec<&u32> = others.iter().filter(|p| !answered.contains(p)).collect();
        if !silent.is_empty() {
            tracing::warn!(
                party,
                ?silent,
                "processes did not re-offer to the restarted party within {} s",
                REOFFER_TIMEOUT.as_secs()
            );
        }
        self.poll()?;
        let n = self.parties.len();
        let Some(i) = self.parties.iter().position(|p| p.name == party) else { return Ok(()) };
        let pred = &self.parties[(i + n - 1) % n];
        let behind = |own: u64, t: u64| if i == 0 { own <= t } else { own < t };
        if let Some(t) = pred.last
            && self.parties[i].last.is_none_or(|own| behind(own, t))
        {
            pred.stand_in.send(&Progress { header: Header::new(0, t) })?;
            tracing::warn!(party, tick_ms = t / 1_000_000, "deterministic clock resumed after a restart");
        }
        Ok(())
    }
}

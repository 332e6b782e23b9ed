//! The restart policy, as pure state: fed with the times and outcomes of a service's exits, it
//! answers "restart at time T" or "give up". It reads no clock and starts nothing, so it is
//! tested with made-up instants.

use std::time::{Duration, Instant};

use serde::Deserialize;

/// When a service that exited is started again.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Restart {
    Never,
    OnFailure,
    Always,
}

/// Largest doubling of the first delay: `backoff_ms << 16`, before the cap.
const MAX_DOUBLINGS: usize = 16;

/// A service's restart rules, from its `[[service]]` table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestartRules {
    pub mode: Restart,
    /// More restarts than this within `window` give up.
    pub max_restarts: u32,
    pub window: Duration,
    /// Delay before the first restart in the window, doubling for each further one...
    pub backoff_ms: u64,
    /// ... up to this.
    pub backoff_max_ms: u64,
}

/// What to do after an exit or a failed start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// The mode does not restart after this exit.
    Stay,
    /// Restart at `at`, `delay` from now: restart number `attempt` within the window.
    Restart { at: Instant, delay: Duration, attempt: usize },
    /// More restarts within the window than the rules allow.
    GiveUp,
}

/// One service's restart state: its recent failures and the restart it waits for.
#[derive(Debug, Clone)]
pub struct RestartPolicy {
    rules: RestartRules,
    /// Times of the exits (and failed starts) that count towards the limit.
    failures: Vec<Instant>,
    restart_at: Option<Instant>,
}

impl RestartPolicy {
    pub fn new(rules: RestartRules) -> Self {
        Self { rules, failures: Vec::new(), restart_at: None }
    }

    pub fn rules(&self) -> &RestartRules {
        &self.rules
    }

    /// The service exited at `now`, successfully or not. Failures older than the window are
    /// forgotten; the delay is `backoff_ms` doubled once for each other failure in the window
    /// (at most 16 times), capped at `backoff_max_ms`.
    pub fn on_exit(&mut self, now: Instant, success: bool) -> Decision {
        let restart = match self.rules.mode {
            Restart::Never => false,
            Restart::OnFailure => !success,
            Restart::Always => true,
        };
        if !restart {
            return Decision::Stay;
        }
        let window = self.rules.window;
        self.failures.retain(|t| now.duration_since(*t) < window);
        self.failures.push(now);
        if self.exceeded() {
            return Decision::GiveUp;
        }
        let exp = (self.failures.len() - 1).min(MAX_DOUBLINGS) as u32;
        let delay = Duration::from_millis((self.rules.backoff_ms << exp).min(self.rules.backoff_max_ms));
        self.schedule(now, delay)
    }

    /// A restart at `now` failed (the service did not start or never became ready): it counts
    /// as a failure, without forgetting old ones, and the next try waits `backoff_max_ms`.
    pub fn on_failed_start(&mut self, now: Instant) -> Decision {
        self.failures.push(now);
        if self.exceeded() {
            return Decision::GiveUp;
        }
        self.schedule(now, Duration::from_millis(self.rules.backoff_max_ms))
    }

    /// Whether the pending restart is due at `now`; if so it is taken (answered once).
    pub fn take_due(&mut self, now: Instant) -> bool {
        let due = self.restart_at.is_some_and(|t| t <= now);
        if due {
            self.restart_at = None;
        }
        due
    }

    /// When the pending restart is due, if one is.
    pub fn next_restart(&self) -> Option<Instant> {
        self.restart_at
    }

    fn exceeded(&self) -> bool {
        self.failures.len() > self.rules.max_restarts as usize
    }

    fn schedule(&mut self, now: Instant, delay: Duration) -> Decision {
        let at = now + delay;
        self.restart_at = Some(at);
        Decision::Restart { at, delay, attempt: self.failures.len() }
    }
}

#[cfg(test)]
mod tests;

//! The simulated DRV's watchdog, as a real DRV has: when no frame has come from the host for
//! longer than its deadline of simulated time, the vehicle stops.

/// Counts simulated time since the host's last frame (a command, `SY` or `HB`).
#[derive(Debug)]
pub struct HostWatchdog {
    deadline_ms: u64,
    last_ms: Option<u64>,
}

impl HostWatchdog {
    pub fn new(deadline_ms: u64) -> Self {
        Self { deadline_ms, last_ms: None }
    }

    /// A frame from the host at simulated time `time_ms`.
    pub fn feed(&mut self, time_ms: u64) {
        self.last_ms = Some(time_ms);
    }

    /// Whether the host has been silent for the deadline at `time_ms`; never before its first
    /// frame (nothing moves before the host's first command).
    pub fn lapsed(&self, time_ms: u64) -> bool {
        self.last_ms.is_some_and(|t| time_ms.saturating_sub(t) >= self.deadline_ms)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_lapses_only_after_a_silence_as_long_as_its_deadline() {
        let mut w = HostWatchdog::new(200);
        assert!(!w.lapsed(10_000), "not before the first frame");
        w.feed(1_000);
        assert!(!w.lapsed(1_150));
        assert!(w.lapsed(1_200));
        w.feed(1_200);
        assert!(!w.lapsed(1_350));
    }
}

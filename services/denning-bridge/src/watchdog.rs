//! The bridge's safe stop (issue 20): a watchdog on the executive's heartbeat, kept in vehicle
//! time (the stamps of the DRV's reports), that asks for a stop when the executive has gone
//! silent for longer than its deadline.

/// The id of the stop the bridge sends when the executive's heartbeat lapses. The executive
/// numbers its commands from 1 up; the bridge's own stops take the top of the range.
pub const WATCHDOG_STOP_ID: u32 = u32::MAX;
/// The id of the stop the bridge sends as it shuts down.
pub const SHUTDOWN_STOP_ID: u32 = u32::MAX - 1;

/// Watches the executive's heartbeat (its status, or any command from it) against a deadline
/// of vehicle time. It counts from the first heartbeat only (the executive may start after the
/// vehicle), and asks for one stop per lapse; the next heartbeat re-arms it.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct Watchdog {
    deadline_ns: u64,
    /// The vehicle's time: the stamp of the latest DRV report.
    now_ns: u64,
    last_beat_ns: Option<u64>,
    tripped: bool,
}

impl Watchdog {
    pub fn new(deadline_ns: u64) -> Self {
        Self { deadline_ns, now_ns: 0, last_beat_ns: None, tripped: false }
    }

    /// The executive is alive now (at the vehicle time of the latest report).
    pub fn heartbeat(&mut self) {
        self.last_beat_ns = Some(self.now_ns);
        self.tripped = false;
    }

    /// The vehicle's clock has reached `stamp_ns` (a report's stamp). True when the executive's
    /// heartbeat has just lapsed: the vehicle must stop.
    pub fn on_vehicle_time(&mut self, stamp_ns: u64) -> bool {
        self.now_ns = self.now_ns.max(stamp_ns);
        if self.tripped || !self.lapsed() {
            return false;
        }
        self.tripped = true;
        true
    }

    /// Whether a heartbeat has come and the latest is older than the deadline.
    pub fn lapsed(&self) -> bool {
        self.last_beat_ns.is_some_and(|t| self.now_ns.saturating_sub(t) >= self.deadline_ns)
    }

    /// The vehicle's time in milliseconds, as the DRV counts it.
    pub fn now_ms(&self) -> u64 {
        self.now_ns / 1_000_000
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn nothing_fires_before_the_first_heartbeat() {
        let mut w = Watchdog::new(200 * MS);
        assert!((1..100).all(|k| !w.on_vehicle_time(k * 50 * MS)));
    }

    #[test]
    fn a_steady_heartbeat_keeps_it_quiet() {
        let mut w = Watchdog::new(200 * MS);
        for k in 1..100 {
            assert!(!w.on_vehicle_time(k * 50 * MS), "tick {k}");
            w.heartbeat();
        }
    }

    #[test]
    fn a_lapse_stops_once_and_a_new_heartbeat_rearms() {
        let mut w = Watchdog::new(200 * MS);
        w.on_vehicle_time(1_000 * MS);
        w.heartbeat();
        assert!(!w.on_vehicle_time(1_150 * MS));
        assert!(w.on_vehicle_time(1_200 * MS), "200 ms of silence");
        assert!(!w.on_vehicle_time(1_250 * MS), "one stop per lapse");
        assert!(w.lapsed());
        w.heartbeat();
        assert!(!w.lapsed() && !w.on_vehicle_time(1_300 * MS));
        assert!(w.on_vehicle_time(1_450 * MS));
        assert_eq!(w.now_ms(), 1_450);
    }
}

//! A topic's rate as `ros2 topic hz` reports it: the mean rate over a window of the latest
//! intervals between arrivals, with their shortest, longest and standard deviation.

use std::collections::VecDeque;
use std::time::Duration;

/// The latest arrival intervals.
pub struct Rate {
    window: usize,
    intervals: VecDeque<f64>,
    last: Option<Duration>,
}

/// What [`Rate::stats`] reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    pub rate_hz: f64,
    pub min_s: f64,
    pub max_s: f64,
    pub std_dev_s: f64,
    pub window: usize,
}

impl Rate {
    pub fn new(window: usize) -> Self {
        Self { window: window.max(1), intervals: VecDeque::new(), last: None }
    }

    /// A message arrived at `at` (any fixed origin).
    pub fn arrived(&mut self, at: Duration) {
        if let Some(last) = self.last.replace(at) {
            if self.intervals.len() == self.window {
                self.intervals.pop_front();
            }
            self.intervals.push_back(at.saturating_sub(last).as_secs_f64());
        }
    }

    /// The figures over the window; `None` before two arrivals.
    pub fn stats(&self) -> Option<Stats> {
        let n = self.intervals.len();
        if n == 0 {
            return None;
        }
        let mean = self.intervals.iter().sum::<f64>() / n as f64;
        let var = self.intervals.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / n as f64;
        let (min_s, max_s) =
            self.intervals.iter().fold((f64::MAX, 0f64), |(lo, hi), &d| (lo.min(d), hi.max(d)));
        let rate_hz = if mean > 0.0 { 1.0 / mean } else { f64::INFINITY };
        Some(Stats { rate_hz, min_s, max_s, std_dev_s: var.sqrt(), window: n })
    }
}

impl Stats {
    pub fn text(&self) -> String {
        format!(
            "average rate: {:.3}\n\tmin: {:.3}s max: {:.3}s std dev: {:.5}s window: {}",
            self.rate_hz, self.min_s, self.max_s, self.std_dev_s, self.window
        )
    }

    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "rate_hz": self.rate_hz, "min_s": self.min_s, "max_s": self.max_s,
            "std_dev_s": self.std_dev_s, "window": self.window,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twenty_hertz_with_one_late_message() {
        let mut r = Rate::new(4);
        assert_eq!(r.stats(), None);
        for ms in [0, 50, 100, 150, 200, 280] {
            r.arrived(Duration::from_millis(ms));
        }
        let s = r.stats().expect("stats");
        assert_eq!(s.window, 4, "the window keeps the latest four intervals");
        assert!((s.rate_hz - 1.0 / 0.0575).abs() < 1e-9, "{s:?}");
        assert!((s.min_s - 0.05).abs() < 1e-12 && (s.max_s - 0.08).abs() < 1e-12, "{s:?}");
        assert!(s.std_dev_s > 0.01 && s.std_dev_s < 0.02, "{s:?}");
    }
}

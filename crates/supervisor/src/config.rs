//! The launch file's tables: `[launch]` settings and each `[[service]]`, with their defaults.

use std::path::PathBuf;
use std::time::Duration;

use serde::Deserialize;
use toml::Spanned;

pub use crate::launch_file::{LaunchError, LaunchFile};
pub use crate::policy::Restart;
use crate::policy::RestartRules;

/// The `[launch]` table.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    pub name: String,
    /// World file, relative to the launch file; substituted for `${world}`.
    pub world: Option<PathBuf>,
    /// Seed handed to services as `${seed}`.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The service whose exit ends the launch (the mission is over).
    pub end_with: Option<Spanned<String>>,
    #[serde(default = "default_grace_ms")]
    pub grace_period_ms: u64,
    #[serde(default = "default_ready_ms")]
    pub ready_timeout_ms: u64,
    /// The longest the launch may run by the wall clock: a mission's own timeout counts
    /// simulated time, which stands still when the clock chain stalls; this ends even that.
    #[serde(default = "default_wall_limit_s")]
    pub wall_limit_s: u64,
    /// `lockstep` (deterministic: ticks advance when every party has finished the last one) or
    /// `realtime` (paced by the wall clock, for a real robot).
    #[serde(default)]
    pub clock: ClockMode,
    /// Deterministic mode: the party that starts each tick.
    pub clock_master: Option<Spanned<String>>,
    /// Data files the services read (acceptor tables...), relative to the launch file: the
    /// recorder attaches them so that `harvey replay` has them.
    #[serde(default)]
    pub files: Vec<Spanned<String>>,
}

/// How a launch keeps time (DESIGN.md, Time and determinism).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClockMode {
    Lockstep,
    #[default]
    Realtime,
}

impl ClockMode {
    /// The mode's name in the services' environment.
    pub fn as_str(self) -> &'static str {
        match self {
            ClockMode::Lockstep => "lockstep",
            ClockMode::Realtime => "realtime",
        }
    }
}

fn default_seed() -> u64 {
    1
}
fn default_grace_ms() -> u64 {
    3000
}
fn default_ready_ms() -> u64 {
    10_000
}
/// Half an hour: the longest shipped mission takes a few minutes of wall time on two cores.
fn default_wall_limit_s() -> u64 {
    1800
}
fn default_restart() -> Restart {
    Restart::OnFailure
}
fn default_max_restarts() -> u32 {
    5
}
fn default_window_s() -> f64 {
    60.0
}
fn default_backoff_ms() -> u64 {
    50
}
fn default_backoff_max_ms() -> u64 {
    2000
}

/// The host of the services a launch file does not place.
pub const MAIN_HOST: &str = "main";

/// One `[[service]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Service {
    pub name: Spanned<String>,
    /// Executable: a path, or a name looked up beside `harvey` and then on `PATH`.
    /// Default: `harvey-<name>`.
    pub binary: Option<String>,
    #[serde(default)]
    pub args: Vec<String>,
    #[serde(default = "default_restart")]
    pub restart: Restart,
    /// More restarts than this within `restart_window_s` stop the launch.
    #[serde(default = "default_max_restarts")]
    pub max_restarts: u32,
    #[serde(default = "default_window_s")]
    pub restart_window_s: f64,
    /// Delay before the first restart, doubling for each further one in the window.
    #[serde(default = "default_backoff_ms")]
    pub backoff_ms: u64,
    #[serde(default = "default_backoff_max_ms")]
    pub backoff_max_ms: u64,
    /// Deterministic mode: whether this service takes turns in the clock chain (`false` for a
    /// service on the far side of a serial line, like the simulated DRV).
    #[serde(default = "default_true")]
    pub clock_party: bool,
    /// The host this service runs on when the launch is split over hosts (`harvey launch FILE
    /// --host NAME`, `docs/zenoh.md`); unplaced services run on the main host, `main`. A launch
    /// run on one host runs every service whatever its host.
    #[serde(default)]
    pub host: Option<Spanned<String>>,
}

fn default_true() -> bool {
    true
}

impl Service {
    pub fn name(&self) -> &str {
        self.name.get_ref()
    }

    /// The host this service is placed on (`main` unless it says otherwise).
    pub fn host(&self) -> &str {
        self.host.as_ref().map_or(MAIN_HOST, |h| h.get_ref().as_str())
    }

    pub fn binary_name(&self) -> String {
        self.binary.clone().unwrap_or_else(|| format!("harvey-{}", self.name()))
    }

    /// The service's restart rules. A window too long for a [`Duration`] never expires.
    pub fn restart_rules(&self) -> RestartRules {
        RestartRules {
            mode: self.restart,
            max_restarts: self.max_restarts,
            window: Duration::try_from_secs_f64(self.restart_window_s).unwrap_or(Duration::MAX),
            backoff_ms: self.backoff_ms,
            backoff_max_ms: self.backoff_max_ms,
        }
    }
}

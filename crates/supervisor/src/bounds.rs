//! The range of every number of a launch file, checked when it is loaded: a refused number is
//! named by file, line and key before anything starts.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use crate::config::{Service, Settings};

/// The least grace a service gets between SIGTERM and SIGKILL. The recorder closes its MCAP and
/// Rerun files on SIGTERM (flush, summary, index); with no grace it was killed mid-write and a
/// successful mission exited 2 (issue 20). The recorder took about 100 ms to close the default
/// mission's recording (6585 messages) on the 2-core bench machine: 200 ms is twice that, and
/// still lets a test stop a stubborn service quickly. The shipped missions give 3000 ms.
pub const MIN_GRACE_MS: u64 = 200;
/// The longest any wait of the launch file may be (grace, readiness): ten minutes. Larger
/// values only hang a launch, and `u64::MAX` ms overflows the clock's instants.
pub const MAX_WAIT_MS: u64 = 600_000;
/// The longest wall-clock limit of a launch: a week (a real robot's long run).
pub const MAX_WALL_S: u64 = 604_800;
/// The longest restart window: a week. Longer windows never forget a failure in any launch.
pub const MAX_WINDOW_S: f64 = 604_800.0;
/// Restarts a window may allow (each keeps an instant).
pub const MAX_RESTARTS: u32 = 1_000;
/// The longest backoff: an hour.
pub const MAX_BACKOFF_MS: u64 = 3_600_000;
/// Services a launch may start (each is a process).
pub const MAX_SERVICES: usize = 100;

/// A refused number: the key as the file spells it (`launch.grace_period_ms`,
/// `service[2].restart_window_s`) and why.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Refused {
    /// `None` for `[launch]`, else the service's index.
    pub service: Option<usize>,
    pub key: &'static str,
    pub detail: String,
}

impl Refused {
    /// The key's full name.
    pub fn path(&self) -> String {
        match self.service {
            None => format!("launch.{}", self.key),
            Some(i) => format!("service[{i}].{}", self.key),
        }
    }
}

fn refuse(service: Option<usize>, key: &'static str, detail: String) -> Refused {
    Refused { service, key, detail }
}

/// `lo <= v <= hi` for an integer key.
fn int(
    service: Option<usize>,
    key: &'static str,
    v: u64,
    lo: u64,
    hi: u64,
    unit: &str,
) -> Result<(), Refused> {
    if (lo..=hi).contains(&v) {
        return Ok(());
    }
    Err(refuse(service, key, format!("{v} is outside [{lo}, {hi}] {unit}")))
}

/// The `[launch]` numbers in range.
pub(crate) fn check_settings(s: &Settings) -> Result<(), Refused> {
    int(None, "grace_period_ms", s.grace_period_ms, MIN_GRACE_MS, MAX_WAIT_MS, "ms")?;
    int(None, "ready_timeout_ms", s.ready_timeout_ms, 1, MAX_WAIT_MS, "ms")?;
    int(None, "wall_limit_s", s.wall_limit_s, 1, MAX_WALL_S, "s")
}

/// The numbers of the `[[service]]` at `i` in range.
pub(crate) fn check_service(i: usize, s: &Service) -> Result<(), Refused> {
    let at = Some(i);
    int(at, "max_restarts", u64::from(s.max_restarts), 0, u64::from(MAX_RESTARTS), "restarts")?;
    let w = s.restart_window_s;
    if !(w.is_finite() && w > 0.0 && w <= MAX_WINDOW_S) {
        let what = if w.is_finite() { "outside" } else { "not a finite number in" };
        // As a file gives it: `60`, `1e300`, `inf`, `NaN`.
        let shown = if w.is_finite() && w.abs() < 1e15 { format!("{w}") } else { format!("{w:?}") };
        return Err(refuse(at, "restart_window_s", format!("{shown} is {what} (0, {MAX_WINDOW_S}] s")));
    }
    int(at, "backoff_ms", s.backoff_ms, 1, MAX_BACKOFF_MS, "ms")?;
    int(at, "backoff_max_ms", s.backoff_max_ms, 1, MAX_BACKOFF_MS, "ms")?;
    if s.backoff_max_ms < s.backoff_ms {
        let detail = format!("{} is less than backoff_ms ({})", s.backoff_max_ms, s.backoff_ms);
        return Err(refuse(at, "backoff_max_ms", detail));
    }
    Ok(())
}

/// Where the `[launch]` and `[[service]]` keys are, to name the line of a refused one.
#[derive(Deserialize)]
struct KeySpans {
    #[serde(default)]
    launch: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    service: Vec<Spanned<BTreeMap<String, Spanned<toml::Value>>>>,
}

/// The byte offset of `r`'s key in `text`: the value if the file gives it, else its table (the
/// service, or the file's start for `[launch]`).
pub(crate) fn offset_of(text: &str, r: &Refused) -> usize {
    let Ok(spans) = toml::from_str::<KeySpans>(text) else { return 0 };
    match r.service {
        None => spans.launch.get(r.key).map_or(0, |v| v.span().start),
        Some(i) => spans
            .service
            .get(i)
            .map_or(0, |s| s.get_ref().get(r.key).map_or(s.span().start, |v| v.span().start)),
    }
}

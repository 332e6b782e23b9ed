//! The supervisor: starts a launch file's services in order, each once the previous is ready;
//! restarts them by policy with backoff and a limit; cleans the bus after dead processes; and on
//! SIGINT/SIGTERM, or when the `end_with` service exits, stops them in reverse order.

use std::time::Duration;

use crate::child::{self, describe};
use crate::clock::ClockWatch;
use crate::config::LaunchFile;
use crate::error::SupervisorError;
use crate::outcome::{Options, Outcome};
use crate::signals::Signals;
use crate::slots::{self, Slot};
use crate::supervise::supervise;

/// Runs a launch file to its end. Services are stopped whatever happens.
pub fn run(launch: &LaunchFile, opts: &Options) -> Result<Outcome, SupervisorError> {
    harvey_bus::validate_prefix(&opts.prefix)?;
    let chain = launch.clock_chain();
    let mut slots = slots::prepare(launch, opts, &chain)?;
    claim_domain(launch, &opts.prefix)?;

    let signals = Signals::install().map_err(SupervisorError::Signals)?;
    let mut clock = if chain.is_empty() { None } else { Some(ClockWatch::new(&opts.prefix, &chain)?) };
    let ready = Duration::from_millis(launch.settings.ready_timeout_ms);
    let grace = Duration::from_millis(launch.settings.grace_period_ms);

    let outcome = (|| -> Result<Outcome, SupervisorError> {
        for slot in slots.iter_mut() {
            if signals.received() {
                return Ok(Outcome::Interrupted);
            }
            let r = slot.spawn(ready)?;
            tracing::info!(service = %r.name, pid = r.child.id(), "ready");
            slot.running = Some(r);
        }
        if let Some(c) = &mut clock {
            c.start()?;
        }
        supervise(&mut slots, launch, &opts.prefix, clock.as_mut(), ready, &signals)
    })();
    shutdown(&mut slots, grace);
    drop(clock);
    match harvey_bus::retire_domain(&opts.prefix) {
        Ok(n) => tracing::debug!(removed = n, "bus domain retired"),
        Err(e) => tracing::warn!("bus domain not retired: {e}"),
    }
    outcome
}

/// Makes sure no live copy of the launch's services is on the bus (observers, tools and tests,
/// may be), then removes what dead nodes left behind.
fn claim_domain(launch: &LaunchFile, prefix: &str) -> Result<(), SupervisorError> {
    let clashes: Vec<_> = harvey_bus::live_nodes(prefix)?
        .into_iter()
        .filter(|n| n.alive && launch.services.iter().any(|s| s.name() == n.name))
        .collect();
    if !clashes.is_empty() {
        return Err(SupervisorError::Clash { prefix: prefix.to_owned(), clashes });
    }
    let cleaned = harvey_bus::cleanup_dead_nodes(prefix)?;
    if cleaned > 0 {
        tracing::info!(cleaned, prefix = %prefix, "removed resources of dead nodes");
    }
    Ok(())
}

/// Stops the running services, last started first.
fn shutdown(slots: &mut [Slot], grace: Duration) {
    for slot in slots.iter_mut().rev() {
        if let Some(mut r) = slot.running.take() {
            let status = child::stop(&mut r, grace);
            tracing::info!(service = %r.name, "stopped: {}", describe(status));
        }
    }
}

//! The supervisor: starts a launch file's services in order, each once the previous is ready;
//! restarts them by policy with backoff and a limit; cleans the bus after dead processes; and on
//! SIGINT/SIGTERM, or when the `end_with` service exits, stops them in reverse order. It runs
//! under a keeper (`keeper.rs`), which starts the processes for it; a supervisor that follows
//! one that died takes over the running services and the clock chain where they are.

use std::os::unix::process::ExitStatusExt;
use std::process::ExitStatus;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use crate::child::{self, Running, describe};
use crate::clock::ClockWatch;
use crate::config::LaunchFile;
use crate::error::SupervisorError;
use crate::keeper_line::KeeperLine;
use crate::link::Memo;
use crate::outcome::{Options, Outcome};
use crate::signals::Signals;
use crate::slots::{self, Slot};
use crate::supervise::supervise;

/// Runs a launch file to its end. Services are stopped whatever happens.
pub fn run(launch: &LaunchFile, opts: &Options, line: &mut KeeperLine) -> Result<Outcome, SupervisorError> {
    harvey_bus::validate_prefix(&opts.prefix)?;
    let chain = launch.clock_chain();
    let taking_over = line.hello.predecessors > 0;
    let mut slots = slots::prepare(launch, opts, &chain, !taking_over)?;
    if taking_over {
        let cleaned = harvey_bus::cleanup_dead_nodes(&opts.prefix)?;
        tracing::warn!(
            predecessors = line.hello.predecessors,
            running = line.hello.live.len(),
            cleaned,
            "taking over from a supervisor that died"
        );
    } else {
        claim_domain(launch, &opts.prefix)?;
    }

    let signals = Signals::install().map_err(SupervisorError::Signals)?;
    let mut clock = if chain.is_empty() { None } else { Some(ClockWatch::new(&opts.prefix, &chain)?) };
    let ready = Duration::from_millis(launch.settings.ready_timeout_ms);
    let grace = Duration::from_millis(launch.settings.grace_period_ms);
    let mut memo = line.hello.memo.clone().unwrap_or_else(|| Memo {
        clock_started: false,
        deadline_unix_ms: unix_ms() + launch.settings.wall_limit_s.saturating_mul(1000),
    });
    line.remember(&memo)?;
    adopt(&mut slots, line);

    let outcome = (|| -> Result<Outcome, SupervisorError> {
        for slot in slots.iter_mut().filter(|s| s.running.is_none()) {
            if signals.received() {
                return Ok(Outcome::Interrupted);
            }
            let r = slot.spawn(line, ready)?;
            tracing::info!(service = %r.name, pid = r.pid, "ready");
            slot.running = Some(r);
        }
        if let Some(c) = &mut clock
            && !memo.clock_started
        {
            c.start()?;
            memo.clock_started = true;
            line.remember(&memo)?;
        }
        let left_ms = memo.deadline_unix_ms.saturating_sub(unix_ms());
        supervise(&mut slots, launch, opts, clock.as_mut(), line, Duration::from_millis(left_ms), &signals)
    })();
    shutdown(&mut slots, line, grace);
    drop(clock);
    match harvey_bus::retire_domain(&opts.prefix) {
        Ok(n) => tracing::debug!(removed = n, "bus domain retired"),
        Err(e) => tracing::warn!("bus domain not retired: {e}"),
    }
    outcome
}

/// Milliseconds since the Unix epoch (the wall-clock limit must outlive a supervisor).
fn unix_ms() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_millis() as u64)
}

/// Takes over the services the keeper says are running, and queues the last exit of those that
/// ended while no supervisor listened, for the supervision loop to judge.
fn adopt(slots: &mut [Slot], line: &mut KeeperLine) {
    let hello = line.hello.clone();
    for slot in slots.iter_mut() {
        if let Some((_, pid)) = hello.live.iter().find(|(n, _)| n == slot.name()) {
            tracing::info!(service = %slot.name(), pid, "taken over");
            slot.running = Some(Running { name: slot.name().to_owned(), pid: *pid });
        } else if let Some((_, pid, status)) = hello.exited.iter().find(|(n, ..)| n == slot.name()) {
            slot.running = Some(Running { name: slot.name().to_owned(), pid: *pid });
            line.queue_exit(*pid, ExitStatus::from_raw(*status));
        }
    }
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
fn shutdown(slots: &mut [Slot], line: &mut KeeperLine, grace: Duration) {
    for slot in slots.iter_mut().rev() {
        if let Some(r) = slot.running.take() {
            match child::stop(line, &r, grace) {
                Ok(status) => tracing::info!(service = %r.name, "stopped: {}", describe(status)),
                Err(e) => tracing::warn!(service = %r.name, "stopping: {e}"),
            }
        }
    }
}

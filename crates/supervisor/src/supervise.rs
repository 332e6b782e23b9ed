//! The supervision loop: takes in exits, asks each service's restart policy what to do, restarts
//! the services that are due, and sleeps until a child exits, a signal arrives or a restart is
//! due. In lockstep mode it also samples the clock chain's progress every 10 ms.

use std::process::ExitStatus;
use std::time::{Duration, Instant};

use crate::child::describe;
use crate::clock::ClockWatch;
use crate::config::LaunchFile;
use crate::error::{SupervisorError, chain};
use crate::outcome::Outcome;
use crate::policy::Decision;
use crate::signals::Signals;
use crate::slots::Slot;
use crate::wait::poll_input;

/// How often the clock chain's progress is sampled, and how often children are checked where
/// the kernel has no pidfds to wake the loop.
const POLL: Duration = Duration::from_millis(10);

/// The longest the loop sleeps with nothing to wait for (a safety net: every wake-up it needs
/// comes from a descriptor or a deadline).
const MAX_WAIT: Duration = Duration::from_secs(1);

/// Supervises the started services until the launch ends.
pub fn supervise(
    slots: &mut [Slot],
    launch: &LaunchFile,
    prefix: &str,
    mut clock: Option<&mut ClockWatch>,
    ready: Duration,
    signals: &Signals,
) -> Result<Outcome, SupervisorError> {
    let end_with = launch.settings.end_with.as_ref().map(|s| s.get_ref().clone());
    let limit_s = launch.settings.wall_limit_s;
    let deadline = Instant::now() + Duration::from_secs(limit_s);
    loop {
        if Instant::now() >= deadline {
            let waiting = clock.as_deref().map(|c| c.holder().0.to_owned());
            tracing::error!(limit_s, waiting = ?waiting, "the launch ran past its wall-clock limit: stopping");
            return Ok(Outcome::WallLimit { limit_s });
        }
        if let Some(c) = clock.as_deref_mut() {
            c.poll()?;
        }
        if signals.received() {
            tracing::info!("signal received: stopping");
            return Ok(Outcome::Interrupted);
        }
        let now = Instant::now();
        for slot in slots.iter_mut() {
            let Some(r) = &mut slot.running else { continue };
            let Some(status) = r.child.try_wait().map_err(SupervisorError::Wait)? else { continue };
            slot.running = None;
            if let Some(outcome) = exited(slot, status, now, end_with.as_deref()) {
                return Ok(outcome);
            }
        }
        for i in 0..slots.len() {
            if slots[i].policy.take_due(now)
                && let Some(outcome) = restart(slots, i, prefix, clock.as_deref_mut(), ready)?
            {
                return Ok(outcome);
            }
        }
        wait_for_events(slots, signals, clock.is_some());
    }
}

/// A service exited at `now`: the launch ends if it was the `end_with` service (unless a signal
/// killed it and its policy restarts it: a crash is not the mission's end) or its policy gives
/// up; otherwise its restart, if any, is scheduled.
fn exited(slot: &mut Slot, status: ExitStatus, now: Instant, end_with: Option<&str>) -> Option<Outcome> {
    let name = slot.name().to_owned();
    let crashed = std::os::unix::process::ExitStatusExt::signal(&status).is_some();
    if end_with == Some(name.as_str()) && !(crashed && slot.spec.restart != crate::Restart::Never) {
        tracing::info!(service = %name, "ended with {}", describe(status));
        return Some(Outcome::Ended { service: name, code: status.code().unwrap_or(1) });
    }
    match slot.policy.on_exit(now, status.success()) {
        Decision::Stay => {
            tracing::warn!(service = %name, "exited with {}; not restarted (policy {:?})", describe(status), slot.spec.restart);
            None
        }
        Decision::GiveUp => {
            let rules = slot.policy.rules();
            tracing::error!(service = %name, "exited with {}: {} restarts within {:.0} s, giving up", describe(status), rules.max_restarts, rules.window.as_secs_f64());
            Some(Outcome::GaveUp { service: name })
        }
        Decision::Restart { delay, attempt, .. } => {
            tracing::warn!(service = %name, "exited with {}: restart {} in {} ms", describe(status), attempt, delay.as_millis());
            None
        }
    }
}

/// Starts a service again after cleaning the bus of dead nodes; a failed start counts as a
/// failure and may end the launch.
fn restart(
    slots: &mut [Slot],
    i: usize,
    prefix: &str,
    clock: Option<&mut ClockWatch>,
    ready: Duration,
) -> Result<Option<Outcome>, SupervisorError> {
    let cleaned = harvey_bus::cleanup_dead_nodes(prefix)?;
    let slot = &mut slots[i];
    match slot.spawn(ready) {
        Ok(r) => {
            tracing::info!(service = %r.name, pid = r.child.id(), cleaned, "restarted");
            slot.running = Some(r);
            if let Some(c) = clock {
                let name = slots[i].name().to_owned();
                let others: Vec<u32> = slots
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .filter_map(|(_, s)| s.running.as_ref().map(|r| r.child.id()))
                    .collect();
                c.resume(&name, &others)?;
            }
            Ok(None)
        }
        Err(e) => {
            tracing::error!("{}", chain(&e));
            match slot.policy.on_failed_start(Instant::now()) {
                Decision::GiveUp => Ok(Some(Outcome::GaveUp { service: slot.name().to_owned() })),
                Decision::Stay | Decision::Restart { .. } => Ok(None),
            }
        }
    }
}

/// Sleeps until a child exits, a signal arrives or the next restart is due; at most [`POLL`]
/// when the clock chain is sampled or a child has no pidfd.
fn wait_for_events(slots: &[Slot], signals: &Signals, sampling: bool) {
    let mut fds = vec![signals.wake_fd()];
    let mut unwatched = false;
    for r in slots.iter().filter_map(|s| s.running.as_ref()) {
        match r.exit_fd() {
            Some(fd) => fds.push(fd),
            None => unwatched = true,
        }
    }
    let now = Instant::now();
    let next = slots.iter().filter_map(|s| s.policy.next_restart()).min();
    let mut timeout = next.map_or(MAX_WAIT, |t| t.saturating_duration_since(now).min(MAX_WAIT));
    if sampling || unwatched {
        timeout = timeout.min(POLL);
    }
    match poll_input(&fds, Some(timeout)) {
        Ok(true) => signals.drain(),
        Ok(false) => {}
        Err(e) => {
            tracing::warn!("waiting for the services: {e}");
            std::thread::sleep(POLL);
        }
    }
}

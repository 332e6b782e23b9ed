//! The supervision loop: takes in exits, asks each service's restart policy what to do, restarts
//! the services that are due, and sleeps until a child exits, a signal arrives or a restart is
//! due (the keeper's line says when a child exits). In lockstep mode it also samples the clock
//! chain's progress every 10 ms.

use std::process::ExitStatus;
use std::time::{Duration, Instant};

use crate::child::describe;
use crate::clock::ClockWatch;
use crate::config::LaunchFile;
use crate::error::{SupervisorError, chain};
use crate::keeper_line::KeeperLine;
use crate::outcome::{Options, Outcome};
use crate::policy::Decision;
use crate::signals::Signals;
use crate::slots::Slot;
use crate::wait::poll_input;

/// How often the clock chain's progress is sampled.
const POLL: Duration = Duration::from_millis(10);

/// The longest the loop sleeps with nothing to wait for (a safety net: every wake-up it needs
/// comes from a descriptor or a deadline).
const MAX_WAIT: Duration = Duration::from_secs(1);

/// Supervises the started services until the launch ends (at the latest after `time_left`).
pub fn supervise(
    slots: &mut [Slot],
    launch: &LaunchFile,
    opts: &Options,
    mut clock: Option<&mut ClockWatch>,
    line: &mut KeeperLine,
    time_left: Duration,
    signals: &Signals,
) -> Result<Outcome, SupervisorError> {
    let end_with = launch.settings.end_with.as_ref().map(|s| s.get_ref().clone());
    let limit_s = launch.settings.wall_limit_s;
    let ready = Duration::from_millis(launch.settings.ready_timeout_ms);
    let deadline = Instant::now() + time_left;
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
        for (pid, status) in line.exits()? {
            let Some(slot) = slots.iter_mut().find(|s| s.running.as_ref().is_some_and(|r| r.pid == pid))
            else {
                continue;
            };
            slot.running = None;
            if let Some(outcome) = exited(slot, status, now, end_with.as_deref()) {
                return Ok(outcome);
            }
        }
        for i in 0..slots.len() {
            if slots[i].policy.take_due(now)
                && let Some(outcome) = restart(slots, i, &opts.prefix, clock.as_deref_mut(), line, ready)?
            {
                return Ok(outcome);
            }
        }
        wait_for_events(slots, signals, line, clock.is_some());
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
    line: &mut KeeperLine,
    ready: Duration,
) -> Result<Option<Outcome>, SupervisorError> {
    let cleaned = harvey_bus::cleanup_dead_nodes(prefix)?;
    let slot = &mut slots[i];
    match slot.spawn(line, ready) {
        Ok(r) => {
            tracing::info!(service = %r.name, pid = r.pid, cleaned, "restarted");
            slot.running = Some(r);
            if let Some(c) = clock {
                let name = slots[i].name().to_owned();
                let others: Vec<u32> = slots
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .filter_map(|(_, s)| s.running.as_ref().map(|r| r.pid))
                    .collect();
                c.resume(&name, &others)?;
            }
            Ok(None)
        }
        Err(e @ SupervisorError::Keeper(_)) => Err(e),
        Err(e) => {
            tracing::error!("{}", chain(&e));
            match slot.policy.on_failed_start(Instant::now()) {
                Decision::GiveUp => Ok(Some(Outcome::GaveUp { service: slot.name().to_owned() })),
                Decision::Stay | Decision::Restart { .. } => Ok(None),
            }
        }
    }
}

/// Sleeps until the keeper reports an exit, a signal arrives or the next restart is due; at
/// most [`POLL`] when the clock chain is sampled.
fn wait_for_events(slots: &[Slot], signals: &Signals, line: &KeeperLine, sampling: bool) {
    let fds = [signals.wake_fd(), line.fd()];
    let now = Instant::now();
    let next = slots.iter().filter_map(|s| s.policy.next_restart()).min();
    let mut timeout = next.map_or(MAX_WAIT, |t| t.saturating_duration_since(now).min(MAX_WAIT));
    if sampling {
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

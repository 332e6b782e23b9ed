//! The keeper: a launch's outer process, small enough to trust. It runs the supervisor as a
//! child, starts every service on the supervisor's request (so the services are the keeper's
//! children and outlive the supervisor), reaps them and tells the supervisor how they ended.
//! When the supervisor dies without saying how the launch ended, the keeper starts a new one
//! and hands it the running services, how the others last ended, and the memo its predecessor
//! left; the services and the clock chain run on meanwhile.

use std::collections::{HashMap, VecDeque};
use std::os::fd::AsRawFd;
use std::os::unix::process::ExitStatusExt;
use std::process::{Child, Command};
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill, killpg};
use nix::unistd::Pid;

use crate::child::describe;
use crate::link::{Hello, Memo, Socket, ToKeeper, ToSupervisor};
use crate::outcome::Outcome;
use crate::signals::Signals;
use crate::spawn;

/// A supervisor that dies more often than this within [`RELAUNCH_WINDOW`] is not started again.
const MAX_RELAUNCHES: usize = 5;
const RELAUNCH_WINDOW: Duration = Duration::from_secs(60);
/// The longest the keeper sleeps between checks (SIGCHLD and the line wake it sooner).
const TICK: Duration = Duration::from_millis(50);

/// How a kept launch ended.
#[derive(Debug)]
pub enum Kept {
    /// The supervisor said so.
    Outcome(Outcome),
    /// The supervisor exited without an outcome (it reported its error itself), or died too
    /// often; the process exit code to return.
    Failed(i32),
}

struct Keeper {
    services: Vec<(String, Child)>,
    /// How each service's last process ended: pid and raw wait status.
    last_exit: HashMap<String, (u32, i32)>,
    memo: Option<Memo>,
    outcome: Option<Outcome>,
    forwarded: bool,
}

/// Runs supervisors made by `make_supervisor` until one reports how the launch ended; stops
/// whatever it started before returning. `grace` is how long a service has between SIGTERM and
/// SIGKILL if the keeper must stop the services itself.
pub fn keep(make_supervisor: &dyn Fn() -> Command, grace: Duration) -> std::io::Result<Kept> {
    let signals = Signals::install_waking(&[signal_hook::consts::SIGCHLD])?;
    let mut k = Keeper {
        services: Vec::new(),
        last_exit: HashMap::new(),
        memo: None,
        outcome: None,
        forwarded: false,
    };
    let mut deaths: VecDeque<Instant> = VecDeque::new();
    let mut predecessors = 0;
    let result = loop {
        let (ours, theirs) = Socket::pair()?;
        let mut sup = spawn::supervisor(make_supervisor(), theirs.fd().as_raw_fd())?;
        // Only the supervisor holds its end now: the line closes when it dies.
        drop(theirs);
        ours.send(&ToSupervisor::Hello(k.hello(predecessors)), &[])?;
        let status = k.serve(&ours, &mut sup, &signals)?;
        if let Some(o) = k.outcome.take() {
            break Kept::Outcome(o);
        }
        if signals.received() {
            break Kept::Outcome(Outcome::Interrupted);
        }
        let now = Instant::now();
        deaths.retain(|t| now.duration_since(*t) < RELAUNCH_WINDOW);
        deaths.push_back(now);
        if status.signal().is_none() || deaths.len() > MAX_RELAUNCHES {
            if status.signal().is_some() {
                tracing::error!(
                    "the supervisor died {} times within {} s: giving up",
                    deaths.len(),
                    RELAUNCH_WINDOW.as_secs()
                );
            }
            break Kept::Failed(status.code().unwrap_or(1));
        }
        predecessors += 1;
        tracing::warn!(
            "the supervisor ended with {} without an outcome: starting a new one, which takes over {} running services",
            describe(status),
            k.services.len()
        );
    };
    k.stop_all(grace);
    Ok(result)
}

impl Keeper {
    fn hello(&self, predecessors: u32) -> Hello {
        let live: Vec<(String, u32)> = self.services.iter().map(|(n, c)| (n.clone(), c.id())).collect();
        let exited = self
            .last_exit
            .iter()
            .filter(|(n, _)| !live.iter().any(|(l, _)| l == *n))
            .map(|(n, (pid, st))| (n.clone(), *pid, *st))
            .collect();
        Hello { predecessors, live, exited, memo: self.memo.clone() }
    }

    /// Serves one supervisor until it exits; returns how it ended.
    fn serve(
        &mut self,
        line: &Socket,
        sup: &mut Child,
        signals: &Signals,
    ) -> std::io::Result<std::process::ExitStatus> {
        let mut open = true;
        loop {
            if let Some(status) = sup.try_wait()? {
                // Whatever it sent before it went is still in the socket.
                while open && self.take_message(line, Some(Duration::ZERO), &mut open)? {}
                self.reap(line);
                return Ok(status);
            }
            if signals.received() && !self.forwarded {
                // A signal to the keeper alone (a terminal's goes to both) stops the supervisor.
                self.forwarded = true;
                let sig = signals.which().and_then(|s| Signal::try_from(s).ok()).unwrap_or(Signal::SIGTERM);
                let _ = kill(Pid::from_raw(sup.id() as i32), sig);
            }
            self.reap(line);
            let mut fds = vec![signals.wake_fd()];
            if open {
                fds.push(line.fd());
            }
            if crate::wait::poll_input(&fds, Some(TICK)).is_ok() {
                signals.drain();
            }
            while open && self.take_message(line, Some(Duration::ZERO), &mut open)? {}
        }
    }

    /// Handles one message from the supervisor, if one is waiting; `open` turns false when the
    /// supervisor has closed its end.
    fn take_message(
        &mut self,
        line: &Socket,
        wait: Option<Duration>,
        open: &mut bool,
    ) -> std::io::Result<bool> {
        let msg = match line.recv::<ToKeeper>(wait) {
            Ok(Some((msg, _))) => msg,
            Ok(None) => return Ok(false),
            Err(e) => {
                if e.kind() != std::io::ErrorKind::UnexpectedEof {
                    tracing::warn!("the supervisor's line: {e}");
                }
                *open = false;
                return Ok(false);
            }
        };
        match msg {
            ToKeeper::Spawn(spec) => match spawn::service(&spec) {
                Ok((child, ready)) => {
                    let reply = ToSupervisor::Spawned { pid: child.id() };
                    self.services.push((spec.name, child));
                    line.send(&reply, &[ready.as_raw_fd()])?;
                }
                Err(e) => {
                    let error = format!("cannot start {}: {e}", spec.binary.display());
                    line.send(&ToSupervisor::SpawnFailed { error }, &[])?;
                }
            },
            ToKeeper::Remember(memo) => self.memo = Some(memo),
            ToKeeper::Ended(o) => self.outcome = Some(o),
        }
        Ok(true)
    }

    /// Reaps the services that have exited and tells the supervisor (if it still listens).
    fn reap(&mut self, line: &Socket) {
        let mut i = 0;
        while i < self.services.len() {
            let (name, child) = &mut self.services[i];
            let Ok(Some(status)) = child.try_wait() else {
                i += 1;
                continue;
            };
            let (pid, raw) = (child.id(), status.into_raw());
            self.last_exit.insert(name.clone(), (pid, raw));
            self.services.swap_remove(i);
            let _ = line.send(&ToSupervisor::Exited { pid, status: raw }, &[]);
        }
    }

    /// SIGTERM to every service still running, SIGKILL after `grace`; all reaped.
    fn stop_all(&mut self, grace: Duration) {
        if self.services.is_empty() {
            return;
        }
        tracing::warn!(services = self.services.len(), "the keeper stops the services its supervisor left");
        for (_, c) in &self.services {
            let _ = killpg(Pid::from_raw(c.id() as i32), Signal::SIGTERM);
        }
        let deadline = Instant::now() + grace;
        while Instant::now() < deadline
            && self.services.iter_mut().any(|(_, c)| matches!(c.try_wait(), Ok(None)))
        {
            std::thread::sleep(Duration::from_millis(10));
        }
        for (name, c) in &mut self.services {
            if matches!(c.try_wait(), Ok(None)) {
                tracing::warn!(service = %name, "did not stop within {} ms: SIGKILL", grace.as_millis());
                let _ = killpg(Pid::from_raw(c.id() as i32), Signal::SIGKILL);
                let _ = c.wait();
            }
        }
        self.services.clear();
    }
}

//! The supervisor's end of its keeper's line: it asks the keeper to start services, hears how
//! they exit (queued until the supervision loop takes them), leaves its memo and reports the
//! launch's outcome.

use std::collections::VecDeque;
use std::os::fd::{BorrowedFd, OwnedFd};
use std::os::unix::process::ExitStatusExt;
use std::process::ExitStatus;
use std::time::{Duration, Instant};

use crate::error::SupervisorError;
use crate::link::{Hello, KEEPER_FD_ENV, Memo, Socket, SpawnSpec, ToKeeper, ToSupervisor};
use crate::outcome::Outcome;

/// How long a new supervisor waits for its keeper's first message.
const HELLO_TIMEOUT: Duration = Duration::from_secs(10);

/// The line to the keeper, with what it said when this supervisor started.
pub struct KeeperLine {
    socket: Socket,
    exits: VecDeque<(u32, ExitStatus)>,
    pub hello: Hello,
}

impl KeeperLine {
    /// The line this process was started with, if a keeper started it (`HARVEY_KEEPER_FD`).
    /// Call it once: the line's descriptor becomes the returned value's.
    pub fn from_env() -> Result<Option<Self>, SupervisorError> {
        let Some(value) = std::env::var_os(KEEPER_FD_ENV) else { return Ok(None) };
        let fd: i32 = value.to_str().and_then(|v| v.parse().ok()).filter(|fd| *fd > 2).ok_or_else(|| {
            SupervisorError::Keeper(format!("{KEEPER_FD_ENV}={value:?} is not a descriptor"))
        })?;
        // SAFETY: the keeper passed this descriptor and nothing else in this process owns it.
        let socket = unsafe { Socket::from_raw(fd) };
        let hello = match socket.recv::<ToSupervisor>(Some(HELLO_TIMEOUT)) {
            Ok(Some((ToSupervisor::Hello(h), _))) => h,
            Ok(Some((other, _))) => {
                return Err(SupervisorError::Keeper(format!("expected a hello, got {other:?}")));
            }
            Ok(None) => return Err(SupervisorError::Keeper("no hello from the keeper".into())),
            Err(e) => return Err(SupervisorError::Keeper(format!("reading the keeper's hello: {e}"))),
        };
        Ok(Some(Self { socket, exits: VecDeque::new(), hello }))
    }

    /// Readable when the keeper has news.
    pub fn fd(&self) -> BorrowedFd<'_> {
        self.socket.fd()
    }

    fn send(&self, msg: &ToKeeper) -> Result<(), SupervisorError> {
        self.socket.send(msg, &[]).map_err(|e| SupervisorError::Keeper(format!("writing to the keeper: {e}")))
    }

    /// Takes in what the keeper sent, waiting at most `wait` for the first message; returns the
    /// replies that are not exits.
    fn pump(&mut self, wait: Option<Duration>) -> Result<Vec<(ToSupervisor, Vec<OwnedFd>)>, SupervisorError> {
        let mut replies = Vec::new();
        let mut wait = wait;
        loop {
            let got = self.socket.recv::<ToSupervisor>(wait);
            let Some((msg, fds)) =
                got.map_err(|e| SupervisorError::Keeper(format!("the keeper's line: {e}")))?
            else {
                return Ok(replies);
            };
            match msg {
                ToSupervisor::Exited { pid, status } => {
                    self.exits.push_back((pid, ExitStatus::from_raw(status)))
                }
                other => replies.push((other, fds)),
            }
            wait = Some(Duration::ZERO);
        }
    }

    /// Asks the keeper to start a service; returns its pid and readiness pipe, or why not.
    pub fn spawn(&mut self, spec: SpawnSpec) -> Result<Result<(u32, OwnedFd), String>, SupervisorError> {
        self.send(&ToKeeper::Spawn(spec))?;
        let deadline = Instant::now() + HELLO_TIMEOUT;
        while Instant::now() < deadline {
            let left = deadline.saturating_duration_since(Instant::now());
            for (msg, mut fds) in self.pump(Some(left))? {
                match msg {
                    ToSupervisor::Spawned { pid } if fds.len() == 1 => return Ok(Ok((pid, fds.remove(0)))),
                    ToSupervisor::SpawnFailed { error } => return Ok(Err(error)),
                    other => tracing::warn!("unexpected from the keeper: {other:?}"),
                }
            }
        }
        Err(SupervisorError::Keeper("the keeper did not answer a spawn request".into()))
    }

    /// Takes in the keeper's news and hands over the exits heard so far.
    pub fn exits(&mut self) -> Result<Vec<(u32, ExitStatus)>, SupervisorError> {
        for (msg, _) in self.pump(Some(Duration::ZERO))? {
            tracing::warn!("unexpected from the keeper: {msg:?}");
        }
        Ok(self.exits.drain(..).collect())
    }

    /// Queues an exit the keeper reported to a predecessor.
    pub fn queue_exit(&mut self, pid: u32, status: ExitStatus) {
        self.exits.push_back((pid, status));
    }

    /// Waits at most `timeout` for process `pid` to have exited.
    pub fn wait_exit(&mut self, pid: u32, timeout: Duration) -> Result<Option<ExitStatus>, SupervisorError> {
        let deadline = Instant::now() + timeout;
        for (msg, _) in self.pump(Some(Duration::ZERO))? {
            tracing::warn!("unexpected from the keeper: {msg:?}");
        }
        loop {
            if let Some(i) = self.exits.iter().position(|(p, _)| *p == pid) {
                return Ok(self.exits.remove(i).map(|(_, s)| s));
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(None);
            }
            for (msg, _) in self.pump(Some(left))? {
                tracing::warn!("unexpected from the keeper: {msg:?}");
            }
        }
    }

    /// Leaves `memo` for a successor.
    pub fn remember(&self, memo: &Memo) -> Result<(), SupervisorError> {
        self.send(&ToKeeper::Remember(memo.clone()))
    }

    /// Says how the launch ended (the last message).
    pub fn report(&self, outcome: &Outcome) -> Result<(), SupervisorError> {
        self.send(&ToKeeper::Ended(outcome.clone()))
    }
}

//! Waiting on file descriptors: a child's readiness pipe (it writes `READY\n`), the keeper's
//! line, a signal's self-pipe.

use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::time::{Duration, Instant};

use nix::errno::Errno;
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};

/// Why a child did not become ready.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NotReady {
    #[error("no readiness within {} ms", .0.as_millis())]
    Timeout(Duration),
    #[error("it exited or closed its readiness pipe first")]
    Closed,
    #[error("waiting for readiness: {0}")]
    Poll(Errno),
    #[error("reading readiness: {0}")]
    Read(Errno),
}

/// A poll timeout of at least `d` (rounded up to whole milliseconds, at most a minute).
pub fn timeout_of(d: Duration) -> PollTimeout {
    let ms = d.as_micros().div_ceil(1000).min(60_000) as i32;
    PollTimeout::try_from(ms).unwrap_or(PollTimeout::MAX)
}

/// Polls `fds` for input for up to `timeout` (`None`: until one has some). Returns whether one
/// has; an interrupted poll counts as a wake-up.
pub fn poll_input(fds: &[BorrowedFd<'_>], timeout: Option<Duration>) -> Result<bool, Errno> {
    let mut polled: Vec<_> = fds.iter().map(|fd| PollFd::new(*fd, PollFlags::POLLIN)).collect();
    match poll(&mut polled, timeout.map_or(PollTimeout::NONE, timeout_of)) {
        Ok(n) => Ok(n > 0),
        Err(Errno::EINTR) => Ok(true),
        Err(e) => Err(e),
    }
}

/// Waits until `READY\n` arrives on `pipe`, for at most `timeout`.
pub fn wait_ready(pipe: &OwnedFd, timeout: Duration) -> Result<(), NotReady> {
    let deadline = Instant::now() + timeout;
    let mut got = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(NotReady::Timeout(timeout));
        }
        let mut fds = [PollFd::new(pipe.as_fd(), PollFlags::POLLIN)];
        let ms = PollTimeout::try_from(left.as_millis().min(60_000) as i32).unwrap_or(PollTimeout::MAX);
        match poll(&mut fds, ms) {
            Ok(0) => continue,
            Ok(_) => {}
            Err(Errno::EINTR) => continue,
            Err(e) => return Err(NotReady::Poll(e)),
        }
        let mut buf = [0u8; 16];
        match nix::unistd::read(pipe, &mut buf) {
            Ok(0) => return Err(NotReady::Closed),
            Ok(n) => got.extend_from_slice(&buf[..n]),
            Err(Errno::EINTR) => continue,
            Err(e) => return Err(NotReady::Read(e)),
        }
        if got.starts_with(harvey_runtime::READY_LINE) {
            return Ok(());
        }
    }
}

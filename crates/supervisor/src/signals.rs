//! SIGINT and SIGTERM for one launch: a flag to check, and a self-pipe that wakes the
//! supervisor's wait. The pipe's handlers go with the launch; the flag's stay installed, so a
//! signal after the launch still does not kill the program mid-summary.

use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use nix::fcntl::OFlag;
use signal_hook::SigId;

/// Signals received during a launch.
pub struct Signals {
    flag: Arc<AtomicUsize>,
    wake: OwnedFd,
    pipe_handlers: Vec<SigId>,
}

impl Signals {
    /// Installs the handlers.
    pub fn install() -> std::io::Result<Self> {
        Self::install_waking(&[])
    }

    /// Installs the handlers, and makes `wake_only` signals (SIGCHLD for the keeper) wake the
    /// pipe without counting as received.
    pub fn install_waking(wake_only: &[i32]) -> std::io::Result<Self> {
        let flag = Arc::new(AtomicUsize::new(0));
        let (wake, ping) = nix::unistd::pipe2(OFlag::O_CLOEXEC | OFlag::O_NONBLOCK)?;
        let mut signals = Self { flag, wake, pipe_handlers: Vec::new() };
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            signal_hook::flag::register_usize(sig, Arc::clone(&signals.flag), sig as usize)?;
            // Dropping `signals` on an error unregisters the pipe handlers already installed.
            let id = signal_hook::low_level::pipe::register(sig, ping.try_clone()?)?;
            signals.pipe_handlers.push(id);
        }
        for sig in wake_only {
            let id = signal_hook::low_level::pipe::register(*sig, ping.try_clone()?)?;
            signals.pipe_handlers.push(id);
        }
        Ok(signals)
    }

    /// Whether SIGINT or SIGTERM arrived.
    pub fn received(&self) -> bool {
        self.flag.load(Ordering::Relaxed) != 0
    }

    /// The signal that arrived last, if any.
    pub fn which(&self) -> Option<i32> {
        Some(self.flag.load(Ordering::Relaxed) as i32).filter(|s| *s != 0)
    }

    /// Readable once a signal has arrived (until [`Signals::drain`]).
    pub fn wake_fd(&self) -> BorrowedFd<'_> {
        self.wake.as_fd()
    }

    /// Empties the self-pipe after a wake-up.
    pub fn drain(&self) {
        let mut buf = [0u8; 64];
        while matches!(nix::unistd::read(&self.wake, &mut buf), Ok(n) if n > 0) {}
    }
}

impl Drop for Signals {
    fn drop(&mut self) {
        for id in self.pipe_handlers.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}

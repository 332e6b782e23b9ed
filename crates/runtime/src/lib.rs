//! What every Harvey service process shares: logging set-up, the readiness handshake with
//! the supervisor, [`checkpoint`]s of a service's state across restarts, and its warnings on
//! `rosout` ([`rosout`]), repeated ones said once a period ([`throttle`]), and the bridges' taps
//! on every topic ([`taps`]).
//!
//! Readiness: the supervisor passes a pipe's write end in `$HARVEY_READY_FD`; a service calls
//! [`notify_ready`] once its ports exist, which writes `READY\n` and closes the pipe. A service
//! started by hand (no variable) skips the handshake.

pub mod checkpoint;
pub mod endpoint;
pub mod journal;
pub mod node;
pub mod resume;
pub mod rosout;
pub mod taps;
pub mod throttle;

pub use checkpoint::{Checkpoint, CheckpointError, STATE_DIR_ENV};
pub use journal::Journal;
pub use node::{End, FrameIn, FrameOut, FrameView, In, Io, Node, Out, Ports};
pub use resume::{Marks, Resume, Sent};
pub use rosout::Rosout;
pub use throttle::{Say, Throttle};

use std::io::Write;
use std::os::fd::FromRawFd;

/// Environment variable naming the readiness pipe's file descriptor.
pub const READY_FD_ENV: &str = "HARVEY_READY_FD";
/// Environment variable set by the supervisor for its children.
pub const SUPERVISED_ENV: &str = "HARVEY_SUPERVISED";
/// The line a ready service writes.
pub const READY_LINE: &[u8] = b"READY\n";

/// Logs to stderr, filtered by `RUST_LOG` (default `info`). Under the supervisor, which prefixes
/// and timestamps lines itself, lines are plain. WARN and ERROR events of a turn are also
/// captured for [`Rosout`], whatever `RUST_LOG` says (what is recorded must not depend on it).
pub fn init_logging() {
    use tracing_subscriber::Layer;
    use tracing_subscriber::layer::SubscriberExt;
    use tracing_subscriber::util::SubscriberInitExt;
    let supervised = std::env::var_os(SUPERVISED_ENV).is_some();
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let fmt = tracing_subscriber::fmt::layer().with_writer(std::io::stderr);
    let fmt =
        if supervised { fmt.without_time().with_ansi(false).with_target(false).boxed() } else { fmt.boxed() };
    let capture = rosout::CaptureLayer.with_filter(tracing_subscriber::filter::LevelFilter::WARN);
    tracing_subscriber::registry().with(fmt.with_filter(filter)).with(capture).init();
}

/// Tells the supervisor this service is ready. Idempotent: only the first call writes.
pub fn notify_ready() -> anyhow::Result<()> {
    let Some(raw) = std::env::var_os(READY_FD_ENV) else {
        return Ok(());
    };
    // Only the first call may use the descriptor; later calls find the variable gone.
    // SAFETY: single-threaded at this point of start-up in every service.
    unsafe { std::env::remove_var(READY_FD_ENV) };
    let fd: i32 = raw
        .to_str()
        .and_then(|s| s.parse().ok())
        .filter(|fd| *fd > 2)
        .ok_or_else(|| anyhow::anyhow!("${READY_FD_ENV} is not a file descriptor: {raw:?}"))?;
    // SAFETY: the supervisor opened this descriptor for us alone and nothing else in the
    // process uses it; the File takes ownership and closes it.
    let mut pipe = unsafe { std::fs::File::from_raw_fd(fd) };
    pipe.write_all(READY_LINE).map_err(|e| anyhow::anyhow!("writing readiness to fd {fd}: {e}"))?;
    tracing::debug!("ready");
    Ok(())
}

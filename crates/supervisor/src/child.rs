//! One supervised service process, as the supervisor sees it: started by the keeper on request
//! (in its own process group, readiness pipe on fd 3, output prefixed with its name), waited
//! for until ready, stopped with SIGTERM to its group then SIGKILL; the keeper reaps it and
//! reports how it ended.

use std::os::unix::process::ExitStatusExt;
use std::path::PathBuf;
use std::process::ExitStatus;
use std::time::Duration;

use nix::sys::signal::{Signal, killpg};
use nix::unistd::Pid;

use crate::error::SupervisorError;
use crate::keeper_line::KeeperLine;
use crate::link::SpawnSpec;
use crate::wait::{NotReady, wait_ready};

/// How long a SIGKILLed service may take to be reported gone.
const KILLED_TIMEOUT: Duration = Duration::from_secs(5);

/// A child that could not be started.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("service `{service}`: {error}")]
    Start { service: String, binary: PathBuf, error: String },
    #[error("service `{service}` did not become ready: {why} (then {status})")]
    NotReady { service: String, why: NotReady, status: String },
}

/// A running service (the keeper's child).
#[derive(Debug)]
pub struct Running {
    pub name: String,
    pub pid: u32,
}

/// How a child ended.
pub fn describe(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(c), _) => format!("exit code {c}"),
        (None, Some(s)) => Signal::try_from(s).map_or(format!("signal {s}"), |s| format!("{s}")),
        _ => "unknown status".into(),
    }
}

/// Has the keeper start `spec`; returns once it is ready, or an error naming the service if it
/// exits or stays silent for `ready_timeout`.
pub fn spawn(
    line: &mut KeeperLine,
    spec: SpawnSpec,
    ready_timeout: Duration,
) -> Result<Running, SupervisorError> {
    let (name, binary) = (spec.name.clone(), spec.binary.clone());
    let (pid, ready) =
        line.spawn(spec)?.map_err(|error| SpawnError::Start { service: name.clone(), binary, error })?;
    let running = Running { name: name.clone(), pid };
    match wait_ready(&ready, ready_timeout) {
        Ok(()) => Ok(running),
        Err(why) => {
            let status = stop(line, &running, Duration::from_millis(500))?;
            Err(SpawnError::NotReady { service: name, why, status: describe(status) }.into())
        }
    }
}

/// SIGTERM to the child's process group, then SIGKILL after `grace`; returns how it ended.
pub fn stop(line: &mut KeeperLine, r: &Running, grace: Duration) -> Result<ExitStatus, SupervisorError> {
    // The child leads its own process group: signal the group, so helpers it started go too.
    if let Some(status) = line.wait_exit(r.pid, Duration::ZERO)? {
        return Ok(status);
    }
    let group = Pid::from_raw(r.pid as i32);
    let _ = killpg(group, Signal::SIGTERM);
    if let Some(status) = line.wait_exit(r.pid, grace)? {
        return Ok(status);
    }
    tracing::warn!(service = %r.name, "did not stop within {} ms: SIGKILL", grace.as_millis());
    let _ = killpg(group, Signal::SIGKILL);
    Ok(line.wait_exit(r.pid, KILLED_TIMEOUT)?.unwrap_or_else(|| ExitStatus::from_raw(libc::SIGKILL)))
}

//! One supervised child process: spawned in its own process group with a readiness pipe on
//! fd 3, its output prefixed with its name, stopped with SIGTERM then SIGKILL, always reaped.

use std::io::{BufRead, BufReader, Read};
use std::os::fd::{AsFd, AsRawFd, BorrowedFd, OwnedFd};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use nix::errno::Errno;
use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

use crate::wait::{NotReady, pidfd, poll_input, wait_ready};

/// The fd number a child finds its readiness pipe on.
const READY_FD: i32 = 3;

/// How often a child without a pidfd is checked while it is being stopped.
const EXIT_POLL: Duration = Duration::from_millis(10);

/// A child that could not be started.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("creating a readiness pipe")]
    Pipe(#[source] Errno),
    #[error("service `{service}`: cannot start {}", binary.display())]
    Start {
        service: String,
        binary: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("service `{service}` did not become ready: {why} (then {status})")]
    NotReady { service: String, why: NotReady, status: String },
}

/// A running child.
pub struct Running {
    pub name: String,
    pub child: Child,
    /// Its pidfd, readable once it has exited; `None` on kernels without pidfds.
    exited: Option<OwnedFd>,
}

impl Running {
    /// A descriptor that becomes readable when the child exits, if the kernel has pidfds.
    pub fn exit_fd(&self) -> Option<BorrowedFd<'_>> {
        self.exited.as_ref().map(|fd| fd.as_fd())
    }
}

/// How a child ended.
pub fn describe(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(c), _) => format!("exit code {c}"),
        (None, Some(s)) => Signal::try_from(s).map_or(format!("signal {s}"), |s| format!("{s}")),
        _ => "unknown status".into(),
    }
}

fn forward_lines(name: String, stream: impl Read + Send + 'static) {
    std::thread::spawn(move || {
        for line in BufReader::new(stream).lines() {
            match line {
                Ok(l) => eprintln!("[{name}] {l}"),
                Err(_) => break,
            }
        }
    });
}

/// Starts `binary` with `args` and the bus environment; returns once it is ready, or an error
/// naming the service if it exits or stays silent for `ready_timeout`.
pub fn spawn(
    name: &str,
    binary: &Path,
    args: &[String],
    env: &[(&str, String)],
    ready_timeout: Duration,
) -> Result<Running, SpawnError> {
    let (ready_read, ready_write): (OwnedFd, OwnedFd) =
        nix::unistd::pipe2(nix::fcntl::OFlag::O_CLOEXEC).map_err(SpawnError::Pipe)?;
    let write_raw = ready_write.as_raw_fd();
    let mut cmd = Command::new(binary);
    cmd.args(args)
        .envs(env.iter().map(|(k, v)| (*k, v.as_str())))
        .env(harvey_runtime::READY_FD_ENV, READY_FD.to_string())
        .env(harvey_runtime::SUPERVISED_ENV, "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // SAFETY: only async-signal-safe calls (dup2, setpgid, prctl) between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            if libc::dup2(write_raw, READY_FD) < 0 || libc::setpgid(0, 0) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            // If the supervisor dies, its children must not run on unsupervised.
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = cmd.spawn().map_err(|source| SpawnError::Start {
        service: name.to_owned(),
        binary: binary.to_owned(),
        source,
    })?;
    drop(ready_write);
    if let Some(out) = child.stdout.take() {
        forward_lines(name.to_owned(), out);
    }
    if let Some(err) = child.stderr.take() {
        forward_lines(name.to_owned(), err);
    }
    // Not yet reaped (only we wait for it), so the pid cannot name another process.
    let exited = pidfd(child.id());
    let mut running = Running { name: name.to_owned(), child, exited };
    match wait_ready(&ready_read, ready_timeout) {
        Ok(()) => Ok(running),
        Err(why) => {
            let status = stop(&mut running, Duration::from_millis(500));
            Err(SpawnError::NotReady { service: name.to_owned(), why, status: describe(status) })
        }
    }
}

/// SIGTERM to the child's process group, then SIGKILL after `grace`; reaps the child and returns
/// how it ended.
pub fn stop(r: &mut Running, grace: Duration) -> ExitStatus {
    if let Ok(Some(status)) = r.child.try_wait() {
        return status;
    }
    // The child leads its own process group: signal the group, so helpers it started go too.
    let group = Pid::from_raw(-(r.child.id() as i32));
    let _ = kill(group, Signal::SIGTERM);
    if let Some(status) = wait_exit(r, grace) {
        return status;
    }
    tracing::warn!(service = %r.name, "did not stop within {} ms: SIGKILL", grace.as_millis());
    let _ = kill(group, Signal::SIGKILL);
    r.child.wait().unwrap_or_else(|_| ExitStatus::from_raw(libc::SIGKILL))
}

/// Reaps the child if it exits within `grace`: woken by its pidfd, else checked every 10 ms.
fn wait_exit(r: &mut Running, grace: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + grace;
    while Instant::now() < deadline {
        if let Ok(Some(status)) = r.child.try_wait() {
            return Some(status);
        }
        let left = deadline.saturating_duration_since(Instant::now());
        let woken = r.exit_fd().map(|fd| poll_input(&[fd], Some(left)));
        if !matches!(woken, Some(Ok(_))) {
            std::thread::sleep(EXIT_POLL.min(left));
        }
    }
    None
}

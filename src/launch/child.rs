//! One supervised child process: spawned in its own process group with a readiness pipe on
//! fd 3, its output prefixed with its name, stopped with SIGTERM then SIGKILL, always reaped.

use std::io::{BufRead, BufReader, Read};
use std::os::fd::{AsRawFd, OwnedFd};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use nix::poll::{PollFd, PollFlags, PollTimeout, poll};
use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

/// The fd number a child finds its readiness pipe on.
const READY_FD: i32 = 3;

/// A running child.
pub struct Running {
    pub name: String,
    pub child: Child,
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
) -> anyhow::Result<Running> {
    let (ready_read, ready_write): (OwnedFd, OwnedFd) =
        nix::unistd::pipe2(nix::fcntl::OFlag::O_CLOEXEC).context("creating a readiness pipe")?;
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
    let mut child =
        cmd.spawn().with_context(|| format!("service `{name}`: cannot start {}", binary.display()))?;
    drop(ready_write);
    if let Some(out) = child.stdout.take() {
        forward_lines(name.to_owned(), out);
    }
    if let Some(err) = child.stderr.take() {
        forward_lines(name.to_owned(), err);
    }
    let mut running = Running { name: name.to_owned(), child };
    match wait_ready(&ready_read, ready_timeout) {
        Ok(()) => Ok(running),
        Err(why) => {
            let status = stop(&mut running, Duration::from_millis(500));
            anyhow::bail!("service `{name}` did not become ready: {why} (then {})", describe(status))
        }
    }
}

fn wait_ready(pipe: &OwnedFd, timeout: Duration) -> Result<(), String> {
    let deadline = Instant::now() + timeout;
    let mut got = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(format!("no readiness within {} ms", timeout.as_millis()));
        }
        let mut fds = [PollFd::new(pipe_fd(pipe), PollFlags::POLLIN)];
        let ms = PollTimeout::try_from(left.as_millis().min(60_000) as i32).unwrap_or(PollTimeout::MAX);
        match poll(&mut fds, ms) {
            Ok(0) => continue,
            Ok(_) => {}
            Err(nix::errno::Errno::EINTR) => continue,
            Err(e) => return Err(format!("waiting for readiness: {e}")),
        }
        let mut buf = [0u8; 16];
        match nix::unistd::read(pipe, &mut buf) {
            Ok(0) => return Err("it exited or closed its readiness pipe first".into()),
            Ok(n) => got.extend_from_slice(&buf[..n]),
            Err(nix::errno::Errno::EINTR) => continue,
            Err(e) => return Err(format!("reading readiness: {e}")),
        }
        if got.starts_with(harvey_runtime::READY_LINE) {
            return Ok(());
        }
    }
}

fn pipe_fd(fd: &OwnedFd) -> std::os::fd::BorrowedFd<'_> {
    use std::os::fd::AsFd;
    fd.as_fd()
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
    let deadline = Instant::now() + grace;
    while Instant::now() < deadline {
        if let Ok(Some(status)) = r.child.try_wait() {
            return status;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    tracing::warn!(service = %r.name, "did not stop within {} ms: SIGKILL", grace.as_millis());
    let _ = kill(group, Signal::SIGKILL);
    r.child.wait().unwrap_or_else(|_| ExitStatus::from_raw(libc::SIGKILL))
}

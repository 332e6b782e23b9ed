//! Starting a process for the keeper: a service in its own process group with its readiness
//! pipe on fd 3 and its output prefixed with its name, or the supervisor with the keeper's line
//! on an agreed descriptor. Both die with the keeper (PDEATHSIG), never with the supervisor.

use std::io::{BufRead, BufReader, Read};
use std::os::fd::{AsRawFd, OwnedFd, RawFd};
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, Stdio};

use crate::link::SpawnSpec;

/// The fd number a service finds its readiness pipe on.
const READY_FD: RawFd = 3;

/// The fd number a supervisor finds its keeper's line on.
pub const KEEPER_FD: RawFd = 3;

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

/// Makes `fd` the child's descriptor `to`, kept open across exec. Runs between fork and exec.
fn inherit(fd: RawFd, to: RawFd) -> std::io::Result<()> {
    // SAFETY: dup2 and fcntl are async-signal-safe.
    let ok =
        unsafe { if fd == to { libc::fcntl(to, libc::F_SETFD, 0) >= 0 } else { libc::dup2(fd, to) >= 0 } };
    if ok { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}

/// Asks the kernel to SIGTERM the calling process when the thread that started it ends.
fn die_with_parent() -> std::io::Result<()> {
    // SAFETY: prctl is async-signal-safe.
    if unsafe { libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) } < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

/// Starts a service; returns the child and the read end of its readiness pipe.
pub fn service(spec: &SpawnSpec) -> std::io::Result<(Child, OwnedFd)> {
    let (ready_read, ready_write): (OwnedFd, OwnedFd) = nix::unistd::pipe2(nix::fcntl::OFlag::O_CLOEXEC)?;
    let write_raw = ready_write.as_raw_fd();
    let mut cmd = Command::new(&spec.binary);
    cmd.args(&spec.args)
        .envs(spec.env.iter().map(|(k, v)| (k.as_str(), v.as_str())))
        .env(harvey_runtime::READY_FD_ENV, READY_FD.to_string())
        .env(harvey_runtime::SUPERVISED_ENV, "1")
        .env_remove(crate::link::KEEPER_FD_ENV)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // SAFETY: only async-signal-safe calls (dup2, fcntl, setpgid, prctl) between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            inherit(write_raw, READY_FD)?;
            if libc::setpgid(0, 0) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            // If the keeper dies, the services must not run on unsupervised.
            die_with_parent()
        });
    }
    let mut child = cmd.spawn()?;
    drop(ready_write);
    if let Some(out) = child.stdout.take() {
        forward_lines(spec.name.clone(), out);
    }
    if let Some(err) = child.stderr.take() {
        forward_lines(spec.name.clone(), err);
    }
    Ok((child, ready_read))
}

/// Starts the supervisor process: `cmd` with the keeper's end of the line on [`KEEPER_FD`].
/// It shares the keeper's output and process group (a terminal's Ctrl-C reaches both).
pub fn supervisor(mut cmd: Command, line: RawFd) -> std::io::Result<Child> {
    let raw = line;
    cmd.env(crate::link::KEEPER_FD_ENV, KEEPER_FD.to_string()).stdin(Stdio::null());
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            inherit(raw, KEEPER_FD)?;
            die_with_parent()
        });
    }
    cmd.spawn()
}

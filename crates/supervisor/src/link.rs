//! The line between the keeper and the supervisor process it keeps alive: a `SOCK_SEQPACKET`
//! socket pair (one message per packet, ordered, closed when either side dies), postcard
//! messages, and descriptors (a child's readiness pipe) passed alongside with `SCM_RIGHTS`.

use std::io::{IoSlice, IoSliceMut};
use std::os::fd::{AsFd, AsRawFd, BorrowedFd, FromRawFd, OwnedFd, RawFd};
use std::path::PathBuf;
use std::time::Duration;

use nix::errno::Errno;
use nix::sys::socket::{
    AddressFamily, ControlMessage, ControlMessageOwned, MsgFlags, SockFlag, SockType, recvmsg, sendmsg,
    socketpair,
};
use serde::{Deserialize, Serialize};

use crate::outcome::Outcome;
use crate::wait::poll_input;

/// The environment variable naming the descriptor a supervisor finds its keeper's socket on.
pub const KEEPER_FD_ENV: &str = "HARVEY_KEEPER_FD";

/// The largest message either side sends (a service's arguments and environment).
const MAX_MESSAGE: usize = 256 * 1024;

/// How to start one service, as the supervisor asks the keeper.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SpawnSpec {
    pub name: String,
    pub binary: PathBuf,
    pub args: Vec<String>,
    pub env: Vec<(String, String)>,
}

/// What a supervisor leaves with its keeper so that its successor can take over.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Memo {
    /// The deterministic clock chain has been started.
    pub clock_started: bool,
    /// The launch's wall-clock limit, as Unix time in milliseconds.
    pub deadline_unix_ms: u64,
}

/// Supervisor to keeper.
#[derive(Debug, Serialize, Deserialize)]
pub enum ToKeeper {
    Spawn(SpawnSpec),
    Remember(Memo),
    /// The launch ended so; the supervisor exits next.
    Ended(Outcome),
}

/// What the keeper knows of the services when a supervisor starts.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Hello {
    /// How many supervisors ran before this one (0: a fresh launch).
    pub predecessors: u32,
    /// Services running now: name and pid.
    pub live: Vec<(String, u32)>,
    /// For each service without a running process, how its last one ended: name, pid, raw
    /// wait status.
    pub exited: Vec<(String, u32, i32)>,
    pub memo: Option<Memo>,
}

/// Keeper to supervisor.
#[derive(Debug, Serialize, Deserialize)]
pub enum ToSupervisor {
    Hello(Hello),
    /// The service is started; its readiness pipe comes with this message.
    Spawned {
        pid: u32,
    },
    SpawnFailed {
        error: String,
    },
    /// A service exited (raw wait status).
    Exited {
        pid: u32,
        status: i32,
    },
}

/// One end of the line.
pub struct Socket(OwnedFd);

impl Socket {
    /// A connected pair, both ends close-on-exec.
    pub fn pair() -> Result<(Socket, Socket), Errno> {
        let (a, b) = socketpair(AddressFamily::Unix, SockType::SeqPacket, None, SockFlag::SOCK_CLOEXEC)?;
        Ok((Socket(a), Socket(b)))
    }

    /// Takes over an inherited descriptor.
    ///
    /// # Safety
    /// `fd` must be an open socket nothing else owns.
    pub unsafe fn from_raw(fd: RawFd) -> Socket {
        // SAFETY: as the caller promises.
        Socket(unsafe { OwnedFd::from_raw_fd(fd) })
    }

    pub fn fd(&self) -> BorrowedFd<'_> {
        self.0.as_fd()
    }

    /// Sends one message, with `fds` alongside.
    pub fn send<T: Serialize>(&self, msg: &T, fds: &[RawFd]) -> std::io::Result<()> {
        let bytes = postcard::to_stdvec(msg).map_err(std::io::Error::other)?;
        let cmsg = [ControlMessage::ScmRights(fds)];
        let cmsgs: &[ControlMessage] = if fds.is_empty() { &[] } else { &cmsg };
        loop {
            match sendmsg::<()>(
                self.0.as_raw_fd(),
                &[IoSlice::new(&bytes)],
                cmsgs,
                MsgFlags::MSG_NOSIGNAL,
                None,
            ) {
                Err(Errno::EINTR) => continue,
                Err(e) => return Err(e.into()),
                Ok(_) => return Ok(()),
            }
        }
    }

    /// Receives one message and the descriptors that came with it; `Ok(None)` if none arrives
    /// within `timeout`, an `UnexpectedEof` error once the other end has closed.
    pub fn recv<T: for<'de> Deserialize<'de>>(
        &self,
        timeout: Option<Duration>,
    ) -> std::io::Result<Option<(T, Vec<OwnedFd>)>> {
        if !poll_input(&[self.fd()], timeout)? {
            return Ok(None);
        }
        let mut buf = vec![0u8; MAX_MESSAGE];
        let mut space = nix::cmsg_space!([RawFd; 4]);
        let (len, fds) = loop {
            let mut iov = [IoSliceMut::new(&mut buf)];
            let got = recvmsg::<()>(
                self.0.as_raw_fd(),
                &mut iov,
                Some(&mut space),
                MsgFlags::MSG_CMSG_CLOEXEC | MsgFlags::MSG_DONTWAIT,
            );
            let msg = match got {
                Err(Errno::EINTR) => continue,
                Err(Errno::EAGAIN) => return Ok(None),
                Err(e) => return Err(e.into()),
                Ok(m) => m,
            };
            let mut fds = Vec::new();
            for c in msg.cmsgs()? {
                if let ControlMessageOwned::ScmRights(raw) = c {
                    // SAFETY: the kernel just installed these descriptors for us.
                    fds.extend(raw.into_iter().map(|fd| unsafe { OwnedFd::from_raw_fd(fd) }));
                }
            }
            break (msg.bytes, fds);
        };
        if len == 0 {
            return Err(std::io::ErrorKind::UnexpectedEof.into());
        }
        let msg = postcard::from_bytes(&buf[..len])
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, format!("keeper line: {e}")))?;
        Ok(Some((msg, fds)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_and_descriptors_cross_the_line() {
        let (a, b) = Socket::pair().expect("pair");
        let (r, w) = nix::unistd::pipe().expect("pipe");
        a.send(&ToSupervisor::Spawned { pid: 42 }, &[r.as_raw_fd()]).expect("send");
        drop(r);
        let (msg, fds) =
            b.recv::<ToSupervisor>(Some(Duration::from_secs(1))).expect("recv").expect("a message");
        assert!(matches!(msg, ToSupervisor::Spawned { pid: 42 }));
        assert_eq!(fds.len(), 1);
        nix::unistd::write(&w, b"x").expect("write");
        let mut got = [0u8; 1];
        assert_eq!(nix::unistd::read(&fds[0], &mut got), Ok(1));
        assert_eq!(&got, b"x");
        assert!(b.recv::<ToSupervisor>(Some(Duration::from_millis(1))).expect("quiet").is_none());
        drop(a);
        let closed = b.recv::<ToSupervisor>(Some(Duration::from_secs(1)));
        assert!(matches!(closed, Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof));
    }

    #[test]
    fn a_garbled_message_is_an_error_not_a_panic() {
        let (a, b) = Socket::pair().expect("pair");
        let raw = a.0.as_raw_fd();
        sendmsg::<()>(raw, &[IoSlice::new(&[0xff, 0xff, 0xff])], &[], MsgFlags::empty(), None).expect("send");
        let got = b.recv::<ToSupervisor>(Some(Duration::from_secs(1)));
        assert!(matches!(got, Err(e) if e.kind() == std::io::ErrorKind::InvalidData));
    }
}

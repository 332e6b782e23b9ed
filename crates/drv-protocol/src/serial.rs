//! Serial-line set-up shared by the bridge and the simulated DRV: raw mode (no echo, no line
//! editing, 8 data bits) and non-blocking reads and writes.

use std::io::{self, Read, Write};
use std::os::fd::AsFd;

use nix::fcntl::{FcntlArg, OFlag, fcntl};
use nix::sys::termios::{SetArg, cfmakeraw, tcgetattr, tcsetattr};

/// Puts a terminal device into raw mode, so bytes pass unaltered in both directions.
pub fn make_raw(fd: impl AsFd) -> io::Result<()> {
    let mut t = tcgetattr(&fd).map_err(io::Error::from)?;
    cfmakeraw(&mut t);
    tcsetattr(&fd, SetArg::TCSANOW, &t).map_err(io::Error::from)
}

/// Makes reads and writes on `fd` return `WouldBlock` instead of waiting.
pub fn set_nonblocking(fd: impl AsFd) -> io::Result<()> {
    let flags = fcntl(&fd, FcntlArg::F_GETFL).map_err(io::Error::from)?;
    let flags = OFlag::from_bits_truncate(flags) | OFlag::O_NONBLOCK;
    fcntl(&fd, FcntlArg::F_SETFL(flags)).map(|_| ()).map_err(io::Error::from)
}

/// Reads everything available now into `buf` (cleared first). `Ok(false)`: the line hung up.
pub fn read_available(port: &mut impl Read, buf: &mut Vec<u8>) -> io::Result<bool> {
    buf.clear();
    let mut chunk = [0u8; 512];
    loop {
        match port.read(&mut chunk) {
            Ok(0) => return Ok(false),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(true),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Writes a whole frame or nothing; `Ok(false)` when the line's buffer is full (the far end is
/// not reading) and the frame was dropped.
pub fn write_frame(port: &mut impl Write, frame: &[u8]) -> io::Result<bool> {
    match port.write(frame) {
        Ok(n) if n == frame.len() => Ok(true),
        Ok(n) => {
            // A partial write of a short frame on a pty is rare; finish it blocking-free.
            port.write_all(&frame[n..])?;
            Ok(true)
        }
        Err(e) if e.kind() == io::ErrorKind::WouldBlock => Ok(false),
        Err(e) => Err(e),
    }
}

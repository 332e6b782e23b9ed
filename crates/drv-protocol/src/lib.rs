//! The Denning DRV serial protocol as Harvey speaks it (see `docs/drv-protocol.md`): ASCII
//! frames `$BODY*CS\r\n` with an XOR checksum, commands from the host and reports from the
//! vehicle, in the DRV's own units (tenths of a foot, tenths of a degree, milliseconds).

mod decoder;
mod frame;
pub mod serial;

pub use decoder::{Decoder, DecoderStats};
pub use frame::{Command, FrameError, Line, NakReason, Report, SONAR_NO_ECHO, encode};

/// Longest frame, `$` to `\n` inclusive; longer runs of bytes are garbage.
pub const MAX_FRAME_LEN: usize = 96;

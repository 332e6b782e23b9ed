//! Harvey's wire types: `#[repr(C)]` zero-copy payloads, their common header and the topic table.
//!
//! Every payload is plain old data that iceoryx2 can place in shared memory (`ZeroCopySend`).
//! Units are SI and appear in field names (`range_m`, `heading_rad`, `stamp_ns`); frames appear
//! in names too (`world_from_robot`). Only `denning-bridge` knows the DRV's own units.
//! This crate does no IO; it depends on iceoryx2's marker trait and derive only.

mod executive;
mod frame;
mod holds;
mod log;
mod payloads;
pub mod topics;
mod vision;

pub use executive::*;
pub use frame::{Encoding, FrameHeader};
pub use iceoryx2_bb_derive_macros::ZeroCopySend;
pub use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;
pub use log::{LOG_NAME_BYTES, LOG_TEXT_BYTES, LogLevel, LogLine};
pub use payloads::*;
pub use topics::{FrameTopic, Qos, Topic};
pub use vision::*;

/// The header every message starts with: a per-publisher sequence number and the time the
/// message is about (simulated or sensor time, never the wall clock of the publisher).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, ZeroCopySend, serde::Serialize, serde::Deserialize)]
#[repr(C)]
#[type_name("harvey_msgs/Header")]
pub struct Header {
    pub seq: u64,
    pub stamp_ns: u64,
}

impl Header {
    pub const fn new(seq: u64, stamp_ns: u64) -> Self {
        Self { seq, stamp_ns }
    }
}

/// A message type: a payload with a [`Header`] and a stable name shared by every process.
pub trait Message: ZeroCopySend + Copy + Default + core::fmt::Debug + 'static {
    fn header(&self) -> &Header;
}

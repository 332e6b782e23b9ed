//! Harvey's MCAP recordings: the one crate that knows how a run is written and read.
//!
//! A recording is an MCAP file with the ROS 2 conventions (profile `ros2`, `ros2msg` schemas,
//! `cdr` payloads), its log times the messages' own stamps. It carries as attachments the world
//! file of the run (with a `harvey.world` metadata record: its name and the seed that placed its
//! poles), the launch file and the data files the launch names, so that it replays on its own;
//! the recorder's per-topic counts are a `harvey.recorder` metadata record.
//!
//! [`Recorder`] writes one, [`Recording`] reads one back; [`compare`], [`recover`] and
//! [`export`] (to a Rerun file, drawn by [`rrd`]) are the offline tools; [`ticks`] splits a
//! recording's inputs into the ticks a replay feeds.
//!
//! Every reader reads through [`Recording`], which never trusts the bytes: each record's length
//! is checked against what the file has left and its length fields against its own end before
//! the mcap crate parses it (`records.rs`, `fields.rs`), each chunk's size against limits and its
//! CRC before its records are taken (`chunk.rs`), the data and summary sections' CRCs where the
//! file has them (`stream.rs`, `summary.rs`); a damaged file is an error naming the file, the byte
//! offset and the [`Damage`], never a panic or an allocation of what a flipped bit claims.

mod attachments;
pub mod carry_over;
mod chunk;
pub mod compare;
mod damage;
pub mod data_files;
pub mod derive;
pub mod draw;
mod error;
pub mod export;
mod fields;
pub mod reader;
mod records;
pub mod recover;
pub mod rrd;
mod salvage;
pub mod same_file;
pub mod schemas;
mod stream;
mod summary;
pub mod ticks;
pub mod topics;
pub mod writer;

pub use attachments::DataFile;
pub use chunk::MAX_CHUNK_BYTES;
pub use damage::Damage;
pub use data_files::DATA_MEDIA_TYPE;
pub use error::RecordingError;
pub use reader::{Message, Recording};
pub use writer::{Channel, ChannelStats, ChunkCompression, Recorder};

/// Media type of the world file attached to a recording.
pub const WORLD_MEDIA_TYPE: &str = "application/toml; harvey-world";
/// Name of the metadata record that goes with the world attachment: its file name and the seed.
pub const WORLD_METADATA: &str = "harvey.world";
/// Media type of the launch file (services and mission) attached to a recording: what
/// `harvey replay` runs again.
pub const LAUNCH_MEDIA_TYPE: &str = "application/toml; harvey-launch";
/// Name of the metadata record of the recorder's per-topic counts: `<topic>.messages` and
/// `<topic>.seq_gaps`.
pub const RECORDER_METADATA: &str = "harvey.recorder";
/// Name of the metadata record `harvey recover` adds: the source, messages salvaged, where it
/// stopped.
pub const RECOVER_METADATA: &str = "harvey.recover";

//! What can go wrong with a recording: every error names the file and says what is wrong with
//! it, a damaged one also where (the byte offset and the [`Damage`]). The MCAP side is
//! [`RecordingError`]; the Rerun side is [`crate::rrd::RrdError`]; a launch file's list of data
//! files is [`crate::data_files::DataFilesError`].

use std::error::Error;
use std::path::PathBuf;

use harvey_cdr::CdrError;

use crate::damage::Damage;

/// `e` and the errors beneath it, `: `-separated (what `anyhow`'s `{:#}` prints), so that a
/// cause's own cause is not lost when it is shown inside another message.
pub(crate) fn chain(e: &dyn Error) -> String {
    let mut out = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        out += &format!(": {cause}");
        next = cause.source();
    }
    out
}

/// A failure reading, writing, comparing, salvaging or exporting an MCAP recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    // Files.
    /// The file could not be read.
    #[error("reading {file}: {cause}")]
    Read { file: PathBuf, cause: std::io::Error },
    /// The file could not be created.
    #[error("recording {file}: {cause}")]
    Create { file: PathBuf, cause: std::io::Error },

    // Writing (`writer.rs`, `recover.rs`, `export.rs`).
    /// The MCAP writer failed.
    #[error("recording {file}: {}", chain(cause))]
    Write { file: PathBuf, cause: mcap::McapError },

    /// An output path that is the input itself (through a symlink or a hard link too): a tool
    /// never writes over what it reads.
    #[error("{output} is {input} itself: refusing to overwrite the recording read")]
    Overwrite { input: PathBuf, output: PathBuf },

    // Reading messages (`reader.rs`, `stream.rs`, `ticks.rs`).
    /// Not even the magic bytes of an MCAP file at the start.
    #[error("{file}: not an MCAP file (no magic bytes at the start)")]
    NoMagic { file: PathBuf },
    /// The messages stop being readable (a writer killed mid-chunk, a damaged file): the damage,
    /// and the byte offset of the record it is in.
    #[error("{file}: corrupt after {after} messages, at byte {offset}: {what}")]
    Corrupt { file: PathBuf, after: usize, offset: u64, what: Damage },
    /// The data section does not check (its CRC, or a record that runs past the file): what a
    /// record without a CRC of its own (metadata) is read only after.
    #[error("{file}: damaged at byte {offset}: {what}")]
    Damaged { file: PathBuf, offset: u64, what: Damage },
    /// A recorded message does not decode as its topic's type.
    #[error("{file}: message {index} on /{topic}: {cause}")]
    Decode { file: PathBuf, index: usize, topic: String, cause: CdrError },
    /// A recorded input is stamped before the one recorded ahead of it.
    #[error("{file}: message {index} on /{topic} goes back in time")]
    BackInTime { file: PathBuf, index: usize, topic: String },

    // The summary, attachments and metadata (`reader.rs`).
    /// The summary section is there but does not read.
    #[error("{file}: no readable summary (run `harvey recover` on it first): at byte {offset}: {what}")]
    BadSummary { file: PathBuf, offset: u64, what: Damage },
    /// No summary section (the writer never finished the file, or the footer says there is none).
    #[error("{file}: no summary (run `harvey recover` on it first)")]
    NoSummary { file: PathBuf },
    /// No attachment of a media type a tool needs.
    #[error("{file}: no `{media_type}` attachment: was it recorded by `harvey run`?")]
    NoAttachment { file: PathBuf, media_type: &'static str },
    /// An attachment does not read.
    #[error("{file}: attachment `{name}`, at byte {offset}: {what}")]
    Attachment { file: PathBuf, name: String, offset: u64, what: Damage },
    /// A text attachment (launch or world file) is not UTF-8.
    #[error("{file}: attachment `{name}` is not text: {cause}")]
    NotText { file: PathBuf, name: String, cause: std::str::Utf8Error },
    /// A data attachment whose name would put it outside the replay's run folder.
    #[error("{file}: data attachment `{name}` is not a relative path inside the run folder")]
    DataName { file: PathBuf, name: String },
    /// A metadata record does not read.
    #[error("{file}: `{name}` metadata, at byte {offset}: {what}")]
    Metadata { file: PathBuf, name: &'static str, offset: u64, what: Damage },
    /// The `harvey.world` metadata's seed is not a number.
    #[error("{file}: `{}` metadata: seed `{text}`: {cause}", crate::WORLD_METADATA)]
    Seed { file: PathBuf, text: String, cause: std::num::ParseIntError },
    /// The attached world file does not load.
    #[error("{file}: world attachment: {cause}")]
    World { file: PathBuf, cause: harvey_world::WorldError },
    /// The attached world's `[poles]` cannot be placed.
    #[error("{file}: world attachment `{name}`: {cause}")]
    Poles { file: PathBuf, name: String, cause: harvey_world::PoleError },

    // Export (`export.rs`).
    /// A message could not be drawn into the Rerun file.
    #[error("{file}: message {index} on /{topic}: {cause}")]
    Draw { file: PathBuf, index: usize, topic: String, cause: Box<crate::draw::DrawError> },
    /// The Rerun file failed.
    #[error(transparent)]
    Rrd(Box<crate::rrd::RrdError>),
}

impl From<crate::rrd::RrdError> for RecordingError {
    fn from(e: crate::rrd::RrdError) -> Self {
        Self::Rrd(Box::new(e))
    }
}

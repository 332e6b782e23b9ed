//! What is wrong with the bytes of a damaged MCAP file, found by the checked readers
//! (`records.rs`, `fields.rs`, `chunk.rs`, `summary.rs`, `stream.rs`) before anything is handed
//! to the mcap crate. Where it is, is the error's business: [`crate::RecordingError::Corrupt`]
//! and its siblings carry the byte offset beside it.

use crate::error::chain;

/// The damage found at one place in a file.
#[derive(Debug, thiserror::Error)]
pub enum Damage {
    /// Fewer bytes left than a record's opcode and length need (a file cut short).
    #[error("{left} bytes left, too few for a record's opcode and length")]
    Cut { left: u64 },
    /// A record claims more bytes than there are left of the file (or of its chunk).
    #[error("record 0x{opcode:02x} claims {claims} bytes, {left} are left")]
    PastEnd { opcode: u8, claims: u64, left: u64 },
    /// A length inside a record (a string, a map, the data of an attachment) runs past the record.
    #[error("record 0x{opcode:02x}: a length field at byte {at} of it runs past its end")]
    Field { opcode: u8, at: usize },
    /// A record that does not parse.
    #[error("record 0x{opcode:02x} does not parse: {}", chain(cause))]
    Parse { opcode: u8, cause: mcap::McapError },
    /// The mcap crate panicked on these bytes (the last line of defence: caught, not shown).
    #[error("record 0x{opcode:02x} made the MCAP parser fail: {message}")]
    Panicked { opcode: u8, message: String },
    /// A chunk claims to decompress to more than its bytes could, or than any chunk may.
    #[error("chunk claims {claims} bytes decompressed from {compressed}, at most {cap} may be")]
    ChunkTooLarge { claims: u64, compressed: u64, cap: u64 },
    /// A chunk's data does not decompress to the size it claims.
    #[error("chunk decompresses to {got} bytes, not the {claims} it claims")]
    ChunkSize { claims: u64, got: u64 },
    /// A chunk's data does not decompress.
    #[error("chunk does not decompress: {0}")]
    Decompress(String),
    /// A chunk compressed with something this reader does not decode.
    #[error("chunk compressed with `{0}`, which is not supported")]
    Compression(String),
    /// The chunk's records are not what its CRC says they were.
    #[error("chunk CRC does not match: {saved:08x} recorded, {calculated:08x} read")]
    ChunkCrc { saved: u32, calculated: u32 },
    /// The data section is not what its CRC (in the data end record) says it was.
    #[error("data section CRC does not match: {saved:08x} recorded, {calculated:08x} read")]
    DataCrc { saved: u32, calculated: u32 },
    /// The summary section is not what its CRC (in the footer) says it was.
    #[error("summary section CRC does not match: {saved:08x} recorded, {calculated:08x} read")]
    SummaryCrc { saved: u32, calculated: u32 },
    /// A record inside a chunk is damaged; `at` is its offset in the decompressed records.
    #[error("record at byte {at} of the chunk's records: {what}")]
    InChunk { at: u64, what: Box<Damage> },
    /// A message on a channel no channel record defined (before it).
    #[error("message on channel {channel}, which no channel record defines")]
    UnknownChannel { channel: u16 },
    /// Schema and channel records that do not link (an unknown schema, a conflicting redefinition).
    #[error("{}", chain(.0))]
    Link(mcap::McapError),
    /// No footer record and end magic where the file ends.
    #[error("no footer and end magic at the end of the file")]
    NoFooter,
    /// The footer's offsets point outside the file.
    #[error("the footer's summary start {start} is outside the file")]
    SummaryStart { start: u64 },
    /// The summary section's records do not end where the footer starts.
    #[error("the summary section's records end at byte {end}, not at the footer")]
    SummaryEnd { end: u64 },
    /// The data section ends without a data end record (and so without a summary or footer).
    #[error("the file ends without a data end record")]
    NoDataEnd,
    /// An index record points at bytes outside the file, or at another kind of record.
    #[error("index points at {what} (bytes {offset}..+{length})")]
    BadIndex { what: &'static str, offset: u64, length: u64 },
}

impl Damage {
    /// The damage of a record inside a chunk, at `at` in the chunk's decompressed records.
    pub(crate) fn in_chunk(at: u64, what: Damage) -> Self {
        Self::InChunk { at, what: Box::new(what) }
    }
}

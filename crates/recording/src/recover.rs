//! `harvey recover`: salvages a recording whose writer died (SIGKILL, power loss) or whose bytes
//! are damaged into a valid MCAP file: every message of every chunk whose CRC checks (`salvage.rs`),
//! the attachments whose CRC checks, the metadata, in order; a message outside chunks only when
//! the data section's CRC vouches for it. What the dead writer had not yet flushed is gone, a
//! damaged chunk is skipped (never written again under a fresh CRC); how far the salvage got, and
//! what it skipped where, is reported.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use mcap::records::Metadata;

use crate::same_file::refuse_overwrite;
use crate::{RECOVER_METADATA, Recording, RecordingError, salvage};

/// What was salvaged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Salvage {
    pub messages: u64,
    pub attachments: u64,
    /// File offsets of the chunks skipped: their CRC did not check (or was 0, and the data
    /// section's CRC did not vouch for them either), or their records did not parse or link to a
    /// channel.
    pub damaged_chunks: Vec<u64>,
    /// File offsets of the other records skipped: attachments whose CRC does not check, records
    /// that do not parse or link, and the records nothing vouches for: schemas, channels and
    /// messages outside chunks (and attachments whose CRC is 0) when the data section's CRC is
    /// not there to check them, or does not match.
    pub damaged_records: Vec<u64>,
    /// The data section's CRC does not match though every chunk and attachment does: a record
    /// without a CRC of its own (metadata, a message index) is damaged, and was copied.
    pub bad_data_crc: bool,
    /// Why reading stopped before a proper end, if it did.
    pub stopped_at: Option<String>,
}

impl Salvage {
    /// Whether the input read to its end with nothing skipped and every CRC matching.
    pub fn is_whole(&self) -> bool {
        self.damaged_chunks.is_empty()
            && self.damaged_records.is_empty()
            && !self.bad_data_crc
            && self.stopped_at.is_none()
    }

    /// What was skipped and lost, for the line `harvey recover` prints after its counts: empty
    /// for a whole input.
    pub fn losses(&self) -> String {
        let offsets = |o: &[u64]| o.iter().map(u64::to_string).collect::<Vec<_>>().join(", ");
        let plural = |n: usize, what: &str| format!("{n} damaged {what}{}", if n == 1 { "" } else { "s" });
        let mut out = String::new();
        for (skipped, what) in [(&self.damaged_chunks, "chunk"), (&self.damaged_records, "record")] {
            if !skipped.is_empty() {
                let at = if skipped.len() == 1 { "offset" } else { "offsets" };
                out += &format!(", {} skipped at {at} {}", plural(skipped.len(), what), offsets(skipped));
            }
        }
        if self.bad_data_crc {
            out += ", but the data section's CRC does not match: a record without a CRC of its own \
                    (metadata, an index) is damaged";
        }
        if let Some(e) = &self.stopped_at {
            out += &format!(" (the rest was lost: {e})");
        }
        out
    }
}

/// Copies what can be read and verified of `input` into a new, complete MCAP file at `output`,
/// which may not be `input` itself.
pub fn recover(input: &Path, output: &Path) -> Result<Salvage, RecordingError> {
    refuse_overwrite(input, output)?;
    let recording = Recording::open(input)?;
    let bytes = recording.bytes();
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(RecordingError::NoMagic { file: input.to_owned() });
    }
    // What alone vouches for the records without a CRC of their own.
    let vouched = salvage::data_crc_vouches(bytes);
    let records = salvage::records(bytes, vouched);
    let out =
        File::create(output).map_err(|cause| RecordingError::Create { file: output.to_owned(), cause })?;
    let oerr = |cause| RecordingError::Write { file: output.to_owned(), cause };
    let mut w = mcap::WriteOptions::new()
        .profile(&records.profile)
        .library(concat!("harvey recover ", env!("CARGO_PKG_VERSION")))
        .create(BufWriter::new(out))
        .map_err(oerr)?;
    for a in &records.attachments {
        w.attach(a).map_err(oerr)?;
    }
    for m in &records.metadata {
        w.write_metadata(m).map_err(oerr)?;
    }
    let mut messages = 0;
    // Channels a damaged chunk defined are still known from the summary, when its CRC checks.
    let mut salvaged = salvage::Messages::new(bytes, recording.summary_if_any(), vouched);
    for chunk in salvaged.by_ref() {
        for m in &chunk {
            w.write(m).map_err(oerr)?;
            messages += 1;
        }
    }
    let mut damaged_records = records.damaged;
    damaged_records.extend(&salvaged.damaged_records);
    damaged_records.sort_unstable();
    let s = Salvage {
        messages,
        attachments: records.attachments.len() as u64,
        bad_data_crc: records.bad_data_crc
            && salvaged.damaged_chunks.is_empty()
            && damaged_records.is_empty(),
        damaged_chunks: salvaged.damaged_chunks,
        damaged_records,
        stopped_at: records.stopped_at,
    };
    w.write_metadata(&metadata(input, &s)).map_err(oerr)?;
    w.finish().map_err(oerr)?;
    Ok(s)
}

/// The `harvey.recover` record: the source, messages salvaged, where it stopped, and (only when
/// there were any) the offsets of what was skipped.
fn metadata(input: &Path, s: &Salvage) -> Metadata {
    let mut md = std::collections::BTreeMap::new();
    md.insert("source".to_owned(), input.display().to_string());
    md.insert("messages".to_owned(), s.messages.to_string());
    md.insert("stopped_at".to_owned(), s.stopped_at.clone().unwrap_or_else(|| "end of file".into()));
    let offsets = |o: &[u64]| o.iter().map(u64::to_string).collect::<Vec<_>>().join(",");
    if !s.damaged_chunks.is_empty() {
        md.insert("damaged_chunks".to_owned(), offsets(&s.damaged_chunks));
    }
    if !s.damaged_records.is_empty() {
        md.insert("damaged_records".to_owned(), offsets(&s.damaged_records));
    }
    if s.bad_data_crc {
        md.insert("bad_data_crc".to_owned(), "true".to_owned());
    }
    Metadata { name: RECOVER_METADATA.into(), metadata: md }
}

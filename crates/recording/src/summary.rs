//! The footer and the summary section of a recording, and the attachment and metadata records its
//! indexes point at, read without trusting them: the footer must be where the file ends, the
//! summary's CRC must match before its records are taken, and an index must point at one whole
//! record of its kind inside the file. What mcap's `Summary::read` and `read::attachment` do,
//! with the checks.

use std::borrow::Cow;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use mcap::read::ChannelAccumulator;
use mcap::records::{AttachmentIndex, Metadata, MetadataIndex, Record, op};
use mcap::{Attachment, Schema, Summary};

use crate::damage::Damage;
use crate::records::{OPCODE_AND_LENGTH, record_at};

/// Damage at a byte offset of the file.
#[derive(Debug)]
pub(crate) struct Located {
    pub offset: u64,
    pub what: Damage,
}

pub(crate) fn located(offset: usize, what: Damage) -> Located {
    Located { offset: offset as u64, what }
}

/// The footer record's body: summary start, summary offset start, summary CRC.
const FOOTER_BODY: usize = 8 + 8 + 4;
/// The footer record and the end magic.
const FOOTER_AND_MAGIC: usize = OPCODE_AND_LENGTH + FOOTER_BODY + 8;

/// The footer: where it starts, and what it says.
pub(crate) struct Footer {
    pub offset: usize,
    pub summary_start: u64,
    pub summary_crc: u32,
}

fn le_u64(bytes: &[u8], at: usize) -> u64 {
    let mut le = [0u8; 8];
    le.copy_from_slice(&bytes[at..at + 8]);
    u64::from_le_bytes(le)
}

/// The footer at the end of `bytes`, before the end magic.
pub(crate) fn footer(bytes: &[u8]) -> Result<Footer, Located> {
    let no_footer = || located(bytes.len(), Damage::NoFooter);
    if bytes.len() < mcap::MAGIC.len() + FOOTER_AND_MAGIC || !bytes.ends_with(mcap::MAGIC) {
        return Err(no_footer());
    }
    let offset = bytes.len() - FOOTER_AND_MAGIC;
    if bytes[offset] != op::FOOTER || le_u64(bytes, offset + 1) != FOOTER_BODY as u64 {
        return Err(no_footer());
    }
    let body = offset + OPCODE_AND_LENGTH;
    let mut crc = [0u8; 4];
    crc.copy_from_slice(&bytes[body + 16..body + 20]);
    Ok(Footer { offset, summary_start: le_u64(bytes, body), summary_crc: u32::from_le_bytes(crc) })
}

/// Checks the summary CRC (when the footer has one): it covers the summary section from `start`
/// to the footer's summary CRC field.
pub(crate) fn check_summary_crc(bytes: &[u8], start: usize, footer: &Footer) -> Result<(), Located> {
    let saved = footer.summary_crc;
    let covered = bytes.get(start..footer.offset + OPCODE_AND_LENGTH + 16).unwrap_or_default();
    let calculated = crc32fast::hash(covered);
    if saved != 0 && calculated != saved {
        return Err(located(footer.offset, Damage::SummaryCrc { saved, calculated }));
    }
    Ok(())
}

/// The summary section, `None` when the footer says there is none.
pub(crate) fn read(bytes: &[u8]) -> Result<Option<Summary>, Located> {
    let footer = footer(bytes)?;
    // No summary, says the footer: its CRC then covers the footer's own fields alone (so that a
    // summary start zeroed by damage is not taken for "none").
    if footer.summary_start == 0 {
        check_summary_crc(bytes, footer.offset, &footer)?;
        return Ok(None);
    }
    let start = match usize::try_from(footer.summary_start) {
        Ok(start) if start >= mcap::MAGIC.len() && start <= footer.offset => start,
        _ => return Err(located(footer.offset, Damage::SummaryStart { start: footer.summary_start })),
    };
    check_summary_crc(bytes, start, &footer)?;
    let section = &bytes[..footer.offset];
    let (mut summary, mut channels) = (Summary::default(), ChannelAccumulator::default());
    let mut at = start;
    while at < section.len() {
        let raw = record_at(section, at).map_err(|what| located(at, what))?;
        let here = |what| located(raw.offset, what);
        match raw.parse().map_err(here)? {
            Record::AttachmentIndex(index) => summary.attachment_indexes.push(index),
            Record::MetadataIndex(index) => summary.metadata_indexes.push(index),
            Record::Statistics(statistics) => summary.stats = Some(statistics),
            Record::Channel(channel) => {
                let id = channel.id;
                channels.add_channel(channel).map_err(|e| here(Damage::Link(e)))?;
                if let (Entry::Vacant(slot), Some(linked)) = (summary.channels.entry(id), channels.get(id)) {
                    slot.insert(linked);
                }
            }
            Record::Schema { header, data } => {
                let schema = Schema {
                    id: header.id,
                    name: header.name.clone(),
                    encoding: header.encoding.clone(),
                    data: Cow::Owned(data.to_vec()),
                };
                channels
                    .add_schema(header, Cow::Owned(data.into_owned()))
                    .map_err(|e| here(Damage::Link(e)))?;
                summary.schemas.entry(schema.id).or_insert_with(|| Arc::new(schema));
            }
            Record::ChunkIndex(index) => summary.chunk_indexes.push(index),
            _ => {}
        }
        at = raw.end;
    }
    Ok(Some(summary))
}

/// The one record `offset`/`length` point at, which must be of kind `opcode`.
fn indexed(bytes: &[u8], offset: u64, length: u64, opcode: u8) -> Result<Record<'_>, Located> {
    let what = match opcode {
        op::ATTACHMENT => "no attachment",
        _ => "no metadata record",
    };
    let bad = |at| located(at, Damage::BadIndex { what, offset, length });
    let (start, end) = match (usize::try_from(offset), offset.checked_add(length).map(usize::try_from)) {
        (Ok(start), Some(Ok(end))) if start <= end && end <= bytes.len() => (start, end),
        _ => return Err(bad(bytes.len())),
    };
    let slice = &bytes[start..end];
    let raw = record_at(slice, 0).map_err(|what| located(start, what))?;
    if raw.opcode != opcode || raw.end != slice.len() {
        return Err(bad(start));
    }
    raw.parse().map_err(|what| located(start, what))
}

/// The attachment `index` points at; its CRC, when it has one, is checked by mcap's parse.
pub(crate) fn attachment<'a>(bytes: &'a [u8], index: &AttachmentIndex) -> Result<Attachment<'a>, Located> {
    match indexed(bytes, index.offset, index.length, op::ATTACHMENT)? {
        Record::Attachment { header, data, .. } => Ok(Attachment {
            log_time: header.log_time,
            create_time: header.create_time,
            name: header.name,
            media_type: header.media_type,
            data,
        }),
        _ => Err(located(
            bytes.len(),
            Damage::BadIndex { what: "no attachment", offset: index.offset, length: index.length },
        )),
    }
}

/// The metadata record `index` points at.
pub(crate) fn metadata(bytes: &[u8], index: &MetadataIndex) -> Result<Metadata, Located> {
    match indexed(bytes, index.offset, index.length, op::METADATA)? {
        Record::Metadata(m) => Ok(m),
        _ => Err(located(
            bytes.len(),
            Damage::BadIndex { what: "no metadata record", offset: index.offset, length: index.length },
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An MCAP file of one attachment, with or without a summary section.
    fn file(summary: bool) -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        let options = mcap::WriteOptions::new().emit_summary_records(summary).emit_summary_offsets(summary);
        let mut w = options.create(&mut out).expect("writer");
        let data = std::borrow::Cow::Borrowed(&b"text"[..]);
        let a = Attachment { log_time: 0, create_time: 0, name: "a".into(), media_type: "t".into(), data };
        w.attach(&a).expect("attach");
        w.finish().expect("finish");
        drop(w);
        out.into_inner()
    }

    #[test]
    fn a_summary_reads_as_mcap_reads_it_and_one_zeroed_by_damage_is_not_taken_for_none() {
        let bytes = file(true);
        let summary = read(&bytes).expect("reads").expect("a summary");
        assert_eq!(Some(summary.clone()), mcap::Summary::read(&bytes).expect("mcap reads it"));
        let a = attachment(&bytes, &summary.attachment_indexes[0]).expect("the attachment");
        assert_eq!((a.name.as_str(), &a.data[..]), ("a", &b"text"[..]));

        assert!(read(&file(false)).expect("reads").is_none(), "none, says the footer");
        let mut zeroed = bytes.clone();
        let start = footer(&bytes).expect("a footer").offset + OPCODE_AND_LENGTH;
        zeroed[start..start + 8].fill(0);
        let e = read(&zeroed).expect_err("damaged");
        assert!(matches!(e.what, Damage::SummaryCrc { .. }), "{:?}", e.what);
        assert!(matches!(read(&bytes[..bytes.len() - 1]), Err(Located { what: Damage::NoFooter, .. })));
    }

    #[test]
    fn an_index_pointing_outside_the_file_or_at_another_record_is_damage() {
        let bytes = file(true);
        let mut index = read(&bytes).expect("reads").expect("a summary").attachment_indexes[0].clone();
        index.length = u64::MAX - index.offset + 1; // offset + length overflows
        assert!(matches!(attachment(&bytes, &index), Err(Located { what: Damage::BadIndex { .. }, .. })));
        index.offset = 8; // the header record
        index.length = 9 + u64::from_le_bytes(bytes[9..17].try_into().expect("8 bytes"));
        assert!(matches!(
            attachment(&bytes, &index),
            Err(Located { what: Damage::BadIndex { .. }, offset: 8 })
        ));
    }
}

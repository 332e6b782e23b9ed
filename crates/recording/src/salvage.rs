//! What `harvey recover` can take from a recording whose writer died or whose bytes are damaged,
//! read through the crate's checked readers: the data section's records up to its end (or to the
//! first record that runs past the file), and of those only what a CRC vouches for. A chunk is
//! taken when its own CRC checks and its records all parse and link; an attachment when its own
//! CRC checks. A record without a CRC of its own (a schema, channel or message outside chunks, a
//! chunk or attachment whose CRC is 0, "not computed") is taken only when the data section's CRC
//! is there and checks: a message index whose opcode a flipped bit made a message's, or the bytes
//! a damaged length makes the walk land in, parse as well as a real record does. What is skipped
//! is kept by offset; nothing that could not be verified is handed on to be written with a fresh
//! CRC (the metadata records, which nothing but the data section's CRC covers, are copied, and a
//! data section CRC that does not match is reported).

use mcap::read::ChannelAccumulator;
use mcap::records::{Metadata, Record, op};

use crate::chunk;
use crate::records::{DataSection, Raw, record_at};

/// What the data section holds besides messages.
pub(crate) struct Records<'a> {
    pub profile: String,
    pub attachments: Vec<mcap::Attachment<'a>>,
    pub metadata: Vec<Metadata>,
    /// Offsets of the records skipped: attachments whose CRC does not check (or is 0, with nothing
    /// else to vouch for them), records that do not parse.
    pub damaged: Vec<u64>,
    /// Where and why the data section stopped before its data end record.
    pub stopped_at: Option<String>,
    /// Whether the data end record's CRC does not match the data section.
    pub bad_data_crc: bool,
}

/// Whether the data section's CRC vouches for every record of it: the data end record is reached,
/// and its CRC is not 0 ("not computed") and matches the bytes before it.
pub(crate) fn data_crc_vouches(bytes: &[u8]) -> bool {
    for raw in DataSection::new(bytes) {
        let Ok(raw) = raw else { return false };
        if raw.opcode == op::DATA_END {
            let Ok(Record::DataEnd(end)) = raw.parse() else { return false };
            let saved = end.data_section_crc;
            return saved != 0 && saved == crc32fast::hash(&bytes[..raw.offset]);
        }
    }
    false
}

/// The header, attachments and metadata of the data section, and where it stops. An attachment
/// without a CRC (0) is taken only when `vouched`: the data section's CRC checks
/// ([`data_crc_vouches`]).
pub(crate) fn records(bytes: &[u8], vouched: bool) -> Records<'_> {
    let mut out = Records {
        profile: String::new(),
        attachments: Vec::new(),
        metadata: Vec::new(),
        damaged: Vec::new(),
        stopped_at: None,
        bad_data_crc: false,
    };
    for raw in DataSection::new(bytes) {
        let raw = match raw {
            Ok(raw) => raw,
            Err((at, what)) => {
                out.stopped_at = Some(format!("at byte {at}: {what}"));
                break;
            }
        };
        if !matches!(raw.opcode, op::HEADER | op::ATTACHMENT | op::METADATA | op::DATA_END) {
            continue;
        }
        match raw.parse() {
            Ok(Record::Header(h)) => out.profile = h.profile,
            // mcap has checked a CRC that is not 0.
            Ok(Record::Attachment { header, data, crc }) if crc != 0 || vouched => {
                out.attachments.push(mcap::Attachment {
                    log_time: header.log_time,
                    create_time: header.create_time,
                    name: header.name,
                    media_type: header.media_type,
                    data,
                });
            }
            Ok(Record::Attachment { .. }) => out.damaged.push(raw.offset as u64),
            Ok(Record::Metadata(m)) => out.metadata.push(m),
            Ok(Record::DataEnd(end)) => {
                let saved = end.data_section_crc;
                out.bad_data_crc = saved != 0 && saved != crc32fast::hash(&bytes[..raw.offset]);
            }
            Ok(_) => {}
            Err(_) => out.damaged.push(raw.offset as u64),
        }
    }
    out
}

/// The messages of the data section, a verified chunk's worth (or one vouched-for message outside
/// a chunk) at a time; the chunks and records skipped are counted by offset.
pub(crate) struct Messages<'a> {
    records: DataSection<'a>,
    channels: ChannelAccumulator<'static>,
    /// Whether the data section's CRC checks ([`data_crc_vouches`]): what alone vouches for the
    /// records outside chunks, and for a chunk whose CRC is 0.
    vouched: bool,
    /// Offsets of the chunks skipped.
    pub damaged_chunks: Vec<u64>,
    /// Offsets of schema, channel and message records outside chunks that were skipped: they do
    /// not parse or link, or (all of them) the data section's CRC does not vouch for them.
    pub damaged_records: Vec<u64>,
}

impl<'a> Messages<'a> {
    /// The messages of `bytes`, linked to the channels of `summary` (when it reads and had a CRC
    /// to check it by) as well as to those the file defines as it goes: a chunk that defined a
    /// channel may be the damaged one. `vouched`: whether the data section's CRC checks.
    pub fn new(bytes: &'a [u8], summary: Option<&mcap::Summary>, vouched: bool) -> Self {
        // `summary::read` checks the summary's CRC unless it is 0; then nothing vouches for it.
        let checked = crate::summary::footer(bytes).is_ok_and(|f| f.summary_crc != 0);
        let channels = summary.filter(|_| checked).map(ChannelAccumulator::from_summary).unwrap_or_default();
        Self {
            records: DataSection::new(bytes),
            channels,
            vouched,
            damaged_chunks: Vec::new(),
            damaged_records: Vec::new(),
        }
    }

    /// The messages of a chunk that verifies (by its own CRC, or by the data section's when its
    /// own is 0), parses and links throughout; `None` when it does not.
    fn chunk(&mut self, raw: Raw<'_>) -> Option<Vec<mcap::Message<'static>>> {
        let Ok(Record::Chunk { header, data }) = raw.parse() else { return None };
        let opened = chunk::open(&header, &data).ok().filter(|o| o.verified || self.vouched)?;
        let mut parsed = Vec::new();
        let mut at = 0;
        while at < opened.records.len() {
            let inner = record_at(&opened.records, at).ok()?;
            parsed.push(inner.parse().ok()?);
            at = inner.end;
        }
        let mut messages = Vec::new();
        for record in parsed {
            if let Some(m) = link(&mut self.channels, record).ok()? {
                messages.push(m);
            }
        }
        Some(messages)
    }
}

/// Takes a schema or channel record into `channels`, links a message to its channel.
fn link(
    channels: &mut ChannelAccumulator<'static>,
    record: Record<'_>,
) -> Result<Option<mcap::Message<'static>>, ()> {
    match record {
        Record::Schema { header, data } => {
            channels.add_schema(header, data.into_owned().into()).map_err(drop)?
        }
        Record::Channel(channel) => channels.add_channel(channel).map_err(drop)?,
        Record::Message { header, data } => {
            let channel = channels.get(header.channel_id).ok_or(())?;
            return Ok(Some(mcap::Message {
                channel,
                sequence: header.sequence,
                log_time: header.log_time,
                publish_time: header.publish_time,
                data: data.into_owned().into(),
            }));
        }
        _ => {}
    }
    Ok(None)
}

impl Iterator for Messages<'_> {
    type Item = Vec<mcap::Message<'static>>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let raw = self.records.next()?.ok()?;
            match raw.opcode {
                op::CHUNK => match self.chunk(raw) {
                    Some(messages) => return Some(messages),
                    None => self.damaged_chunks.push(raw.offset as u64),
                },
                // No CRC of their own: only the data section's can vouch for them.
                op::SCHEMA | op::CHANNEL | op::MESSAGE if !self.vouched => {
                    self.damaged_records.push(raw.offset as u64);
                }
                op::SCHEMA | op::CHANNEL | op::MESSAGE => {
                    match raw.parse().map_err(drop).and_then(|r| link(&mut self.channels, r)) {
                        Ok(Some(message)) => return Some(vec![message]),
                        Ok(None) => {}
                        Err(()) => self.damaged_records.push(raw.offset as u64),
                    }
                }
                _ => {}
            }
        }
    }
}

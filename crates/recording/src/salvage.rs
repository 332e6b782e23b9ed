//! What `harvey recover` can take from a recording whose writer died or whose bytes are damaged,
//! read through the crate's checked readers: the data section's records up to its end (or to the
//! first record that runs past the file), and of its chunks only those whose CRC checks and whose
//! records all parse and link. A damaged chunk is skipped and its offset kept; nothing that could
//! not be verified is handed on to be written with a fresh CRC.

use mcap::read::ChannelAccumulator;
use mcap::records::{Metadata, Record, op};

use crate::chunk;
use crate::records::{DataSection, Raw, record_at};

/// What the data section holds besides messages.
pub(crate) struct Records<'a> {
    pub profile: String,
    pub attachments: Vec<mcap::Attachment<'a>>,
    pub metadata: Vec<Metadata>,
    /// Offsets of the records skipped: attachments whose CRC does not check, records that do not
    /// parse.
    pub damaged: Vec<u64>,
    /// Where and why the data section stopped before its data end record.
    pub stopped_at: Option<String>,
    /// Whether the data end record's CRC does not match the data section.
    pub bad_data_crc: bool,
}

/// The header, attachments and metadata of the data section, and where it stops.
pub(crate) fn records(bytes: &[u8]) -> Records<'_> {
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
            Ok(Record::Attachment { header, data, .. }) => out.attachments.push(mcap::Attachment {
                log_time: header.log_time,
                create_time: header.create_time,
                name: header.name,
                media_type: header.media_type,
                data,
            }),
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

/// The messages of the data section, a verified chunk's worth (or one message outside a chunk)
/// at a time; the chunks and records skipped are counted by offset.
pub(crate) struct Messages<'a> {
    records: DataSection<'a>,
    channels: ChannelAccumulator<'static>,
    /// Offsets of the chunks skipped.
    pub damaged_chunks: Vec<u64>,
    /// Offsets of schema, channel and message records outside chunks that were skipped.
    pub damaged_records: Vec<u64>,
}

impl<'a> Messages<'a> {
    /// The messages of `bytes`, linked to the channels of `summary` (when it reads) as well as to
    /// those the file defines as it goes: a chunk that defined a channel may be the damaged one.
    pub fn new(bytes: &'a [u8], summary: Option<&mcap::Summary>) -> Self {
        let channels = summary.map(ChannelAccumulator::from_summary).unwrap_or_default();
        Self {
            records: DataSection::new(bytes),
            channels,
            damaged_chunks: Vec::new(),
            damaged_records: Vec::new(),
        }
    }

    /// The messages of a chunk that verifies, parses and links throughout; `None` when it does not.
    fn chunk(&mut self, raw: Raw<'_>) -> Option<Vec<mcap::Message<'static>>> {
        let Ok(Record::Chunk { header, data }) = raw.parse() else { return None };
        let opened = chunk::open(&header, &data).ok().filter(|o| o.verified)?;
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

//! A recording's messages in file order, read with every check an MCAP file offers: each record's
//! length against the bytes left, each chunk's size limits and CRC before any of its records is
//! taken (`chunk.rs`), the data section's CRC at its data end record, and the summary section's
//! CRC at the footer, then the end magic. What mcap's `MessageStream` yields for an intact file,
//! and for a damaged one the damage and the byte offset of the record it is in, never a panic.

use std::borrow::Cow;

use mcap::read::ChannelAccumulator;
use mcap::records::{Record, op};

use crate::chunk;
use crate::damage::Damage;
use crate::records::{Raw, record_at};
use crate::summary::{Located, check_summary_crc, footer, located};

/// Which part of the file the next top-level record is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Data,
    /// After the data end record, which ends at `start`.
    Summary {
        start: usize,
    },
    Done,
}

/// The chunk whose records are being read.
struct Open<'a> {
    /// The chunk record's offset in the file.
    offset: usize,
    records: Cow<'a, [u8]>,
    at: usize,
}

/// The messages of MCAP `bytes`, in file order; the first damage ends them.
pub(crate) struct Stream<'a> {
    bytes: &'a [u8],
    at: usize,
    part: Part,
    chunk: Option<Open<'a>>,
    channels: ChannelAccumulator<'static>,
}

impl<'a> Stream<'a> {
    /// The messages of `bytes`, which must start with the MCAP magic.
    pub fn new(bytes: &'a [u8]) -> Self {
        let at = mcap::MAGIC.len();
        Self { bytes, at, part: Part::Data, chunk: None, channels: ChannelAccumulator::default() }
    }

    /// The next message of the chunk being read, if it has one left.
    fn next_in_chunk(&mut self) -> Option<Result<mcap::Message<'static>, Located>> {
        loop {
            let open = self.chunk.as_mut()?;
            if open.at >= open.records.len() {
                self.chunk = None;
                return None;
            }
            let (offset, at) = (open.offset, open.at);
            let in_chunk = |what| located(offset, Damage::in_chunk(at as u64, what));
            let raw = match record_at(&open.records, at) {
                Ok(raw) => raw,
                Err(what) => return Some(Err(in_chunk(what))),
            };
            open.at = raw.end;
            // A data end record inside a chunk is a stray record, skipped as mcap does.
            if raw.opcode == op::DATA_END {
                continue;
            }
            match take(&mut self.channels, raw) {
                Ok(Some(message)) => return Some(Ok(message)),
                Ok(None) => {}
                Err(what) => return Some(Err(in_chunk(what))),
            }
        }
    }

    /// Reads the next top-level record: `Some` with a message or damage, `None` to read on.
    fn step(&mut self) -> Option<Result<mcap::Message<'static>, Located>> {
        let at = self.at;
        let here = |what| Some(Err(located(at, what)));
        if at >= self.bytes.len() {
            let what = if self.part == Part::Data { Damage::NoDataEnd } else { Damage::NoFooter };
            return here(what);
        }
        let raw = match record_at(self.bytes, at) {
            Ok(raw) => raw,
            Err(what) => return here(what),
        };
        self.at = raw.end;
        match (self.part, raw.opcode) {
            (Part::Data, op::CHUNK) => match raw.parse() {
                Ok(Record::Chunk { header, data }) => {
                    let opened = match data {
                        Cow::Borrowed(data) => chunk::open(&header, data),
                        Cow::Owned(data) => chunk::open(&header, &data).map(chunk::Opened::into_owned),
                    };
                    match opened {
                        Ok(opened) => {
                            self.chunk = Some(Open { offset: at, records: opened.records, at: 0 });
                            None
                        }
                        Err(what) => here(what),
                    }
                }
                Ok(_) => None,
                Err(what) => here(what),
            },
            (Part::Data, op::DATA_END) => match raw.parse() {
                Ok(Record::DataEnd(end)) => {
                    let (saved, calculated) = (end.data_section_crc, crc32fast::hash(&self.bytes[..at]));
                    if saved != 0 && saved != calculated {
                        return here(Damage::DataCrc { saved, calculated });
                    }
                    self.part = Part::Summary { start: raw.end };
                    None
                }
                Ok(_) => None,
                Err(what) => here(what),
            },
            (Part::Data, _) => match take(&mut self.channels, raw) {
                Ok(Some(message)) => Some(Ok(message)),
                Ok(None) => None,
                Err(what) => here(what),
            },
            (Part::Summary { start }, op::FOOTER) => {
                self.part = Part::Done;
                self.end(start, raw).err().map(Err)
            }
            // The summary repeats schemas and channels: parsed, not taken again.
            (Part::Summary { .. }, _) => raw.parse().err().and_then(here),
            (Part::Done, _) => None,
        }
    }

    /// Checks the footer at `raw` (the summary section from `start` before it) and the end magic.
    fn end(&self, start: usize, raw: Raw<'_>) -> Result<(), Located> {
        raw.parse().map_err(|what| located(raw.offset, what))?;
        let magic = self.bytes.get(raw.end..raw.end + mcap::MAGIC.len());
        if magic != Some(mcap::MAGIC) {
            return Err(located(raw.end, Damage::NoFooter));
        }
        let at_end = footer(&self.bytes[..raw.end + mcap::MAGIC.len()])?;
        check_summary_crc(self.bytes, start, &at_end)
    }
}

/// Takes a record of the data section (or of a chunk): schemas and channels are kept to link the
/// messages that follow to; a message comes back linked; other records are parsed and left.
fn take(
    channels: &mut ChannelAccumulator<'static>,
    raw: Raw<'_>,
) -> Result<Option<mcap::Message<'static>>, Damage> {
    match raw.parse()? {
        Record::Schema { header, data } => {
            channels.add_schema(header, Cow::Owned(data.into_owned())).map_err(Damage::Link)?;
        }
        Record::Channel(channel) => channels.add_channel(channel).map_err(Damage::Link)?,
        Record::Message { header, data } => {
            let channel = channels
                .get(header.channel_id)
                .ok_or(Damage::UnknownChannel { channel: header.channel_id })?;
            return Ok(Some(mcap::Message {
                channel,
                sequence: header.sequence,
                log_time: header.log_time,
                publish_time: header.publish_time,
                data: Cow::Owned(data.into_owned()),
            }));
        }
        _ => {}
    }
    Ok(None)
}

impl Iterator for Stream<'_> {
    type Item = Result<mcap::Message<'static>, Located>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(message) = self.next_in_chunk() {
                if message.is_err() {
                    self.part = Part::Done;
                }
                return Some(message);
            }
            if self.part == Part::Done {
                return None;
            }
            if let Some(item) = self.step() {
                if item.is_err() {
                    (self.part, self.chunk) = (Part::Done, None);
                }
                return Some(item);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use harvey_msgs::{Encoding, FrameHeader, Header, TruePose};

    #[test]
    fn an_intact_file_yields_exactly_what_mcaps_message_stream_does() {
        let dir = std::env::temp_dir().join(format!("harvey-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        let (truth, cam) =
            (r.channel::<TruePose>("sim/truth").expect("channel"), r.image_channel("cam").expect("ch"));
        for seq in 1..=40u64 {
            r.record(truth, &TruePose { header: Header::new(seq, seq * 1000), ..Default::default() })
                .expect("record");
            let h = FrameHeader::new(seq, seq * 1000, 4, 2, Encoding::Mono8);
            r.record_frame(cam, &h, &[seq as u8; 8]).expect("frame");
            if seq % 10 == 0 {
                r.flush().expect("a chunk");
            }
        }
        r.finish().expect("finish");
        let bytes = std::fs::read(&path).expect("read");
        let ours: Vec<_> = Stream::new(&bytes).collect::<Result<_, _>>().expect("intact");
        let theirs: Vec<_> =
            mcap::MessageStream::new(&bytes).expect("mcap").collect::<Result<_, _>>().expect("intact");
        assert_eq!(ours.len(), 80);
        assert_eq!(ours, theirs);
        std::fs::remove_dir_all(&dir).ok();
    }
}
